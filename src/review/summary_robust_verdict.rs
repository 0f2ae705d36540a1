//! The sentence `summary.md` opens with (issue 36 item 6): Winner, Statistically tied,
//! Undecided (with the worlds it needs) or no winner, with the confidence, the tests and the
//! designs pending more worlds (`docs/statistics.md`). A child of `summary_robust`.

use std::collections::BTreeMap;

use super::{Robust, TOP};
use crate::batch::records::CASE_ID;
use crate::stats::ranking::{Contender, Verdict};

impl Robust<'_> {
    /// The line the summary opens with: the verdict, then (with adaptive worlds) the rounds,
    /// why they stopped and the worlds each design met.
    pub fn verdict_line(&self) -> String {
        let mut line = self.verdict_sentence();
        line.push_str(&self.adaptive_text());
        line
    }

    /// The worlds row `r` met (its rows in `worlds.csv`).
    pub(super) fn worlds_met(&self, r: usize) -> usize {
        let Ok(case) = self.worlds.i64(CASE_ID) else {
            return 0;
        };
        case.iter().filter(|c| **c == self.ids[r]).count()
    }

    /// Whether row `r` ran in its worlds (its success probability is a number).
    fn ran(&self, r: usize) -> bool {
        self.table
            .f64(crate::batch::worlds::SUCCESS_PROBABILITY)
            .is_ok_and(|p| p[r].is_finite())
    }

    /// The worlds the verdict's leader met (the first `worlds` without a leader): what the
    /// verdict sentence says it was judged over.
    fn judged_worlds(&self) -> usize {
        match (self.leader(), &self.info.adaptive) {
            (_, None) => self.info.worlds,
            (Some(l), Some(_)) => self.worlds_met(l),
            (None, Some(a)) => a.worlds_used,
        }
    }

    /// With adaptive worlds: the rounds run, why they stopped (and what is still in
    /// contention when the budget stopped them), and the worlds each design met.
    fn adaptive_text(&self) -> String {
        let Some(a) = &self.info.adaptive else {
            return String::new();
        };
        let ran: Vec<usize> = (0..self.ids.len())
            .filter(|&r| self.worlds_met(r) > 0 && self.ran(r))
            .collect();
        let mut by_count: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for &r in &ran {
            by_count.entry(self.worlds_met(r)).or_default().push(r);
        }
        let groups: Vec<String> = by_count
            .iter()
            .rev()
            .map(|(n, rows)| {
                if *n == self.info.worlds && by_count.len() > 1 {
                    format!("{n} by the other {} that ran", rows.len())
                } else {
                    let ids: Vec<String> = rows
                        .iter()
                        .take(TOP)
                        .map(|r| format!("#{}", self.ids[*r]))
                        .collect();
                    let more = rows.len().saturating_sub(TOP);
                    format!(
                        "{n} by {}{}",
                        ids.join(", "),
                        if more > 0 {
                            format!(" and {more} more")
                        } else {
                            String::new()
                        }
                    )
                }
            })
            .collect();
        let delta = self.info.equivalence.max(self.verdict.noise);
        let why = match a.stopped.as_str() {
            "decided" => "stopped: the verdict is decided (no design left that more worlds \
                          could rank or separate from the leader)"
                .to_string(),
            _ => {
                let open: Vec<String> = crate::batch::adaptive::contention(&self.verdict, delta)
                    .iter()
                    .take(TOP)
                    .map(|r| format!("#{}", self.ids[*r]))
                    .collect();
                format!(
                    "stopped: the budget of {} worlds is spent with {} still in contention \
                     ({})",
                    a.budget,
                    if open.len() == 1 {
                        "1 design".to_string()
                    } else {
                        format!("{} designs", open.len())
                    },
                    open.join(", ")
                )
            }
        };
        format!(
            " Adaptive worlds (`adaptive_worlds` = {}, batch {}): {} round{} after the first {} \
             worlds, {why}. Worlds met: {}.",
            a.budget,
            a.batch,
            a.rounds,
            if a.rounds == 1 { "" } else { "s" },
            self.info.worlds,
            groups.join("; ")
        )
    }

    /// The verdict itself.
    fn verdict_sentence(&self) -> String {
        let v = &self.verdict;
        let n = self.judged_worlds();
        let o = self.info.objective();
        let noise = if v.noise_measured {
            format!(
                "median tuning noise {}; tie margin max(equivalence {}, noise)",
                Self::pct(v.noise),
                Self::pct(self.info.equivalence)
            )
        } else {
            format!(
                "tuning noise not measured; tie margin: equivalence {}",
                Self::pct(self.info.equivalence)
            )
        };
        match &v.verdict {
            Verdict::Winner {
                leader, runner_up, ..
            } if leader == runner_up => format!(
                "**Winner: {}** — the only design ranked (success probability ≥ {} at {:.0} % \
                 confidence, Wilson lower bound) over {n} worlds by `{o}`.{}",
                self.label(*leader),
                self.info.min_success_probability,
                100.0 * self.info.confidence,
                self.pending_text()
            ),
            Verdict::Winner {
                leader,
                runner_up,
                p_beats,
                margin,
                p_value,
            } => format!(
                "**Winner: {}** by `{o}` — beats every other ranked design at {:.0} % confidence \
                 (one-sided sign tests of the paired margin over {n} worlds, Holm-corrected; \
                 largest adjusted p = {}); runner-up {}: beaten in {:.0} % of the worlds, median \
                 margin {} ({noise}).{}",
                self.label(*leader),
                100.0 * self.info.confidence,
                fmt_p(*p_value),
                self.label(*runner_up),
                100.0 * p_beats,
                Self::pct(*margin),
                self.pending_text()
            ),
            Verdict::Tied { leader, tied } => self.tied_line(*leader, tied, &noise),
            Verdict::Undecided {
                leader,
                open,
                needs_worlds,
            } => self.undecided_line(*leader, open, *needs_worlds, &noise),
            Verdict::NoneEligible if !v.pending.is_empty() => {
                let need = v.pending.iter().filter_map(|p| p.worlds_needed).min();
                format!(
                    "**Undecided: {}** — no design is shown to succeed with probability ≥ {} at \
                     {:.0} % confidence over {n} worlds (one-sided Wilson lower bound); {} \
                     succeeded often enough to qualify with more worlds: {}.",
                    need.map_or("needs more worlds".to_string(), |w| format!(
                        "needs ≥ {w} worlds"
                    )),
                    self.info.min_success_probability,
                    100.0 * self.info.confidence,
                    v.pending.len(),
                    self.pending_list()
                )
            }
            Verdict::NoneEligible => format!(
                "**No winner: no design reaches the required success probability {}** over {n} \
                 worlds (one-sided Wilson lower bound at {:.0} % confidence).",
                self.info.min_success_probability,
                100.0 * self.info.confidence
            ),
        }
    }

    /// The verdict sentence of a tie: the leader and the cases it does not beat.
    fn tied_line(&self, leader: usize, tied: &[Contender], noise: &str) -> String {
        let (n, o) = (self.judged_worlds(), self.info.objective());
        let list: Vec<String> = std::iter::once(format!("#{}", self.ids[leader]))
            .chain(
                tied.iter()
                    .take(TOP)
                    .map(|c| format!("#{}", self.ids[c.case])),
            )
            .collect();
        let margins: Vec<String> = tied
            .iter()
            .take(5)
            .map(|c| {
                format!(
                    "#{} {} (beaten in {:.0} % of worlds, p = {})",
                    self.ids[c.case],
                    Self::pct(c.margin),
                    100.0 * c.p_beats,
                    fmt_p(c.p_adjusted)
                )
            })
            .collect();
        format!(
            "**Statistically tied: {}{}** by `{o}` over {n} paired worlds — the leader \
             does not beat these at {:.0} % confidence and the worlds do not lean its \
             way (a tie: more worlds would not separate them). Leader {}; median \
             margins behind it: {} ({noise}).{}",
            list.join(", "),
            if tied.len() > TOP { ", …" } else { "" },
            100.0 * self.info.confidence,
            self.label(leader),
            margins.join("; "),
            self.pending_text()
        )
    }

    /// The verdict sentence of an undecided study: the open comparisons and the worlds needed.
    fn undecided_line(
        &self,
        leader: usize,
        open: &[Contender],
        needs_worlds: usize,
        noise: &str,
    ) -> String {
        let (n, o) = (self.judged_worlds(), self.info.objective());
        let margins: Vec<String> = open
            .iter()
            .take(5)
            .map(|c| {
                format!(
                    "#{} {} (beaten in {} of {n} worlds, p = {})",
                    self.ids[c.case],
                    Self::pct(c.margin),
                    c.wins,
                    fmt_p(c.p_adjusted)
                )
            })
            .collect();
        format!(
            "**Undecided: needs ≥ {needs_worlds} worlds** — the leader {} by `{o}` leads \
             every ranked design, but {n} worlds cannot show it at {:.0} % confidence \
             against {}: {} ({noise}).{}",
            self.label(leader),
            100.0 * self.info.confidence,
            if open.len() == 1 {
                "one of them".to_string()
            } else {
                format!("{} of them", open.len())
            },
            margins.join("; "),
            self.pending_text()
        )
    }

    /// The designs that succeeded often enough in their worlds but cannot yet be shown to
    /// meet the requirement, with their lower bounds.
    fn pending_list(&self) -> String {
        let items: Vec<String> = self
            .verdict
            .pending
            .iter()
            .take(TOP)
            .map(|p| {
                format!(
                    "{} (success {:.2}, lower bound {:.2})",
                    self.label(p.row),
                    p.share,
                    p.lower
                )
            })
            .collect();
        let more = self.verdict.pending.len().saturating_sub(TOP);
        if more > 0 {
            format!("{}, and {more} more", items.join("; "))
        } else {
            items.join("; ")
        }
    }

    /// A sentence on pending designs after a verdict (empty without any).
    fn pending_text(&self) -> String {
        let p = &self.verdict.pending;
        if p.is_empty() {
            return String::new();
        }
        let need = p.iter().filter_map(|x| x.worlds_needed).max();
        format!(
            " Not ranked for too few worlds ({} design{} whose success proportion meets the \
             requirement but not its {:.0} % lower bound{}): {}.",
            p.len(),
            if p.len() == 1 { "" } else { "s" },
            100.0 * self.info.confidence,
            need.map_or(String::new(), |w| format!(
                "; ≥ {w} worlds would qualify them"
            )),
            self.pending_list()
        )
    }
}

/// A p-value for the verdict line: `< 1e-4` below it, else three significant digits.
fn fmt_p(p: f64) -> String {
    if !p.is_finite() {
        "–".into()
    } else if p < 1e-4 {
        "< 1e-4".into()
    } else {
        format!("{p:.3}")
    }
}

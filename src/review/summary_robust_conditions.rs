//! The robust sections of a study with condition axes (issue 42 item 3; a child of
//! `summary_robust`): one view per condition ([`crate::batch::conditions`]), each with its own
//! verdict, box and ranking among the designs under that condition — never across them; and
//! the rank-interval plot of a ranking (one per condition).

use std::fmt::Write as _;
use std::path::Path;

use super::{
    rank_interval_pdf, rank_interval_svg, verdict_box, BoxInput, RankRow, Robust, RANK_COLUMNS,
    TOP, VERDICT_END,
};
use crate::batch::conditions::PER_CONDITION;
use crate::batch::robust::condition_verdicts;
use crate::review::plots_ranked::{write_pdf, write_plot};

impl<'a> Robust<'a> {
    /// Whether this is the whole study of one with condition axes (its verdict, leader and
    /// ranking are per condition, in [`Robust::views`]).
    pub(super) fn across_conditions(&self) -> bool {
        self.condition.is_none() && !self.info.conditions.is_empty()
    }

    /// One view per condition, each judged among its own rows, labelled without the condition
    /// axes (constant within it); empty for a study without condition axes.
    fn views(&self) -> Vec<Robust<'a>> {
        if !self.across_conditions() {
            return Vec::new();
        }
        let conds = &self.info.conditions;
        condition_verdicts(self.table, &self.worlds, self.info)
            .unwrap_or_default()
            .into_iter()
            .map(|(c, v)| Robust {
                table: self.table,
                info: self.info,
                worlds: std::rc::Rc::clone(&self.worlds),
                verdict: v,
                ids: self.ids.clone(),
                axes: self
                    .axes
                    .iter()
                    .copied()
                    .filter(|a| !conds.iter().any(|c| c == a))
                    .collect(),
                condition: Some(c),
                firm: String::new(),
            })
            .collect()
    }

    /// The opening of a study with condition axes: what a condition is, then per condition
    /// its verdict line and box.
    pub(super) fn opening_per_condition(&self) -> String {
        let views = self.views();
        let axes: Vec<String> = self
            .info
            .conditions
            .iter()
            .map(|c| format!("`{c}`"))
            .collect();
        let mut md = format!(
            "{PER_CONDITION}** ({} conditions of {}) — a condition (`condition = true`) is a \
             circumstance the designs meet, not a design choice: each design is ranked and \
             judged only against the designs under the same condition, never across \
             conditions.\n\n",
            views.len(),
            axes.join(", ")
        );
        md.push_str(&self.firm);
        for v in &views {
            let ranked = v.ranked_rows();
            let label = |r: usize| v.label(r);
            let inp = BoxInput {
                table: v.table,
                ranked: &ranked,
                objective: v.info.objective(),
                label: &label,
                axes: &v.axes,
                within: v.condition.as_ref().map(|c| c.rows.as_slice()),
                min_success: v.info.min_success_probability,
            };
            let c = v.condition.as_ref().map_or("", |c| c.label.as_str());
            let _ = write!(
                md,
                "**Under {c}:** {}\n\n{}",
                v.verdict_line(),
                verdict_box(&inp)
            );
        }
        md.push_str(VERDICT_END);
        md
    }

    /// The ranking section of a study with condition axes: the counts over every condition,
    /// then one ranking per condition.
    pub(super) fn ranking_per_condition(
        &self,
        md: &mut String,
        plots: &Path,
        warnings: &mut Vec<String>,
    ) {
        let _ = writeln!(
            md,
            "## Ranking per condition\n\n{} of the designs are ranked over all conditions \
             together; {} ran but are not ranked (success probability below {}). Ranks and \
             `p_best` are among the designs under the same condition.\n",
            self.verdict.ranked, self.verdict.below_requirement, self.info.min_success_probability
        );
        for v in self.views() {
            v.ranking_section(md, plots, warnings);
        }
    }

    /// The rank-interval plot of the ranked `rows` (best first), linked from `md`.
    pub(super) fn rank_plot(
        &self,
        rows: &[usize],
        md: &mut String,
        plots: &Path,
        warnings: &mut Vec<String>,
    ) {
        let o = self.info.objective();
        let (p05, p50, p95) = (
            self.col(RANK_COLUMNS[0]),
            self.col(RANK_COLUMNS[1]),
            self.col(RANK_COLUMNS[2]),
        );
        let leader = self.leader();
        let rank_rows: Vec<RankRow> = rows
            .iter()
            .take(TOP)
            .map(|&r| RankRow {
                label: self.label(r),
                p05: p05[r],
                p50: p50[r],
                p95: p95[r],
                highlight: Some(r) == leader,
            })
            .collect();
        if !rank_rows.is_empty() && self.verdict.ranked > 0 {
            let under = self.condition.as_ref().map_or(String::new(), |c| {
                format!(", under {}", c.label.replace('`', ""))
            });
            let title = format!(
                "Rank of each design by {o} over {} worlds (5–95 %){under}",
                self.info.worlds
            );
            let file = match &self.condition {
                Some(c) => format!(
                    "rank_intervals_{}.svg",
                    crate::report::file_stem_safe(&c.label)
                ),
                None => "rank_intervals.svg".to_string(),
            };
            match rank_interval_svg(&title, &rank_rows, self.verdict.ranked) {
                Ok(svg) => {
                    write_plot(plots, &file, &svg, warnings);
                    let pdf = rank_interval_pdf(&title, &rank_rows, self.verdict.ranked);
                    write_pdf(plots, &file, pdf, warnings);
                    let _ = writeln!(md, "![rank intervals](plots/{file})\n");
                }
                Err(e) => warnings.push(format!("{file}: {e}")),
            }
        }
    }
}

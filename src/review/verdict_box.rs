//! The verdict box `summary.md`, `report.html` and the end of a sweep open with (issue 25
//! item 1), after the verdict line of [`super::summary_robust`]: the leader's caveats (every
//! review metric on which it sits in the worst quartile of the ranked designs, e.g. how much
//! of joint space leaves it without commanded authority) and the top three ranked designs side
//! by side. Markdown only; the page adds the drawings.

use std::fmt::Write as _;

use super::families::{families, families_note, family_name, minor_axes};
use crate::report::{fmt_short, MarkdownTable, Table};
use crate::stats::describe::quantile_sorted;
use crate::study::directions::larger_is_better;

/// The metrics a reviewer weighs beside the objective, in the order the box lists them; a
/// study shows those its table has.
pub const REVIEW_METRICS: [&str; 12] = [
    "success_probability",
    "p_best",
    "tcm_singular_fraction_commanded",
    "authority_margin",
    "authority_min_force",
    "fault_tolerance",
    "saturation_fraction",
    "cross_track_iae",
    "joint_energy",
    "total_energy_per_metre",
    "reach",
    "tune_noise",
];

/// A leader's tuning noise above this (relative spread of its independent tuning starts) is a
/// caveat of its own.
pub const NOISY_TUNING: f64 = 0.1;

/// How many designs the box sets side by side.
pub const TOP_N: usize = 3;

/// What the box needs of a study's ranked designs.
pub struct BoxInput<'a> {
    /// The case table.
    pub table: &'a Table,
    /// Ranked rows, best first.
    pub ranked: &'a [usize],
    /// The objective (nominal world) and its summary over worlds (`<objective>_mean`).
    pub objective: &'a str,
    /// A row's label (`#45 (ends, 4, 0.06)`).
    pub label: &'a dyn Fn(usize) -> String,
    /// The study's axes (the families of [`super::families`] are over them).
    pub axes: &'a [&'a str],
    /// The rows this box judges (a condition's; `None`: every row).
    pub within: Option<&'a [bool]>,
    /// The success probability a design needs (its lower confidence bound) to be ranked.
    pub min_success: f64,
}

/// The column `name` as numbers (`None` when the table lacks it or it is not numeric).
fn column(t: &Table, name: &str) -> Option<Vec<f64>> {
    t.f64(name).ok().map(<[f64]>::to_vec)
}

/// The metrics of the box: the objective's world mean and nominal value, then the
/// [`REVIEW_METRICS`] the table has (the objective itself once).
fn box_metrics(inp: &BoxInput) -> Vec<String> {
    let mut v = vec![format!("{}_mean", inp.objective), inp.objective.to_string()];
    v.extend(REVIEW_METRICS.iter().map(|s| s.to_string()));
    v.dedup();
    v.into_iter()
        .filter(|m| column(inp.table, m).is_some())
        .collect()
}

/// The leader's caveats: each box metric (besides the objective and the ranking columns)
/// on which the leader is in the worst quartile of the ranked designs, with its value and the
/// median. Empty with fewer than four ranked designs (no quartile to speak of).
pub fn caveats(inp: &BoxInput) -> Vec<String> {
    let Some(&leader) = inp.ranked.first() else {
        return Vec::new();
    };
    if inp.ranked.len() < 4 {
        return Vec::new();
    }
    let skip = ["success_probability", "p_best", inp.objective];
    let mut out = Vec::new();
    for m in box_metrics(inp) {
        if skip.contains(&m.as_str()) || m.starts_with(inp.objective) {
            continue;
        }
        let Some(col) = column(inp.table, &m) else {
            continue;
        };
        let mut xs: Vec<f64> = inp
            .ranked
            .iter()
            .map(|&r| col[r])
            .filter(|x| x.is_finite())
            .collect();
        let x = col[leader];
        if xs.len() < 4 || !x.is_finite() {
            continue;
        }
        xs.sort_by(f64::total_cmp);
        let larger = larger_is_better(&m);
        let (worst_q, bad) = if larger {
            let q = quantile_sorted(&xs, 0.25);
            (q, x < q)
        } else {
            let q = quantile_sorted(&xs, 0.75);
            (q, x > q)
        };
        if bad && xs[0] != xs[xs.len() - 1] {
            out.push(format!(
                "`{m}` = {} is in the worst quartile of the {} ranked designs ({} than {}; \
                 median {})",
                fmt_short(x),
                xs.len(),
                if larger { "lower" } else { "higher" },
                fmt_short(worst_q),
                fmt_short(quantile_sorted(&xs, 0.5))
            ));
        }
    }
    out
}

/// The held-out validation variants (`validate.<name>.success` columns) in which row `r` did
/// not succeed, each as a caveat line with the criterion it missed when recorded.
pub fn failed_variants(t: &Table, r: usize) -> Vec<String> {
    let mut out = Vec::new();
    for c in &t.columns {
        let Some(name) = c
            .name
            .strip_prefix("validate.")
            .and_then(|n| n.strip_suffix(".success"))
        else {
            continue;
        };
        let Some(ok) = column(t, &c.name) else {
            continue;
        };
        if ok[r] == 1.0 {
            continue;
        }
        let gap = column(t, &format!("validate.{name}.gap")).map_or(f64::NAN, |g| g[r]);
        out.push(format!(
            "`{name}`: {} (`validate.{name}.success` = {}{})",
            if ok[r].is_nan() {
                "did not run to an outcome"
            } else {
                "unsuccessful"
            },
            fmt_short(ok[r]),
            if gap.is_finite() {
                format!(", gap {:+.1} % from the nominal run", 100.0 * gap)
            } else {
                String::new()
            }
        ));
    }
    out
}

/// The top [`TOP_N`] families of ranked designs ([`super::families`]) side by side: one
/// column per family (its best-ranked member's values, the range of its minor axes and its
/// members in the header), one row per box metric, and the family's `p_best` (the sum over its
/// members). Without a minor axis every family is one design.
pub fn top_table(inp: &BoxInput) -> Option<String> {
    if inp.ranked.is_empty() {
        return None;
    }
    let minor = minor_axes(inp.table, inp.axes, inp.ranked, inp.objective);
    let fams = families(inp.table, inp.axes, inp.ranked, &minor);
    let top: Vec<&Vec<usize>> = fams.iter().take(TOP_N).collect();
    let mut header = vec!["metric".to_string()];
    header.extend(top.iter().enumerate().map(|(i, f)| {
        if f.len() == 1 {
            format!("{}. {}", i + 1, (inp.label)(f[0]))
        } else {
            let ids: Vec<String> = f.iter().map(|&r| (inp.label)(r)).collect();
            let ids: Vec<&str> = ids.iter().filter_map(|l| l.split(' ').next()).collect();
            format!(
                "{}. family ({}): {}",
                i + 1,
                family_name(inp.table, inp.axes, f),
                ids.join(", ")
            )
        }
    }));
    let mut t = MarkdownTable::new(header);
    let p_best = column(inp.table, "p_best");
    for m in box_metrics(inp) {
        let col = column(inp.table, &m)?;
        let mut row = vec![format!("`{m}`")];
        row.extend(top.iter().map(|f| fmt_short(col[f[0]])));
        t.row(row);
        if m == inp.objective && top.iter().any(|f| f.len() > 1) {
            let mut row = vec![format!("`{m}` range in the family")];
            row.extend(top.iter().map(|f| {
                let v: Vec<f64> = f.iter().map(|&r| col[r]).collect();
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                format!("{} … {}", fmt_short(lo), fmt_short(hi))
            }));
            t.row(row);
        }
        if m == "p_best" && top.iter().any(|f| f.len() > 1) {
            let mut row = vec!["family `p_best` (sum over its members)".to_string()];
            row.extend(top.iter().map(|f| {
                let s: f64 = f
                    .iter()
                    .filter_map(|&r| p_best.as_ref().map(|p| p[r]))
                    .sum();
                fmt_short(s)
            }));
            t.row(row);
        }
    }
    let mut md = t.finish();
    if let Some(note) = families_note(&minor, inp.objective) {
        md.push('\n');
        md.push_str(&note);
        md.push('\n');
    }
    Some(md)
}

/// Why ranked row `r` is ranked or unranked row `r` is not: its success probability over the
/// worlds with its lower confidence bound against the requirement, or the nominal criterion
/// it missed.
pub fn rank_reason(t: &Table, r: usize, min_success: f64) -> String {
    let at = |c: &str| column(t, c).map_or(f64::NAN, |v| v[r]);
    let (p, lo, met) = (
        at("success_probability"),
        at("success_probability_lower"),
        at("worlds_met"),
    );
    if p.is_finite() {
        let worlds = if met.is_finite() {
            format!("success in {} of {} worlds, ", (p * met).round(), met)
        } else {
            String::new()
        };
        return format!(
            "{worlds}success probability {} (95 % lower bound {} {} {})",
            fmt_short(p),
            fmt_short(lo),
            if lo >= min_success { "≥" } else { "<" },
            fmt_short(min_success)
        );
    }
    let missed = t
        .str("missed")
        .ok()
        .or_else(|| t.str(crate::batch::records::REASON).ok())
        .map(|c| c[r].clone())
        .filter(|s| !s.is_empty());
    match missed {
        Some(m) => format!("unsuccessful in the nominal world ({m}), so never met the worlds"),
        None => "did not run in the worlds".into(),
    }
}

/// The nominal-best design (the best objective among the cases successful in the nominal
/// world, within the box's rows) named beside the leader when it differs, with the reason:
/// the same family, behind over the worlds, or not ranked and why.
pub fn nominal_best_line(inp: &BoxInput) -> Option<String> {
    let &leader = inp.ranked.first()?;
    let obj = column(inp.table, inp.objective)?;
    let bad = super::plots::unsuccessful_rows(inp.table);
    let larger = larger_is_better(inp.objective);
    let best = (0..inp.table.n_rows())
        .filter(|&r| !bad[r] && obj[r].is_finite() && inp.within.is_none_or(|w| w[r]))
        .min_by(|&a, &b| {
            let o = obj[a].total_cmp(&obj[b]);
            if larger {
                o.reverse()
            } else {
                o
            }
        })?;
    let o = inp.objective;
    if best == leader {
        return Some(format!(
            "The leader is also the best design in the nominal world (`{o}` = {}).",
            fmt_short(obj[best])
        ));
    }
    let head = format!(
        "**Best in the nominal world: {}** (`{o}` = {} against the leader's {}), **robust-best \
         (the verdict): {}** — ",
        (inp.label)(best),
        fmt_short(obj[best]),
        fmt_short(obj[leader]),
        (inp.label)(leader)
    );
    let minor = minor_axes(inp.table, inp.axes, inp.ranked, o);
    let fams = families(inp.table, inp.axes, inp.ranked, &minor);
    let why = if fams
        .iter()
        .any(|f| f.contains(&best) && f.contains(&leader))
    {
        "the same family: they differ only in a minor axis, so this is one layout.".to_string()
    } else if inp.ranked.contains(&best) {
        let mean = column(inp.table, &format!("{o}_mean"));
        let m = |r: usize| mean.as_ref().map_or(f64::NAN, |v| v[r]);
        format!(
            "ranked, but behind over the worlds (mean `{o}` {} against {}): cheaper in the \
             nominal world is not cheaper where the worlds vary.",
            fmt_short(m(best)),
            fmt_short(m(leader))
        )
    } else {
        format!(
            "**not ranked**: {}; a design must succeed reliably over the worlds before its \
             cost counts.",
            rank_reason(inp.table, best, inp.min_success)
        )
    };
    Some(head + &why)
}

/// What `p_best` and "tied" mean, for the line under the box's table.
pub const P_BEST_NOTE: &str = "`p_best`: the fraction of the paired worlds in which the design \
has the best objective of all ranked designs (a family's: the sum over its members). *Tied*: \
the leader does not beat the design at 95 % confidence over the paired worlds and the margin is \
inside max(equivalence margin, tuning noise) — the study cannot tell them apart, which is not a \
claim that they are equal.";

/// The box below the verdict line: caveats, then the top designs side by side.
pub fn verdict_box(inp: &BoxInput) -> String {
    let mut md = String::new();
    let cav = caveats(inp);
    if let Some(&leader) = inp.ranked.first() {
        let noise_col = column(inp.table, "tune_noise");
        let noise = noise_col.as_ref().map_or(f64::NAN, |c| c[leader]);
        if noise_col.is_some() && noise.is_nan() {
            let _ = writeln!(
                md,
                "Caveat: fewer than two of the independent tuning starts of {} reached a point \
                 meeting every tuning constraint, so its tuning noise is not measured \
                 (`tune_noise` empty); its cost is what one start found.\n",
                (inp.label)(leader)
            );
        } else if noise > NOISY_TUNING {
            let _ = writeln!(
                md,
                "Caveat: the tuning of {} did not settle — its independent starts ended {:.0} % \
                 apart (`tune_noise`); its cost is what this budget found, not the design's best.\n",
                (inp.label)(leader),
                100.0 * noise
            );
        }
        let failed = failed_variants(inp.table, leader);
        if !failed.is_empty() {
            let _ = writeln!(
                md,
                "Held-out variants {} fails (`[[validate]]`, at its tuned values; not part of \
                 the ranking):\n",
                (inp.label)(leader)
            );
            for v in &failed {
                let _ = writeln!(md, "- {v}");
            }
            md.push('\n');
        }
        if inp.ranked.len() < 4 {
            let _ = writeln!(
                md,
                "Caveats by quartile: not judged — {} ranked design(s) are too few for quartiles.\n",
                inp.ranked.len()
            );
        } else if cav.is_empty() {
            let _ = writeln!(
                md,
                "Caveats: none — {} is outside the worst quartile of the ranked designs on \
                 every review metric the study reports.\n",
                (inp.label)(leader)
            );
        } else {
            let _ = writeln!(md, "Caveats for {}:\n", (inp.label)(leader));
            for c in &cav {
                let _ = writeln!(md, "- {c}");
            }
            md.push('\n');
        }
    }
    if let Some(line) = nominal_best_line(inp) {
        let _ = writeln!(md, "{line}\n");
    }
    // The top layouts first (what a reader looks for), then the leader's caveats.
    match top_table(inp) {
        Some(t) => format!(
            "Top {} layouts side by side (ranked by the probability of being best, then the \
             mean objective):\n\n{t}\n{P_BEST_NOTE}\n\n{md}",
            inp.ranked.len().min(TOP_N)
        ),
        None => md,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::ColumnData;

    fn table() -> Table {
        let mut t = Table::new();
        t.push("success_probability", ColumnData::F64(vec![1.0; 5]))
            .unwrap();
        t.push(
            "mission_cost",
            ColumnData::F64(vec![40.0, 41.0, 42.0, 43.0, 44.0]),
        )
        .unwrap();
        t.push(
            "tcm_singular_fraction_commanded",
            ColumnData::F64(vec![0.9, 0.1, 0.2, 0.3, 0.4]),
        )
        .unwrap();
        t.push("reach", ColumnData::F64(vec![3.0, 2.0, 3.0, 4.0, 5.0]))
            .unwrap();
        t
    }

    #[test]
    fn the_leader_is_warned_where_it_is_in_the_worst_quartile() {
        let t = table();
        let label = |r: usize| format!("#{r}");
        let inp = BoxInput {
            table: &t,
            ranked: &[0, 1, 2, 3, 4],
            objective: "mission_cost",
            label: &label,
            axes: &[],
            within: None,
            min_success: 0.9,
        };
        let c = caveats(&inp);
        assert_eq!(c.len(), 1, "{c:?}");
        assert!(
            c[0].starts_with("`tcm_singular_fraction_commanded` = 0.9"),
            "{c:?}"
        );
        let b = verdict_box(&inp);
        assert!(b.contains("| metric | 1. #0 | 2. #1 | 3. #2 |"), "{b}");
        assert!(b.contains("| `reach` | 3 | 2 | 3 |"), "{b}");
        // Fewer than four ranked designs: no quartile, no caveat.
        let inp = BoxInput {
            ranked: &[0, 1],
            ..inp
        };
        assert!(caveats(&inp).is_empty());
    }

    #[test]
    fn a_leader_without_two_feasible_tuning_starts_is_named() {
        let mut t = table();
        t.push(
            "tune_noise",
            ColumnData::F64(vec![f64::NAN, 0.05, 0.5, 0.02, 0.01]),
        )
        .unwrap();
        let label = |r: usize| format!("#{r}");
        let inp = BoxInput {
            table: &t,
            ranked: &[0, 1, 2, 3, 4],
            objective: "mission_cost",
            label: &label,
            axes: &[],
            within: None,
            min_success: 0.9,
        };
        assert!(verdict_box(&inp).contains("fewer than two of the independent tuning starts of #0"));
        let inp = BoxInput {
            ranked: &[2, 0],
            ..inp
        };
        let b = verdict_box(&inp);
        assert!(b.contains("#2 did not settle") && b.contains("50 %"), "{b}");
    }

    #[test]
    fn the_box_shows_families_and_names_a_nominal_best_that_is_not_ranked() {
        let mut t = Table::new();
        let rule = ["a", "a", "b", "b", "c"].map(String::from).to_vec();
        t.push("rule", ColumnData::Str(rule)).unwrap();
        t.push("off", ColumnData::F64(vec![0.1, 0.2, 0.1, 0.2, 0.1]))
            .unwrap();
        let cost = vec![10.0, 10.01, 12.0, 12.02, 5.0];
        t.push("mission_cost", ColumnData::F64(cost)).unwrap();
        t.push(
            "mission_cost_mean",
            ColumnData::F64(vec![11.0, 11.1, 13.0, 13.1, 9.0]),
        )
        .unwrap();
        let p = vec![0.6, 0.3, 0.1, 0.0, f64::NAN];
        t.push("p_best", ColumnData::F64(p)).unwrap();
        t.push(
            "success_probability",
            ColumnData::F64(vec![1.0, 1.0, 1.0, 1.0, 0.5]),
        )
        .unwrap();
        t.push(
            "success_probability_lower",
            ColumnData::F64(vec![0.9, 0.9, 0.9, 0.9, 0.3]),
        )
        .unwrap();
        let label = |r: usize| format!("#{r}");
        let inp = BoxInput {
            table: &t,
            ranked: &[0, 1, 2, 3],
            objective: "mission_cost",
            label: &label,
            axes: &["rule", "off"],
            within: None,
            min_success: 0.9,
        };
        let top = top_table(&inp).unwrap();
        assert!(
            top.contains(
                "| metric | 1. family (a, 0.1–0.2): #0, #1 | 2. family (b, 0.1–0.2): #2, #3 |"
            ),
            "{top}"
        );
        assert!(
            top.contains("| family `p_best` (sum over its members) | 0.9 | 0.1 |"),
            "{top}"
        );
        let line = nominal_best_line(&inp).unwrap();
        assert!(
            line.contains("Best in the nominal world: #4") && line.contains("**not ranked**"),
            "{line}"
        );
        assert!(line.contains("95 % lower bound 0.3 < 0.9"), "{line}");
    }
}

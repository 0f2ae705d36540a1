//! The verdict box `summary.md`, `report.html` and the end of a sweep open with (issue 25
//! item 1), after the verdict line of [`super::summary_robust`]: the leader's caveats (every
//! review metric on which it sits in the worst quartile of the ranked designs, e.g. how much
//! of joint space leaves it without commanded authority) and the top three ranked designs side
//! by side. Markdown only; the page adds the drawings.

use std::fmt::Write as _;

use super::directions::larger_is_better;
use crate::report::{fmt_short, MarkdownTable, Table};
use crate::stats::describe::quantile_sorted;

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

/// The top [`TOP_N`] ranked designs side by side: one column per design, one row per box
/// metric.
pub fn top_table(inp: &BoxInput) -> Option<String> {
    if inp.ranked.is_empty() {
        return None;
    }
    let top: Vec<usize> = inp.ranked.iter().copied().take(TOP_N).collect();
    let mut header = vec!["metric".to_string()];
    header.extend(
        top.iter()
            .enumerate()
            .map(|(i, &r)| format!("{}. {}", i + 1, (inp.label)(r))),
    );
    let mut t = MarkdownTable::new(header);
    for m in box_metrics(inp) {
        let col = column(inp.table, &m)?;
        let mut row = vec![format!("`{m}`")];
        row.extend(top.iter().map(|&r| fmt_short(col[r])));
        t.row(row);
    }
    Some(t.finish())
}

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
    if let Some(t) = top_table(inp) {
        let _ = writeln!(
            md,
            "Top {} side by side (ranked by the probability of being best, then the mean \
             objective):\n\n{t}",
            inp.ranked.len().min(TOP_N)
        );
    }
    md
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
        };
        assert!(verdict_box(&inp).contains("fewer than two of the independent tuning starts of #0"));
        let inp = BoxInput {
            ranked: &[2, 0],
            ..inp
        };
        let b = verdict_box(&inp);
        assert!(b.contains("#2 did not settle") && b.contains("50 %"), "{b}");
    }
}

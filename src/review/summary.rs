//! The sweep report: `summary.md` and the SVG plots under `plots/` ([`super::plots`]),
//! generated from the final case table and the manifest only (so `usm-study report DIR` can
//! regenerate them).
//!
//! `summary.md`: counts, the best case by each metric, the main effects of each axis (median of
//! the key metrics per axis value; numeric axes with many values binned), the Pareto-optimal
//! cases of the trade-off (energy vs singularity exposure by default), the cases left out.
//!
//! Only successful cases (status `ok`) are ranked, averaged and put on the Pareto front; the
//! summary says how many were left out and why (per missed `[success]` criterion, failures,
//! skips) and lists them with the criterion they missed.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::plots::{axis_plots, extreme_names, heatmaps, pareto_plot, timeseries_plot};
use super::selection::{cell_text, levels, ok_rows, Front, Selection, SUCCESS};
use super::summary_robust::Robust;
use crate::batch::faults::{fault_table, FAULT_PREFIX};
use crate::batch::manifest::Manifest;
use crate::batch::records::{CaseEnd, CaseStatus, CASE_ID, REASON, STATUS};
use crate::outcome::run_summary::SUCCESS_MARGIN;
use crate::report::{fmt_short, MarkdownTable, Table};
use crate::study::schema::{DoeKind, TUNED_PREFIX, TUNE_EVALUATIONS, TUNE_FEASIBLE};

/// What every section of the summary reads.
struct Ctx<'a> {
    table: &'a Table,
    sel: Selection,
    ids: Vec<i64>,
    /// The successful rows: the only ones ranked.
    ok_rows: Vec<usize>,
    /// The rows left out, each with its status and the criterion it missed (`None` for a
    /// skipped case).
    left_out: Vec<(usize, CaseStatus, Option<&'a str>)>,
    axes: Vec<&'a str>,
    key: Vec<String>,
}

impl Ctx<'_> {
    /// The rows that ran (`ok` or unsuccessful), ascending.
    fn ran_rows(&self) -> Vec<usize> {
        let mut ran: Vec<usize> = self.ok_rows.clone();
        ran.extend(
            self.left_out
                .iter()
                .filter(|x| x.1 == CaseStatus::Unsuccessful)
                .map(|x| x.0),
        );
        ran.sort_unstable();
        ran
    }

    /// A table with the columns `first…` followed by one column per axis.
    fn table(&self, first: &[&str]) -> MarkdownTable {
        MarkdownTable::new(first.iter().copied().chain(self.axes.iter().copied()))
    }

    /// A row of [`Ctx::table`]: the cells `first`, then the axis values of case row `r`.
    fn row(&self, t: &mut MarkdownTable, first: Vec<String>, r: Option<usize>) {
        let axes = self.axes.iter().map(|a| match r {
            Some(r) => cell_text(self.table, a, r),
            None => "–".to_string(),
        });
        t.row(first.into_iter().chain(axes));
    }
}

/// Write `summary.md` and the plots into `dir`; returns non-fatal problems.
pub fn write_report(dir: &Path, table: &Table, m: &Manifest) -> Vec<String> {
    let mut warnings = Vec::new();
    let plots = dir.join("plots");
    // The figures of an earlier report go first: this one writes its own again.
    if let Err(e) = crate::batch::outdir::remove_owned_plots(dir) {
        warnings.push(e.to_string());
    }
    if let Err(e) = std::fs::create_dir_all(&plots) {
        warnings.push(format!("{}: {e}", plots.display()));
        return warnings;
    }
    let sel = Selection::new(table, m);
    let key = sel.key_metrics();
    let c = Ctx {
        table,
        sel,
        ids: table.i64(CASE_ID).map(|s| s.to_vec()).unwrap_or_default(),
        ok_rows: ok_rows(table),
        left_out: left_out(table),
        axes: m.axes.iter().map(|a| a.name.as_str()).collect(),
        key,
    };
    let robust = Robust::load(dir, table, m);
    let mut md = header_section(&c, m, robust.as_ref().map(Robust::opening));
    if let Some(r) = &robust {
        md.push_str(&r.sections(dir, &plots, &mut warnings));
    }
    let bound = super::summary_bound::bound_section(
        table,
        &c.axes,
        &c.ok_rows,
        &c.sel,
        &plots,
        &mut warnings,
    );
    if let Some(b) = bound {
        md.push_str(&b);
    }
    tune_section(&c, &mut md, robust.is_some());
    best_section(&c, &mut md);
    effects_section(&c, &mut md);
    if let Some(f) = c.sel.front(table, &c.ok_rows) {
        pareto_section(&c, &f, &mut md);
        pareto_plot(table, &c.axes, &f, &plots, &mut warnings);
        let _ = writeln!(md);
    }
    fault_section(&c, &mut md);
    left_out_section(&c, &mut md);
    if let Err(e) = crate::report::atomic_write(&dir.join("summary.md"), md.as_bytes()) {
        warnings.push(e.to_string());
    }
    axis_plots(table, &c.axes, &c.key, &c.ok_rows, &plots, &mut warnings);
    if m.doe == DoeKind::Grid {
        if let Some(o) = &c.sel.objective {
            // Too few successful cases to fill a grid: every case that ran, said so in the
            // title (a sensitivity study's unsuccessful cases are information).
            heatmaps(
                table,
                &c.axes,
                o,
                (&c.ok_rows, &c.ran_rows()),
                &plots,
                &mut warnings,
            );
        }
    }
    let names = extreme_names(table, &c.sel);
    timeseries_plot(dir, &names, &plots, &mut warnings);
    warnings
}

/// The rows whose status is not `ok`, with their status and missed criterion.
fn left_out(table: &Table) -> Vec<(usize, CaseStatus, Option<&str>)> {
    let status = table.str(STATUS).unwrap_or(&[]);
    let reasons = table.str(REASON).unwrap_or(&[]);
    (0..table.n_rows())
        .filter_map(|i| {
            let s = CaseStatus::parse(status.get(i)?)?;
            let r = reasons.get(i).map_or("", String::as_str);
            let k = CaseEnd::read(s, r).and_then(|e| e.criterion());
            (s != CaseStatus::Ok).then_some((i, s, k))
        })
        .collect()
}

/// How many cases were left out of the ranking per (status, missed criterion), in that
/// order.
fn left_out_counts<'a>(c: &Ctx<'a>) -> BTreeMap<(CaseStatus, Option<&'a str>), usize> {
    let mut groups = BTreeMap::new();
    for &(_, s, k) in &c.left_out {
        *groups.entry((s, k)).or_insert(0) += 1;
    }
    groups
}

/// `left out: 40 missed `cross_track_bound`, 2 failed, 1 skipped` (or `none left out`).
fn left_out_text(c: &Ctx) -> String {
    let parts: Vec<String> = left_out_counts(c)
        .iter()
        .map(|((s, k), n)| match (s, k) {
            (CaseStatus::Unsuccessful, Some(k)) => format!("{n} missed `{k}`"),
            (s, _) => format!("{n} {s}"),
        })
        .collect();
    if parts.is_empty() {
        "none left out".into()
    } else {
        format!("{} left out: {}", c.left_out.len(), parts.join(", "))
    }
}

/// The reason of a left-out case without the criterion an unsuccessful case's reason starts
/// with (the table shows it in its own column).
fn detail(s: CaseStatus, reason: &str) -> &str {
    crate::evaluate::reason_detail(s, reason)
}

/// Title, description, counts and the objective.
fn header_section(c: &Ctx, m: &Manifest, verdict: Option<String>) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Sweep `{}`\n", m.study_name);
    if let Some(v) = verdict {
        let _ = writeln!(md, "{v}\n");
    }
    if !m.description.is_empty() {
        let _ = writeln!(md, "{}\n", m.description.trim());
    }
    let _ = writeln!(
        md,
        "Mode `{}`{}, design of experiments `{}`, seed {}, {} of {} cases in this output: \
         **{} ok, {} unsuccessful, {} failed, {} skipped**. Study hash `{}`, usm-study {}.\n",
        m.mode,
        if m.static_analysis {
            " + static TCM analysis"
        } else {
            ""
        },
        m.doe,
        m.seed,
        m.cases.in_output,
        m.cases.planned,
        m.cases.ok,
        m.cases.unsuccessful,
        m.cases.failed,
        m.cases.skipped,
        &m.study_hash[..16.min(m.study_hash.len())],
        m.tool_version
    );
    let _ = writeln!(
        md,
        "**Only the {} successful cases** (status `ok`{}) are ranked, averaged and put on the \
         Pareto front; {} (see [the cases left out](#cases-left-out)).\n",
        c.ok_rows.len(),
        if m.mode.is_dynamic() {
            ": the run met every `[success]` criterion of the scenario"
        } else {
            ""
        },
        left_out_text(c)
    );
    if let Some(o) = &c.sel.objective {
        let _ = writeln!(
            md,
            "Objective (best/worst case): `{o}` ({}).\n",
            match c.sel.goal(o) {
                "max" => "larger is better",
                "min abs" => "smaller magnitude is better",
                _ => "smaller is better",
            }
        );
    }
    md
}

/// With per-case tuning (`[tune]`): how many cases tuning made feasible and successful, and
/// the winner at tuned values (the best successful case by the objective) with its values.
fn tune_section(c: &Ctx, md: &mut String, robust: bool) {
    let (Ok(feasible), Ok(evals)) = (c.table.f64(TUNE_FEASIBLE), c.table.f64(TUNE_EVALUATIONS))
    else {
        return;
    };
    let tuned: Vec<usize> = (0..c.table.n_rows())
        .filter(|&r| feasible[r].is_finite())
        .collect();
    let met = tuned.iter().filter(|&&r| feasible[r] == 1.0).count();
    let total: f64 = tuned.iter().map(|&r| evals[r]).sum();
    let _ = writeln!(
        md,
        "## Per-design tuning
"
    );
    let _ =
        writeln!(
        md,
        "Every case was tuned before it was scored (`[tune]`: its own design and axis values), \
         then scored at its tuned values: {} cases tuned, {} of them to a point meeting every \
         tuning constraint, {:.0} evaluations per case on average; **{} of {} cases are not \
         successful at their tuned values** ({}).\n",
        tuned.len(),
        met,
        if tuned.is_empty() { 0.0 } else { total / tuned.len() as f64 },
        c.table.n_rows() - c.ok_rows.len(),
        c.table.n_rows(),
        left_out_text(c)
    );
    let (Some(o), Some((best, _))) = (&c.sel.objective, c.sel.extremes(c.table)) else {
        return;
    };
    let values: Vec<String> = c
        .table
        .columns
        .iter()
        .filter(|col| col.name.starts_with(TUNED_PREFIX))
        .map(|col| {
            format!(
                "`{}` = {}",
                &col.name[TUNED_PREFIX.len()..],
                cell_text(c.table, &col.name, best)
            )
        })
        .collect();
    let axes: Vec<String> = c
        .axes
        .iter()
        .map(|a| format!("`{a}` = {}", cell_text(c.table, a, best)))
        .collect();
    let _ = writeln!(
        md,
        "**{}** by `{o}`: case #{} ({}), `{o}` = {}, tuned {}.\n",
        if robust {
            "Best in the nominal world at tuned values (the verdict above is over the worlds)"
        } else {
            "Winner at tuned values"
        },
        c.ids[best],
        axes.join(", "),
        cell_text(c.table, o, best),
        values.join(", ")
    );
}

/// The layouts × single faults table ([`fault_table`]) of the successful cases, best objective
/// first (at most 40 rows).
fn fault_section(c: &Ctx, md: &mut String) {
    let Some(o) = &c.sel.objective else { return };
    let Ok(v) = c.table.f64(o) else { return };
    let sign = if c.sel.goal(o) == "max" { -1.0 } else { 1.0 };
    let key = |r: usize| sign * c.sel.ranked(o, v[r]);
    let mut ranked = c.ok_rows.clone();
    ranked.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    ranked.truncate(40);
    if let Some(t) = fault_table(c.table, &ranked, &c.ids, o) {
        md.push_str(&t);
    }
}

/// The best case by each metric (design columns aside).
fn best_section(c: &Ctx, md: &mut String) {
    let _ = writeln!(md, "## Best case by each metric\n");
    let _ = writeln!(
        md,
        "Among the {} successful cases ({}); signed metrics by magnitude (`min abs`).\n",
        c.ok_rows.len(),
        left_out_text(c)
    );
    let mut t = c.table(&["metric", "goal", "case", "value"]);
    let shown = c.sel.metrics.iter().filter(|m| {
        !m.starts_with("design_")
            && *m != SUCCESS
            && !m.starts_with(TUNED_PREFIX)
            && *m != TUNE_EVALUATIONS
            && *m != TUNE_FEASIBLE
            && !m.starts_with(FAULT_PREFIX)
    });
    for metric in shown {
        let goal = c.sel.goal(metric);
        let best = c.sel.best_row(c.table, metric, false);
        let (case, value) = match best {
            Some(r) => (format!("#{}", c.ids[r]), cell_text(c.table, metric, r)),
            None => ("–".into(), "–".into()),
        };
        c.row(
            &mut t,
            vec![format!("`{metric}`"), goal.into(), case, value],
            best,
        );
    }
    md.push_str(&t.finish());
}

/// The median of `v` over `rows` (finite values; NaN without any): effect tables use medians,
/// so that a few cost blow-ups of unsuccessful or fragile designs do not make the column.
fn median(v: &[f64], rows: &[usize]) -> f64 {
    let mut x: Vec<f64> = rows
        .iter()
        .map(|&r| v[r])
        .filter(|x| x.is_finite())
        .collect();
    if x.is_empty() {
        return f64::NAN;
    }
    x.sort_by(f64::total_cmp);
    crate::stats::describe::quantile_sorted(&x, 0.5)
}

/// Main effects: per axis value, how many cases ran, succeeded and (over worlds) are ranked,
/// and the median of each key metric over the successful ones and over all that ran.
fn effects_section(c: &Ctx, md: &mut String) {
    if c.axes.is_empty() || c.ok_rows.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Effect of each axis\n\nPer axis value: the cases that ran (`ok` or \
         `unsuccessful`), how many of them succeeded (and, in a study over worlds, how many are \
         ranked) and their success rate, the **median** `success_margin` of all that ran (signed \
         distance to the success bounds: < 0 missed, by that fraction of the bound), and the \
         **median** of each key metric over the successful ones (`ok`) beside its median over \
         all that ran (`all`): medians, not means, so that the cost blow-ups of a few failing \
         designs do not decide a column; unsuccessful cases are information in a sensitivity \
         study.\n"
    );
    let ran = c.ran_rows();
    let margin = c.table.f64(SUCCESS_MARGIN).ok();
    // Metrics constant over the cases that ran say nothing per axis value: left out (named).
    let varies = |k: &str| {
        c.table.f64(k).is_ok_and(|v| {
            let xs: Vec<f64> = ran
                .iter()
                .map(|&r| v[r])
                .filter(|x| x.is_finite())
                .collect();
            xs.iter().any(|x| *x != xs[0])
        })
    };
    let (keys, constant): (Vec<&String>, Vec<&String>) = c.key.iter().partition(|k| varies(k));
    let keys: Vec<&String> = keys.into_iter().take(6).collect();
    if !constant.is_empty() {
        let names: Vec<String> = constant.iter().map(|k| format!("`{k}`")).collect();
        let _ = writeln!(
            md,
            "Left out as constant over the cases that ran: {}.\n",
            names.join(", ")
        );
    }
    for a in &c.axes {
        let _ = writeln!(md, "### `{a}`\n");
        let mut header: Vec<String> = ["value", "cases", "successful", "success rate"]
            .into_iter()
            .map(String::from)
            .collect();
        let ranked = super::plots_ranked::ranked_mask(c.table);
        if ranked.is_some() {
            header.insert(3, "ranked".into());
        }
        if margin.is_some() {
            header.push(format!("`{SUCCESS_MARGIN}` median (all)"));
        }
        for k in &keys {
            header.push(format!("`{k}` median (ok)"));
            header.push(format!("`{k}` median (all)"));
        }
        let mut t = MarkdownTable::new(header);
        for (label, _, rows) in levels(c.table, a, &ran) {
            let ok: Vec<usize> = rows
                .iter()
                .copied()
                .filter(|r| c.ok_rows.binary_search(r).is_ok())
                .collect();
            let mut row = vec![
                label.replace('|', "\\|"),
                rows.len().to_string(),
                ok.len().to_string(),
                format!(
                    "{:.0} %",
                    100.0 * ok.len() as f64 / rows.len().max(1) as f64
                ),
            ];
            if let Some(m) = &ranked {
                row.insert(3, rows.iter().filter(|&&r| m[r]).count().to_string());
            }
            if let Some(m) = margin {
                row.push(fmt_short(median(m, &rows)));
            }
            for k in &keys {
                let col = c.table.f64(k).ok();
                row.push(fmt_short(col.map_or(f64::NAN, |v| median(v, &ok))));
                row.push(fmt_short(col.map_or(f64::NAN, |v| median(v, &rows))));
            }
            t.row(row);
        }
        let _ = writeln!(md, "{}", t.finish());
    }
}

/// The Pareto-optimal successful cases (at most 50 listed).
fn pareto_section(c: &Ctx, f: &Front, md: &mut String) {
    let (x, y) = (f.x, f.y);
    let _ = writeln!(md, "## Pareto-optimal cases: `{x}` vs `{y}`\n");
    let _ = writeln!(
        md,
        "{} non-dominated of {} successful cases with both metrics ({}; `{x}`: {}, `{y}`: {}).\n",
        f.front.len(),
        f.rows.len(),
        left_out_text(c),
        c.sel.goal(x),
        c.sel.goal(y)
    );
    let mut t = c.table(&["case", x, y]);
    for &k in f.front.iter().take(50) {
        let r = f.rows[k];
        let first = vec![
            format!("#{}", c.ids[r]),
            fmt_short(f.xs[r]),
            fmt_short(f.ys[r]),
        ];
        c.row(&mut t, first, Some(r));
    }
    md.push_str(&t.finish());
}

/// The cases left out of the ranking: counts per status and missed criterion, then the
/// first 100 with the criterion they missed and the reason.
fn left_out_section(c: &Ctx, md: &mut String) {
    let _ = writeln!(md, "## Cases left out\n");
    if c.left_out.is_empty() {
        let _ = writeln!(md, "None: every case succeeded.");
        return;
    }
    let _ = writeln!(
        md,
        "Unsuccessful cases ran but missed the `[success]` criterion named (the first one \
         missed); failed cases stopped early (`no_failure`); skipped cases never ran.\n"
    );
    let mut t = MarkdownTable::new(["status", "criterion missed", "cases"]);
    for ((s, k), n) in left_out_counts(c) {
        t.row([s.to_string(), k.unwrap_or("–").to_string(), n.to_string()]);
    }
    let _ = writeln!(md, "{}", t.finish());
    let reasons = c.table.str(REASON).unwrap_or(&[]);
    let mut t = c.table(&["case", "status", "criterion missed", "reason"]);
    for &(i, s, k) in c.left_out.iter().take(100) {
        let first = vec![
            format!("#{}", c.ids[i]),
            s.to_string(),
            k.unwrap_or("–").to_string(),
            detail(s, reasons.get(i).map_or("", String::as_str)).replace('|', "\\|"),
        ];
        c.row(&mut t, first, Some(i));
    }
    md.push_str(&t.finish());
    if c.left_out.len() > 100 {
        let _ = writeln!(md, "\n({} more; see cases.csv)", c.left_out.len() - 100);
    }
}

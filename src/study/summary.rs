//! The sweep report: `summary.md` and the SVG plots under `plots/` ([`super::plots`]),
//! generated from the final case table and the manifest only (so `usm-study report DIR` can
//! regenerate them).
//!
//! `summary.md`: counts, the best case by each metric, the main effects of each axis (mean of
//! the key metrics per axis value; numeric axes with many values binned), the Pareto-optimal
//! cases of the trade-off (energy vs singularity exposure by default), failures.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::manifest::Manifest;
use super::plots::{axis_plots, heatmaps, pareto_plot, timeseries_plot};
use super::records::{CaseStatus, CASE_ID, REASON, STATUS};
use super::schema::DoeKind;
use super::selection::{cell_text, levels, mean, ok_rows, Front, Selection};
use crate::report::{fmt_short, MarkdownTable, Table};

/// What every section of the summary reads.
struct Ctx<'a> {
    table: &'a Table,
    sel: Selection,
    ids: Vec<i64>,
    ok_rows: Vec<usize>,
    axes: Vec<&'a str>,
    key: Vec<String>,
}

impl Ctx<'_> {
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
        axes: m.axes.iter().map(|a| a.name.as_str()).collect(),
        key,
    };
    let mut md = header_section(&c, m);
    best_section(&c, &mut md);
    effects_section(&c, &mut md);
    if let Some(f) = c.sel.front(table, &c.ok_rows) {
        pareto_section(&c, &f, &mut md);
        pareto_plot(table, &c.axes, &f, &plots, &mut warnings);
        let _ = writeln!(md);
    }
    failures_section(&c, &mut md);
    if let Err(e) = crate::report::atomic_write(&dir.join("summary.md"), md.as_bytes()) {
        warnings.push(e.to_string());
    }
    axis_plots(table, &c.axes, &c.key, &c.ok_rows, &plots, &mut warnings);
    if m.doe == DoeKind::Grid {
        if let Some(o) = &c.sel.objective {
            heatmaps(table, &c.axes, o, &c.ok_rows, &plots, &mut warnings);
        }
    }
    timeseries_plot(dir, &plots, &mut warnings);
    warnings
}

/// Title, description, counts and the objective.
fn header_section(c: &Ctx, m: &Manifest) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Sweep `{}`\n", m.study_name);
    if !m.description.is_empty() {
        let _ = writeln!(md, "{}\n", m.description.trim());
    }
    let _ = writeln!(
        md,
        "Mode `{}`{}, design of experiments `{}`, seed {}, {} of {} cases in this output: \
         **{} ok, {} failed, {} skipped**. Study hash `{}`, usm-study {}.\n",
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
        m.cases.failed,
        m.cases.skipped,
        &m.study_hash[..16.min(m.study_hash.len())],
        m.tool_version
    );
    if let Some(o) = &c.sel.objective {
        let _ = writeln!(
            md,
            "Objective (best/worst case): `{o}` ({}).\n",
            if c.sel.maximise.contains(o) {
                "larger is better"
            } else {
                "smaller is better"
            }
        );
    }
    md
}

/// The best case by each metric (design columns aside).
fn best_section(c: &Ctx, md: &mut String) {
    let _ = writeln!(md, "## Best case by each metric\n");
    let mut t = c.table(&["metric", "goal", "case", "value"]);
    for metric in c.sel.metrics.iter().filter(|m| !m.starts_with("design_")) {
        let goal = if c.sel.maximise.contains(metric) {
            "max"
        } else {
            "min"
        };
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

/// Main effects: the mean of each key metric at each level of each axis.
fn effects_section(c: &Ctx, md: &mut String) {
    if c.axes.is_empty() || c.ok_rows.is_empty() {
        return;
    }
    let _ = writeln!(md, "\n## Effect of each axis\n\nMean of each key metric over the `ok` cases at each axis value.\n");
    for a in &c.axes {
        let _ = writeln!(md, "### `{a}`\n");
        let header = ["value", "cases"]
            .into_iter()
            .chain(c.key.iter().map(String::as_str));
        let mut t = MarkdownTable::new(header);
        for (label, _, rows) in levels(c.table, a, &c.ok_rows) {
            let means = c
                .key
                .iter()
                .map(|k| fmt_short(c.table.f64(k).map(|v| mean(v, &rows)).unwrap_or(f64::NAN)));
            t.row(
                [label.replace('|', "\\|"), rows.len().to_string()]
                    .into_iter()
                    .chain(means),
            );
        }
        let _ = writeln!(md, "{}", t.finish());
    }
}

/// The Pareto-optimal cases (at most 50 listed).
fn pareto_section(c: &Ctx, f: &Front, md: &mut String) {
    let (x, y) = (f.x, f.y);
    let _ = writeln!(md, "## Pareto-optimal cases: `{x}` vs `{y}`\n");
    let _ = writeln!(
        md,
        "{} non-dominated of {} `ok` cases.\n",
        f.front.len(),
        f.rows.len()
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

/// Failed and skipped cases: grouped by reason, then the first 100.
fn failures_section(c: &Ctx, md: &mut String) {
    let status = c.table.str(STATUS).unwrap_or(&[]);
    let bad: Vec<usize> = (0..c.table.n_rows())
        .filter(|&i| CaseStatus::parse(&status[i]) != Some(CaseStatus::Ok))
        .collect();
    let _ = writeln!(md, "## Failed and skipped cases\n");
    if bad.is_empty() {
        let _ = writeln!(md, "None.");
        return;
    }
    let reasons = c.table.str(REASON).unwrap_or(&[]);
    let mut groups: BTreeMap<(&str, &str), usize> = BTreeMap::new();
    for &i in &bad {
        *groups
            .entry((status[i].as_str(), reasons[i].as_str()))
            .or_default() += 1;
    }
    let mut t = MarkdownTable::new(["status", "cases", "reason"]);
    for ((s, r), n) in &groups {
        t.row([s.to_string(), n.to_string(), r.replace('|', "\\|")]);
    }
    let _ = writeln!(md, "{}", t.finish());
    let mut t = MarkdownTable::new(["case", "status", "reason"]);
    for &i in bad.iter().take(100) {
        let id = format!("#{}", c.ids[i]);
        t.row([id, status[i].clone(), reasons[i].replace('|', "\\|")]);
    }
    md.push_str(&t.finish());
    if bad.len() > 100 {
        let _ = writeln!(md, "\n({} more; see cases.csv)", bad.len() - 100);
    }
}

//! The sweep report: `summary.md` and SVG plots under `plots/`, generated from the final case
//! table and the manifest only (so `usm-study report DIR` can regenerate them).
//!
//! - `summary.md`: counts, the best case by each metric, the main effects of each axis (mean
//!   of the key metrics per axis value; numeric axes with many values binned), the Pareto-
//!   optimal cases of the trade-off (energy vs singularity exposure by default), failures.
//! - `plots/axis_<axis>.svg`: each key metric against the axis (`ok` cases).
//! - `plots/heatmap_<a>__<b>.svg`: mean objective per cell for every pair of grid axes.
//! - `plots/pareto.svg`: the trade-off with the non-dominated cases labelled `#id`.
//! - `plots/timeseries.svg`: best and worst case trajectories (dynamic modes, when
//!   `trajectory_best.csv` / `trajectory_worst.csv` exist).

use std::collections::{BTreeMap, HashSet};
use std::fmt::Write as _;
use std::path::Path;

use super::engine::Manifest;
use crate::report::{
    heatmap, pareto_front, read_csv, scatter_labelled, ColourScale, ColumnData, ColumnKind, Figure,
    LabelledPoint, Panel, PanelKind, Series, Table,
};

const FIXED: [&str; 4] = ["case_id", "hash", "status", "reason"];

/// Most points drawn per scatter panel (a deterministic stride through the rows beyond it),
/// so plots of 100 000-case sweeps stay small.
pub const MAX_PLOT_POINTS: usize = 4000;

/// Every `k`-th row so that at most [`MAX_PLOT_POINTS`] remain.
fn thin(rows: &[usize]) -> Vec<usize> {
    let k = rows.len().div_ceil(MAX_PLOT_POINTS).max(1);
    rows.iter().copied().step_by(k).collect()
}

/// Which metrics the report looks at and in which direction.
pub struct Selection {
    /// Every metric column (f64, not an axis).
    pub metrics: Vec<String>,
    /// Metrics where larger is better.
    pub maximise: HashSet<String>,
    /// Objective for best/worst.
    pub objective: Option<String>,
    /// Pareto trade-off `(x, y)`.
    pub pareto: Option<(String, String)>,
}

impl Selection {
    /// Resolve the settings of `manifest` against the columns of `table`.
    pub fn new(table: &Table, manifest: &Manifest) -> Self {
        let axes: HashSet<&str> = manifest.axes.iter().map(|a| a.name.as_str()).collect();
        let metrics: Vec<String> = table
            .columns
            .iter()
            .filter(|c| c.data.kind() == ColumnKind::F64)
            .map(|c| c.name.clone())
            .filter(|n| !FIXED.contains(&n.as_str()) && !axes.contains(n.as_str()))
            .collect();
        let has = |n: &str| metrics.iter().any(|m| m == n);
        let mut maximise: HashSet<String> = manifest.report.maximise.iter().cloned().collect();
        for m in &metrics {
            // Larger is better for conditioning (σ_min) and for run outcomes.
            if m.starts_with("tcm_sigma_min")
                || m == "tcm_straight_sigma_min"
                || m.starts_with("sigma_min")
                || matches!(
                    m.as_str(),
                    "completed" | "converged" | "segments_reached" | "simulated_time"
                )
            {
                maximise.insert(m.clone());
            }
        }
        let energy = metrics.iter().find(|m| m.contains("energy")).cloned();
        let objective = manifest
            .report
            .objective
            .clone()
            .filter(|o| has(o))
            .or_else(|| energy.clone())
            .or_else(|| has("tcm_singular_fraction").then(|| "tcm_singular_fraction".to_string()))
            .or_else(|| metrics.first().cloned());
        let pareto = match &manifest.report.pareto {
            Some([x, y]) if has(x) && has(y) => Some((x.clone(), y.clone())),
            _ => {
                let x =
                    energy.or_else(|| has("design_thrusters").then(|| "design_thrusters".into()));
                let y = metrics
                    .iter()
                    .find(|m| m.contains("singular") && !m.starts_with("tcm_"))
                    .cloned()
                    .or_else(|| {
                        has("tcm_singular_fraction").then(|| "tcm_singular_fraction".into())
                    });
                x.zip(y)
            }
        };
        Selection {
            metrics,
            maximise,
            objective,
            pareto,
        }
    }

    fn better(&self, metric: &str, a: f64, b: f64) -> bool {
        if self.maximise.contains(metric) {
            a > b
        } else {
            a < b
        }
    }

    /// Row of the best value of `metric` among `ok` rows (first on ties).
    fn best_row(&self, table: &Table, metric: &str, worst: bool) -> Option<usize> {
        let v = table.f64(metric).ok()?;
        let ok = table.str("status").ok()?;
        let mut best: Option<usize> = None;
        for i in 0..v.len() {
            if ok[i] != "ok" || !v[i].is_finite() {
                continue;
            }
            let replace = match best {
                None => true,
                Some(b) => {
                    if worst {
                        self.better(metric, v[b], v[i])
                    } else {
                        self.better(metric, v[i], v[b])
                    }
                }
            };
            if replace {
                best = Some(i);
            }
        }
        best
    }

    /// `(best, worst)` rows by the objective.
    pub fn extremes(&self, table: &Table) -> Option<(usize, usize)> {
        let o = self.objective.as_ref()?;
        Some((
            self.best_row(table, o, false)?,
            self.best_row(table, o, true)?,
        ))
    }

    fn key_metrics(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        let mut push = |m: &String| {
            if !out.contains(m) && out.len() < 10 {
                out.push(m.clone());
            }
        };
        if let Some(o) = &self.objective {
            push(o);
        }
        if let Some((x, y)) = &self.pareto {
            push(x);
            push(y);
        }
        for m in &self.metrics {
            if !m.starts_with("design_") && !m.starts_with("tcm_lost_") {
                push(m);
            }
        }
        out
    }
}

fn fmt(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else if x == 0.0 || (x.abs() >= 1e-3 && x.abs() < 1e5) {
        format!("{x:.4}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.3e}")
    }
}

fn cell_text(table: &Table, col: &str, row: usize) -> String {
    match table.column(col).map(|c| &c.data) {
        Some(ColumnData::F64(v)) => fmt(v[row]),
        Some(ColumnData::I64(v)) => v[row].to_string(),
        Some(ColumnData::Str(v)) => v[row].replace('|', "\\|"),
        Some(ColumnData::Bool(v)) => v[row].to_string(),
        None => String::new(),
    }
}

fn sanitise(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The levels of an axis over `rows`: `(label, x position, rows)`. Numeric axes with more than
/// 12 distinct values are binned into 6 equal-count bins.
fn levels(table: &Table, axis: &str, rows: &[usize]) -> Vec<(String, f64, Vec<usize>)> {
    match table.column(axis).map(|c| &c.data) {
        Some(ColumnData::F64(v)) => {
            let mut distinct: Vec<f64> = rows
                .iter()
                .map(|&r| v[r])
                .filter(|x| x.is_finite())
                .collect();
            distinct.sort_by(f64::total_cmp);
            distinct.dedup();
            if distinct.len() <= 12 {
                distinct
                    .iter()
                    .map(|&x| {
                        (
                            fmt(x),
                            x,
                            rows.iter().copied().filter(|&r| v[r] == x).collect(),
                        )
                    })
                    .collect()
            } else {
                let mut sorted: Vec<usize> =
                    rows.iter().copied().filter(|&r| v[r].is_finite()).collect();
                sorted.sort_by(|&a, &b| v[a].total_cmp(&v[b]).then(a.cmp(&b)));
                let k = 6;
                (0..k)
                    .filter_map(|b| {
                        let lo = b * sorted.len() / k;
                        let hi = (b + 1) * sorted.len() / k;
                        let rs: Vec<usize> = sorted[lo..hi].to_vec();
                        let (a, z) = (v[*rs.first()?], v[*rs.last()?]);
                        let mut rs = rs;
                        rs.sort_unstable();
                        Some((format!("[{}, {}]", fmt(a), fmt(z)), 0.5 * (a + z), rs))
                    })
                    .collect()
            }
        }
        Some(ColumnData::Str(v)) => {
            let mut order: Vec<&str> = Vec::new();
            for &r in rows {
                if !order.contains(&v[r].as_str()) {
                    order.push(&v[r]);
                }
            }
            order
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    (
                        s.to_string(),
                        i as f64,
                        rows.iter().copied().filter(|&r| v[r] == *s).collect(),
                    )
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

fn mean(v: &[f64], rows: &[usize]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for &r in rows {
        if v[r].is_finite() {
            s += v[r];
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

/// Write `summary.md` and the plots into `dir`; returns non-fatal problems.
pub fn write_report(dir: &Path, table: &Table, m: &Manifest) -> Vec<String> {
    let mut warnings = Vec::new();
    let sel = Selection::new(table, m);
    let plots = dir.join("plots");
    if let Err(e) = std::fs::create_dir_all(&plots) {
        warnings.push(format!("{}: {e}", plots.display()));
        return warnings;
    }
    let n = table.n_rows();
    let status = table.str("status").map(|s| s.to_vec()).unwrap_or_default();
    let ids = table.i64("case_id").map(|s| s.to_vec()).unwrap_or_default();
    let ok_rows: Vec<usize> = (0..n)
        .filter(|&i| status.get(i).is_some_and(|s| s == "ok"))
        .collect();
    let axes: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    let key = sel.key_metrics();
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
    if let Some(o) = &sel.objective {
        let _ = writeln!(
            md,
            "Objective (best/worst case): `{o}` ({}).\n",
            if sel.maximise.contains(o) {
                "larger is better"
            } else {
                "smaller is better"
            }
        );
    }

    // Best case by each metric.
    let _ = writeln!(md, "## Best case by each metric\n");
    let mut header = "| metric | goal | case | value |".to_string();
    let mut rule = "|---|---|---|---|".to_string();
    for a in &axes {
        let _ = write!(header, " {a} |");
        rule.push_str("---|");
    }
    let _ = writeln!(md, "{header}\n{rule}");
    for metric in sel.metrics.iter().filter(|m| !m.starts_with("design_")) {
        let goal = if sel.maximise.contains(metric) {
            "max"
        } else {
            "min"
        };
        match sel.best_row(table, metric, false) {
            Some(r) => {
                let mut line = format!(
                    "| `{metric}` | {goal} | #{} | {} |",
                    ids[r],
                    cell_text(table, metric, r)
                );
                for a in &axes {
                    let _ = write!(line, " {} |", cell_text(table, a, r));
                }
                let _ = writeln!(md, "{line}");
            }
            None => {
                let _ = writeln!(
                    md,
                    "| `{metric}` | {goal} | – | – |{}",
                    " – |".repeat(axes.len())
                );
            }
        }
    }

    // Main effects.
    if !axes.is_empty() && !ok_rows.is_empty() {
        let _ = writeln!(md, "\n## Effect of each axis\n\nMean of each key metric over the `ok` cases at each axis value.\n");
        for a in &axes {
            let _ = writeln!(md, "### `{a}`\n");
            let mut h = "| value | cases |".to_string();
            let mut r = "|---|---|".to_string();
            for k in &key {
                let _ = write!(h, " {k} |");
                r.push_str("---|");
            }
            let _ = writeln!(md, "{h}\n{r}");
            for (label, _, rows) in levels(table, a, &ok_rows) {
                let mut line = format!("| {} | {} |", label.replace('|', "\\|"), rows.len());
                for k in &key {
                    let v = table.f64(k).map(|v| mean(v, &rows)).unwrap_or(f64::NAN);
                    let _ = write!(line, " {} |", fmt(v));
                }
                let _ = writeln!(md, "{line}");
            }
            let _ = writeln!(md);
        }
    }

    // Pareto front.
    if let Some((x, y)) = &sel.pareto {
        let (xs, ys) = (table.f64(x).unwrap_or(&[]), table.f64(y).unwrap_or(&[]));
        let sign = |mname: &str| {
            if sel.maximise.contains(mname) {
                -1.0
            } else {
                1.0
            }
        };
        let rows: Vec<usize> = ok_rows
            .iter()
            .copied()
            .filter(|&r| xs[r].is_finite() && ys[r].is_finite())
            .collect();
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .map(|&r| (sign(x) * xs[r], sign(y) * ys[r]))
            .collect();
        let front = pareto_front(&pts);
        let _ = writeln!(md, "## Pareto-optimal cases: `{x}` vs `{y}`\n");
        let _ = writeln!(
            md,
            "{} non-dominated of {} `ok` cases.\n",
            front.len(),
            rows.len()
        );
        let mut h = format!("| case | {x} | {y} |");
        let mut rr = "|---|---|---|".to_string();
        for a in &axes {
            let _ = write!(h, " {a} |");
            rr.push_str("---|");
        }
        let _ = writeln!(md, "{h}\n{rr}");
        for &f in front.iter().take(50) {
            let r = rows[f];
            let mut line = format!("| #{} | {} | {} |", ids[r], fmt(xs[r]), fmt(ys[r]));
            for a in &axes {
                let _ = write!(line, " {} |", cell_text(table, a, r));
            }
            let _ = writeln!(md, "{line}");
        }
        // Plot a thinned set of rows plus every front row.
        let mut shown: Vec<usize> = thin(&(0..rows.len()).collect::<Vec<_>>());
        shown.extend(front.iter().copied());
        shown.sort_unstable();
        shown.dedup();
        let highlight: Vec<usize> = front
            .iter()
            .filter_map(|f| shown.binary_search(f).ok())
            .collect();
        let points: Vec<LabelledPoint> = shown
            .iter()
            .map(|&k| {
                let r = rows[k];
                LabelledPoint {
                    x: xs[r],
                    y: ys[r],
                    label: format!("#{}", ids[r]),
                }
            })
            .collect();
        match scatter_labelled(
            &points,
            &highlight,
            &format!("Pareto front: {x} vs {y}"),
            x,
            y,
        ) {
            Ok(fig) => {
                if let Err(e) = fig.write_svg(&plots.join("pareto.svg")) {
                    warnings.push(e.to_string());
                }
            }
            Err(e) => warnings.push(e.to_string()),
        }
        let _ = writeln!(md);
    }

    // Failures.
    let bad: Vec<usize> = (0..n).filter(|&i| status[i] != "ok").collect();
    let _ = writeln!(md, "## Failed and skipped cases\n");
    if bad.is_empty() {
        let _ = writeln!(md, "None.");
    } else {
        let reasons = table.str("reason").unwrap_or(&[]);
        let mut groups: BTreeMap<(&str, &str), usize> = BTreeMap::new();
        for &i in &bad {
            *groups
                .entry((status[i].as_str(), reasons[i].as_str()))
                .or_default() += 1;
        }
        let _ = writeln!(md, "| status | cases | reason |\n|---|---|---|");
        for ((s, r), c) in &groups {
            let _ = writeln!(md, "| {s} | {c} | {} |", r.replace('|', "\\|"));
        }
        let _ = writeln!(md, "\n| case | status | reason |\n|---|---|---|");
        for &i in bad.iter().take(100) {
            let _ = writeln!(
                md,
                "| #{} | {} | {} |",
                ids[i],
                status[i],
                reasons[i].replace('|', "\\|")
            );
        }
        if bad.len() > 100 {
            let _ = writeln!(md, "\n({} more; see cases.csv)", bad.len() - 100);
        }
    }
    if let Err(e) = crate::report::atomic_write(&dir.join("summary.md"), md.as_bytes()) {
        warnings.push(e.to_string());
    }

    // Metric against each axis.
    for a in &axes {
        let lv = levels(table, a, &ok_rows);
        let cat = matches!(
            table.column(a).map(|c| c.data.kind()),
            Some(ColumnKind::Str)
        );
        let xv: Vec<f64> = match table.column(a).map(|c| &c.data) {
            Some(ColumnData::F64(v)) => v.clone(),
            Some(ColumnData::Str(v)) => v
                .iter()
                .map(|s| lv.iter().find(|l| l.0 == *s).map_or(f64::NAN, |l| l.1))
                .collect(),
            _ => continue,
        };
        let x_label = if cat {
            let names: Vec<String> = lv.iter().map(|l| format!("{}={}", l.1, l.0)).collect();
            format!("{a} ({})", names.join(", "))
        } else {
            a.to_string()
        };
        let mut fig = Figure::new(format!("metrics against {a}"));
        let plotted = thin(&ok_rows);
        for k in &key {
            let Ok(yv) = table.f64(k) else { continue };
            let s = Series::new(
                "",
                plotted.iter().map(|&r| xv[r]).collect(),
                plotted.iter().map(|&r| yv[r]).collect(),
            );
            let mut p = Panel::new(k.clone(), x_label.clone(), k.clone())
                .kind(PanelKind::Scatter)
                .with_series(s);
            p.legend = false;
            fig.panels.push(p);
        }
        let cols = (fig.panels.len() as f64).sqrt().ceil().max(1.0) as u32;
        let rows = (fig.panels.len() as u32).div_ceil(cols).max(1);
        fig.size = (420 * cols, 320 * rows + 40);
        if let Err(e) = fig.write_svg(&plots.join(format!("axis_{}.svg", sanitise(a)))) {
            warnings.push(e.to_string());
        }
    }

    // Heat maps for every pair of grid axes (objective, mean per cell).
    if m.doe == "grid" {
        if let Some(o) = &sel.objective {
            if let Ok(z) = table.f64(o) {
                for i in 0..axes.len() {
                    for j in i + 1..axes.len() {
                        let (la, lb) = (
                            levels(table, axes[i], &ok_rows),
                            levels(table, axes[j], &ok_rows),
                        );
                        if la.len() < 2 || lb.len() < 2 {
                            continue;
                        }
                        let mut zz = Vec::with_capacity(la.len() * lb.len());
                        for (_, _, rb) in &lb {
                            let sb: HashSet<usize> = rb.iter().copied().collect();
                            for (_, _, ra) in &la {
                                let cell: Vec<usize> =
                                    ra.iter().copied().filter(|r| sb.contains(r)).collect();
                                zz.push(mean(z, &cell));
                            }
                        }
                        let label = |l: &[(String, f64, Vec<usize>)], a: &str| {
                            if matches!(
                                table.column(a).map(|c| c.data.kind()),
                                Some(ColumnKind::Str)
                            ) {
                                let names: Vec<String> =
                                    l.iter().map(|x| format!("{}={}", x.1, x.0)).collect();
                                format!("{a} ({})", names.join(", "))
                            } else {
                                a.to_string()
                            }
                        };
                        let h = heatmap(
                            la.iter().map(|l| l.1).collect(),
                            lb.iter().map(|l| l.1).collect(),
                            zz,
                            &format!("mean {o}"),
                            &label(&la, axes[i]),
                            &label(&lb, axes[j]),
                            o,
                            ColourScale::Viridis,
                        );
                        let path = plots.join(format!(
                            "heatmap_{}__{}.svg",
                            sanitise(axes[i]),
                            sanitise(axes[j])
                        ));
                        if let Err(e) = h.and_then(|h| h.write_svg(&path)) {
                            warnings.push(e.to_string());
                        }
                    }
                }
            }
        }
    }

    // Time series of the best and worst case.
    let trajs: Vec<(&str, Table)> = ["best", "worst"]
        .iter()
        .filter_map(|l| {
            let p = dir.join(format!("trajectory_{l}.csv"));
            p.is_file()
                .then(|| read_csv(&p).ok().map(|t| (*l, t)))
                .flatten()
        })
        .collect();
    if !trajs.is_empty() {
        if let Err(e) = timeseries(&trajs).write_svg(&plots.join("timeseries.svg")) {
            warnings.push(e.to_string());
        }
    }
    warnings
}

fn timeseries(trajs: &[(&str, Table)]) -> Figure {
    let t0 = &trajs[0].1;
    let f64_cols: Vec<&str> = t0
        .columns
        .iter()
        .filter(|c| c.data.kind() == ColumnKind::F64)
        .map(|c| c.name.as_str())
        .collect();
    let time = f64_cols
        .iter()
        .copied()
        .find(|n| *n == "t" || *n == "time" || n.starts_with("t_") || n.starts_with("time_"))
        .or(f64_cols.first().copied())
        .unwrap_or("t");
    let mut fig = Figure::new("best and worst case");
    for c in f64_cols.iter().filter(|c| **c != time).take(12) {
        let mut p = Panel::new(c.to_string(), time, c.to_string());
        for (k, (label, t)) in trajs.iter().enumerate() {
            if let (Ok(x), Ok(y)) = (t.f64(time), t.f64(c)) {
                p.series.push(
                    Series::new(label.to_string(), x.to_vec(), y.to_vec())
                        .colour(crate::report::Colour::Palette(k)),
                );
            }
        }
        fig.panels.push(p);
    }
    let cols = (fig.panels.len() as f64).sqrt().ceil().max(1.0) as u32;
    let rows = (fig.panels.len() as u32).div_ceil(cols).max(1);
    fig.size = (420 * cols, 300 * rows + 40);
    fig
}

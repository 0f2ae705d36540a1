//! The SVG plots of the sweep report under `plots/`:
//!
//! - `axis_<axis>.svg`: each key metric against the axis (`ok` cases).
//! - `heatmap_<a>__<b>.svg`: mean objective per cell for every pair of grid axes.
//! - `pareto.svg`: the trade-off with the non-dominated cases labelled `#id`.
//! - `timeseries.svg`: best and worst case trajectories (dynamic modes, when
//!   `trajectory_best.csv` / `trajectory_worst.csv` exist).
//!
//! Every function returns its problems as warnings; none is fatal.

use std::collections::HashSet;
use std::path::Path;

use super::records::Extreme;
use super::selection::{levels, mean, thin, Front};
use crate::report::file_stem_safe;
use crate::report::{
    heatmap, read_csv, scatter_labelled, ColourScale, ColumnData, ColumnKind, Figure,
    LabelledPoint, Panel, PanelKind, Series, Table,
};

/// An axis label: the axis name, with the numbering of its levels for a text axis.
fn axis_label(table: &Table, a: &str, lv: &[(String, f64, Vec<usize>)]) -> String {
    if matches!(
        table.column(a).map(|c| c.data.kind()),
        Some(ColumnKind::Str)
    ) {
        let names: Vec<String> = lv.iter().map(|l| format!("{}={}", l.1, l.0)).collect();
        format!("{a} ({})", names.join(", "))
    } else {
        a.to_string()
    }
}

/// `pareto.svg`: a thinned set of rows plus every front row, the front labelled.
pub(crate) fn pareto_plot(f: &Front, ids: &[i64], plots: &Path, warnings: &mut Vec<String>) {
    let mut shown: Vec<usize> = thin(&(0..f.rows.len()).collect::<Vec<_>>());
    shown.extend(f.front.iter().copied());
    shown.sort_unstable();
    shown.dedup();
    let highlight: Vec<usize> = f
        .front
        .iter()
        .filter_map(|k| shown.binary_search(k).ok())
        .collect();
    let points: Vec<LabelledPoint> = shown
        .iter()
        .map(|&k| {
            let r = f.rows[k];
            LabelledPoint {
                x: f.xs[r],
                y: f.ys[r],
                label: format!("#{}", ids[r]),
            }
        })
        .collect();
    match scatter_labelled(
        &points,
        &highlight,
        &format!("Pareto front: {} vs {}", f.x, f.y),
        f.x,
        f.y,
    ) {
        Ok(fig) => {
            if let Err(e) = fig.write_svg(&plots.join("pareto.svg")) {
                warnings.push(e.to_string());
            }
        }
        Err(e) => warnings.push(e.to_string()),
    }
}

/// `axis_<axis>.svg` for every axis: each key metric against the axis over the `ok` rows.
pub(crate) fn axis_plots(
    table: &Table,
    axes: &[&str],
    key: &[String],
    ok_rows: &[usize],
    plots: &Path,
    warnings: &mut Vec<String>,
) {
    for a in axes {
        let lv = levels(table, a, ok_rows);
        let xv: Vec<f64> = match table.column(a).map(|c| &c.data) {
            Some(ColumnData::F64(v)) => v.clone(),
            Some(ColumnData::Str(v)) => v
                .iter()
                .map(|s| lv.iter().find(|l| l.0 == *s).map_or(f64::NAN, |l| l.1))
                .collect(),
            _ => continue,
        };
        let x_label = axis_label(table, a, &lv);
        let mut fig = Figure::new(format!("metrics against {a}"));
        let plotted = thin(ok_rows);
        for k in key {
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
        if let Err(e) = fig.write_svg(&plots.join(format!("axis_{}.svg", file_stem_safe(a)))) {
            warnings.push(e.to_string());
        }
    }
}

/// `heatmap_<a>__<b>.svg` for every pair of axes with at least two levels each: the mean of
/// `objective` per cell over the `ok` rows.
pub(crate) fn heatmaps(
    table: &Table,
    axes: &[&str],
    objective: &str,
    ok_rows: &[usize],
    plots: &Path,
    warnings: &mut Vec<String>,
) {
    let Ok(z) = table.f64(objective) else {
        return;
    };
    for i in 0..axes.len() {
        for j in i + 1..axes.len() {
            let (la, lb) = (
                levels(table, axes[i], ok_rows),
                levels(table, axes[j], ok_rows),
            );
            if la.len() < 2 || lb.len() < 2 {
                continue;
            }
            let mut zz = Vec::with_capacity(la.len() * lb.len());
            for (_, _, rb) in &lb {
                let sb: HashSet<usize> = rb.iter().copied().collect();
                for (_, _, ra) in &la {
                    let cell: Vec<usize> = ra.iter().copied().filter(|r| sb.contains(r)).collect();
                    zz.push(mean(z, &cell));
                }
            }
            let h = heatmap(
                la.iter().map(|l| l.1).collect(),
                lb.iter().map(|l| l.1).collect(),
                zz,
                &format!("mean {objective}"),
                &axis_label(table, axes[i], &la),
                &axis_label(table, axes[j], &lb),
                objective,
                ColourScale::Viridis,
            );
            let path = plots.join(format!(
                "heatmap_{}__{}.svg",
                file_stem_safe(axes[i]),
                file_stem_safe(axes[j])
            ));
            if let Err(e) = h.and_then(|h| h.write_svg(&path)) {
                warnings.push(e.to_string());
            }
        }
    }
}

/// `timeseries.svg` from `trajectory_best.csv` / `trajectory_worst.csv` in `dir`, when
/// either exists.
pub(crate) fn timeseries_plot(dir: &Path, plots: &Path, warnings: &mut Vec<String>) {
    let trajs: Vec<(&str, Table)> = Extreme::BOTH
        .iter()
        .filter_map(|e| {
            let p = dir.join(e.trajectory_file());
            p.is_file()
                .then(|| read_csv(&p).ok().map(|t| (e.label(), t)))
                .flatten()
        })
        .collect();
    if !trajs.is_empty() {
        if let Err(e) = timeseries(&trajs).write_svg(&plots.join("timeseries.svg")) {
            warnings.push(e.to_string());
        }
    }
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

//! The SVG plots of the sweep report under `plots/`:
//!
//! - `axis_<axis>.svg`: each key metric against the axis (`ok` cases).
//! - `heatmap_<a>__<b>.svg`: mean objective per cell for every pair of grid axes.
//! - `pareto.svg`: the trade-off with the non-dominated cases labelled `#id`.
//! - `timeseries.svg`: best and worst case trajectories (dynamic modes, when
//!   `trajectory_best.csv` / `trajectory_worst.csv` exist).
//!
//! Every plot titles its axes in words with units ([`metric_title`]), names its series in the
//! legend, labels points with their design (axis values, [`case_name`]) without overlaps, and
//! draws unsuccessful cases ([`unsuccessful_rows`]) as a separate red series.
//!
//! Every function returns its problems as warnings; none is fatal.

use std::collections::HashSet;
use std::path::Path;

use super::records::{Extreme, CASE_ID, STATUS};
use super::selection::{levels, mean, thin, Front};
use crate::report::file_stem_safe;
use crate::report::{
    heatmap, read_csv, scatter_labelled, Colour, ColourScale, ColumnData, ColumnKind, Figure,
    LabelledPoint, Panel, PanelKind, Series, Table,
};

/// Units of metric and design columns, by name or by name suffix (docs/model.md §6 and the design
/// columns); unknown names get no unit.
const UNITS: [(&str, &str); 23] = [
    ("energy_per_metre", "J/m"),
    ("effort_sq", "N²·s"),
    ("effort_abs", "N·s"),
    ("joint_torque_peak", "N·m"),
    ("peak_thrust", "N"),
    ("design_length_m", "m"),
    ("design_mass_kg", "kg"),
    ("longitudinal_offset", "m"),
    ("link_length", "m"),
    ("thrust_limit", "N"),
    ("_deg", "°"),
    ("_energy", "J"),
    ("_energy_static", "J"),
    ("_time", "s"),
    ("_cross_track", "m"),
    ("cross_track_rms", "m"),
    ("overshoot", "m"),
    ("path_progress", "m"),
    ("position_error", "m"),
    ("duration", "s"),
    ("omega_n", "rad/s"),
    ("_fraction", "0–1"),
    ("singularity_exposure", "fraction of time, 0–1"),
];

/// A column name as an axis title: words instead of underscores and dots, and its unit in
/// brackets when known (`thruster_energy` → `thruster energy [J]`,
/// `design.longitudinal_offset` → `longitudinal offset [m]`).
pub fn metric_title(name: &str) -> String {
    // Suffix keys (`_energy`) match any name ending in them; whole names match exactly.
    let short = name.strip_prefix("design.").unwrap_or(name);
    let words = short
        .trim_end_matches("_m")
        .trim_end_matches("_kg")
        .replace(['_', '.'], " ");
    let unit = UNITS
        .iter()
        .find(|(key, _)| name == *key || name.ends_with(key))
        .map(|(_, u)| *u)
        .or_else(|| {
            // Singular values and condition numbers of the scaled T(q) (docs/model.md §6).
            (name.contains("sigma_min") || name.contains("kappa")).then_some("scaled, –")
        });
    match unit {
        Some(u) => format!("{words} [{u}]"),
        None => words,
    }
}

/// A case's design name: its axis values joined by `/` (e.g. `paper/5/0.06`).
pub fn case_name(table: &Table, axes: &[&str], row: usize) -> String {
    axes.iter()
        .map(|a| super::selection::cell_text(table, a, row).replace("\\|", "|"))
        .collect::<Vec<_>>()
        .join("/")
}

/// Whether each row is unsuccessful: its `status` is not `ok`, or its `success` column (when
/// the table has one: bool, 0/1 or `true`/`yes`) says no.
pub fn unsuccessful_rows(table: &Table) -> Vec<bool> {
    let status = table.str(STATUS).ok();
    let success = table.column("success").map(|c| &c.data);
    (0..table.n_rows())
        .map(|r| {
            let failed = status.is_some_and(|s| s[r] != "ok");
            let missed = success.is_some_and(|d| match d {
                ColumnData::Bool(v) => !v[r],
                ColumnData::F64(v) => !(v[r] != 0.0 && v[r].is_finite()),
                ColumnData::I64(v) => v[r] == 0,
                ColumnData::Str(v) => !matches!(
                    v[r].trim().to_ascii_lowercase().as_str(),
                    "true" | "1" | "yes" | "ok"
                ),
            });
            failed || missed
        })
        .collect()
}

/// The unsuccessful rows with finite `xs` and `ys`, as a red series (`None` when there are
/// none).
fn unsuccessful_series(bad: &[bool], xs: &[f64], ys: &[f64]) -> Option<Series> {
    let rows: Vec<usize> = (0..bad.len())
        .filter(|&r| bad[r] && xs[r].is_finite() && ys[r].is_finite())
        .collect();
    (!rows.is_empty()).then(|| {
        Series::new(
            "unsuccessful cases",
            rows.iter().map(|&r| xs[r]).collect(),
            rows.iter().map(|&r| ys[r]).collect(),
        )
        .colour(Colour::Alert)
        .kind(PanelKind::Scatter)
    })
}

/// An axis label: the axis name, with the numbering of its levels for a text axis.
fn axis_label(table: &Table, a: &str, lv: &[(String, f64, Vec<usize>)]) -> String {
    if matches!(
        table.column(a).map(|c| c.data.kind()),
        Some(ColumnKind::Str)
    ) {
        let names: Vec<String> = lv.iter().map(|l| format!("{}={}", l.1, l.0)).collect();
        format!("{} ({})", metric_title(a), names.join(", "))
    } else {
        metric_title(a)
    }
}

/// `pareto.svg`: a thinned set of rows plus every front row, the front labelled with case
/// number and design name, unsuccessful cases in red.
pub(crate) fn pareto_plot(
    table: &Table,
    axes: &[&str],
    f: &Front,
    plots: &Path,
    warnings: &mut Vec<String>,
) {
    let ids = table.i64(CASE_ID).unwrap_or(&[]);
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
                label: format!(
                    "#{} {}",
                    ids.get(r).copied().unwrap_or(r as i64),
                    case_name(table, axes, r)
                ),
            }
        })
        .collect();
    let fig = scatter_labelled(
        &points,
        &highlight,
        &format!(
            "Pareto front: {} vs {}",
            metric_title(f.x),
            metric_title(f.y)
        ),
        &metric_title(f.x),
        &metric_title(f.y),
    );
    let result = fig.and_then(|mut fig| {
        let p = &mut fig.panels[0];
        p.series[0].name = "successful cases".into();
        let short: Vec<&str> = axes
            .iter()
            .map(|a| a.rsplit('.').next().unwrap_or(a))
            .collect();
        p.series[2].name = format!("Pareto-optimal: #case {}", short.join("/"));
        if let Some(s) = unsuccessful_series(&unsuccessful_rows(table), f.xs, f.ys) {
            p.series.push(s);
        }
        fig.write_svg(&plots.join("pareto.svg"))
    });
    if let Err(e) = result {
        warnings.push(e.to_string());
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
        let mut fig = Figure::new(format!("key metrics against {}", metric_title(a)));
        let plotted = thin(ok_rows);
        let bad = unsuccessful_rows(table);
        for k in key {
            let Ok(yv) = table.f64(k) else { continue };
            let s = Series::new(
                "successful cases",
                plotted.iter().map(|&r| xv[r]).collect(),
                plotted.iter().map(|&r| yv[r]).collect(),
            );
            let mut p = Panel::new(metric_title(k), x_label.clone(), metric_title(k))
                .kind(PanelKind::Scatter)
                .with_series(s);
            match unsuccessful_series(&bad, &xv, yv) {
                Some(u) => p.series.push(u),
                None => p.legend = false,
            }
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
/// `objective` per cell over the `ok` rows (`rows.0`), or, when those do not fill two levels of
/// both axes, over every case that ran (`rows.1`, `ok` and unsuccessful; the title says so).
pub(crate) fn heatmaps(
    table: &Table,
    axes: &[&str],
    objective: &str,
    rows: (&[usize], &[usize]),
    plots: &Path,
    warnings: &mut Vec<String>,
) {
    let Ok(z) = table.f64(objective) else {
        return;
    };
    for i in 0..axes.len() {
        for j in i + 1..axes.len() {
            let grid = |r: &[usize]| (levels(table, axes[i], r), levels(table, axes[j], r));
            let (ok_a, ok_b) = grid(rows.0);
            let (la, lb, over) = if ok_a.len() >= 2 && ok_b.len() >= 2 {
                (ok_a, ok_b, "the successful cases".to_string())
            } else {
                let (a, b) = grid(rows.1);
                let n = rows.0.len();
                (
                    a,
                    b,
                    format!("all {} cases that ran ({n} successful)", rows.1.len()),
                )
            };
            // Fewer than two values of an axis among the cases that ran: no grid to draw
            // (`warnings` is for outputs that could not be written).
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
                &format!("mean {} over {over}", metric_title(objective)),
                &axis_label(table, axes[i], &la),
                &axis_label(table, axes[j], &lb),
                &metric_title(objective),
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
        let mut p = Panel::new(c.to_string(), format!("{time} [s]"), c.to_string());
        for (k, (label, t)) in trajs.iter().enumerate() {
            if let (Ok(x), Ok(y)) = (t.f64(time), t.f64(c)) {
                p.series.push(
                    Series::new(format!("{label} case"), x.to_vec(), y.to_vec())
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_titles_say_what_and_in_which_unit() {
        assert_eq!(metric_title("thruster_energy"), "thruster energy [J]");
        assert_eq!(metric_title("energy_per_metre"), "energy per metre [J/m]");
        assert_eq!(
            metric_title("design.longitudinal_offset"),
            "longitudinal offset [m]"
        );
        assert_eq!(metric_title("design_mass_kg"), "design mass [kg]");
        assert_eq!(
            metric_title("seg1_convergence_time"),
            "seg1 convergence time [s]"
        );
        assert_eq!(
            metric_title("singularity_exposure"),
            "singularity exposure [fraction of time, 0–1]"
        );
        assert_eq!(metric_title("design.links"), "links");
    }

    #[test]
    fn unsuccessful_rows_read_status_and_success_when_present() {
        let mut t = Table::default();
        let status = ["ok", "failed", "ok"].map(String::from).to_vec();
        t.push(STATUS, ColumnData::Str(status)).unwrap();
        assert_eq!(unsuccessful_rows(&t), [false, true, false]);
        t.push("success", ColumnData::F64(vec![1.0, 1.0, 0.0]))
            .unwrap();
        assert_eq!(unsuccessful_rows(&t), [false, true, true]);
    }
}

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

pub use super::plots_ranked::unsuccessful_rows;
use super::plots_ranked::{clip_to_ranked, ranked_mask, split_series, unsuccessful_series};
use super::selection::{levels, mean, thin, Front, Selection};
use crate::batch::records::{Extreme, CASE_ID};
use crate::report::file_stem_safe;
use crate::report::{
    fmt_short, heatmap, read_csv, scatter_labelled, ColourScale, ColumnData, ColumnKind, Figure,
    LabelledPoint, Panel, PanelKind, Scale, Series, Table,
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

/// A column name as an axis title: the name as in the tables, with its unit in brackets from
/// the data dictionary ([`crate::study::dictionary::unit_of`]; design axes from their key's unit)
/// when known (`mission_cost` → `mission_cost [J/m]`, `design.longitudinal_offset` →
/// `design.longitudinal_offset [m]`).
pub fn metric_title(name: &str) -> String {
    let unit = crate::study::dictionary::unit_of(name).or_else(|| {
        // Suffix keys (`_energy`) match any name ending in them; whole names match exactly.
        UNITS
            .iter()
            .find(|(key, _)| name == *key || name.ends_with(key))
            .map(|(_, u)| *u)
    });
    match unit {
        Some(u) => format!("{name} [{u}]"),
        None => name.to_string(),
    }
}

/// The scale of an axis over values `v` at `rows`: integers when every finite value is whole
/// (link counts, thruster numbers), plain numbers otherwise.
fn number_scale(v: &[f64], rows: &[usize]) -> Scale {
    let mut finite = rows
        .iter()
        .map(|&r| v[r])
        .filter(|x| x.is_finite())
        .peekable();
    if finite.peek().is_some() && finite.all(|x| x.fract() == 0.0 && x.abs() < 1e15) {
        Scale::Integer
    } else {
        Scale::Linear
    }
}

/// The scale of a metric's values at `rows`: log when all are positive and span 2–9 decades
/// (saturating designs at 10⁵ J/m; wider is a rounding "zero"), else [`number_scale`].
fn value_scale(v: &[f64], rows: &[usize]) -> Scale {
    let (lo, hi, all_positive) = rows
        .iter()
        .map(|&r| v[r])
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY, true), |(a, b, p), x| {
            (a.min(x), b.max(x), p && x > 0.0)
        });
    if all_positive && lo.is_finite() && hi >= 100.0 * lo && hi <= 1e9 * lo {
        Scale::Log
    } else {
        number_scale(v, rows)
    }
}

/// The value of `v` at `rows` when it is the same at every row (finite values within a
/// relative 1e-9, or no finite value at all: `NaN`); `None` when it varies.
fn constant_value(v: &[f64], rows: &[usize]) -> Option<f64> {
    let finite: Vec<f64> = rows
        .iter()
        .map(|&r| v[r])
        .filter(|x| x.is_finite())
        .collect();
    let (lo, hi) = finite
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if finite.is_empty() {
        Some(f64::NAN)
    } else {
        (hi - lo <= 1e-9 * lo.abs().max(hi.abs()).max(1e-300)).then_some(lo)
    }
}

/// A case's design name: its axis values joined by `/` (e.g. `paper/5/0.06`).
pub fn case_name(table: &Table, axes: &[&str], row: usize) -> String {
    axes.iter()
        .map(|a| super::selection::cell_text(table, a, row).replace("\\|", "|"))
        .collect::<Vec<_>>()
        .join("/")
}

/// The scale of axis `a` over its levels `lv`: the level names for a text axis, integers for
/// whole-numbered axes.
fn axis_scale(table: &Table, a: &str, lv: &[(String, f64, Vec<usize>)]) -> Scale {
    match table.column(a).map(|c| &c.data) {
        Some(ColumnData::Str(_)) => Scale::Categories(lv.iter().map(|l| l.0.clone()).collect()),
        Some(ColumnData::F64(v)) => {
            let rows: Vec<usize> = lv.iter().flat_map(|l| l.2.iter().copied()).collect();
            number_scale(v, &rows)
        }
        _ => Scale::Linear,
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
    let mask = ranked_mask(table);
    let unranked = |r: usize| mask.as_ref().is_some_and(|m| !m[r]);
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
                    "#{} {}{}",
                    ids.get(r).copied().unwrap_or(r as i64),
                    case_name(table, axes, r),
                    if unranked(r) { " (not ranked)" } else { "" }
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
        let drawn: Vec<usize> = (0..f.xs.len().min(f.ys.len())).collect();
        p.x_scale = value_scale(f.xs, &drawn);
        p.y_scale = value_scale(f.ys, &drawn);
        if let Some(s) = unsuccessful_series(&unsuccessful_rows(table), f.xs, f.ys) {
            p.series.push(s);
        }
        if let Some(m) = &mask {
            let rows: Vec<usize> = shown.iter().map(|&k| f.rows[k]).collect();
            p.series.splice(0..1, split_series(&rows, f.xs, f.ys, m));
            let r: Vec<usize> = f.rows.iter().copied().filter(|&r| m[r]).collect();
            let (x, y): (Vec<f64>, Vec<f64>) = r.iter().map(|&r| (f.xs[r], f.ys[r])).unzip();
            clip_to_ranked(p, &x, &y, true);
        }
        fig.write_svg_pdf(&plots.join("pareto.svg"))
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
    let all: Vec<usize> = (0..table.n_rows()).collect();
    let bad = unsuccessful_rows(table);
    let mask = ranked_mask(table);
    for a in axes {
        // Levels over every case, so that a text axis has the same categories in every plot.
        let lv = levels(table, a, &all);
        let xv: Vec<f64> = match table.column(a).map(|c| &c.data) {
            Some(ColumnData::F64(v)) => v.clone(),
            Some(ColumnData::Str(v)) => v
                .iter()
                .map(|s| lv.iter().find(|l| l.0 == *s).map_or(f64::NAN, |l| l.1))
                .collect(),
            _ => continue,
        };
        let x_scale = match table.column(a).map(|c| &c.data) {
            Some(ColumnData::F64(v)) => number_scale(v, &all),
            _ => axis_scale(table, a, &lv),
        };
        let mut fig = Figure::new(format!("key metrics against {}", metric_title(a)));
        let plotted = thin(ok_rows);
        let mut constant = Vec::new();
        for k in key {
            let Ok(yv) = table.f64(k) else { continue };
            if let Some(c) = constant_value(yv, &all) {
                constant.push(format!("{k} = {}", fmt_short(c)));
                continue;
            }
            let s = Series::new(
                "successful cases",
                plotted.iter().map(|&r| xv[r]).collect(),
                plotted.iter().map(|&r| yv[r]).collect(),
            );
            let mut p = Panel::new(k.as_str(), metric_title(a), metric_title(k))
                .kind(PanelKind::Scatter)
                .with_series(s);
            p.x_scale = x_scale.clone();
            p.y_scale = value_scale(yv, &all);
            if let Some(m) = &mask {
                p.series = split_series(&plotted, &xv, yv, m);
            }
            match unsuccessful_series(&bad, &xv, yv) {
                Some(u) => p.series.push(u),
                None => p.legend = mask.is_some(),
            }
            if let Some(m) = &mask {
                let (x, y): (Vec<f64>, Vec<f64>) = ok_rows
                    .iter()
                    .filter(|&&r| m[r])
                    .map(|&r| (xv[r], yv[r]))
                    .unzip();
                clip_to_ranked(&mut p, &x, &y, false);
            }
            fig.panels.push(p);
        }
        if !constant.is_empty() {
            fig.note = format!("Left out, the same in every case: {}", constant.join(", "));
        }
        fig.grid_layout(3, 320);
        if let Err(e) = fig.write_svg_pdf(&plots.join(format!("axis_{}.svg", file_stem_safe(a)))) {
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
    // Over the ranked designs by default (a study ranking over worlds), the others counted.
    let ranked: Option<Vec<usize>> =
        ranked_mask(table).map(|m| rows.0.iter().copied().filter(|&r| m[r]).collect());
    let (rows, what) = match &ranked {
        Some(r) => (
            (r.as_slice(), rows.1),
            format!(
                "the {} ranked designs ({} successful not ranked and {} unsuccessful left out)",
                r.len(),
                rows.0.len() - r.len(),
                rows.1.len() - rows.0.len()
            ),
        ),
        None => (rows, "the successful cases".to_string()),
    };
    for i in 0..axes.len() {
        for j in i + 1..axes.len() {
            let grid = |r: &[usize]| (levels(table, axes[i], r), levels(table, axes[j], r));
            let (ok_a, ok_b) = grid(rows.0);
            let (la, lb, over) = if ok_a.len() >= 2 && ok_b.len() >= 2 {
                (ok_a, ok_b, what.clone())
            } else {
                let (a, b) = grid(rows.1);
                let n = rows.0.len();
                (
                    a,
                    b,
                    format!(
                        "all {} cases that ran ({n} ranked or successful)",
                        rows.1.len()
                    ),
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
                &metric_title(axes[i]),
                &metric_title(axes[j]),
                &metric_title(objective),
                ColourScale::Viridis,
            )
            .map(|mut h| {
                h.x_scale = axis_scale(table, axes[i], &la);
                h.y_scale = axis_scale(table, axes[j], &lb);
                h
            });
            let path = plots.join(format!(
                "heatmap_{}__{}.svg",
                file_stem_safe(axes[i]),
                file_stem_safe(axes[j])
            ));
            if let Err(e) = h.and_then(|h| h.write_svg_pdf(&path)) {
                warnings.push(e.to_string());
            }
        }
    }
}

/// The legend names of the best and worst case (`best: case #44, mission_cost = 1.58`) by
/// the objective of `sel`, in [`Extreme::BOTH`]'s order; `best case` / `worst case` when the
/// table does not say.
pub(crate) fn extreme_names(table: &Table, sel: &Selection) -> [String; 2] {
    let ids = table.i64(CASE_ID).unwrap_or(&[]);
    let found = sel.objective.as_ref().zip(sel.extremes(table));
    let name = |e: Extreme, row: Option<usize>| match (found, row) {
        (Some((o, _)), Some(r)) => {
            let v = table.f64(o).map_or(f64::NAN, |v| v[r]);
            let id = ids.get(r).copied().unwrap_or(r as i64);
            let rk = match ranked_mask(table) {
                Some(m) if m[r] => " (ranked)",
                Some(_) => " (not ranked)",
                None => "",
            };
            format!("{}: case #{id}{rk}, {o} = {}", e.label(), fmt_short(v))
        }
        _ => format!("{} case", e.label()),
    };
    [
        name(Extreme::Best, found.map(|f| f.1 .0)),
        name(Extreme::Worst, found.map(|f| f.1 .1)),
    ]
}

/// `timeseries.svg` from `trajectory_best.csv` / `trajectory_worst.csv` in `dir`, when
/// either exists; `names` are their legend entries ([`extreme_names`]).
pub(crate) fn timeseries_plot(
    dir: &Path,
    names: &[String; 2],
    plots: &Path,
    warnings: &mut Vec<String>,
) {
    let trajs: Vec<(&str, Table)> = Extreme::BOTH
        .iter()
        .zip(names)
        .filter_map(|(e, name)| {
            let p = dir.join(e.trajectory_file());
            p.is_file()
                .then(|| read_csv(&p).ok().map(|t| (name.as_str(), t)))
                .flatten()
        })
        .collect();
    if !trajs.is_empty() {
        if let Err(e) = timeseries(&trajs).write_svg_pdf(&plots.join("timeseries.svg")) {
            warnings.push(e.to_string());
        }
    }
}

/// Channels (or `prefix_` families) drawn first in `timeseries.svg`, in this order.
const FIRST: [&str; 12] = [
    "cross_track",
    "heading_error",
    "surge_error",
    "ee_position_error",
    "ee_x",
    "ee_y",
    "ee_z",
    "base_yaw",
    "q_",
    "u_",
    "base_u",
    "tau_",
];

/// Whether a logged channel is flat: its finite values span at most 1e-5 (in its unit) plus
/// 1e-9 of their magnitude, so that numerical noise (a base heave of 3e-6 m in a planar
/// run) does not take a panel.
fn is_flat(v: &[f64]) -> bool {
    let (lo, hi) = v
        .iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    hi - lo <= 1e-5 + 1e-9 * lo.abs().max(hi.abs())
}

/// Most panels of `timeseries.svg`; further moving channels are named in the note.
const MAX_CHANNELS: usize = 12;

/// The figure of `timeseries.svg`: one panel per channel that moves in any of `trajs`
/// (`max − min` above 1e-9 of its magnitude), units from the dictionary; the flat channels
/// (and any beyond [`MAX_CHANNELS`]) are named in the note.
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
    let mut fig = Figure::new("best and worst case by the objective");
    let (mut flat, mut more) = (Vec::new(), Vec::new());
    let mut channels: Vec<&str> = f64_cols.iter().copied().filter(|c| *c != time).collect();
    // The tracking errors and the end effector first, the base's many states last.
    channels.sort_by_key(|c| {
        FIRST
            .iter()
            .position(|p| c == p || (p.ends_with('_') && c.starts_with(p)))
            .unwrap_or(FIRST.len())
    });
    for c in channels {
        let moves = trajs
            .iter()
            .any(|(_, t)| t.f64(c).is_ok_and(|v| !is_flat(v)));
        if !moves {
            flat.push(c);
            continue;
        }
        if fig.panels.len() == MAX_CHANNELS {
            more.push(c);
            continue;
        }
        let mut p = Panel::new(c, metric_title(time), metric_title(c));
        for (k, (label, t)) in trajs.iter().enumerate() {
            if let (Ok(x), Ok(y)) = (t.f64(time), t.f64(c)) {
                p.series.push(
                    Series::new(*label, x.to_vec(), y.to_vec())
                        .colour(crate::report::Colour::Palette(k)),
                );
            }
        }
        fig.panels.push(p);
    }
    let mut note = Vec::new();
    if !flat.is_empty() {
        note.push(format!(
            "Left out as flat (max − min ≈ 0): {}.",
            flat.join(", ")
        ));
    }
    if !more.is_empty() {
        note.push(format!(
            "Not drawn (the first {MAX_CHANNELS} moving channels are): {}.",
            more.join(", ")
        ));
    }
    fig.note = note.join(" ");
    fig.grid_layout(3, 300);
    fig
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::records::STATUS;

    #[test]
    fn metrics_spanning_decades_get_a_log_axis() {
        let all = [0, 1, 2];
        assert_eq!(value_scale(&[60.0, 70.0, 4.4e5], &all), Scale::Log);
        assert_eq!(value_scale(&[60.5, 70.0, 5000.0], &all), Scale::Linear);
        assert_eq!(value_scale(&[-1.5, 70.0, 4.4e5], &all), Scale::Linear);
        assert_eq!(value_scale(&[3.0, 4.0, 5.0], &all), Scale::Integer);
        assert_eq!(value_scale(&[1e-45, 0.5, 0.7], &all), Scale::Linear);
    }

    #[test]
    fn axis_titles_carry_the_column_name_and_its_unit_from_the_dictionary() {
        assert_eq!(metric_title("thruster_energy"), "thruster_energy [J]");
        assert_eq!(metric_title("mission_cost"), "mission_cost [J/m]");
        assert_eq!(metric_title("mission_cost_p95"), "mission_cost_p95 [J/m]");
        assert_eq!(
            metric_title("design.longitudinal_offset"),
            "design.longitudinal_offset [m]"
        );
        assert_eq!(metric_title("design_mass_kg"), "design_mass_kg [kg]");
        assert_eq!(
            metric_title("seg1_convergence_time"),
            "seg1_convergence_time [s]"
        );
        assert_eq!(metric_title("wrench_peak_sway"), "wrench_peak_sway [N]");
        assert_eq!(metric_title("wrench_peak_yaw"), "wrench_peak_yaw [N·m]");
        assert_eq!(metric_title("base_yaw"), "base_yaw [rad]");
        assert_eq!(metric_title("q_3"), "q_3 [rad]");
        assert_eq!(
            metric_title("singularity_exposure"),
            "singularity_exposure [–]"
        );
        assert_eq!(metric_title("design.links"), "design.links");
    }

    /// A sweep table: a text axis, an integer axis, a varying and a constant metric.
    fn sweep_table() -> Table {
        let mut t = Table::default();
        let rule = ["paper", "ends", "paper", "ends", "even", "even"];
        t.push(
            "design.rule",
            ColumnData::Str(rule.map(String::from).to_vec()),
        )
        .unwrap();
        t.push("design.links", vec![3.0, 3.0, 4.0, 4.0, 5.0, 5.0])
            .unwrap();
        t.push("mission_cost", vec![2.0, 2.5, 1.5, 1.8, 1.2, f64::NAN])
            .unwrap();
        t.push("design_thrusters", vec![8.0; 6]).unwrap();
        let status = ["ok", "ok", "ok", "unsuccessful", "ok", "failed"];
        t.push(STATUS, ColumnData::Str(status.map(String::from).to_vec()))
            .unwrap();
        t
    }

    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| t.split_once('>').and_then(|(_, r)| r.split_once("</text>")))
            .map(|(inner, _)| inner.trim().to_string())
            .collect()
    }

    #[test]
    fn axis_plots_draw_categories_integers_units_and_leave_constants_out() {
        let dir = tempfile::tempdir().unwrap();
        let t = sweep_table();
        let key = ["mission_cost".to_string(), "design_thrusters".to_string()];
        let mut warnings = Vec::new();
        let axes = ["design.rule", "design.links"];
        axis_plots(&t, &axes, &key, &[0, 1, 2, 4], dir.path(), &mut warnings);
        assert!(warnings.is_empty(), "{warnings:?}");
        let rule = std::fs::read_to_string(dir.path().join("axis_design.rule.svg"))
            .or_else(|_| std::fs::read_to_string(dir.path().join("axis_design_rule.svg")))
            .unwrap();
        let words = texts(&rule);
        for name in ["paper", "ends", "even"] {
            assert!(words.iter().any(|w| w == name), "{name} not in {words:?}");
        }
        assert!(
            !words
                .iter()
                .any(|w| w == "-0.5" || w == "0.5" || w == "2.5"),
            "{words:?}"
        );
        assert!(words.iter().any(|w| w == "mission_cost [J/m]"), "{words:?}");
        // The constant metric has no panel; the note names it and its value.
        assert!(!words.iter().any(|w| w == "design_thrusters"), "{words:?}");
        assert!(
            words.iter().any(|w| w.contains("design_thrusters = 8")),
            "{words:?}"
        );
        let links = std::fs::read_to_string(dir.path().join("axis_design_links.svg"))
            .or_else(|_| std::fs::read_to_string(dir.path().join("axis_design.links.svg")))
            .unwrap();
        let words = texts(&links);
        assert!(
            words.iter().any(|w| w == "3") && words.iter().any(|w| w == "5"),
            "{words:?}"
        );
        assert!(!words.iter().any(|w| w == "3.0" || w == "3.5"), "{words:?}");
        // Text is at least 11 px at the figure's natural size.
        for size in links.split("font-size=\"").skip(1) {
            let px: f64 = size.split('"').next().unwrap().parse().unwrap();
            assert!(px >= 11.0, "font-size {px}");
        }
    }

    #[test]
    fn timeseries_draws_moving_channels_with_units_and_names_the_flat_ones_and_the_cases() {
        let mut t = Table::default();
        t.push("t", vec![0.0, 0.1, 0.2]).unwrap();
        t.push("base_yaw", vec![0.0, 0.05, 0.1]).unwrap();
        t.push("u_3", vec![0.0, 0.0, 0.0]).unwrap();
        t.push("q_0", vec![0.2, 0.2, 0.2]).unwrap();
        t.push("base_z", vec![0.0, -1e-6, -3e-6]).unwrap();
        let fig = timeseries(&[("best: case #4, mission_cost = 1.58", t)]);
        assert_eq!(fig.panels.len(), 1);
        assert_eq!(fig.panels[0].y_label, "base_yaw [rad]");
        assert_eq!(fig.panels[0].x_label, "t [s]");
        assert!(fig.note.contains("q_0, u_3, base_z"), "{}", fig.note);
        let svg = fig.render_svg().unwrap();
        let words = texts(&svg);
        assert!(words
            .iter()
            .any(|w| w == "best: case #4, mission_cost = 1.58"));
        assert!(
            words.iter().any(|w| w.contains("q_0, u_3, base_z")),
            "{words:?}"
        );
    }

    #[test]
    fn extremes_are_named_by_case_and_objective() {
        let t = sweep_table();
        let sel = Selection {
            metrics: vec!["mission_cost".into()],
            maximise: HashSet::new(),
            magnitude: HashSet::new(),
            objective: Some("mission_cost".into()),
            pareto: None,
        };
        let mut t = t;
        t.push(CASE_ID, ColumnData::I64(vec![10, 11, 12, 13, 14, 15]))
            .unwrap();
        let [best, worst] = extreme_names(&t, &sel);
        // Among the `ok` cases (#10, #11, #12, #14): lowest and highest mission cost.
        assert_eq!(best, "best: case #14, mission_cost = 1.2");
        assert_eq!(worst, "worst: case #11, mission_cost = 2.5");
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

//! The progress plots of `optimise`: `progress.svg` (objective against evaluations, on a
//! range chosen from the data that matter) and `parameters.svg` (each parameter's trace
//! between its bounds, log-scaled parameters on a log axis, the best point marked).

use crate::optimise::history::{best_so_far, Record};
use crate::optimise::Outcome;
use crate::report::{Colour, Figure, Panel, PanelKind, Scale, Series};
use crate::study::tune_space::{Param, Scale as ParamScale};

/// The `q`-quantile (0–1) of `v` (finite values, nearest rank); `None` when empty.
fn quantile(v: &[f64], q: f64) -> Option<f64> {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return None;
    }
    s.sort_by(f64::total_cmp);
    let k = ((s.len() - 1) as f64 * q).round() as usize;
    Some(s[k.min(s.len() - 1)])
}

/// The y range of `progress.svg`: from the lower of the best so far and the feasible
/// evaluations' 5 % quantile to the higher of the best so far (its start) and their 95 %
/// quantile, padded; and whether it spans more than a decade of positive values (then the
/// axis is logarithmic).
fn progress_range(feasible: &[f64], best: &[f64]) -> Option<((f64, f64), bool)> {
    let b = best.iter().copied().filter(|x| x.is_finite());
    let lo = b.clone().fold(quantile(feasible, 0.05)?, f64::min);
    let hi = b.fold(quantile(feasible, 0.95)?, f64::max);
    if lo > 0.0 && hi / lo > 10.0 {
        let f = (hi / lo).powf(0.05);
        return Some(((lo / f, hi * f), true));
    }
    let pad = 0.05 * (hi - lo).max(1e-12 * hi.abs().max(1e-300));
    Some(((lo - pad, hi + pad), false))
}

/// `progress.svg`: the objective of every feasible evaluation (points), the best so far
/// (line) and the best evaluation (marked), on the range of [`progress_range`]; the
/// evaluations outside it are counted in the note.
pub(super) fn progress_figure(o: &Outcome) -> Figure {
    let (mut xf, mut yf) = (Vec::new(), Vec::new());
    for r in o.records.iter().filter(|r| r.score.feasible && !r.repeat) {
        xf.push(r.index as f64);
        yf.push(r.score.objective);
    }
    let best = best_so_far(&o.records);
    let (xb, yb): (Vec<f64>, Vec<f64>) = best
        .iter()
        .enumerate()
        .filter(|(_, y)| y.is_finite())
        .map(|(i, y)| (i as f64, *y))
        .unzip();
    let range = progress_range(&yf, &yb);
    let b = o.best();
    let mut panel = Panel::new(
        "objective against evaluations",
        "evaluation [–]",
        "objective",
    )
    .with_series(Series::new("feasible evaluations", xf, yf.clone()).kind(PanelKind::Scatter))
    .with_series(Series::new("best so far", xb, yb).colour(Colour::Palette(3)))
    .with_series(
        Series::new(
            format!("best: evaluation {}", b.index),
            vec![b.index as f64],
            vec![b.score.objective],
        )
        .colour(Colour::Alert)
        .kind(PanelKind::Scatter),
    );
    panel.x_scale = Scale::Integer;
    let mut fig = Figure::new("optimisation progress");
    if let Some(((lo, hi), log)) = range {
        panel.y_range = Some((lo, hi));
        if log {
            panel.y_scale = Scale::Log;
            panel.y_label = "objective (log scale)".into();
        }
        let out = yf.iter().filter(|y| **y < lo || **y > hi).count();
        if out > 0 {
            fig.note = format!(
                "{out} of {} feasible evaluations lie outside the range shown (5–95 % of the \
                 feasible evaluations and the best so far).",
                yf.len()
            );
        }
    }
    fig.panels.push(panel);
    fig.layout = (1, 1);
    fig.size = (900, 560);
    fig.size.1 += fig.note_height();
    fig
}

/// `parameters.svg`: each parameter's value at every evaluation, its bounds as dashed lines,
/// the best evaluation marked; log-scaled parameters on a log axis, integer ones with
/// integer ticks.
pub(super) fn parameter_figure(params: &[Param], records: &[Record], best: usize) -> Figure {
    let x: Vec<f64> = records.iter().map(|r| r.index as f64).collect();
    let n = records.len().max(1) as f64;
    let mut fig = Figure::new("parameter traces");
    for (k, p) in params.iter().enumerate() {
        let y: Vec<f64> = records.iter().map(|r| r.x[k]).collect();
        let log = p.scale == ParamScale::Log && p.lower > 0.0;
        let bound = |v: f64| vec![v, v];
        let mut panel = Panel::new(p.name.as_str(), "evaluation [–]", p.name.as_str())
            .with_series(Series::new("", x.clone(), y).kind(PanelKind::Scatter))
            .with_series(
                Series::new("bounds", vec![0.0, n - 1.0], bound(p.lower))
                    .colour(Colour::Grey)
                    .dashed(),
            )
            .with_series(
                Series::new("", vec![0.0, n - 1.0], bound(p.upper))
                    .colour(Colour::Grey)
                    .dashed(),
            );
        if let Some(r) = records.get(best) {
            panel.series.push(
                Series::new(
                    format!("best (evaluation {})", r.index),
                    vec![r.index as f64],
                    vec![r.x[k]],
                )
                .colour(Colour::Alert)
                .kind(PanelKind::Scatter),
            );
        }
        panel.x_scale = Scale::Integer;
        if p.lower < p.upper && p.lower.is_finite() && p.upper.is_finite() {
            panel.y_range = Some(if log {
                let f = (p.upper / p.lower).powf(0.05);
                (p.lower / f, p.upper * f)
            } else {
                let pad = 0.05 * (p.upper - p.lower);
                (p.lower - pad, p.upper + pad)
            });
        }
        if log {
            panel.y_scale = Scale::Log;
            panel.y_label = format!("{} (log scale)", p.name);
        } else if p.integer {
            panel.y_scale = Scale::Integer;
        }
        fig.panels.push(panel);
    }
    let rows = params.len().div_ceil(2).max(1);
    fig.layout = (rows, 2.min(params.len().max(1)));
    fig.size = (1000, (300 * rows).max(300) as u32);
    fig
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_progress_range_follows_the_gain_not_the_outliers() {
        // A start at 2.25, a best of 1.58, most evaluations near them, a few at 16.
        let mut feasible: Vec<f64> = (0..100).map(|k| 1.6 + 0.006 * k as f64).collect();
        feasible.extend([16.0, 15.0]);
        let best = [2.25, 2.0, 1.8, 1.58];
        let ((lo, hi), log) = progress_range(&feasible, &best).unwrap();
        assert!(!log);
        assert!(lo < 1.58 && lo > 1.4, "{lo}");
        assert!(hi > 2.25 && hi < 2.5, "{hi}");
        // Decades apart: log scale.
        let ((_, _), log) = progress_range(&[1.0, 100.0, 1000.0], &[1000.0, 1.0]).unwrap();
        assert!(log);
        assert!(progress_range(&[], &best).is_none());
    }

    fn record(index: usize, x: f64, objective: f64) -> Record {
        Record {
            index,
            run: 1,
            iteration: index as u64,
            u: vec![0.5],
            x: vec![x],
            metrics: Vec::new(),
            failure: None,
            repeat: false,
            score: crate::optimise::score::Score {
                objective,
                violation: 0.0,
                feasible: true,
            },
        }
    }

    #[test]
    fn parameter_traces_have_bounds_a_log_axis_and_the_best_point() {
        let p = Param {
            name: "control.k_psi".into(),
            target: crate::study::schema::Target::Scenario(
                crate::input::keypath::KeyPath::parse("control.k_psi").unwrap(),
            ),
            lower: 0.01,
            upper: 10.0,
            scale: ParamScale::Log,
            start: 1.0,
            integer: false,
        };
        let records: Vec<Record> = [1.0, 0.1, 3.0, 0.05]
            .iter()
            .enumerate()
            .map(|(i, &x)| record(i, x, 2.0 - 0.1 * i as f64))
            .collect();
        let fig = parameter_figure(&[p], &records, 3);
        let panel = &fig.panels[0];
        assert_eq!(panel.y_scale, Scale::Log);
        let bounds: Vec<f64> = panel
            .series
            .iter()
            .filter(|s| s.style == crate::report::LineStyle::Dashed)
            .map(|s| s.y[0])
            .collect();
        assert_eq!(bounds, [0.01, 10.0]);
        let best = panel.series.last().unwrap();
        assert_eq!(
            (best.x.as_slice(), best.y.as_slice()),
            (&[3.0][..], &[0.05][..])
        );
        let svg = fig.render_svg().unwrap();
        // Log ticks are printed as values (0.01 … 10), not as their logarithms.
        assert!(
            svg.contains(">\n10\n<") || svg.contains(">10<"),
            "no 10 tick"
        );
        assert!(svg.contains("best (evaluation 3)"));
    }
}

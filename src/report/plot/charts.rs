//! Ready-made figures: [`histogram`] and the labelled trade-off scatter [`scatter_labelled`].

use super::canvas::{bounds, widen, LIMIT};
use super::spec::{Colour, Figure, Panel, PanelKind, Series};
use crate::report::error::{ReportError, Result};

/// A histogram of the finite `values` in `bins` equal bins (at least 1) over their range.
///
/// Non-finite values are left out and counted in the panel title. The y axis is the count.
pub fn histogram(values: &[f64], bins: usize, title: &str, x_label: &str) -> Figure {
    let bins = bins.clamp(1, 100_000);
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let skipped = values.len() - finite.len();
    let mut panel_title = format!("n = {}", finite.len());
    if skipped > 0 {
        panel_title.push_str(&format!(" ({skipped} non-finite left out)"));
    }
    let mut panel = Panel::new(panel_title, x_label, "count [-]");
    panel.legend = false;
    if let Some((lo, hi)) = bounds(finite.iter().copied()) {
        let (lo, hi) = widen((lo.clamp(-LIMIT, LIMIT), hi.clamp(-LIMIT, LIMIT)));
        let width = (hi - lo) / bins as f64;
        let mut counts = vec![0.0; bins];
        for v in &finite {
            let k = ((v - lo) / width).floor();
            let k = if k.is_finite() && k > 0.0 {
                (k as usize).min(bins - 1)
            } else {
                0
            };
            counts[k] += 1.0;
        }
        let centres = (0..bins).map(|k| lo + (k as f64 + 0.5) * width).collect();
        panel.kind = PanelKind::Bars { width };
        panel.series.push(Series::new("", centres, counts));
    }
    let mut fig = Figure::new(title).with_panel(panel);
    fig.layout = (1, 1);
    fig
}

/// A point with a text label, for [`scatter_labelled`].
#[derive(Debug, Clone, PartialEq)]
pub struct LabelledPoint {
    /// Abscissa.
    pub x: f64,
    /// Ordinate.
    pub y: f64,
    /// Text shown next to the point when it is highlighted.
    pub label: String,
}

/// A trade-off scatter plot (e.g. a Pareto front, both axes minimised): all points grey, the
/// `highlight`ed ones (indices into `points`, e.g. from [`super::pareto_front`]) coloured,
/// labelled with their text and joined by a staircase line in order of increasing x.
///
/// Errors if a highlight index is out of range.
pub fn scatter_labelled(
    points: &[LabelledPoint],
    highlight: &[usize],
    title: &str,
    x_label: &str,
    y_label: &str,
) -> Result<Figure> {
    if let Some(&bad) = highlight.iter().find(|&&i| i >= points.len()) {
        return Err(ReportError::InvalidFigure {
            figure: title.to_owned(),
            detail: format!(
                "highlight index {bad} out of range for {} points",
                points.len()
            ),
        });
    }
    let all = Series::new(
        "all",
        points.iter().map(|p| p.x).collect(),
        points.iter().map(|p| p.y).collect(),
    )
    .colour(Colour::Grey)
    .kind(PanelKind::Scatter);

    let mut front: Vec<usize> = highlight
        .iter()
        .copied()
        .filter(|&i| points[i].x.is_finite() && points[i].y.is_finite())
        .collect();
    front.sort_by(|&a, &b| {
        points[a]
            .x
            .total_cmp(&points[b].x)
            .then(points[a].y.total_cmp(&points[b].y))
            .then(a.cmp(&b))
    });
    front.dedup();
    let mut step_x = Vec::new();
    let mut step_y = Vec::new();
    for (k, &i) in front.iter().enumerate() {
        if k > 0 {
            step_x.push(points[i].x);
            step_y.push(points[front[k - 1]].y);
        }
        step_x.push(points[i].x);
        step_y.push(points[i].y);
    }
    let steps = Series::new("", step_x, step_y)
        .colour(Colour::Palette(0))
        .kind(PanelKind::Line);
    let marked = Series::new(
        "highlighted",
        front.iter().map(|&i| points[i].x).collect(),
        front.iter().map(|&i| points[i].y).collect(),
    )
    .colour(Colour::Palette(0))
    .kind(PanelKind::Scatter)
    .labels(front.iter().map(|&i| points[i].label.clone()).collect());

    let panel = Panel::new("", x_label, y_label)
        .kind(PanelKind::Scatter)
        .with_series(all)
        .with_series(steps)
        .with_series(marked);
    let mut fig = Figure::new(title).with_panel(panel);
    fig.layout = (1, 1);
    Ok(fig)
}

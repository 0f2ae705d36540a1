//! Rendering of a [`Figure`]: panels, ranges, clipping and series.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::{
    Cartesian2d, ChartBuilder, ChartContext, Circle, DashedLineSeries, DrawingBackend,
    EmptyElement, IntoFont, LineSeries, PathElement, RGBColor, Rectangle, SeriesLabelPosition,
    ShapeStyle, Text, TextStyle, BLACK, WHITE,
};
use plotters::style::Color;

use super::canvas::{
    auto_range, bounds, finite_points, merge_bounds, render_to_svg, titled, widen, Area,
    DrawResult, Look, DESC_FONT, FONT, TICK_FONT,
};
use super::labels::{place_labels, LABEL_FONT};
use super::scale::Scale;
use super::spec::{Figure, LineStyle, Panel, PanelKind, Series};

/// A chart with `f64` axes on a canvas of backend `DB`.
type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
use crate::report::atomic::atomic_write;
use crate::report::error::{ReportError, Result};

impl Figure {
    /// Renders the figure to an SVG document.
    pub fn render_svg(&self) -> Result<String, ReportError> {
        self.validate()?;
        render_to_svg(self.size, &self.title, |root| {
            draw_figure(self, root, Look::SCREEN)
        })
    }

    /// Renders the figure and writes it to `path` atomically.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        atomic_write(path, self.render_svg()?.as_bytes())
    }
}

/// Draws `fig` onto `root` in `look`.
pub(super) fn draw_figure<DB: DrawingBackend>(
    fig: &Figure,
    root: &Area<DB>,
    look: Look,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let body = if fig.title.is_empty() {
        root.clone()
    } else {
        titled(root, &fig.title, 22, look)?
    };
    let note = fig.note_lines_for(look);
    let body = if note.is_empty() {
        body
    } else {
        let (_, h) = body.dim_in_pixel();
        let (top, bottom) = body.split_vertically(h as i32 - fig.note_height_for(look) as i32);
        let style = TextStyle::from((FONT, look.font(NOTE_FONT)).into_font()).color(&NOTE_RGB);
        let step = look.pxi(18);
        for (k, line) in note.into_iter().enumerate() {
            bottom.draw(&Text::new(line, (12, 4 + step * k as i32), style.clone()))?;
        }
        top
    };
    let areas = body.split_evenly(fig.grid());
    // At the column a grid shows each legend once (its names without their counts).
    let mut shown: Vec<Vec<String>> = Vec::new();
    for (panel, area) in fig.panels.iter().zip(&areas) {
        let names: Vec<String> = panel
            .series
            .iter()
            .filter(|s| !s.name.is_empty())
            .map(|s| s.name.chars().filter(|c| !c.is_ascii_digit()).collect())
            .collect();
        let legend = !look.fits() || !shown.contains(&names);
        if panel.legend && !names.is_empty() && legend {
            shown.push(names);
        }
        draw_panel(panel, area, look, legend)?;
    }
    Ok(())
}

/// Font size of a figure's note as given to plotters (written as 15 / 1.24 ≈ 12.1 px).
const NOTE_FONT: u32 = 15;
const NOTE_RGB: RGBColor = RGBColor(70, 70, 70);
/// Panel captions as given to plotters (written as 17 / 1.24 ≈ 13.7 px).
const CAPTION_FONT: u32 = 17;

/// The panel in drawn coordinates: data (and fixed ranges) of a log axis as log10.
fn drawn(panel: &Panel) -> std::borrow::Cow<'_, Panel> {
    if panel.x_scale != Scale::Log && panel.y_scale != Scale::Log {
        return std::borrow::Cow::Borrowed(panel);
    }
    let mut p = panel.clone();
    let (xs, ys) = (panel.x_scale.clone(), panel.y_scale.clone());
    for s in &mut p.series {
        s.x.iter_mut().for_each(|v| *v = xs.forward(*v));
        s.y.iter_mut().for_each(|v| *v = ys.forward(*v));
    }
    let map = |r: Option<(f64, f64)>, sc: &Scale| {
        r.map(|r| (sc.forward(r.0), sc.forward(r.1)))
            .filter(|r| r.0.is_finite() && r.1.is_finite() && r.0 < r.1)
    };
    p.x_range = map(panel.x_range, &xs);
    p.y_range = map(panel.y_range, &ys);
    std::borrow::Cow::Owned(p)
}

fn panel_ranges(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let mut xb = None;
    let mut yb = None;
    for s in &panel.series {
        let pts: Vec<(f64, f64)> = finite_points(&s.x, &s.y).collect();
        let sx = bounds(pts.iter().map(|p| p.0));
        let sy = bounds(pts.iter().map(|p| p.1));
        if let (PanelKind::Bars { width }, Some((x0, x1)), Some((y0, y1))) =
            (s.kind.unwrap_or(panel.kind), sx, sy)
        {
            xb = merge_bounds(xb, Some((x0 - 0.5 * width, x1 + 0.5 * width)));
            yb = merge_bounds(yb, Some((y0.min(0.0), y1.max(0.0))));
        } else {
            xb = merge_bounds(xb, sx);
            yb = merge_bounds(yb, sy);
        }
    }
    let x = (panel.x_range.or(panel.x_scale.fixed_range()))
        .map(widen)
        .unwrap_or_else(|| auto_range(xb));
    let y = (panel.y_range.or(panel.y_scale.fixed_range()))
        .map(widen)
        .unwrap_or_else(|| auto_range(yb));
    (x, y)
}

/// Clips the segment `p`–`q` to the box (Liang–Barsky). `None` if it lies outside.
fn clip(
    p: (f64, f64),
    q: (f64, f64),
    xr: (f64, f64),
    yr: (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    // (t, edge that set it: 0..4 = x min, x max, y min, y max; 4 = segment end).
    let (mut t0, mut e0) = (0.0_f64, 4);
    let (mut t1, mut e1) = (1.0_f64, 4);
    let edges = [
        (-dx, p.0 - xr.0, xr.0),
        (dx, xr.1 - p.0, xr.1),
        (-dy, p.1 - yr.0, yr.0),
        (dy, yr.1 - p.1, yr.1),
    ];
    for (k, &(pk, qk, _)) in edges.iter().enumerate() {
        if pk == 0.0 {
            if qk < 0.0 {
                return None;
            }
        } else {
            let r = qk / pk;
            if !r.is_finite() {
                return None;
            }
            if pk < 0.0 && r > t0 {
                (t0, e0) = (r, k);
            } else if pk > 0.0 && r < t1 {
                (t1, e1) = (r, k);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    // Put a clipped end exactly on its edge (interpolation alone loses it for steep segments).
    let at = |t: f64, edge: usize, end: (f64, f64)| {
        if edge == 4 {
            return end;
        }
        let (x, y) = (p.0 + t * dx, p.1 + t * dy);
        let bound = edges[edge].2;
        if edge < 2 {
            (bound, y.clamp(yr.0, yr.1))
        } else {
            (x.clamp(xr.0, xr.1), bound)
        }
    };
    Some((at(t0, e0, p), at(t1, e1, q)))
}

/// Splits a series into visible polylines: broken at non-finite values and clipped to the box.
/// Isolated visible points become one-point polylines.
fn polylines(x: &[f64], y: &[f64], xr: (f64, f64), yr: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let inside = |p: (f64, f64)| p.0 >= xr.0 && p.0 <= xr.1 && p.1 >= yr.0 && p.1 <= yr.1;
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let mut prev: Option<(f64, f64)> = None;
    for (&a, &b) in x.iter().zip(y) {
        let p = (a, b);
        if !(a.is_finite() && b.is_finite()) {
            if !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            prev = None;
            continue;
        }
        match prev {
            None => {
                if inside(p) {
                    current.push(p);
                }
            }
            Some(o) => match clip(o, p, xr, yr) {
                Some((s, e)) => {
                    if current.last() != Some(&s) {
                        if !current.is_empty() {
                            out.push(std::mem::take(&mut current));
                        }
                        current.push(s);
                    }
                    current.push(e);
                }
                None => {
                    if !current.is_empty() {
                        out.push(std::mem::take(&mut current));
                    }
                }
            },
        }
        prev = Some(p);
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

fn draw_panel<DB: DrawingBackend>(
    panel: &Panel,
    area: &Area<DB>,
    look: Look,
    legend: bool,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let panel = &*drawn(panel);
    let (xr, yr) = panel_ranges(panel);
    // Tick counts from the panel size (plotters rounds them to "nice" steps).
    let (w, h) = area.dim_in_pixel();
    let x_ticks = panel
        .x_scale
        .tick_count(xr, (w as usize / look.px(60) as usize).clamp(3, 12));
    let y_ticks = panel
        .y_scale
        .tick_count(yr, (h as usize / look.px(40) as usize).clamp(3, 12));
    let desc_font = look.fit_font(
        DESC_FONT,
        &[
            (&panel.x_label, w as i32 - look.pxi(98)),
            (&panel.y_label, h as i32 - look.pxi(90)),
        ],
    );
    let mut chart = ChartBuilder::on(area)
        .caption(
            &panel.title,
            (
                FONT,
                look.fit_to(look.title(CAPTION_FONT), &[(&panel.title, w as i32)]),
            ),
        )
        .margin(look.px(10))
        .x_label_area_size(look.px(50))
        .y_label_area_size(look.px(78))
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
    let x_fmt = |v: &f64| panel.x_scale.label(*v);
    let y_fmt = |v: &f64| panel.y_scale.label(*v);
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style((FONT, look.font(TICK_FONT)))
        .axis_desc_style((FONT, desc_font))
        .x_labels(x_ticks)
        .y_labels(y_ticks)
        .max_light_lines(0)
        .bold_line_style(RGBColor(225, 225, 225));
    mesh.x_label_formatter(&x_fmt).y_label_formatter(&y_fmt);
    mesh.draw()?;

    let mut named = 0;
    for s in &panel.series {
        let rgb = s.colour.rgb();
        let line = ShapeStyle {
            color: rgb.to_rgba(),
            filled: false,
            stroke_width: 2,
        };
        let kind = s.kind.unwrap_or(panel.kind);
        draw_data(&mut chart, s, kind, line, (xr, yr), look)?;
        if !s.name.is_empty() {
            named += 1;
            let anno = chart.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
            let anno = anno.label(s.name.as_str());
            let u = |v: i32| look.pxi(v);
            match (kind, s.style) {
                (PanelKind::Line, LineStyle::Dashed) => {
                    anno.legend(move |(x, y)| {
                        DashedPathElement::new(vec![(x, y), (x + u(20), y)], 6, 4, line)
                    });
                }
                (PanelKind::Line, LineStyle::Solid) => {
                    anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + u(20), y)], line));
                }
                (PanelKind::Scatter, _) => {
                    let r = look.px(3);
                    anno.legend(move |(x, y)| Circle::new((x + u(10), y), r, rgb.filled()));
                }
                (PanelKind::Bars { .. }, _) => {
                    anno.legend(move |(x, y)| {
                        Rectangle::new(
                            [(x + u(4), y - u(5)), (x + u(16), y + u(5))],
                            rgb.mix(0.7).filled(),
                        )
                    });
                }
            }
        }
    }
    if panel.legend && named > 0 && legend {
        chart
            .configure_series_labels()
            .position(legend_corner(panel, (xr, yr)))
            .label_font((FONT, look.font(TICK_FONT)))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}

/// Draws the data of series `s` as `kind` (lines broken at non-finite values and clipped to
/// the ranges, markers or bars inside them) and its point labels.
fn draw_data<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    s: &Series,
    kind: PanelKind,
    line: ShapeStyle,
    (xr, yr): ((f64, f64), (f64, f64)),
    look: Look,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let rgb = s.colour.rgb();
    let inside = |p: &(f64, f64)| p.0 >= xr.0 && p.0 <= xr.1 && p.1 >= yr.0 && p.1 <= yr.1;
    match kind {
        PanelKind::Line => {
            for poly in polylines(&s.x, &s.y, xr, yr) {
                if poly.len() == 1 {
                    let r = look.px(2);
                    chart.draw_series(poly.iter().map(|&p| Circle::new(p, r, rgb.filled())))?;
                } else if s.style == LineStyle::Dashed {
                    chart.draw_series(DashedLineSeries::new(poly, 6, 4, line))?;
                } else {
                    chart.draw_series(LineSeries::new(poly, line))?;
                }
            }
        }
        PanelKind::Scatter => {
            let pts: Vec<(f64, f64)> = finite_points(&s.x, &s.y).filter(|p| inside(p)).collect();
            let r = look.px(3);
            chart.draw_series(pts.into_iter().map(|p| Circle::new(p, r, rgb.filled())))?;
        }
        PanelKind::Bars { width } => {
            let fill = rgb.mix(0.7).filled();
            let clamp_x = |v: f64| v.clamp(xr.0, xr.1);
            let clamp_y = |v: f64| v.clamp(yr.0, yr.1);
            let corners: Vec<[(f64, f64); 2]> = finite_points(&s.x, &s.y)
                .map(|(x, y)| {
                    [
                        (clamp_x(x - 0.5 * width), clamp_y(0.0)),
                        (clamp_x(x + 0.5 * width), clamp_y(y)),
                    ]
                })
                .collect();
            chart.draw_series(corners.iter().map(|c| Rectangle::new(*c, fill)))?;
            chart.draw_series(
                corners
                    .iter()
                    .map(|c| Rectangle::new(*c, WHITE.stroke_width(1))),
            )?;
        }
    }
    if !s.labels.is_empty() {
        draw_labels(chart, s, &inside, look)?;
    }
    Ok(())
}

/// The point labels of `s` (those inside the ranges), placed so that none overlaps another
/// or a marker of the series ([`place_labels`]), with leader lines to labels moved away.
fn draw_labels<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    s: &Series,
    inside: &dyn Fn(&(f64, f64)) -> bool,
    look: Look,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let labelled: Vec<((f64, f64), &str)> =
        s.x.iter()
            .zip(&s.y)
            .zip(&s.labels)
            .map(|((&x, &y), l)| ((x, y), l.as_str()))
            .filter(|(p, l)| p.0.is_finite() && p.1.is_finite() && inside(p) && !l.is_empty())
            .collect();
    let px: Vec<(i32, i32)> = labelled
        .iter()
        .map(|(p, _)| chart.backend_coord(p))
        .collect();
    let markers: Vec<(i32, i32)> = finite_points(&s.x, &s.y)
        .filter(|p| inside(p))
        .map(|p| chart.backend_coord(&p))
        .collect();
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let area = [xs.start, ys.start, xs.end, ys.end];
    let texts: Vec<&str> = labelled.iter().map(|(_, l)| *l).collect();
    let placed = place_labels(&px, &texts, &markers, area, look.k);
    let grey = RGBColor(120, 120, 120).stroke_width(1);
    for (((p, l), pl), _) in labelled.iter().zip(&placed).zip(&px) {
        let text = Text::new(
            l.to_string(),
            pl.offset,
            (FONT, look.font(LABEL_FONT)).into_font(),
        );
        match pl.leader {
            Some(end) => chart.draw_series(std::iter::once(
                EmptyElement::at(*p) + PathElement::new(vec![(0, 0), end], grey) + text,
            ))?,
            None => chart.draw_series(std::iter::once(EmptyElement::at(*p) + text))?,
        };
    }
    Ok(())
}

/// The corner of the panel for its legend: the one of upper right, upper left, lower right,
/// lower left (in that order of preference) whose 45 % × 30 % of the ranges holds the fewest
/// data points, so that the legend hides as little as possible.
fn legend_corner(panel: &Panel, (xr, yr): ((f64, f64), (f64, f64))) -> SeriesLabelPosition {
    let (fx, fy) = (0.45, 0.30);
    let (wx, wy) = ((xr.1 - xr.0) * fx, (yr.1 - yr.0) * fy);
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let count = |right: bool, upper: bool| {
        panel
            .series
            .iter()
            .flat_map(|s| finite_points(&s.x, &s.y))
            .filter(|p| {
                let in_x = if right {
                    p.0 >= xr.1 - wx
                } else {
                    p.0 <= xr.0 + wx
                };
                let in_y = if upper {
                    p.1 >= yr.1 - wy
                } else {
                    p.1 <= yr.0 + wy
                };
                in_x && in_y
            })
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, right, upper)| count(right, upper))
        .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
}

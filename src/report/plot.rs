//! Data-driven SVG figures (plotters, SVG backend, no font files).
//!
//! A [`Figure`] is a grid of [`Panel`]s, each holding [`Series`] of `(x, y)` data drawn as
//! lines, markers or bars. [`histogram`] and [`scatter_labelled`] build common figures;
//! [`Heatmap`] draws a grid of cells with a colour bar.
//!
//! Rendering rules, whatever the input:
//! - non-finite values (NaN, ±inf) are skipped; a line breaks at them;
//! - empty series and empty panels are drawn as empty axes on `[0, 1]`;
//! - degenerate (constant or single-point) ranges are padded;
//! - lines are clipped to the panel's range, markers outside it are not drawn;
//! - text is native SVG `<text>` (no font files), and the output depends only on the
//!   specification, so rendering twice gives identical bytes.
//!
//! Files are written atomically (temporary name in the same directory, then rename).

use std::path::Path;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::{
    ChartBuilder, Circle, DashedLineSeries, DrawingArea, EmptyElement, IntoDrawingArea, IntoFont,
    LineSeries, PathElement, RGBColor, Rectangle, SVGBackend, SeriesLabelPosition, ShapeStyle,
    Text, BLACK, WHITE,
};
use plotters::style::Color;

use super::{atomic_write, ReportError, Result};

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

const FONT: &str = "sans-serif";
const GREY_RGB: RGBColor = RGBColor(170, 170, 170);
const NAN_CELL_RGB: RGBColor = RGBColor(200, 200, 200);
/// Categorical palette (Tableau 10).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// How a series' line is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// Continuous line.
    #[default]
    Solid,
    /// Dashed line (6 px dashes, 4 px gaps).
    Dashed,
}

/// Colour of a series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Colour {
    /// Entry of the 10-colour categorical palette (index taken modulo 10).
    Palette(usize),
    /// Light grey, for background data.
    Grey,
}

impl Default for Colour {
    fn default() -> Self {
        Colour::Palette(0)
    }
}

impl Colour {
    fn rgb(self) -> RGBColor {
        match self {
            Colour::Palette(i) => PALETTE[i % PALETTE.len()],
            Colour::Grey => GREY_RGB,
        }
    }
}

/// How the series of a panel are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum PanelKind {
    /// Connected lines through the points in the given order.
    #[default]
    Line,
    /// Markers (filled circles) at the points.
    Scatter,
    /// Vertical bars from 0 to `y`, centred on `x`, of the given width (x units).
    Bars {
        /// Bar width in x units.
        width: f64,
    },
}

/// One data series.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Series {
    /// Legend entry; an empty name is left out of the legend.
    pub name: String,
    /// Abscissae (same length as `y`).
    pub x: Vec<f64>,
    /// Ordinates.
    pub y: Vec<f64>,
    /// Line stroke (for line series).
    pub style: LineStyle,
    /// Colour.
    pub colour: Colour,
    /// Overrides the panel's [`PanelKind`] for this series.
    pub kind: Option<PanelKind>,
    /// Text drawn next to each point (empty: no labels; otherwise one per point).
    pub labels: Vec<String>,
}

impl Series {
    /// A series with the given name and data, solid, palette colour 0, drawn as the panel says.
    pub fn new(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self {
            name: name.into(),
            x,
            y,
            ..Self::default()
        }
    }

    /// Sets a dashed stroke.
    pub fn dashed(mut self) -> Self {
        self.style = LineStyle::Dashed;
        self
    }

    /// Sets the colour.
    pub fn colour(mut self, colour: Colour) -> Self {
        self.colour = colour;
        self
    }

    /// Draws this series as `kind` whatever the panel's kind.
    pub fn kind(mut self, kind: PanelKind) -> Self {
        self.kind = Some(kind);
        self
    }

    /// Sets one text label per point.
    pub fn labels(mut self, labels: Vec<String>) -> Self {
        self.labels = labels;
        self
    }
}

/// One set of axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Caption above the axes.
    pub title: String,
    /// X axis label, with units, e.g. `"time [s]"`.
    pub x_label: String,
    /// Y axis label, with units, e.g. `"thrust [N]"`.
    pub y_label: String,
    /// The data.
    pub series: Vec<Series>,
    /// Default drawing of the series.
    pub kind: PanelKind,
    /// Fixed x range `(min, max)`; `None`: from the data.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range `(min, max)`; `None`: from the data.
    pub y_range: Option<(f64, f64)>,
    /// Draw a legend of the named series (when there is at least one).
    pub legend: bool,
}

impl Panel {
    /// A line panel with a legend and automatic ranges.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            kind: PanelKind::Line,
            x_range: None,
            y_range: None,
            legend: true,
        }
    }

    /// Adds a series.
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Sets the default drawing kind.
    pub fn kind(mut self, kind: PanelKind) -> Self {
        self.kind = kind;
        self
    }
}

/// A figure: a title over a grid of panels, rendered to SVG.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title over the whole figure (empty: none).
    pub title: String,
    /// Panels, filled row by row into the layout.
    pub panels: Vec<Panel>,
    /// Grid `(rows, cols)`; a zero in either means automatic (near-square grid).
    pub layout: (usize, usize),
    /// Size in pixels `(width, height)`, each at least 50.
    pub size: (u32, u32),
}

impl Figure {
    /// An empty figure, automatic layout, 800 × 600 px.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            panels: Vec::new(),
            layout: (0, 0),
            size: (800, 600),
        }
    }

    /// Adds a panel.
    pub fn with_panel(mut self, panel: Panel) -> Self {
        self.panels.push(panel);
        self
    }

    fn invalid(&self, detail: String) -> ReportError {
        ReportError::InvalidFigure {
            figure: self.title.clone(),
            detail,
        }
    }

    fn grid(&self) -> (usize, usize) {
        let n = self.panels.len().max(1);
        if self.layout.0 == 0 || self.layout.1 == 0 {
            let cols = (1..=n).find(|c| c * c >= n).unwrap_or(n);
            (n.div_ceil(cols), cols)
        } else {
            self.layout
        }
    }

    fn validate(&self) -> Result<()> {
        check_size(self.size).map_err(|d| self.invalid(d))?;
        let (rows, cols) = self.grid();
        if rows.saturating_mul(cols) < self.panels.len() {
            return Err(self.invalid(format!(
                "{} panels do not fit a {rows}×{cols} layout",
                self.panels.len()
            )));
        }
        if rows > 64 || cols > 64 {
            return Err(self.invalid(format!("layout {rows}×{cols} is too large")));
        }
        for (i, p) in self.panels.iter().enumerate() {
            let at = |d: String| self.invalid(format!("panel {} `{}`: {d}", i + 1, p.title));
            for r in [p.x_range, p.y_range].into_iter().flatten() {
                if !(r.0.is_finite() && r.1.is_finite() && r.0 < r.1) {
                    return Err(at(format!("range {r:?} must be finite with min < max")));
                }
            }
            for s in &p.series {
                if s.x.len() != s.y.len() {
                    return Err(at(format!(
                        "series `{}` has {} x and {} y values",
                        s.name,
                        s.x.len(),
                        s.y.len()
                    )));
                }
                if !s.labels.is_empty() && s.labels.len() != s.x.len() {
                    return Err(at(format!(
                        "series `{}` has {} labels for {} points",
                        s.name,
                        s.labels.len(),
                        s.x.len()
                    )));
                }
                if let PanelKind::Bars { width } = s.kind.unwrap_or(p.kind) {
                    if !(width.is_finite() && width > 0.0) {
                        return Err(at(format!("bar width {width} must be finite and > 0")));
                    }
                }
            }
        }
        Ok(())
    }

    /// Renders the figure to an SVG document.
    pub fn render_svg(&self) -> Result<String> {
        self.validate()?;
        render_to_svg(self.size, &self.title, |root| draw_figure(self, root))
    }

    /// Renders the figure and writes it to `path` atomically.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        atomic_write(path, self.render_svg()?.as_bytes())
    }
}

fn check_size(size: (u32, u32)) -> std::result::Result<(), String> {
    if size.0 < 50 || size.1 < 50 || size.0 > 20_000 || size.1 > 20_000 {
        return Err(format!(
            "size {}×{} px must be within 50..=20000",
            size.0, size.1
        ));
    }
    Ok(())
}

/// Draw onto a fresh SVG canvas of `size` pixels and return the document; drawing errors
/// become [`ReportError::Plot`] naming the figure `title`.
fn render_to_svg(
    size: (u32, u32),
    title: &str,
    draw: impl FnOnce(&Area<'_>) -> DrawResult,
) -> Result<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        draw(&root)
            .and_then(|()| root.present().map_err(Into::into))
            .map_err(|e| ReportError::Plot {
                figure: title.to_string(),
                message: e.to_string(),
            })?;
    }
    Ok(buf)
}

fn draw_figure(fig: &Figure, root: &Area<'_>) -> DrawResult {
    root.fill(&WHITE)?;
    let body = if fig.title.is_empty() {
        root.clone()
    } else {
        root.titled(&fig.title, (FONT, 22))?
    };
    let areas = body.split_evenly(fig.grid());
    for (panel, area) in fig.panels.iter().zip(&areas) {
        draw_panel(panel, area)?;
    }
    Ok(())
}

/// Finite (x, y) pairs.
fn finite_points<'a>(x: &'a [f64], y: &'a [f64]) -> impl Iterator<Item = (f64, f64)> + 'a {
    x.iter()
        .zip(y)
        .map(|(&a, &b)| (a, b))
        .filter(|(a, b)| a.is_finite() && b.is_finite())
}

/// Largest magnitude used for automatic ranges, so that widths and paddings stay finite.
const LIMIT: f64 = f64::MAX / 8.0;

/// Smallest range width used: spreads below it are drawn as constant data.
const TINY: f64 = 1e-300;

/// A drawable range from data bounds: padded by 5 % (or made non-degenerate), finite.
fn auto_range(bounds: Option<(f64, f64)>) -> (f64, f64) {
    let Some((lo, hi)) = bounds else {
        return (0.0, 1.0);
    };
    let (lo, hi) = (lo.clamp(-LIMIT, LIMIT), hi.clamp(-LIMIT, LIMIT));
    let pad = 0.05 * (hi - lo);
    widen((lo - pad, hi + pad))
}

/// Makes a range wide enough for plotters' tick computation: at least 1e-9 relative to its
/// magnitude and at least [`TINY`] (an empty range around 0 becomes `[-0.5, 0.5]`).
fn widen((lo, hi): (f64, f64)) -> (f64, f64) {
    let mag = lo.abs().max(hi.abs());
    let min_width = if mag > 0.0 {
        (mag * 1e-9).max(TINY)
    } else {
        1.0
    };
    if hi - lo >= min_width {
        return (lo, hi);
    }
    let mid = 0.5 * lo + 0.5 * hi;
    let half = if mag > 0.0 {
        (mag * 0.05).clamp(TINY, LIMIT)
    } else {
        0.5
    };
    (mid - half, mid + half)
}

fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

fn merge_bounds(a: Option<(f64, f64)>, b: Option<(f64, f64)>) -> Option<(f64, f64)> {
    match (a, b) {
        (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
        (a, None) => a,
        (None, b) => b,
    }
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
    let x = panel.x_range.map(widen).unwrap_or_else(|| auto_range(xb));
    let y = panel.y_range.map(widen).unwrap_or_else(|| auto_range(yb));
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

fn draw_panel(panel: &Panel, area: &Area<'_>) -> DrawResult {
    let (xr, yr) = panel_ranges(panel);
    // Tick counts from the panel size (plotters rounds them to "nice" steps).
    let (w, h) = area.dim_in_pixel();
    let x_ticks = (w as usize / 50).clamp(3, 12);
    let y_ticks = (h as usize / 40).clamp(3, 12);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 16))
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .x_labels(x_ticks)
        .y_labels(y_ticks)
        .max_light_lines(0)
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()?;

    let inside = |p: &(f64, f64)| p.0 >= xr.0 && p.0 <= xr.1 && p.1 >= yr.0 && p.1 <= yr.1;
    let mut named = 0;
    for s in &panel.series {
        let rgb = s.colour.rgb();
        let line = ShapeStyle {
            color: rgb.to_rgba(),
            filled: false,
            stroke_width: 2,
        };
        let kind = s.kind.unwrap_or(panel.kind);
        match kind {
            PanelKind::Line => {
                for poly in polylines(&s.x, &s.y, xr, yr) {
                    if poly.len() == 1 {
                        chart.draw_series(poly.iter().map(|&p| Circle::new(p, 2, rgb.filled())))?;
                    } else if s.style == LineStyle::Dashed {
                        chart.draw_series(DashedLineSeries::new(poly, 6, 4, line))?;
                    } else {
                        chart.draw_series(LineSeries::new(poly, line))?;
                    }
                }
            }
            PanelKind::Scatter => {
                let pts: Vec<(f64, f64)> =
                    finite_points(&s.x, &s.y).filter(|p| inside(p)).collect();
                chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, rgb.filled())))?;
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
            let texts: Vec<_> = s
                .x
                .iter()
                .zip(&s.y)
                .zip(&s.labels)
                .map(|((&x, &y), l)| ((x, y), l))
                .filter(|(p, l)| p.0.is_finite() && p.1.is_finite() && inside(p) && !l.is_empty())
                .map(|(p, l)| {
                    EmptyElement::at(p) + Text::new(l.clone(), (5, -14), (FONT, 11).into_font())
                })
                .collect();
            chart.draw_series(texts)?;
        }
        if !s.name.is_empty() {
            named += 1;
            let anno = chart.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
            let anno = anno.label(s.name.as_str());
            match (kind, s.style) {
                (PanelKind::Line, LineStyle::Dashed) => {
                    anno.legend(move |(x, y)| {
                        DashedPathElement::new(vec![(x, y), (x + 20, y)], 6, 4, line)
                    });
                }
                (PanelKind::Line, LineStyle::Solid) => {
                    anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], line));
                }
                (PanelKind::Scatter, _) => {
                    anno.legend(move |(x, y)| Circle::new((x + 10, y), 3, rgb.filled()));
                }
                (PanelKind::Bars { .. }, _) => {
                    anno.legend(move |(x, y)| {
                        Rectangle::new([(x + 4, y - 5), (x + 16, y + 5)], rgb.mix(0.7).filled())
                    });
                }
            }
        }
    }
    if panel.legend && named > 0 {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, 12))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    Ok(())
}

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

/// Colour scale of a [`Heatmap`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColourScale {
    /// Perceptually uniform dark blue → green → yellow (viridis, 5-point approximation).
    #[default]
    Viridis,
    /// White → black.
    Greys,
    /// Blue → white → red, for signed quantities (centre the range on 0 via `z_range`).
    BlueRed,
}

impl ColourScale {
    /// Colour at `t` in `[0, 1]` (clamped).
    fn at(self, t: f64) -> RGBColor {
        const VIRIDIS: [(u8, u8, u8); 5] = [
            (68, 1, 84),
            (59, 82, 139),
            (33, 145, 140),
            (94, 201, 98),
            (253, 231, 37),
        ];
        const GREYS: [(u8, u8, u8); 2] = [(255, 255, 255), (0, 0, 0)];
        const BLUE_RED: [(u8, u8, u8); 3] = [(59, 76, 192), (247, 247, 247), (180, 4, 38)];
        let stops: &[(u8, u8, u8)] = match self {
            ColourScale::Viridis => &VIRIDIS,
            ColourScale::Greys => &GREYS,
            ColourScale::BlueRed => &BLUE_RED,
        };
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let pos = t * (stops.len() - 1) as f64;
        let k = (pos.floor() as usize).min(stops.len() - 2);
        let f = pos - k as f64;
        let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
        let (a, b) = (stops[k], stops[k + 1]);
        RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
    }
}

/// A heat map: one filled rectangle per cell of a rectilinear grid, a colour bar on the right;
/// NaN (and ±inf) cells are grey.
#[derive(Debug, Clone, PartialEq)]
pub struct Heatmap {
    /// Title over the figure.
    pub title: String,
    /// X axis label with units.
    pub x_label: String,
    /// Y axis label with units.
    pub y_label: String,
    /// Colour bar label with units.
    pub z_label: String,
    /// Cell centres along x, strictly increasing and finite.
    pub x: Vec<f64>,
    /// Cell centres along y, strictly increasing and finite.
    pub y: Vec<f64>,
    /// Values, row-major by y: `z[j * x.len() + i]` is the cell at `(x[i], y[j])`.
    pub z: Vec<f64>,
    /// Colour scale.
    pub scale: ColourScale,
    /// Fixed colour range `(min, max)`; `None`: from the finite values.
    pub z_range: Option<(f64, f64)>,
    /// Size in pixels.
    pub size: (u32, u32),
}

/// Builds a [`Heatmap`] (800 × 600 px, automatic colour range), checking the grid.
///
/// `z` is row-major by y: `z[j * x_centres.len() + i]` is the value at
/// `(x_centres[i], y_centres[j])`. Centres must be finite and strictly increasing; cell edges lie
/// half-way between centres (a single centre gets a unit-wide cell).
#[allow(clippy::too_many_arguments)]
pub fn heatmap(
    x_centres: Vec<f64>,
    y_centres: Vec<f64>,
    z: Vec<f64>,
    title: &str,
    x_label: &str,
    y_label: &str,
    z_label: &str,
    scale: ColourScale,
) -> Result<Heatmap> {
    let h = Heatmap {
        title: title.to_owned(),
        x_label: x_label.to_owned(),
        y_label: y_label.to_owned(),
        z_label: z_label.to_owned(),
        x: x_centres,
        y: y_centres,
        z,
        scale,
        z_range: None,
        size: (800, 600),
    };
    h.validate()?;
    Ok(h)
}

/// Cell edges from centres (validated: finite, strictly increasing, non-empty).
fn edges(c: &[f64]) -> Vec<f64> {
    if c.len() == 1 {
        return vec![c[0] - 0.5, c[0] + 0.5];
    }
    let mut e = Vec::with_capacity(c.len() + 1);
    e.push(c[0] - 0.5 * (c[1] - c[0]));
    for w in c.windows(2) {
        e.push(0.5 * w[0] + 0.5 * w[1]);
    }
    let n = c.len();
    e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
    e
}

impl Heatmap {
    fn invalid(&self, detail: String) -> ReportError {
        ReportError::InvalidFigure {
            figure: self.title.clone(),
            detail,
        }
    }

    fn validate(&self) -> Result<()> {
        check_size(self.size).map_err(|d| self.invalid(d))?;
        for (axis, c) in [("x", &self.x), ("y", &self.y)] {
            let ok = c.iter().all(|v| v.is_finite() && v.abs() <= LIMIT)
                && c.windows(2).all(|w| w[0] < w[1]);
            if !ok {
                return Err(self.invalid(format!(
                    "{axis} centres must be finite and strictly increasing"
                )));
            }
        }
        if self.x.len().checked_mul(self.y.len()) != Some(self.z.len()) {
            return Err(self.invalid(format!(
                "z has {} values for a {}×{} grid",
                self.z.len(),
                self.x.len(),
                self.y.len()
            )));
        }
        if let Some(r) = self.z_range {
            if !(r.0.is_finite() && r.1.is_finite() && r.0 < r.1) {
                return Err(self.invalid(format!("z range {r:?} must be finite with min < max")));
            }
        }
        Ok(())
    }

    /// Renders the heat map to an SVG document.
    pub fn render_svg(&self) -> Result<String> {
        self.validate()?;
        render_to_svg(self.size, &self.title, |root| self.draw(root))
    }

    /// Renders the heat map and writes it to `path` atomically.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        atomic_write(path, self.render_svg()?.as_bytes())
    }

    fn draw(&self, root: &Area<'_>) -> DrawResult {
        root.fill(&WHITE)?;
        let body = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(&self.title, (FONT, 22))?
        };
        let bar_width = 110_i32.min(self.size.0 as i32 / 3);
        let (w, _) = body.dim_in_pixel();
        let (main, bar) = body.split_horizontally(w as i32 - bar_width);

        let (zr, any_finite) = match self.z_range {
            Some(r) => (widen(r), true),
            None => {
                let b = bounds(self.z.iter().copied().filter(|v| v.is_finite()));
                (auto_range(b.map(|(lo, hi)| widen((lo, hi)))), b.is_some())
            }
        };
        let colour = |v: f64| {
            if v.is_finite() {
                self.scale.at((v - zr.0) / (zr.1 - zr.0))
            } else {
                NAN_CELL_RGB
            }
        };

        let (xe, ye) = if self.x.is_empty() || self.y.is_empty() {
            (vec![0.0, 1.0], vec![0.0, 1.0])
        } else {
            (edges(&self.x), edges(&self.y))
        };
        let xr = widen((xe[0], xe[xe.len() - 1]));
        let yr = widen((ye[0], ye[ye.len() - 1]));
        let mut chart = ChartBuilder::on(&main)
            .margin(10)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style((FONT, 12))
            .axis_desc_style((FONT, 14))
            .draw()?;
        let nx = self.x.len();
        let cells: Vec<Rectangle<(f64, f64)>> = (0..self.y.len())
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .map(|(i, j)| {
                Rectangle::new(
                    [(xe[i], ye[j]), (xe[i + 1], ye[j + 1])],
                    colour(self.z[j * nx + i]).filled(),
                )
            })
            .collect();
        chart.draw_series(cells)?;

        // Colour bar: 64 bands over the colour range, with a labelled axis.
        let caption = if any_finite {
            "grey: NaN".to_owned()
        } else {
            "no finite values".to_owned()
        };
        let mut cb = ChartBuilder::on(&bar)
            .margin_top(10)
            .margin_bottom(10)
            .margin_right(5)
            .caption(caption, (FONT, 11))
            .x_label_area_size(45)
            .y_label_area_size(65)
            .build_cartesian_2d(0.0..1.0, zr.0..zr.1)?;
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(self.z_label.as_str())
            .label_style((FONT, 11))
            .axis_desc_style((FONT, 13))
            .draw()?;
        let n = 64;
        let dz = (zr.1 - zr.0) / n as f64;
        cb.draw_series((0..n).map(|k| {
            let z0 = zr.0 + k as f64 * dz;
            let z1 = if k + 1 == n { zr.1 } else { z0 + dz };
            Rectangle::new(
                [(0.0, z0), (1.0, z1)],
                self.scale.at((k as f64 + 0.5) / n as f64).filled(),
            )
        }))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Checks that start and end tags balance (a small well-formedness check).
    fn assert_well_formed(svg: &str) {
        let mut stack: Vec<String> = Vec::new();
        let mut rest = svg;
        while let Some(start) = rest.find('<') {
            let end = rest[start..].find('>').expect("unterminated tag") + start;
            let tag = &rest[start + 1..end];
            rest = &rest[end + 1..];
            if tag.starts_with('?') || tag.starts_with('!') {
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                let open = stack.pop().expect("close without open");
                assert_eq!(open, name.trim(), "mismatched close tag");
            } else if !tag.ends_with('/') {
                let name = tag.split_whitespace().next().unwrap_or("").to_owned();
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed tags: {stack:?}");
        assert!(svg.trim_start().starts_with("<svg"));
    }

    fn demo_figure() -> Figure {
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let sin: Vec<f64> = t.iter().map(|v| v.sin()).collect();
        let mut cos: Vec<f64> = t.iter().map(|v| v.cos()).collect();
        cos[10] = f64::NAN;
        cos[11] = f64::INFINITY;
        let a = Panel::new("thrust", "time [s]", "force [N]")
            .with_series(Series::new("sin", t.clone(), sin.clone()))
            .with_series(
                Series::new("cos & <more>", t.clone(), cos)
                    .dashed()
                    .colour(Colour::Palette(1)),
            );
        let b = Panel::new("scatter", "x [m]", "y [m]")
            .kind(PanelKind::Scatter)
            .with_series(Series::new("pts", sin, t));
        let empty = Panel::new("empty", "e [-]", "f [-]");
        let constant = Panel::new("constant", "c [s]", "d [W]")
            .with_series(Series::new("", vec![1.0, 2.0, 3.0], vec![5.0; 3]))
            .with_series(Series::new("single", vec![2.0], vec![5.0]).kind(PanelKind::Scatter));
        let mut ranged = Panel::new("ranged", "r [s]", "q [m]")
            .with_series(Series::new("", vec![-10.0, 0.5, 10.0], vec![-10.0, 0.5, 10.0]).dashed())
            .with_series(Series::new("", vec![0.2, 0.8], vec![1e300, -1e300]));
        ranged.x_range = Some((0.0, 1.0));
        ranged.y_range = Some((0.0, 1.0));
        let nan_only = Panel::new("nan", "n [-]", "m [-]").with_series(Series::new(
            "nan",
            vec![f64::NAN],
            vec![f64::NAN],
        ));
        Figure::new("Demo figure")
            .with_panel(a)
            .with_panel(b)
            .with_panel(empty)
            .with_panel(constant)
            .with_panel(ranged)
            .with_panel(nan_only)
    }

    #[test]
    fn figure_svg_is_well_formed_deterministic_and_labelled() {
        let fig = demo_figure();
        let a = fig.render_svg().unwrap();
        let b = fig.render_svg().unwrap();
        assert_eq!(a, b);
        assert_well_formed(&a);
        for label in [
            "time [s]",
            "force [N]",
            "x [m]",
            "Demo figure",
            "cos &amp; &lt;more&gt;",
        ] {
            assert!(a.contains(label), "missing {label}");
        }
        assert!(a.contains("<text"));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("fig.svg");
        fig.write_svg(&p).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), a);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn figure_validation_errors() {
        let mut fig = demo_figure();
        fig.layout = (1, 2);
        assert!(matches!(
            fig.render_svg(),
            Err(ReportError::InvalidFigure { .. })
        ));
        let mut fig = demo_figure();
        fig.panels[0].series[0].y.pop();
        assert!(fig.render_svg().is_err());
        let mut fig = demo_figure();
        fig.panels[0].x_range = Some((1.0, 1.0));
        assert!(fig.render_svg().is_err());
        let mut fig = demo_figure();
        fig.size = (0, 0);
        assert!(fig.render_svg().is_err());
        // An empty figure renders.
        assert_well_formed(&Figure::new("").render_svg().unwrap());
    }

    #[test]
    fn extreme_values_do_not_panic() {
        let cases: Vec<Vec<f64>> = vec![
            vec![f64::MAX, -f64::MAX],
            vec![f64::MAX, f64::MAX],
            vec![5e-324, 1e-323],
            vec![1e15, 1e15 + 0.125],
            vec![0.0, -0.0],
            vec![1e300, -1e-300, 3.0],
        ];
        for v in cases {
            let x: Vec<f64> = (0..v.len()).map(|i| i as f64).collect();
            let fig = Figure::new("x").with_panel(
                Panel::new("p", "a [1]", "b [1]")
                    .with_series(Series::new("l", x.clone(), v.clone()).dashed())
                    .with_series(Series::new("s", v.clone(), x).kind(PanelKind::Scatter)),
            );
            assert_well_formed(&fig.render_svg().unwrap());
            assert_well_formed(&histogram(&v, 5, "h", "v [1]").render_svg().unwrap());
        }
    }

    #[test]
    fn histogram_renders() {
        let v: Vec<f64> = (0..200).map(|i| ((i * 37) % 101) as f64 / 10.0).collect();
        let mut with_nan = v.clone();
        with_nan.push(f64::NAN);
        let fig = histogram(&with_nan, 12, "Distribution", "cost [J]");
        let svg = fig.render_svg().unwrap();
        assert_well_formed(&svg);
        assert!(svg.contains("cost [J]") && svg.contains("count [-]"));
        assert!(svg.contains("1 non-finite"));
        assert!(svg.matches("<rect").count() >= 12);
        // Degenerate inputs.
        assert_well_formed(&histogram(&[], 10, "e", "x").render_svg().unwrap());
        assert_well_formed(&histogram(&[3.0; 5], 0, "c", "x").render_svg().unwrap());
    }

    #[test]
    fn pareto_scatter_renders_labels() {
        let pts: Vec<LabelledPoint> = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0)]
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| LabelledPoint {
                x,
                y,
                label: format!("design-{i}"),
            })
            .collect();
        let xy: Vec<(f64, f64)> = pts.iter().map(|p| (p.x, p.y)).collect();
        let front = super::super::pareto_front(&xy);
        assert_eq!(front, vec![0, 1, 3]);
        let fig = scatter_labelled(&pts, &front, "Trade-off", "energy [J]", "error [m]").unwrap();
        let svg = fig.render_svg().unwrap();
        assert_well_formed(&svg);
        for l in [
            "design-0",
            "design-1",
            "design-3",
            "energy [J]",
            "error [m]",
        ] {
            assert!(svg.contains(l), "missing {l}");
        }
        assert!(!svg.contains("design-2"));
        assert!(scatter_labelled(&pts, &[9], "t", "x", "y").is_err());
        assert_eq!(svg, fig.render_svg().unwrap());
    }

    #[test]
    fn heatmap_renders() {
        let x = vec![0.0, 1.0, 2.0];
        let y = vec![10.0, 20.0];
        let z = vec![1.0, 2.0, f64::NAN, 4.0, 5.0, 6.0];
        let h = heatmap(
            x.clone(),
            y.clone(),
            z,
            "Map",
            "gain [-]",
            "depth [m]",
            "cost [J]",
            ColourScale::Viridis,
        )
        .unwrap();
        let svg = h.render_svg().unwrap();
        assert_well_formed(&svg);
        assert_eq!(svg, h.render_svg().unwrap());
        for l in ["gain [-]", "depth [m]", "cost [J]", "Map"] {
            assert!(svg.contains(l), "missing {l}");
        }
        assert!(svg.contains("#C8C8C8"), "NaN cell is grey");
        let dir = tempfile::tempdir().unwrap();
        h.write_svg(&dir.path().join("h.svg")).unwrap();
        // Bad grids are errors; degenerate ones render.
        assert!(heatmap(
            x.clone(),
            y.clone(),
            vec![1.0],
            "",
            "",
            "",
            "",
            ColourScale::Greys
        )
        .is_err());
        assert!(heatmap(
            vec![1.0, 0.0],
            vec![0.0],
            vec![1.0, 2.0],
            "",
            "",
            "",
            "",
            ColourScale::Greys
        )
        .is_err());
        for z in [vec![f64::NAN; 6], vec![3.0; 6]] {
            let h = heatmap(
                x.clone(),
                y.clone(),
                z,
                "d",
                "a",
                "b",
                "c",
                ColourScale::BlueRed,
            )
            .unwrap();
            assert_well_formed(&h.render_svg().unwrap());
        }
        let h = heatmap(
            vec![],
            vec![],
            vec![],
            "e",
            "a",
            "b",
            "c",
            ColourScale::Greys,
        )
        .unwrap();
        assert_well_formed(&h.render_svg().unwrap());
        let h = heatmap(
            vec![1.0],
            vec![2.0],
            vec![3.0],
            "one",
            "a",
            "b",
            "c",
            ColourScale::Greys,
        )
        .unwrap();
        assert_well_formed(&h.render_svg().unwrap());
    }
}

//! Charts of decisions under uncertainty: a tornado chart of sensitivity measures
//! ([`tornado_svg`]) and the rank interval of each design over the worlds
//! ([`rank_interval_svg`]). Both are one horizontal row per item, labelled on the left.

use plotters::element::{Circle, PathElement, Rectangle, Text};
use plotters::prelude::{ChartBuilder, DrawingBackend, RGBColor, BLACK, WHITE};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{Color, IntoFont, TextStyle};

use super::canvas::{
    auto_range, bounds, check_size, render_to_pdf, render_to_svg, title_height, titled, Area,
    DrawResult, Look, COLUMN_PT_PER_PX, COLUMN_PX, DESC_FONT, FONT, TICK_FONT,
};
use super::spec::Colour;
use crate::report::error::{ReportError, Result};

/// One bar of a [`tornado_svg`] chart.
#[derive(Clone, Debug, PartialEq)]
pub struct TornadoRow {
    /// The parameter's name, written left of its bar.
    pub name: String,
    /// The sensitivity measure (e.g. an SRRC in [−1, 1] or a Sobol index in [0, 1]).
    pub value: f64,
    /// Lower end of its interval (NaN: no whisker).
    pub lo: f64,
    /// Upper end of its interval (NaN: no whisker).
    pub hi: f64,
}

/// One design of a [`rank_interval_svg`] chart.
#[derive(Clone, Debug, PartialEq)]
pub struct RankRow {
    /// The design's label, written left of its interval.
    pub label: String,
    /// 5 % quantile of its rank over the worlds.
    pub p05: f64,
    /// Median rank (marked by a dot).
    pub p50: f64,
    /// 95 % quantile of its rank.
    pub p95: f64,
    /// Drawn in the accent colour.
    pub highlight: bool,
}

/// Width of the charts in pixels.
const WIDTH: u32 = 800;
/// The x axis title of the rank intervals.
const RANK_DESC: &str = "rank over the worlds (1 = best): 5–95 % interval, median dot";
/// Height of one row in pixels.
const ROW_PX: u32 = 28;
/// Half the height of a bar, in row units.
const HALF_BAR: f64 = 0.32;
/// Colour of the rows that are not highlighted.
const PLAIN_RGB: RGBColor = RGBColor(90, 90, 90);

/// Canvas size for `rows` rows, `width` px wide in `look`, checked.
fn size_for(title: &str, rows: usize, width: u32, look: Look) -> Result<(u32, u32)> {
    let invalid = |detail: String| ReportError::InvalidFigure {
        figure: title.to_owned(),
        detail,
    };
    if rows == 0 {
        return Err(invalid("no rows to draw".to_owned()));
    }
    let height = u32::try_from(rows)
        .ok()
        .and_then(|r| r.checked_mul(look.px(ROW_PX)))
        .and_then(|h| h.checked_add(look.px(110)))
        .and_then(|h| h.checked_add(extra_title(title, width, look)))
        .unwrap_or(u32::MAX);
    check_size((width, height)).map_err(|e| invalid(format!("{rows} rows: {e}")))?;
    Ok((width, height))
}

/// The height [px] a wrapped column title takes beyond one line (0 on screen).
fn extra_title(title: &str, width: u32, look: Look) -> u32 {
    if !look.fits() {
        return 0;
    }
    let one = title_height("x", 20, width, look);
    title_height(title, 20, width, look).saturating_sub(one)
}

/// Width in pixels of the label column for `labels` (about 7 px a character on screen).
fn label_width<'a>(labels: impl Iterator<Item = &'a str>, width: u32, look: Look) -> u32 {
    let chars = labels.map(|l| l.chars().count()).max().unwrap_or(0);
    ((chars as f64 * 7.0 * look.k).round() as u32 + 16).clamp(60, width / 2)
}

/// The centre of row `k` of `n`, counted from the top, in chart units (rows span `[0, n]`).
fn row_y(k: usize, n: usize) -> f64 {
    (n - k) as f64 - 0.5
}

/// Writes `text` right-aligned just left of the chart's left edge at row height `y`.
fn row_label<DB: DrawingBackend>(
    root: &Area<DB>,
    at: (i32, i32),
    text: &str,
    look: Look,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let style = TextStyle::from((FONT, look.font(TICK_FONT)).into_font())
        .pos(Pos::new(HPos::Right, VPos::Center));
    root.draw(&Text::new(
        text.to_owned(),
        (at.0 - look.pxi(8), at.1),
        style,
    ))?;
    Ok(())
}

/// A tornado chart's rows in drawing order, their labels and the x range.
struct Tornado<'a> {
    order: Vec<&'a TornadoRow>,
    labels: Vec<String>,
    xr: (f64, f64),
}

impl<'a> Tornado<'a> {
    fn new(rows: &'a [TornadoRow]) -> Self {
        let mut order: Vec<&TornadoRow> = rows.iter().collect();
        order.sort_by(|a, b| {
            let key = |r: &TornadoRow| r.value.abs();
            key(a)
                .is_nan()
                .cmp(&key(b).is_nan())
                .then(key(b).total_cmp(&key(a)))
        });
        let xr = auto_range(bounds(
            order
                .iter()
                .flat_map(|r| {
                    let whisker = r.lo.is_finite() && r.hi.is_finite();
                    [
                        Some(r.value),
                        whisker.then_some(r.lo),
                        whisker.then_some(r.hi),
                    ]
                })
                .flatten()
                .filter(|v| v.is_finite())
                .chain([0.0]),
        ));
        let labels: Vec<String> = order
            .iter()
            .map(|r| {
                if r.value.is_finite() {
                    r.name.clone()
                } else {
                    format!("{} (n/a)", r.name)
                }
            })
            .collect();
        Tornado { order, labels, xr }
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &Area<DB>,
        look: Look,
        title: &str,
        metric: &str,
    ) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        let (width, _) = root.dim_in_pixel();
        let left = label_width(self.labels.iter().map(String::as_str), width, look);
        let xr = self.xr;
        root.fill(&WHITE)?;
        let body = titled(root, title, 20, look)?;
        let n = self.order.len();
        let mut chart = ChartBuilder::on(&body)
            .margin(look.px(10))
            .margin_left(left)
            .x_label_area_size(look.px(45))
            .build_cartesian_2d(xr.0..xr.1, 0.0..n as f64)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .disable_y_axis()
            .x_desc(metric)
            .label_style((FONT, look.font(TICK_FONT)))
            .axis_desc_style((
                FONT,
                look.fit_font(DESC_FONT, &[(metric, width as i32 - 20)]),
            ))
            .draw()?;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, 0.0), (0.0, n as f64)],
            BLACK.stroke_width(1),
        )))?;
        for (k, (r, label)) in self.order.iter().zip(&self.labels).enumerate() {
            let y = row_y(k, n);
            row_label(root, chart.backend_coord(&(xr.0, y)), label, look)?;
            if !r.value.is_finite() {
                continue;
            }
            let colour = if r.value >= 0.0 {
                Colour::Palette(0)
            } else {
                Colour::Palette(1)
            };
            chart.draw_series(std::iter::once(Rectangle::new(
                [(0.0, y - HALF_BAR), (r.value, y + HALF_BAR)],
                colour.rgb().filled(),
            )))?;
            if r.lo.is_finite() && r.hi.is_finite() {
                let cap = HALF_BAR * 0.5;
                let style = BLACK.stroke_width(2);
                chart.draw_series(
                    [
                        vec![(r.lo, y), (r.hi, y)],
                        vec![(r.lo, y - cap), (r.lo, y + cap)],
                        vec![(r.hi, y - cap), (r.hi, y + cap)],
                    ]
                    .into_iter()
                    .map(|p| PathElement::new(p, style)),
                )?;
            }
        }
        Ok(())
    }
}

/// A tornado chart: one horizontal bar per row from 0 to its value, sorted by decreasing
/// |value| from the top (NaN values last, drawn as "n/a" without a bar), the interval
/// `[lo, hi]` as a whisker with end caps when both ends are finite. The x axis (labelled
/// `metric`) spans the values, the finite interval ends and 0. Positive bars are blue, negative
/// orange.
///
/// Errors ([`ReportError::InvalidFigure`]) without rows or with more rows than fit on a
/// 20000 px canvas.
pub fn tornado_svg(title: &str, metric: &str, rows: &[TornadoRow]) -> Result<String> {
    let size = size_for(title, rows.len(), WIDTH, Look::SCREEN)?;
    let t = Tornado::new(rows);
    render_to_svg(size, title, |root| {
        t.draw(root, Look::SCREEN, title, metric)
    })
}

/// [`tornado_svg`] as a PDF at a paper's column width: 252 pt wide ([`COLUMN_PX`] px at
/// [`COLUMN_PT_PER_PX`] pt a pixel), text 7.3–8.5 pt.
pub fn tornado_pdf(title: &str, metric: &str, rows: &[TornadoRow]) -> Result<Vec<u8>> {
    let size = size_for(title, rows.len(), COLUMN_PX, Look::COLUMN)?;
    let t = Tornado::new(rows);
    render_to_pdf(size, COLUMN_PT_PER_PX, title, |root| {
        t.draw(root, Look::COLUMN, title, metric)
    })
}

/// Draws the rank intervals of `rows` over `n_cases` onto `root` in `look`.
fn draw_ranks<DB: DrawingBackend>(
    root: &Area<DB>,
    look: Look,
    title: &str,
    rows: &[RankRow],
    n_cases: usize,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (width, _) = root.dim_in_pixel();
    let xr = (0.5, n_cases as f64 + 0.5);
    let clamp = |v: f64| v.clamp(1.0, n_cases as f64);
    let left = label_width(rows.iter().map(|r| r.label.as_str()), width, look);
    let ticks = n_cases.min((20.0 / look.k).round() as usize);
    let integer = |v: &f64| {
        if (v - v.round()).abs() < 1e-9 && *v >= 1.0 {
            format!("{:.0}", v)
        } else {
            String::new()
        }
    };
    root.fill(&WHITE)?;
    let body = titled(root, title, 20, look)?;
    let n = rows.len();
    let mut chart = ChartBuilder::on(&body)
        .margin(look.px(10))
        .margin_left(left)
        .x_label_area_size(look.px(45))
        .build_cartesian_2d(xr.0..xr.1, 0.0..n as f64)?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .disable_y_axis()
        .x_labels(ticks)
        .x_label_formatter(&integer)
        .x_desc(RANK_DESC)
        .label_style((FONT, look.font(TICK_FONT)))
        .axis_desc_style((
            FONT,
            look.fit_font(DESC_FONT, &[(RANK_DESC, width as i32 - 20)]),
        ))
        .draw()?;
    for (k, r) in rows.iter().enumerate() {
        let y = row_y(k, n);
        row_label(root, chart.backend_coord(&(xr.0, y)), &r.label, look)?;
        let rgb = if r.highlight {
            Colour::Palette(1).rgb()
        } else {
            PLAIN_RGB
        };
        if r.p05.is_finite() && r.p95.is_finite() {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(clamp(r.p05), y), (clamp(r.p95), y)],
                rgb.stroke_width(look.px(4)),
            )))?;
        }
        if r.p50.is_finite() {
            chart.draw_series(std::iter::once(Circle::new(
                (clamp(r.p50), y),
                look.px(6),
                rgb.filled(),
            )))?;
        }
    }
    Ok(())
}

fn check_cases(title: &str, n_cases: usize) -> Result<()> {
    if n_cases == 0 {
        return Err(ReportError::InvalidFigure {
            figure: title.to_owned(),
            detail: "n_cases must be at least 1".to_owned(),
        });
    }
    Ok(())
}

/// Rank intervals: one row per design in the given order (top to bottom), a line from its
/// rank's 5 % to 95 % quantile and a dot at the median, on a rank axis from 1 (best, left) to
/// `n_cases`; highlighted rows in the accent colour, others dark grey. Non-finite quantiles
/// are left out (a row without a finite median shows only its label); values are clamped to
/// the axis.
///
/// Errors ([`ReportError::InvalidFigure`]) without rows, with `n_cases = 0`, or with more rows
/// than fit on a 20000 px canvas.
pub fn rank_interval_svg(title: &str, rows: &[RankRow], n_cases: usize) -> Result<String> {
    let size = size_for(title, rows.len(), WIDTH, Look::SCREEN)?;
    check_cases(title, n_cases)?;
    render_to_svg(size, title, |root| {
        draw_ranks(root, Look::SCREEN, title, rows, n_cases)
    })
}

/// [`rank_interval_svg`] as a PDF at a paper's column width (as [`tornado_pdf`]).
pub fn rank_interval_pdf(title: &str, rows: &[RankRow], n_cases: usize) -> Result<Vec<u8>> {
    let size = size_for(title, rows.len(), COLUMN_PX, Look::COLUMN)?;
    check_cases(title, n_cases)?;
    render_to_pdf(size, COLUMN_PT_PER_PX, title, |root| {
        draw_ranks(root, Look::COLUMN, title, rows, n_cases)
    })
}

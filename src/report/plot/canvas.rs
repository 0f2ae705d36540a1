//! Drawing plumbing shared by figures and heat maps: the SVG and PDF canvases, fonts, the
//! [`Look`] of a rendering (screen or paper column), and the rules that turn data bounds into
//! finite, non-degenerate axis ranges.

use plotters::coord::Shift;
use plotters::element::Text;
use plotters::prelude::{DrawingArea, DrawingBackend, IntoDrawingArea, SVGBackend};
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{IntoFont, TextStyle};

use super::pdf_backend::PdfBackend;
use crate::report::error::{ReportError, Result};
use crate::report::pdf::PdfPage;
use crate::report::pdf_fonts::text_width;

/// A drawing area on a canvas of backend `DB` (SVG or PDF).
pub(super) type Area<DB> = DrawingArea<DB, Shift>;
/// The result of a drawing step (plotters' errors, boxed).
pub(super) type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// The font family of every text element.
pub(super) const FONT: &str = "sans-serif";
/// Font sizes as given to plotters, which writes them into the SVG divided by 1.24: tick
/// labels and legends 14 (11.3 px), axis titles 15 (12.1 px) — readable at 100 % zoom.
pub(super) const TICK_FONT: u32 = 14;
/// Axis titles (see [`TICK_FONT`]).
pub(super) const DESC_FONT: u32 = 15;

/// The width of a figure drawn for a paper's single column [px]: drawn at
/// [`COLUMN_PT_PER_PX`] it is 252 pt (3.5 in) wide.
pub const COLUMN_PX: u32 = 504;
/// Points a pixel of a column-width figure: a one-pixel line is 0.5 pt, the thinnest drawn.
pub const COLUMN_PT_PER_PX: f64 = 0.5;

/// How big text and the furniture around plots are drawn, relative to the screen figures:
/// font sizes, label areas, margins and marker radii are multiplied by `k` (font sizes rounded
/// up to whole units, as plotters' chart styles truncate them; lengths rounded to whole
/// pixels), titles are at most `title_max` (plotters' size).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Look {
    /// Factor on font sizes and pixel dimensions.
    pub k: f64,
    /// The largest title font size as given to plotters.
    pub title_max: f64,
}

impl Look {
    /// The SVG figures as they have always been drawn (factor 1, titles unbounded).
    pub const SCREEN: Look = Look {
        k: 1.0,
        title_max: f64::INFINITY,
    };
    /// A paper column ([`COLUMN_PX`] at [`COLUMN_PT_PER_PX`]): ×1.24, so that tick labels of
    /// plotters size 14 become 18 (18 / 1.24 = 14.5 px = 7.3 pt), axis titles 15 → 19 (7.7 pt),
    /// and every title at most 21 (16.9 px = 8.5 pt).
    pub const COLUMN: Look = Look {
        k: 1.24,
        title_max: 21.0,
    };

    /// A font size (plotters' size, a whole number) for a screen size.
    pub fn font(self, size: u32) -> f64 {
        (f64::from(size) * self.k).ceil()
    }

    /// A title font size (plotters' size) for a screen size.
    pub fn title(self, size: u32) -> f64 {
        self.font(size).min(self.title_max)
    }

    /// A length [px] for a screen length.
    pub fn px(self, v: u32) -> u32 {
        (f64::from(v) * self.k).round() as u32
    }

    /// A signed length [px] for a screen length.
    pub fn pxi(self, v: i32) -> i32 {
        (f64::from(v) * self.k).round() as i32
    }

    /// Whether text is fitted to the canvas (the column) rather than drawn as on screen.
    pub fn fits(self) -> bool {
        self.k != 1.0
    }

    /// The font size (plotters' size) of a screen size `size` for texts that must fit
    /// `avail` pixels: on screen [`Look::font`]; at the column shrunk (to whole units) until
    /// the widest text fits, but not below [`MIN_FIT_FONT`] (6 pt).
    pub fn fit_font(self, size: u32, texts: &[(&str, i32)]) -> f64 {
        self.fit_to(self.font(size), texts)
    }

    /// [`Look::fit_font`] from a font size `font` (plotters' size) already in this look.
    pub fn fit_to(self, font: f64, texts: &[(&str, i32)]) -> f64 {
        if !self.fits() {
            return font;
        }
        texts
            .iter()
            .filter(|(t, _)| !t.is_empty())
            .map(|&(t, avail)| (f64::from(avail - 4) / text_width(t) * 1.24).floor())
            .fold(font, f64::min)
            .max(MIN_FIT_FONT)
    }
}

/// The smallest font (plotters' size) text is shrunk to at the column: 15 / 1.24 px × 0.5 =
/// 6 pt.
pub(super) const MIN_FIT_FONT: f64 = 15.0;

/// `text` wrapped at spaces into lines at most `max_em` wide (a longer word stays whole).
fn wrap(text: &str, max_em: f64) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(l) if text_width(&format!("{l} {word}")) <= max_em => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// The lines of a title of screen size `size` over `width` pixels at the column, their font
/// (plotters' size) and line height [px].
fn title_lines(text: &str, size: u32, width: u32, look: Look) -> (Vec<String>, f64, i32) {
    let font = look.title(size);
    let px = font / 1.24;
    let lines = wrap(text, (f64::from(width) - 8.0) / px);
    (lines, font, (px * 1.2).ceil() as i32)
}

/// The height [px] a title of screen size `size` takes over `width` pixels at the column
/// (0 without a title).
pub(super) fn title_height(text: &str, size: u32, width: u32, look: Look) -> u32 {
    let (lines, _, step) = title_lines(text, size, width, look);
    if lines.is_empty() {
        return 0;
    }
    (8 + step * lines.len() as i32) as u32
}

/// Writes the title `text` (screen size `size`) over `root` and returns the area under it: on
/// screen plotters' one centred line; at the column wrapped into centred lines that fit.
pub(super) fn titled<DB: DrawingBackend>(
    root: &Area<DB>,
    text: &str,
    size: u32,
    look: Look,
) -> std::result::Result<Area<DB>, Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    if !look.fits() {
        return Ok(root.titled(text, (FONT, look.title(size)))?);
    }
    let (w, _) = root.dim_in_pixel();
    let (lines, font, step) = title_lines(text, size, w, look);
    let style = TextStyle::from((FONT, font).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
    for (k, line) in lines.iter().enumerate() {
        root.draw(&Text::new(
            line.clone(),
            (w as i32 / 2, 4 + step * k as i32),
            style.clone(),
        ))?;
    }
    let used = title_height(text, size, w, look) as i32;
    Ok(root.split_vertically(used).1)
}

/// A canvas size outside 50..=20000 px on a side.
#[derive(Debug, thiserror::Error)]
#[error("size {}×{} px must be within 50..=20000", .0.0, .0.1)]
pub(super) struct BadSize(pub (u32, u32));

/// `Err` unless both sides of `size` are within 50..=20000 px.
pub(super) fn check_size(size: (u32, u32)) -> std::result::Result<(), BadSize> {
    if size.0 < 50 || size.1 < 50 || size.0 > 20_000 || size.1 > 20_000 {
        return Err(BadSize(size));
    }
    Ok(())
}

fn plot_error(title: &str, e: &dyn std::error::Error) -> ReportError {
    ReportError::Plot {
        figure: title.to_string(),
        message: e.to_string(),
    }
}

/// Draw onto a fresh SVG canvas of `size` pixels and return the document; drawing errors
/// become [`ReportError::Plot`] naming the figure `title`.
pub(super) fn render_to_svg(
    size: (u32, u32),
    title: &str,
    draw: impl FnOnce(&Area<SVGBackend<'_>>) -> DrawResult,
) -> Result<String, ReportError> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size).into_drawing_area();
        draw(&root)
            .and_then(|()| root.present().map_err(Into::into))
            .map_err(|e| plot_error(title, &*e))?;
    }
    Ok(buf)
}

/// Draw onto a fresh PDF page of `size` pixels at `scale` points a pixel and return the
/// document (its information dictionary titled `title`); errors as [`render_to_svg`]'s, or
/// [`ReportError::Pdf`] for a page too large.
pub(super) fn render_to_pdf(
    size: (u32, u32),
    scale: f64,
    title: &str,
    draw: impl FnOnce(&Area<PdfBackend<'_>>) -> DrawResult,
) -> Result<Vec<u8>, ReportError> {
    let pdf_error = |source| ReportError::Pdf {
        figure: title.to_string(),
        source,
    };
    let mut page =
        PdfPage::new(f64::from(size.0) * scale, f64::from(size.1) * scale).map_err(pdf_error)?;
    {
        let root = PdfBackend::new(&mut page, size, scale).into_drawing_area();
        draw(&root)
            .and_then(|()| root.present().map_err(Into::into))
            .map_err(|e| plot_error(title, &*e))?;
    }
    Ok(page.finish(title))
}

/// Finite (x, y) pairs.
pub(super) fn finite_points<'a>(
    x: &'a [f64],
    y: &'a [f64],
) -> impl Iterator<Item = (f64, f64)> + 'a {
    x.iter()
        .zip(y)
        .map(|(&a, &b)| (a, b))
        .filter(|(a, b)| a.is_finite() && b.is_finite())
}

/// Largest magnitude used for automatic ranges, so that widths and paddings stay finite.
pub(super) const LIMIT: f64 = f64::MAX / 8.0;

/// Smallest range width used: spreads below it are drawn as constant data.
const TINY: f64 = 1e-300;

/// A drawable range from data bounds: padded by 5 % (or made non-degenerate), finite.
pub(super) fn auto_range(bounds: Option<(f64, f64)>) -> (f64, f64) {
    let Some((lo, hi)) = bounds else {
        return (0.0, 1.0);
    };
    let (lo, hi) = (lo.clamp(-LIMIT, LIMIT), hi.clamp(-LIMIT, LIMIT));
    let pad = 0.05 * (hi - lo);
    widen((lo - pad, hi + pad))
}

/// Makes a range wide enough for plotters' tick computation: at least 1e-9 relative to its
/// magnitude and at least [`TINY`] (an empty range around 0 becomes `[-0.5, 0.5]`).
pub(super) fn widen((lo, hi): (f64, f64)) -> (f64, f64) {
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

pub(super) fn bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

pub(super) fn merge_bounds(a: Option<(f64, f64)>, b: Option<(f64, f64)>) -> Option<(f64, f64)> {
    match (a, b) {
        (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
        (a, None) => a,
        (None, b) => b,
    }
}

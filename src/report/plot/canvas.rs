//! Drawing plumbing shared by figures and heat maps: the SVG canvas, fonts, and the rules that
//! turn data bounds into finite, non-degenerate axis ranges.

use plotters::coord::Shift;
use plotters::prelude::{DrawingArea, IntoDrawingArea, SVGBackend};

use crate::report::error::{ReportError, Result};

/// A drawing area on an SVG canvas.
pub(super) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
/// The result of a drawing step (plotters' errors, boxed).
pub(super) type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// The font family of every text element.
pub(super) const FONT: &str = "sans-serif";
/// Font sizes as given to plotters, which writes them into the SVG divided by 1.24: tick
/// labels and legends 14 (11.3 px), axis titles 15 (12.1 px) — readable at 100 % zoom.
pub(super) const TICK_FONT: u32 = 14;
/// Axis titles (see [`TICK_FONT`]).
pub(super) const DESC_FONT: u32 = 15;

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

/// Draw onto a fresh SVG canvas of `size` pixels and return the document; drawing errors
/// become [`ReportError::Plot`] naming the figure `title`.
pub(super) fn render_to_svg(
    size: (u32, u32),
    title: &str,
    draw: impl FnOnce(&Area<'_>) -> DrawResult,
) -> Result<String, ReportError> {
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

//! Data-driven SVG figures (plotters, SVG backend, no font files).
//!
//! A [`Figure`] is a grid of [`Panel`]s, each holding [`Series`] of `(x, y)` data drawn as
//! lines, markers or bars. [`histogram`] and [`scatter_labelled`] build common figures;
//! [`Heatmap`] draws a grid of cells with a colour bar; [`tornado_svg`] and
//! [`rank_interval_svg`] draw sensitivity measures and rank intervals over uncertain worlds.
//!
//! Rendering rules, whatever the input:
//! - non-finite values (NaN, ±inf) are skipped; a line breaks at them;
//! - empty series and empty panels are drawn as empty axes on `[0, 1]`;
//! - degenerate (constant or single-point) ranges are padded;
//! - lines are clipped to the panel's range, markers outside it are not drawn;
//! - point labels never overlap each other or a marker (a leader line joins a label moved
//!   away from its point);
//! - text is native SVG `<text>` (no font files), and the output depends only on the
//!   specification, so rendering twice gives identical bytes.
//!
//! Files are written atomically (temporary name in the same directory, then rename).
//!
//! Every figure can also be drawn at a paper's column width as a PDF ([`Figure::render_pdf`],
//! [`Heatmap::render_pdf`], [`tornado_pdf`], [`rank_interval_pdf`]): re-drawn on a 504 px
//! canvas with larger text and written through a plotters backend of PDF operators
//! ([`crate::report::pdf`]) at 0.5 pt a pixel — 252 pt wide, text 7.3–8.5 pt.

mod canvas;
mod charts;
mod column;
mod draw;
mod heatmap;
mod labels;
mod pdf_backend;
mod scale;
mod spec;
mod uncertainty;

pub use canvas::{COLUMN_PT_PER_PX, COLUMN_PX};
pub use charts::{histogram, scatter_labelled, LabelledPoint};
pub use column::MIN_PANEL_PX;
pub use heatmap::{heatmap, ColourScale, Heatmap};
pub use scale::Scale;
pub use spec::{Colour, Figure, LineStyle, Panel, PanelKind, Series};
pub use uncertainty::{
    rank_interval_pdf, rank_interval_svg, tornado_pdf, tornado_svg, RankRow, TornadoRow,
};

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_pdf;

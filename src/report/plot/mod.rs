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

mod canvas;
mod charts;
mod draw;
mod heatmap;
mod labels;
mod scale;
mod spec;
mod uncertainty;

pub use charts::{histogram, scatter_labelled, LabelledPoint};
pub use heatmap::{heatmap, ColourScale, Heatmap};
pub use scale::Scale;
pub use spec::{Colour, Figure, LineStyle, Panel, PanelKind, Series};
pub use uncertainty::{rank_interval_svg, tornado_svg, RankRow, TornadoRow};

#[cfg(test)]
mod tests;

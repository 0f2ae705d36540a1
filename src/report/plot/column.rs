//! Figures at a paper's column width, as PDF: the same figure re-drawn (not scaled down) on a
//! canvas [`COLUMN_PX`] = 504 px wide in [`Look::COLUMN`], each pixel [`COLUMN_PT_PER_PX`] =
//! 0.5 pt, so the page is 252 pt (3.5 in) wide: tick labels and legends 7.3 pt, axis titles
//! 7.7 pt, titles 8.5 pt, lines at least 0.5 pt. Scaling the screen SVG (640–1200 px) to 252 pt
//! instead would leave its 11 px text at 2.5–4.4 pt.
//!
//! The height keeps the figure's aspect ratio; a grid of more than two columns is laid out in
//! two (more rows), each panel keeping its aspect ratio, at least [`MIN_PANEL_PX`] high.

use std::path::Path;

use super::canvas::{render_to_pdf, title_height, Look, COLUMN_PT_PER_PX, COLUMN_PX};
use super::draw::draw_figure;
use super::heatmap::Heatmap;
use super::spec::Figure;
use crate::report::atomic::atomic_write;
use crate::report::error::Result;

/// The least height of a panel row of a column-width figure [px] (65 pt).
pub const MIN_PANEL_PX: u32 = 130;
/// The height of a figure's title strip on screen [px] (as [`Figure::grid_layout`] leaves).
const TITLE_PX: u32 = 40;

/// `width` × `height` scaled to [`COLUMN_PX`] wide, its aspect ratio kept.
fn column_size((width, height): (u32, u32)) -> (u32, u32) {
    let h = f64::from(height) * f64::from(COLUMN_PX) / f64::from(width.max(1));
    (COLUMN_PX, (h.round() as u32).max(50))
}

impl Figure {
    /// The figure laid out for a paper's column: [`COLUMN_PX`] wide, at most two panel
    /// columns, its panels' aspect ratio kept.
    pub fn column_layout(&self) -> Figure {
        let mut fig = self.clone();
        let (rows, cols) = self.grid();
        let n = self.panels.len().max(1);
        let new_cols = cols.min(2);
        let new_rows = if new_cols < cols {
            n.div_ceil(new_cols)
        } else {
            rows
        };
        let title = if self.title.is_empty() { 0 } else { TITLE_PX };
        let screen_body = self
            .size
            .1
            .saturating_sub(self.note_height() + title)
            .max(1);
        // A screen panel's height over its width.
        let aspect = (f64::from(screen_body) / rows.max(1) as f64)
            / (f64::from(self.size.0) / cols.max(1) as f64);
        let panel_w = f64::from(COLUMN_PX) / new_cols as f64;
        let panel_h = ((panel_w * aspect).round() as u32).max(MIN_PANEL_PX);
        fig.layout = (new_rows, new_cols);
        fig.size = (COLUMN_PX, 0);
        let title = title_height(&self.title, 22, COLUMN_PX, Look::COLUMN);
        fig.size.1 = panel_h * new_rows as u32 + title + fig.note_height_for(Look::COLUMN);
        fig
    }

    /// Renders the figure at a paper's column width as a PDF document ([`Figure::column_layout`],
    /// 252 pt wide; see the module documentation for the sizes).
    pub fn render_pdf(&self) -> Result<Vec<u8>> {
        self.validate()?;
        let fig = self.column_layout();
        fig.validate()?;
        render_to_pdf(fig.size, COLUMN_PT_PER_PX, &fig.title, |root| {
            draw_figure(&fig, root, Look::COLUMN)
        })
    }

    /// Renders the column-width PDF and writes it to `path` atomically.
    pub fn write_pdf(&self, path: &Path) -> Result<()> {
        atomic_write(path, &self.render_pdf()?)
    }

    /// Writes the SVG to `path` and the column-width PDF beside it (`path` with the extension
    /// `pdf`). The SVG is written first; an error of either is returned.
    pub fn write_svg_pdf(&self, path: &Path) -> Result<()> {
        self.write_svg(path)?;
        self.write_pdf(&path.with_extension("pdf"))
    }
}

impl Heatmap {
    /// Renders the heat map at a paper's column width as a PDF document: 252 pt wide, its
    /// aspect ratio kept.
    pub fn render_pdf(&self) -> Result<Vec<u8>> {
        self.validate()?;
        let (w, h0) = column_size(self.size);
        // The title may wrap: the lines beyond the first are added.
        let one = title_height("x", 22, w, Look::COLUMN);
        let size = (
            w,
            h0 + title_height(&self.title, 22, w, Look::COLUMN).saturating_sub(one),
        );
        let mut h = self.clone();
        h.size = size;
        render_to_pdf(size, COLUMN_PT_PER_PX, &self.title, |root| {
            h.draw(root, Look::COLUMN)
        })
    }

    /// Renders the column-width PDF and writes it to `path` atomically.
    pub fn write_pdf(&self, path: &Path) -> Result<()> {
        atomic_write(path, &self.render_pdf()?)
    }

    /// Writes the SVG to `path` and the column-width PDF beside it (`path` with the extension
    /// `pdf`), as [`Figure::write_svg_pdf`].
    pub fn write_svg_pdf(&self, path: &Path) -> Result<()> {
        self.write_svg(path)?;
        self.write_pdf(&path.with_extension("pdf"))
    }
}

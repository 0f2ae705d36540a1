//! Figure specifications: [`Figure`] is a grid of [`Panel`]s holding [`Series`].

use plotters::prelude::RGBColor;

use super::canvas::{check_size, Look};
use super::scale::Scale;
use crate::report::error::{ReportError, Result};

const GREY_RGB: RGBColor = RGBColor(170, 170, 170);
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
    /// Red, for cases that failed or missed their success criteria.
    Alert,
}

impl Default for Colour {
    fn default() -> Self {
        Colour::Palette(0)
    }
}

impl Colour {
    pub(super) fn rgb(self) -> RGBColor {
        match self {
            Colour::Palette(i) => PALETTE[i % PALETTE.len()],
            Colour::Grey => GREY_RGB,
            Colour::Alert => RGBColor(200, 30, 30),
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
    /// Scale of the x axis (categories, integers, log, …).
    pub x_scale: Scale,
    /// Scale of the y axis.
    pub y_scale: Scale,
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
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
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
    /// A line of text under the panels (e.g. what was left out and why; empty: none).
    pub note: String,
}

impl Figure {
    /// An empty figure, automatic layout, 800 × 600 px.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            panels: Vec::new(),
            layout: (0, 0),
            size: (800, 600),
            note: String::new(),
        }
    }

    /// Adds a panel.
    pub fn with_panel(mut self, panel: Panel) -> Self {
        self.panels.push(panel);
        self
    }

    /// The note wrapped to the figure's width: one string per line (none without a note).
    #[cfg(test)]
    pub(super) fn note_lines(&self) -> Vec<String> {
        self.note_lines_for(Look::SCREEN)
    }

    /// The note wrapped to the figure's width in `look`.
    pub(super) fn note_lines_for(&self, look: Look) -> Vec<String> {
        // About 0.6 em per character of the 12.1 px note font (× the look's factor).
        let per_line = ((self.size.0 as usize).saturating_sub(24) / look.px(7) as usize).max(20);
        let mut lines: Vec<String> = Vec::new();
        for word in self.note.split_whitespace() {
            match lines.last_mut() {
                Some(l) if l.chars().count() + 1 + word.chars().count() <= per_line => {
                    l.push(' ');
                    l.push_str(word);
                }
                _ => lines.push(word.to_string()),
            }
        }
        lines
    }

    /// The height [px] of the strip under the panels that holds the note (0 without one):
    /// add it to the height the panels need.
    pub fn note_height(&self) -> u32 {
        self.note_height_for(Look::SCREEN)
    }

    /// [`Figure::note_height`] in `look` [px].
    pub(super) fn note_height_for(&self, look: Look) -> u32 {
        match self.note_lines_for(look).len() {
            0 => 0,
            n => 8 + look.px(18) * n as u32,
        }
    }

    /// Lay the panels out in a near-square grid of at most `max_cols` columns: 400 px a column
    /// (the width of two at least), `row_height` px a row, 40 px for the title and the note's
    /// strip ([`Figure::note_height`]; set the note first).
    pub fn grid_layout(&mut self, max_cols: u32, row_height: u32) {
        let n = self.panels.len() as u32;
        let cols = ((n as f64).sqrt().ceil() as u32).clamp(1, max_cols.max(1));
        let rows = n.div_ceil(cols).max(1);
        self.layout = (rows as usize, cols as usize);
        // The note wraps at the figure's width: set the width before measuring it.
        self.size = (400 * cols.max(2), row_height * rows + 40);
        self.size.1 += self.note_height();
    }

    pub(super) fn invalid(&self, detail: String) -> ReportError {
        ReportError::InvalidFigure {
            figure: self.title.clone(),
            detail,
        }
    }

    pub(super) fn grid(&self) -> (usize, usize) {
        let n = self.panels.len().max(1);
        if self.layout.0 == 0 || self.layout.1 == 0 {
            let cols = (1..=n).find(|c| c * c >= n).unwrap_or(n);
            (n.div_ceil(cols), cols)
        } else {
            self.layout
        }
    }

    pub(super) fn validate(&self) -> Result<()> {
        check_size(self.size).map_err(|e| self.invalid(e.to_string()))?;
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_measures_its_note_at_the_grid_width() {
        // 120 words of 9 characters: at the default 800 px they wrap into more lines than at the
        // 1200 px of a three-column grid, and the height must follow the final width.
        let mut fig = Figure::new("t");
        for k in 0..9 {
            fig.panels.push(Panel::new(format!("p{k}"), "x", "y"));
        }
        fig.note = vec!["abcdefgh,"; 120].join(" ");
        fig.grid_layout(3, 300);
        assert_eq!(fig.layout, (3, 3));
        assert_eq!(fig.size.0, 1200);
        let lines = fig.note_lines().len() as u32;
        assert_eq!(fig.size.1, 300 * 3 + 40 + 8 + 18 * lines);
        fig.size.0 = 800;
        assert!(fig.note_lines().len() as u32 > lines);
    }
}

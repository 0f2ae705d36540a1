//! [`Heatmap`]: a grid of coloured cells with a colour bar.

use std::path::Path;

use plotters::prelude::{ChartBuilder, DrawingBackend, RGBColor, Rectangle, WHITE};
use plotters::style::Color;

use super::canvas::{
    auto_range, bounds, check_size, render_to_svg, titled, widen, Area, DrawResult, Look,
    DESC_FONT, FONT, LIMIT, TICK_FONT,
};
use super::scale::Scale;
use crate::report::atomic::atomic_write;
use crate::report::error::{ReportError, Result};

const NAN_CELL_RGB: RGBColor = RGBColor(200, 200, 200);

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
    /// Scale of the x axis: [`Scale::Categories`] names the cells (`x` must then be `0, 1, …`),
    /// [`Scale::Integer`] prints whole numbers.
    pub x_scale: Scale,
    /// Scale of the y axis.
    pub y_scale: Scale,
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
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
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

    pub(super) fn validate(&self) -> Result<()> {
        check_size(self.size).map_err(|e| self.invalid(e.to_string()))?;
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
    pub fn render_svg(&self) -> Result<String, ReportError> {
        self.validate()?;
        render_to_svg(self.size, &self.title, |root| self.draw(root, Look::SCREEN))
    }

    /// Renders the heat map and writes it to `path` atomically.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        atomic_write(path, self.render_svg()?.as_bytes())
    }

    /// Draws the heat map onto `root` in `look`.
    pub(super) fn draw<DB: DrawingBackend>(&self, root: &Area<DB>, look: Look) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let body = if self.title.is_empty() {
            root.clone()
        } else {
            titled(root, &self.title, 22, look)?
        };
        let bar_width = look.pxi(110).min(self.size.0 as i32 / 3);
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
        let (mw, mh) = main.dim_in_pixel();
        let desc_font = look.fit_font(
            DESC_FONT,
            &[
                (&self.x_label, mw as i32 - look.pxi(98)),
                (&self.y_label, mh as i32 - look.pxi(70)),
            ],
        );
        let mut chart = ChartBuilder::on(&main)
            .margin(look.px(10))
            .x_label_area_size(look.px(50))
            .y_label_area_size(look.px(78))
            .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
        let x_fmt = |v: &f64| self.x_scale.label(*v);
        let y_fmt = |v: &f64| self.y_scale.label(*v);
        let mut mesh = chart.configure_mesh();
        mesh.disable_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .label_style((FONT, look.font(TICK_FONT)))
            .axis_desc_style((FONT, desc_font));
        let ticks = (10.0 / look.k).round() as usize;
        mesh.x_labels(self.x_scale.tick_count(xr, ticks))
            .y_labels(self.y_scale.tick_count(yr, ticks))
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt);
        mesh.draw()?;
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
            .margin_top(look.px(10))
            .margin_bottom(look.px(10))
            .margin_right(look.px(5))
            .caption(caption, (FONT, look.font(TICK_FONT)))
            .x_label_area_size(look.px(45))
            .y_label_area_size(look.px(72))
            .build_cartesian_2d(0.0..1.0, zr.0..zr.1)?;
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_label_formatter(&|v| Scale::Linear.label(*v))
            .y_desc(self.z_label.as_str())
            .label_style((FONT, look.font(TICK_FONT)))
            .axis_desc_style((FONT, look.font(DESC_FONT)))
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

//! A plotters drawing backend that writes a PDF page ([`crate::report::pdf::PdfPage`]).
//!
//! plotters draws in integer pixels with y down; the backend maps a pixel to `scale` points
//! with y up (the page is `size × scale` points). It writes what the SVG backend writes, as
//! PDF operators: lines and polylines (stroke width in pixels, at least 0.5 pt), rectangles
//! (outlines 1 px wide, as SVG's default), filled polygons, circles, and text placed as the
//! SVG backend places it — anchored left, centre or right by its Helvetica/Symbol width,
//! the baseline 0.76 em under a top anchor and ½ x-height (0.523 em) off a centre or bottom
//! anchor, turned by 90°, 180° or 270° about its anchor. The font size is plotters' size
//! divided by 1.24, as in the SVG. Text sizes for layout are plotters' own estimate, the same
//! as for the SVG, so both files have one layout.

use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    FontTransform,
};

use crate::report::error::PdfError;
use crate::report::pdf::PdfPage;
use crate::report::pdf_fonts::text_width;

/// The thinnest line drawn [pt].
pub(super) const MIN_LINE_PT: f64 = 0.5;

/// Half the x-height of Helvetica [em] (its AFM `XHeight` 523): the SVG backend's `0.5ex`.
const HALF_EX: f64 = 0.2615;

/// A plotters backend drawing onto one PDF page.
pub(super) struct PdfBackend<'a> {
    size: (u32, u32),
    scale: f64,
    page: &'a mut PdfPage,
}

impl<'a> PdfBackend<'a> {
    /// A backend of `size` pixels drawn onto `page` at `scale` points a pixel (the page
    /// should be `size × scale` points).
    pub(super) fn new(page: &'a mut PdfPage, size: (u32, u32), scale: f64) -> Self {
        PdfBackend { size, scale, page }
    }

    /// A pixel position as a page position [pt].
    fn pt(&self, (x, y): (f64, f64)) -> (f64, f64) {
        (x * self.scale, (f64::from(self.size.1) - y) * self.scale)
    }

    fn pti(&self, p: BackendCoord) -> (f64, f64) {
        self.pt((f64::from(p.0), f64::from(p.1)))
    }

    fn line_pt(&self, px: u32) -> f64 {
        (f64::from(px) * self.scale).max(MIN_LINE_PT)
    }
}

fn rgb(c: BackendColor) -> (u8, u8, u8) {
    c.rgb
}

type Res = Result<(), DrawingErrorKind<PdfError>>;

impl DrawingBackend for PdfBackend<'_> {
    type ErrorType = PdfError;

    fn get_size(&self) -> (u32, u32) {
        self.size
    }

    fn ensure_prepared(&mut self) -> Res {
        Ok(())
    }

    fn present(&mut self) -> Res {
        Ok(())
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Res {
        let (x, y) = self.pti((point.0, point.1 + 1));
        self.page.rect(
            (x, y, self.scale, self.scale),
            rgb(color),
            color.alpha,
            true,
            0.0,
        );
        Ok(())
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Res {
        let w = self.line_pt(style.stroke_width());
        let pts = [self.pti(from), self.pti(to)];
        self.page
            .stroke_path(&pts, rgb(style.color()), style.color().alpha, w);
        Ok(())
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Res {
        let (x0, y1) = self.pti(upper_left);
        let (x1, y0) = self.pti(bottom_right);
        let line = self.line_pt(1);
        self.page.rect(
            (x0, y0, x1 - x0, y1 - y0),
            rgb(style.color()),
            style.color().alpha,
            fill,
            line,
        );
        Ok(())
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Res {
        let pts: Vec<(f64, f64)> = path.into_iter().map(|p| self.pti(p)).collect();
        let w = self.line_pt(style.stroke_width());
        self.page
            .stroke_path(&pts, rgb(style.color()), style.color().alpha, w);
        Ok(())
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Res {
        let c = self.pti(center);
        let line = self.line_pt(style.stroke_width());
        self.page.circle(
            c,
            f64::from(radius) * self.scale,
            rgb(style.color()),
            style.color().alpha,
            fill,
            line,
        );
        Ok(())
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Res {
        let pts: Vec<(f64, f64)> = vert.into_iter().map(|p| self.pti(p)).collect();
        self.page
            .fill_polygon(&pts, rgb(style.color()), style.color().alpha);
        Ok(())
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Res {
        let color = style.color();
        if color.alpha == 0.0 || text.is_empty() {
            return Ok(());
        }
        // Font size in pixels, as the SVG backend writes it.
        let px = style.size() / 1.24;
        let width = text_width(text) * px;
        let dx = match style.anchor().h_pos {
            HPos::Left => 0.0,
            HPos::Center => -0.5 * width,
            HPos::Right => -width,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0.76 * px,
            VPos::Center => HALF_EX * px,
            VPos::Bottom => -HALF_EX * px,
        };
        // Clockwise turn on the screen (SVG's rotate), in radians.
        let turn = match style.transform() {
            FontTransform::Rotate90 => 90.0_f64,
            FontTransform::Rotate180 => 180.0,
            FontTransform::Rotate270 => 270.0,
            _ => 0.0,
        }
        .to_radians();
        let (s, c) = turn.sin_cos();
        // Along the text (c, s) and down its glyphs (−s, c), in screen pixels.
        let x = f64::from(pos.0) + dx * c - dy * s;
        let y = f64::from(pos.1) + dx * s + dy * c;
        let origin = self.pt((x, y));
        // Counter-clockwise on the page (y up) is clockwise on the screen negated.
        self.page.text(
            text,
            origin,
            px * self.scale,
            -turn,
            rgb(color),
            color.alpha,
        );
        Ok(())
    }
}

//! A small PDF 1.4 writer for one-page vector figures.
//!
//! A [`PdfPage`] collects content-stream operators in points (origin at the bottom left, y
//! up): stroked and filled paths, rectangles and text in the standard fonts Helvetica
//! (WinAnsiEncoding) and Symbol, neither embedded ([`super::pdf_fonts`]). Transparency uses
//! one `ExtGState` per opacity. [`PdfPage::finish`] writes the document: catalog, page tree,
//! one page, the two fonts, the uncompressed content stream, an information dictionary with
//! the title, and a cross-reference table with the byte offset of every object.
//!
//! The bytes depend only on what was drawn: no dates, no random identifiers (the trailer has
//! no `/ID`), numbers written with at most three decimals.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::error::PdfError;
use super::pdf_fonts::{encode, PdfFont, Run};

/// The largest page side PDF viewers accept [pt] (200 in).
pub const MAX_PAGE_PT: f64 = 14_400.0;

/// A number as PDF writes it: at most three decimals, no exponent, no `-0`; non-finite
/// values as 0.
pub fn num(v: f64) -> String {
    if !v.is_finite() {
        return "0".to_owned();
    }
    let r = (v * 1000.0).round() / 1000.0;
    let mut s = format!("{r:.3}");
    while s.ends_with('0') {
        s.pop();
    }
    if s.ends_with('.') {
        s.pop();
    }
    if s == "-0" {
        s = "0".to_owned();
    }
    s
}

/// An RGB colour with components in 0..=255.
pub type Rgb = (u8, u8, u8);

fn rgb_ops(c: Rgb) -> String {
    let f = |v: u8| num(f64::from(v) / 255.0);
    format!("{} {} {}", f(c.0), f(c.1), f(c.2))
}

/// One page being drawn: its size [pt] and content stream.
#[derive(Debug, Clone)]
pub struct PdfPage {
    width: f64,
    height: f64,
    content: String,
    /// Opacities in use, in thousandths (one `ExtGState` each).
    alphas: BTreeSet<u16>,
}

impl PdfPage {
    /// A blank page of `width` × `height` points; both must be finite, positive and at most
    /// [`MAX_PAGE_PT`].
    pub fn new(width: f64, height: f64) -> Result<Self, PdfError> {
        let ok = |v: f64| (1.0..=MAX_PAGE_PT).contains(&v);
        if !(ok(width) && ok(height)) {
            return Err(PdfError::BadPage { width, height });
        }
        Ok(PdfPage {
            width,
            height,
            content: String::new(),
            alphas: BTreeSet::new(),
        })
    }

    /// The page width [pt].
    pub fn width(&self) -> f64 {
        self.width
    }

    /// The page height [pt].
    pub fn height(&self) -> f64 {
        self.height
    }

    /// Opens a graphics state with opacity `alpha` (0..=1) when it is below 1; the caller
    /// closes it with [`Self::end_alpha`] given the same value.
    fn begin_alpha(&mut self, alpha: f64) {
        let milli = (alpha.clamp(0.0, 1.0) * 1000.0).round() as u16;
        if milli < 1000 {
            self.alphas.insert(milli);
            let _ = writeln!(self.content, "q /GA{milli} gs");
        }
    }

    fn end_alpha(&mut self, alpha: f64) {
        if (alpha.clamp(0.0, 1.0) * 1000.0).round() < 1000.0 {
            self.content.push_str("Q\n");
        }
    }

    /// Strokes the open polyline through `points` [pt] with `colour`, opacity `alpha` and
    /// line `width` [pt]. Fewer than two points draw nothing.
    pub fn stroke_path(&mut self, points: &[(f64, f64)], colour: Rgb, alpha: f64, width: f64) {
        if points.len() < 2 || alpha <= 0.0 {
            return;
        }
        self.begin_alpha(alpha);
        let _ = write!(self.content, "{} w {} RG", num(width), rgb_ops(colour));
        for (k, p) in points.iter().enumerate() {
            let op = if k == 0 { "m" } else { "l" };
            let _ = write!(self.content, " {} {} {op}", num(p.0), num(p.1));
        }
        self.content.push_str(" S\n");
        self.end_alpha(alpha);
    }

    /// Fills the closed polygon through `points` [pt] (non-zero winding). Fewer than three
    /// points draw nothing.
    pub fn fill_polygon(&mut self, points: &[(f64, f64)], colour: Rgb, alpha: f64) {
        if points.len() < 3 || alpha <= 0.0 {
            return;
        }
        self.begin_alpha(alpha);
        let _ = write!(self.content, "{} rg", rgb_ops(colour));
        for (k, p) in points.iter().enumerate() {
            let op = if k == 0 { "m" } else { "l" };
            let _ = write!(self.content, " {} {} {op}", num(p.0), num(p.1));
        }
        self.content.push_str(" h f\n");
        self.end_alpha(alpha);
    }

    /// A rectangle with lower-left corner `(x, y)` and size `w` × `h` [pt], filled, or
    /// stroked with line width `line` [pt] when `fill` is false.
    pub fn rect(
        &mut self,
        (x, y, w, h): (f64, f64, f64, f64),
        colour: Rgb,
        alpha: f64,
        fill: bool,
        line: f64,
    ) {
        if alpha <= 0.0 {
            return;
        }
        self.begin_alpha(alpha);
        let rect = format!("{} {} {} {} re", num(x), num(y), num(w), num(h));
        if fill {
            let _ = writeln!(self.content, "{} rg {rect} f", rgb_ops(colour));
        } else {
            let _ = writeln!(
                self.content,
                "{} w {} RG {rect} S",
                num(line),
                rgb_ops(colour)
            );
        }
        self.end_alpha(alpha);
    }

    /// A circle of `radius` about `centre` [pt] (four Bézier arcs), filled or stroked with
    /// line width `line` [pt].
    pub fn circle(
        &mut self,
        centre: (f64, f64),
        radius: f64,
        colour: Rgb,
        alpha: f64,
        fill: bool,
        line: f64,
    ) {
        if alpha <= 0.0 || radius.is_nan() || radius <= 0.0 {
            return;
        }
        // Control-point distance of a quarter circle.
        const K: f64 = 0.552_284_75;
        let (cx, cy, r) = (centre.0, centre.1, radius);
        let k = K * r;
        self.begin_alpha(alpha);
        let paint = if fill {
            format!("{} rg", rgb_ops(colour))
        } else {
            format!("{} w {} RG", num(line), rgb_ops(colour))
        };
        let p = |x: f64, y: f64| format!("{} {}", num(x), num(y));
        let _ = writeln!(
            self.content,
            "{paint} {} m {} {} {} c {} {} {} c {} {} {} c {} {} {} c {}",
            p(cx + r, cy),
            p(cx + r, cy + k),
            p(cx + k, cy + r),
            p(cx, cy + r),
            p(cx - k, cy + r),
            p(cx - r, cy + k),
            p(cx - r, cy),
            p(cx - r, cy - k),
            p(cx - k, cy - r),
            p(cx, cy - r),
            p(cx + k, cy - r),
            p(cx + r, cy - k),
            p(cx + r, cy),
            if fill { "f" } else { "S" }
        );
        self.end_alpha(alpha);
    }

    /// Writes `text` with its baseline starting at `origin` [pt], in `size` [pt], turned
    /// counter-clockwise by `angle` (radians), in `colour`. The fonts are chosen per
    /// character ([`encode`]).
    pub fn text(
        &mut self,
        text: &str,
        origin: (f64, f64),
        size: f64,
        angle: f64,
        colour: Rgb,
        alpha: f64,
    ) {
        let runs = encode(text);
        if runs.is_empty() || alpha <= 0.0 || size.is_nan() || size <= 0.0 {
            return;
        }
        let (s, c) = angle.sin_cos();
        self.begin_alpha(alpha);
        let _ = write!(
            self.content,
            "BT {} rg {} {} {} {} {} {} Tm",
            rgb_ops(colour),
            num(c),
            num(s),
            num(-s),
            num(c),
            num(origin.0),
            num(origin.1)
        );
        for Run { font, codes } in &runs {
            let name = match font {
                PdfFont::Helvetica => "F1",
                PdfFont::Symbol => "F2",
            };
            let _ = write!(
                self.content,
                " /{name} {} Tf ({}) Tj",
                num(size),
                literal(codes)
            );
        }
        self.content.push_str(" ET\n");
        self.end_alpha(alpha);
    }

    /// The document: a PDF 1.4 file of this one page, `title` in its information dictionary.
    pub fn finish(self, title: &str) -> Vec<u8> {
        let mut gs = String::new();
        for a in &self.alphas {
            let v = num(f64::from(*a) / 1000.0);
            let _ = write!(gs, " /GA{a} << /Type /ExtGState /ca {v} /CA {v} >>");
        }
        let page = format!(
            "<< /Type /Page /Parent 2 0 R /MediaBox [0 0 {} {}] /Resources << /Font << /F1 4 0 R \
             /F2 5 0 R >> /ExtGState <<{gs} >> >> /Contents 6 0 R >>",
            num(self.width),
            num(self.height)
        );
        let stream = format!(
            "<< /Length {} >>\nstream\n{}endstream",
            self.content.len(),
            self.content
        );
        let objects = [
            "<< /Type /Catalog /Pages 2 0 R >>".to_owned(),
            "<< /Type /Pages /Kids [3 0 R] /Count 1 >>".to_owned(),
            page,
            "<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica /Encoding /WinAnsiEncoding >>"
                .to_owned(),
            "<< /Type /Font /Subtype /Type1 /BaseFont /Symbol >>".to_owned(),
            stream,
            format!("<< /Title {} /Creator (usm-study) >>", utf16_string(title)),
        ];
        let mut out: Vec<u8> = b"%PDF-1.4\n%\xE2\xE3\xCF\xD3\n".to_vec();
        let mut offsets = Vec::with_capacity(objects.len());
        for (k, body) in objects.iter().enumerate() {
            offsets.push(out.len());
            out.extend_from_slice(format!("{} 0 obj\n{body}\nendobj\n", k + 1).as_bytes());
        }
        let xref = out.len();
        let mut tail = format!("xref\n0 {}\n0000000000 65535 f \n", objects.len() + 1);
        for o in &offsets {
            let _ = writeln!(tail, "{o:010} 00000 n ");
        }
        let _ = write!(
            tail,
            "trailer\n<< /Size {} /Root 1 0 R /Info {} 0 R >>\nstartxref\n{xref}\n%%EOF\n",
            objects.len() + 1,
            objects.len()
        );
        out.extend_from_slice(tail.as_bytes());
        out
    }
}

/// A PDF literal string of `codes`: parentheses and backslashes escaped, bytes outside
/// printable ASCII as octal escapes (the content stream stays ASCII).
fn literal(codes: &[u8]) -> String {
    let mut s = String::with_capacity(codes.len());
    for &b in codes {
        match b {
            b'(' | b')' | b'\\' => {
                s.push('\\');
                s.push(char::from(b));
            }
            32..=126 => s.push(char::from(b)),
            _ => {
                let _ = write!(s, "\\{b:03o}");
            }
        }
    }
    s
}

/// A text string of the information dictionary: UTF-16BE with its byte-order mark, in hex.
fn utf16_string(text: &str) -> String {
    let mut s = String::from("<FEFF");
    for u in text.encode_utf16() {
        let _ = write!(s, "{u:04X}");
    }
    s.push('>');
    s
}

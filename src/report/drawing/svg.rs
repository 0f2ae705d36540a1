//! A tiny SVG writer: elements with attributes, escaped text, numbers with a fixed number of
//! decimals. Hand-written instead of plotters' backend because the drawing needs stable ids,
//! classes and `data-*` attributes on its elements (tests and the later HTML report address
//! them) and exact control over every coordinate; the bytes depend only on the input.

use std::fmt::Write;

/// An attribute value: text (escaped when written) or a number (two decimals, `-0` as `0`).
#[derive(Clone, Debug)]
pub enum Attr {
    /// Text, escaped for XML.
    Text(String),
    /// A coordinate or length in SVG user units (px).
    Num(f64),
}

impl From<&str> for Attr {
    fn from(s: &str) -> Self {
        Attr::Text(s.to_string())
    }
}

impl From<String> for Attr {
    fn from(s: String) -> Self {
        Attr::Text(s)
    }
}

impl From<f64> for Attr {
    fn from(x: f64) -> Self {
        Attr::Num(x)
    }
}

/// `x` with two decimals, never `-0.00`: SVG coordinates in px, deterministic.
pub fn num(x: f64) -> String {
    let s = format!("{x:.2}");
    if s == "-0.00" {
        "0.00".into()
    } else {
        s
    }
}

/// `s` escaped for XML text and attribute values.
pub fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c => o.push(c),
        }
    }
    o
}

/// An SVG document being written, one element per line.
#[derive(Debug, Default)]
pub struct Svg {
    out: String,
    depth: usize,
}

impl Svg {
    /// A document of `width` × `height` px with a white background; `style` is the inline
    /// style sheet (no external resources).
    pub fn new(width: f64, height: f64, style: &str) -> Self {
        let mut s = Svg::default();
        s.out
            .push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        s.open(
            "svg",
            &[
                ("xmlns", "http://www.w3.org/2000/svg".into()),
                ("width", width.into()),
                ("height", height.into()),
                (
                    "viewBox",
                    format!("0 0 {} {}", num(width), num(height)).into(),
                ),
            ],
        );
        s.line(&format!("<style>{style}</style>"));
        s.empty(
            "rect",
            &[
                ("x", 0.0.into()),
                ("y", 0.0.into()),
                ("width", width.into()),
                ("height", height.into()),
                ("fill", "#fff".into()),
            ],
        );
        s
    }

    fn line(&mut self, text: &str) {
        for _ in 0..self.depth {
            self.out.push(' ');
        }
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn tag(name: &str, attrs: &[(&str, Attr)]) -> String {
        let mut t = format!("<{name}");
        for (k, v) in attrs {
            let v = match v {
                Attr::Text(s) => escape(s),
                Attr::Num(x) => num(*x),
            };
            let _ = write!(t, " {k}=\"{v}\"");
        }
        t
    }

    /// Opens `<name …>`; close it with [`Svg::close`].
    pub fn open(&mut self, name: &str, attrs: &[(&str, Attr)]) {
        let t = Self::tag(name, attrs);
        self.line(&format!("{t}>"));
        self.depth += 1;
    }

    /// Closes the innermost open element `name`.
    pub fn close(&mut self, name: &str) {
        self.depth = self.depth.saturating_sub(1);
        self.line(&format!("</{name}>"));
    }

    /// An element without children, `<name …/>`.
    pub fn empty(&mut self, name: &str, attrs: &[(&str, Attr)]) {
        let t = Self::tag(name, attrs);
        self.line(&format!("{t}/>"));
    }

    /// A `<text>` element holding `content` (escaped).
    pub fn text(&mut self, attrs: &[(&str, Attr)], content: &str) {
        let t = Self::tag("text", attrs);
        self.line(&format!("{t}>{}</text>", escape(content)));
    }

    /// The finished document.
    pub fn finish(mut self) -> String {
        self.close("svg");
        self.out
    }
}

#[cfg(test)]
mod tests {
    use crate::report::drawing::svg::*;

    #[test]
    fn numbers_and_text_are_stable() {
        assert_eq!(num(-0.001), "0.00");
        assert_eq!(num(1.005e3), "1005.00");
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        let mut s = Svg::new(10.0, 5.0, "");
        s.text(&[("x", 1.0.into())], "T<1>");
        let doc = s.finish();
        assert!(doc.contains("<text x=\"1.00\">T&lt;1&gt;</text>"), "{doc}");
        assert!(doc.ends_with("</svg>\n"));
    }
}

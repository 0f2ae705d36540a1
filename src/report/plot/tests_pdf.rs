//! Tests of the column-width PDFs: the file's structure read back (cross-reference offsets,
//! one page, its MediaBox, the fonts), determinism, text sizes and the SVGs left alone.

use super::*;
use crate::report::pdf_fonts::{encode, text_width, PdfFont};

fn figure() -> Figure {
    let x: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
    let y: Vec<f64> = x.iter().map(|v| (v * 1.3).sin()).collect();
    let mut p = Panel::new("σ_min over time", "time [s]", "thrust [N]");
    p.series.push(Series::new("run", x.clone(), y.clone()));
    p.series
        .push(Series::new("other", x, y.iter().map(|v| v * 0.5).collect()).dashed());
    let mut fig = Figure::new("A figure −1 ≤ ζ");
    fig.panels.push(p);
    fig.note = "Left out: nothing".into();
    fig
}

/// `pdf` as text, every non-ASCII byte as `?` (byte offsets kept).
fn ascii(pdf: &[u8]) -> String {
    pdf.iter()
        .map(|&b| if b.is_ascii() { char::from(b) } else { '?' })
        .collect()
}

/// The objects of `pdf` by the cross-reference table: each offset must start `k 0 obj`.
fn check_xref(pdf: &[u8]) -> usize {
    let text = ascii(pdf);
    let sx = text.rfind("startxref\n").expect("startxref");
    let at: usize = text[sx + 10..]
        .lines()
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert!(text[at..].starts_with("xref\n0 "), "xref at {at}");
    let mut lines = text[at..].lines().skip(1);
    let n: usize = lines.next().unwrap()[2..].parse().unwrap();
    assert_eq!(lines.next().unwrap(), "0000000000 65535 f ");
    for k in 1..n {
        let entry = lines.next().unwrap();
        assert_eq!(entry.len(), 19, "{entry:?}");
        let off: usize = entry[..10].parse().unwrap();
        assert!(
            text[off..].starts_with(&format!("{k} 0 obj\n")),
            "object {k} at {off}"
        );
    }
    assert!(text.contains(&format!("/Size {n} ")));
    assert!(text.ends_with("%%EOF\n"));
    n
}

fn media_box(pdf: &[u8]) -> (f64, f64) {
    let text = ascii(pdf);
    let at = text.find("/MediaBox [0 0 ").expect("MediaBox") + 15;
    let end = at + text[at..].find(']').unwrap();
    let v: Vec<f64> = text[at..end]
        .split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect();
    (v[0], v[1])
}

fn stream(pdf: &[u8]) -> String {
    let text = ascii(pdf);
    let at = text.find("/Length ").unwrap() + 8;
    let len: usize = text[at..]
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let start = at + text[at..].find("stream\n").unwrap() + 7;
    assert!(
        text[start + len..].starts_with("endstream"),
        "stream length"
    );
    text[start..start + len].to_string()
}

/// Font sizes [pt] of the text operators of a content stream.
fn font_sizes(content: &str) -> Vec<f64> {
    content
        .split(" Tf")
        .filter_map(|s| s.rsplit(' ').next()?.parse().ok())
        .collect()
}

#[test]
fn a_figure_pdf_is_one_column_wide_page_with_a_correct_xref_and_both_fonts() {
    let fig = figure();
    let pdf = fig.render_pdf().unwrap();
    assert!(pdf.starts_with(b"%PDF-1.4\n"));
    assert_eq!(check_xref(&pdf), 8);
    let (w, h) = media_box(&pdf);
    assert_eq!(w, 252.0);
    // 800 × 600 at the column: the panel keeps its aspect, plus title and note strips.
    assert!(h > 150.0 && h < 260.0, "height {h}");
    let text = ascii(&pdf);
    assert_eq!(text.matches("/Type /Page ").count(), 1);
    assert!(text.contains("/Count 1"));
    assert!(text.contains("/BaseFont /Helvetica /Encoding /WinAnsiEncoding"));
    assert!(text.contains("/BaseFont /Symbol"));
    assert!(!text.contains("/ID"), "no random identifier");
    let content = stream(&pdf);
    assert!(content.contains("(time [s]) Tj"), "axis label as text");
    // σ in Symbol (code 163 octal 163 is ≤; σ is 's' = 115).
    assert!(content.contains("/F2") && content.contains("(s) Tj"));
    let sizes = font_sizes(&content);
    let least = sizes.iter().copied().fold(f64::INFINITY, f64::min);
    let most = sizes.iter().copied().fold(0.0, f64::max);
    assert!(
        least >= 7.0 - 1e-9 && most <= 8.5 + 1e-9,
        "{least} … {most}"
    );
    // Every stroked line at least 0.5 pt.
    for w in content
        .split(" w ")
        .filter_map(|s| s.rsplit(' ').next()?.parse::<f64>().ok())
    {
        assert!(w >= 0.5, "line width {w}");
    }
}

#[test]
fn rendering_twice_gives_the_same_bytes_and_the_svg_is_untouched() {
    let fig = figure();
    assert_eq!(fig.render_pdf().unwrap(), fig.render_pdf().unwrap());
    let svg = fig.render_svg().unwrap();
    let _ = fig.render_pdf().unwrap();
    assert_eq!(svg, fig.render_svg().unwrap());
    // The screen figure keeps its 11.3 px text.
    assert!(svg.contains("font-size=\"11.290322580645162\""));
}

#[test]
fn grids_wider_than_two_columns_are_laid_out_in_two() {
    let mut fig = Figure::new("six panels");
    for k in 0..6 {
        fig.panels
            .push(Panel::new(format!("p{k}"), "x [m]", "y [m]"));
    }
    fig.grid_layout(3, 320);
    assert_eq!(fig.layout, (2, 3));
    let col = fig.column_layout();
    assert_eq!(col.layout, (3, 2));
    assert_eq!(col.size.0, COLUMN_PX);
    assert!(col.size.1 >= 3 * MIN_PANEL_PX);
    let pdf = fig.render_pdf().unwrap();
    check_xref(&pdf);
    assert_eq!(media_box(&pdf).0, 252.0);
}

#[test]
fn heat_maps_tornados_and_rank_intervals_have_column_pdfs() {
    let h = heatmap(
        vec![0.0, 1.0, 2.0],
        vec![0.0, 1.0],
        vec![1.0, 2.0, f64::NAN, 4.0, 5.0, 6.0],
        "cost map",
        "links [-]",
        "offset [m]",
        "cost [J/m]",
        ColourScale::Viridis,
    )
    .unwrap();
    let pdf = h.render_pdf().unwrap();
    check_xref(&pdf);
    assert_eq!(media_box(&pdf), (252.0, 189.0));
    let rows = vec![
        TornadoRow {
            name: "drag".into(),
            value: 0.6,
            lo: 0.4,
            hi: 0.8,
        },
        TornadoRow {
            name: "mass".into(),
            value: -0.2,
            lo: f64::NAN,
            hi: f64::NAN,
        },
    ];
    let t = tornado_pdf("What drives cost", "SRRC [-]", &rows).unwrap();
    check_xref(&t);
    assert_eq!(media_box(&t).0, 252.0);
    let r = rank_interval_pdf(
        "ranks",
        &[RankRow {
            label: "#1".into(),
            p05: 1.0,
            p50: 1.0,
            p95: 2.0,
            highlight: true,
        }],
        3,
    )
    .unwrap();
    check_xref(&r);
    assert!(stream(&r).contains("(#1) Tj"));
    assert!(tornado_pdf("none", "x", &[]).is_err());
}

#[test]
fn text_is_split_into_helvetica_and_symbol_runs_with_documented_fallbacks() {
    let runs = encode("σ ≤ 10⁻⁵ −1 ‖x‖ m²");
    assert_eq!(runs[0].font, PdfFont::Symbol);
    assert_eq!(runs[0].codes, vec![115]);
    assert_eq!(runs[2].font, PdfFont::Symbol);
    assert_eq!(runs[2].codes, vec![163]);
    let helv: Vec<u8> = runs
        .iter()
        .filter(|r| r.font == PdfFont::Helvetica)
        .flat_map(|r| r.codes.clone())
        .collect();
    assert_eq!(helv, b"  10^-5 \x961 ||x|| m\xb2".to_vec());
    // Helvetica's AFM widths: H 722, e 556, l 222, o 556.
    assert!((text_width("Hello") - 2.278).abs() < 1e-12);
    assert!((text_width("ζ") - 0.494).abs() < 1e-12);
    assert_eq!(encode(""), vec![]);
}

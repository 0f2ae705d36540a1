//! The figures' column-width PDFs (issue 42) read by independent tools: `qpdf --check`
//! accepts the file and `pdftotext` finds the axis labels as text. A sweep writes a PDF beside
//! every figure of `plots/` and the review page links it. Without `qpdf` or `pdftotext` (Debian
//! packages `qpdf`, `poppler-utils`) the tool checks print why and are skipped, unless
//! `USM_PDF_TOOLS` is set (CI), which makes a missing tool a failure.

mod common;

use common::{arg, run, stderr, write};
use std::path::Path;
use std::process::Command;

use usm_study::report::{heatmap, ColourScale, Figure, Panel, Series};

/// Runs `tool args…` (no shell); `None` when the tool is not installed (skip, or fail under
/// `USM_PDF_TOOLS`).
fn tool(tool: &str, args: &[&str]) -> Option<std::process::Output> {
    match Command::new(tool).args(args).output() {
        Ok(o) => Some(o),
        Err(e) => {
            assert!(
                std::env::var_os("USM_PDF_TOOLS").is_none(),
                "USM_PDF_TOOLS is set but {tool} does not run: {e}"
            );
            eprintln!("skipped: {tool} does not run ({e}); install qpdf and poppler-utils");
            None
        }
    }
}

/// `qpdf --check` passes on `pdf` (when qpdf is there).
fn qpdf_ok(pdf: &Path) {
    if let Some(o) = tool("qpdf", &["--check", arg(pdf)]) {
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success(), "qpdf --check {}: {out}", pdf.display());
        assert!(out.contains("No syntax or stream encoding errors"), "{out}");
    }
}

/// The text pdftotext reads from `pdf` (when it is there).
fn pdf_text(pdf: &Path) -> Option<String> {
    let o = tool("pdftotext", &[arg(pdf), "-"])?;
    assert!(o.status.success(), "pdftotext {}", pdf.display());
    Some(String::from_utf8_lossy(&o.stdout).into_owned())
}

#[test]
fn a_column_pdf_passes_qpdf_and_its_labels_come_out_as_text() {
    let dir = tempfile::tempdir().unwrap();
    let x: Vec<f64> = (0..40).map(|k| k as f64 * 0.25).collect();
    let y: Vec<f64> = x.iter().map(|v| v.sin() * 40.0).collect();
    let mut p = Panel::new("σ_min of T(q)", "time [s]", "thrust [N]");
    p.series.push(Series::new("surge", x, y));
    let fig = Figure::new("Thrust along the run").with_panel(p);
    let path = dir.path().join("thrust.svg");
    fig.write_svg_pdf(&path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        svg,
        fig.render_svg().unwrap(),
        "the SVG is the screen figure"
    );
    let pdf = dir.path().join("thrust.pdf");
    assert_eq!(std::fs::read(&pdf).unwrap(), fig.render_pdf().unwrap());
    qpdf_ok(&pdf);
    if let Some(text) = pdf_text(&pdf) {
        for label in [
            "time [s]",
            "thrust [N]",
            "Thrust along the run",
            "surge",
            "σ",
        ] {
            assert!(text.contains(label), "{label:?} not in {text:?}");
        }
    }
    if let Some(o) = tool("pdfinfo", &[arg(&pdf)]) {
        let info = String::from_utf8_lossy(&o.stdout);
        let info = info.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(info.contains("Pages: 1"), "{info}");
        assert!(info.contains("Page size: 252 x"), "{info}");
    }

    let h = heatmap(
        vec![3.0, 4.0, 5.0],
        vec![0.06, 0.1],
        vec![1.0, 2.0, 3.0, 4.0, f64::NAN, 6.0],
        "mission cost",
        "links [-]",
        "offset [m]",
        "cost [J/m]",
        ColourScale::Viridis,
    )
    .unwrap();
    let hp = dir.path().join("heat.pdf");
    h.write_pdf(&hp).unwrap();
    qpdf_ok(&hp);
    if let Some(text) = pdf_text(&hp) {
        for label in ["links [-]", "offset [m]", "cost [J/m]", "grey: NaN"] {
            assert!(text.contains(label), "{label:?} not in {text:?}");
        }
    }
}

/// The tiny review study of tests/cli_report.rs: four cases, two of them failed.
const STUDY: &str = r#"
[study]
name = "pdfs"
seed = 3

[design.generator]
links = 3
link_length = 0.6
thrust_limit = 40.0

[scenario]
mode = "transport"
duration = 4.0

[physics]
integrator = "rk4"

[[axis]]
name = "design.links"
values = [3, 5]

[[axis]]
name = "servo.omega_n"
values = [3.0, 2000.0]
"#;

#[test]
fn a_sweep_writes_a_column_pdf_beside_every_figure_and_the_page_links_them() {
    let dir = tempfile::tempdir().unwrap();
    let study = write(dir.path(), "pdfs.toml", STUDY);
    let out = dir.path().join("out");
    let o = run(&["sweep", arg(&study), "--out", arg(&out), "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let plots = out.join("plots");
    let mut svgs: Vec<String> = std::fs::read_dir(&plots)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".svg"))
        .collect();
    svgs.sort();
    assert!(!svgs.is_empty());
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    let owned = std::fs::read_to_string(out.join(".usm-study.files")).unwrap();
    for svg in &svgs {
        let stem = svg.trim_end_matches(".svg");
        let pdf = plots.join(format!("{stem}.pdf"));
        assert!(pdf.is_file(), "{stem}.pdf beside {svg}");
        let href = format!("href=\"plots/{stem}.pdf\">PDF, column width</a>");
        assert!(page.contains(&href), "the page links {stem}.pdf");
        assert!(owned.contains(&format!("plots/{stem}.pdf\n")), "recorded");
        qpdf_ok(&pdf);
    }
    // Every figure's axis titles come out of its PDF as text.
    if let Some(text) = svgs
        .iter()
        .find(|s| s.starts_with("axis_"))
        .and_then(|s| pdf_text(&plots.join(s.replace(".svg", ".pdf"))))
    {
        assert!(text.contains("design.links"), "{text}");
    }
}

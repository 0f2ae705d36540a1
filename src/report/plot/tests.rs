//! Tests of the SVG figures.

use super::*;
use crate::report::error::ReportError;

/// Checks that start and end tags balance (a small well-formedness check).
fn assert_well_formed(svg: &str) {
    let mut stack: Vec<String> = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find('<') {
        let end = rest[start..].find('>').expect("unterminated tag") + start;
        let tag = &rest[start + 1..end];
        rest = &rest[end + 1..];
        if tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack.pop().expect("close without open");
            assert_eq!(open, name.trim(), "mismatched close tag");
        } else if !tag.ends_with('/') {
            let name = tag.split_whitespace().next().unwrap_or("").to_owned();
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed tags: {stack:?}");
    assert!(svg.trim_start().starts_with("<svg"));
}

fn demo_figure() -> Figure {
    let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
    let sin: Vec<f64> = t.iter().map(|v| v.sin()).collect();
    let mut cos: Vec<f64> = t.iter().map(|v| v.cos()).collect();
    cos[10] = f64::NAN;
    cos[11] = f64::INFINITY;
    let a = Panel::new("thrust", "time [s]", "force [N]")
        .with_series(Series::new("sin", t.clone(), sin.clone()))
        .with_series(
            Series::new("cos & <more>", t.clone(), cos)
                .dashed()
                .colour(Colour::Palette(1)),
        );
    let b = Panel::new("scatter", "x [m]", "y [m]")
        .kind(PanelKind::Scatter)
        .with_series(Series::new("pts", sin, t));
    let empty = Panel::new("empty", "e [-]", "f [-]");
    let constant = Panel::new("constant", "c [s]", "d [W]")
        .with_series(Series::new("", vec![1.0, 2.0, 3.0], vec![5.0; 3]))
        .with_series(Series::new("single", vec![2.0], vec![5.0]).kind(PanelKind::Scatter));
    let mut ranged = Panel::new("ranged", "r [s]", "q [m]")
        .with_series(Series::new("", vec![-10.0, 0.5, 10.0], vec![-10.0, 0.5, 10.0]).dashed())
        .with_series(Series::new("", vec![0.2, 0.8], vec![1e300, -1e300]));
    ranged.x_range = Some((0.0, 1.0));
    ranged.y_range = Some((0.0, 1.0));
    let nan_only = Panel::new("nan", "n [-]", "m [-]").with_series(Series::new(
        "nan",
        vec![f64::NAN],
        vec![f64::NAN],
    ));
    Figure::new("Demo figure")
        .with_panel(a)
        .with_panel(b)
        .with_panel(empty)
        .with_panel(constant)
        .with_panel(ranged)
        .with_panel(nan_only)
}

#[test]
fn figure_svg_is_well_formed_deterministic_and_labelled() {
    let fig = demo_figure();
    let a = fig.render_svg().unwrap();
    let b = fig.render_svg().unwrap();
    assert_eq!(a, b);
    assert_well_formed(&a);
    for label in [
        "time [s]",
        "force [N]",
        "x [m]",
        "Demo figure",
        "cos &amp; &lt;more&gt;",
    ] {
        assert!(a.contains(label), "missing {label}");
    }
    assert!(a.contains("<text"));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("fig.svg");
    fig.write_svg(&p).unwrap();
    assert_eq!(std::fs::read_to_string(&p).unwrap(), a);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn figure_validation_errors() {
    let mut fig = demo_figure();
    fig.layout = (1, 2);
    assert!(matches!(
        fig.render_svg(),
        Err(ReportError::InvalidFigure { .. })
    ));
    let mut fig = demo_figure();
    fig.panels[0].series[0].y.pop();
    assert!(fig.render_svg().is_err());
    let mut fig = demo_figure();
    fig.panels[0].x_range = Some((1.0, 1.0));
    assert!(fig.render_svg().is_err());
    let mut fig = demo_figure();
    fig.size = (0, 0);
    assert!(fig.render_svg().is_err());
    // An empty figure renders.
    assert_well_formed(&Figure::new("").render_svg().unwrap());
}

#[test]
fn extreme_values_do_not_panic() {
    let cases: Vec<Vec<f64>> = vec![
        vec![f64::MAX, -f64::MAX],
        vec![f64::MAX, f64::MAX],
        vec![5e-324, 1e-323],
        vec![1e15, 1e15 + 0.125],
        vec![0.0, -0.0],
        vec![1e300, -1e-300, 3.0],
    ];
    for v in cases {
        let x: Vec<f64> = (0..v.len()).map(|i| i as f64).collect();
        let fig = Figure::new("x").with_panel(
            Panel::new("p", "a [1]", "b [1]")
                .with_series(Series::new("l", x.clone(), v.clone()).dashed())
                .with_series(Series::new("s", v.clone(), x).kind(PanelKind::Scatter)),
        );
        assert_well_formed(&fig.render_svg().unwrap());
        assert_well_formed(&histogram(&v, 5, "h", "v [1]").render_svg().unwrap());
    }
}

#[test]
fn histogram_renders() {
    let v: Vec<f64> = (0..200).map(|i| ((i * 37) % 101) as f64 / 10.0).collect();
    let mut with_nan = v.clone();
    with_nan.push(f64::NAN);
    let fig = histogram(&with_nan, 12, "Distribution", "cost [J]");
    let svg = fig.render_svg().unwrap();
    assert_well_formed(&svg);
    assert!(svg.contains("cost [J]") && svg.contains("count [-]"));
    assert!(svg.contains("1 non-finite"));
    assert!(svg.matches("<rect").count() >= 12);
    // Degenerate inputs.
    assert_well_formed(&histogram(&[], 10, "e", "x").render_svg().unwrap());
    assert_well_formed(&histogram(&[3.0; 5], 0, "c", "x").render_svg().unwrap());
}

#[test]
fn pareto_scatter_renders_labels() {
    let pts: Vec<LabelledPoint> = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0)]
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| LabelledPoint {
            x,
            y,
            label: format!("design-{i}"),
        })
        .collect();
    let xy: Vec<(f64, f64)> = pts.iter().map(|p| (p.x, p.y)).collect();
    let front = super::super::pareto_front(&xy);
    assert_eq!(front, vec![0, 1, 3]);
    let fig = scatter_labelled(&pts, &front, "Trade-off", "energy [J]", "error [m]").unwrap();
    let svg = fig.render_svg().unwrap();
    assert_well_formed(&svg);
    for l in [
        "design-0",
        "design-1",
        "design-3",
        "energy [J]",
        "error [m]",
    ] {
        assert!(svg.contains(l), "missing {l}");
    }
    assert!(!svg.contains("design-2"));
    assert!(scatter_labelled(&pts, &[9], "t", "x", "y").is_err());
    assert_eq!(svg, fig.render_svg().unwrap());
}

#[test]
fn heatmap_renders() {
    let x = vec![0.0, 1.0, 2.0];
    let y = vec![10.0, 20.0];
    let z = vec![1.0, 2.0, f64::NAN, 4.0, 5.0, 6.0];
    let h = heatmap(
        x.clone(),
        y.clone(),
        z,
        "Map",
        "gain [-]",
        "depth [m]",
        "cost [J]",
        ColourScale::Viridis,
    )
    .unwrap();
    let svg = h.render_svg().unwrap();
    assert_well_formed(&svg);
    assert_eq!(svg, h.render_svg().unwrap());
    for l in ["gain [-]", "depth [m]", "cost [J]", "Map"] {
        assert!(svg.contains(l), "missing {l}");
    }
    assert!(svg.contains("#C8C8C8"), "NaN cell is grey");
    let dir = tempfile::tempdir().unwrap();
    h.write_svg(&dir.path().join("h.svg")).unwrap();
    // Bad grids are errors; degenerate ones render.
    assert!(heatmap(
        x.clone(),
        y.clone(),
        vec![1.0],
        "",
        "",
        "",
        "",
        ColourScale::Greys
    )
    .is_err());
    assert!(heatmap(
        vec![1.0, 0.0],
        vec![0.0],
        vec![1.0, 2.0],
        "",
        "",
        "",
        "",
        ColourScale::Greys
    )
    .is_err());
    for z in [vec![f64::NAN; 6], vec![3.0; 6]] {
        let h = heatmap(
            x.clone(),
            y.clone(),
            z,
            "d",
            "a",
            "b",
            "c",
            ColourScale::BlueRed,
        )
        .unwrap();
        assert_well_formed(&h.render_svg().unwrap());
    }
    let h = heatmap(
        vec![],
        vec![],
        vec![],
        "e",
        "a",
        "b",
        "c",
        ColourScale::Greys,
    )
    .unwrap();
    assert_well_formed(&h.render_svg().unwrap());
    let h = heatmap(
        vec![1.0],
        vec![2.0],
        vec![3.0],
        "one",
        "a",
        "b",
        "c",
        ColourScale::Greys,
    )
    .unwrap();
    assert_well_formed(&h.render_svg().unwrap());
}

#[test]
fn crowded_point_labels_get_leader_lines() {
    // Eight front points crowded into one corner: their labels cannot all sit beside them.
    let pts: Vec<LabelledPoint> = (0..8)
        .map(|i| LabelledPoint {
            x: 1.0 + 0.001 * i as f64,
            y: 1.0 - 0.001 * i as f64,
            label: format!("#{i} paper/5/0.06"),
        })
        .chain(std::iter::once(LabelledPoint {
            x: 10.0,
            y: 0.0,
            label: "far".into(),
        }))
        .collect();
    let front: Vec<usize> = (0..9).collect();
    let fig = scatter_labelled(&pts, &front, "t", "x", "y").unwrap();
    let svg = fig.render_svg().unwrap();
    assert!(svg.contains("stroke=\"#787878\""), "no leader line");
}

fn tornado_rows() -> Vec<TornadoRow> {
    let row = |name: &str, value: f64, lo: f64, hi: f64| TornadoRow {
        name: name.to_owned(),
        value,
        lo,
        hi,
    };
    vec![
        row("hydro.drag_scale", 0.12, 0.05, 0.2),
        row("hydro.linear_damping_scale", -0.81, -0.9, -0.7),
        row("current <speed> & dir", 0.45, f64::NAN, f64::NAN),
        row("start.offset", f64::NAN, f64::NAN, f64::NAN),
    ]
}

#[test]
fn tornado_chart_sorts_by_magnitude_and_draws_whiskers() {
    let rows = tornado_rows();
    let svg = tornado_svg("Drivers of energy per metre", "SRRC [-]", &rows).unwrap();
    assert_well_formed(&svg);
    assert_eq!(
        svg,
        tornado_svg("Drivers of energy per metre", "SRRC [-]", &rows).unwrap()
    );
    for l in [
        "Drivers of energy per metre",
        "SRRC [-]",
        "hydro.linear_damping_scale",
        "hydro.drag_scale",
        "current &lt;speed&gt; &amp; dir",
        "start.offset (n/a)",
    ] {
        assert!(svg.contains(l), "missing {l}");
    }
    assert!(!svg.contains("NaN"));
    // Rows from the top by decreasing |value|: the labels appear in that order.
    let at = |l: &str| svg.find(l).unwrap();
    assert!(at("linear_damping") < at("current") && at("current") < at("drag_scale"));
    assert!(at("drag_scale") < at("start.offset"));
    // Three bars (blue positive, orange negative); whiskers with two caps on the two rows
    // with a finite interval only.
    assert_eq!(svg.matches("fill=\"#1F77B4\"").count(), 2);
    assert_eq!(svg.matches("fill=\"#FF7F0E\"").count(), 1);
    assert_eq!(svg.matches("stroke-width=\"2\"").count(), 6);
    // Sobol indices in [0, 1] render too; a lone row and an all-NaN row as well.
    let sobol: Vec<TornadoRow> = ["a", "b"]
        .iter()
        .zip([0.6, 0.02])
        .map(|(n, v)| TornadoRow {
            name: n.to_string(),
            value: v,
            lo: v - 0.01,
            hi: v + 0.01,
        })
        .collect();
    assert_well_formed(&tornado_svg("S", "first-order index [-]", &sobol).unwrap());
    let nan = tornado_svg("n", "x", &rows[3..]).unwrap();
    assert_well_formed(&nan);
    assert!(!nan.contains("NaN"));
}

#[test]
fn rank_intervals_mark_medians_and_highlight() {
    let row = |label: &str, p: (f64, f64, f64), highlight: bool| RankRow {
        label: label.to_owned(),
        p05: p.0,
        p50: p.1,
        p95: p.2,
        highlight,
    };
    let rows = vec![
        row("#44 ends/3/0.14", (1.0, 1.0, 2.0), true),
        row("#12 paper/5/0.06", (1.0, 2.0, 4.0), false),
        row("#7 mid/4/0.10", (2.0, 3.5, 5.0), false),
        row("#3 never ranked", (f64::NAN, f64::NAN, f64::NAN), false),
    ];
    let svg = rank_interval_svg("Rank over 16 worlds", &rows, 5).unwrap();
    assert_well_formed(&svg);
    assert_eq!(
        svg,
        rank_interval_svg("Rank over 16 worlds", &rows, 5).unwrap()
    );
    for l in [
        "Rank over 16 worlds",
        "#44 ends/3/0.14",
        "#12 paper/5/0.06",
        "#3 never ranked",
        "1 = best",
    ] {
        assert!(svg.contains(l), "missing {l}");
    }
    assert!(!svg.contains("NaN"));
    // Three medians, one of them in the accent colour.
    assert_eq!(svg.matches("<circle").count(), 3);
    assert_eq!(svg.matches("fill=\"#FF7F0E\"").count(), 1);
    // One design alone and out-of-range ranks still render.
    let one = rank_interval_svg("one", &[row("only", (0.0, 1.0, 9.0), true)], 1).unwrap();
    assert_well_formed(&one);
}

#[test]
fn uncertainty_charts_refuse_empty_input() {
    for e in [
        tornado_svg("t", "m", &[]),
        rank_interval_svg("r", &[], 3),
        rank_interval_svg(
            "r",
            &[RankRow {
                label: "a".into(),
                p05: 1.0,
                p50: 1.0,
                p95: 1.0,
                highlight: false,
            }],
            0,
        ),
    ] {
        match e {
            Err(ReportError::InvalidFigure { detail, .. }) => assert!(!detail.is_empty()),
            other => panic!("expected InvalidFigure, got {other:?}"),
        }
    }
    let many: Vec<TornadoRow> = (0..1000)
        .map(|i| TornadoRow {
            name: format!("p{i}"),
            value: 0.1,
            lo: f64::NAN,
            hi: f64::NAN,
        })
        .collect();
    assert!(matches!(
        tornado_svg("big", "m", &many),
        Err(ReportError::InvalidFigure { .. })
    ));
}

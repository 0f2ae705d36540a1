//! Drawings of a run: the vehicle at several times in one picture ([`render_shapes_svg`]) and
//! as an SMIL animation ([`render_animation_svg`]), each in a top (`x–y`) and a side (`x–z`)
//! view to one scale, with the base and end-effector traces.
//!
//! Structure (for tests and the HTML report): each view is a `<g class="view" id="view-top|side">`
//! with the same `data-scale`/`data-x0`/`data-y0` transform attributes as the design drawing
//! ([`super::ViewTransform`]); each snapshot is a `<g class="snap" data-t="…">` holding its
//! body outlines (`polygon.body`) and, in the animation, its thrust arrows (`g.thruster`); the
//! overlaid picture draws the arrows after every outline, in `<g class="thrust" data-t="…">`,
//! so that no later outline hides a thrust. In the animation each snapshot group carries one
//! discrete `<animate>` of its opacity, so that exactly one is visible at a time; the document
//! needs no script, and a viewer without SMIL shows the first frame alone (every frame but the
//! first has opacity 0 until animated; the still sequence is the overlaid picture,
//! `shapes.svg`). The thrust dots inside the animation's zoomed camera are drawn at 1/zoom of
//! their radius, so the zoom does not blow them up over the arrows.

use std::fmt::Write as _;

use super::camera::{body_centre, follow_zoom, open_camera};
use super::labels::Labeller;
use super::page::{nice_length, ACCENT};
use super::scene::Scene;
use super::svg::{num, Attr, Svg};
use super::views::{cylinder_outline, open_view, Bounds, View, ViewTransform};
use crate::spatial::Vec3;

/// The vehicle at one time of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// Time [s].
    pub t: f64,
    /// The vehicle's geometry at that time, inertial frame [m].
    pub scene: Scene,
}

/// What a drawing of a run shows.
#[derive(Clone, Debug, PartialEq)]
pub struct RunDrawing {
    /// Caption lines; the first is the title.
    pub caption: Vec<String>,
    /// The vehicle at increasing times.
    pub snapshots: Vec<Snapshot>,
    /// Base origin over the whole run, inertial frame [m].
    pub base_trace: Vec<Vec3>,
    /// End-effector origin over the whole run, inertial frame [m].
    pub ee_trace: Vec<Vec3>,
}

/// Page width [px].
const WIDTH: f64 = 1200.0;
/// Largest total height of the two views [px].
const MAX_VIEWS_HEIGHT: f64 = 760.0;
/// Margin, gap between views, label room [px].
const MARGIN: f64 = 24.0;
const GAP: f64 = 40.0;
const PAD: f64 = 22.0;
/// Caption line height [px].
const LINE: f64 = 18.0;
/// Smallest extent of a view [m], so that a flat run still gets a readable strip.
const MIN_EXTENT: f64 = 1.0;
/// Length of the animation's time bar [px].
const TIME_BAR: f64 = 240.0;
/// The two views drawn.
const VIEWS: [View; 2] = [View::Top, View::Side];

const STYLE: &str = "text{font-family:'DejaVu Sans',Arial,Helvetica,sans-serif;fill:#000}\
.title{font-size:13px;font-weight:bold}.caption{font-size:13px}.label{font-size:12px}\
.body{fill:#fff;fill-opacity:0.55;stroke-width:1.3}.thruster{stroke:#c2410c;fill:#c2410c}\
.thruster line{stroke-width:1.2}.frame{fill:none;stroke:#bbb;stroke-width:0.8}\
.base{fill:none;stroke:#777;stroke-width:1.2;stroke-dasharray:6 4}\
.ee{fill:none;stroke:#15803d;stroke-width:1.4}.leader{stroke:#888;stroke-width:0.6}\
.camera *{vector-effect:non-scaling-stroke}";

/// The colour of time fraction `f` ∈ [0, 1]: light blue (start) to dark navy (end).
pub fn time_colour(f: f64) -> String {
    let f = f.clamp(0.0, 1.0);
    let lerp = |a: f64, b: f64| (a + (b - a) * f).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        lerp(125.0, 8.0),
        lerp(185.0, 29.0),
        lerp(230.0, 88.0)
    )
}

/// Per-view bounds of everything drawn [m], each at least [`MIN_EXTENT`] in both directions.
fn bounds(d: &RunDrawing, view: View) -> Bounds {
    let mut b = Bounds::empty();
    for s in &d.snapshots {
        for c in &s.scene.cylinders {
            for p in cylinder_outline(view, &c.pose, c.length, c.radius) {
                b.extend(p);
            }
        }
        for a in &s.scene.arrows {
            b.extend(view.project(&(a.start + a.direction * a.length)));
        }
    }
    for p in d.base_trace.iter().chain(&d.ee_trace) {
        b.extend(view.project(p));
    }
    if !b.min[0].is_finite() {
        b.extend([0.0, 0.0]);
    }
    for k in 0..2 {
        let grow = (MIN_EXTENT - (b.max[k] - b.min[k])).max(0.0) / 2.0;
        b.min[k] -= grow;
        b.max[k] += grow;
    }
    b.padded(0.05 * (b.max[0] - b.min[0]).max(b.max[1] - b.min[1]))
}

/// The transforms and boxes of the two views (top above side, sharing x) and the caption top.
fn layout(d: &RunDrawing) -> ([ViewTransform; 2], [[f64; 4]; 2], f64) {
    let [top, side] = VIEWS.map(|v| bounds(d, v));
    let x = (top.min[0].min(side.min[0]), top.max[0].max(side.max[0]));
    let h_m = top.size()[1] + side.size()[1];
    let scale = ((WIDTH - 2.0 * (MARGIN + PAD)) / (x.1 - x.0))
        .min((MAX_VIEWS_HEIGHT - 2.0 * GAP - 4.0 * PAD) / h_m);
    let left = MARGIN + PAD;
    let top_y = MARGIN + GAP + PAD;
    let side_y = top_y + top.size()[1] * scale + 2.0 * PAD + GAP;
    let t = [
        ViewTransform {
            scale,
            x0: left - x.0 * scale,
            y0: top_y + top.max[1] * scale,
        },
        ViewTransform {
            scale,
            x0: left - x.0 * scale,
            y0: side_y + side.max[1] * scale,
        },
    ];
    let w = (x.1 - x.0) * scale + 2.0 * PAD;
    let boxes = [
        [
            left - PAD,
            top_y - PAD,
            w,
            top.size()[1] * scale + 2.0 * PAD,
        ],
        [
            left - PAD,
            side_y - PAD,
            w,
            side.size()[1] * scale + 2.0 * PAD,
        ],
    ];
    (t, boxes, side_y + side.size()[1] * scale + PAD + GAP * 0.75)
}

/// Projected view points as an SVG `points` list.
fn points(t: &ViewTransform, ps: impl Iterator<Item = [f64; 2]>) -> String {
    let mut out = String::new();
    for p in ps {
        let q = t.to_svg(p);
        let _ = write!(out, "{},{} ", num(q[0]), num(q[1]));
    }
    out.trim_end().to_string()
}

/// A trace as a polyline of class `class`.
fn trace(s: &mut Svg, class: &str, view: View, t: &ViewTransform, ps: &[Vec3]) {
    if ps.len() > 1 {
        let pts = points(t, ps.iter().map(|p| view.project(p)));
        s.empty(
            "polyline",
            &[("class", class.into()), ("points", pts.into())],
        );
    }
}

/// What of a snapshot a group draws, and how: [`Layer::Bodies`] and [`Layer::Arrows`] apart
/// (the overlaid picture draws every body first, so no later outline hides an earlier thrust
/// arrow), [`Layer::Both`] in one group (an animation frame).
#[derive(Clone, Copy, PartialEq)]
enum Layer {
    Bodies,
    Arrows,
    Both,
}

/// How a snapshot group is drawn: its layer; `dot`, the scale of the thrust dots' radii (1 on
/// the page; 1/zoom inside the animation's camera, whose zoom would blow them up over the
/// arrows); `opacity`, the group's opacity without SMIL (the animation shows its first frame
/// alone where SMIL is not supported; `None` = visible).
#[derive(Clone, Copy)]
struct Style {
    layer: Layer,
    dot: f64,
    opacity: Option<&'static str>,
}

/// One snapshot in one view: outlines stroked in the snapshot's colour, thrust arrows in the
/// accent colour (as `style` says). `extra` is written first inside the group (the
/// animation's `<animate>`). The arrows' group is `g.thrust` when drawn apart, else the
/// snapshot's `g.snap` holds both.
fn snapshot(
    s: &mut Svg,
    view: View,
    t: &ViewTransform,
    snap: &Snapshot,
    colour: &str,
    extra: &[(&str, Attr)],
    style: Style,
) {
    let class = if style.layer == Layer::Arrows {
        "thrust"
    } else {
        "snap"
    };
    let mut attrs = vec![
        ("class", class.into()),
        ("data-t", Attr::Text(format!("{:.3}", snap.t))),
        ("stroke", colour.into()),
    ];
    if let Some(o) = style.opacity {
        attrs.push(("opacity", o.into()));
    }
    s.open("g", &attrs);
    if !extra.is_empty() {
        s.empty("animate", extra);
    }
    if style.layer != Layer::Arrows {
        for c in &snap.scene.cylinders {
            let pts = points(
                t,
                cylinder_outline(view, &c.pose, c.length, c.radius).into_iter(),
            );
            s.empty(
                "polygon",
                &[
                    ("class", "body".into()),
                    ("data-body", c.name.as_str().into()),
                    ("points", pts.into()),
                ],
            );
        }
    }
    if style.layer != Layer::Bodies {
        for a in &snap.scene.arrows {
            arrow(s, view, t, a, style.dot);
        }
    }
    s.close("g");
}

/// One thrust arrow (`g.thruster`): a line from the thruster with a dot at its tip, or a dot
/// alone when it is shorter than 2 px (no thrust, or seen end-on); dots of radius × `dot`.
fn arrow(s: &mut Svg, view: View, t: &ViewTransform, a: &super::scene::Arrow, dot: f64) {
    let p1 = t.to_svg(view.project(&a.start));
    let p2 = t.to_svg(view.project(&(a.start + a.direction * a.length)));
    s.open(
        "g",
        &[
            ("class", "thruster".into()),
            ("data-thruster", a.name.as_str().into()),
            ("data-length-m", a.length.into()),
        ],
    );
    if (p2[0] - p1[0]).hypot(p2[1] - p1[1]) < 2.0 {
        s.empty(
            "circle",
            &[
                ("cx", p1[0].into()),
                ("cy", p1[1].into()),
                ("r", (1.2 * dot).into()),
            ],
        );
        s.close("g");
        return;
    }
    s.empty(
        "line",
        &[
            ("x1", p1[0].into()),
            ("y1", p1[1].into()),
            ("x2", p2[0].into()),
            ("y2", p2[1].into()),
        ],
    );
    s.empty(
        "circle",
        &[
            ("cx", p2[0].into()),
            ("cy", p2[1].into()),
            ("r", (1.6 * dot).into()),
        ],
    );
    s.close("g");
}

/// Caption (left) and legend (right): time colours, traces, thrusters, scale bar.
fn caption_and_legend(s: &mut Svg, d: &RunDrawing, scale: f64, top: f64) {
    let y = |i: usize| top + LINE * (i as f64 + 0.8);
    for (i, line) in d.caption.iter().enumerate() {
        let class = if i == 0 { "title" } else { "caption" };
        s.text(
            &[
                ("class", class.into()),
                ("x", MARGIN.into()),
                ("y", y(i).into()),
            ],
            line,
        );
    }
    let x = WIDTH * 0.56;
    let (t0, t1) = match (d.snapshots.first(), d.snapshots.last()) {
        (Some(a), Some(b)) => (a.t, b.t),
        _ => (0.0, 0.0),
    };
    for k in 0..10 {
        let f = k as f64 / 9.0;
        s.empty(
            "rect",
            &[
                ("x", (x + 12.0 * k as f64).into()),
                ("y", (y(0) - 10.0).into()),
                ("width", 12.0.into()),
                ("height", 10.0.into()),
                ("fill", time_colour(f).into()),
            ],
        );
    }
    let text = |s: &mut Svg, i: usize, t: &str| {
        s.text(
            &[
                ("class", "caption".into()),
                ("x", (x + 130.0).into()),
                ("y", y(i).into()),
            ],
            t,
        );
    };
    text(
        s,
        0,
        &format!(
            "body outline at t = {} s … {} s (light → dark)",
            num(t0),
            num(t1)
        ),
    );
    s.empty(
        "line",
        &[
            ("class", "base".into()),
            ("x1", x.into()),
            ("y1", (y(1) - 4.0).into()),
            ("x2", (x + 120.0).into()),
            ("y2", (y(1) - 4.0).into()),
        ],
    );
    text(s, 1, "base origin trace");
    s.empty(
        "line",
        &[
            ("class", "ee".into()),
            ("x1", x.into()),
            ("y1", (y(2) - 4.0).into()),
            ("x2", (x + 120.0).into()),
            ("y2", (y(2) - 4.0).into()),
        ],
    );
    text(s, 2, "end-effector trace");
    s.empty(
        "line",
        &[
            ("stroke", ACCENT.into()),
            ("stroke-width", 1.5.into()),
            ("x1", x.into()),
            ("y1", (y(3) - 4.0).into()),
            ("x2", (x + 40.0).into()),
            ("y2", (y(3) - 4.0).into()),
        ],
    );
    text(s, 3, "thrust at that time (length ∝ thrust, signed)");
    let len = nice_length(120.0 / scale);
    s.empty(
        "rect",
        &[
            ("id", "scale-bar".into()),
            ("data-length-m", len.into()),
            ("x", x.into()),
            ("y", (y(4) - 7.0).into()),
            ("width", (len * scale).into()),
            ("height", 6.0.into()),
            ("fill", "#000".into()),
        ],
    );
    text(
        s,
        4,
        &format!(
            "{} m (both views to this scale)",
            num(len).trim_end_matches('0').trim_end_matches('.')
        ),
    );
}

/// Page height for a caption of `n` lines below `top`.
fn page_height(top: f64, n: usize) -> f64 {
    (top + LINE * (n.max(5) as f64 + 1.0) + MARGIN).ceil()
}

/// The snapshots of `d` overlaid in one picture, coloured by time and labelled with their
/// time in the top view.
pub fn render_shapes_svg(d: &RunDrawing) -> String {
    let (ts, boxes, cap) = layout(d);
    let mut s = Svg::new(WIDTH, page_height(cap, d.caption.len()), STYLE);
    let n = d.snapshots.len().max(2) - 1;
    let mut labels = Labeller::new(WIDTH);
    for (k, view) in VIEWS.into_iter().enumerate() {
        open_view(&mut s, view, &ts[k], boxes[k], Vec::new());
        trace(&mut s, "base", view, &ts[k], &d.base_trace);
        trace(&mut s, "ee", view, &ts[k], &d.ee_trace);
        // Every outline first, then every arrow: a later outline never hides a thrust.
        for layer in [Layer::Bodies, Layer::Arrows] {
            let style = Style {
                layer,
                dot: 1.0,
                opacity: None,
            };
            for (i, snap) in d.snapshots.iter().enumerate() {
                let colour = time_colour(i as f64 / n as f64);
                snapshot(&mut s, view, &ts[k], snap, &colour, &[], style);
            }
        }
        if view == View::Top {
            for (i, snap) in d.snapshots.iter().enumerate() {
                let Some(c) = snap.scene.cylinders.first() else {
                    continue;
                };
                let at = ts[k].to_svg(view.project(&c.pose.p));
                let id = format!("time-label-{i}");
                labels.place(
                    &mut s,
                    &format!(
                        "{} s",
                        num(snap.t).trim_end_matches('0').trim_end_matches('.')
                    ),
                    at,
                    [0.0, -1.0],
                    &id,
                );
            }
        }
        s.close("g");
    }
    caption_and_legend(&mut s, d, ts[0].scale, cap);
    s.finish()
}

/// The run as an animation lasting `duration` seconds and repeating: each snapshot shown in
/// turn (SMIL, discrete opacity), over the static traces, with the run time written in the
/// top view.
pub fn render_animation_svg(d: &RunDrawing, duration: f64) -> String {
    let (ts, boxes, cap) = layout(d);
    let mut s = Svg::new(WIDTH, page_height(cap, d.caption.len()), STYLE);
    let n = d.snapshots.len().max(1);
    let dur = format!("{}s", num(duration));
    let body_length: f64 = d
        .snapshots
        .first()
        .map_or(0.0, |s| s.scene.cylinders.iter().map(|c| c.length).sum());
    let zoom = follow_zoom(body_length, ts[0].scale, boxes[0][2]);
    for (k, view) in VIEWS.into_iter().enumerate() {
        open_view(&mut s, view, &ts[k], boxes[k], Vec::new());
        let centres: Vec<[f64; 2]> = d
            .snapshots
            .iter()
            .map(|snap| ts[k].to_svg(view.project(&body_centre(&snap.scene))))
            .collect();
        open_camera(&mut s, &centres, boxes[k], zoom, &dur);
        trace(&mut s, "base", view, &ts[k], &d.base_trace);
        trace(&mut s, "ee", view, &ts[k], &d.ee_trace);
        for (i, snap) in d.snapshots.iter().enumerate() {
            let (values, times) = visible_during(i, n);
            let anim = [
                ("attributeName", "opacity".into()),
                ("calcMode", "discrete".into()),
                ("values", values.into()),
                ("keyTimes", times.into()),
                ("dur", dur.clone().into()),
                ("repeatCount", "indefinite".into()),
            ];
            let style = Style {
                layer: Layer::Both,
                dot: 1.0 / zoom,
                opacity: Some(if i == 0 { "1" } else { "0" }),
            };
            let colour = time_colour(i as f64 / (n.max(2) - 1) as f64);
            snapshot(&mut s, view, &ts[k], snap, &colour, &anim, style);
        }
        s.close("g");
        s.close("svg");
        if view == View::Top {
            s.empty(
                "rect",
                &[
                    ("class", "time-bar-frame".into()),
                    ("x", (boxes[0][0] + 110.0).into()),
                    ("y", (boxes[0][1] + 8.0).into()),
                    ("width", TIME_BAR.into()),
                    ("height", 8.0.into()),
                    ("fill", "none".into()),
                    ("stroke", "#888".into()),
                ],
            );
        }
        for (i, snap) in d.snapshots.iter().enumerate() {
            let (values, times) = visible_during(i, n);
            let anim = [
                ("attributeName", "opacity".into()),
                ("calcMode", "discrete".into()),
                ("values", values.into()),
                ("keyTimes", times.into()),
                ("dur", dur.clone().into()),
                ("repeatCount", "indefinite".into()),
            ];
            if view == View::Top {
                // The clock: one text per frame, shown with its frame.
                let still = if i == 0 { "1" } else { "0" };
                s.open("g", &[("class", "clock".into()), ("opacity", still.into())]);
                s.empty("animate", &anim);
                s.text(
                    &[
                        ("class", "title".into()),
                        ("x", (boxes[0][0] + 8.0).into()),
                        ("y", (boxes[0][1] + 18.0).into()),
                    ],
                    &format!("t = {} s", num(snap.t)),
                );
                // The time bar: filled to this frame's share of the run.
                let (t0, t1) = (d.snapshots[0].t, d.snapshots[n - 1].t);
                let f = if t1 > t0 {
                    (snap.t - t0) / (t1 - t0)
                } else {
                    1.0
                };
                s.empty(
                    "rect",
                    &[
                        ("class", "time-bar".into()),
                        ("x", (boxes[0][0] + 110.0).into()),
                        ("y", (boxes[0][1] + 8.0).into()),
                        ("width", (TIME_BAR * f.clamp(0.0, 1.0)).into()),
                        ("height", 8.0.into()),
                        ("fill", ACCENT.into()),
                    ],
                );
                s.close("g");
            }
        }
        s.close("g");
    }
    // The scale bar at the camera's zoom.
    caption_and_legend(&mut s, d, ts[0].scale * zoom, cap);
    s.finish()
}

/// Discrete opacity values and key times that show frame `i` of `n` during
/// `[i/n, (i+1)/n)` of the cycle and hide it otherwise.
pub fn visible_during(i: usize, n: usize) -> (String, String) {
    let f = |k: usize| format!("{:.6}", k as f64 / n as f64);
    if i == 0 {
        ("1;0".into(), format!("0;{}", f(1)))
    } else if i + 1 == n {
        ("0;1".into(), format!("0;{}", f(i)))
    } else {
        ("0;1;0".into(), format!("0;{};{}", f(i), f(i + 1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_take_turns() {
        assert_eq!(visible_during(0, 4), ("1;0".into(), "0;0.250000".into()));
        assert_eq!(
            visible_during(2, 4),
            ("0;1;0".into(), "0;0.500000;0.750000".into())
        );
        assert_eq!(visible_during(3, 4), ("0;1".into(), "0;0.750000".into()));
        assert_eq!(time_colour(0.0), "#7db9e6");
        assert_eq!(time_colour(1.0), "#081d58");
    }

    /// A straight 60 m run of a 3 m body (one cylinder) in `frames` frames.
    fn long_run(frames: usize) -> RunDrawing {
        use super::super::scene::{Cylinder, Scene};
        let snap = |k: usize| {
            let x = 60.0 * k as f64 / (frames - 1) as f64;
            Snapshot {
                t: k as f64,
                scene: Scene {
                    caption: Vec::new(),
                    cylinders: vec![Cylinder {
                        name: "link".into(),
                        pose: crate::spatial::Se3 {
                            r: crate::spatial::Mat3::identity(),
                            p: Vec3::new(x, 0.0, 0.0),
                        },
                        length: 3.0,
                        radius: 0.2,
                        module: false,
                    }],
                    joints: Vec::new(),
                    arrows: Vec::new(),
                    triads: Vec::new(),
                    arrow_legend: String::new(),
                    markers: Vec::new(),
                },
            }
        };
        RunDrawing {
            caption: vec!["run".into()],
            snapshots: (0..frames).map(snap).collect(),
            base_trace: vec![Vec3::zeros(), Vec3::new(63.0, 0.0, 0.0)],
            ee_trace: Vec::new(),
        }
    }

    #[test]
    fn the_camera_follows_the_body_and_a_time_bar_fills() {
        let d = long_run(4);
        let svg = render_animation_svg(&d, 4.0);
        // Zoomed so that the window spans about three body lengths of the 63 m path.
        let (ts, boxes, _) = layout(&d);
        let z = follow_zoom(3.0, ts[0].scale, boxes[0][2]);
        assert!(z > 5.0, "{z}");
        // One camera per view, moving to each frame's body centre.
        assert_eq!(svg.matches("class=\"camera\"").count(), 2);
        let values: Vec<&str> = svg
            .split("type=\"translate\"")
            .nth(1)
            .and_then(|r| r.split("values=\"").nth(1))
            .and_then(|r| r.split('"').next())
            .unwrap()
            .split(';')
            .collect();
        assert_eq!(values.len(), 4);
        let xs: Vec<f64> = values
            .iter()
            .map(|v| v.split(',').next().unwrap().parse().unwrap())
            .collect();
        let c0 = ts[0].to_svg([1.5, 0.0]);
        assert!((xs[0] + c0[0]).abs() < 0.01, "{xs:?} vs {c0:?}");
        assert!(xs.windows(2).all(|w| w[1] < w[0]), "{xs:?}");
        // The time bar: empty at the start, full at the end.
        let bars: Vec<f64> = svg
            .split("class=\"time-bar\"")
            .skip(1)
            .map(|r| {
                let w = r.split("width=\"").nth(1).unwrap();
                w.split('"').next().unwrap().parse().unwrap()
            })
            .collect();
        assert_eq!(bars.len(), 4);
        assert_eq!(bars[0], 0.0);
        assert_eq!(bars[3], TIME_BAR);
    }
}

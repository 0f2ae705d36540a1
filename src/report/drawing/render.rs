//! One view of a [`Scene`]: body outlines (far to near), joint axes, thrust arrows, frame
//! triads, then the labels; and the legend's symbols, drawn by the same functions.

use super::labels::Labeller;
use super::scene::Scene;
use super::svg::{Attr, Svg};
use super::views::{cylinder_outline, open_view, View, ViewTransform};
use crate::report::file_stem_safe;
use crate::spatial::Vec3;

/// Below this projected length [px] an arrow or triad axis is drawn as seen end-on.
const END_ON_PX: f64 = 6.0;
/// A joint axis whose projection is shorter than this fraction of its length shows as a dot.
const DOT_FRACTION: f64 = 0.5;

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn line(s: &mut Svg, class: &str, a: [f64; 2], b: [f64; 2], extra: &[(&str, Attr)]) {
    let mut attrs = vec![
        ("class", class.into()),
        ("x1", a[0].into()),
        ("y1", a[1].into()),
        ("x2", b[0].into()),
        ("y2", b[1].into()),
    ];
    attrs.extend_from_slice(extra);
    s.empty("line", &attrs);
}

fn circle(s: &mut Svg, class: &str, c: [f64; 2], r: f64) {
    s.empty(
        "circle",
        &[
            ("class", class.into()),
            ("cx", c[0].into()),
            ("cy", c[1].into()),
            ("r", r.into()),
        ],
    );
}

/// A joint's centre line from `a` to `b` [px].
pub(super) fn axis_line(s: &mut Svg, a: [f64; 2], b: [f64; 2]) {
    line(s, "jaxis", a, b, &[]);
}

/// A joint axis seen end-on at `c` [px]: a ringed dot.
pub(super) fn axis_dot(s: &mut Svg, c: [f64; 2]) {
    circle(s, "jring", c, 4.5);
    circle(s, "jdot", c, 2.0);
}

/// An arrow from `a` to `b` [px] with a filled head.
fn arrow(s: &mut Svg, a: [f64; 2], b: [f64; 2]) {
    let d = sub(b, a);
    let len = d[0].hypot(d[1]);
    let head = 10.0f64.min(0.4 * len);
    let u = [d[0] / len, d[1] / len];
    let base = [b[0] - u[0] * head, b[1] - u[1] * head];
    let w = 0.45 * head;
    line(s, "", a, base, &[]);
    let pts = [
        b,
        [base[0] - u[1] * w, base[1] + u[0] * w],
        [base[0] + u[1] * w, base[1] - u[0] * w],
    ];
    let text: Vec<String> = pts
        .iter()
        .map(|p| format!("{},{}", super::svg::num(p[0]), super::svg::num(p[1])))
        .collect();
    s.empty("polygon", &[("points", text.join(" ").into())]);
}

/// The legend's thruster symbol.
pub(super) fn legend_arrow(s: &mut Svg, a: [f64; 2], b: [f64; 2]) {
    s.open("g", &[("class", "thruster".into())]);
    arrow(s, a, b);
    s.close("g");
}

/// A thrust along the view's normal at `c` [px]: ⊙ towards the viewer, ⊗ away from them.
pub(super) fn out_of_page_mark(s: &mut Svg, c: [f64; 2], towards: bool) {
    s.open("g", &[("class", "thruster".into())]);
    circle(s, "mark", c, 6.0);
    if towards {
        circle(s, "", c, 2.2);
    } else {
        let k = 6.0 * std::f64::consts::FRAC_1_SQRT_2;
        line(s, "", [c[0] - k, c[1] - k], [c[0] + k, c[1] + k], &[]);
        line(s, "", [c[0] - k, c[1] + k], [c[0] + k, c[1] - k], &[]);
    }
    s.close("g");
}

/// Dash patterns of a triad's x, y, z axes.
const TRIAD_DASH: [&str; 3] = ["none", "5 3", "1.5 2.5"];

/// The legend's triad symbol: three short strokes in the axes' dash patterns.
pub(super) fn triad_legend(s: &mut Svg, at: [f64; 2]) {
    s.open("g", &[("class", "triad".into())]);
    for (k, dash) in TRIAD_DASH.iter().enumerate() {
        let x = at[0] + 10.0 * k as f64;
        line(
            s,
            "",
            [x, at[1] + 5.0],
            [x + 7.0, at[1] - 5.0],
            &[("stroke-dasharray", (*dash).into())],
        );
    }
    s.close("g");
}

/// Writes `view` of `scene` with transform `t` inside the box `frame` ([x, y, w, h] px).
pub(super) fn view(
    s: &mut Svg,
    labels: &mut Labeller,
    scene: &Scene,
    view: View,
    t: &ViewTransform,
    frame: [f64; 4],
) {
    let (u, v) = view.axis_names();
    open_view(
        s,
        view,
        t,
        frame,
        vec![("data-u", u.into()), ("data-v", v.into())],
    );
    bodies(s, scene, view, t);
    joints(s, scene, view, t);
    let pending = arrows(s, labels, scene, view, t);
    triads(s, labels, scene, view, t);
    markers(s, labels, scene, view, t);
    for (names, anchor, pref) in group_labels(pending) {
        let id = format!("{}-label-{}", view.id(), file_stem_safe(&names[0]));
        labels.place(s, &label_text(&names), anchor, pref, &id);
    }
    s.close("g");
}

/// Labels whose anchors coincide (within [`SAME_ANCHOR_PX`]) merged into one, in order of
/// first appearance: arrows seen end-on or sharing a tip get one label.
fn group_labels(
    pending: Vec<(String, [f64; 2], [f64; 2])>,
) -> Vec<(Vec<String>, [f64; 2], [f64; 2])> {
    let mut groups: Vec<(Vec<String>, [f64; 2], [f64; 2])> = Vec::new();
    for (name, anchor, pref) in pending {
        let near = |g: &&mut (Vec<String>, [f64; 2], [f64; 2])| {
            let d = sub(g.1, anchor);
            d[0].hypot(d[1]) < SAME_ANCHOR_PX
        };
        match groups.iter_mut().find(near) {
            Some(g) => g.0.push(name),
            None => groups.push((vec![name], anchor, pref)),
        }
    }
    groups
}

/// Anchors closer than this [px] share a label.
const SAME_ANCHOR_PX: f64 = 3.0;
/// At most this many names in a shared label; the rest are counted.
const MAX_NAMES: usize = 3;

/// `T1, T5, T7`, or `T2, T4, T6 +15` when more than [`MAX_NAMES`] share a label.
fn label_text(names: &[String]) -> String {
    let shown = names[..names.len().min(MAX_NAMES)].join(", ");
    if names.len() > MAX_NAMES {
        format!("{shown} +{}", names.len() - MAX_NAMES)
    } else {
        shown
    }
}

/// Body outlines, far to near along the view's normal (a stable sort keeps ties in order).
fn bodies(s: &mut Svg, scene: &Scene, view: View, t: &ViewTransform) {
    let n = view.normal();
    let mut order: Vec<usize> = (0..scene.cylinders.len()).collect();
    let depth = |i: usize| {
        let c = &scene.cylinders[i];
        c.pose
            .act_point(&Vec3::new(c.length / 2.0, 0.0, 0.0))
            .dot(&n)
    };
    order.sort_by(|&a, &b| depth(a).total_cmp(&depth(b)));
    for i in order {
        let c = &scene.cylinders[i];
        let pts: Vec<String> = cylinder_outline(view, &c.pose, c.length, c.radius)
            .into_iter()
            .map(|p| {
                let q = t.to_svg(p);
                format!("{},{}", super::svg::num(q[0]), super::svg::num(q[1]))
            })
            .collect();
        let kind = if c.module { "module" } else { "link" };
        s.empty(
            "polygon",
            &[
                ("class", format!("body {kind}").into()),
                ("data-body", c.name.as_str().into()),
                ("points", pts.join(" ").into()),
            ],
        );
    }
}

/// Joint axes: centre lines, or ringed dots where the axis points out of the page.
fn joints(s: &mut Svg, scene: &Scene, view: View, t: &ViewTransform) {
    for j in &scene.joints {
        let a = view.project(&j.axis);
        s.open(
            "g",
            &[
                ("class", "joint".into()),
                ("data-joint", j.name.as_str().into()),
            ],
        );
        if a[0].hypot(a[1]) < DOT_FRACTION {
            axis_dot(s, t.to_svg(view.project(&j.position)));
        } else {
            let p = |k: f64| t.to_svg(view.project(&(j.position + j.axis * (k * j.half_length))));
            axis_line(s, p(-1.0), p(1.0));
        }
        s.close("g");
    }
}

/// Thrust arrows (or end-on marks); returns each label's name, anchor and preferred
/// direction, placed after everything else of the view is drawn.
fn arrows(
    s: &mut Svg,
    labels: &mut Labeller,
    scene: &Scene,
    view: View,
    t: &ViewTransform,
) -> Vec<(String, [f64; 2], [f64; 2])> {
    let mut pending = Vec::new();
    for a in &scene.arrows {
        let p1 = t.to_svg(view.project(&a.start));
        let p2 = t.to_svg(view.project(&(a.start + a.direction * a.length)));
        let d = sub(p2, p1);
        s.open(
            "g",
            &[
                ("class", "thruster".into()),
                (
                    "id",
                    format!("{}-{}", view.id(), file_stem_safe(&a.name)).into(),
                ),
                ("data-thruster", a.name.as_str().into()),
                ("data-x1", p1[0].into()),
                ("data-y1", p1[1].into()),
                ("data-x2", p2[0].into()),
                ("data-y2", p2[1].into()),
            ],
        );
        if d[0].hypot(d[1]) >= END_ON_PX {
            arrow(s, p1, p2);
            pending.push((a.name.clone(), p2, d));
        } else {
            out_of_page_mark(s, p1, a.direction.dot(&view.normal()) > 0.0);
            labels.reserve([p1[0] - 7.0, p1[1] - 7.0, 14.0, 14.0]);
            pending.push((a.name.clone(), p1, [1.0, -1.0]));
        }
        s.close("g");
    }
    pending
}

/// Frame triads: each axis in its dash pattern with its letter, the frame's name at the
/// origin; axes seen end-on are left out.
fn triads(s: &mut Svg, labels: &mut Labeller, scene: &Scene, view: View, t: &ViewTransform) {
    for tr in &scene.triads {
        let o = t.to_svg(view.project(&tr.pose.p));
        s.open(
            "g",
            &[
                ("class", "triad".into()),
                ("data-frame", tr.name.as_str().into()),
            ],
        );
        for (k, dash) in TRIAD_DASH.iter().enumerate() {
            let tip = t.to_svg(view.project(&(tr.pose.p + tr.pose.r.column(k) * tr.size)));
            let d = sub(tip, o);
            if d[0].hypot(d[1]) < END_ON_PX {
                continue;
            }
            line(s, "", o, tip, &[("stroke-dasharray", (*dash).into())]);
            s.text(
                &[
                    ("class", "small".into()),
                    ("x", (tip[0] + 3.0).into()),
                    ("y", (tip[1] - 2.0).into()),
                ],
                ["x", "y", "z"][k],
            );
            labels.reserve([tip[0], tip[1] - 12.0, 10.0, 12.0]);
        }
        s.close("g");
        let id = format!("{}-frame-{}", view.id(), file_stem_safe(&tr.name));
        labels.place(s, &tr.name, o, [-1.0, 1.0], &id);
    }
}

/// Labelled points: a filled dot or a ring, the name beside it.
fn markers(s: &mut Svg, labels: &mut Labeller, scene: &Scene, view: View, t: &ViewTransform) {
    for m in &scene.markers {
        let c = t.to_svg(view.project(&m.position));
        s.open("g", &[("data-marker", m.name.as_str().into())]);
        if m.filled {
            circle(s, "jdot", c, 3.0);
        } else {
            circle(s, "jring", c, 4.5);
        }
        s.close("g");
        let id = format!("{}-marker-{}", view.id(), file_stem_safe(&m.name));
        labels.place(s, &m.name, c, [1.0, 1.0], &id);
    }
}

//! The page: three views laid out to one scale, the caption, the legend and the scale bar.

use super::labels::Labeller;
use super::render;
use super::scene::Scene;
use super::svg::Svg;
use super::views::{self, Bounds, View, ViewTransform};

/// Page width [px].
const PAGE_WIDTH: f64 = 1200.0;
/// Largest total height of the views [px]; a tall (curled) vehicle is drawn smaller.
const MAX_VIEWS_HEIGHT: f64 = 900.0;
/// Outer margin [px].
const MARGIN: f64 = 24.0;
/// Space between views, and room for a view's title [px].
const GAP: f64 = 36.0;
/// Room around a view's content for labels [px].
const PAD: f64 = 26.0;
/// Height of one caption line [px].
const LINE: f64 = 18.0;
/// The accent colour of thrusters (the only colour; everything else is black or grey).
pub const ACCENT: &str = "#c2410c";

const STYLE: &str = "text{font-family:'DejaVu Sans',Arial,Helvetica,sans-serif;fill:#000}\
.title{font-size:13px;font-weight:bold}.caption{font-size:13px}.small{font-size:11px}\
.label{font-size:12px}.body{stroke:#000;stroke-width:1.2}.link{fill:#fff}.module{fill:#c8c8c8}\
.jaxis{stroke:#444;stroke-width:1;stroke-dasharray:8 3 2 3;fill:none}.jdot{fill:#444}\
.jring{fill:#fff;stroke:#444;stroke-width:1}.thruster{stroke:#c2410c;fill:#c2410c}\
.thruster line{stroke-width:2}.mark{fill:#fff;stroke-width:1.5}.triad{stroke:#555;stroke-width:1.3}\
.leader{stroke:#888;stroke-width:0.6}.frame{fill:none;stroke:#bbb;stroke-width:0.8}";

/// The views' transforms and the page height.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// One transform per view, in the order of [`View::ALL`].
    pub transforms: [ViewTransform; 3],
    /// Each view's box in SVG px `[x, y, width, height]` (content plus label room).
    pub boxes: [[f64; 4]; 3],
    /// Top of the caption [px].
    pub caption_top: f64,
}

/// The view-coordinate bounds of everything `scene` draws in `view` [m].
fn content_bounds(scene: &Scene, view: View) -> Bounds {
    let mut b = Bounds::empty();
    for c in &scene.cylinders {
        for p in views::cylinder_outline(view, &c.pose, c.length, c.radius) {
            b.extend(p);
        }
    }
    for j in &scene.joints {
        b.extend(view.project(&(j.position + j.axis * j.half_length)));
        b.extend(view.project(&(j.position - j.axis * j.half_length)));
    }
    for a in &scene.arrows {
        b.extend(view.project(&a.start));
        b.extend(view.project(&(a.start + a.direction * a.length)));
    }
    for m in &scene.markers {
        b.extend(view.project(&m.position));
    }
    for t in &scene.triads {
        b.extend(view.project(&t.pose.p));
        for k in 0..3 {
            b.extend(view.project(&(t.pose.p + t.pose.r.column(k) * t.size)));
        }
    }
    if !b.min[0].is_finite() {
        b.extend([0.0, 0.0]);
    }
    // A degenerate extent (a point) still gets a visible box.
    b.padded(0.05)
}

/// Lays the views out: top above side (sharing x), front right of side (sharing z), one scale
/// for all three chosen so that the page is [`PAGE_WIDTH`] wide and the views at most
/// [`MAX_VIEWS_HEIGHT`] tall.
pub fn layout(scene: &Scene) -> Layout {
    let [top, side, front] = View::ALL.map(|v| content_bounds(scene, v));
    let x = (top.min[0].min(side.min[0]), top.max[0].max(side.max[0]));
    let z = (side.min[1].min(front.min[1]), side.max[1].max(front.max[1]));
    let width_m = (x.1 - x.0) + front.size()[0];
    let height_m = top.size()[1] + (z.1 - z.0);
    let fixed_w = 2.0 * MARGIN + 4.0 * PAD + GAP;
    let fixed_h = 2.0 * GAP + 4.0 * PAD;
    let scale = ((PAGE_WIDTH - fixed_w) / width_m).min((MAX_VIEWS_HEIGHT - fixed_h) / height_m);
    let left = MARGIN + PAD;
    let top_y = MARGIN + GAP + PAD;
    let t_top = ViewTransform {
        scale,
        x0: left - x.0 * scale,
        y0: top_y + top.max[1] * scale,
    };
    let side_y = top_y + top.size()[1] * scale + 2.0 * PAD + GAP;
    let t_side = ViewTransform {
        scale,
        x0: t_top.x0,
        y0: side_y + z.1 * scale,
    };
    let front_x = left + (x.1 - x.0) * scale + 2.0 * PAD + GAP;
    let t_front = ViewTransform {
        scale,
        x0: front_x - front.min[0] * scale,
        y0: t_side.y0,
    };
    let wx = (x.1 - x.0) * scale + 2.0 * PAD;
    let hz = (z.1 - z.0) * scale + 2.0 * PAD;
    let boxes = [
        [
            left - PAD,
            top_y - PAD,
            wx,
            top.size()[1] * scale + 2.0 * PAD,
        ],
        [left - PAD, side_y - PAD, wx, hz],
        [
            front_x - PAD,
            side_y - PAD,
            front.size()[0] * scale + 2.0 * PAD,
            hz,
        ],
    ];
    Layout {
        transforms: [t_top, t_side, t_front],
        boxes,
        caption_top: side_y - PAD + hz + GAP * 0.75,
    }
}

/// The largest 1–2–5 × 10ᵏ value not above `x` (x > 0): scale bars and arrow scales.
pub fn nice_length(x: f64) -> f64 {
    let e = 10f64.powf(x.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * e)
        .find(|&l| l <= x)
        .unwrap_or(e)
}

/// `x` [m] as text without trailing zeros (`0.5 m`, `2 m`).
fn metres(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    format!("{s} m")
}

/// The scene as a self-contained SVG document (see the module docs for its structure).
pub fn render_svg(scene: &Scene) -> String {
    let lay = layout(scene);
    let legend_lines = 7.0;
    let caption_lines = scene.caption.len().max(legend_lines as usize) as f64;
    let height = lay.caption_top + caption_lines * LINE + MARGIN + LINE;
    let mut s = Svg::new(PAGE_WIDTH, height.ceil(), STYLE);
    let mut labels = Labeller::new(PAGE_WIDTH);
    for (k, view) in View::ALL.into_iter().enumerate() {
        render::view(
            &mut s,
            &mut labels,
            scene,
            view,
            &lay.transforms[k],
            lay.boxes[k],
        );
    }
    caption(&mut s, scene, lay.caption_top);
    legend(&mut s, scene, &lay);
    s.finish()
}

/// The caption: title in bold, then the caller's lines.
fn caption(s: &mut Svg, scene: &Scene, top: f64) {
    s.open(
        "g",
        &[("class", "caption".into()), ("id", "caption".into())],
    );
    for (i, line) in scene.caption.iter().enumerate() {
        let class = if i == 0 { "title" } else { "caption" };
        s.text(
            &[
                ("class", class.into()),
                ("x", MARGIN.into()),
                ("y", (top + LINE * (i as f64 + 0.8)).into()),
            ],
            line,
        );
    }
    s.close("g");
}

/// The legend (right of the caption): symbols, the scale bar and the arrow scale.
fn legend(s: &mut Svg, scene: &Scene, lay: &Layout) {
    let x = PAGE_WIDTH * 0.62;
    let top = lay.caption_top;
    let y = |i: f64| top + LINE * (i + 0.8);
    s.open("g", &[("class", "legend".into()), ("id", "legend".into())]);
    let sym = |s: &mut Svg, i: f64, class: &str| {
        s.empty(
            "rect",
            &[
                ("class", format!("body {class}").into()),
                ("x", x.into()),
                ("y", (y(i) - 9.0).into()),
                ("width", 28.0.into()),
                ("height", 10.0.into()),
            ],
        );
    };
    let text = |s: &mut Svg, i: f64, t: &str| {
        s.text(
            &[
                ("class", "caption".into()),
                ("x", (x + 36.0).into()),
                ("y", y(i).into()),
            ],
            t,
        );
    };
    sym(s, 0.0, "link");
    text(s, 0.0, "link (body outline)");
    sym(s, 1.0, "module");
    text(s, 1.0, "joint module");
    render::axis_line(s, [x, y(2.0) - 4.0], [x + 28.0, y(2.0) - 4.0]);
    render::axis_dot(s, [x + 40.0, y(2.0) - 4.0]);
    s.text(
        &[
            ("class", "caption".into()),
            ("x", (x + 50.0).into()),
            ("y", y(2.0).into()),
        ],
        "joint axis (in the page / out of the page)",
    );
    if scene.arrows.is_empty() {
        text(s, 3.0, "no thrusters");
    } else {
        render::legend_arrow(s, [x, y(3.0) - 4.0], [x + 28.0, y(3.0) - 4.0]);
        text(s, 3.0, &format!("thruster, {}", scene.arrow_legend));
        render::out_of_page_mark(s, [x + 6.0, y(4.0) - 4.0], true);
        render::out_of_page_mark(s, [x + 22.0, y(4.0) - 4.0], false);
        text(s, 4.0, "thrust towards / away from the viewer");
    }
    render::triad_legend(s, [x, y(5.0) - 4.0]);
    text(s, 5.0, "frame axes x (solid), y (dashed), z (dotted)");
    scale_bar(s, lay, [x, y(6.0) - 4.0]);
    s.close("g");
}

/// A scale bar of a round length near a fifth of the top view's width.
fn scale_bar(s: &mut Svg, lay: &Layout, at: [f64; 2]) {
    let scale = lay.transforms[0].scale;
    let len = nice_length(0.2 * lay.boxes[0][2] / scale);
    let px = len * scale;
    s.open(
        "g",
        &[("id", "scale-bar".into()), ("data-length-m", len.into())],
    );
    s.empty(
        "rect",
        &[
            ("x", at[0].into()),
            ("y", (at[1] - 3.0).into()),
            ("width", px.into()),
            ("height", 6.0.into()),
            ("fill", "#000".into()),
        ],
    );
    s.empty(
        "rect",
        &[
            ("x", (at[0] + px / 2.0).into()),
            ("y", (at[1] - 2.0).into()),
            ("width", (px / 2.0 - 1.0).into()),
            ("height", 4.0.into()),
            ("fill", "#fff".into()),
        ],
    );
    s.text(
        &[
            ("class", "caption".into()),
            ("x", (at[0] + px + 8.0).into()),
            ("y", (at[1] + 4.0).into()),
        ],
        &format!("{} (all views to this scale)", metres(len)),
    );
    s.close("g");
}

#[cfg(test)]
mod tests {
    use crate::report::drawing::page::*;

    #[test]
    fn nice_lengths_round_down() {
        assert_eq!(nice_length(0.73), 0.5);
        assert_eq!(nice_length(3.0), 2.0);
        assert_eq!(nice_length(1.0), 1.0);
        assert_eq!(metres(0.5), "0.5 m");
        assert_eq!(metres(2.0), "2 m");
    }
}

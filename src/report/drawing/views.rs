//! The three orthographic views of a drawing and their transforms to SVG coordinates.
//!
//! Views (inertial frame, z up): **top** `x–y` seen from +z (x right, y up), **side** `x–z`
//! seen from −y (x right, z up), **front** `y–z` seen from +x, the head end (y right, z up).
//! Each is right-handed: the screen's out-of-page direction is [`View::normal`].

use super::svg::{Attr, Svg};
use crate::spatial::{Se3, Vec3};

/// One orthographic view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// `x–y`, seen from +z.
    Top,
    /// `x–z`, seen from −y.
    Side,
    /// `y–z`, seen from +x.
    Front,
}

impl View {
    /// The three views in drawing order.
    pub const ALL: [View; 3] = [View::Top, View::Side, View::Front];

    /// Stable identifier used in element ids (`top`, `side`, `front`).
    pub fn id(self) -> &'static str {
        match self {
            View::Top => "top",
            View::Side => "side",
            View::Front => "front",
        }
    }

    /// Heading printed above the view.
    pub fn title(self) -> &'static str {
        match self {
            View::Top => "top (x–y, from +z)",
            View::Side => "side (x–z, from −y)",
            View::Front => "front (y–z, from +x)",
        }
    }

    /// Indices of the inertial axes shown horizontally and vertically.
    pub fn axes(self) -> (usize, usize) {
        match self {
            View::Top => (0, 1),
            View::Side => (0, 2),
            View::Front => (1, 2),
        }
    }

    /// Names of the horizontal and vertical axes (`x`, `y`, `z`).
    pub fn axis_names(self) -> (&'static str, &'static str) {
        let n = ["x", "y", "z"];
        let (u, v) = self.axes();
        (n[u], n[v])
    }

    /// Unit vector out of the page, towards the viewer (inertial frame).
    pub fn normal(self) -> Vec3 {
        match self {
            View::Top => Vec3::z(),
            View::Side => -Vec3::y(),
            View::Front => Vec3::x(),
        }
    }

    /// A point or vector of the inertial frame in view coordinates `[u, v]` [m].
    pub fn project(self, p: &Vec3) -> [f64; 2] {
        let (u, v) = self.axes();
        [p[u], p[v]]
    }
}

/// An axis-aligned box in view coordinates [m].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lower corner `[u, v]`.
    pub min: [f64; 2],
    /// Upper corner `[u, v]`.
    pub max: [f64; 2],
}

impl Bounds {
    /// The empty box (extending it with a point gives that point).
    pub fn empty() -> Self {
        Bounds {
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        }
    }

    /// Grows the box to contain `p`.
    pub fn extend(&mut self, p: [f64; 2]) {
        for (k, x) in p.into_iter().enumerate() {
            self.min[k] = self.min[k].min(x);
            self.max[k] = self.max[k].max(x);
        }
    }

    /// Width and height [m].
    pub fn size(&self) -> [f64; 2] {
        [self.max[0] - self.min[0], self.max[1] - self.min[1]]
    }

    /// The box grown by `pad` [m] on every side.
    pub fn padded(&self, pad: f64) -> Self {
        Bounds {
            min: [self.min[0] - pad, self.min[1] - pad],
            max: [self.max[0] + pad, self.max[1] + pad],
        }
    }
}

/// The map from view coordinates [m] to SVG coordinates [px]:
/// `x = x0 + scale·u`, `y = y0 − scale·v` (SVG's y grows downwards).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewTransform {
    /// Pixels per metre, the same in both directions and in every view.
    pub scale: f64,
    /// SVG x of `u = 0`.
    pub x0: f64,
    /// SVG y of `v = 0`.
    pub y0: f64,
}

impl ViewTransform {
    /// SVG coordinates of the view point `p` [m].
    pub fn to_svg(&self, p: [f64; 2]) -> [f64; 2] {
        [self.x0 + self.scale * p[0], self.y0 - self.scale * p[1]]
    }
}

/// Points around each end circle of a cylinder outline.
const RIM_POINTS: usize = 48;

/// The outline of a solid cylinder in `view`: the convex hull of its two projected end discs
/// (exact for an orthographic projection of a convex body, up to the rim sampling). The
/// cylinder's axis is the x axis of `pose` (inertial frame), from its origin to `length` [m];
/// `radius` [m]. Counter-clockwise in view coordinates.
pub fn cylinder_outline(view: View, pose: &Se3, length: f64, radius: f64) -> Vec<[f64; 2]> {
    let mut pts = Vec::with_capacity(2 * RIM_POINTS);
    for x in [0.0, length] {
        for k in 0..RIM_POINTS {
            let a = std::f64::consts::TAU * k as f64 / RIM_POINTS as f64;
            let p = pose.act_point(&Vec3::new(x, radius * a.cos(), radius * a.sin()));
            pts.push(view.project(&p));
        }
    }
    convex_hull(pts)
}

/// Andrew's monotone chain; collinear points dropped. Counter-clockwise.
fn convex_hull(mut pts: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(pts.len() + 1);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Opens the group of `view` — id `view-<id>`, `extra` attributes, then its transform `t` as
/// `data-scale`/`data-x0`/`data-y0` — and draws its frame (`[x, y, w, h]` px) and title; the
/// caller closes the group.
pub(super) fn open_view(
    s: &mut Svg,
    view: View,
    t: &ViewTransform,
    frame: [f64; 4],
    extra: Vec<(&str, Attr)>,
) {
    let mut attrs: Vec<(&str, Attr)> = vec![
        ("class", "view".into()),
        ("id", format!("view-{}", view.id()).into()),
    ];
    attrs.extend(extra);
    attrs.extend([
        ("data-scale", Attr::Text(format!("{:.6}", t.scale))),
        ("data-x0", Attr::Text(format!("{:.6}", t.x0))),
        ("data-y0", Attr::Text(format!("{:.6}", t.y0))),
    ]);
    s.open("g", &attrs);
    s.empty(
        "rect",
        &[
            ("class", "frame".into()),
            ("x", frame[0].into()),
            ("y", frame[1].into()),
            ("width", frame[2].into()),
            ("height", frame[3].into()),
        ],
    );
    s.text(
        &[
            ("class", "title".into()),
            ("x", frame[0].into()),
            ("y", (frame[1] - 8.0).into()),
        ],
        view.title(),
    );
}

#[cfg(test)]
mod tests {
    use crate::report::drawing::views::*;

    #[test]
    fn a_straight_cylinder_is_a_rectangle_from_the_side_and_a_disc_from_the_front() {
        let pose = Se3::from_translation(Vec3::new(1.0, 0.0, 0.0));
        let side = cylinder_outline(View::Side, &pose, 2.0, 0.5);
        let mut b = Bounds::empty();
        side.iter().for_each(|p| b.extend(*p));
        assert_eq!(side.len(), 4, "{side:?}");
        assert!((b.min[0] - 1.0).abs() < 1e-12 && (b.max[0] - 3.0).abs() < 1e-12);
        assert!((b.max[1] - 0.5).abs() < 1e-12 && (b.min[1] + 0.5).abs() < 1e-12);
        let front = cylinder_outline(View::Front, &pose, 2.0, 0.5);
        assert_eq!(front.len(), RIM_POINTS);
        assert!(front
            .iter()
            .all(|p| ((p[0].hypot(p[1])) - 0.5).abs() < 1e-12));
    }

    #[test]
    fn views_are_right_handed() {
        for v in View::ALL {
            let (u, w) = v.axes();
            let mut eu = Vec3::zeros();
            let mut ev = Vec3::zeros();
            eu[u] = 1.0;
            ev[w] = 1.0;
            assert_eq!(eu.cross(&ev), v.normal(), "{v:?}");
        }
    }
}

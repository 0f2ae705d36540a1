//! The animation's camera: a clipping viewport over a view's box that follows the body,
//! zoomed so that the window spans a few body lengths instead of the whole path.

use super::scene::Scene;
use super::svg::{num, Attr, Svg};
use crate::spatial::Vec3;

/// Body lengths shown across the animation's window.
pub(super) const WINDOW_LENGTHS: f64 = 3.0;

/// The camera's zoom: a view's box `width` [px] spans [`WINDOW_LENGTHS`] × `body_length`
/// [m] at the drawing's `scale` [px/m]; never below 1 (a run shorter than the window is
/// shown whole).
pub(super) fn follow_zoom(body_length: f64, scale: f64, width: f64) -> f64 {
    let z = width / (WINDOW_LENGTHS * body_length * scale);
    if z.is_finite() {
        z.max(1.0)
    } else {
        1.0
    }
}

/// The centre of the box around the scene's cylinders [m] (the origin without any).
pub(super) fn body_centre(scene: &Scene) -> Vec3 {
    let ends = scene.cylinders.iter().flat_map(|c| {
        let axis = c.pose.r.column(0).into_owned();
        [c.pose.p, c.pose.p + axis * c.length]
    });
    let (lo, hi) = ends.fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(&p), hi.sup(&p)),
    );
    if lo.iter().all(|v| v.is_finite()) {
        (lo + hi) * 0.5
    } else {
        Vec3::zeros()
    }
}

/// Opens the camera over a view's box `b` `[x, y, w, h]`: a clipping viewport, zoomed by
/// `zoom` about `centres[i]` (page px) during frame `i` of `centres.len()` (discrete, in step
/// with the frames' opacity animations of `dur`). Close with `close("g")` then
/// `close("svg")`.
pub(super) fn open_camera(s: &mut Svg, centres: &[[f64; 2]], b: [f64; 4], zoom: f64, dur: &str) {
    s.open(
        "svg",
        &[
            ("class", "camera".into()),
            ("x", b[0].into()),
            ("y", b[1].into()),
            ("width", b[2].into()),
            ("height", b[3].into()),
            ("overflow", "hidden".into()),
        ],
    );
    s.open(
        "g",
        &[(
            "transform",
            Attr::Text(format!(
                "translate({},{}) scale({})",
                num(b[2] / 2.0),
                num(b[3] / 2.0),
                num(zoom)
            )),
        )],
    );
    if centres.is_empty() {
        return;
    }
    let n = centres.len();
    let values: Vec<String> = centres
        .iter()
        .map(|c| format!("{},{}", num(-c[0]), num(-c[1])))
        .collect();
    let key_times: Vec<String> = (0..n)
        .map(|i| format!("{:.6}", i as f64 / n as f64))
        .collect();
    s.empty(
        "animateTransform",
        &[
            ("attributeName", "transform".into()),
            ("type", "translate".into()),
            ("additive", "sum".into()),
            ("calcMode", "discrete".into()),
            ("values", values.join(";").into()),
            ("keyTimes", key_times.join(";").into()),
            ("dur", dur.into()),
            ("repeatCount", "indefinite".into()),
        ],
    );
}

//! `design draw`: a design at one state as a drawing ([`crate::report::drawing`]) — bodies,
//! joint axes, thrust arrows, base and end-effector frames — with a caption of the scaled
//! singular values of `T(q)` (docs/model.md §6) and the lost and weakest base directions.

use std::path::Path;

use super::error::PipelineError;
use crate::dynamics::hydrostatics::hydrostatics;
use crate::kinematics::{forward_kinematics, thruster_matrix_owned, KinWorkspace};
use crate::metrics::singularity::{tcm_metrics, TcmMetrics, AXIS_NAMES, DEFAULT_RANK_REL_TOL};
use crate::model::Vehicle;
use crate::report::drawing::{
    nice_length, render_svg, Arrow, Cylinder, JointAxis, Marker, Scene, Triad,
};
use crate::report::{atomic_write, fmt_short};
use crate::state::VehicleState;

/// Longest thrust arrow as a fraction of the vehicle length (before rounding the scale).
const ARROW_FRACTION: f64 = 0.15;
/// Frame triad axis length as a fraction of the vehicle length.
const TRIAD_FRACTION: f64 = 0.08;
/// Half length of a drawn joint axis in radii of the larger neighbouring body.
const AXIS_RADII: f64 = 1.8;

/// Whether body `i` is drawn as a joint module: an inner body (joints at both ends) without
/// thrusters, no longer than its diameter (the 0.104 m modules of docs/model.md §2 and the generator).
pub fn is_joint_module(v: &Vehicle, i: usize) -> bool {
    let b = &v.bodies[i];
    i > 0
        && i + 1 < v.bodies.len()
        && !v.thrusters.iter().any(|t| t.body == i)
        && b.length <= 2.0 * b.radius
}

/// Metres of arrow per newton of thrust limit: a 1–2–5 value that makes the strongest
/// thruster's arrow about [`ARROW_FRACTION`] of the vehicle length (1 when no thruster has a
/// limit).
pub fn arrow_scale(v: &Vehicle) -> f64 {
    let strongest = v.thrusters.iter().map(thrust_limit).fold(0.0, f64::max);
    if strongest > 0.0 {
        nice_length(ARROW_FRACTION * v.total_length() / strongest)
    } else {
        1.0
    }
}

/// The larger magnitude of a thruster's limits [N].
fn thrust_limit(t: &crate::model::Thruster) -> f64 {
    t.u_min.abs().max(t.u_max.abs())
}

/// The geometry of `v` at state `s` in the inertial frame: bodies posed by forward kinematics
/// (USM-1…16), each joint's axis at its child body's origin, each thruster's arrow from its
/// position along its thrust direction (length = limit × [`arrow_scale`]), and the base and
/// end-effector frames. The caption is left empty.
pub fn vehicle_scene(v: &Vehicle, s: &VehicleState) -> Scene {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &s.q, &mut ws);
    let g_ib = s.base.to_se3();
    let pose = |i: usize| g_ib.compose(&ws.g_b[i]);
    let cylinders = v
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| Cylinder {
            name: b.name.clone(),
            pose: pose(i),
            length: b.length,
            radius: b.radius,
            module: is_joint_module(v, i),
        })
        .collect();
    let joints = v
        .joints
        .iter()
        .enumerate()
        .map(|(k, j)| {
            let g = pose(k + 1);
            JointAxis {
                name: j.name.clone(),
                position: g.p,
                axis: g.act_vector(&j.axis).normalize(),
                half_length: AXIS_RADII * v.bodies[k].radius.max(v.bodies[k + 1].radius),
            }
        })
        .collect();
    let m_per_n = arrow_scale(v);
    let arrows = v
        .thrusters
        .iter()
        .map(|t| {
            let g = pose(t.body);
            Arrow {
                name: t.name.clone(),
                start: g.act_point(&t.position),
                direction: g.act_vector(&t.direction).normalize(),
                length: thrust_limit(t) * m_per_n,
            }
        })
        .collect();
    let size = TRIAD_FRACTION * v.total_length();
    let triads = vec![
        Triad {
            name: "base".into(),
            pose: g_ib,
            size,
        },
        Triad {
            name: "end effector".into(),
            pose: g_ib.compose(&ws.g_be),
            size,
        },
    ];
    Scene {
        caption: Vec::new(),
        cylinders,
        joints,
        arrows,
        triads,
        arrow_legend: format!(
            "arrow length ∝ thrust limit: {} m per N",
            fmt_short(m_per_n)
        ),
        markers: Vec::new(),
    }
}

/// The whole vehicle's centres of gravity and buoyancy at `s` as markers (inertial frame),
/// and the caption line of its hydrostatics (docs/model.md §4 "Restoring forces").
pub fn hydrostatic_markers(v: &Vehicle, s: &VehicleState) -> (Vec<Marker>, String) {
    let h = hydrostatics(v, &s.q);
    let g_ib = s.base.to_se3();
    let at = |c: [f64; 3]| g_ib.act_point(&crate::spatial::Vec3::from(c));
    let markers = vec![
        Marker {
            name: "CG".into(),
            position: at(h.centre_of_gravity),
            filled: true,
        },
        Marker {
            name: "CB".into(),
            position: at(h.centre_of_buoyancy),
            filled: false,
        },
    ];
    let line = format!(
        "hydrostatics: wet weight {} N; CB {} m above CG (GM); restoring {} N·m/rad in roll \
         and pitch about the CG",
        fmt_short(h.wet_weight),
        fmt_short(h.metacentric_height),
        fmt_short(h.roll_restoring_moment)
    );
    (markers, line)
}

/// The weakest of the six base DOFs under the thrust limits: the axis whose attainable wrench
/// (the smaller of `±e_k`, moments divided by `L` so that all six are in N, docs/model.md §6) is least;
/// its name and that value [N].
pub fn weakest_axis(m: &TcmMetrics) -> Option<(&'static str, f64)> {
    let att = m.attainable.as_ref()?;
    (0..6)
        .map(|k| {
            let per = if k < 3 { 1.0 } else { m.char_length };
            (AXIS_NAMES[k], att.positive[k].min(att.negative[k]) / per)
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// The scaled `T(q)` metrics of `v` at `s` (docs/model.md §6, moments divided by `L` = half the
/// vehicle length, default rank tolerance, attainable wrench under the thrust limits);
/// `None` without thrusters.
pub fn state_metrics(v: &Vehicle, s: &VehicleState) -> Result<Option<TcmMetrics>, PipelineError> {
    if v.thrusters.is_empty() {
        return Ok(None);
    }
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &s.q, &mut ws);
    let t = thruster_matrix_owned(v, &ws);
    let u_min: Vec<f64> = v.thrusters.iter().map(|t| t.u_min).collect();
    let u_max: Vec<f64> = v.thrusters.iter().map(|t| t.u_max).collect();
    tcm_metrics(
        &t,
        &u_min,
        &u_max,
        v.characteristic_length(),
        DEFAULT_RANK_REL_TOL,
    )
    .map(Some)
    .map_err(|source| PipelineError::Singularity {
        what: "analysing the scaled T(q) of the drawing",
        source,
    })
}

/// The caption of a drawing of `v` at the state described by `state_label`.
pub fn caption(v: &Vehicle, state_label: &str, m: Option<&TcmMetrics>) -> Vec<String> {
    let mut lines = vec![
        format!(
            "{} — {} bodies, {} joints, {} thrusters",
            v.name,
            v.bodies.len(),
            v.n_joints(),
            v.n_thrusters()
        ),
        format!(
            "total length {} m, total mass {} kg; state: {state_label}",
            fmt_short(v.total_length()),
            fmt_short(v.total_mass())
        ),
    ];
    let Some(m) = m else {
        lines.push("no thrusters: T(q) has no columns, every base DOF is lost".into());
        return lines;
    };
    let sv: Vec<String> = m.singular_values.iter().map(|x| fmt_short(*x)).collect();
    lines.push(format!(
        "singular values of T(q), moments / L = {} m: {}",
        fmt_short(m.char_length),
        sv.join(", ")
    ));
    let lost: Vec<&str> = m.lost_directions.iter().map(|d| d.dominant_axis).collect();
    lines.push(format!(
        "rank {} of 6; lost (σ ≤ {DEFAULT_RANK_REL_TOL:e} σ_max): {}",
        m.rank,
        if lost.is_empty() {
            "none".to_string()
        } else {
            lost.join(", ")
        }
    ));
    if let Some((axis, value)) = weakest_axis(m) {
        lines.push(format!(
            "weakest base DOF under the thrust limits: {axis} ({} N attainable, moments / L)",
            fmt_short(value)
        ));
    }
    lines
}

/// Largest coordinate of a drawing [m]: far beyond any vehicle, small enough that the
/// renderer's spans and scales stay finite.
pub const MAX_DRAWING_COORD: f64 = 1e9;

/// Every point of `scene` is finite and within [`MAX_DRAWING_COORD`] of the origin.
fn check_range(scene: &Scene) -> Result<(), PipelineError> {
    let points = scene
        .cylinders
        .iter()
        .map(|c| (format!("body {}", c.name), c.pose.p))
        .chain(
            scene
                .joints
                .iter()
                .map(|j| (format!("joint {}", j.name), j.position)),
        )
        .chain(
            scene
                .arrows
                .iter()
                .map(|a| (format!("thruster {}", a.name), a.start)),
        )
        .chain(
            scene
                .triads
                .iter()
                .map(|t| (format!("the {} frame", t.name), t.pose.p)),
        );
    for (what, p) in points {
        if let Some(x) = p.iter().find(|x| x.is_nan() || x.abs() > MAX_DRAWING_COORD) {
            return Err(PipelineError::DrawingRange {
                what,
                value: crate::input::located::fmt_exact(*x),
                limit: MAX_DRAWING_COORD,
            });
        }
    }
    Ok(())
}

/// The drawing of `v` at `s` as an SVG document; `state_label` says which state it is. A
/// state that puts the geometry out of range ([`MAX_DRAWING_COORD`]) is an error.
pub fn draw_design(
    v: &Vehicle,
    s: &VehicleState,
    state_label: &str,
) -> Result<String, PipelineError> {
    let scene = vehicle_scene(v, s);
    check_range(&scene)?;
    let m = state_metrics(v, s)?;
    let mut scene = scene;
    scene.caption = caption(v, state_label, m.as_ref());
    let (markers, line) = hydrostatic_markers(v, s);
    scene.markers = markers;
    scene.caption.push(line);
    Ok(render_svg(&scene))
}

/// Writes the drawing of `v` at `s` to `out` atomically, creating its directory if needed.
pub fn write_drawing(
    v: &Vehicle,
    s: &VehicleState,
    state_label: &str,
    out: &Path,
) -> Result<(), PipelineError> {
    let svg = draw_design(v, s, state_label)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        super::create_dir(dir)?;
    }
    atomic_write(out, svg.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::{usm_paper, uvms_planar};

    #[test]
    fn modules_scale_and_caption_of_the_straight_usm() {
        let v = usm_paper();
        let modules: Vec<&str> = (0..v.bodies.len())
            .filter(|&i| is_joint_module(&v, i))
            .map(|i| v.bodies[i].name.as_str())
            .collect();
        assert_eq!(modules, ["J1", "J2", "J3", "J4"]);
        assert!(!(0..4).any(|i| is_joint_module(&uvms_planar(), i)));
        // 0.15 · 3.3 m / 40 N = 0.0124 m/N, rounded down to 0.01.
        assert_eq!(arrow_scale(&v), 0.01);
        let s = VehicleState::rest(&v);
        let m = state_metrics(&v, &s).unwrap().unwrap();
        let text = caption(&v, "straight", Some(&m)).join("\n");
        assert!(
            text.contains("rank 5 of 6; lost (σ ≤ 1e-6 σ_max): roll"),
            "{text}"
        );
        assert_eq!(weakest_axis(&m).map(|w| w.0), Some("roll"));
    }

    #[test]
    fn a_bent_scene_follows_forward_kinematics() {
        let v = usm_paper();
        let mut s = VehicleState::rest(&v);
        s.q = vec![0.4, -0.2, 0.3, 0.1, -0.5, 0.2, 0.3, -0.1];
        let scene = vehicle_scene(&v, &s);
        let mut ws = KinWorkspace::new(&v);
        forward_kinematics(&v, &s.q, &mut ws);
        let t = thruster_matrix_owned(&v, &ws);
        for (j, a) in scene.arrows.iter().enumerate() {
            // The arrow's force and moment about the base origin are T(q)'s column (USM-25).
            let f = a.direction;
            let m = a.start.cross(&f);
            for r in 0..3 {
                assert!((t[(r, j)] - f[r]).abs() < 1e-12 && (t[(r + 3, j)] - m[r]).abs() < 1e-12);
            }
            assert!((a.length - 0.4).abs() < 1e-12);
        }
        let ee = scene.triads[1].pose.p;
        assert!((ee - ws.g_be.p).norm() < 1e-12);
    }

    #[test]
    fn a_state_out_of_range_is_refused_not_drawn_with_nan() {
        let v = usm_paper();
        let mut s = VehicleState::rest(&v);
        assert!(draw_design(&v, &s, "rest").is_ok());
        s.base.position[0] = 1e308;
        let e = draw_design(&v, &s, "far").unwrap_err();
        assert!(matches!(e, PipelineError::DrawingRange { .. }), "{e}");
        assert!(e.to_string().contains("1e308"), "{e}");
    }
}

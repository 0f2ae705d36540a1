//! Named designs: `usm-paper` (docs/model.md §2, USM Table II) and `uvms-planar` (docs/model.md §8).

use super::error::ModelError;
use super::{Body, Fluid, Hydro, Joint, Thruster, Vehicle};
use crate::spatial::{Mat3, Se3, Vec3};
use std::f64::consts::FRAC_PI_2;

/// Names of the built-in presets.
pub const PRESETS: &[&str] = &["usm-paper", "uvms-planar"];

/// Look up a preset by name.
pub fn preset(name: &str) -> Result<Vehicle, ModelError> {
    match name {
        "usm-paper" => Ok(usm_paper()),
        "uvms-planar" => Ok(uvms_planar()),
        _ => Err(ModelError::new(
            "design",
            format!(
                "unknown preset '{name}'; known presets: {}",
                PRESETS.join(", ")
            ),
        )),
    }
}

/// A neutrally buoyant cylinder body: displaced volume `m/ρ`, CG = CB at the centre.
pub(crate) fn neutral_body(
    name: &str,
    mass: f64,
    length: f64,
    radius: f64,
    hydro: Hydro,
    rho: f64,
) -> Body {
    let mut b = Body::cylinder(name, mass, length, radius, hydro);
    b.volume = mass / rho;
    b
}

/// A revolute joint at `(x, 0, 0)` of its parent frame about `axis`, limits `±limit` [rad].
pub(crate) fn face_joint(name: &str, x: f64, axis: Vec3, limit: f64) -> Joint {
    Joint {
        name: name.to_string(),
        placement: Se3::from_translation(Vec3::new(x, 0.0, 0.0)),
        axis,
        min: -limit,
        max: limit,
    }
}

/// A thruster on `body` at `(x, y, 0)` in the body frame pushing along `dir`, limits ±`limit` [N].
pub(crate) fn thruster(name: &str, body: usize, x: f64, y: f64, dir: Vec3, limit: f64) -> Thruster {
    Thruster {
        name: name.to_string(),
        body,
        position: Vec3::new(x, y, 0.0),
        direction: dir,
        u_min: -limit,
        u_max: limit,
        time_constant: None,
        rate_limit: None,
    }
}

/// The USM of the paper (docs/model.md §2): nine bodies L0 J1 L1 … J4 L4 from USM Table II, radius
/// 0.085 m, neutrally buoyant, eight joints (yaw at the rear face of each joint module,
/// pitch at its front face, ±90°), seven thrusters of ±40 N in the layout of docs/model.md §2.
pub fn usm_paper() -> Vehicle {
    let fluid = Fluid::default();
    let rho = fluid.rho;
    // (name, mass kg, length m, Cd_y,z) — USM Table II. The axial drag is the hull's
    // (docs/model.md §2 "Hull drag"), not Table II's per-body C_d,x (0.8 at the end links,
    // 0.1 elsewhere: `Hydro::cylinder`, or `cd_x` in a design file, keeps that form).
    let table: [(&str, f64, f64, f64); 9] = [
        ("L0", 14.3, 0.62, 1.0),
        ("J1", 6.0, 0.104, 1.0),
        ("L1", 12.7, 0.584, 1.0),
        ("J2", 6.0, 0.104, 1.0),
        ("L2", 9.8, 0.726, 1.0),
        ("J3", 6.0, 0.104, 1.0),
        ("L3", 12.7, 0.584, 1.0),
        ("J4", 6.0, 0.104, 1.0),
        ("L4", 7.8, 0.37, 1.0),
    ];
    let r = 0.085;
    let bodies: Vec<Body> = table
        .iter()
        .map(|&(n, m, l, cyz)| neutral_body(n, m, l, r, Hydro::hull(l, cyz), rho))
        .collect();
    let mut joints = Vec::new();
    for (k, parent) in bodies.iter().enumerate().take(8) {
        // Body k+1 is a joint module when k is even (rear face: yaw), a link when odd
        // (the module's front face: pitch).
        let (axis, kind) = if k % 2 == 0 {
            (Vec3::z(), "yaw")
        } else {
            (Vec3::y(), "pitch")
        };
        joints.push(face_joint(
            &format!("{kind}{}", k / 2 + 1),
            parent.length,
            axis,
            FRAC_PI_2,
        ));
    }
    let (ex, ey, ez) = (Vec3::x(), Vec3::y(), Vec3::z());
    let thrusters = vec![
        thruster("T1", 2, 0.237, 0.0, ez, 40.0),
        thruster("T2", 2, 0.347, 0.0, ey, 40.0),
        thruster("T3", 4, 0.278, -0.10, ex, 40.0),
        thruster("T4", 4, 0.278, 0.10, ex, 40.0),
        thruster("T5", 4, 0.488, 0.0, ez, 40.0),
        thruster("T6", 6, 0.237, 0.0, ey, 40.0),
        thruster("T7", 6, 0.347, 0.0, ez, 40.0),
    ];
    let last = bodies.last().map(|b| b.length).unwrap_or(0.0);
    Vehicle {
        name: "usm-paper".into(),
        bodies,
        joints,
        thrusters,
        base: Se3::identity(),
        end_effector: Se3::from_translation(Vec3::new(last, 0.0, 0.0)),
        fluid,
    }
}

/// The planar UVMS of Antonelli & Chiaverini (docs/model.md §8): a 5.3 m vehicle (NPS AUV II mass and
/// inertia, base frame at its centre) carrying a three-link arm of 2.0 m links whose first
/// joint is at (2.5, 0, 0) in the vehicle frame; all arm joints about z.
///
/// Inferred (not in the paper): the arm links' mass (30 kg each, neutrally buoyant, radius
/// 0.08 m), the vehicle radius (0.5 m) and drag coefficients, and the vehicle's four
/// thrusters (two longitudinal at ±0.4 m, two lateral near the ends, ±500 N).
pub fn uvms_planar() -> Vehicle {
    let fluid = Fluid::default();
    let rho = fluid.rho;
    let (len, mass) = (5.3, 5443.425);
    let mut vehicle = neutral_body("vehicle", mass, len, 0.5, Hydro::cylinder(0.2, 1.0), rho);
    // NPS AUV II principal inertias (Healey & Lienard 1993, ../shared/data/nps_auv2.toml).
    vehicle.inertia = Mat3::from_diagonal(&Vec3::new(2038.0, 13587.0, 13587.0));
    let mut bodies = vec![vehicle];
    for k in 1..=3 {
        bodies.push(neutral_body(
            &format!("arm{k}"),
            30.0,
            2.0,
            0.08,
            Hydro::cylinder(0.1, 1.0),
            rho,
        ));
    }
    let half = len / 2.0;
    let mut joints = vec![face_joint(
        "q1",
        half + 2.5,
        Vec3::z(),
        std::f64::consts::PI,
    )];
    for k in 2..=3 {
        joints.push(face_joint(
            &format!("q{k}"),
            2.0,
            Vec3::z(),
            std::f64::consts::PI,
        ));
    }
    let (ex, ey) = (Vec3::x(), Vec3::y());
    let thrusters = vec![
        thruster("port", 0, half, -0.4, ex, 500.0),
        thruster("starboard", 0, half, 0.4, ex, 500.0),
        thruster("bow", 0, len - 0.5, 0.0, ey, 500.0),
        thruster("stern", 0, 0.5, 0.0, ey, 500.0),
    ];
    Vehicle {
        name: "uvms-planar".into(),
        bodies,
        joints,
        thrusters,
        base: Se3::from_translation(Vec3::new(half, 0.0, 0.0)),
        end_effector: Se3::from_translation(Vec3::new(2.0, 0.0, 0.0)),
        fluid,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate() {
        for p in PRESETS {
            preset(p).unwrap().validate().unwrap();
        }
        assert!(preset("nope").is_err());
    }

    #[test]
    fn usm_paper_table_ii_totals() {
        // USM Table II: total mass 81.3 kg, total length 3.300 m.
        let v = usm_paper();
        assert!((v.total_mass() - 81.3).abs() < 1e-9);
        assert!((v.total_length() - 3.3).abs() < 1e-9);
        assert_eq!(v.n_joints(), 8);
        assert_eq!(v.n_thrusters(), 7);
    }
}

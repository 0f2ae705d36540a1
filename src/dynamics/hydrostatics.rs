//! Hydrostatics of a design (docs/model.md §4 "Restoring forces"): weight, buoyancy and wet
//! weight, the centres of gravity and buoyancy of the whole vehicle, its metacentric height,
//! the restoring moments per radian of roll and pitch and the trim attitude, at one
//! configuration `q` of the chain held rigid. For `usm-study inspect` and the design drawing;
//! not a hot path (it allocates).
//!
//! Frames: the base frame `F_b` with the base level (`R_Ib = I`, inertial z up). Moments are
//! taken about the vehicle's centre of gravity `G`, where the weight makes none, so they are
//! the buoyancy's alone: with `r = C − G` (`C` the centre of buoyancy) and the inertial
//! vertical `û = R_Ibᵀ e_z` in `F_b`, the restoring moment is `m = r × (B û)`.

use super::hydro::Restoring;
use crate::kinematics::{forward_kinematics, KinWorkspace};
use crate::model::Vehicle;
use crate::spatial::Vec3;
use serde::Serialize;

/// The hydrostatics of one body (its own frame).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BodyHydrostatics {
    /// The body's name.
    pub name: String,
    /// Wet weight `m g − ρ V g` [N]: positive sinks, negative floats.
    pub wet_weight: f64,
    /// `CB − CG` in the body frame [m].
    pub cb_minus_cg: [f64; 3],
    /// The body's metacentric height: the z component of `CB − CG` [m] (positive: the centre
    /// of buoyancy above the centre of gravity when the body is level, a righting moment).
    pub metacentric_height: f64,
}

/// The hydrostatics of the whole vehicle at one configuration (module doc for frames).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Hydrostatics {
    /// Weight `W = Σ m_i g` [N].
    pub weight: f64,
    /// Buoyancy `B = Σ ρ V_i g` [N].
    pub buoyancy: f64,
    /// Wet weight `W − B` [N]: positive sinks, negative floats (0: neutral, the paper's "wet
    /// mass 0").
    pub wet_weight: f64,
    /// Centre of gravity `G = Σ m_i p_G,i / Σ m_i` in `F_b` [m].
    pub centre_of_gravity: [f64; 3],
    /// Centre of buoyancy `C = Σ V_i p_B,i / Σ V_i` in `F_b` [m].
    pub centre_of_buoyancy: [f64; 3],
    /// Metacentric height `GM = (C − G)_z` [m]. A submerged body has no waterplane, so its
    /// metacentre is its centre of buoyancy and the transverse (roll) and longitudinal (pitch)
    /// metacentric heights are both this distance.
    pub metacentric_height: f64,
    /// Roll restoring moment per radian about `G`, `K_φ = −∂m_x/∂φ = B·GM` at level
    /// [N·m/rad]; positive rights the vehicle, negative capsizes it, 0 is neutral.
    pub roll_restoring_moment: f64,
    /// Pitch restoring moment per radian about `G`, `K_θ = −∂m_y/∂θ = B·GM` at level
    /// [N·m/rad].
    pub pitch_restoring_moment: f64,
    /// Restoring moment about `G` at level, `[m_x, m_y] = B [r_y, −r_x]` [N·m]: what the
    /// thrusters must hold to keep the vehicle level (zero when C is straight above G).
    pub level_moment: [f64; 2],
    /// Trim roll [deg]: the ZYX roll of the attitude at which the restoring moment vanishes
    /// stably (`û` along `r`: `φ = atan2(r_y, r_z)`); `None` when `C = G` (neutral: every
    /// attitude is an equilibrium).
    pub trim_roll_deg: Option<f64>,
    /// Trim pitch [deg] of that attitude, `θ = asin(−r_x/|r|)` (positive nose down, the ZYX
    /// pitch about `y` with z up); `None` when `C = G`.
    pub trim_pitch_deg: Option<f64>,
    /// Per body, tail to head.
    pub bodies: Vec<BodyHydrostatics>,
}

/// The hydrostatics of `v` at joint angles `q` (length `n`; the chain held rigid there), in
/// fluid of `v.fluid.rho` and `v.fluid.g` (module doc for the frames and formulas).
pub fn hydrostatics(v: &Vehicle, q: &[f64]) -> Hydrostatics {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, q, &mut ws);
    let (rho, g) = (v.fluid.rho, v.fluid.g);
    let (mut mass, mut volume) = (0.0, 0.0);
    let (mut first_g, mut first_b) = (Vec3::zeros(), Vec3::zeros());
    let mut bodies = Vec::with_capacity(v.bodies.len());
    for (b, pose) in v.bodies.iter().zip(&ws.g_b) {
        mass += b.mass;
        volume += b.volume;
        first_g += pose.act_point(&b.cg) * b.mass;
        first_b += pose.act_point(&b.cb) * b.volume;
        let r = Restoring::of(b, rho, g);
        let d = b.cb - b.cg;
        bodies.push(BodyHydrostatics {
            name: b.name.clone(),
            wet_weight: r.weight - r.buoyancy,
            cb_minus_cg: [d.x, d.y, d.z],
            metacentric_height: d.z,
        });
    }
    let centre_g = if mass > 0.0 { first_g / mass } else { first_g };
    let centre_b = if volume > 0.0 {
        first_b / volume
    } else {
        centre_g
    };
    let (weight, buoyancy) = (mass * g, rho * volume * g);
    let r = centre_b - centre_g;
    let level = Vec3::z().scale(buoyancy);
    let m0 = r.cross(&level);
    let norm = r.norm();
    // C = G to rounding (a neutral design whose centres coincide body by body): no trim.
    let (trim_roll, trim_pitch) = if norm > 1e-12 * v.total_length().max(1.0) {
        (
            Some(r.y.atan2(r.z).to_degrees()),
            Some((-r.x / norm).clamp(-1.0, 1.0).asin().to_degrees()),
        )
    } else {
        (None, None)
    };
    Hydrostatics {
        weight,
        buoyancy,
        wet_weight: weight - buoyancy,
        centre_of_gravity: centre_g.into(),
        centre_of_buoyancy: centre_b.into(),
        metacentric_height: r.z,
        roll_restoring_moment: buoyancy * r.z,
        pitch_restoring_moment: buoyancy * r.z,
        level_moment: [m0.x, m0.y],
        trim_roll_deg: trim_roll,
        trim_pitch_deg: trim_pitch,
        bodies,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::generator::GeneratorSpec;
    use crate::model::{presets, Body, Fluid, Hydro, Vehicle};
    use crate::spatial::{Mat3, Se3, Vec6};
    use nalgebra::Rotation3;

    /// One neutral cylinder (the first body of usm-paper's size) with its CG `gm` below its CB.
    fn one_body(gm: f64) -> Vehicle {
        let mut b = Body::cylinder("L", 14.3, 0.62, 0.085, Hydro::cylinder(0.8, 1.0));
        b.volume = b.mass / 1026.0;
        b.cg.z -= gm;
        Vehicle {
            name: "one".into(),
            bodies: vec![b],
            joints: vec![],
            thrusters: vec![],
            base: Se3::identity(),
            end_effector: Se3::from_translation(Vec3::new(0.62, 0.0, 0.0)),
            fluid: Fluid::default(),
        }
    }

    /// The restoring moment about `G` of every body's wrench (`Restoring::wrench`, the one the
    /// simulator applies) with the whole chain at `q` rotated by `rot` (base → inertial).
    fn moment_about_g(v: &Vehicle, q: &[f64], rot: &Mat3) -> Vec3 {
        let h = hydrostatics(v, q);
        let g = Vec3::from(h.centre_of_gravity);
        let mut ws = KinWorkspace::new(v);
        forward_kinematics(v, q, &mut ws);
        let mut m = Vec3::zeros();
        for (b, pose) in v.bodies.iter().zip(&ws.g_b) {
            let w: Vec6 = Restoring::of(b, v.fluid.rho, v.fluid.g).wrench(&(rot * pose.r));
            // Body wrench → base frame, about the base origin, then about G.
            let f = pose.r * Vec3::new(w[0], w[1], w[2]);
            let mo = pose.r * Vec3::new(w[3], w[4], w[5]) + pose.p.cross(&f);
            m += mo - g.cross(&f);
        }
        m
    }

    #[test]
    fn one_body_restores_with_m_g_gm_sin_phi() {
        // Closed form of a submerged, neutrally buoyant body with its CB a distance GM above
        // its CG: righting moment −m g GM sin φ in roll and −m g GM sin θ in pitch (Fossen,
        // Handbook of Marine Craft Hydrodynamics and Motion Control, 2011, §4.1, g(η) with
        // W = B, x_g = x_b, z_b − z_g = GM).
        let gm = 0.02;
        let v = one_body(gm);
        let mg = 14.3 * 9.81;
        let h = hydrostatics(&v, &[]);
        assert!(h.wet_weight.abs() < 1e-12 * mg);
        assert!((h.metacentric_height - gm).abs() < 1e-15);
        assert!((h.roll_restoring_moment - mg * gm).abs() < 1e-12 * mg * gm);
        assert!((h.pitch_restoring_moment - mg * gm).abs() < 1e-12 * mg * gm);
        assert_eq!(h.trim_roll_deg, Some(0.0));
        assert_eq!(h.trim_pitch_deg.map(f64::abs), Some(0.0));
        for a in [-2.5, -0.7, 0.1, 0.4, 1.2, 3.0] {
            let r = Restoring::of(&v.bodies[0], 1026.0, 9.81);
            let roll = r.wrench(Rotation3::from_euler_angles(a, 0.0, 0.0).matrix());
            let pitch = r.wrench(Rotation3::from_euler_angles(0.0, a, 0.0).matrix());
            let expect = -mg * gm * f64::sin(a);
            assert!((roll[3] - expect).abs() < 1e-12 * mg * gm, "roll {a}");
            assert!((pitch[4] - expect).abs() < 1e-12 * mg * gm, "pitch {a}");
            // A pure couple: no net force, the other moment components zero.
            assert!(roll.fixed_rows::<3>(0).norm() < 1e-12 * mg);
            assert!(roll[4].abs() + roll[5].abs() < 1e-12 * mg * gm);
        }
    }

    #[test]
    fn vehicle_stiffness_is_the_slope_of_the_simulated_restoring_moment() {
        // A generated chain with a metacentric height, bent, with a buoyancy surplus: the
        // reported K_φ and K_θ equal the central difference of the restoring moment about G
        // that the simulator's per-body wrenches make, and the reported trim attitude is where
        // that moment vanishes.
        let mut v = GeneratorSpec {
            links: 4,
            metacentric_height: 0.015,
            ..Default::default()
        }
        .build("g")
        .unwrap();
        for b in &mut v.bodies {
            b.volume *= 1.01;
            b.cb.x += 0.003;
        }
        let q = [0.3, -0.2, 0.1, 0.25, -0.4, 0.05];
        let h = hydrostatics(&v, &q);
        let eps = 1e-6;
        let rx = |a: f64| *Rotation3::from_euler_angles(a, 0.0, 0.0).matrix();
        let ry = |a: f64| *Rotation3::from_euler_angles(0.0, a, 0.0).matrix();
        let k_roll = -(moment_about_g(&v, &q, &rx(eps)).x - moment_about_g(&v, &q, &rx(-eps)).x)
            / (2.0 * eps);
        let k_pitch = -(moment_about_g(&v, &q, &ry(eps)).y - moment_about_g(&v, &q, &ry(-eps)).y)
            / (2.0 * eps);
        let scale = h.roll_restoring_moment.abs();
        assert!(scale > 1.0, "{scale}");
        assert!(
            (k_roll - h.roll_restoring_moment).abs() < 1e-6 * scale,
            "{k_roll}"
        );
        assert!(
            (k_pitch - h.pitch_restoring_moment).abs() < 1e-6 * scale,
            "{k_pitch}"
        );
        let level = moment_about_g(&v, &q, &Mat3::identity());
        assert!((level.x - h.level_moment[0]).abs() < 1e-9 * scale);
        assert!((level.y - h.level_moment[1]).abs() < 1e-9 * scale);
        let trim = *Rotation3::from_euler_angles(
            h.trim_roll_deg.unwrap().to_radians(),
            h.trim_pitch_deg.unwrap().to_radians(),
            0.0,
        )
        .matrix();
        assert!(moment_about_g(&v, &q, &trim).norm() < 1e-9 * scale);
        assert!((h.wet_weight + 0.01 * h.weight).abs() < 1e-9 * h.weight);
    }

    #[test]
    fn usm_paper_is_neutral_with_cb_at_cg() {
        // The preset's inference from "wet mass 0": W = B, C = G, no restoring moment.
        let v = presets::usm_paper();
        let h = hydrostatics(&v, &[0.0; 8]);
        assert!(h.wet_weight.abs() < 1e-9 * h.weight);
        assert!(h.roll_restoring_moment.abs() < 1e-9);
        assert_eq!(h.trim_roll_deg, None);
        assert!((h.weight - 81.3 * 9.81).abs() < 1e-9);
    }
}

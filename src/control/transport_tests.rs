//! Tests of the transport controller (USM-38 … USM-41): measurements, joint references and the
//! commanded accelerations.

use super::*;
use crate::kinematics::forward_kinematics;
use crate::model::presets::{usm_paper, uvms_planar};
use nalgebra::UnitQuaternion;

fn path() -> PathSpec {
    PathSpec {
        waypoints: vec![[0.0, 0.0], [100.0, 0.0]],
        ..Default::default()
    }
}

#[test]
fn yaw_joints_of_presets() {
    let mask = yaw_joint_mask(&usm_paper());
    assert_eq!(
        mask,
        vec![true, false, true, false, true, false, true, false]
    );
    assert!(yaw_joint_mask(&uvms_planar()).iter().all(|y| *y));
}

#[test]
fn positive_yaw_joint_turns_head_left() {
    // The premise of the sign derivation: Σ q_yaw adds to the head heading.
    let v = usm_paper();
    let mut ws = KinWorkspace::new(&v);
    let q = [0.1, 0.0, 0.2, 0.0, -0.05, 0.0, 0.15, 0.0];
    forward_kinematics(&v, &q, &mut ws);
    let meas = measure_transport(&BasePose::default(), &ws, &Vec6::zeros(), &[0.0; 8]);
    assert!((meas.psi - 0.4).abs() < 1e-12);
}

/// Base fixed at heading ψ_b, joints follow q_r through first-order servos (time constant
/// T); ψ from forward kinematics each step. Returns the final head heading.
fn servo_loop(sign: f64, psi_b: f64, psi_r: f64) -> (f64, Vec<f64>) {
    let v = usm_paper();
    let gains = TransportGains {
        joint_sign: sign,
        ..TransportGains::method2()
    };
    let ctl = TransportController::new(&v, gains, &path()).unwrap();
    let mut ws = KinWorkspace::new(&v);
    let base = BasePose {
        orientation: UnitQuaternion::from_euler_angles(0.0, 0.0, psi_b),
        position: Vec3::zeros(),
    };
    let (dt, tau) = (0.01, 0.5);
    let mut q = vec![0.0; 8];
    let mut qr = vec![0.0; 8];
    let mut psi = psi_b;
    for _ in 0..2000 {
        forward_kinematics(&v, &q, &mut ws);
        psi = measure_transport(&base, &ws, &Vec6::zeros(), &[0.0; 8]).psi;
        ctl.joint_references(psi, psi_r, &mut qr);
        for (qi, ri) in q.iter_mut().zip(&qr) {
            *qi += dt / tau * (ri - *qi);
        }
    }
    (psi, q)
}

#[test]
fn usm38_sign_bends_head_towards_reference() {
    // Head (and tail) pointing 0.3 rad left of the reference ψ_r = 0.
    let (psi_b, psi_r) = (0.3, 0.0);
    // Derived sign −1: one law application turns the head towards ψ_r relative to the base,
    // and with servos it settles at ψ − ψ_r = (ψ_b − ψ_r)/(1 + 4k_ψ) (4 yaw joints).
    let (psi, q) = servo_loop(-1.0, psi_b, psi_r);
    assert!(
        q[0] < 0.0 && q[1] == 0.0,
        "yaw joints bend right, pitch stays 0: {q:?}"
    );
    let expect = (psi_b - psi_r) / (1.0 + 4.0 * 0.45);
    assert!((psi - expect).abs() < 1e-6, "{psi} vs {expect}");
    assert!((psi - psi_r).abs() < (psi_b - psi_r).abs());
    // The paper's sign read in our convention runs away to the joint limits, head turned
    // further from ψ_r than the tail.
    let (psi_bad, q_bad) = servo_loop(1.0, psi_b, psi_r);
    assert!((psi_bad - psi_r).abs() > (psi_b - psi_r).abs());
    assert!(q_bad[0] > 0.5, "{q_bad:?}");
    // And symmetric for a head pointing right of the reference.
    let (psi, _) = servo_loop(-1.0, -0.2, 0.1);
    assert!((psi - 0.1 - (-0.3) / 2.8).abs() < 1e-6);
}

#[test]
fn accelerations_follow_usm40_41() {
    let v = usm_paper();
    let mut ctl = TransportController::new(&v, TransportGains::method1(), &path()).unwrap();
    // Method 1 regulates the end-effector surge.
    let meas = TransportMeasurement {
        psi: 0.2,
        psi_dot: 0.05,
        surge_ee: 0.3,
        surge_base: 0.9,
        ee_position: Vec3::new(5.0, 1.0, 0.0),
        ee_velocity: Vec3::new(0.3, 0.0, 0.0),
        ..Default::default()
    };
    let out = ctl.step(0.0, &meas, 0.1);
    let e = 0.3 - 0.5;
    assert!((out.surge_error - e).abs() < 1e-15);
    assert!((ctl.surge_integral() - e * 0.1).abs() < 1e-15);
    assert!((out.a_b[0] - (-0.5 * e - 0.0625 * e * 0.1)).abs() < 1e-15);
    let los = out.los;
    assert!((los.psi_r + (1.0f64 / 3.0).atan()).abs() < 1e-12);
    let a6 = -0.13 * (0.2 - los.psi_r) - 0.12 * (0.05 - los.psi_r_dot);
    assert!((out.a_b[5] - a6).abs() < 1e-15);
    assert_eq!([out.a_b[1], out.a_b[2], out.a_b[3], out.a_b[4]], [0.0; 4]);
    // ψ > ψ_r: yaw acceleration to the right, surge too slow: accelerate forward.
    assert!(out.a_b[5] < 0.0 && out.a_b[0] > 0.0);
    // Heading error is wrapped across ±π.
    let a = ctl.yaw_acceleration(3.1, 0.0, -3.1, 0.0);
    assert!((a - (-0.13 * (6.2 - 2.0 * std::f64::consts::PI))).abs() < 1e-12);
}

#[test]
fn pd_surge_form() {
    let v = usm_paper();
    let g = TransportGains {
        surge_law: SurgeLaw::ProportionalDerivative,
        derivative_time_constant: 0.0,
        ..TransportGains::method2()
    };
    let mut ctl = TransportController::new(&v, g, &path()).unwrap();
    assert!((ctl.surge_acceleration(0.4, 0.1) - (-0.5 * -0.1)).abs() < 1e-15);
    // Error −0.1 → −0.05 over 0.1 s: rate 0.5, k_1d = 0.0625.
    let a = ctl.surge_acceleration(0.45, 0.1);
    assert!((a - (0.5 * 0.05 - 0.0625 * 0.5)).abs() < 1e-12, "{a}");
}

#[test]
fn measurement_matches_jacobian() {
    let v = usm_paper();
    let mut ws = KinWorkspace::new(&v);
    let q = [0.3, -0.2, 0.1, 0.25, -0.4, 0.1, 0.2, -0.1];
    forward_kinematics(&v, &q, &mut ws);
    let vb = Vec6::new(0.4, 0.1, -0.05, 0.02, -0.03, 0.1);
    let qd = [0.1, -0.2, 0.05, 0.0, 0.3, -0.1, 0.2, 0.1];
    let base = BasePose {
        orientation: UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7),
        position: Vec3::new(1.0, 2.0, -3.0),
    };
    let meas = measure_transport(&base, &ws, &vb, &qd);
    let mut j = faer::Mat::<f64>::zeros(6, 14);
    crate::kinematics::ee_jacobian(&ws, &mut j);
    let zeta: Vec<f64> = vb.iter().chain(qd.iter()).copied().collect();
    let ve: Vec<f64> = (0..6)
        .map(|r| (0..14).map(|c| j[(r, c)] * zeta[c]).sum())
        .collect();
    assert!((meas.surge_ee - ve[0]).abs() < 1e-12);
    assert!((meas.surge_base - 0.4).abs() < 1e-15);
    assert!((meas.base_heading - 0.7).abs() < 1e-12);
    let g_ie = base.to_se3().compose(&ws.g_be);
    let vi = g_ie.r * Vec3::new(ve[0], ve[1], ve[2]);
    assert!((meas.ee_velocity - vi).norm() < 1e-12);
    assert!((meas.psi_dot - heading_rate(&g_ie.r, &Vec3::new(ve[3], ve[4], ve[5]))).abs() < 1e-12);
}

#[test]
fn gains_from_toml() {
    let g: TransportGains = toml::from_str(r#"method = "method1""#).unwrap();
    assert_eq!(g, TransportGains::method1());
    let g: TransportGains =
        toml::from_str("k_psi = 0.3\nk_1d = 0.1\nsurge_law = \"proportional_derivative\"").unwrap();
    assert_eq!(g.method, TransportMethod::Method2);
    assert_eq!((g.k_psi, g.k_1i, g.look_ahead), (0.3, 0.1, 2.0));
    assert_eq!(g.surge_law, SurgeLaw::ProportionalDerivative);
    let g: TransportGains = toml::from_str("").unwrap();
    assert_eq!(g, TransportGains::method2());
    assert_eq!(g.surge_source, SurgeSource::Base);
    assert!(toml::from_str::<TransportGains>("kpsi = 1").is_err());
    let e = toml::from_str::<TransportGains>("joint_sign = 2.0").unwrap_err();
    assert!(e.to_string().contains("transport.joint_sign"), "{e}");
    // Round trip through the serialised form.
    let s = toml::to_string(&TransportGains::method1()).unwrap();
    assert_eq!(
        toml::from_str::<TransportGains>(&s).unwrap(),
        TransportGains::method1()
    );
}

/// Closed-loop transport run on the full hydrodynamic model with damped-pseudoinverse
/// allocation (λ = 0.1): the paper's scenario shape (start 3 m off a +X line, 180° turn onto
/// a −X line at t = 95 s). Returns (|e_y| at 90 s, |e_y| at 140 s, peak |u|).
fn closed_loop(gains: TransportGains, nonlinear: bool) -> (f64, f64, f64) {
    use crate::allocation::damped_pinv;
    use crate::control::dynamic::{DynamicController, DynamicGains};
    use crate::dynamics::{ActuatorCommand, SimConfig, Simulator};
    use crate::kinematics::thruster_matrix_owned;
    let v = usm_paper();
    let path: PathSpec = toml::from_str(
        r#"segments = [
             { from = [0.0, 3.0], to = [1000.0, 3.0] },
             { from = [1000.0, 6.0], to = [-1000.0, 6.0], start_time = 95.0 },
           ]"#,
    )
    .unwrap();
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    let mut ctl = TransportController::new(&v, gains, &path).unwrap();
    let dync = DynamicController::new(DynamicGains {
        nonlinear,
        ..DynamicGains::transport()
    })
    .unwrap();
    let mut ws = KinWorkspace::new(&v);
    let dt = 0.05;
    let (mut e90, mut peak) = (f64::NAN, 0.0f64);
    let mut e_end = f64::NAN;
    let zero = vec![0.0; v.n_joints()];
    for k in 0..=2800 {
        let t = k as f64 * dt;
        let st = sim.state().clone();
        forward_kinematics(&v, &st.joint_angles, &mut ws);
        let meas = measure_transport(&st.pose, &ws, &st.base_twist, &st.joint_rates);
        let out = ctl.step(t, &meas, dt);
        if k == 1800 {
            e90 = out.los.cross_track.abs();
        }
        e_end = out.los.cross_track.abs();
        let (m11, n) = sim.base_control_terms().unwrap();
        let tau = dync.acceleration_control(&m11, &n, &out.a_b);
        let tm = thruster_matrix_owned(&v, &ws);
        let u = damped_pinv(&tm, &tau, &[1.0; 7], 0.1).unwrap();
        peak = peak.max(u.iter().fold(0.0f64, |a, x| a.max(x.abs())));
        let cmd = ActuatorCommand {
            thrust: &u,
            joint_ref: ctl.q_ref(),
            joint_rate_ref: &zero,
        };
        if sim.step(dt, &cmd).is_err() {
            return (f64::INFINITY, f64::INFINITY, peak);
        }
    }
    (e90, e_end, peak)
}

#[test]
#[ignore = "closed-loop experiment on the dynamics (seconds); run with --ignored"]
fn closed_loop_transport_derived_sign_beats_paper_sign() {
    // Evidence for USM-38's sign in closed loop (full hydrodynamics, unconstrained
    // allocation, paper gains untuned for this model): with s_q = +1 the vehicle loses the
    // path; with s_q = −1 it stays within about a metre (not a tuning result — the residual
    // oscillation is for the scenario to study). Prints a table of the open choices.
    for g in [TransportGains::method1(), TransportGains::method2()] {
        let mut by_sign = [0.0; 2];
        for src in [YawRateSource::FrontHeading, YawRateSource::BaseYawRate] {
            for (sign, nl) in [(-1.0, true), (-1.0, false), (1.0, true)] {
                let gg = TransportGains {
                    joint_sign: sign,
                    yaw_rate_source: src,
                    ..g.clone()
                };
                let (e90, e_end, peak) = closed_loop(gg, nl);
                eprintln!(
                    "{:?} {src:?} sign {sign} n {nl}: |e_y|(90 s) = {e90:.3}, |e_y|(140 s) = {e_end:.3}, peak u = {peak:.1}",
                    g.method
                );
                if src == YawRateSource::FrontHeading && nl {
                    by_sign[usize::from(sign > 0.0)] = e_end;
                }
            }
        }
        assert!(3.0 * by_sign[0] < by_sign[1], "{by_sign:?}");
        assert!(by_sign[0] < 2.0, "{by_sign:?}");
    }
}

/// A level measurement on the path's line at depth `z` with the base's up direction
/// `up` (in `F_b`) and body rates `rates`.
fn attitude_meas(z: f64, up: Vec3, rates: Vec3, roll_authority: bool) -> TransportMeasurement {
    TransportMeasurement {
        ee_position: Vec3::new(5.0, 0.0, z),
        ee_velocity: Vec3::new(0.5, 0.0, 0.0),
        surge_base: 0.5,
        surge_ee: 0.5,
        base_z: z,
        base_up: up,
        base_rates: rates,
        roll_authority,
        ..Default::default()
    }
}

#[test]
fn the_autopilot_is_off_by_default_and_the_paper_laws_are_unchanged() {
    let v = usm_paper();
    for g in [TransportGains::method1(), TransportGains::method2()] {
        assert!(!g.autopilot);
        let mut off = TransportController::new(&v, g.clone(), &path()).unwrap();
        // Rolled 30°, pitched, 2 m below the start: the paper's laws command none of it.
        let up = Vec3::new(-0.2, 0.5, 0.84).normalize();
        off.step(
            0.0,
            &attitude_meas(0.0, Vec3::z(), Vec3::zeros(), true),
            0.05,
        );
        let out = off.step(
            0.05,
            &attitude_meas(-2.0, up, Vec3::new(0.3, 0.1, 0.0), true),
            0.05,
        );
        assert_eq!(&out.a_b.as_slice()[1..5], &[0.0; 4]);
        assert!(!out.roll_commanded);
        assert_eq!(off.depth_integral(), 0.0);
    }
}

#[test]
fn the_autopilot_holds_depth_with_a_bounded_integral_and_levels_the_base() {
    let v = usm_paper();
    let g = TransportGains {
        autopilot: true,
        ..TransportGains::method2()
    };
    let (kzp, kzi, lim) = (g.k_depth_p, g.k_depth_i, g.depth_integral_limit);
    let mut ctl = TransportController::new(&v, g.clone(), &path()).unwrap();
    // The first step fixes the depth reference (−1.5 m, where the vehicle starts).
    let out = ctl.step(
        0.0,
        &attitude_meas(-1.5, Vec3::z(), Vec3::zeros(), false),
        0.1,
    );
    assert_eq!(ctl.depth_reference(), Some(-1.5));
    assert_eq!(&out.a_b.as_slice()[1..5], &[0.0; 4]);
    // 0.4 m too deep, level: a_z = −k_zp e − k_zi ∫e along the base z (= inertial z).
    let out = ctl.step(
        0.1,
        &attitude_meas(-1.9, Vec3::z(), Vec3::zeros(), false),
        0.1,
    );
    let e = -0.4;
    let expect = -kzp * e - kzi * (e * 0.1);
    assert!((ctl.depth_integral() - e * 0.1).abs() < 1e-15);
    assert!((out.a_b[2] - expect).abs() < 1e-15, "{}", out.a_b[2]);
    assert!(expect > 0.0, "pushes up");
    // Anti-windup: the integral stops at its bound.
    for k in 0..2000 {
        ctl.step(
            0.2 + k as f64 * 0.1,
            &attitude_meas(-1.9, Vec3::z(), Vec3::zeros(), false),
            0.1,
        );
    }
    assert_eq!(ctl.depth_integral(), -lim);
    // Rolled by φ about the base x axis: up = (0, sin φ, cos φ); the roll law acts only with
    // authority, the pitch law always. The error is the exact angle (2.5 rad, not sin 2.5).
    ctl.reset();
    for (phi, p, auth) in [(0.1, 0.02, true), (2.5, -0.1, true), (0.1, 0.02, false)] {
        let up = Vec3::new(0.0, f64::sin(phi), f64::cos(phi));
        let meas = attitude_meas(0.0, up, Vec3::new(p, 0.0, 0.0), auth);
        let out = ctl.step(0.0, &meas, 0.1);
        let want = if auth {
            -g.k_roll_p * phi - g.k_roll_d * p
        } else {
            0.0
        };
        assert!(
            (out.a_b[3] - want).abs() < 1e-12,
            "φ {phi}: {} vs {want}",
            out.a_b[3]
        );
        assert_eq!(out.roll_commanded, auth);
        assert!(out.a_b[4].abs() < 1e-12);
    }
    // Pitched by θ about the base y axis: up = (−sin θ, 0, cos θ).
    let th = 0.2;
    let up = Vec3::new(-f64::sin(th), 0.0, f64::cos(th));
    let out = ctl.step(
        0.0,
        &attitude_meas(0.0, up, Vec3::new(0.0, 0.05, 0.0), false),
        0.1,
    );
    assert!((out.a_b[4] - (-g.k_pitch_p * th - g.k_pitch_d * 0.05)).abs() < 1e-12);
    // The tilt error is that of the base's actual attitude: a base rolled by φ (ZYX, any
    // heading) measured through `measure_transport` gives up = R_Ibᵀ e_z = (0, sin φ, cos φ).
    let mut ws = KinWorkspace::new(&v);
    forward_kinematics(&v, &[0.0; 8], &mut ws);
    let base = BasePose {
        orientation: UnitQuaternion::from_euler_angles(0.3, 0.0, 1.1),
        position: Vec3::new(1.0, 2.0, -3.0),
    };
    let m = measure_transport(&base, &ws, &Vec6::zeros(), &[0.0; 8]);
    assert!((m.base_up - Vec3::new(0.0, 0.3f64.sin(), 0.3f64.cos())).norm() < 1e-12);
    assert_eq!(m.base_z, -3.0);
}

#[test]
fn autopilot_keys_parse_and_are_checked() {
    let g: TransportGains =
        toml::from_str("autopilot = true\nk_depth_p = 0.5\nk_roll_d = 2.0").unwrap();
    assert!(g.autopilot);
    assert_eq!((g.k_depth_p, g.k_roll_d, g.k_depth_i), (0.5, 2.0, 0.02));
    let e = toml::from_str::<TransportGains>("k_depth_i = -1.0").unwrap_err();
    assert!(e.to_string().contains("transport.k_depth_i"), "{e}");
    let s = toml::to_string(&g).unwrap();
    assert_eq!(toml::from_str::<TransportGains>(&s).unwrap(), g);
}

//! Antonelli & Chiaverini (1998) kinematic case studies on `uvms-planar` (docs/model.md §8): the
//! inertial-frame task variables, the singularity-robust task priority (AC-7…9) and the
//! paper's cases 1, 1b and 2. Reference values are the seed's text
//! (`shared/seeds/004_2e118a4aa85a2683.txt`, section 5).

use faer::MatRef;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use usm_study::control::{InertialTask, Srmtp, TaskInverse, TaskVariable};
use usm_study::kinematics::{forward_kinematics, BasePose, KinWorkspace};
use usm_study::model::presets::preset;
use usm_study::model::Vehicle;
use usm_study::paper::antonelli::{
    antonelli_case, planar_weights, run_kinematic_case, AntonelliCase, KinematicHistory,
};
use usm_study::spatial::Vec3;

use TaskVariable::*;

const PRIMARY_CASE2: [TaskVariable; 4] = [EePosition(0), EePosition(1), EeHeading, Joint(1)];
const SECONDARY: [TaskVariable; 2] = [BasePosition(0), BasePosition(1)];

fn planar() -> Vehicle {
    preset("uvms-planar").unwrap()
}

/// Tasks evaluated at the planar state `s = (x, y, ψ, q1, q2, q3)`.
struct At {
    p: InertialTask,
    s: InertialTask,
}

fn at(v: &Vehicle, primary: &[TaskVariable], s: &[f64]) -> At {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &s[3..], &mut ws);
    let base = BasePose {
        orientation: nalgebra::UnitQuaternion::from_axis_angle(&Vec3::z_axis(), s[2]),
        position: Vec3::new(s[0], s[1], 0.0),
    };
    let mut p = InertialTask::new(primary, 3).unwrap();
    let mut sec = InertialTask::new(&SECONDARY, 3).unwrap();
    p.update(&base, &ws, &s[3..]);
    sec.update(&base, &ws, &s[3..]);
    At { p, s: sec }
}

/// AC-7 with the crate's solver: returns ζ and σ_min(J_s N_p).
fn resolve(a: &At, w_p: &[f64], w_s: &[f64]) -> (Vec<f64>, f64) {
    let mut srmtp = Srmtp::new(9, 6, &planar_weights(3), 0.0).unwrap();
    srmtp.reset();
    let exact = TaskInverse::weighted(0.0);
    srmtp.push_task(a.p.jacobian(), w_p, exact).unwrap();
    let sigma = srmtp.projected_singular_value(a.s.jacobian());
    srmtp.push_task(a.s.jacobian(), w_s, exact).unwrap();
    (srmtp.zeta().to_vec(), sigma)
}

fn mul_vec(j: MatRef<'_, f64>, x: &[f64]) -> Vec<f64> {
    (0..j.nrows())
        .map(|r| (0..j.ncols()).map(|c| j[(r, c)] * x[c]).sum())
        .collect()
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|a| a * a).sum::<f64>().sqrt()
}

fn random_state(rng: &mut ChaCha8Rng) -> Vec<f64> {
    let mut s: Vec<f64> = (0..3).map(|_| rng.random_range(-2.0..2.0)).collect();
    // Joint angles away from the arm's stretched (q2 = 0, q3 = 0) singularities.
    s.push(rng.random_range(-2.5..2.5));
    for _ in 0..2 {
        let mag = rng.random_range(0.3..2.5);
        s.push(if rng.random_bool(0.5) { mag } else { -mag });
    }
    s
}

#[test]
fn initial_end_effector_matches_the_paper() {
    // Seed, section 5: q = (1.47, −1.00, 0.30) at vehicle (0, 0, 0) "corresponding to the
    // end-effector location x_e = 5.92, y_e = 4.29, ψ_e = 0.77" (two decimals).
    let v = planar();
    let a = at(
        &v,
        &[EePosition(0), EePosition(1), EeHeading],
        &[0.0, 0.0, 0.0, 1.47, -1.0, 0.3],
    );
    let want = [5.92, 4.29, 0.77];
    for (x, w) in a.p.value().iter().zip(want) {
        assert!((x - w).abs() < 0.005, "{x} vs {w}");
    }
}

#[test]
fn task_jacobians_match_finite_differences() {
    let v = planar();
    let vars = [
        EePosition(0),
        EePosition(1),
        EeHeading,
        BaseHeading,
        Joint(2),
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for _ in 0..20 {
        let s = random_state(&mut rng);
        // A planar ζ = (u, v, 0, 0, 0, r, q̇) and the state rate it implies.
        let z: Vec<f64> = (0..9)
            .map(|i| {
                if (2..5).contains(&i) {
                    0.0
                } else {
                    rng.random_range(-1.0..1.0)
                }
            })
            .collect();
        let (c, sn) = (s[2].cos(), s[2].sin());
        let ds = [
            c * z[0] - sn * z[1],
            sn * z[0] + c * z[1],
            z[5],
            z[6],
            z[7],
            z[8],
        ];
        let h = 1e-6;
        let shifted = |sign: f64| -> Vec<f64> {
            let sp: Vec<f64> = s.iter().zip(ds).map(|(a, b)| a + sign * h * b).collect();
            at(&v, &vars, &sp).p.value().to_vec()
        };
        let (plus, minus) = (shifted(1.0), shifted(-1.0));
        let a = at(&v, &vars, &s);
        let jz = mul_vec(a.p.jacobian(), &z);
        for r in 0..vars.len() {
            let fd = (plus[r] - minus[r]) / (2.0 * h);
            assert!(
                (fd - jz[r]).abs() < 1e-6,
                "{:?}: fd {fd} vs J ζ {}",
                vars[r],
                jz[r]
            );
        }
    }
}

#[test]
fn robust_priority_fulfils_the_primary_task_exactly() {
    // AC-7: J_p ζ = w_p = ξ̇_p,d + K_p ξ̃_p whenever J_p has full row rank, whatever w_s.
    let v = planar();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for primary in [
        [EePosition(0), EePosition(1), EeHeading, BaseHeading],
        PRIMARY_CASE2,
    ] {
        for _ in 0..50 {
            let s = random_state(&mut rng);
            let a = at(&v, &primary, &s);
            let w_p: Vec<f64> = (0..4).map(|_| rng.random_range(-1.0..1.0)).collect();
            let w_s: Vec<f64> = (0..2).map(|_| rng.random_range(-1.0..1.0)).collect();
            let (z, _) = resolve(&a, &w_p, &w_s);
            let e = norm(
                &mul_vec(a.p.jacobian(), &z)
                    .iter()
                    .zip(&w_p)
                    .map(|(x, y)| x - y)
                    .collect::<Vec<_>>(),
            );
            assert!(e < 1e-10, "{primary:?} at {s:?}: ‖J_p ζ − w_p‖ = {e:e}");
            // Heave, roll and pitch rates stay out of the planar solution.
            assert!(z[2] == 0.0 && z[3] == 0.0 && z[4] == 0.0);
        }
    }
}

#[test]
fn robust_priority_is_bounded_at_an_algorithmic_singularity() {
    // Case 2's tasks: J_s N_p loses rank when the vehicle origin, the arm base and joint 3 are
    // collinear (with q2 held, the rotations of vehicle and joint 1 then leave x, y unchanged
    // to first order): with links of 2 m, joint 3 lies along the vehicle x axis when
    // q1 + q2/2 = 0, e.g. q = (0.5, −1.0, 0.3).
    let v = planar();
    let w_p = [0.3, -0.2, 0.1, 0.05];
    let w_s = [0.4, -0.3];
    let singular = at(&v, &PRIMARY_CASE2, &[0.0, 0.0, 0.0, 0.5, -1.0, 0.3]);
    let (z, sigma) = resolve(&singular, &w_p, &w_s);
    assert!(sigma < 1e-7, "σ_min(J_s N_p) = {sigma}");
    // The classical form would divide by σ; the robust one is bounded by
    // ‖J_p⁺ w_p‖ + ‖J_s⁺ w_s‖ (N_p is an orthogonal projector) and is continuous across.
    let (z_p, _) = resolve(&singular, &w_p, &[0.0, 0.0]);
    let bound = norm(&z_p) + norm(&w_s);
    assert!(norm(&z) <= bound + 1e-12, "{} > {bound}", norm(&z));
    let mut prev: Option<Vec<f64>> = None;
    for k in -20..=20 {
        let q1 = 0.5 + 1e-3 * k as f64;
        let (zk, _) = resolve(
            &at(&v, &PRIMARY_CASE2, &[0.0, 0.0, 0.0, q1, -1.0, 0.3]),
            &w_p,
            &w_s,
        );
        if let Some(p) = prev {
            let d: Vec<f64> = zk.iter().zip(&p).map(|(a, b)| a - b).collect();
            assert!(norm(&d) < 1e-2, "jump {} at q1 = {q1}", norm(&d));
        }
        prev = Some(zk);
    }
    let a = mul_vec(singular.p.jacobian(), &z);
    for (x, y) in a.iter().zip(w_p) {
        assert!((x - y).abs() < 1e-10);
    }
}

fn run(which: AntonelliCase) -> KinematicHistory {
    run_kinematic_case(&planar(), &antonelli_case(which)).unwrap()
}

fn trace<'a>(h: &'a KinematicHistory, name: &str) -> &'a usm_study::paper::antonelli::TaskTrace {
    h.primary
        .iter()
        .chain(&h.secondary)
        .find(|t| t.name == name)
        .unwrap()
}

fn max_joint_rate(h: &KinematicHistory) -> f64 {
    h.qd.iter().flatten().fold(0.0, |a: f64, b| a.max(b.abs()))
}

#[test]
fn case1_reorients_the_vehicle_with_the_end_effector_held() {
    // Seed, section 5: ψ_d from 0 to 0.78 rad by a quintic over 10 s, end-effector and vehicle
    // position desired at their initial values; "the end-effector location and vehicle
    // position are held while the vehicle body is re-oriented".
    let h = run(AntonelliCase::Case1);
    assert!((h.t.last().unwrap() - 10.0).abs() < 1e-12);
    assert!((trace(&h, "psi").final_value() - 0.78).abs() < 1e-6);
    for name in ["x_e", "y_e", "psi_e"] {
        assert!(trace(&h, name).max_abs_error() < 1e-8, "{name}");
    }
    // The robust form leaves the secondary task inexact while the primary moves
    // (J_s J_p⁺ w_p is not compensated): centimetres, recovered with K_s = 2.
    for name in ["x", "y"] {
        let e = trace(&h, name).max_abs_error();
        assert!(e < 0.1, "{name}: {e}");
        assert!(trace(&h, name).final_value().abs() < 0.02, "{name}");
    }
    assert!(max_joint_rate(&h) < 0.5);
}

#[test]
fn case1b_tracks_the_line_and_moves_the_vehicle() {
    // Seed, section 5: straight line to (8.00, 9.00, 0.78) in 10 s; "the end-effector location
    // and vehicle orientation achieve their target. On the other hand, the vehicle is moved".
    let h = run(AntonelliCase::Case1b);
    for (name, end) in [("x_e", 8.0), ("y_e", 9.0), ("psi_e", 0.78), ("psi", 0.78)] {
        let tr = trace(&h, name);
        assert!(tr.max_abs_error() < 1e-8, "{name}");
        assert!((tr.final_value() - end).abs() < 1e-8, "{name}");
    }
    let moved = h.base[0].last().unwrap().hypot(*h.base[1].last().unwrap());
    assert!(moved > 1.0, "vehicle moved {moved} m");
    // The paper's remark: the arm ends "almost completely stretched out" (q2 near 0).
    assert!(h.q[1].last().unwrap().abs() < 0.05);
}

#[test]
fn case2_reaches_q2_with_the_end_effector_tracked_into_an_algorithmic_singularity() {
    // Seed, section 5: q2,d → −0.78 rad by a quintic over 10 s along the same line;
    // "the end-effector location and manipulator joint 2 achieve their target".
    let h = run(AntonelliCase::Case2);
    assert!((trace(&h, "q2").final_value() + 0.78).abs() < 1e-6);
    for (name, end) in [("x_e", 8.0), ("y_e", 9.0), ("psi_e", 0.78)] {
        let tr = trace(&h, name);
        assert!(tr.max_abs_error() < 1e-8, "{name}");
        assert!((tr.final_value() - end).abs() < 1e-8, "{name}");
    }
    // The secondary task (vehicle back to the origin) conflicts with the primary one; its
    // constrained minimum is where J_s N_p loses rank, so the run ends on an algorithmic
    // singularity (σ ≈ 4e-8 at t = 9.98 s at 100 Hz sampling, 1e-6 at t = 10 s; q1 + q2/2 ≈ 0).
    // Rates stay bounded all along.
    let sigma_min = h.sigma_s.iter().fold(f64::INFINITY, |a, b| a.min(*b));
    assert!(sigma_min < 1e-5, "σ_min = {sigma_min}");
    assert!(max_joint_rate(&h) < 1.0);
    let base_rate = (0..h.t.len())
        .map(|i| h.base_rate[0][i].hypot(h.base_rate[1][i]))
        .fold(0.0, f64::max);
    assert!(base_rate < 1.0, "{base_rate}");
}

#[test]
fn history_columns_have_one_value_per_sample() {
    let h = run(AntonelliCase::Case1);
    let cols = h.columns();
    assert_eq!(cols[0].0, "t");
    assert!(cols.iter().all(|(_, c)| c.len() == h.t.len()));
}

#[test]
fn invalid_settings_are_rejected_before_running() {
    let v = planar();
    let mut c = antonelli_case(AntonelliCase::Case2);
    c.q0.pop();
    assert!(run_kinematic_case(&v, &c).is_err());
    let mut c = antonelli_case(AntonelliCase::Case2);
    c.dt = 0.0;
    assert!(run_kinematic_case(&v, &c).is_err());
    let mut c = antonelli_case(AntonelliCase::Case1);
    c.secondary[0].variable = TaskVariable::Joint(7);
    assert!(run_kinematic_case(&v, &c).is_err());
}

//! Tests of the OCP room: linear-quadratic problems with closed-form optima (the discrete
//! Riccati recursion; the condensed KKT system solved densely; Clarabel on the condensed QP
//! with active bounds), the Lie-group retraction, and the rigid chain.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::model::{LinearModel, OcpModel};
use super::sqp::{solve, OcpProblem, SqpSettings, Status};
use crate::dynamics::DynOptions;
use crate::kinematics::BasePose;
use crate::model::design::load_design;
use crate::spatial::Vec3;
use nalgebra::{DMatrix, DVector};
use std::ops::AddAssign;

const NX: usize = 4;
const NU: usize = 2;

/// A lightly unstable, coupled linear system (a discretised double integrator pair with
/// cross-coupling), Δt = 0.1.
fn system() -> (DMatrix<f64>, DMatrix<f64>) {
    let a = DMatrix::from_row_slice(
        NX,
        NX,
        &[
            1.0, 0.1, 0.02, 0.0, //
            0.01, 1.0, 0.0, 0.03, //
            0.0, 0.0, 1.01, 0.1, //
            0.0, -0.02, 0.0, 1.0,
        ],
    );
    let b = DMatrix::from_row_slice(NX, NU, &[0.005, 0.0, 0.1, 0.01, 0.0, 0.005, -0.02, 0.1]);
    (a, b)
}

fn weights() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let q = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 0.5, 2.0, 0.1]));
    let r = DMatrix::from_row_slice(NU, NU, &[0.3, 0.05, 0.05, 0.2]);
    let qn = DMatrix::from_diagonal(&DVector::from_vec(vec![5.0, 1.0, 5.0, 1.0]));
    (q, r, qn)
}

fn linear_problem(n: usize, nc: usize, bound: f64) -> (LinearModel, OcpProblem) {
    let (a, b) = system();
    let (q, r, qn) = weights();
    let c = DMatrix::from_row_slice(2, NX, &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0])
        .rows(0, nc)
        .into_owned();
    let target = DVector::from_vec(vec![0.4, -0.3]).rows(0, nc).into_owned();
    let model = LinearModel {
        a,
        b,
        w: DVector::from_vec(vec![0.0, 0.01, 0.0, -0.005]),
        c,
        target,
    };
    let prob = OcpProblem {
        knots: n,
        x0: vec![1.0, -0.5, 0.3, 0.2],
        x_ref: vec![0.0; NX],
        q,
        r,
        q_n: qn,
        u_lo: vec![-bound; NU],
        u_hi: vec![bound; NU],
    };
    (model, prob)
}

/// The condensed problem `min ½uᵀHu + gᵀu + κ` s.t. `G u = h` (u stacked over stages).
struct Condensed {
    h: DMatrix<f64>,
    g: DVector<f64>,
    kappa: f64,
    gm: DMatrix<f64>,
    hv: DVector<f64>,
}

fn condense(model: &LinearModel, prob: &OcpProblem) -> Condensed {
    let n = prob.knots;
    let m = n * NU;
    // x_k = S_k u + s_k.
    let mut s_mat = DMatrix::zeros(NX, m);
    let mut s_vec = DVector::from_column_slice(&prob.x0);
    let mut h = DMatrix::zeros(m, m);
    let mut g = DVector::zeros(m);
    let mut kappa = 0.0;
    for k in 0..=n {
        let w = if k < n { &prob.q } else { &prob.q_n };
        h += s_mat.transpose() * w * &s_mat * 2.0;
        g += s_mat.transpose() * w * &s_vec * 2.0;
        kappa += s_vec.dot(&(w * &s_vec));
        if k < n {
            h.view_mut((k * NU, k * NU), (NU, NU))
                .add_assign(&(&prob.r * 2.0));
            s_mat = &model.a * &s_mat;
            s_mat.view_mut((0, k * NU), (NX, NU)).add_assign(&model.b);
            s_vec = &model.a * &s_vec + &model.w;
        }
    }
    let gm = &model.c * &s_mat;
    let hv = &model.target - &model.c * &s_vec;
    Condensed {
        h,
        g,
        kappa,
        gm,
        hv,
    }
}

fn stacked(us: &[Vec<f64>]) -> DVector<f64> {
    DVector::from_iterator(us.len() * NU, us.iter().flatten().copied())
}

#[test]
fn unconstrained_lqr_equals_the_discrete_riccati_cost() {
    // J* = x0ᵀ P_0 x0 with P_N = Q_N, P = Q + AᵀPA − AᵀPB (R + BᵀPB)⁻¹ BᵀPA (no offset).
    let (mut model, prob) = linear_problem(40, 0, f64::INFINITY);
    model.w.fill(0.0);
    let (q, r, qn) = weights();
    let (a, b) = system();
    let mut p = qn;
    for _ in 0..prob.knots {
        let bpa = b.transpose() * &p * &a;
        let hh = &r + b.transpose() * &p * &b;
        p = &q + a.transpose() * &p * &a - bpa.transpose() * hh.try_inverse().unwrap() * bpa;
    }
    let x0 = DVector::from_column_slice(&prob.x0);
    let j_star = x0.dot(&(&p * &x0));
    let sol = solve(&mut model, &prob, None, None, &SqpSettings::default());
    assert_eq!(sol.status, Status::Converged, "{}", sol.message);
    assert!(
        (sol.objective - j_star).abs() <= 1e-9 * j_star.max(1.0),
        "J = {} vs Riccati {j_star}",
        sol.objective
    );
    // Linear dynamics, quadratic cost: one Newton step, then the check.
    assert_eq!(sol.iterations, 1);
}

#[test]
fn terminal_equality_matches_the_dense_kkt_solution() {
    let (mut model, prob) = linear_problem(30, 2, f64::INFINITY);
    let c = condense(&model, &prob);
    let (m, nc) = (c.h.nrows(), c.gm.nrows());
    let mut kkt = DMatrix::zeros(m + nc, m + nc);
    kkt.view_mut((0, 0), (m, m)).copy_from(&c.h);
    kkt.view_mut((m, 0), (nc, m)).copy_from(&c.gm);
    kkt.view_mut((0, m), (m, nc)).copy_from(&c.gm.transpose());
    let mut rhs = DVector::zeros(m + nc);
    rhs.rows_mut(0, m).copy_from(&(-&c.g));
    rhs.rows_mut(m, nc).copy_from(&c.hv);
    let z = kkt.lu().solve(&rhs).unwrap();
    let u_star = z.rows(0, m).into_owned();
    let j_star = 0.5 * u_star.dot(&(&c.h * &u_star)) + c.g.dot(&u_star) + c.kappa;
    let sol = solve(&mut model, &prob, None, None, &SqpSettings::default());
    assert_eq!(sol.status, Status::Converged, "{}", sol.message);
    let u = stacked(&sol.us);
    assert!((&u - &u_star).amax() <= 1e-9, "{}", (&u - &u_star).amax());
    assert!((sol.objective - j_star).abs() <= 1e-9 * j_star.max(1.0));
    assert!(sol.terminal_violation <= 1e-9);
}

fn csc(m: &DMatrix<f64>, upper: bool) -> clarabel::algebra::CscMatrix<f64> {
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if m[(i, j)] != 0.0 && (!upper || i <= j) {
                rowval.push(i);
                nzval.push(m[(i, j)]);
            }
        }
        colptr.push(rowval.len());
    }
    clarabel::algebra::CscMatrix::new(m.nrows(), m.ncols(), colptr, rowval, nzval)
}

#[test]
fn active_bounds_are_never_violated_and_match_clarabel() {
    use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SupportedConeT};
    let bound = 0.6;
    let (mut model, prob) = linear_problem(30, 2, bound);
    let c = condense(&model, &prob);
    let (m, nc) = (c.h.nrows(), c.gm.nrows());
    // A u + s = b: G u = h (zero cone), u ≤ ub, −u ≤ −lb (non-negative cone).
    let mut a = DMatrix::zeros(nc + 2 * m, m);
    a.view_mut((0, 0), (nc, m)).copy_from(&c.gm);
    a.view_mut((nc, 0), (m, m)).fill_with_identity();
    a.view_mut((nc + m, 0), (m, m))
        .copy_from(&(-DMatrix::identity(m, m)));
    let mut b = vec![bound; nc + 2 * m];
    b[..nc].copy_from_slice(c.hv.as_slice());
    let cones = [
        SupportedConeT::ZeroConeT(nc),
        SupportedConeT::NonnegativeConeT(2 * m),
    ];
    let settings = DefaultSettings {
        verbose: false,
        tol_gap_abs: 1e-12,
        tol_gap_rel: 1e-12,
        tol_feas: 1e-12,
        ..DefaultSettings::default()
    };
    let mut solver = DefaultSolver::new(
        &csc(&c.h, true),
        c.g.as_slice(),
        &csc(&a, false),
        &b,
        &cones,
        settings,
    )
    .unwrap();
    solver.solve();
    let u_ref = DVector::from_column_slice(&solver.solution.x);
    let sol = solve(&mut model, &prob, None, None, &SqpSettings::default());
    assert_eq!(sol.status, Status::Converged, "{}", sol.message);
    let u = stacked(&sol.us);
    // Strictly inside, and some bounds active at the optimum.
    assert!(u.iter().all(|v| v.abs() < bound), "a bound is violated");
    let active = u.iter().filter(|v| bound - v.abs() < 1e-6).count();
    assert!(active >= 2, "the test needs active bounds ({active})");
    assert!((&u - &u_ref).amax() < 1e-6, "{}", (&u - &u_ref).amax());
    assert!(sol.terminal_violation <= 1e-9);
}

fn chain() -> ChainModel {
    let v = load_design("studies/designs/rigid_chain5.toml").unwrap();
    ChainModel::new(v, DynOptions::rigid(), 0.1, Vec3::new(2.884, 0.3, -0.2))
}

fn state(m: &ChainModel) -> Vec<f64> {
    let n = m.n_joints();
    let pose = BasePose {
        position: Vec3::new(0.3, -0.2, 0.1),
        orientation: nalgebra::UnitQuaternion::from_euler_angles(0.2, -0.4, 0.9),
    };
    let q: Vec<f64> = (0..n).map(|k| 0.3 - 0.2 * k as f64).collect();
    let qd: Vec<f64> = (0..n).map(|k| 0.05 * k as f64 - 0.1).collect();
    ChainModel::pack(&pose, &q, &[0.1, -0.05, 0.02, 0.03, 0.1, -0.2], &qd)
}

#[test]
fn retraction_and_difference_are_inverse() {
    let m = chain();
    let x = state(&m);
    let d: Vec<f64> = (0..m.nx())
        .map(|i| 0.1 * ((i as f64) * 0.7).sin())
        .collect();
    let mut y = vec![0.0; m.nq()];
    m.retract(&x, &d, &mut y);
    let mut back = vec![0.0; m.nx()];
    m.difference(&x, &y, &mut back);
    for (a, b) in d.iter().zip(&back) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
}

#[test]
fn chain_at_rest_without_controls_stays_at_rest() {
    let mut m = chain();
    let n = m.n_joints();
    let x = ChainModel::pack(
        &BasePose::default(),
        &vec![0.0; n],
        &[0.0; 6],
        &vec![0.0; n],
    );
    let mut y = vec![0.0; m.nq()];
    m.step(&x, &vec![0.0; m.nu()], &mut y).unwrap();
    assert_eq!(x, y);
}

/// The error of the Jacobians' prediction `A dx + B du` of the step's response to the
/// perturbation `h·(cos 1.3i, sin(w i))` at `h` = 1e-2 and 5e-3, each with the prediction's
/// size: (error, |prediction|)∞. Second-order Jacobians make the error ratio about 4.
fn linear_prediction_errors(m: &mut ChainModel, x: &[f64], u: &[f64], w: f64) -> [(f64, f64); 2] {
    let (nx, nu, nq) = (m.nx(), m.nu(), m.nq());
    let (mut a, mut b) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
    m.jacobians(x, u, &mut a, &mut b).unwrap();
    let mut f0 = vec![0.0; nq];
    m.step(x, u, &mut f0).unwrap();
    let mut err = |h: f64| {
        let dx = DVector::from_fn(nx, |i, _| h * ((i as f64) * 1.3).cos());
        let du = DVector::from_fn(nu, |i, _| h * ((i as f64) * w).sin());
        let (mut f1, mut xp) = (vec![0.0; nq], vec![0.0; nq]);
        m.retract(x, dx.as_slice(), &mut xp);
        let up: Vec<f64> = u.iter().zip(du.iter()).map(|(a, b)| a + b).collect();
        m.step(&xp, &up, &mut f1).unwrap();
        let mut got = vec![0.0; nx];
        m.difference(&f0, &f1, &mut got);
        let pred = &a * &dx + &b * &du;
        ((DVector::from_vec(got) - &pred).amax(), pred.amax())
    };
    [err(1e-2), err(5e-3)]
}

#[test]
fn chain_jacobians_are_consistent_with_the_step() {
    // The central-difference Jacobians predict the step's response to a perturbation h·d
    // with an error of second order: halving h divides it by about 4 (by 2 if A or B were
    // wrong) — a check of the tangent-space bookkeeping of retract/difference.
    let mut m = chain();
    let x = state(&m);
    let u: Vec<f64> = (0..m.nu()).map(|i| 0.2 * (i as f64 - 4.0)).collect();
    let [(e1, p1), (e2, _)] = linear_prediction_errors(&mut m, &x, &u, 0.9);
    assert!(e1 < 0.05 * p1, "linear prediction off: {e1} vs {p1}");
    let ratio = e1 / e2;
    assert!(
        (3.5..4.5).contains(&ratio),
        "error ratio {ratio} (second order: 4)"
    );
}

#[test]
fn short_chain_problem_converges_with_hard_terminal_constraints_and_bounds() {
    let mut m = chain();
    let n = m.n_joints();
    let x0 = ChainModel::pack(
        &BasePose::default(),
        &vec![0.0; n],
        &[0.0; 6],
        &vec![0.0; n],
    );
    let bound = 2.0;
    let knots = 20;
    let dt = 0.1;
    let (nx, nu) = (m.nx(), m.nu());
    let prob = OcpProblem {
        knots,
        x0: x0.clone(),
        x_ref: x0,
        q: DMatrix::zeros(nx, nx),
        r: DMatrix::identity(nu, nu) * dt,
        q_n: DMatrix::zeros(nx, nx),
        u_lo: vec![-bound; nu],
        u_hi: vec![bound; nu],
    };
    // A small move in 2 s.
    m = ChainModel::new(
        m.vehicle().clone(),
        DynOptions::rigid(),
        dt,
        Vec3::new(2.884, 0.03, -0.02),
    );
    let sol = solve(&mut m, &prob, None, None, &SqpSettings::default());
    assert_eq!(sol.status, Status::Converged, "{}", sol.message);
    assert!(sol.terminal_violation <= 1e-6);
    assert!(sol.us.iter().flatten().all(|v| v.abs() < bound));
    assert!(sol.kkt.iter().all(|r| *r <= 1e-6));
}

#[test]
fn chain_weighted_hessian_predicts_the_second_order_response() {
    // φ(h d) = wᵀ(f(x ⊕ h d_x, u + h d_u) ⊖ f(x, u)) = h wᵀJ d + ½h² dᵀHd + O(h³): with the
    // central-difference J and the second-difference H, the remainder shrinks by about 8
    // when h halves (by 4 if H were wrong).
    let mut m = chain();
    let (nx, nu, nq) = (m.nx(), m.nu(), m.nq());
    let x = state(&m);
    let u: Vec<f64> = (0..nu).map(|i| 0.2 * (i as f64 - 4.0)).collect();
    let w: Vec<f64> = (0..nx).map(|i| ((i as f64) * 0.77).cos()).collect();
    let (mut a, mut b) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
    m.jacobians(&x, &u, &mut a, &mut b).unwrap();
    let mut h = DMatrix::zeros(nx + nu, nx + nu);
    m.weighted_hessian(&x, &u, &w, &mut h).unwrap();
    assert!((&h - h.transpose()).amax() == 0.0);
    let mut f0 = vec![0.0; nq];
    m.step(&x, &u, &mut f0).unwrap();
    let wv = DVector::from_column_slice(&w);
    let d = DVector::from_fn(nx + nu, |i, _| ((i as f64) * 1.3).cos());
    let mut rem = |s: f64| {
        let (mut f1, mut xp) = (vec![0.0; nq], vec![0.0; nq]);
        let dx: Vec<f64> = (0..nx).map(|i| s * d[i]).collect();
        m.retract(&x, &dx, &mut xp);
        let up: Vec<f64> = (0..nu).map(|i| u[i] + s * d[nx + i]).collect();
        m.step(&xp, &up, &mut f1).unwrap();
        let mut got = vec![0.0; nx];
        m.difference(&f0, &f1, &mut got);
        let phi = wv.dot(&DVector::from_vec(got));
        let lin = wv.dot(&(&a * d.rows(0, nx) + &b * d.rows(nx, nu))) * s;
        let quad = 0.5 * s * s * d.dot(&(&h * &d));
        ((phi - lin - quad).abs(), quad.abs())
    };
    let (r1, q1) = rem(2e-2);
    let (r2, _) = rem(1e-2);
    assert!(
        q1 > 10.0 * r1,
        "curvature {q1} not above the remainder {r1}"
    );
    let ratio = r1 / r2;
    assert!(
        (6.0..10.0).contains(&ratio),
        "remainder ratio {ratio} (third order: 8)"
    );
}

#[test]
fn short_chain_problem_converges_with_the_gauss_newton_hessian_too() {
    let mut m = ChainModel::new(
        chain().vehicle().clone(),
        DynOptions::rigid(),
        0.1,
        Vec3::new(2.884, 0.03, -0.02),
    );
    let n = m.n_joints();
    let x0 = ChainModel::pack(
        &BasePose::default(),
        &vec![0.0; n],
        &[0.0; 6],
        &vec![0.0; n],
    );
    let (nx, nu) = (m.nx(), m.nu());
    let prob = OcpProblem {
        knots: 20,
        x0: x0.clone(),
        x_ref: x0,
        q: DMatrix::zeros(nx, nx),
        r: DMatrix::identity(nu, nu) * 0.1,
        q_n: DMatrix::zeros(nx, nx),
        u_lo: vec![-2.0; nu],
        u_hi: vec![2.0; nu],
    };
    let exact = solve(&mut m, &prob, None, None, &SqpSettings::default());
    let set = SqpSettings {
        hessian: super::sqp::Hessian::GaussNewton,
        max_iterations: 2000,
        ..SqpSettings::default()
    };
    let gn = solve(&mut m, &prob, None, None, &set);
    assert_eq!(exact.status, Status::Converged, "{}", exact.message);
    assert_eq!(gn.status, Status::Converged, "{}", gn.message);
    assert!((exact.objective - gn.objective).abs() <= 1e-6 * gn.objective);
    assert!(exact.iterations <= gn.iterations);
}

#[test]
fn usm_paper_with_thrusters_and_hydrodynamics_converges_within_the_limits() {
    // A few knots of the shipped reconfiguration: cold start, full hydrodynamics, the seven
    // thrusts and the joint torques as controls; KKT 1e-6 and no bound violated.
    let text = std::fs::read_to_string("studies/ocp_usm_paper.toml")
        .unwrap()
        .replace("knots = 40", "knots = 6")
        .replace("duration = 4.0", "duration = 1.5")
        .replace("[0.0, 0.10, -0.05]", "[0.0, 0.02, -0.01]");
    let path = std::path::Path::new("studies/ocp_usm_paper.toml");
    let spec = super::problem::parse_problem(&text, path).unwrap();
    assert!(spec.thrusters && spec.hydrodynamics);
    let run = super::run::solve_spec(&spec).unwrap();
    let sol = &run.solution;
    assert_eq!(sol.status, Status::Converged, "{}", sol.message);
    assert!(sol.kkt.iter().all(|r| *r <= 1e-6), "{:?}", sol.kkt);
    let m = spec.vehicle.n_thrusters();
    assert_eq!(sol.us[0].len(), m + spec.vehicle.n_joints());
    for u in &sol.us {
        for (j, t) in spec.vehicle.thrusters.iter().enumerate() {
            assert!(t.u_min < u[j] && u[j] < t.u_max, "thrust {} = {}", j, u[j]);
        }
        assert!(u[m..].iter().all(|v| v.abs() < 20.0));
    }
}

#[test]
fn thruster_chain_jacobians_are_consistent_with_the_step_on_every_preset() {
    // Every preset, full hydrodynamics, thruster actuation: the central-difference Jacobians
    // (the ones the SQP uses) predict the step's response to h·d with a second-order error.
    for name in crate::model::presets::PRESETS {
        let v = load_design(name).unwrap();
        let mut m = ChainModel::new(v, DynOptions::full(), 0.05, Vec3::zeros()).with_thrusters();
        let nu = m.nu();
        let n = m.n_joints();
        let pose = BasePose {
            position: Vec3::new(0.3, -0.2, 0.1),
            orientation: nalgebra::UnitQuaternion::from_euler_angles(0.1, -0.2, 0.4),
        };
        let q: Vec<f64> = (0..n).map(|k| 0.2 - 0.1 * k as f64).collect();
        let qd: Vec<f64> = (0..n).map(|k| 0.03 * k as f64 - 0.05).collect();
        let x = ChainModel::pack(&pose, &q, &[0.2, -0.05, 0.03, 0.02, 0.05, -0.1], &qd);
        let u: Vec<f64> = (0..nu).map(|i| 0.5 * ((i as f64) * 0.9).sin()).collect();
        let [(e1, p1), (e2, _)] = linear_prediction_errors(&mut m, &x, &u, 0.7);
        assert!(
            e1 < 0.05 * p1,
            "{name}: linear prediction off: {e1} vs {p1}"
        );
        let ratio = e1 / e2;
        assert!(
            (3.0..5.0).contains(&ratio),
            "{name}: error ratio {ratio} (second order: 4)"
        );
    }
}

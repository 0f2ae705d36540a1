//! The O(n) algorithms of `dynamics::aba` against the CRBA + Cholesky route (issue 23): the
//! articulated-body forward dynamics and the O(n) hybrid dynamics of the ideal servos equal
//! `forward_dynamics` / `hybrid_dynamics` on random states of every preset design, with
//! added mass, drag, restoring forces and current on (and in the rigid and added-mass-only
//! cases).

use super::*;
use crate::model::generator::GeneratorSpec;
use crate::model::presets::uvms_planar;

/// Every preset design of the core: the toys, `usm-paper`, `uvms-planar` and the generated
/// 3–9 link designs (2N−1 bodies, 2N−2 joints), each in a current. (NPS AUV II lives in the
/// `paper` room above this one; it is a single body, where both routes are the same 6×6 solve.)
fn all_designs() -> Vec<Vehicle> {
    let mut out = models();
    out.push(uvms_planar());
    for links in 3..=9 {
        let spec = GeneratorSpec {
            links,
            ..GeneratorSpec::default()
        };
        out.push(spec.build(&format!("gen{links}")).unwrap());
    }
    out.into_iter().map(with_current).collect()
}

/// `|a − b| ≤ 1e-12 · max(1, max|b|)` entry by entry: 1e-12 at the scale of the result
/// (accelerations of O(1–100) rad/s², m/s²; torques of O(1–100) N·m).
fn assert_close(name: &str, a: &[f64], b: &[f64]) {
    let scale = b.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    for (r, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= 1e-12 * scale,
            "{name}[{r}]: {x} vs {y} (difference {:e}, scale {scale})",
            (x - y).abs()
        );
    }
}

#[test]
fn aba_equals_crba_cholesky_on_every_preset() {
    // The raw difference of the two routes is the Cholesky route's own rounding, ε·κ(M) at
    // the scale of the result: up to 1.6e-12 on the 9-link design (13 bodies), whose
    // Newton–Euler residual τ − ID(ζ̇) is 10–30× the ABA's. One step of iterative refinement
    // of the Cholesky route (M d = τ − ID(ζ̇_chol) with the same factor) removes it: then the
    // two agree to 1e-12 of the accelerations' scale (measured ≤ 2.1e-14 on every design).
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for v in all_designs() {
        let nv = v.n_dof();
        let mut ws = DynWorkspace::new(&v);
        let mut ws_ref = DynWorkspace::new(&v);
        let mut back = vec![0.0; nv];
        for opts in all_options() {
            for _ in 0..20 {
                let s = sample(&v, &mut rng, 1.0);
                let tau: Vec<f64> = (0..nv).map(|_| rng.random_range(-30.0..30.0)).collect();
                forward_dynamics(&v, &mut ws_ref, &s.pose, &s.q, &s.zeta, &tau, &opts).unwrap();
                forward_dynamics_aba(&v, &mut ws, &s.pose, &s.q, &s.zeta, &tau, &opts).unwrap();
                let name = format!("{} {opts:?} zeta_dot", v.name);
                // Raw: within 1e-11 (the Cholesky route's ε·κ).
                let scale = ws_ref.zeta_dot.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
                for (r, (a, b)) in ws.zeta_dot.iter().zip(&ws_ref.zeta_dot).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-11 * scale,
                        "{name}[{r}] raw: {a} vs {b}"
                    );
                }
                // Refined reference: 1e-12.
                let x_chol = ws_ref.zeta_dot.clone();
                inverse_dynamics(
                    &v,
                    &mut ws_ref,
                    &s.pose,
                    &s.q,
                    &s.zeta,
                    &x_chol,
                    &opts,
                    &mut back,
                );
                let mut d: Vec<f64> = tau.iter().zip(&back).map(|(t, b)| t - b).collect();
                crate::linalg::solve(&ws_ref.chol, nv, &mut d);
                let refined: Vec<f64> = x_chol.iter().zip(&d).map(|(x, d)| x + d).collect();
                assert_close(&name, &ws.zeta_dot, &refined);
            }
        }
    }
}

#[test]
fn aba_body_accelerations_satisfy_inverse_dynamics() {
    // ID(ABA(τ)) = τ: the ABA's accelerations put back into recursive Newton–Euler give the
    // generalised forces it was given, including the current's and the drag's bias.
    let mut rng = ChaCha8Rng::seed_from_u64(24);
    for v in all_designs() {
        let mut ws = DynWorkspace::new(&v);
        let mut back = vec![0.0; v.n_dof()];
        let opts = DynOptions::full();
        for _ in 0..5 {
            let s = sample(&v, &mut rng, 1.0);
            let tau: Vec<f64> = (0..v.n_dof())
                .map(|_| rng.random_range(-30.0..30.0))
                .collect();
            forward_dynamics_aba(&v, &mut ws, &s.pose, &s.q, &s.zeta, &tau, &opts).unwrap();
            let acc = ws.zeta_dot.clone();
            inverse_dynamics(&v, &mut ws, &s.pose, &s.q, &s.zeta, &acc, &opts, &mut back);
            assert_close(&format!("{} tau", v.name), &back, &tau);
        }
    }
}

#[test]
fn hybrid_on_equals_dense_hybrid_on_every_preset() {
    let mut rng = ChaCha8Rng::seed_from_u64(25);
    for v in all_designs() {
        let n = v.n_joints();
        let mut ws = DynWorkspace::new(&v);
        let mut ws_ref = DynWorkspace::new(&v);
        for opts in all_options() {
            for _ in 0..20 {
                let s = sample(&v, &mut rng, 1.0);
                let q_ext: Vec<f64> = (0..v.n_dof())
                    .map(|_| rng.random_range(-30.0..30.0))
                    .collect();
                let qdd: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
                hybrid_dynamics(&v, &mut ws_ref, &s.pose, &s.q, &s.zeta, &q_ext, &qdd, &opts)
                    .unwrap();
                hybrid_dynamics_on(&v, &mut ws, &s.pose, &s.q, &s.zeta, &q_ext, &qdd, &opts)
                    .unwrap();
                let name = format!("{} {opts:?}", v.name);
                assert_close(&format!("{name} zeta_dot"), &ws.zeta_dot, &ws_ref.zeta_dot);
                assert_close(
                    &format!("{name} joint_torque"),
                    &ws.joint_torque,
                    &ws_ref.joint_torque,
                );
                // The base-control terms M_11 and h_1 are those of the dense route.
                let m11 = ws.mass_base_block() - ws_ref.mass_base_block();
                assert!(m11.amax() <= 1e-12 * ws_ref.mass_base_block().amax());
                assert_close(&format!("{name} bias"), &ws.bias, &ws_ref.bias);
            }
        }
    }
}

#[test]
fn aba_reports_a_massless_chain_instead_of_dividing_by_zero() {
    // A joint whose subtree has no inertia about its axis: D = 0, an error naming the body.
    let mut v = toy(2);
    v.fluid.rho = 0.0;
    v.bodies[1].mass = 0.0;
    v.bodies[1].inertia = Mat3::zeros();
    v.bodies[1].hydro = Hydro::cylinder(0.0, 0.0);
    let mut ws = DynWorkspace::new(&v);
    let zeta = vec![0.0; v.n_dof()];
    let tau = vec![0.0; v.n_dof()];
    let err = forward_dynamics_aba(
        &v,
        &mut ws,
        &BasePose::default(),
        &[0.1],
        &zeta,
        &tau,
        &DynOptions::rigid(),
    )
    .unwrap_err();
    assert!(err.quantity.starts_with("articulated_inertia"), "{err}");
}

/// `a` and `b` have the same bits, or are both zero (a skipped exact-zero term may flip the
/// sign of a zero result, nothing else).
fn same_bits(name: &str, a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len(), "{name}");
    for (r, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            x.to_bits() == y.to_bits() || (*x == 0.0 && *y == 0.0),
            "{name}[{r}]: {x:e} vs {y:e}"
        );
    }
}

#[test]
fn structured_passes_equal_the_dense_products_bit_for_bit() {
    // Axial joints and inertias (structure.rs) skip exact zeros only: every output of the
    // position pass and of the three O(n) and dense routes has the dense route's bits, on
    // random states, at rest in the straight configuration (many exact zeros) and in plane.
    let mut rng = ChaCha8Rng::seed_from_u64(26);
    for v in all_designs() {
        let (nv, n) = (v.n_dof(), v.n_joints());
        let mut ws = DynWorkspace::new(&v);
        let mut dense = DynWorkspace::new(&v).dense();
        for opts in all_options() {
            for t in 0..12 {
                let mut s = sample(&v, &mut rng, 1.0);
                if t == 0 {
                    s.pose = BasePose::default();
                    s.q.fill(0.0);
                    s.zeta.fill(0.0);
                } else if t == 1 {
                    s.pose.orientation = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7);
                    s.zeta[2..5].fill(0.0);
                }
                let tau: Vec<f64> = (0..nv).map(|_| rng.random_range(-30.0..30.0)).collect();
                let qdd: Vec<f64> = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
                let name = format!("{} {opts:?} state {t}", v.name);
                for w in [&mut ws, &mut dense] {
                    hybrid_dynamics_on(&v, w, &s.pose, &s.q, &s.zeta, &tau, &qdd, &opts).unwrap();
                }
                for (i, (a, b)) in ws.kin.g_b.iter().zip(&dense.kin.g_b).enumerate() {
                    same_bits(
                        &format!("{name} g_b[{i}].r"),
                        a.r.as_slice(),
                        b.r.as_slice(),
                    );
                    same_bits(
                        &format!("{name} g_b[{i}].p"),
                        a.p.as_slice(),
                        b.p.as_slice(),
                    );
                    let (a, b) = (&ws.kin.g_up[i], &dense.kin.g_up[i]);
                    same_bits(
                        &format!("{name} g_up[{i}].r"),
                        a.r.as_slice(),
                        b.r.as_slice(),
                    );
                    same_bits(
                        &format!("{name} g_up[{i}].p"),
                        a.p.as_slice(),
                        b.p.as_slice(),
                    );
                }
                for (k, (a, b)) in ws
                    .kin
                    .joint_twist_b
                    .iter()
                    .zip(&dense.kin.joint_twist_b)
                    .enumerate()
                {
                    same_bits(
                        &format!("{name} joint_twist_b[{k}]"),
                        a.as_slice(),
                        b.as_slice(),
                    );
                }
                same_bits(
                    &format!("{name} hybrid zeta_dot"),
                    &ws.zeta_dot,
                    &dense.zeta_dot,
                );
                same_bits(
                    &format!("{name} hybrid torque"),
                    &ws.joint_torque,
                    &dense.joint_torque,
                );
                same_bits(&format!("{name} hybrid bias"), &ws.bias, &dense.bias);
                same_bits(
                    &format!("{name} M_11"),
                    ws.mass_base_block().as_slice(),
                    dense.mass_base_block().as_slice(),
                );
                for w in [&mut ws, &mut dense] {
                    forward_dynamics_aba(&v, w, &s.pose, &s.q, &s.zeta, &tau, &opts).unwrap();
                }
                same_bits(
                    &format!("{name} aba zeta_dot"),
                    &ws.zeta_dot,
                    &dense.zeta_dot,
                );
                for w in [&mut ws, &mut dense] {
                    dynamics_terms(&v, w, &s.pose, &s.q, &s.zeta, &opts);
                }
                same_bits(&format!("{name} bias"), &ws.bias, &dense.bias);
                for c in 0..nv {
                    let (a, b) = (ws.mass.col(c), dense.mass.col(c));
                    let a: Vec<f64> = a.iter().copied().collect();
                    let b: Vec<f64> = b.iter().copied().collect();
                    same_bits(&format!("{name} M column {c}"), &a, &b);
                }
            }
        }
    }
}

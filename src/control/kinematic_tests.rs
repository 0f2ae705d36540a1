//! Tests of the kinematic control: the damped weighted pseudoinverse (USM-31), SRMTP (USM-32)
//! and the joint-limit task.

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_mat(rng: &mut ChaCha8Rng, m: usize, n: usize) -> Mat<f64> {
    Mat::from_fn(m, n, |_, _| rng.random_range(-1.0..1.0))
}

fn mul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(a.nrows(), b.ncols(), |i, j| {
        (0..a.ncols()).map(|k| a[(i, k)] * b[(k, j)]).sum()
    })
}

fn max_abs_diff_identity(a: &Mat<f64>) -> f64 {
    let mut e: f64 = 0.0;
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            let t = if i == j { 1.0 } else { 0.0 };
            e = e.max((a[(i, j)] - t).abs());
        }
    }
    e
}

#[test]
fn pinv_right_inverse_as_damping_vanishes() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let j = random_mat(&mut rng, 6, 14);
    let u: Vec<f64> = (0..14).map(|i| 0.2 + 0.1 * i as f64).collect();
    let mut prev = f64::INFINITY;
    for lambda in [1e-1, 1e-2, 1e-3, 1e-5] {
        let p = damped_weighted_pinv(j.as_ref(), Some(&u), lambda).unwrap();
        let e = max_abs_diff_identity(&mul(j.as_ref(), p.as_ref()));
        // J J^# = I − λ²(JUJᵀ + λ²I)⁻¹: the defect shrinks like λ².
        assert!(e < prev, "λ = {lambda}: {e}");
        prev = e;
    }
    assert!(prev < 1e-8, "{prev}");
    // λ = 0 is the exact weighted right inverse.
    let p = damped_weighted_pinv(j.as_ref(), Some(&u), 0.0).unwrap();
    assert!(max_abs_diff_identity(&mul(j.as_ref(), p.as_ref())) < 1e-10);
}

#[test]
fn pinv_matches_formula_and_apply() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let j = random_mat(&mut rng, 4, 9);
    let u: Vec<f64> = (0..9).map(|_| rng.random_range(0.1..2.0)).collect();
    let lambda = 0.3;
    let p = damped_weighted_pinv(j.as_ref(), Some(&u), lambda).unwrap();
    // Check (J U Jᵀ + λ²I) (U⁻¹ p)ᵀ... directly: J^# (J U Jᵀ + λ²I) = U Jᵀ.
    let ud = Mat::from_fn(9, 9, |a, b| if a == b { u[a] } else { 0.0 });
    let mut a = mul(mul(j.as_ref(), ud.as_ref()).as_ref(), j.transpose());
    for i in 0..4 {
        a[(i, i)] += lambda * lambda;
    }
    let lhs = mul(p.as_ref(), a.as_ref());
    let rhs = mul(ud.as_ref(), j.transpose());
    for r in 0..9 {
        for c in 0..4 {
            assert!((lhs[(r, c)] - rhs[(r, c)]).abs() < 1e-12);
        }
    }
    let b = [0.3, -1.0, 0.5, 2.0];
    let mut x = vec![0.0; 9];
    let mut ws = PinvWorkspace::new(6, 9);
    ws.apply(j.as_ref(), Some(&u), lambda, &b, &mut x).unwrap();
    for r in 0..9 {
        let e: f64 = (0..4).map(|c| p[(r, c)] * b[c]).sum();
        assert!((x[r] - e).abs() < 1e-12);
    }
    // Mismatched dimensions are errors, not panics.
    assert!(ws
        .apply(j.as_ref(), Some(&u), lambda, &b[..3], &mut x)
        .is_err());
    assert!(ws
        .apply(j.as_ref(), Some(&u[..8]), lambda, &b, &mut x)
        .is_err());
}

#[test]
fn zero_usage_weight_freezes_coordinate() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let j = random_mat(&mut rng, 6, 14);
    let mut u = vec![1.0; 14];
    u[3] = 0.0; // base roll, as in the paper's W
    u[9] = 0.0;
    let mut ws = PinvWorkspace::new(6, 14);
    let mut x = vec![0.0; 14];
    ws.apply(
        j.as_ref(),
        Some(&u),
        0.1,
        &[1.0, -2.0, 0.5, 0.3, 0.1, -0.7],
        &mut x,
    )
    .unwrap();
    assert_eq!(x[3], 0.0);
    assert_eq!(x[9], 0.0);
    assert!(x.iter().map(|v| v.abs()).sum::<f64>() > 0.1);
}

#[test]
fn singular_jacobian_without_damping_is_regularised() {
    let mut j = Mat::<f64>::zeros(2, 3);
    j[(0, 0)] = 1.0;
    j[(1, 0)] = 1.0; // rank 1
    let mut ws = PinvWorkspace::new(2, 3);
    let mut x = vec![0.0; 3];
    ws.apply(j.as_ref(), None, 0.0, &[1.0, 1.0], &mut x)
        .unwrap();
    assert!(x.iter().all(|v| v.is_finite()));
    assert_eq!(ws.regularised(), 1);
    let mut jn = j.clone();
    jn[(0, 1)] = f64::NAN;
    ws.apply(jn.as_ref(), None, 0.1, &[1.0, 1.0], &mut x)
        .unwrap();
    assert_eq!(ws.failed(), 1);
    assert!(x.iter().all(|v| *v == 0.0));
}

#[test]
fn srmtp_secondary_does_not_disturb_primary() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let n = 14;
    let j1 = random_mat(&mut rng, 6, n);
    let j2 = random_mat(&mut rng, 3, n);
    let j3 = random_mat(&mut rng, 2, n);
    let u: Vec<f64> = (0..n).map(|_| rng.random_range(0.3..1.0)).collect();
    let r1 = [0.2, -0.1, 0.3, 0.0, 0.05, -0.2];
    let r2 = [1.0, 2.0, -1.5];
    let r3 = [-3.0, 0.7];
    let lambda = 1e-6;
    let mut s = Srmtp::new(n, 11, &u, lambda).unwrap();
    s.reset();
    s.push_task(j1.as_ref(), &r1, TaskInverse::weighted(lambda))
        .unwrap();
    let z1 = s.zeta().to_vec();
    // J_1 N_1 ≈ 0 (it is λ²(J U Jᵀ + λ²I)⁻¹ J_1).
    let jn = mul(j1.as_ref(), s.null_projector());
    let worst = (0..6)
        .flat_map(|r| (0..n).map(move |c| (r, c)))
        .map(|(r, c)| jn[(r, c)].abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    s.push_task(j2.as_ref(), &r2, TaskInverse::plain(lambda))
        .unwrap();
    s.push_task(j3.as_ref(), &r3, TaskInverse::weighted(lambda))
        .unwrap();
    let z = s.zeta().to_vec();
    let task =
        |j: &Mat<f64>, z: &[f64], r: usize| -> f64 { (0..n).map(|c| j[(r, c)] * z[c]).sum() };
    for (r, want) in r1.iter().enumerate() {
        // Primary achieved exactly and unchanged by the lower tasks.
        assert!((task(&j1, &z, r) - want).abs() < 1e-8);
        assert!((task(&j1, &z, r) - task(&j1, &z1, r)).abs() < 1e-8);
    }
    // SRMTP as printed (USM-32) does not compensate J_2 ζ_1, so the lower tasks are not met
    // exactly, only without disturbing the primary. With J_2 = J_1's first three rows the
    // secondary is fully conflicting and contributes nothing beyond damping leakage.
    let mut s2 = Srmtp::new(n, 9, &u, lambda).unwrap();
    s2.reset();
    s2.push_task(j1.as_ref(), &r1, TaskInverse::weighted(lambda))
        .unwrap();
    let j_conf = Mat::from_fn(3, n, |r, c| j1[(r, c)]);
    s2.push_task(j_conf.as_ref(), &r2, TaskInverse::weighted(lambda))
        .unwrap();
    let diff: f64 = s2.zeta().iter().zip(&z1).map(|(a, b)| (a - b).abs()).sum();
    assert!(diff < 1e-8, "{diff}");
    // Exceeding the preallocated rows is an error, not a panic.
    assert!(s
        .push_task(j3.as_ref(), &r3, TaskInverse::weighted(lambda))
        .is_err());
}

#[test]
fn base_position_jacobian_layout() {
    let r = crate::spatial::rot_axis_angle(&Vec3::new(0.0, 0.6, 0.8), 0.4);
    let mut j = Mat::from_fn(3, 10, |_, _| 9.0);
    base_position_jacobian(&r, &mut j);
    for a in 0..3 {
        for c in 0..10 {
            let e = if c < 3 { r[(a, c)] } else { 0.0 };
            assert_eq!(j[(a, c)], e);
        }
    }
}

#[test]
fn joint_limit_task_activation() {
    let mut t = JointLimitTask::new(
        3,
        JointLimitSettings {
            enabled: true,
            margin: 0.1,
            gain: 2.0,
        },
    );
    let lim = [(-1.0, 1.0); 3];
    // Joint 0 near the top moving up: active. Joint 1 near the bottom moving away: not.
    // Joint 2 past the band at the bottom moving down: active with a positive push-back.
    assert!(t.update(&[0.95, -0.95, -0.98], &[0.1, 0.1, -0.1], &lim));
    assert_eq!(t.count(), 2);
    let j = t.jacobian();
    assert_eq!(j[(0, 6)], 1.0);
    assert_eq!(j[(1, 8)], 1.0);
    assert!((t.rate()[0] - 2.0 * (0.9 - 0.95)).abs() < 1e-12);
    assert!((t.rate()[1] - 2.0 * (-0.9 + 0.98)).abs() < 1e-12);
    assert!(!t.update(&[0.95, -0.95, -0.98], &[0.1, 0.1, -0.1], &lim));
}

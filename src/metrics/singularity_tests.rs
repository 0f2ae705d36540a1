//! Tests of the TCM singularity metrics: known singular values, the straight USM's lost roll,
//! attainable wrench by hand, and the commanded-subspace σ_min against an independent SVD.
#![allow(clippy::needless_range_loop)]
use super::*;
use crate::metrics::extremes::{commanded_extremes_pair_with, commanded_extremes_with};

fn approx(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// A straight USM: 7 thrusters on the body x axis, so no thruster makes a roll moment
/// (the allocation tests' fixture).
fn straight_usm() -> Matrix6xX<f64> {
    crate::allocation::tests::straight_t()
}

#[test]
fn known_singular_values_of_diagonal_t() {
    // T = diag(1..6), L = 2: T_L = diag(1, 2, 3, 2, 2.5, 3).
    let mut t = Matrix6xX::zeros(6);
    for i in 0..6 {
        t[(i, i)] = (i + 1) as f64;
    }
    let r = tcm_svd_metrics(&t, 2.0, DEFAULT_RANK_REL_TOL).unwrap();
    let want = [3.0, 3.0, 2.5, 2.0, 2.0, 1.0];
    for k in 0..6 {
        assert!(approx(r.singular_values[k], want[k], 1e-12), "{r:?}");
    }
    assert_eq!(r.rank, 6);
    assert!(approx(r.condition_number, 3.0, 1e-12));
    assert!(r.lost_directions.is_empty());
}

#[test]
fn straight_usm_loses_roll() {
    let t = straight_usm();
    let r = tcm_svd_metrics(&t, 1.0, DEFAULT_RANK_REL_TOL).unwrap();
    assert_eq!(r.rank, 5, "{r:?}");
    assert!(r.condition_number.is_infinite());
    assert_eq!(r.lost_directions.len(), 1);
    let lost = &r.lost_directions[0];
    assert_eq!(lost.dominant_axis, "roll");
    assert!(approx(lost.direction[3], 1.0, 1e-9), "{lost:?}");
    assert!(r.sigma_min < 1e-9);
}

#[test]
fn fewer_than_six_thrusters_is_rank_deficient() {
    let t = straight_usm().columns(2, 3).into_owned();
    let r = tcm_svd_metrics(&t, 1.0, DEFAULT_RANK_REL_TOL).unwrap();
    assert_eq!(r.rank, 3);
    assert_eq!(r.lost_directions.len(), 3);
    assert_eq!(r.sigma_min, 0.0);
}

#[test]
fn attainable_wrench_by_hand() {
    // Thrusters: two along x at the origin, one along each of y, z, and pure moment
    // "thrusters" about x, y, z. Bounds [-10, 20] N.
    let mut t = Matrix6xX::zeros(7);
    t[(0, 0)] = 1.0;
    t[(0, 1)] = 1.0;
    t[(1, 2)] = 1.0;
    t[(2, 3)] = 1.0;
    t[(3, 4)] = 0.5;
    t[(4, 5)] = 2.0;
    t[(5, 6)] = 1.0;
    let r = tcm_metrics(&t, &[-10.0; 7], &[20.0; 7], 1.0, DEFAULT_RANK_REL_TOL).unwrap();
    let a = r.attainable.unwrap();
    let pos = [40.0, 20.0, 20.0, 10.0, 40.0, 20.0];
    let neg = [20.0, 10.0, 10.0, 5.0, 20.0, 10.0];
    for k in 0..6 {
        assert!(approx(a.positive[k], pos[k], 1e-6), "{a:?}");
        assert!(approx(a.negative[k], neg[k], 1e-6), "{a:?}");
    }
}

#[test]
fn attainable_roll_of_straight_usm_is_zero() {
    let t = straight_usm();
    let a = attainable_wrench(&t, &[-40.0; 7], &[40.0; 7]).unwrap();
    assert!(
        a.positive[3].abs() < 1e-6 && a.negative[3].abs() < 1e-6,
        "{a:?}"
    );
    assert!(a.positive[0] > 79.0, "{a:?}");
}

#[test]
fn bad_inputs_are_errors() {
    let t = straight_usm();
    assert!(matches!(
        tcm_svd_metrics(&t, 0.0, 1e-6),
        Err(SingularityError::CharLength(_))
    ));
    let mut bad = t.clone();
    bad[(2, 3)] = f64::NAN;
    assert!(tcm_svd_metrics(&bad, 1.0, 1e-6).is_err());
    assert!(tcm_metrics(&t, &[1.0; 7], &[0.0; 7], 1.0, 1e-6).is_err());
}

#[test]
fn singular_fraction_counts() {
    assert_eq!(singular_fraction(&[0.0, 0.5, 1.0, f64::NAN], 0.6), 0.75);
    assert_eq!(singular_fraction(&[], 0.6), 0.0);
}

#[test]
fn residual_counts_only_commanded_rows() {
    let roll_free = CommandedDofs::new([true, true, true, false, true, true]);
    let tau = Vector6::new(10.0, 0.0, 0.0, 0.0, 0.0, 2.0);
    // A roll slack the straight body cannot avoid is not a commanded residual.
    let roll = Vector6::new(0.0, 0.0, 0.0, 5.0, 0.0, 0.0);
    assert!(!residual_exceeds(&roll, &tau, 2.0, roll_free, 1e-2));
    assert!(residual_exceeds(&roll, &tau, 2.0, CommandedDofs::ALL, 1e-2));
    // Yaw slack 0.2 N·m at L = 2 m is 0.1 N scaled; |τ_L| = √(100 + 1): just under 1 %.
    let yaw = Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.2);
    assert!(!residual_exceeds(&yaw, &tau, 2.0, roll_free, 1e-2));
    assert!(residual_exceeds(&yaw, &tau, 2.0, roll_free, 0.9e-2));
    assert!(!residual_exceeds(
        &Vector6::zeros(),
        &Vector6::zeros(),
        1.0,
        roll_free,
        1e-2
    ));
}

/// σ_min of the rows `dofs` of `T_L` by nalgebra's SVD of the explicitly built `k×m` matrix
/// (independent of [`commanded_sigma`]), with σ_max.
fn svd_reference(t: &Matrix6xX<f64>, l: f64, dofs: CommandedDofs) -> (f64, f64) {
    let tl = scale_moment_rows(t, l);
    let rows: Vec<usize> = (0..6).filter(|&i| dofs.contains(i)).collect();
    let a = nalgebra::DMatrix::from_fn(rows.len(), t.ncols(), |r, c| tl[(rows[r], c)]);
    let sv = a.singular_values();
    let k = rows.len();
    let min = if t.ncols() < k { 0.0 } else { sv.min() };
    (min, sv.max())
}

/// `|a − b| ≤ 1e-12·b + 1e-14·σ_max`: 1e-12 relative for well-conditioned matrices, the
/// working precision of σ_max for (near-)rank-deficient ones, where any backward-stable
/// method only determines σ_min to `ε·σ_max`.
fn agrees(a: f64, b: f64, sigma_max: f64) -> bool {
    (a - b).abs() <= 1e-12 * b + 1e-14 * sigma_max
}

/// The static analysis' accuracy (issue 11): 1e-10 relative, `1e-14·σ_max` absolute.
fn agrees_static(a: f64, b: f64, sigma_max: f64) -> bool {
    (a - b).abs() <= 1e-10 * b + 1e-14 * sigma_max
}

/// [`commanded_extremes_with`] of `t` against nalgebra's SVD (σ_min to the static analysis'
/// 1e-10, σ_max to 1e-12) and its rank against [`commanded_sigma`]'s.
fn check_extremes(t: &Matrix6xX<f64>, l: f64, dofs: CommandedDofs, label: &str) {
    let x = commanded_extremes_with(&ScaledGram::new(t, l), t, dofs, 1e-6);
    check_extremes_of(&x, t, l, dofs, label);
}

/// [`check_extremes`] of two selections at once by [`commanded_extremes_pair_with`] (one
/// Householder reduction for both when one is all six rows).
fn check_extremes_pair(t: &Matrix6xX<f64>, l: f64, pair: [CommandedDofs; 2], label: &str) {
    let both = commanded_extremes_pair_with(&ScaledGram::new(t, l), t, pair, 1e-6);
    for (x, dofs) in both.iter().zip(pair) {
        check_extremes_of(x, t, l, dofs, &format!("{label} pair {pair:?}"));
    }
}

/// The checks of [`check_extremes`] on the extremes `x` of the rows `dofs` of `t`.
fn check_extremes_of(
    x: &SigmaExtremes,
    t: &Matrix6xX<f64>,
    l: f64,
    dofs: CommandedDofs,
    label: &str,
) {
    let (want, smax) = svd_reference(t, l, dofs);
    assert!(
        agrees_static(x.sigma_min, want, smax),
        "{label} {dofs:?}: {x:?} vs {want}"
    );
    assert!(
        agrees(x.sigma_max, smax, smax),
        "{label} {dofs:?}: {x:?} vs {smax}"
    );
    let full = commanded_sigma(t, l, dofs);
    assert_eq!(x.rank, full.rank(1e-6), "{label} {dofs:?}");
}

/// Transport's commanded axes under the paper's `K_p = diag(1, 1, 1, 0, 1, 1)`.
fn transport_dofs() -> CommandedDofs {
    CommandedDofs::transport(&[1.0, 1.0, 1.0, 0.0, 1.0, 1.0])
}

#[test]
fn commanded_dofs_follow_the_gains() {
    let roll_free = CommandedDofs::new([true, true, true, false, true, true]);
    assert_eq!(transport_dofs(), roll_free);
    // Surge and yaw come from USM-40/41 whatever K_p says.
    assert_eq!(
        CommandedDofs::transport(&[0.0; 6]),
        CommandedDofs::new([true, false, false, false, false, true])
    );
    let w = [0.3, 0.3, 0.3, 0.0, 0.3, 0.3];
    let kp = [1.0, 1.0, 1.0, 0.0, 1.0, 1.0];
    assert_eq!(CommandedDofs::work(&w, &kp, &[0.0; 6]), roll_free);
    let mut ki = [0.0; 6];
    ki[3] = 0.1;
    assert_eq!(CommandedDofs::work(&w, &kp, &ki), CommandedDofs::ALL);
    assert_eq!(roll_free.len(), 5);
    assert_eq!(roll_free.label(), "surge+sway+heave+pitch+yaw");
    assert_eq!(CommandedDofs::new([false; 6]).label(), "none");
}

#[test]
fn straight_body_in_transport_by_hand() {
    // Surge thrusters at x = 0.2, 1.8 (no moment), sway at a, b (yaw moment x), heave at c, d
    // (pitch moment −x); L = 1. Without the roll row T_L splits into blocks: surge with
    // Gram 2; sway/yaw and heave/pitch with Gram [[2, ±(a+b)], [±(a+b), a²+b²]], whose smaller
    // eigenvalue is (tr − √(tr² − 4 det))/2, det = (a − b)².
    let (a, b, c, d) = (0.5, 1.5, 0.3, 1.2);
    let mut t = Matrix6xX::zeros(6);
    t[(0, 0)] = 1.0;
    t[(0, 1)] = 1.0;
    for (j, x) in [(2, a), (3, b)] {
        t[(1, j)] = 1.0;
        t[(5, j)] = x;
    }
    for (j, x) in [(4, c), (5, d)] {
        t[(2, j)] = 1.0;
        t[(4, j)] = -x;
    }
    let small = |p: f64, q: f64| {
        let tr = 2.0 + p * p + q * q;
        let det = (p - q) * (p - q);
        ((tr - (tr * tr - 4.0 * det).sqrt()) / 2.0).sqrt()
    };
    let want = small(a, b).min(small(c, d)).min(2f64.sqrt());
    let r = commanded_sigma(&t, 1.0, transport_dofs());
    assert!(approx(r.sigma_min, want, 1e-13), "{r:?} vs {want}");
    assert_eq!(r.k, 5);
    assert_eq!(r.rank(DEFAULT_RANK_REL_TOL), 5);
    // The full 6-DOF figure has lost roll.
    let full = commanded_sigma(&t, 1.0, CommandedDofs::ALL);
    assert!(full.sigma_min < 1e-14 * full.sigma_max, "{full:?}");
    assert_eq!(full.rank(DEFAULT_RANK_REL_TOL), 5);
    assert!(full.condition_number > 1e13);
}

#[test]
fn straight_paper_design_commanded_sigma_is_t_without_roll() {
    let v = crate::model::presets::usm_paper();
    let mut ws = crate::kinematics::KinWorkspace::new(&v);
    crate::kinematics::forward_kinematics(&v, &vec![0.0; v.n_joints()], &mut ws);
    let t = crate::kinematics::thruster_matrix_owned(&v, &ws);
    let l = v.characteristic_length();
    let r = commanded_sigma(&t, l, transport_dofs());
    let (want, smax) = svd_reference(&t, l, transport_dofs());
    assert!(agrees(r.sigma_min, want, smax), "{r:?} vs {want}");
    assert!(r.sigma_min > 0.05, "{r:?}");
    let full = commanded_sigma(&t, l, CommandedDofs::ALL);
    assert!(full.sigma_min < 1e-12, "{full:?}");
}

#[test]
fn commanded_sigma_matches_svd_over_random_configurations() {
    let v = crate::model::presets::usm_paper();
    let mut ws = crate::kinematics::KinWorkspace::new(&v);
    let l = v.characteristic_length();
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let sets = [
        CommandedDofs::ALL,
        transport_dofs(),
        CommandedDofs::new([true, false, true, false, true, false]),
    ];
    for n in 0..400 {
        // Every tenth sample straight in all but one joint (near the rank-deficient set).
        let q: Vec<f64> = v
            .joints
            .iter()
            .enumerate()
            .map(|(i, j)| {
                let x = j.min + unit() * (j.max - j.min);
                if n % 10 == 0 && i != n % v.n_joints() {
                    0.0
                } else {
                    x
                }
            })
            .collect();
        crate::kinematics::forward_kinematics(&v, &q, &mut ws);
        let t = crate::kinematics::thruster_matrix_owned(&v, &ws);
        for dofs in sets {
            let r = commanded_sigma(&t, l, dofs);
            let (want, smax) = svd_reference(&t, l, dofs);
            assert!(
                agrees(r.sigma_min, want, smax),
                "{n} {dofs:?}: {r:?} vs {want}"
            );
            assert!(
                agrees(r.sigma_max, smax, smax),
                "{n} {dofs:?}: {r:?} vs {smax}"
            );
            // The static analysis' extremes-only route (Laguerre on the Gram matrix) agrees
            // just as well, and its rank is the full route's.
            check_extremes(&t, l, dofs, &format!("{n}"));
        }
        // Two selections at once (the static analysis' all-six and commanded rows; one
        // reduction when one of them is all six) agree with the SVD as well.
        let pairs = [
            [sets[0], sets[1]],
            [sets[1], sets[0]],
            [sets[0], sets[0]],
            [sets[1], sets[2]],
            [sets[2], sets[2]],
        ];
        for pair in pairs {
            check_extremes_pair(&t, l, pair, &format!("{n}"));
        }
    }
}

#[test]
fn extremes_agree_with_the_svd_on_random_gram_spectra() {
    // Random T = U diag(σ) Vᵀ with prescribed singular values spanning κ from 1 to 1e12,
    // repeated values and exact zeros: σ_min, σ_max and the rank of the extremes-only route
    // against nalgebra's SVD (σ_min to 1e-10 relative, σ_max to 1e-12, or 1e-14·σ_max
    // absolute when tiny).
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for n in 0..600 {
        let m = 6 + n % 4;
        let a = nalgebra::DMatrix::from_fn(6, 6, |_, _| unit() - 0.5);
        let b = nalgebra::DMatrix::from_fn(m, m, |_, _| unit() - 0.5);
        let (u, w) = (a.qr().q(), b.qr().q());
        let mut sig = [0.0; 6];
        for (i, s) in sig.iter_mut().enumerate() {
            *s = match n % 5 {
                0 => 10f64.powf(-12.0 * unit()),
                1 => 1.0 + 1e-3 * i as f64,
                2 => {
                    if i < 3 {
                        0.5
                    } else {
                        2.0
                    }
                }
                3 => {
                    if i == 5 {
                        0.0
                    } else {
                        unit() + 0.1
                    }
                }
                _ => unit() + 1e-3,
            };
        }
        let mut d = nalgebra::DMatrix::zeros(6, m);
        for i in 0..6 {
            d[(i, i)] = sig[i];
        }
        let t: Matrix6xX<f64> = Matrix6xX::from_column_slice((u * d * w.transpose()).as_slice());
        for dofs in [CommandedDofs::ALL, transport_dofs()] {
            check_extremes(&t, 1.0, dofs, &format!("{n}"));
        }
        // The nested reduction for every size of commanded block, its rows anywhere.
        let sel = [
            transport_dofs(),
            CommandedDofs::new([false, true, true, false, true, true]),
            CommandedDofs::new([true, false, false, true, false, true]),
            CommandedDofs::new([false, false, true, false, true, false]),
        ];
        check_extremes_pair(&t, 1.0, [CommandedDofs::ALL, sel[n % 4]], &format!("{n}"));
    }
}

#[test]
fn commanded_sigma_of_rank_deficient_and_degenerate_input() {
    // Exactly rank-deficient (the straight USM has no roll): σ_min at working precision.
    let t = straight_usm();
    let r = commanded_sigma(&t, 1.0, CommandedDofs::ALL);
    let (want, smax) = svd_reference(&t, 1.0, CommandedDofs::ALL);
    assert!(agrees(r.sigma_min, want, smax), "{r:?} vs {want}");
    assert!(r.sigma_min <= 1e-14 * smax);
    // Nearly so: a 1e-7 roll authority is resolved far below the Gram route's √ε·σ_max.
    let mut near = t.clone();
    near[(3, 4)] = 1e-7;
    let r = commanded_sigma(&near, 1.0, CommandedDofs::ALL);
    let (want, smax) = svd_reference(&near, 1.0, CommandedDofs::ALL);
    assert!(
        want > 1e-9 && agrees(r.sigma_min, want, smax),
        "{r:?} vs {want}"
    );
    // Fewer thrusters than commanded axes.
    let few = t.columns(0, 3).into_owned();
    let r = commanded_sigma(&few, 1.0, transport_dofs());
    assert!(r.sigma_min <= 1e-14 * r.sigma_max, "{r:?}");
    // Nothing commanded; bad length; non-finite T.
    let none = commanded_sigma(&t, 1.0, CommandedDofs::new([false; 6]));
    assert_eq!(none.sigma_min, f64::INFINITY);
    assert!(commanded_sigma(&t, 0.0, CommandedDofs::ALL)
        .sigma_min
        .is_nan());
    let mut bad = t.clone();
    bad[(0, 0)] = f64::NAN;
    assert!(commanded_sigma(&bad, 1.0, CommandedDofs::ALL)
        .sigma_min
        .is_nan());
}

#[test]
fn weakest_direction_is_the_smallest_left_singular_vector() {
    // Straight USM: the lost direction is pure roll (σ_min at rounding level).
    let t = straight_usm();
    let s = commanded_sigma(&t, 1.0, CommandedDofs::ALL);
    let d = weakest_direction(&t, 1.0, CommandedDofs::ALL, s.sigma_min);
    assert!(s.sigma_min < 1e-12 && approx(d[3], 1.0, 1e-9), "{d:?}");
    // Bent paper designs: ‖(S T_L)ᵀ d‖ = σ_min, d unit, zero off the selection; against the
    // SVD's left singular vector.
    let v = crate::model::presets::usm_paper();
    let mut ws = crate::kinematics::KinWorkspace::new(&v);
    let l = v.characteristic_length();
    for bend in [0.05, 0.3, 0.8] {
        let q: Vec<f64> = (0..v.n_joints()).map(|i| bend - 0.07 * i as f64).collect();
        crate::kinematics::forward_kinematics(&v, &q, &mut ws);
        let t = crate::kinematics::thruster_matrix_owned(&v, &ws);
        for dofs in [CommandedDofs::ALL, transport_dofs()] {
            let s = commanded_sigma(&t, l, dofs);
            let d = weakest_direction(&t, l, dofs, s.sigma_min);
            let tl = scale_moment_rows(&t, l);
            let dv = Vector6::from(d);
            assert!(approx(dv.norm(), 1.0, 1e-12));
            let got = (tl.transpose() * dv).norm();
            assert!(
                (got - s.sigma_min).abs() < 1e-10 * s.sigma_max,
                "{s:?} {d:?}"
            );
            assert!((0..6).all(|i| dofs.contains(i) || d[i] == 0.0));
            if dofs == CommandedDofs::ALL {
                let m = tcm_svd_metrics(&t, l, 1e-20).unwrap();
                let u = nalgebra::Matrix6::from(tl.clone() * tl.transpose()).symmetric_eigen();
                let i = u.eigenvalues.imin();
                let dot = u.eigenvectors.column(i).dot(&dv).abs();
                assert!(approx(dot, 1.0, 1e-9), "{bend}: {dot} {m:?}");
            }
        }
    }
}

#[test]
fn tridiagonal_eigenvalues_match_nalgebra() {
    // Random symmetric matrices of every size, plus diagonal ones (case 0).
    let mut seed = 12345u64;
    let mut unit = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for k in 1..=6 {
        for case in 0..50 {
            let mut a = [[0.0; 6]; 6];
            for i in 0..k {
                for j in 0..=i {
                    let x = if case == 0 && i != j { 0.0 } else { unit() };
                    a[i][j] = x;
                    a[j][i] = x;
                }
            }
            let m = nalgebra::DMatrix::from_fn(k, k, |i, j| a[i][j]);
            let mut want: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
            let mut got = super::super::small_svd::tridiagonal_eigenvalues(&mut a, k);
            got[..k].sort_by(f64::total_cmp);
            want.sort_by(f64::total_cmp);
            for i in 0..k {
                assert!(
                    (got[i] - want[i]).abs() < 1e-14,
                    "k={k} case {case}: {got:?} vs {want:?}"
                );
            }
        }
    }
}

/// The unrolled Gram matrix of all six rows is the generic one's, bit for bit (so the static
/// analysis' outputs did not move when it was unrolled), and selecting all six rows returns it.
#[test]
fn full_gram_is_the_generic_gram_bit_for_bit() {
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut unit = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let all = selected_rows(CommandedDofs::ALL);
    for n in [1, 5, 7, 9, 16] {
        for _ in 0..50 {
            let t = Matrix6xX::from_fn(n, |_, _| 40.0 * unit());
            let l = 0.5 + unit().abs() * 3.0;
            let (a, b) = (full_gram(&t, l), commanded_gram(&t, l, &all, 6));
            for i in 0..6 {
                for j in 0..6 {
                    assert_eq!(a[i][j].to_bits(), b[i][j].to_bits(), "n {n} ({i},{j})");
                }
            }
            let g = ScaledGram::new(&t, l);
            assert_eq!(g.select(&all, 6), b);
        }
    }
}

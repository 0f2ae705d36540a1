//! Tests of the dedicated authority simplex: closed forms, a fixed (removed) variable, dependent
//! rows, Beale's degenerate programme, no state carried between solves, and a property test
//! against brute-force vertex enumeration on random small programmes (integer data: many ties
//! and degenerate vertices; some with a repeated row).

use super::*;
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

/// A workspace for `max g·u` s.t. `e u = 0` and the box: `M = [g; e]`, row 0, sign +1.
fn lp(e: &[Vec<f64>], g: &[f64], lo: &[f64], hi: &[f64]) -> BoxLp {
    let m = g.len();
    let mut s = BoxLp::new(m, e.len() + 1);
    for j in 0..m {
        let col = s.column(j);
        col[0] = g[j];
        for (i, row) in e.iter().enumerate() {
            col[i + 1] = row[j];
        }
        s.set_bounds(j, lo[j], hi[j]);
    }
    s.crash();
    s
}

/// `max g·u` over `E u = 0`, `lo ≤ u ≤ hi` by enumerating vertices: every vertex has a set `F`
/// of free variables with linearly independent columns (`|F| ≤ rank E`), the others at a
/// bound; solve `E_F u_F = −E_N u_N` by SVD and keep the feasible solutions.
fn brute_force(e: &[Vec<f64>], g: &[f64], lo: &[f64], hi: &[f64]) -> f64 {
    let (p, m) = (e.len(), g.len());
    let mut best = f64::NEG_INFINITY;
    for free in 0u32..(1 << m) {
        if free.count_ones() as usize > p {
            continue;
        }
        let f: Vec<usize> = (0..m).filter(|j| free & (1 << j) != 0).collect();
        let n: Vec<usize> = (0..m).filter(|j| free & (1 << j) == 0).collect();
        for at in 0u32..(1 << n.len()) {
            let mut u = vec![0.0; m];
            for (b, &j) in n.iter().enumerate() {
                u[j] = if at & (1 << b) != 0 { hi[j] } else { lo[j] };
            }
            let rhs = DVector::from_fn(p, |i, _| -n.iter().map(|&j| e[i][j] * u[j]).sum::<f64>());
            if !f.is_empty() {
                let ef = DMatrix::from_fn(p, f.len(), |i, k| e[i][f[k]]);
                let svd = ef.clone().svd(true, true);
                if svd.singular_values.min() < 1e-9 {
                    continue;
                }
                let uf = svd.solve(&rhs, 1e-12).unwrap();
                for (k, &j) in f.iter().enumerate() {
                    u[j] = uf[k];
                }
            }
            let feasible = (0..m).all(|j| u[j] >= lo[j] - 1e-9 && u[j] <= hi[j] + 1e-9)
                && (0..p).all(|i| (0..m).map(|j| e[i][j] * u[j]).sum::<f64>().abs() < 1e-9);
            if feasible {
                best = best.max((0..m).map(|j| g[j] * u[j]).sum());
            }
        }
    }
    best
}

#[test]
fn no_equality_rows_give_the_box_support() {
    // max g·u over the box alone: Σ max(l g, h g) = 2·3 + 0 + (−1)(−4) = 10.
    let mut s = lp(
        &[],
        &[2.0, 0.0, -1.0],
        &[-1.0, -5.0, -4.0],
        &[3.0, 5.0, 2.0],
    );
    assert_eq!(s.solve(0, 1.0), Some(10.0));
    assert!(s.last.certified && s.last.dual_bound == 10.0);
}

#[test]
fn two_surge_thrusters_with_yaw_held_at_zero() {
    // The hand-computed layout of authority_tests: surge = u0 + u1, yaw = 0.5 (u1 − u0) = 0,
    // limits [−10, 30]: surge+ 60, surge− 20; with thruster 1 removed nothing is left.
    let e = [vec![-0.5, 0.5]];
    let (lo, hi) = ([-10.0; 2], [30.0; 2]);
    let mut s = lp(&e, &[1.0, 1.0], &lo, &hi);
    assert_eq!(s.solve(0, 1.0), Some(60.0));
    assert_eq!(s.solve(0, -1.0), Some(20.0));
    // Yaw (row 1) with surge held at zero: u1 = −u0 = v, |v| ≤ 10, yaw = v: 10 both ways.
    assert_eq!(s.solve(1, 1.0), Some(10.0));
    assert_eq!(s.solve(1, -1.0), Some(10.0));
    s.set_bounds(1, 0.0, 0.0);
    s.crash();
    assert_eq!(s.solve(0, 1.0), Some(0.0));
    assert_eq!(s.solve(1, -1.0), Some(0.0));
}

#[test]
fn dependent_rows_and_an_objective_in_their_span_give_zero() {
    // Rows 2 = 2 × row 1 (rank deficient); g = row 1 + row 0: every feasible u has g·u = 0.
    let e = [
        vec![1.0, 0.0, 1.0, -1.0],
        vec![0.0, 1.0, 1.0, 2.0],
        vec![0.0, 2.0, 2.0, 4.0],
    ];
    let g = [1.0, 1.0, 2.0, 1.0];
    let mut s = lp(&e, &g, &[-1.0; 4], &[1.0; 4]);
    let a = s.solve(0, 1.0).unwrap();
    assert!(a.abs() < 1e-12, "{a} {:?}", s.last);
    // An objective outside the span: the brute force's answer.
    let g = [1.0, -1.0, 0.5, 0.0];
    let want = brute_force(&e, &g, &[-1.0; 4], &[1.0; 4]);
    let got = lp(&e, &g, &[-1.0; 4], &[1.0; 4]).solve(0, 1.0).unwrap();
    assert!((got - want).abs() < 1e-12, "{got} {want}");
}

#[test]
fn beales_degenerate_programme() {
    // Beale (1955), the classic example on which Dantzig's rule cycles: min −¾x4 + 150x5 −
    // x6/50 + 6x7 s.t. ¼x4 − 60x5 − x6/25 + 9x7 ≤ 0, ½x4 − 90x5 − x6/50 + 3x7 ≤ 0, x6 ≤ 1,
    // x ≥ 0; optimum −1/20 at x4 = 1/25, x6 = 1 (degenerate start: both slacks x1, x2 at 0).
    // As a programme here: max the negated objective, the slacks as variables with boxes
    // [0, 100] that do not cut the optimum: max = 1/20.
    let e = [
        vec![1.0, 0.0, 0.25, -60.0, -1.0 / 25.0, 9.0],
        vec![0.0, 1.0, 0.5, -90.0, -1.0 / 50.0, 3.0],
    ];
    let g = [0.0, 0.0, 0.75, -150.0, 1.0 / 50.0, -6.0];
    let lo = [0.0; 6];
    let hi = [100.0, 100.0, 100.0, 100.0, 1.0, 100.0];
    let mut s = lp(&e, &g, &lo, &hi);
    let a = s.solve(0, 1.0).unwrap();
    assert!((a - 0.05).abs() < 1e-12, "{a} {:?}", s.last);
    s.degenerate_limit = 0;
    let a = s.solve(0, 1.0).unwrap();
    assert!((a - 0.05).abs() < 1e-12 && s.last.bland, "{a} {:?}", s.last);
    assert!((brute_force(&e, &g, &lo, &hi) - 0.05).abs() < 1e-12);
}

#[test]
fn a_solve_carries_no_state_from_the_one_before() {
    let e = [
        vec![0.3, -1.2, 0.7, 0.1, -0.4],
        vec![1.0, 0.2, -0.3, 0.8, 0.5],
    ];
    let g = [0.9, 0.1, -0.6, 0.4, 1.1];
    let (lo, hi) = ([-20.0; 5], [30.0; 5]);
    let mut s = lp(&e, &g, &lo, &hi);
    let first = s.solve(0, 1.0).unwrap();
    // Another programme in the same workspace, then the first again: bit-identical.
    s.solve(2, -1.0).unwrap();
    s.set_bounds(2, 0.0, 0.0);
    s.crash();
    s.solve(1, 1.0).unwrap();
    s.set_bounds(2, -20.0, 30.0);
    s.crash();
    s.solve(0, -1.0).unwrap();
    assert_eq!(s.solve(0, 1.0).unwrap().to_bits(), first.to_bits());
    assert!((first - brute_force(&e, &g, &lo, &hi)).abs() < 1e-10);
}

/// A random small programme: `p ≤ 4` rows of `m ≤ 6` columns, integer entries in −3..3 (or
/// fractional), integer boxes containing 0 (some a point, some one-sided), and optionally a
/// repeated row (rank deficient).
fn programme() -> impl Strategy<Value = (Vec<Vec<f64>>, Vec<f64>, Vec<f64>, Vec<f64>)> {
    (1usize..=6, 0usize..=4, any::<bool>(), any::<bool>()).prop_flat_map(|(m, p, repeat, frac)| {
        let entry = move || {
            (-3i32..=3, 0u8..4).prop_map(move |(a, b)| {
                if frac {
                    a as f64 + b as f64 / 4.0 - 0.375
                } else {
                    a as f64
                }
            })
        };
        (
            prop::collection::vec(prop::collection::vec(entry(), m), p),
            prop::collection::vec(entry(), m),
            prop::collection::vec(-3i32..=0, m),
            prop::collection::vec(0i32..=3, m),
        )
            .prop_map(move |(mut e, g, lo, hi)| {
                if repeat && e.len() >= 2 {
                    e[1] = e[0].iter().map(|x| 2.0 * x).collect();
                }
                let f = |v: Vec<i32>| v.into_iter().map(f64::from).collect::<Vec<_>>();
                (e, g, f(lo), f(hi))
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn equals_brute_force_vertex_enumeration(
        (e, g, lo, hi) in programme(),
        bland in any::<bool>(),
        pick in 0usize..5,
        negative in any::<bool>(),
    ) {
        // M = [g; e]; the programme of row r = pick mod c, sign ±: brute force on
        // max ±M_r u s.t. the other rows = 0.
        let mut s = lp(&e, &g, &lo, &hi);
        if bland {
            // Bland's rule from the start: the anti-cycling path on every kind of programme.
            s.degenerate_limit = 0;
        }
        let mut rows = vec![g.clone()];
        rows.extend(e.iter().cloned());
        let r = pick % rows.len();
        let sign = if negative { -1.0 } else { 1.0 };
        let obj: Vec<f64> = rows[r].iter().map(|x| sign * x).collect();
        let others: Vec<Vec<f64>> =
            rows.iter().enumerate().filter(|&(i, _)| i != r).map(|(_, x)| x.clone()).collect();
        let want = brute_force(&others, &obj, &lo, &hi);
        let got = s.solve(r, sign);
        prop_assert!(got.is_some(), "not certified: {:?}", s.last);
        let got = got.unwrap();
        let tol = 1e-9 * (1.0 + want.abs());
        prop_assert!((got - want).abs() <= tol, "{} vs {} {:?}", got, want, s.last);
        // The dual bound is an upper bound on the optimum and the certificate's gap is tight.
        prop_assert!(s.last.dual_bound >= want - tol);
        prop_assert!(s.last.dual_bound - s.last.primal <= tol);
        prop_assert!(s.last.residual <= 1e-12 && s.last.violation <= 1e-12, "{:?}", s.last);
    }
}

//! Tests of the statistics kernels: quantiles against numpy, the normal quantile, Sobol indices
//! of the Ishigami function, (rank) regression coefficients.

use super::*;
use std::f64::consts::PI;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn quantiles_and_description_match_numpy() {
    // numpy 1.26: np.percentile(x, [5, 25, 50, 75, 95]) (method="linear"), x.mean(),
    // x.std(ddof=1) for x = [0.5, 2, -1.25, 3, 10, 4.5, 2] (Python's statistics.quantiles
    // with method="inclusive" agrees).
    let x = [0.5, 2.0, -1.25, 3.0, 10.0, 4.5, 2.0];
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    for (p, want) in [
        (0.05, -0.725),
        (0.25, 1.25),
        (0.5, 2.0),
        (0.75, 3.75),
        (0.95, 8.35),
        (0.0, -1.25),
        (1.0, 10.0),
    ] {
        let got = quantile_sorted(&s, p);
        assert!(close(got, want, 1e-12), "p = {p}: {got} vs {want}");
    }
    let mut with_nan = x.to_vec();
    with_nan.insert(3, f64::NAN);
    let d = describe(&with_nan);
    assert_eq!(d.n, 7);
    assert!(close(d.mean, 2.964_285_714_285_714_4, 1e-15));
    assert!(close(d.std, 3.595_218_385_313_365, 1e-14));
    assert!(close(d.p05, -0.725, 1e-12) && close(d.p95, 8.35, 1e-12));
    assert_eq!((d.p50, d.min, d.max), (2.0, -1.25, 10.0));
    // The order of the input does not matter, bit for bit.
    let mut rev = with_nan.clone();
    rev.reverse();
    assert_eq!(describe(&rev), d);
    // Edge cases.
    assert!(quantile_sorted(&[], 0.5).is_nan());
    assert!(quantile_sorted(&s, f64::NAN).is_nan());
    assert_eq!(
        quantile_sorted(&[f64::INFINITY, f64::INFINITY], 0.3),
        f64::INFINITY
    );
    let one = describe(&[4.0]);
    assert_eq!(
        (one.n, one.mean, one.std, one.p05, one.p95),
        (1, 4.0, 0.0, 4.0, 4.0)
    );
    for empty in [describe(&[]), describe(&[f64::NAN, f64::NAN])] {
        assert_eq!(empty.n, 0);
        assert!(empty.mean.is_nan() && empty.std.is_nan() && empty.p50.is_nan());
        assert!(empty.min.is_nan() && empty.max.is_nan());
    }
}

#[test]
fn normal_quantile_is_accurate_and_inverts_the_cdf() {
    // Reference values: scipy.stats.norm.ppf / norm.cdf (double precision).
    for (p, x) in [
        (0.5, 0.0),
        (0.975, 1.959_963_984_540_054),
        (0.95, 1.644_853_626_951_472_2),
        (0.01, -2.326_347_874_040_841),
        (0.841_344_746_068_542_9, 1.0),
    ] {
        let got = normal::inv_cdf(p);
        assert!(close(got, x, 1e-14 * x.abs().max(1.0)), "{p}: {got} vs {x}");
    }
    assert!(close(normal::cdf(1.96), 0.975_002_104_851_779_5, 1e-15));
    assert!(close(normal::cdf(-1.0), 0.158_655_253_931_457_07, 1e-15));
    assert_eq!(normal::cdf(0.0), 0.5);
    // Round trip over the whole range, all three regions of AS 241, both tails.
    let mut p = 1e-300_f64;
    while p < 1.0 {
        for q in [p, 1.0 - p] {
            if q <= 0.0 || q >= 1.0 {
                continue;
            }
            let x = normal::inv_cdf(q);
            // Each tail through its own side of the cdf (symmetry), so no cancellation.
            let back = if q < 0.5 {
                normal::cdf(x) / q
            } else {
                normal::cdf(-x) / (1.0 - q)
            };
            // dΦ/Φ ≈ |x| dx: allow for the steepness of the far tail.
            assert!(
                (back - 1.0).abs() < 2e-15 * (1.0 + x * x),
                "p = {q}: x = {x}, ratio {back}"
            );
        }
        p *= 3.7;
    }
    assert_eq!(normal::inv_cdf(0.0), f64::NEG_INFINITY);
    assert_eq!(normal::inv_cdf(1.0), f64::INFINITY);
    assert!(normal::inv_cdf(-0.1).is_nan() && normal::inv_cdf(f64::NAN).is_nan());
    assert!(normal::inv_cdf(1.5).is_nan());
    // Symmetry.
    assert_eq!(normal::inv_cdf(0.3), -normal::inv_cdf(0.7));
}

#[test]
fn saltelli_points_follow_the_documented_order() {
    let design = SaltelliDesign { n: 8, d: 3 };
    let pts = design.points(11);
    assert_eq!(pts.len(), 8 * 5);
    assert_eq!(design.len(), 40);
    for j in 0..8 {
        let (a, b) = (&pts[j * 5], &pts[j * 5 + 1]);
        for i in 0..3 {
            let mut ab = a.clone();
            ab[i] = b[i];
            assert_eq!(pts[j * 5 + 2 + i], ab);
        }
        assert_ne!(a, b);
    }
    let mut out = vec![0.0; 3];
    for (k, p) in pts.iter().enumerate() {
        design.point(11, k, &mut out);
        assert_eq!(&out, p);
        assert!(p.iter().all(|v| (0.0..1.0).contains(v)));
    }
    // A and B: columns of one scrambled 6-D Sobol sequence, so each column of the first 8
    // base samples has one point in each eighth of [0, 1).
    for col in 0..6 {
        let mut seen = [false; 8];
        for j in 0..8 {
            let v = if col < 3 {
                pts[j * 5][col]
            } else {
                pts[j * 5 + 1][col - 3]
            };
            seen[(v * 8.0) as usize] = true;
        }
        assert!(seen.iter().all(|s| *s), "column {col}");
    }
    assert_eq!(design.points(11), pts);
    assert_ne!(design.points(12), pts);
    // Beyond the Sobol tables' dimensions: still points, still deterministic.
    let wide = SaltelliDesign { n: 2, d: 200 };
    let w = wide.points(5);
    assert_eq!(w.len(), 2 * 202);
    assert!(w.iter().flatten().all(|v| (0.0..1.0).contains(v)));
    assert_ne!(w[0][150..], w[1][150..]);
}

/// The Ishigami function with a = 7, b = 0.1 on [−π, π]³, from a point of [0, 1)³.
fn ishigami(u: &[f64]) -> f64 {
    let x: Vec<f64> = u.iter().map(|v| -PI + 2.0 * PI * v).collect();
    x[0].sin() + 7.0 * x[1].sin().powi(2) + 0.1 * x[2].powi(4) * x[0].sin()
}

/// Analytic (first-order, total) indices of the Ishigami function: Ishigami & Homma (1990);
/// closed forms as in Sobol' & Levitan (1999) and Saltelli et al. (2008), "Global Sensitivity
/// Analysis. The Primer", §4.8 (also SALib's test_functions/Ishigami docstring):
/// V = a²/8 + bπ⁴/5 + b²π⁸/18 + 1/2, V₁ = (1 + bπ⁴/5)²/2, V₂ = a²/8, V₃ = 0,
/// V₁₃ = b²π⁸ (1/18 − 1/50), all other terms 0.
fn ishigami_indices(a: f64, b: f64) -> [(f64, f64); 3] {
    let pi4 = PI.powi(4);
    let pi8 = PI.powi(8);
    let v = a * a / 8.0 + b * pi4 / 5.0 + b * b * pi8 / 18.0 + 0.5;
    let v1 = 0.5 * (1.0 + b * pi4 / 5.0).powi(2);
    let v2 = a * a / 8.0;
    let v13 = b * b * pi8 * (1.0 / 18.0 - 1.0 / 50.0);
    [(v1 / v, (v1 + v13) / v), (v2 / v, v2 / v), (0.0, v13 / v)]
}

#[test]
fn sobol_indices_of_ishigami_match_the_closed_form() {
    let exact = ishigami_indices(7.0, 0.1);
    // The values usually quoted.
    assert!(close(exact[0].0, 0.3139, 1e-4) && close(exact[1].0, 0.4424, 1e-4));
    assert!(close(exact[0].1, 0.5576, 1e-4) && close(exact[2].1, 0.2437, 1e-4));
    let design = SaltelliDesign { n: 1 << 13, d: 3 };
    let y: Vec<f64> = design.points(2024).iter().map(|p| ishigami(p)).collect();
    let s = sobol_indices(&design, &y, 200, 7);
    assert_eq!(s.len(), 3);
    for (i, (idx, (first, total))) in s.iter().zip(exact).enumerate() {
        let show = |v: f64, lo: f64, hi: f64, exact: f64| {
            format!("{v:.4} [{lo:.4}, {hi:.4}] (exact {exact:.4})")
        };
        eprintln!(
            "S{0} = {1}, ST{0} = {2}",
            i + 1,
            show(idx.first, idx.first_lo, idx.first_hi, first),
            show(idx.total, idx.total_lo, idx.total_hi, total)
        );
        assert!(
            close(idx.first, first, 0.02),
            "S{}: {} vs {first}",
            i + 1,
            idx.first
        );
        assert!(
            close(idx.total, total, 0.02),
            "ST{}: {} vs {total}",
            i + 1,
            idx.total
        );
        assert!(
            idx.first_lo <= idx.first && idx.first <= idx.first_hi,
            "{idx:?}"
        );
        assert!(
            idx.total_lo <= idx.total && idx.total <= idx.total_hi,
            "{idx:?}"
        );
        assert!(idx.first_hi - idx.first_lo < 0.1 && idx.total_hi > idx.total_lo);
    }
    // Same inputs, same seed: bit-identical; another bootstrap seed moves only the intervals.
    assert_eq!(sobol_indices(&design, &y, 200, 7), s);
    let other = sobol_indices(&design, &y, 200, 8);
    assert_eq!(other[0].first, s[0].first);
    assert_ne!(other[0].first_lo, s[0].first_lo);
}

#[test]
fn sobol_indices_drop_non_finite_base_samples() {
    let design = SaltelliDesign { n: 64, d: 2 };
    let f = |p: &Vec<f64>| p[0] + 2.0 * p[1] * p[1];
    let mut y: Vec<f64> = design.points(3).iter().map(f).collect();
    // Base sample 5 loses one output: the result is that of the design without sample 5.
    let mut rest = y.clone();
    rest.drain(5 * 4..6 * 4);
    y[5 * 4 + 3] = f64::NAN;
    let with_nan = sobol_indices(&design, &y, 0, 1);
    let without = sobol_indices(&SaltelliDesign { n: 63, d: 2 }, &rest, 0, 1);
    let fields = |v: &[SobolIndex]| v.iter().map(|s| (s.first, s.total)).collect::<Vec<_>>();
    assert_eq!(fields(&with_nan), fields(&without));
    assert!(with_nan
        .iter()
        .all(|s| s.first.is_finite() && s.total.is_finite()));
    assert!(with_nan
        .iter()
        .all(|s| s.first_lo.is_nan() && s.total_hi.is_nan()));
    // Wrong length, constant output, too few samples: NaN, never a panic.
    assert!(sobol_indices(&design, &y[1..], 10, 1)[0].first.is_nan());
    assert!(sobol_indices(&design, &vec![1.0; 256], 10, 1)[1]
        .total
        .is_nan());
    // Constant at A and B but not at AB: still NaN, not infinite.
    let flat_ab: Vec<f64> = (0..256)
        .map(|k| if k % 4 < 2 { 1.0 } else { k as f64 })
        .collect();
    let s = sobol_indices(&design, &flat_ab, 10, 1);
    assert!(s
        .iter()
        .all(|i| i.first.is_nan() && i.total.is_nan() && i.first_lo.is_nan()));
    let mut all_nan = y.clone();
    all_nan.iter_mut().skip(4).for_each(|v| *v = f64::NAN);
    assert!(sobol_indices(&design, &all_nan, 10, 1)[0].first.is_nan());
    assert!(sobol_indices(&SaltelliDesign { n: 0, d: 2 }, &[], 10, 1)[0]
        .first
        .is_nan());
}

#[test]
fn average_ranks_share_ties() {
    assert_eq!(
        average_ranks(&[10.0, 20.0, 20.0, 30.0]),
        [1.0, 2.5, 2.5, 4.0]
    );
    assert_eq!(average_ranks(&[3.0, 1.0, 2.0]), [3.0, 1.0, 2.0]);
    assert_eq!(average_ranks(&[5.0; 3]), [2.0; 3]);
    assert!(average_ranks(&[]).is_empty());
}

/// `n` rows of `d` uniform inputs from a seeded generator.
fn uniform_rows(n: usize, d: usize, seed: u64) -> Vec<Vec<f64>> {
    use rand::Rng;
    let mut rng = crate::sampling::rng_for(seed, 0);
    (0..n)
        .map(|_| (0..d).map(|_| rng.random::<f64>()).collect())
        .collect()
}

#[test]
fn srrc_orders_linear_drivers() {
    let x = uniform_rows(400, 3, 5);
    let y: Vec<f64> = x
        .iter()
        .map(|r| 3.0 * r[0] + 0.1 * r[1] + 0.0 * r[2])
        .collect();
    let s = srrc(&x, &y);
    assert!(s.coef[0].abs() > s.coef[1].abs(), "{s:?}");
    assert!(s.coef[1] > 0.01 && s.coef[0] > 0.9, "{s:?}");
    assert!(s.coef[2].abs() < 0.02, "{s:?}");
    assert!(s.r2 > 0.99, "{s:?}");
    // On raw values the linear model is exact: SRC_i = b_i sd(x_i) / sd(y), R² = 1.
    let l = src(&x, &y);
    assert!(close(l.r2, 1.0, 1e-12), "{l:?}");
    let sd = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / (v.len() - 1) as f64).sqrt()
    };
    let col = |i: usize| x.iter().map(|r| r[i]).collect::<Vec<_>>();
    assert!(close(l.coef[0], 3.0 * sd(&col(0)) / sd(&y), 1e-10));
    assert!(close(l.coef[1], 0.1 * sd(&col(1)) / sd(&y), 1e-10));
    assert!(close(l.coef[2], 0.0, 1e-10));
}

#[test]
fn srrc_sees_monotone_nonlinear_drivers() {
    let x = uniform_rows(300, 2, 9);
    let y: Vec<f64> = x.iter().map(|r| (6.0 * r[0]).exp()).collect();
    let s = srrc(&x, &y);
    assert!(
        close(s.coef[0], 1.0, 1e-9) && close(s.coef[1], 0.0, 1e-9),
        "{s:?}"
    );
    assert!(close(s.r2, 1.0, 1e-9));
    // The raw-value regression misses part of it.
    assert!(src(&x, &y).r2 < 0.9);
}

#[test]
fn srrc_handles_constant_columns_missing_rows_and_bad_shapes() {
    let mut x = uniform_rows(50, 3, 1);
    for r in &mut x {
        r[1] = 2.5;
    }
    let mut y: Vec<f64> = x.iter().map(|r| r[0] - r[2]).collect();
    y[7] = f64::NAN;
    let s = srrc(&x, &y);
    assert_eq!(s.coef[1], 0.0);
    assert!(s.coef[0] > 0.5 && s.coef[2] < -0.5 && s.r2 > 0.9, "{s:?}");
    // Leaving out row 7 by hand gives the same numbers.
    let (mut x2, mut y2) = (x.clone(), y.clone());
    x2.remove(7);
    y2.remove(7);
    assert_eq!(srrc(&x2, &y2), s);
    // Collinear columns share the effect instead of blowing up.
    let xc: Vec<Vec<f64>> = x.iter().map(|r| vec![r[0], r[0]]).collect();
    let yc: Vec<f64> = x.iter().map(|r| r[0]).collect();
    let c = srrc(&xc, &yc);
    assert!(
        close(c.coef[0], 0.5, 1e-9) && close(c.coef[1], 0.5, 1e-9),
        "{c:?}"
    );
    // Constant y: zero coefficients; bad shapes and too few rows: NaN.
    let flat = srrc(&x, &vec![1.0; 50]);
    assert_eq!(flat.coef, vec![0.0; 3]);
    assert!(flat.r2.is_nan());
    assert!(srrc(&x, &y[1..]).coef.iter().all(|c| c.is_nan()));
    assert!(srrc(&x[..1], &y[..1]).r2.is_nan());
    assert!(srrc(&[], &[]).coef.is_empty());
}

//! Tests of the small dense kernels: Laguerre's interleaved iteration and the nested reduction.

use super::*;
use rand::{Rng, SeedableRng};

/// One side iterated alone: the loop `laguerre_extremes` interleaves.
fn one_side<const K: usize>(d: &[f64; 6], e2: &[f64; 6], start: f64, below: bool) -> Option<f64> {
    let tiny = 4.0 * f64::EPSILON * 10.0;
    let mut x = start;
    for _ in 0..40 {
        let (mut p0, mut p1) = (1.0, d[0] - x);
        let (mut dp0, mut dp1) = (0.0, -1.0);
        let (mut ddp0, mut ddp1) = (0.0, 0.0);
        for j in 1..K {
            let (a, b) = (d[j] - x, e2[j - 1]);
            let p2 = a * p1 - b * p0;
            let dp2 = a * dp1 - b * dp0 - p1;
            let ddp2 = a * ddp1 - b * ddp0 - 2.0 * dp1;
            (p0, p1, dp0, dp1, ddp0, ddp1) = (p1, p2, dp1, dp2, ddp1, ddp2);
        }
        if let Some(r) = laguerre_update(&mut x, [p1, dp1, ddp1], K as f64, below, tiny) {
            return r;
        }
    }
    None
}

#[test]
fn nested_reduction_gives_the_extremes_of_the_whole_and_the_leading_block() {
    // Random Gram matrices B Bᵀ (6×m, m = 6..9, some columns scaled down to spread the
    // spectrum, some rank-deficient): the nested route's extremes of the whole matrix and
    // of its leading 5×5 block against the implicit QL eigenvalues of each, to
    // 1e-13·λ_max absolute.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for trial in 0..2000 {
        let m = 6 + trial % 4;
        let scale: Vec<f64> = (0..m)
            .map(|c| {
                if trial % 3 == 0 && c == 0 {
                    0.0
                } else {
                    10f64.powf(-3.0 * rng.random::<f64>())
                }
            })
            .collect();
        let b: Vec<[f64; 6]> = (0..m)
            .map(|c| std::array::from_fn(|_| scale[c] * (rng.random::<f64>() - 0.5)))
            .collect();
        let mut a = [[0.0; 6]; 6];
        for col in &b {
            for i in 0..6 {
                for j in 0..6 {
                    a[i][j] += col[i] * col[j];
                }
            }
        }
        for kc in [5, 6] {
            let [whole, lead] = extreme_eigenvalues_nested(&mut a.clone(), kc);
            for (got, k) in [(whole, 6), (lead, kc)] {
                let ev = tridiagonal_eigenvalues(&mut a.clone(), k);
                let (lo, hi) = min_max(&ev[..k]);
                let tol = 1e-13 * hi;
                assert!(
                    (got.0 - lo).abs() <= tol && (got.1 - hi).abs() <= tol,
                    "trial {trial} k {k}: {got:?} vs ({lo}, {hi})"
                );
            }
        }
    }
}

#[test]
fn interleaved_equals_one_side_at_a_time() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    for trial in 0..500 {
        let d: [f64; 6] = std::array::from_fn(|_| rng.random::<f64>() * 4.0);
        // Some trials with a (near-)zero coupling: repeated or decoupled roots.
        let e2: [f64; 6] = std::array::from_fn(|_| {
            if trial % 7 == 0 && rng.random::<f64>() < 0.5 {
                0.0
            } else {
                rng.random::<f64>()
            }
        });
        let (lo, hi) = (-3.0, 8.0);
        let tri = |k| Tridiagonal {
            k,
            d,
            e: [0.0; 6],
            e2,
            starts: [lo, hi],
            scale: 10.0,
        };
        let (t6, t5, t3) = (tri(6), tri(5), tri(3));
        let alone = |k| match k {
            6 => [
                one_side::<6>(&d, &e2, lo, true),
                one_side::<6>(&d, &e2, hi, false),
            ],
            5 => [
                one_side::<5>(&d, &e2, lo, true),
                one_side::<5>(&d, &e2, hi, false),
            ],
            _ => [
                one_side::<3>(&d, &e2, lo, true),
                one_side::<3>(&d, &e2, hi, false),
            ],
        };
        let bits = |r: [Option<f64>; 2]| r.map(|x| x.map(f64::to_bits));
        let [r6] = laguerre_extremes([&t6]);
        assert_eq!(bits(r6), bits(alone(6)), "trial {trial}");
        let [r6, r5] = laguerre_extremes([&t6, &t5]);
        assert_eq!(bits(r6), bits(alone(6)), "trial {trial}");
        assert_eq!(bits(r5), bits(alone(5)), "trial {trial}");
        let [r3, r6] = laguerre_extremes([&t3, &t6]);
        assert_eq!(bits(r3), bits(alone(3)), "trial {trial}");
        assert_eq!(bits(r6), bits(alone(6)), "trial {trial}");
    }
}

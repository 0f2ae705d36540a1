//! Distributions of a per-sample quantity of the static TCM analysis (docs/model.md §6): min, max,
//! mean of the finite values and the [`QUANTILES`], exact (from all samples, sorted).

use serde::Serialize;

/// Quantile levels reported for σ_min and κ.
pub const QUANTILES: [f64; 7] = [0.01, 0.05, 0.10, 0.25, 0.50, 0.75, 0.95];

/// Distribution of a per-sample quantity.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Distribution {
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Mean of the finite values (summed in index order).
    pub mean: f64,
    /// Number of non-finite values (κ of rank-deficient samples).
    pub non_finite: usize,
    /// `(level, value)` pairs for [`QUANTILES`] (linear interpolation between order statistics).
    pub quantiles: Vec<(f64, f64)>,
}

impl Distribution {
    /// The value at quantile level `p` if it is one of [`QUANTILES`].
    pub fn quantile(&self, p: f64) -> Option<f64> {
        self.quantiles
            .iter()
            .find(|(l, _)| *l == p)
            .map(|(_, v)| *v)
    }
}

/// The lower order-statistic index of level `p` among `len ≥ 1` values (type 7).
fn order_index(len: usize, p: f64) -> usize {
    (p.clamp(0.0, 1.0) * (len - 1) as f64).floor() as usize
}

/// Put the order statistics at the ascending positions `wanted` (relative to `offset`, the
/// slice's position in the whole) in place, as a sort by `f64::total_cmp` would: select the
/// middle wanted position, then recurse into the two sides with the positions each holds.
fn select_order_statistics(values: &mut [f64], wanted: &[usize], offset: usize) {
    if wanted.is_empty() || values.len() < 2 {
        return;
    }
    let mid = wanted.len() / 2;
    let k = wanted[mid] - offset;
    let (left, _, right) = values.select_nth_unstable_by(k, f64::total_cmp);
    select_order_statistics(left, &wanted[..mid], offset);
    select_order_statistics(right, &wanted[mid + 1..], offset + k + 1);
}

/// Quantile at level `p` of sorted values (linear interpolation, "type 7"); `inf` propagates.
/// Only the two order statistics around `p` are read.
pub fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = p.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let lo = order_index(sorted.len(), p);
    let hi = (lo + 1).min(sorted.len() - 1);
    let f = h - lo as f64;
    let (a, b) = (sorted[lo], sorted[hi]);
    if f == 0.0 || a == b {
        a
    } else if !a.is_finite() || !b.is_finite() {
        if f < 1.0 {
            b.max(a)
        } else {
            b
        }
    } else {
        a + (b - a) * f
    }
}

/// The distribution of `values` (consumed: reordered in place). Only the order statistics the
/// report reads (min, max and the two neighbours of each quantile level) are put in place, by
/// selection (O(n)) instead of a full sort; under `f64::total_cmp` the `k`-th order statistic
/// is one bit pattern whatever the algorithm, so the result equals the sorted route's bit for
/// bit (`selection_equals_sorting` below).
pub fn distribution(mut values: Vec<f64>) -> Distribution {
    let (mut sum, mut n) = (0.0, 0usize);
    for x in &values {
        if x.is_finite() {
            sum += x;
            n += 1;
        }
    }
    let non_finite = values.len() - n;
    let len = values.len();
    if len > 0 {
        let mut wanted: Vec<usize> = vec![0, len - 1];
        for &p in &QUANTILES {
            let lo = order_index(len, p);
            wanted.extend([lo, (lo + 1).min(len - 1)]);
        }
        wanted.sort_unstable();
        wanted.dedup();
        select_order_statistics(&mut values, &wanted, 0);
    }
    Distribution {
        min: values.first().copied().unwrap_or(f64::NAN),
        max: values.last().copied().unwrap_or(f64::NAN),
        mean: if n > 0 { sum / n as f64 } else { f64::NAN },
        non_finite,
        quantiles: QUANTILES
            .iter()
            .map(|&p| (p, quantile_sorted(&values, p)))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The sorted route the selection replaced.
    fn sorted_distribution(mut values: Vec<f64>) -> Distribution {
        let (mut sum, mut n) = (0.0, 0usize);
        for x in &values {
            if x.is_finite() {
                sum += x;
                n += 1;
            }
        }
        values.sort_unstable_by(f64::total_cmp);
        Distribution {
            min: values.first().copied().unwrap_or(f64::NAN),
            max: values.last().copied().unwrap_or(f64::NAN),
            mean: if n > 0 { sum / n as f64 } else { f64::NAN },
            non_finite: values.len() - n,
            quantiles: QUANTILES
                .iter()
                .map(|&p| (p, quantile_sorted(&values, p)))
                .collect(),
        }
    }

    fn bits(d: &Distribution) -> Vec<u64> {
        let mut out = vec![
            d.min.to_bits(),
            d.max.to_bits(),
            d.mean.to_bits(),
            d.non_finite as u64,
        ];
        out.extend(
            d.quantiles
                .iter()
                .flat_map(|(p, v)| [p.to_bits(), v.to_bits()]),
        );
        out
    }

    #[test]
    fn selection_equals_sorting() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for len in [0usize, 1, 2, 3, 7, 8, 100, 101, 1000, 4097] {
            for trial in 0..4 {
                let v: Vec<f64> = (0..len)
                    .map(|_| match (trial, rng.random_range(0..10)) {
                        // ties, infinities, signed zeros and a NaN mixed in
                        (1, 0) => f64::INFINITY,
                        (1, 1) => 0.0,
                        (1, 2) => -0.0,
                        (2, k) if k < 5 => (rng.random_range(0..4) as f64) * 0.5,
                        (3, 0) => f64::NAN,
                        _ => rng.random::<f64>() * 10.0 - 2.0,
                    })
                    .collect();
                assert_eq!(
                    bits(&distribution(v.clone())),
                    bits(&sorted_distribution(v)),
                    "len {len} trial {trial}"
                );
            }
        }
    }
}

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

/// Quantile at level `p` of sorted values (linear interpolation, "type 7"); `inf` propagates.
pub fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let h = p.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let lo = h.floor() as usize;
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

/// The distribution of `values` (consumed: sorted in place).
pub fn distribution(mut values: Vec<f64>) -> Distribution {
    let (mut sum, mut n) = (0.0, 0usize);
    for x in &values {
        if x.is_finite() {
            sum += x;
            n += 1;
        }
    }
    let non_finite = values.len() - n;
    values.sort_unstable_by(f64::total_cmp);
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

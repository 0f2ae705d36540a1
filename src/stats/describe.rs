//! Quantiles and a one-line description of a sample.

/// The `p`-quantile of an ascending `sorted` slice by linear interpolation between order
/// statistics: R's type 7, numpy's default (`method = "linear"`), with numpy's interpolation
/// formula so that results match it bit for bit on finite data.
///
/// `p` is clamped to `[0, 1]`; an empty slice or a NaN `p` gives NaN. The slice must be sorted
/// ascending (NaN-free); this is not checked.
pub fn quantile_sorted(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    if n == 0 || p.is_nan() {
        return f64::NAN;
    }
    let h = (n - 1) as f64 * p.clamp(0.0, 1.0);
    let lo = (h.floor() as usize).min(n - 1);
    let hi = (lo + 1).min(n - 1);
    let t = h - lo as f64;
    let (a, b) = (sorted[lo], sorted[hi]);
    if a == b {
        // Also keeps equal infinities from turning into NaN.
        return a;
    }
    // numpy's `_lerp`: from the nearer end, so that t = 1 gives b exactly.
    let diff = b - a;
    if t >= 0.5 {
        b - diff * (1.0 - t)
    } else {
        a + diff * t
    }
}

/// A summary of a sample (NaN values left out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Describe {
    /// Number of non-NaN values.
    pub n: usize,
    /// Arithmetic mean (NaN when `n = 0`).
    pub mean: f64,
    /// Sample standard deviation (divisor `n − 1`); 0 when `n = 1`, NaN when `n = 0`.
    pub std: f64,
    /// 5 % quantile ([`quantile_sorted`]).
    pub p05: f64,
    /// Median.
    pub p50: f64,
    /// 95 % quantile.
    pub p95: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Describe {
    /// The description of an empty sample: `n = 0`, every field NaN.
    pub const EMPTY: Describe = Describe {
        n: 0,
        mean: f64::NAN,
        std: f64::NAN,
        p05: f64::NAN,
        p50: f64::NAN,
        p95: f64::NAN,
        min: f64::NAN,
        max: f64::NAN,
    };
}

/// Describes the non-NaN values of `xs` (infinities are kept: they move the quantiles and make
/// the mean infinite). Sums run over a sorted copy, so the result does not depend on the order
/// of `xs`. Empty or all-NaN input gives [`Describe::EMPTY`].
pub fn describe(xs: &[f64]) -> Describe {
    let mut s: Vec<f64> = xs.iter().copied().filter(|x| !x.is_nan()).collect();
    if s.is_empty() {
        return Describe::EMPTY;
    }
    s.sort_by(f64::total_cmp);
    let n = s.len();
    let mean = s.iter().sum::<f64>() / n as f64;
    let std = if n == 1 {
        0.0
    } else {
        (s.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64).sqrt()
    };
    Describe {
        n,
        mean,
        std,
        p05: quantile_sorted(&s, 0.05),
        p50: quantile_sorted(&s, 0.5),
        p95: quantile_sorted(&s, 0.95),
        min: s[0],
        max: s[n - 1],
    }
}

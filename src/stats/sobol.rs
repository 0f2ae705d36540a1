//! Variance-based sensitivity: Saltelli designs and Sobol first-order and total indices.
//!
//! A [`SaltelliDesign`] of `n` base samples in `d` dimensions has `n·(d + 2)` points: for base
//! sample `j`, `A_j`, `B_j` and `AB_j^(1) … AB_j^(d)`, where `AB^(i)` is `A` with coordinate `i`
//! taken from `B`. `A` and `B` are the two halves of one `2d`-dimensional scrambled Sobol
//! sequence of [`crate::sampling`], so every point is a pure function of `(seed, index)`.
//! [`sobol_indices`] turns the outputs at those points into indices (Saltelli et al. 2010 first
//! order, Jansen 1999 total, normalised like SALib) with percentile-bootstrap intervals.

use rand::Rng;

use super::describe::quantile_sorted;
use crate::sampling::{derive_seed, rng_for, Sampler, Sampling, MAX_SOBOL_DIMS};

/// A Saltelli design: `n` base samples of `d` uncertain inputs (see the module doc for the
/// order of its points). Powers of two for `n` keep the Sobol points balanced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SaltelliDesign {
    /// Number of base samples (rows of `A` and `B`).
    pub n: usize,
    /// Number of inputs.
    pub d: usize,
}

/// Stream offset of the bootstrap resamples' generators (apart from other uses of a seed).
const BOOTSTRAP_STREAM: u64 = 0x534F_424F_4C00_0000;

impl SaltelliDesign {
    /// Points per base sample: `d + 2`.
    pub fn stride(&self) -> usize {
        self.d + 2
    }

    /// Number of points, `n·(d + 2)`.
    pub fn len(&self) -> usize {
        self.n * self.stride()
    }

    /// Whether the design has no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `j` of `A` and of `B` (each of length `d`): coordinates `0..d` and `d..2d` of point
    /// `j` of a `2d`-dimensional scrambled Sobol sequence seeded with `seed`. Beyond the
    /// Sobol tables' [`MAX_SOBOL_DIMS`] dimensions, each further block of dimensions uses the
    /// same tables under a scramble seed derived from `(seed, block)`.
    pub fn base(&self, seed: u64, j: usize, a: &mut [f64], b: &mut [f64]) {
        debug_assert!(a.len() == self.d && b.len() == self.d);
        let dims = 2 * self.d;
        let mut buf = vec![0.0; dims.min(MAX_SOBOL_DIMS)];
        let mut start = 0;
        while start < dims {
            let block = start / MAX_SOBOL_DIMS;
            let width = (dims - start).min(MAX_SOBOL_DIMS);
            let block_seed = if block == 0 {
                seed
            } else {
                derive_seed(seed, block as u64)
            };
            let n = self.n.clamp(1, u32::MAX as usize);
            let sampler = Sampler::new(Sampling::Sobol, n, width, block_seed)
                .expect("width ≤ MAX_SOBOL_DIMS and n ≤ u32::MAX by construction");
            sampler.point(j, &mut buf[..width]);
            for (k, &v) in buf[..width].iter().enumerate() {
                let dim = start + k;
                if dim < self.d {
                    a[dim] = v;
                } else {
                    b[dim - self.d] = v;
                }
            }
            start += width;
        }
    }

    /// Point `index` (< [`len`](Self::len)) of the design, written into `out` (length `d`):
    /// base sample `index / (d + 2)`, and within it `A`, `B`, then `AB^(1) … AB^(d)`.
    pub fn point(&self, seed: u64, index: usize, out: &mut [f64]) {
        let (j, k) = (index / self.stride(), index % self.stride());
        let mut b = vec![0.0; self.d];
        self.base(seed, j, out, &mut b);
        match k {
            0 => {}
            1 => out.copy_from_slice(&b),
            _ => out[k - 2] = b[k - 2],
        }
    }

    /// All `n·(d + 2)` points in `[0, 1)^d`, in the order of the module doc.
    pub fn points(&self, seed: u64) -> Vec<Vec<f64>> {
        let mut out = Vec::with_capacity(self.len());
        let mut a = vec![0.0; self.d];
        let mut b = vec![0.0; self.d];
        for j in 0..self.n {
            self.base(seed, j, &mut a, &mut b);
            out.push(a.clone());
            out.push(b.clone());
            for i in 0..self.d {
                let mut ab = a.clone();
                ab[i] = b[i];
                out.push(ab);
            }
        }
        out
    }
}

/// Sobol indices of one input, with 95 % percentile-bootstrap intervals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SobolIndex {
    /// First-order index S_i (Saltelli et al. 2010).
    pub first: f64,
    /// Lower end of the 95 % bootstrap interval of `first` (NaN without bootstrap).
    pub first_lo: f64,
    /// Upper end of the 95 % bootstrap interval of `first` (NaN without bootstrap).
    pub first_hi: f64,
    /// Total index ST_i (Jansen 1999).
    pub total: f64,
    /// Lower end of the 95 % bootstrap interval of `total` (NaN without bootstrap).
    pub total_lo: f64,
    /// Upper end of the 95 % bootstrap interval of `total` (NaN without bootstrap).
    pub total_hi: f64,
}

impl SobolIndex {
    /// Every field NaN: what cannot be estimated.
    pub const NAN: SobolIndex = SobolIndex {
        first: f64::NAN,
        first_lo: f64::NAN,
        first_hi: f64::NAN,
        total: f64::NAN,
        total_lo: f64::NAN,
        total_hi: f64::NAN,
    };
}

/// The centred outputs of the kept base samples, one row of `d + 2` values per sample.
struct Outputs {
    y: Vec<f64>,
    d: usize,
}

impl Outputs {
    fn rows(&self) -> usize {
        self.y.len() / (self.d + 2)
    }

    /// First-order and total indices over the base samples `rows` (with repetition).
    fn estimate(&self, rows: &[usize], first: &mut [f64], total: &mut [f64]) {
        let s = self.d + 2;
        let m = rows.len() as f64;
        // Variance of A and B together, about their own mean (np.var of np.r_[A, B]).
        let mean = rows
            .iter()
            .map(|&j| self.y[j * s] + self.y[j * s + 1])
            .sum::<f64>()
            / (2.0 * m);
        let var = rows
            .iter()
            .map(|&j| {
                let (a, b) = (self.y[j * s] - mean, self.y[j * s + 1] - mean);
                a * a + b * b
            })
            .sum::<f64>()
            / (2.0 * m);
        if !(var > 0.0 && var.is_finite()) {
            // No variance at A and B: the indices are undefined (not ±∞).
            first.fill(f64::NAN);
            total.fill(f64::NAN);
            return;
        }
        for i in 0..self.d {
            let (mut s1, mut st) = (0.0, 0.0);
            for &j in rows {
                let (a, b, ab) = (self.y[j * s], self.y[j * s + 1], self.y[j * s + 2 + i]);
                s1 += b * (ab - a);
                st += (a - ab) * (a - ab);
            }
            first[i] = s1 / m / var;
            total[i] = 0.5 * st / m / var;
        }
    }
}

/// Sobol first-order and total indices of `y`, the outputs at the points of `design` (same
/// order, length `n·(d + 2)`), with 95 % percentile-bootstrap intervals from `bootstrap`
/// resamples of the base samples (seeded by `seed`; 0 resamples: NaN intervals).
///
/// Estimators as SALib's `analyze.sobol`: the outputs are centred on their overall mean, then
/// with `V` the variance (divisor N) of the `A` and `B` outputs together,
/// `S_i = mean(f(B)·(f(AB_i) − f(A))) / V` (Saltelli et al. 2010) and
/// `ST_i = mean((f(A) − f(AB_i))²) / (2V)` (Jansen 1999). A base sample with any non-finite
/// output is dropped entirely. The indices are NaN when fewer than two base samples remain,
/// when the outputs at `A` and `B` do not vary (`V = 0`), or when `y.len()` does not match
/// the design.
pub fn sobol_indices(
    design: &SaltelliDesign,
    y: &[f64],
    bootstrap: usize,
    seed: u64,
) -> Vec<SobolIndex> {
    let (d, s) = (design.d, design.stride());
    if y.len() != design.len() {
        return vec![SobolIndex::NAN; d];
    }
    let kept: Vec<f64> = y
        .chunks_exact(s)
        .filter(|row| row.iter().all(|v| v.is_finite()))
        .flatten()
        .copied()
        .collect();
    let m = kept.len() / s;
    if m < 2 {
        return vec![SobolIndex::NAN; d];
    }
    let mu = kept.iter().sum::<f64>() / kept.len() as f64;
    let out = Outputs {
        y: kept.iter().map(|v| v - mu).collect(),
        d,
    };
    let all: Vec<usize> = (0..out.rows()).collect();
    let (mut first, mut total) = (vec![0.0; d], vec![0.0; d]);
    out.estimate(&all, &mut first, &mut total);

    // Bootstrap: resample the base samples with replacement, one generator per resample.
    let mut boot_first = vec![Vec::with_capacity(bootstrap); d];
    let mut boot_total = vec![Vec::with_capacity(bootstrap); d];
    let mut rows = vec![0usize; m];
    let (mut f, mut t) = (vec![0.0; d], vec![0.0; d]);
    for r in 0..bootstrap {
        let mut rng = rng_for(seed, BOOTSTRAP_STREAM + r as u64);
        for row in rows.iter_mut() {
            *row = rng.random_range(0..m);
        }
        out.estimate(&rows, &mut f, &mut t);
        for i in 0..d {
            boot_first[i].push(f[i]);
            boot_total[i].push(t[i]);
        }
    }
    (0..d)
        .map(|i| {
            let (first_lo, first_hi) = percentile_interval(&mut boot_first[i]);
            let (total_lo, total_hi) = percentile_interval(&mut boot_total[i]);
            SobolIndex {
                first: first[i],
                first_lo,
                first_hi,
                total: total[i],
                total_lo,
                total_hi,
            }
        })
        .collect()
}

/// The 2.5 % and 97.5 % quantiles of the non-NaN values (NaN, NaN when there are none).
fn percentile_interval(values: &mut Vec<f64>) -> (f64, f64) {
    values.retain(|v| !v.is_nan());
    values.sort_by(f64::total_cmp);
    (
        quantile_sorted(values, 0.025),
        quantile_sorted(values, 0.975),
    )
}

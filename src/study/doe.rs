//! Designs of experiments: expanding a study's axes into cases.
//!
//! Grid: the Cartesian product of every axis' value list, the first axis varying slowest.
//! Sampled (`random`, `lhs`, `sobol`): `cases` points of a [`Sampler`] over the unit hypercube
//! (one dimension per axis, seeded from the study seed); each coordinate `u` becomes a value:
//! a `values` list picks element `⌊u·len⌋`, a `range` maps linearly (geometrically with `log`)
//! onto `[start, stop]`, a distribution by its inverse CDF. Integer-valued targets are rounded.
//! Case `i` is a pure function of `(study, i)`.

use super::schema::{Axis, AxisSpec, Dist, Doe, Study};
use crate::sampling::{derive_seed, Sampler, SamplerError};

/// One case: its id and one value per axis (in axis order).
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Case id (0-based, dense).
    pub id: usize,
    /// Axis values, in axis order.
    pub values: Vec<toml::Value>,
}

fn range_value(start: f64, stop: f64, log: bool, t: f64) -> f64 {
    if log {
        (start.ln() + (stop.ln() - start.ln()) * t).exp()
    } else {
        start + (stop - start) * t
    }
}

/// The grid values of an axis.
pub fn grid_values(a: &Axis) -> Vec<toml::Value> {
    match &a.spec {
        AxisSpec::Values(v) => v.clone(),
        AxisSpec::Range {
            start,
            stop,
            steps,
            log,
        } => {
            let n = steps.unwrap_or(1);
            (0..n)
                .map(|k| {
                    let t = if n == 1 {
                        0.0
                    } else {
                        k as f64 / (n - 1) as f64
                    };
                    let x = if k == 0 {
                        *start
                    } else if k + 1 == n {
                        *stop
                    } else {
                        range_value(*start, *stop, *log, t)
                    };
                    number(a, x)
                })
                .collect()
        }
        AxisSpec::Distribution(_) => Vec::new(),
    }
}

fn number(a: &Axis, x: f64) -> toml::Value {
    if a.integer {
        toml::Value::Integer(x.round() as i64)
    } else {
        toml::Value::Float(x)
    }
}

/// The value of axis `a` at unit coordinate `u` ∈ [0, 1) (sampled designs).
pub fn sampled_value(a: &Axis, u: f64) -> toml::Value {
    match &a.spec {
        AxisSpec::Values(v) => v[((u * v.len() as f64) as usize).min(v.len() - 1)].clone(),
        AxisSpec::Range {
            start, stop, log, ..
        } => number(a, range_value(*start, *stop, *log, u)),
        AxisSpec::Distribution(d) => number(
            a,
            match *d {
                Dist::Uniform(lo, hi) => lo + (hi - lo) * u,
                Dist::LogUniform(lo, hi) => (lo.ln() + (hi.ln() - lo.ln()) * u).exp(),
                Dist::Normal(m, s) => m + s * inverse_normal_cdf(u),
            },
        ),
    }
}

/// Number of cases of the study.
pub fn case_count(study: &Study) -> usize {
    match study.doe {
        Doe::Grid => study.axes.iter().map(|a| a.spec.grid_len()).product(),
        Doe::Sampled { cases, .. } => cases,
    }
}

/// Expands the study's cases (ids `0..case_count`); for shards, only ids `≡ index (mod count)`.
pub fn expand(study: &Study, shard: Option<(usize, usize)>) -> Result<Vec<Case>, SamplerError> {
    let n = case_count(study);
    let keep = |id: usize| shard.is_none_or(|(i, k)| id % k == i);
    let mut out = Vec::new();
    match study.doe {
        Doe::Grid => {
            let lists: Vec<Vec<toml::Value>> = study.axes.iter().map(grid_values).collect();
            for id in (0..n).filter(|&id| keep(id)) {
                let mut rem = id;
                let mut values = vec![toml::Value::Integer(0); lists.len()];
                for (k, l) in lists.iter().enumerate().rev() {
                    values[k] = l[rem % l.len()].clone();
                    rem /= l.len();
                }
                out.push(Case { id, values });
            }
        }
        Doe::Sampled { kind, cases } => {
            let sampler = Sampler::new(
                kind,
                cases,
                study.axes.len(),
                derive_seed(study.seed, 0xD0E),
            )?;
            let mut u = vec![0.0; study.axes.len()];
            for id in (0..n).filter(|&id| keep(id)) {
                sampler.point(id, &mut u);
                let values = study
                    .axes
                    .iter()
                    .zip(&u)
                    .map(|(a, &x)| sampled_value(a, x))
                    .collect();
                out.push(Case { id, values });
            }
        }
    }
    Ok(out)
}

/// The standard normal quantile function Φ⁻¹(p) (Acklam's rational approximation, relative
/// error < 1.2e-9 on (0, 1)). `p` is clamped to [1e-300, 1 − 1e-16].
#[allow(clippy::excessive_precision)] // published coefficients, kept verbatim
pub fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e+01,
        2.209460984245205e+02,
        -2.759285104469687e+02,
        1.383577518672690e+02,
        -3.066479806614716e+01,
        2.506628277459239e+00,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e+01,
        1.615858368580409e+02,
        -1.556989798598866e+02,
        6.680131188771972e+01,
        -1.328068155288572e+01,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-03,
        -3.223964580411365e-01,
        -2.400758277161838e+00,
        -2.549732539343734e+00,
        4.374664141464968e+00,
        2.938163982698783e+00,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-03,
        3.224671290700398e-01,
        2.445134137142996e+00,
        3.754408661907416e+00,
    ];
    let p = if p.is_nan() {
        0.5
    } else {
        p.clamp(1e-300, 1.0 - 1e-16)
    };
    let plow = 0.02425;
    if p < plow {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - plow {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    }
}

#[cfg(test)]
#[path = "doe_tests.rs"]
mod tests;

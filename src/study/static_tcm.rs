//! Static configuration-space analysis of the thruster configuration matrix (SPEC §6):
//! "how often is `T(q)` singular" over a seeded distribution of joint configurations.
//!
//! Joint configurations are drawn uniformly within the joint limits by a
//! [`crate::sampling::Sampler`] (random, Latin hypercube or scrambled Sobol); for each sample
//! `T(q)` ([`crate::kinematics::thruster_matrix`]) is scored by the scaled singularity metrics
//! of [`crate::metrics::singularity`] (moment rows divided by a characteristic length `L`).
//!
//! Determinism: sample `i` is a pure function of `(seed, i)` (and `n` for LHS); samples are
//! evaluated in parallel in chunks and aggregated strictly in index order, so every number of
//! the [`StaticSummary`] — including means — is bit-identical for any thread count.
//!
//! Memory: per-sample rows are handed to a caller-supplied sink in index order, one chunk of
//! [`CHUNK`] samples at a time; the summary keeps σ_min and κ of every sample for exact
//! quantiles (16 bytes per sample) and the [`StaticSpec::worst`] lowest-σ_min configurations.

use nalgebra::{Matrix6, Matrix6xX};
use rayon::prelude::*;
use serde::Serialize;

use crate::kinematics::{forward_kinematics, thruster_matrix, KinWorkspace};
use crate::metrics::singularity::{
    scale_moment_rows, tcm_svd_metrics, SingularityError, AXIS_NAMES, DEFAULT_RANK_REL_TOL,
};
use crate::model::Vehicle;
use crate::sampling::{Sampler, Sampling};

/// Samples evaluated per parallel chunk (the unit of progress reporting and of the memory held
/// for streaming rows).
pub const CHUNK: usize = 4096;

/// Largest sample count accepted with Latin hypercube sampling (its permutation tables hold
/// `samples × joints` 32-bit integers); use Sobol for more.
pub const MAX_LHS_SAMPLES: usize = 2_000_000;

/// Default number of joint configurations sampled (`[static] samples` in study files,
/// `tcm --samples`): the singular fraction then has a standard error of at most 1.6 %, and one
/// case costs about 30 ms (one SVD of `T` per sample).
pub const DEFAULT_SAMPLES: usize = 1000;

/// Default threshold on the scaled σ_min below which `T` counts as (near-)singular.
pub const DEFAULT_THRESHOLD: f64 = 0.02;

/// Default design of experiments in joint space.
pub const DEFAULT_SAMPLING: Sampling = Sampling::Sobol;

/// Default number of lowest-σ_min configurations kept (`tcm --worst`).
pub const DEFAULT_WORST: usize = 10;

/// Quantile levels reported for σ_min and κ.
pub const QUANTILES: [f64; 7] = [0.01, 0.05, 0.10, 0.25, 0.50, 0.75, 0.95];

/// Errors of the static analysis (bad settings or a design the metrics cannot score).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StaticError {
    /// A setting is out of range.
    #[error("static analysis: `{key}` {message}")]
    Setting {
        /// The setting's key (as in study files: `samples`, `threshold`, …).
        key: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The design cannot be scored (e.g. it has no thrusters).
    #[error("static analysis of design `{design}`: {source}")]
    Metrics {
        /// Design name.
        design: String,
        /// The metric error.
        #[source]
        source: SingularityError,
    },
    /// The row sink (e.g. a CSV writer) failed.
    #[error("static analysis: writing rows: {0}")]
    Sink(String),
    /// The local thread pool could not be built.
    #[error("static analysis: thread pool: {0}")]
    Threads(String),
}

/// Settings of a static analysis. [`Default`] gives every setting its documented default;
/// the `[static]` table of study files and the `tcm` command start from it.
#[derive(Clone, Debug, PartialEq)]
pub struct StaticSpec {
    /// Number of joint configurations sampled (≥ 1; default [`DEFAULT_SAMPLES`]).
    pub samples: usize,
    /// Seed of the sampler (default 0).
    pub seed: u64,
    /// Threshold on the scaled σ_min (dimensionless, N per N) below which `T` counts as
    /// singular (≥ 0; default [`DEFAULT_THRESHOLD`]).
    pub threshold: f64,
    /// Design of experiments in joint space (default [`DEFAULT_SAMPLING`]).
    pub sampling: Sampling,
    /// Characteristic length `L` [m] dividing the moment rows (> 0); `None` (the default):
    /// half the vehicle length.
    pub char_length: Option<f64>,
    /// Relative rank tolerance (≥ 0; default [`DEFAULT_RANK_REL_TOL`]).
    pub rank_rel_tol: f64,
    /// How many lowest-σ_min configurations to keep (default [`DEFAULT_WORST`]).
    pub worst: usize,
}

impl Default for StaticSpec {
    fn default() -> Self {
        Self {
            samples: DEFAULT_SAMPLES,
            seed: 0,
            threshold: DEFAULT_THRESHOLD,
            sampling: DEFAULT_SAMPLING,
            char_length: None,
            rank_rel_tol: DEFAULT_RANK_REL_TOL,
            worst: DEFAULT_WORST,
        }
    }
}

impl StaticSpec {
    /// Check the settings; the error names the key that is wrong.
    pub fn validate(&self) -> Result<(), StaticError> {
        let bad = |key, message: String| Err(StaticError::Setting { key, message });
        if self.samples == 0 {
            return bad("samples", "must be >= 1".into());
        }
        if self.sampling == Sampling::Lhs && self.samples > MAX_LHS_SAMPLES {
            return bad(
                "samples",
                format!(
                    "at most {MAX_LHS_SAMPLES} with lhs sampling (use sobol), got {}",
                    self.samples
                ),
            );
        }
        if !(self.threshold.is_finite() && self.threshold >= 0.0) {
            return bad(
                "threshold",
                format!("must be finite and >= 0, got {}", self.threshold),
            );
        }
        if let Some(l) = self.char_length {
            if !(l.is_finite() && l > 0.0) {
                return bad(
                    "char_length",
                    format!("must be finite and > 0 (m), got {l}"),
                );
            }
        }
        if !(self.rank_rel_tol.is_finite() && self.rank_rel_tol >= 0.0) {
            return bad(
                "rank_rel_tol",
                format!("must be finite and >= 0, got {}", self.rank_rel_tol),
            );
        }
        Ok(())
    }

    /// The characteristic length used for `vehicle` [m].
    pub fn char_length_for(&self, vehicle: &Vehicle) -> f64 {
        self.char_length
            .unwrap_or_else(|| vehicle.characteristic_length())
    }
}

/// The metrics of one joint configuration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleEval {
    /// Sample index (0-based).
    pub index: usize,
    /// Joint angles [rad].
    pub q: Vec<f64>,
    /// Smallest singular value of the scaled `T_L` (N per N).
    pub sigma_min: f64,
    /// Condition number σ_max/σ_min (`inf` when rank-deficient; JSON `null`).
    pub kappa: f64,
    /// Numerical rank of `T_L`.
    pub rank: usize,
    /// Dominant axis of the weakest wrench direction when σ_min is below the threshold or the
    /// rank is below 6 (`surge` … `yaw`); `None` otherwise.
    pub lost_axis: Option<&'static str>,
}

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

/// How often one wrench axis is the lost (weakest) direction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisCount {
    /// Axis label (`surge`, `sway`, `heave`, `roll`, `pitch`, `yaw`).
    pub axis: &'static str,
    /// Number of samples whose lost direction is dominated by this axis.
    pub count: usize,
    /// `count / samples`.
    pub fraction: f64,
}

/// Result of [`analyse`] (written as `summary.json` by `usm-study tcm`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StaticSummary {
    /// Design name.
    pub design: String,
    /// Joint names, in order.
    pub joints: Vec<String>,
    /// Number of thrusters.
    pub thrusters: usize,
    /// Number of samples.
    pub samples: usize,
    /// Sampler seed.
    pub seed: u64,
    /// Sampling method.
    pub sampling: String,
    /// σ_min threshold.
    pub threshold: f64,
    /// Characteristic length used [m].
    pub char_length: f64,
    /// Relative rank tolerance used.
    pub rank_rel_tol: f64,
    /// Fraction of samples with σ_min below the threshold ("how often T is singular").
    pub singular_fraction: f64,
    /// Fraction of samples with rank < 6.
    pub rank_deficient_fraction: f64,
    /// Distribution of σ_min.
    pub sigma_min: Distribution,
    /// Distribution of κ.
    pub kappa: Distribution,
    /// The lowest-σ_min samples, ascending (ties by index).
    pub worst: Vec<SampleEval>,
    /// Lost-direction counts per axis, in axis order.
    pub lost_axes: Vec<AxisCount>,
    /// The straight configuration `q = 0`, for reference.
    pub straight: SampleEval,
}

impl StaticSummary {
    /// The value of σ_min at quantile level `p` if it is one of [`QUANTILES`].
    pub fn sigma_min_quantile(&self, p: f64) -> Option<f64> {
        self.sigma_min
            .quantiles
            .iter()
            .find(|(l, _)| *l == p)
            .map(|(_, v)| *v)
    }
}

/// Per-worker scratch: kinematics workspace and `T`.
struct Scratch {
    ws: KinWorkspace,
    t: Matrix6xX<f64>,
    u: Vec<f64>,
    q: Vec<f64>,
}

impl Scratch {
    fn new(v: &Vehicle) -> Self {
        Self {
            ws: KinWorkspace::new(v),
            t: Matrix6xX::zeros(v.n_thrusters()),
            u: vec![0.0; v.n_joints()],
            q: vec![0.0; v.n_joints()],
        }
    }
}

/// Settings resolved for one vehicle.
struct Eval<'a> {
    v: &'a Vehicle,
    l: f64,
    tol: f64,
    threshold: f64,
}

impl Eval<'_> {
    /// Metrics at `q` (the scratch's `q`).
    fn at(&self, s: &mut Scratch, index: usize) -> Result<SampleEval, StaticError> {
        forward_kinematics(self.v, &s.q, &mut s.ws);
        thruster_matrix(self.v, &s.ws, &mut s.t);
        let m = tcm_svd_metrics(&s.t, self.l, self.tol).map_err(|source| StaticError::Metrics {
            design: self.v.name.clone(),
            source,
        })?;
        let lost_axis = if let Some(d) = m.lost_directions.first() {
            Some(d.dominant_axis)
        } else if m.sigma_min < self.threshold {
            Some(weakest_axis(&s.t, self.l))
        } else {
            None
        };
        Ok(SampleEval {
            index,
            q: s.q.clone(),
            sigma_min: m.sigma_min,
            kappa: m.condition_number,
            rank: m.rank,
            lost_axis,
        })
    }
}

/// Dominant axis of the weakest direction of `T_L` (smallest eigenvector of `T_L T_Lᵀ`).
fn weakest_axis(t: &Matrix6xX<f64>, l: f64) -> &'static str {
    let tl = scale_moment_rows(t, l);
    let g: Matrix6<f64> = &tl * tl.transpose();
    let eig = g.symmetric_eigen();
    let k = eig.eigenvalues.imin();
    let (imax, _) = eig.eigenvectors.column(k).iamax_full();
    AXIS_NAMES[imax]
}

fn map_joint(v: &Vehicle, u: &[f64], q: &mut [f64]) {
    for ((qk, uk), j) in q.iter_mut().zip(u).zip(&v.joints) {
        *qk = j.min + uk * (j.max - j.min);
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
    values.sort_by(f64::total_cmp);
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

/// Static TCM analysis of `vehicle` (SPEC §6).
///
/// Samples `spec.samples` joint configurations uniformly within the joint limits, evaluates
/// the scaled singularity metrics of `T(q)` for each, hands every sample to `sink` in index
/// order, reports progress (samples done) through `progress`, and returns the summary.
/// `threads`: 1 evaluates inline (no thread pool: use this inside an outer parallel loop),
/// 0 uses all cores, `k` a local pool of `k` threads. The result does not depend on `threads`.
pub fn analyse(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    threads: usize,
    sink: &mut dyn FnMut(&SampleEval) -> Result<(), String>,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<StaticSummary, StaticError> {
    spec.validate()?;
    let l = spec.char_length_for(vehicle);
    if !(l.is_finite() && l > 0.0) {
        return Err(StaticError::Setting {
            key: "char_length",
            message: format!("the vehicle's half-length {l} m is not usable; give char_length"),
        });
    }
    let sampler = Sampler::new(spec.sampling, spec.samples, vehicle.n_joints(), spec.seed)
        .map_err(|message| StaticError::Setting {
            key: "sampling",
            message,
        })?;
    let eval = Eval {
        v: vehicle,
        l,
        tol: spec.rank_rel_tol,
        threshold: spec.threshold,
    };
    let pool = local_pool(threads)?;
    let run_chunk = |range: std::ops::Range<usize>| -> Vec<Result<SampleEval, StaticError>> {
        let one = |s: &mut Scratch, i: usize| {
            sampler.point(i, &mut s.u);
            let u = std::mem::take(&mut s.u);
            map_joint(vehicle, &u, &mut s.q);
            s.u = u;
            eval.at(s, i)
        };
        match &pool {
            None => {
                let mut s = Scratch::new(vehicle);
                range.map(|i| one(&mut s, i)).collect()
            }
            Some(pool) => pool.install(|| {
                range
                    .into_par_iter()
                    .map_init(|| Scratch::new(vehicle), |s, i| one(s, i))
                    .collect()
            }),
        }
    };
    let mut tally = Tally::new(spec);
    let mut start = 0;
    while start < spec.samples {
        let end = (start + CHUNK).min(spec.samples);
        for r in run_chunk(start..end) {
            tally.add(r?, sink)?;
        }
        start = end;
        progress(start);
    }
    let straight = eval.at(&mut Scratch::new(vehicle), 0)?;
    Ok(tally.summary(vehicle, spec, l, straight))
}

/// A local pool of `threads` workers (0: all cores), or none for 1 (inline evaluation).
fn local_pool(threads: usize) -> Result<Option<rayon::ThreadPool>, StaticError> {
    if threads == 1 {
        return Ok(None);
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map(Some)
        .map_err(|e| StaticError::Threads(e.to_string()))
}

/// The running aggregates of [`analyse`], fed in sample-index order.
struct Tally {
    threshold: f64,
    keep: usize,
    sigmas: Vec<f64>,
    kappas: Vec<f64>,
    worst: Vec<SampleEval>,
    counts: [usize; 6],
    below: usize,
    deficient: usize,
}

impl Tally {
    fn new(spec: &StaticSpec) -> Self {
        Self {
            threshold: spec.threshold,
            keep: spec.worst,
            sigmas: Vec::with_capacity(spec.samples),
            kappas: Vec::with_capacity(spec.samples),
            worst: Vec::new(),
            counts: [0; 6],
            below: 0,
            deficient: 0,
        }
    }

    /// Count sample `e` and hand it to `sink`.
    fn add(
        &mut self,
        e: SampleEval,
        sink: &mut dyn FnMut(&SampleEval) -> Result<(), String>,
    ) -> Result<(), StaticError> {
        self.sigmas.push(e.sigma_min);
        self.kappas.push(e.kappa);
        // NaN counts as singular.
        if e.sigma_min.is_nan() || e.sigma_min < self.threshold {
            self.below += 1;
        }
        if e.rank < 6 {
            self.deficient += 1;
        }
        if let Some(a) = e.lost_axis {
            if let Some(k) = AXIS_NAMES.iter().position(|n| *n == a) {
                self.counts[k] += 1;
            }
        }
        sink(&e).map_err(StaticError::Sink)?;
        keep_worst(&mut self.worst, e, self.keep);
        Ok(())
    }

    fn summary(
        self,
        vehicle: &Vehicle,
        spec: &StaticSpec,
        l: f64,
        straight: SampleEval,
    ) -> StaticSummary {
        let n = spec.samples as f64;
        StaticSummary {
            design: vehicle.name.clone(),
            joints: vehicle.joints.iter().map(|j| j.name.clone()).collect(),
            thrusters: vehicle.n_thrusters(),
            samples: spec.samples,
            seed: spec.seed,
            sampling: spec.sampling.to_string(),
            threshold: spec.threshold,
            char_length: l,
            rank_rel_tol: spec.rank_rel_tol,
            singular_fraction: self.below as f64 / n,
            rank_deficient_fraction: self.deficient as f64 / n,
            sigma_min: distribution(self.sigmas),
            kappa: distribution(self.kappas),
            worst: self.worst,
            lost_axes: AXIS_NAMES
                .iter()
                .zip(self.counts)
                .map(|(axis, count)| AxisCount {
                    axis,
                    count,
                    fraction: count as f64 / n,
                })
                .collect(),
            straight,
        }
    }
}

/// Keep the `k` lowest-σ_min samples, ascending, ties by index (NaN counts as lowest).
fn keep_worst(worst: &mut Vec<SampleEval>, e: SampleEval, k: usize) {
    if k == 0 {
        return;
    }
    let key = |s: &SampleEval| {
        if s.sigma_min.is_nan() {
            f64::NEG_INFINITY
        } else {
            s.sigma_min
        }
    };
    let pos = worst.partition_point(|w| {
        key(w)
            .total_cmp(&key(&e))
            .then(w.index.cmp(&e.index))
            .is_lt()
    });
    if pos < k {
        worst.insert(pos, e);
        worst.truncate(k);
    }
}

/// σ_min over a 2-D slice of joint space: joints `i` and `j` on a `resolution × resolution`
/// grid within their limits, every other joint at 0.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SliceGrid {
    /// Index of the joint along x.
    pub joint_x: usize,
    /// Index of the joint along y.
    pub joint_y: usize,
    /// Grid angles of joint x [rad].
    pub x: Vec<f64>,
    /// Grid angles of joint y [rad].
    pub y: Vec<f64>,
    /// σ_min, row-major by y: `sigma_min[b * x.len() + a]` at `(x[a], y[b])`.
    pub sigma_min: Vec<f64>,
}

fn linspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![0.5 * (lo + hi)];
    }
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// σ_min on a grid over joints `i` and `j` (others 0); see [`SliceGrid`]. Errors if a joint
/// index is out of range or equal.
pub fn slice_grid(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    i: usize,
    j: usize,
    resolution: usize,
    threads: usize,
) -> Result<SliceGrid, StaticError> {
    let n = vehicle.n_joints();
    if i >= n || j >= n || i == j {
        return Err(StaticError::Setting {
            key: "slice",
            message: format!("needs two different joint indices in 0..{n}, got {i},{j}"),
        });
    }
    let eval = Eval {
        v: vehicle,
        l: spec.char_length_for(vehicle),
        tol: spec.rank_rel_tol,
        threshold: spec.threshold,
    };
    let res = resolution.clamp(2, 1000);
    let (ji, jj) = (&vehicle.joints[i], &vehicle.joints[j]);
    let x = linspace(ji.min, ji.max, res);
    let y = linspace(jj.min, jj.max, res);
    let cell = |s: &mut Scratch, k: usize| {
        s.q.iter_mut().for_each(|q| *q = 0.0);
        s.q[i] = x[k % res];
        s.q[j] = y[k / res];
        eval.at(s, k).map(|e| e.sigma_min)
    };
    let compute = || -> Result<Vec<f64>, StaticError> {
        if threads == 1 {
            let mut s = Scratch::new(vehicle);
            (0..res * res).map(|k| cell(&mut s, k)).collect()
        } else {
            (0..res * res)
                .into_par_iter()
                .map_init(|| Scratch::new(vehicle), |s, k| cell(s, k))
                .collect()
        }
    };
    let sigma_min = match local_pool(threads)? {
        None => compute()?,
        Some(pool) => pool.install(compute)?,
    };
    Ok(SliceGrid {
        joint_x: i,
        joint_y: j,
        x,
        y,
        sigma_min,
    })
}

/// The two joints whose bending most restores the TCM: among the yaw joints (axis along z;
/// all joints when fewer than two are yaw), the two with the largest mean σ_min when swept
/// alone over their range (others 0). Ties go to the lower index. `None` with fewer than two
/// joints.
pub fn influential_joints(
    vehicle: &Vehicle,
    spec: &StaticSpec,
) -> Result<Option<(usize, usize)>, StaticError> {
    let n = vehicle.n_joints();
    if n < 2 {
        return Ok(None);
    }
    let yaw: Vec<usize> = (0..n)
        .filter(|&k| vehicle.joints[k].axis.z.abs() > 0.9)
        .collect();
    let cands: Vec<usize> = if yaw.len() >= 2 {
        yaw
    } else {
        (0..n).collect()
    };
    let eval = Eval {
        v: vehicle,
        l: spec.char_length_for(vehicle),
        tol: spec.rank_rel_tol,
        threshold: spec.threshold,
    };
    let mut s = Scratch::new(vehicle);
    let mut scores = Vec::new();
    for &k in &cands {
        let j = &vehicle.joints[k];
        let mut sum = 0.0;
        for a in linspace(j.min, j.max, 21) {
            s.q.iter_mut().for_each(|q| *q = 0.0);
            s.q[k] = a;
            sum += eval.at(&mut s, 0)?.sigma_min;
        }
        scores.push((k, sum));
    }
    scores.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let (a, b) = (scores[0].0, scores[1].0);
    Ok(Some((a.min(b), a.max(b))))
}

#[cfg(test)]
#[path = "static_tcm_tests.rs"]
mod tests;

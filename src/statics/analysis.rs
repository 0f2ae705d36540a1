//! Static configuration-space analysis of the thruster configuration matrix (docs/model.md §6):
//! "how often is `T(q)` singular" over a seeded distribution of joint configurations.
//!
//! Joint configurations are drawn uniformly within the joint limits by a
//! [`crate::sampling::Sampler`] (random, Latin hypercube or scrambled Sobol); for each sample
//! `T(q)` ([`crate::kinematics::thruster_matrix`]) is scored by the scaled singularity metrics
//! of [`crate::metrics::singularity`] (moment rows divided by a characteristic length `L`):
//! σ_min and κ of all six rows and of the rows the mode's controller commands
//! ([`StaticSpec::commanded`], [`crate::metrics::singularity::commanded_sigma`]), against the
//! one threshold the trajectory metrics share
//! ([`crate::metrics::singularity::SINGULARITY_THRESHOLD`]).
//!
//! Speed: the design is built once per case and shared; each configuration costs one forward
//! kinematics pass and two small allocation-free eigenvalue problems (the Gram matrix of
//! `S·T_L`); workers evaluate batches into preallocated
//! buffers.
//!
//! Determinism: sample `i` is a pure function of `(seed, i)` (and `n` for LHS); samples are
//! evaluated in parallel in chunks and aggregated strictly in index order, so every number of
//! the [`StaticSummary`] — including means — is bit-identical for any thread count.
//!
//! Memory: per-sample rows are handed to a caller-supplied sink in index order (as borrowed
//! slices, one chunk of [`CHUNK`] samples at a time with threads, one by one without); the
//! summary keeps σ_min and κ, full and commanded, of every sample for exact quantiles (32 bytes
//! per sample) and the [`StaticSpec::worst`] lowest-σ_min configurations.

use rayon::prelude::*;
use serde::Serialize;

use super::eval::{local_pool, map_joint, Eval, Scratch};
use crate::metrics::singularity::{
    CommandedDofs, SingularityError, AXIS_NAMES, DEFAULT_RANK_REL_TOL, SINGULARITY_THRESHOLD,
};
use crate::model::Vehicle;
use crate::sampling::{Sampler, SamplerError, Sampling};
use crate::scenario::Mode;

use super::dist::{distribution, Distribution};
use super::eval::SampleMetrics;

/// Samples evaluated per parallel chunk (the unit of progress reporting and of the memory held
/// for streaming rows).
pub const CHUNK: usize = 16384;

/// Samples per worker batch within a chunk (one scratch per batch).
const BATCH: usize = 256;

/// Largest sample count accepted with Latin hypercube sampling (its permutation tables hold
/// `samples × joints` 32-bit integers); use Sobol for more.
pub const MAX_LHS_SAMPLES: usize = 2_000_000;

/// Default number of joint configurations sampled (`[static] samples` in study files,
/// `tcm --samples`): the singular fraction then has a standard error of at most 1.6 %, and one
/// case costs about 1–2 ms.
pub const DEFAULT_SAMPLES: usize = 1000;

/// Default threshold on the scaled σ_min below which `T` counts as (near-)singular: the one
/// shared with the trajectory metrics, [`SINGULARITY_THRESHOLD`].
pub const DEFAULT_THRESHOLD: f64 = SINGULARITY_THRESHOLD;

/// Default mode whose commanded axes are scored ([`StaticSpec::mode`]).
pub const DEFAULT_MODE: Mode = Mode::Transport;

/// Default design of experiments in joint space.
pub const DEFAULT_SAMPLING: Sampling = Sampling::Sobol;

/// Default number of lowest-σ_min configurations kept (`tcm --worst`).
pub const DEFAULT_WORST: usize = 10;

/// The error a row or text sink stops an analysis with: the sink's own error (an I/O error,
/// a deadline passed, …), kept as the cause of [`StaticError::Sink`].
pub type SinkError = Box<dyn std::error::Error + Send + Sync>;

/// Errors of the static analysis (bad settings or a design the metrics cannot score).
#[derive(Debug, thiserror::Error)]
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
    /// The sampler cannot cover the joint space (too many joints for Sobol, too many samples).
    #[error("static analysis: `sampling` {0}")]
    Sampler(#[source] SamplerError),
    /// The row sink (e.g. a CSV writer) failed.
    #[error("static analysis: writing rows: {0}")]
    Sink(#[source] SinkError),
    /// The local thread pool could not be built.
    #[error("static analysis: thread pool: {0}")]
    Threads(#[source] rayon::ThreadPoolBuildError),
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
    /// The closed-loop mode whose commanded axes are scored (default [`DEFAULT_MODE`]).
    pub mode: Mode,
    /// The base axes that mode's controller commands, the rows of `S·T_L` (default: the
    /// mode's default controller, [`Mode::default_commanded_dofs`]).
    pub commanded: CommandedDofs,
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
            mode: DEFAULT_MODE,
            commanded: DEFAULT_MODE.default_commanded_dofs(),
        }
    }
}

impl StaticSpec {
    /// Score the base axes `mode`'s default controller commands: sets [`StaticSpec::mode`] and
    /// [`StaticSpec::commanded`] together (the `tcm` command's `--mode`).
    pub fn for_mode(self, mode: Mode) -> Self {
        Self {
            mode,
            commanded: mode.default_commanded_dofs(),
            ..self
        }
    }

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

/// One joint configuration and its metrics (the worst samples and the straight configuration
/// of a [`StaticSummary`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleEval {
    /// Sample index (0-based).
    pub index: usize,
    /// Joint angles [rad].
    pub q: Vec<f64>,
    /// The metrics.
    #[serde(flatten)]
    pub metrics: SampleMetrics,
}

/// The consumer of the per-sample rows of [`analyse`], called in index order with the
/// sample's index, joint angles [rad] and metrics; an `Err` stops the analysis.
pub type RowSink<'a> = dyn FnMut(usize, &[f64], &SampleMetrics) -> Result<(), SinkError> + 'a;

/// Formats one sample (index, joint angles [rad], metrics) as text appended to the buffer:
/// run by the workers of [`analyse_text`], so it must not depend on other samples.
pub type RowText = dyn Fn(usize, &[f64], &SampleMetrics, &mut String) + Sync;

/// Where the samples of an analysis go: row by row to a sink on the calling thread, or
/// formatted by the workers and handed over as text, in index order.
enum Output<'a, 'b> {
    Rows(&'a mut RowSink<'b>),
    Text(&'a RowText, &'a mut TextSink<'b>, &'a mut RowSink<'b>),
}

impl<'a> Output<'a, '_> {
    /// The row formatter run by the workers, if the rows go out as text.
    fn format(&self) -> Option<&'a RowText> {
        match self {
            Output::Text(f, _, _) => Some(*f),
            Output::Rows(_) => None,
        }
    }

    /// One sample to the row sink.
    fn row(&mut self, index: usize, q: &[f64], m: &SampleMetrics) -> Result<(), StaticError> {
        let (Output::Rows(sink) | Output::Text(_, _, sink)) = self;
        sink(index, q, m).map_err(StaticError::Sink)
    }

    /// Formatted rows to the text sink (none without one).
    fn text(&mut self, text: &str) -> Result<(), StaticError> {
        match self {
            Output::Text(_, write, _) => write(text).map_err(StaticError::Sink),
            Output::Rows(_) => Ok(()),
        }
    }
}

/// The consumer of [`analyse_text`]'s formatted rows, in index order; an `Err` stops the
/// analysis.
pub type TextSink<'a> = dyn FnMut(&str) -> Result<(), SinkError> + 'a;

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
    /// σ_min threshold (N per N), shared by the full and the commanded figures.
    pub threshold: f64,
    /// The mode whose commanded axes are scored (`transport`, `work`).
    pub mode: String,
    /// The commanded axes (`surge+sway+heave+pitch+yaw`).
    pub commanded_axes: String,
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
    /// Fraction of samples with the commanded σ_min below the threshold: how often the
    /// controller loses authority over an axis it commands.
    pub singular_fraction_commanded: f64,
    /// Fraction of samples whose commanded rows `S·T_L` are rank-deficient.
    pub rank_deficient_fraction_commanded: f64,
    /// Distribution of the commanded σ_min.
    pub sigma_min_commanded: Distribution,
    /// Distribution of the commanded κ.
    pub kappa_commanded: Distribution,
    /// The lowest-σ_min samples, ascending (ties by index).
    pub worst: Vec<SampleEval>,
    /// Lost-direction counts per axis, in axis order.
    pub lost_axes: Vec<AxisCount>,
    /// The straight configuration `q = 0`, for reference.
    pub straight: SampleEval,
}

/// Static TCM analysis of `vehicle` (docs/model.md §6).
///
/// Samples `spec.samples` joint configurations uniformly within the joint limits, evaluates
/// the scaled singularity metrics of `T(q)` for each (all six rows and the commanded ones),
/// hands every sample to `sink` in index order, reports progress (samples done) through
/// `progress`, and returns the summary.
/// `threads`: 1 evaluates inline (no thread pool, nothing allocated per sample: use this inside
/// an outer parallel loop), 0 uses all cores, `k` a local pool of `k` threads evaluating
/// batches of a chunk into preallocated buffers. The result does not depend on `threads`.
pub fn analyse(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    threads: usize,
    sink: &mut RowSink,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<StaticSummary, StaticError> {
    analyse_with(vehicle, spec, threads, Output::Rows(sink), progress)
}

/// [`analyse`] with the rows also formatted as text by `format` on the workers (a sample's
/// text does not depend on the others) and handed to `write` in index order, chunk by chunk:
/// with several threads the formatting is parallel too and the calling thread only writes
/// (and calls `sink`, which should be cheap). Same result and the same text for any
/// `threads`.
pub fn analyse_text(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    threads: usize,
    format: &RowText,
    write: &mut TextSink,
    sink: &mut RowSink,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<StaticSummary, StaticError> {
    analyse_with(
        vehicle,
        spec,
        threads,
        Output::Text(format, write, sink),
        progress,
    )
}

fn analyse_with(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    threads: usize,
    mut out: Output,
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
        .map_err(StaticError::Sampler)?;
    let mut scratch = Scratch::new(vehicle);
    let eval = evaluator(vehicle, spec, l, &mut scratch)?;
    scratch.q.fill(0.0);
    let straight = SampleEval {
        index: 0,
        q: scratch.q.clone(),
        metrics: eval.at(&mut scratch),
    };
    let mut tally = Tally::new(spec);
    let format = out.format();
    match pool(threads)? {
        None => {
            let s = &mut scratch;
            let mut text = String::new();
            for i in 0..spec.samples {
                sampler.point(i, &mut s.u);
                map_joint(vehicle, &s.u, &mut s.q);
                let m = eval.at(s);
                tally.add(i, &s.q, m);
                if let Some(f) = format {
                    f(i, &s.q, &m, &mut text);
                }
                out.row(i, &s.q, &m)?;
                if (i + 1) % CHUNK == 0 || i + 1 == spec.samples {
                    out.text(&text)?;
                    text.clear();
                    progress(i + 1);
                }
            }
        }
        Some(pool) => {
            // Two chunk buffers: the workers fill one (metrics, and the rows' text with
            // `analyse_text`) while this thread hands the other's rows, in sample order, to
            // the tally and the output, so the serial part overlaps the parallel evaluation.
            let n = vehicle.n_joints();
            let fill = |start: usize, buf: &mut ChunkView| {
                let ChunkView { qs, ms, texts } = buf;
                pool.install(|| {
                    qs.par_chunks_mut((BATCH * n).max(1))
                        .zip(ms.par_chunks_mut(BATCH))
                        .zip(texts.par_iter_mut())
                        .enumerate()
                        .for_each_init(
                            || Scratch::new(vehicle),
                            |s, (b, ((qb, mb), text))| {
                                text.clear();
                                for (j, m) in mb.iter_mut().enumerate() {
                                    let index = start + b * BATCH + j;
                                    sampler.point(index, &mut s.u);
                                    map_joint(vehicle, &s.u, &mut s.q);
                                    *m = eval.at(s);
                                    qb[j * n..(j + 1) * n].copy_from_slice(&s.q);
                                    if let Some(f) = format {
                                        f(index, &s.q, m, text);
                                    }
                                }
                            },
                        )
                })
            };
            let blank = eval.at(&mut scratch);
            let mut cur = ChunkBuf {
                qs: vec![0.0; CHUNK * n],
                ms: vec![blank; CHUNK],
                texts: vec![String::new(); CHUNK.div_ceil(BATCH)],
            };
            let mut next = cur.clone();
            let mut start = 0;
            let mut len = CHUNK.min(spec.samples);
            fill(0, &mut cur.prefix(len, n));
            while len > 0 {
                let after = start + len;
                let next_len = CHUNK.min(spec.samples - after);
                let mut next_view = next.prefix(next_len, n);
                let handed = std::thread::scope(|scope| {
                    let worker = scope.spawn(|| fill(after, &mut next_view));
                    let handed = hand_over(&mut tally, &mut out, &cur, start, len, n);
                    // A worker panic is a bug: pass it on.
                    if let Err(p) = worker.join() {
                        std::panic::resume_unwind(p);
                    }
                    handed
                });
                handed?;
                progress(after);
                std::mem::swap(&mut cur, &mut next);
                (start, len) = (after, next_len);
            }
        }
    }
    Ok(tally.summary(vehicle, spec, l, straight))
}

/// One chunk's buffers in the parallel path: joint angles (`n` per sample), metrics, and
/// the text of each batch of `BATCH` samples.
#[derive(Clone)]
struct ChunkBuf {
    qs: Vec<f64>,
    ms: Vec<SampleMetrics>,
    texts: Vec<String>,
}

/// Mutable views of the first `len` samples of a [`ChunkBuf`].
struct ChunkView<'a> {
    qs: &'a mut [f64],
    ms: &'a mut [SampleMetrics],
    texts: &'a mut [String],
}

impl ChunkBuf {
    fn prefix(&mut self, len: usize, n: usize) -> ChunkView<'_> {
        ChunkView {
            qs: &mut self.qs[..len * n],
            ms: &mut self.ms[..len],
            texts: &mut self.texts[..len.div_ceil(BATCH)],
        }
    }
}

/// The samples `start..start + len` of a filled chunk to the tally and the output, in order.
fn hand_over(
    tally: &mut Tally,
    out: &mut Output,
    buf: &ChunkBuf,
    start: usize,
    len: usize,
    n: usize,
) -> Result<(), StaticError> {
    for (j, m) in buf.ms[..len].iter().enumerate() {
        let q = &buf.qs[j * n..(j + 1) * n];
        tally.add(start + j, q, *m);
        out.row(start + j, q, m)?;
    }
    for t in &buf.texts[..len.div_ceil(BATCH)] {
        out.text(t)?;
    }
    Ok(())
}

/// A local pool of `threads` workers (0: all cores), or none for 1 (inline evaluation).
pub(super) fn pool(threads: usize) -> Result<Option<rayon::ThreadPool>, StaticError> {
    local_pool(threads).map_err(StaticError::Threads)
}

/// The evaluator of `spec` on `v` with characteristic length `l` [m], its design checked.
pub(super) fn evaluator<'a>(
    v: &'a Vehicle,
    spec: &StaticSpec,
    l: f64,
    scratch: &mut Scratch,
) -> Result<Eval<'a>, StaticError> {
    let eval = Eval::new(v, l, spec.rank_rel_tol, spec.threshold, spec.commanded);
    eval.check(scratch).map_err(|source| StaticError::Metrics {
        design: v.name.clone(),
        source,
    })?;
    Ok(eval)
}

/// Sorted-later samples of one per-sample quantity, full and over the commanded rows.
#[derive(Default)]
struct Pair {
    full: Vec<f64>,
    commanded: Vec<f64>,
}

impl Pair {
    fn with_capacity(n: usize) -> Self {
        Self {
            full: Vec::with_capacity(n),
            commanded: Vec::with_capacity(n),
        }
    }
}

/// The running aggregates of [`analyse`], fed in sample-index order.
struct Tally {
    threshold: f64,
    keep: usize,
    sigmas: Pair,
    kappas: Pair,
    worst: Vec<SampleEval>,
    counts: [usize; 6],
    below: usize,
    below_commanded: usize,
    deficient: usize,
    deficient_commanded: usize,
    k_commanded: usize,
}

/// Whether σ_min counts as singular under `threshold` (NaN does).
fn singular(sigma_min: f64, threshold: f64) -> bool {
    sigma_min.is_nan() || sigma_min < threshold
}

impl Tally {
    fn new(spec: &StaticSpec) -> Self {
        Self {
            threshold: spec.threshold,
            keep: spec.worst,
            sigmas: Pair::with_capacity(spec.samples),
            kappas: Pair::with_capacity(spec.samples),
            worst: Vec::new(),
            counts: [0; 6],
            below: 0,
            below_commanded: 0,
            deficient: 0,
            deficient_commanded: 0,
            k_commanded: spec.commanded.len(),
        }
    }

    /// Count sample `index` at joint angles `q` with metrics `m` and hand it to `sink`.
    fn add(&mut self, index: usize, q: &[f64], m: SampleMetrics) {
        self.sigmas.full.push(m.sigma_min);
        self.kappas.full.push(m.kappa);
        self.sigmas.commanded.push(m.sigma_min_commanded);
        self.kappas.commanded.push(m.kappa_commanded);
        self.below += usize::from(singular(m.sigma_min, self.threshold));
        self.below_commanded += usize::from(singular(m.sigma_min_commanded, self.threshold));
        self.deficient += usize::from(m.rank < 6);
        self.deficient_commanded += usize::from(m.rank_commanded < self.k_commanded);
        if let Some(a) = m.lost_axis {
            if let Some(k) = AXIS_NAMES.iter().position(|n| *n == a) {
                self.counts[k] += 1;
            }
        }
        keep_worst(&mut self.worst, index, q, m, self.keep);
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
            mode: spec.mode.to_string(),
            commanded_axes: spec.commanded.label(),
            char_length: l,
            rank_rel_tol: spec.rank_rel_tol,
            singular_fraction: self.below as f64 / n,
            rank_deficient_fraction: self.deficient as f64 / n,
            sigma_min: distribution(self.sigmas.full),
            kappa: distribution(self.kappas.full),
            singular_fraction_commanded: self.below_commanded as f64 / n,
            rank_deficient_fraction_commanded: self.deficient_commanded as f64 / n,
            sigma_min_commanded: distribution(self.sigmas.commanded),
            kappa_commanded: distribution(self.kappas.commanded),
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

/// Keep the `k` lowest-σ_min samples, ascending, ties by index (NaN counts as lowest); a
/// sample is copied only when it enters the list.
fn keep_worst(worst: &mut Vec<SampleEval>, index: usize, q: &[f64], m: SampleMetrics, k: usize) {
    if k == 0 {
        return;
    }
    let key = |s: f64| if s.is_nan() { f64::NEG_INFINITY } else { s };
    let pos = worst.partition_point(|w| {
        key(w.metrics.sigma_min)
            .total_cmp(&key(m.sigma_min))
            .then(w.index.cmp(&index))
            .is_lt()
    });
    if pos < k {
        let e = SampleEval {
            index,
            q: q.to_vec(),
            metrics: m,
        };
        worst.insert(pos, e);
        worst.truncate(k);
    }
}

#[cfg(test)]
#[path = "analysis_tests.rs"]
mod tests;

//! The per-case tuning hook of a sweep (`[tune]`, `docs/study-format.md`). The tuner itself
//! lives with the optimiser (`crate::optimise::case_tuner`); the sweep engine only knows this
//! interface, handed in by the caller ([`TuningHook`] in `SweepOptions::tuning` and to
//! [`crate::review::finish::finish_report`]), so `study` never imports `optimise`.
//!
//! A tuned case's row carries the tuned values (`tuned.<param>`), the evaluations used
//! (`tune_evaluations`) and whether the tuned point met every `[[tune.constraint]]`
//! (`tune_feasible`), all set by name ([`Tuned::record`]).

use std::fmt;

use crate::evaluate::{Deadline, Metrics};
use crate::study::cases::Resolved;
use crate::study::doe::Case;
use crate::study::error::{InputError, StudyError};
use crate::study::schema::{
    Study, TUNED_PREFIX, TUNE_BOUND_HITS, TUNE_CURVE_PREFIX, TUNE_EVALUATIONS, TUNE_FEASIBLE,
    TUNE_NOISE, TUNE_SUCCESS_SPREAD,
};

/// Why a case could not be tuned (its row is `failed` with reason `tune: …`).
#[derive(Debug, thiserror::Error)]
#[error("tune: {message}")]
pub struct TuneError {
    /// What went wrong.
    pub message: String,
    /// The underlying error, when there is one.
    #[source]
    pub source: Option<Box<dyn std::error::Error + Send + Sync>>,
}

impl TuneError {
    /// A tuning error for `source`, its message kept.
    pub fn from_error(source: impl std::error::Error + Send + Sync + 'static) -> Self {
        TuneError {
            message: source.to_string(),
            source: Some(Box::new(source)),
        }
    }

    /// A tuning error with a message only.
    pub fn msg(message: impl Into<String>) -> Self {
        TuneError {
            message: message.into(),
            source: None,
        }
    }
}

/// A tuned case: its tables at the tuned values and what the tuning found.
#[derive(Clone, Debug)]
pub struct Tuned {
    /// The case's tables at the tuned values (its hash the case's own).
    pub resolved: Resolved,
    /// The tuned values, in `[[tune.param]]` order.
    pub x: Vec<f64>,
    /// Fresh evaluations the tuning used.
    pub evaluations: usize,
    /// Closed-loop runs those evaluations used: one per tuning world of each evaluation, fewer
    /// when a candidate is raced out (`[tune] race`); not a column (racing leaves every
    /// column unchanged).
    pub runs: usize,
    /// Whether the tuned point met every constraint.
    pub feasible: bool,
    /// Relative spread of the best feasible objective across independent tuning starts
    /// (`[tune] starts`; NaN with one start or fewer than two feasible): the tuning noise.
    pub noise: f64,
    /// With `[tune] seeds` ≥ 2: the spread (max − min) over the seeds of the fraction of the
    /// pooled tuning worlds in which each seed's best point meets every constraint; NaN with
    /// one seed.
    pub success_spread: f64,
    /// Tuned parameters on a bound of their box (within 0.1 % of its width).
    pub bound_hits: usize,
    /// Best feasible tuning objective after each fresh evaluation (relative to the start
    /// point's scale; NaN before the first feasible point).
    pub curve: Vec<f64>,
}

impl Tuned {
    /// Write the tuning columns of `study` into `metrics` by name.
    pub fn record(&self, study: &Study, metrics: &mut Metrics) {
        for (c, x) in tuned_columns(study).iter().zip(&self.x) {
            metrics.set(c, *x);
        }
        metrics.set(TUNE_EVALUATIONS, self.evaluations as f64);
        metrics.set(TUNE_FEASIBLE, f64::from(u8::from(self.feasible)));
        metrics.set(TUNE_NOISE, self.noise);
        if !self.success_spread.is_nan() {
            metrics.set(TUNE_SUCCESS_SPREAD, self.success_spread);
        }
        metrics.set(TUNE_BOUND_HITS, self.bound_hits as f64);
        for (k, x) in self.curve.iter().enumerate() {
            metrics.push(format!("{TUNE_CURVE_PREFIX}{k}"), *x);
        }
    }
}

/// The `tuned.<param>` columns of `study`, in `[[tune.param]]` order.
pub fn tuned_columns(study: &Study) -> Vec<String> {
    study
        .tune_columns()
        .into_iter()
        .filter(|c| c.starts_with(TUNED_PREFIX))
        .collect()
}

/// Tunes the cases of one study.
pub trait CaseTuner: Sync {
    /// Tune case `case` (resolved as `r`) within `deadline`: its tables at the tuned values.
    fn tune(
        &self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        deadline: Deadline,
    ) -> Result<Tuned, TuneError>;

    /// Case `r` at tuned values `x` (in `[[tune.param]]` order, as a row records them): the
    /// report's reruns of the best and worst cases.
    fn at(
        &self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        x: &[f64],
    ) -> Result<Resolved, TuneError>;
}

/// The tuner of a study (`None` without `[tune]`); `Err` for a bad `[tune]` section, located.
pub type TunerFactory = fn(&Study) -> Result<Option<Box<dyn CaseTuner>>, InputError>;

/// How a sweep tunes its cases: the factory the caller wires in (the optimiser's tuner).
#[derive(Clone, Copy)]
pub struct TuningHook(pub TunerFactory);

impl TuningHook {
    /// The tuner of `study` (`None` without `[tune]`).
    pub fn tuner(&self, study: &Study) -> Result<Option<Box<dyn CaseTuner>>, InputError> {
        (self.0)(study)
    }
}

impl fmt::Debug for TuningHook {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("TuningHook")
    }
}

/// The tuner of `study` through `hook`; `None` without `[tune]`. A study with `[tune]` but
/// no hook cannot be run as written: refused.
pub fn case_tuner(
    study: &Study,
    hook: Option<TuningHook>,
) -> Result<Option<Box<dyn CaseTuner>>, StudyError> {
    match hook {
        Some(h) => Ok(h.tuner(study)?),
        None if study.tune.is_some() => Err(StudyError::NoTuner),
        None => Ok(None),
    }
}

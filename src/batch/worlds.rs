//! One case in its uncertain worlds and validation variants (issue 22): after the nominal
//! run (at the case's tuned values), the case meets every world of the study's
//! `[uncertainty]` ([`crate::study::uncertainty`], the same worlds for every case) and every
//! `[[validate]]` variant, and its row gains
//!
//! - per tracked metric `m`: `m_mean`, `m_std`, `m_p05`, `m_p95`, `m_worst` over the worlds
//!   (worst by the metric's direction, [`larger_is_better`]); `success_probability`;
//! - per world `k`: `world.<k>.<m>` and `world.<k>.success`, which the final tables move to
//!   `worlds.csv` (the paired data of the ranking, [`super::robust`]);
//! - per variant `v`: `validate.<v>.<objective>`, `validate.<v>.success` and
//!   `validate.<v>.gap` (relative change of the objective from the nominal run).

use crate::evaluate::{
    CaseEnd, CaseInput, CaseResult, Deadline, Evaluator, Metrics, Overrides, Phases, TIMEOUT,
};
use crate::scenario::criteria::Criterion;
use crate::stats::describe::describe;
use crate::study::cases::{overrides_of, Resolved};
use crate::study::directions::{larger_is_better, BY_MAGNITUDE, SUCCESS};
use crate::study::schema::Study;
use crate::study::schema::World;
use rayon::prelude::*;

/// Prefix of the per-world columns of a row (`world.<k>.<metric>`).
pub const WORLD_PREFIX: &str = "world.";
/// Fraction of worlds in which the case met every `[success]` criterion.
pub const SUCCESS_PROBABILITY: &str = "success_probability";
/// Prefix of the validation columns (`validate.<name>.<metric>`).
pub const VALIDATE_PREFIX: &str = "validate.";

/// Per-world column: the first `[success]` criterion the run missed, as its index in
/// [`Criterion::ALL`] (NaN when it met all); `worlds.csv` writes its id.
pub const MISSED: &str = "missed";

/// The index of `c` in [`Criterion::ALL`].
pub(super) fn criterion_index(c: Criterion) -> f64 {
    Criterion::ALL
        .iter()
        .position(|x| *x == c)
        .map_or(f64::NAN, |i| i as f64)
}

/// Evaluate resolved case `r` (case `id`) with `evaluator`: the given phases, with the
/// trajectory when `log`, within `deadline` (the sweep's runs and the worlds' alike).
pub fn evaluate_phases(
    evaluator: &mut Evaluator,
    r: &Resolved,
    id: usize,
    phases: Phases,
    log: bool,
    deadline: Deadline,
) -> CaseResult {
    evaluate_varied(evaluator, r, id, phases, log, deadline, &[])
}

/// [`evaluate_phases`] with `overrides` on top of `r`'s tables (a world, a validation variant,
/// a fault): the evaluator applies them ([`crate::evaluate::overrides`]).
pub fn evaluate_varied(
    evaluator: &mut Evaluator,
    r: &Resolved,
    id: usize,
    phases: Phases,
    log: bool,
    deadline: Deadline,
    overrides: &Overrides,
) -> CaseResult {
    evaluator.evaluate(&CaseInput {
        design: &r.design,
        design_hash: &r.design_hash,
        scenario: &r.scenario,
        overrides,
        seed: r.seed,
        deadline,
        phases,
        trajectory: log,
        label: &format!("case {id} design"),
    })
}

/// Run `r` (closed loop only) with `overrides` on top, with `evaluator`.
fn run(
    evaluator: &mut Evaluator,
    r: &Resolved,
    id: usize,
    deadline: Deadline,
    overrides: &Overrides,
) -> CaseResult {
    let phases = Phases {
        static_analysis: false,
        closed_loop: true,
    };
    evaluate_varied(evaluator, r, id, phases, false, deadline, overrides)
}

/// Whether a run stopped at the case's wall-clock budget.
fn timed_out(res: &CaseResult) -> bool {
    res.end.timed_out()
}

/// The value of `metric` over worlds that is worst for it.
fn worst(metric: &str, xs: &[f64]) -> f64 {
    let finite = xs.iter().copied().filter(|x| x.is_finite());
    if larger_is_better(metric) {
        finite.fold(f64::NAN, f64::min)
    } else if BY_MAGNITUDE.contains(&metric) {
        finite
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(f64::NAN)
    } else {
        finite.fold(f64::NAN, f64::max)
    }
}

/// One case's run in one world.
pub(super) struct WorldRun {
    ok: bool,
    metrics: Metrics,
    missed: f64,
    timeout: bool,
}

/// Why scoring a case in its worlds stopped: its wall-clock budget ran out.
#[derive(Debug, thiserror::Error)]
#[error("{TIMEOUT} in world {world} (the case's wall-clock budget)")]
pub struct WorldTimeout {
    /// The world being run.
    pub world: usize,
}

/// Run resolved case `r` (at its tuned values) in `worlds` of `u`, in world order. The worlds
/// of one case are independent runs: run side by side (a sweep with fewer cases than threads
/// keeps every thread busy), one evaluator per rayon work split (its vehicle cache serves
/// every world of an unchanged design), collected in world order so nothing depends on the
/// thread count. A world whose overrides do not apply counts as unsuccessful with NaN metrics.
pub(super) fn run_worlds(
    u: &crate::study::schema::Uncertainty,
    worlds: &[World],
    id: usize,
    r: &Resolved,
    deadline: Deadline,
) -> Vec<WorldRun> {
    worlds
        .par_iter()
        .map_init(Evaluator::new, |evaluator, w| {
            run_world(evaluator, u, w, id, r, deadline)
        })
        .collect()
}

/// Case `r` in world `w` of `u` (see [`run_worlds`]).
pub(super) fn run_world(
    evaluator: &mut Evaluator,
    u: &crate::study::schema::Uncertainty,
    w: &World,
    id: usize,
    r: &Resolved,
    deadline: Deadline,
) -> WorldRun {
    if deadline.passed() {
        // Past the budget: the remaining worlds are not started (each would build its
        // vehicle before its first deadline check; 100 000 of them overran a 5 s budget by
        // 10 s).
        return WorldRun {
            ok: false,
            metrics: Metrics::new(),
            missed: f64::NAN,
            timeout: true,
        };
    }
    let overrides = overrides_of(
        u.params
            .iter()
            .zip(&w.values)
            .map(|(p, v)| (p.name.as_str(), &p.target, v)),
    );
    let res = run(evaluator, r, id, deadline, &overrides);
    // A world whose overrides do not apply counts as a failure to run (`no_failure`).
    let missed = match res.end {
        CaseEnd::NotApplicable => criterion_index(Criterion::NoFailure),
        ref end => end.missed_criterion().map_or(f64::NAN, criterion_index),
    };
    WorldRun {
        ok: res.success(),
        timeout: timed_out(&res),
        metrics: res.metrics,
        missed,
    }
}

impl WorldRun {
    /// Whether the run stopped at the case's wall-clock budget.
    pub(super) fn timed_out(&self) -> bool {
        self.timeout
    }
}

/// The per-world columns of run `wr` in world `k` (`world.<k>.missed`, `world.<k>.<m>` per
/// tracked metric, `world.<k>.success`), pushed in that order.
pub(super) fn push_world_columns(
    u: &crate::study::schema::Uncertainty,
    k: usize,
    wr: &WorldRun,
    metrics: &mut Metrics,
) {
    metrics.push(format!("{WORLD_PREFIX}{k}.{MISSED}"), wr.missed);
    for name in &u.metrics {
        metrics.push(format!("{WORLD_PREFIX}{k}.{name}"), wr.metrics.value(name));
    }
    metrics.push(
        format!("{WORLD_PREFIX}{k}.{SUCCESS}"),
        f64::from(u8::from(wr.ok)),
    );
}

/// The summaries over worlds (`m_mean`, `m_std`, `m_p05`, `m_p95`, `m_worst` per tracked metric
/// `m` of `u`, from `values[m]` in world order; `success_probability` = `successes` / worlds),
/// each handed to `set` by name. One function for the first worlds and for adaptive ones, so a
/// case that met `n` worlds adaptively has the summaries of a study with `worlds = n`.
pub(super) fn set_world_summaries(
    u: &crate::study::schema::Uncertainty,
    values: &[Vec<f64>],
    successes: usize,
    mut set: impl FnMut(&str, f64),
) {
    let n = values.first().map_or(0, Vec::len);
    for (name, xs) in u.metrics.iter().zip(values) {
        let d = describe(xs);
        for (suffix, x) in [
            ("mean", d.mean),
            ("std", d.std),
            ("p05", d.p05),
            ("p95", d.p95),
            ("worst", worst(name, xs)),
        ] {
            set(&format!("{name}_{suffix}"), x);
        }
    }
    let p = if n == 0 {
        f64::NAN
    } else {
        successes as f64 / n as f64
    };
    set(SUCCESS_PROBABILITY, p);
}

/// Score resolved case `r` (at its tuned values) in `worlds` and the study's validation
/// variants; the columns are added to `metrics` (see the module docs). A world whose
/// overrides do not apply or whose run fails counts as unsuccessful with NaN metrics.
pub fn score_worlds(
    evaluator: &mut Evaluator,
    study: &Study,
    worlds: &[World],
    id: usize,
    r: &Resolved,
    deadline: Deadline,
    metrics: &mut Metrics,
) -> Result<(), WorldTimeout> {
    if let Some(u) = &study.uncertainty {
        let runs = run_worlds(u, worlds, id, r, deadline);
        for (w, wr) in worlds.iter().zip(&runs) {
            if wr.timeout {
                return Err(WorldTimeout { world: w.index });
            }
            push_world_columns(u, w.index, wr, metrics);
        }
        let values: Vec<Vec<f64>> = u
            .metrics
            .iter()
            .map(|name| runs.iter().map(|wr| wr.metrics.value(name)).collect())
            .collect();
        let successes = runs.iter().filter(|wr| wr.ok).count();
        set_world_summaries(u, &values, successes, |name, x| metrics.set(name, x));
    }
    score_variants(evaluator, study, id, r, deadline, metrics)
}

/// The validation columns of `r` (see the module docs).
fn score_variants(
    evaluator: &mut Evaluator,
    study: &Study,
    id: usize,
    r: &Resolved,
    deadline: Deadline,
    metrics: &mut Metrics,
) -> Result<(), WorldTimeout> {
    let objective = study
        .uncertainty
        .as_ref()
        .map(|u| u.objective().to_string())
        .unwrap_or_else(|| crate::study::directions::TRANSPORT_OBJECTIVE.to_string());
    let nominal = metrics.value(&objective);
    for v in &study.validate {
        if deadline.passed() {
            return Err(WorldTimeout { world: usize::MAX });
        }
        let overrides = overrides_of(v.set.iter().map(|(n, t, x)| (n.as_str(), t, x)));
        let res = run(evaluator, r, id, deadline, &overrides);
        if timed_out(&res) {
            return Err(WorldTimeout { world: usize::MAX });
        }
        // A variant whose overrides do not apply: unsuccessful, its objective NaN (no metrics).
        let (ok, x) = (res.success(), res.metrics.value(&objective));
        let col = |m: &str| format!("{VALIDATE_PREFIX}{}.{m}", v.name);
        metrics.set(&col(&objective), x);
        metrics.set(&col(SUCCESS), f64::from(u8::from(ok)));
        metrics.set(&col("gap"), (x - nominal) / nominal.abs());
    }
    Ok(())
}

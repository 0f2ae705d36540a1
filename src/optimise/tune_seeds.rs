//! Independent tuning seeds (`[tune] seeds`, issue 36 item 5): each seed tunes a case afresh in
//! its own tuning worlds ([`tune_worlds_seed`]), and the seeds' best points are then compared in
//! the pooled tuning worlds of every seed ([`compare_in_pooled_worlds`]): the case takes the best
//! there, and the seeds' disagreement — in cost and in the share of worlds meeting every
//! constraint — is the tuning noise the verdict uses (`docs/study-format.md`, `[tune] seeds`).

use super::evaluate::CaseEvaluator;
use super::history::Record;
use super::score::{Score, Scorer};
use super::search::Evaluator as _;
use super::Problem;
use crate::evaluate::Deadline;
use crate::sampling::derive_seed;
use rayon::prelude::*;

/// Seed stream of the tuning worlds (shared by every case: common random numbers), apart from
/// the scoring worlds' stream so that a design is not tuned on the worlds it is scored in.
const TUNE_WORLDS_STREAM: u64 = 0x5455_4e45_574c; // "TUNEWL"

/// Which tuning worlds a tuning problem runs in.
#[derive(Clone, Copy, Debug)]
pub(super) enum WorldsOf {
    /// The nominal world alone (how a tuned case is scored).
    Nominal,
    /// Tuning seed `k`'s worlds.
    Seed(usize),
    /// Every seed's worlds together (the seeds' best points compared).
    Pooled,
}

/// What one tuning seed found.
pub(super) struct SeedResult {
    /// The seed's best point.
    pub best: Record,
    /// Spread of the starts' bests within the seed.
    pub noise: f64,
    /// Best-so-far curve over the seed's evaluations.
    pub curve: Vec<f64>,
    /// Fresh evaluations the seed used.
    pub evaluations: usize,
    /// Tuning-world runs those evaluations used (fewer than evaluations × worlds when raced).
    pub runs: usize,
}

/// Seed stream of tuning seed `k`'s solver seeds (seed 0 keeps the study's).
pub(super) const SEEDS_STREAM: u64 = 0x5345_4544_5353; // "SEEDSS"

/// The seed of tuning seed `k`'s worlds: seed 0 the tuning-worlds stream itself (a one-seed
/// tuning is unchanged), seed `k > 0` a stream derived from it.
pub(super) fn tune_worlds_seed(study_seed: u64, k: usize) -> u64 {
    let base = derive_seed(study_seed, TUNE_WORLDS_STREAM);
    if k == 0 {
        base
    } else {
        derive_seed(base, k as u64)
    }
}

/// The seeds' best points run in the pooled worlds ([`compare_in_pooled_worlds`]).
pub(super) struct Pooled {
    /// The seed whose point the case takes.
    pub pick: usize,
    /// Whether that point meets every constraint in every pooled world.
    pub feasible: bool,
    /// Relative spread of the seeds' pooled objectives (`tune_noise`).
    pub noise: f64,
    /// Spread of the share of pooled worlds each seed's point meets every constraint in
    /// (`tune_success_spread`).
    pub success_spread: f64,
    /// Runs used (one evaluation per seed).
    pub evaluations: usize,
}

/// Run each seed's best point in `pooled` (the pooled tuning worlds of every seed) as case
/// `case_id` within `deadline`, and take the one that is feasible there with the lowest
/// unnormalised objective (else the least infeasible; ties to the lower seed).
pub(super) fn compare_in_pooled_worlds(
    pooled: &Problem,
    case_id: usize,
    deadline: Deadline,
    seeds: &[SeedResult],
) -> Pooled {
    let ev = CaseEvaluator::new(pooled).for_case(case_id, deadline);
    let evals: Vec<_> = seeds
        .par_iter()
        .with_max_len(1)
        .map(|s| ev.evaluate(&s.best.x))
        .collect();
    let scorer = Scorer::new(
        &pooled.spec.objective,
        &pooled.spec.constraints,
        ev.metrics(),
        &evals[0].metrics,
    );
    let scored: Vec<(Score, f64, f64)> = evals
        .iter()
        .map(|e| {
            let mut score = scorer.score(&e.metrics);
            if e.failure.is_some() {
                score.feasible = false;
                score.violation = score.violation.max(1.0);
            }
            let raw = raw_metrics_objective(&scorer, &e.metrics);
            let met = e
                .metrics
                .iter()
                .filter(|m| {
                    (0..scorer.constraints.len()).all(|k| scorer.constraint_violation(k, m) == 0.0)
                })
                .count();
            (score, raw, met as f64 / e.metrics.len().max(1) as f64)
        })
        .collect();
    let mut pick = 0;
    for i in 1..scored.len() {
        let (a, b) = (&scored[i], &scored[pick]);
        let better = match (a.0.feasible, b.0.feasible) {
            (true, true) => a.1 < b.1,
            _ => a.0.better_than(&b.0),
        };
        if better {
            pick = i;
        }
    }
    let costs: Vec<f64> = scored.iter().map(|s| s.1).collect();
    let (lo, hi) = scored
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x.2), b.max(x.2))
        });
    Pooled {
        pick,
        feasible: scored[pick].0.feasible,
        noise: relative_spread(&costs),
        success_spread: hi - lo,
        evaluations: evals.len(),
    }
}

/// The unnormalised objective `Σ w_i · m_i` of one evaluation's metrics (each term's metric
/// averaged over the scenarios, without the start point's normalisation).
pub(super) fn raw_metrics_objective(scorer: &Scorer, metrics: &[Vec<f64>]) -> f64 {
    scorer
        .objective
        .terms
        .iter()
        .zip(&scorer.term_columns)
        .map(|(t, &c)| t.weight * super::score::mean_of(metrics, c))
        .sum()
}

/// Relative spread `(max − min) / |min|` of the finite values (NaN with fewer than two).
pub(super) fn relative_spread(xs: &[f64]) -> f64 {
    let f: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    if f.len() < 2 {
        return f64::NAN;
    }
    let (lo, hi) = f
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    (hi - lo) / lo.abs()
}

//! The argmin wiring: one cost function ([`Search`]) over the normalised unit box for every
//! solver, evaluating points through an [`Evaluator`] — the closed-loop cases of a problem
//! file, or an analytic function in the tests, through the same code.
//!
//! - Points are projected onto the unit box and mapped to physical values
//!   ([`Space`]); the cost is [`Score::cost`] plus `PENALTY · (distance moved)²`.
//! - `bulk_cost` (particle swarm, finite differences) evaluates a batch on the run's own rayon
//!   pool (`--jobs`) and records it in the batch's order, so the history does not depend on
//!   the number of threads.
//! - A point seen before in this run is served from memory (recorded with `repeat`, not
//!   simulated again) but counts against `max_evals` like any other: a solver that keeps
//!   proposing the same points (restarts of a converged search) still ends. Points simulated by
//!   an earlier, interrupted run of the same problem (the journal) are served from memory too
//!   and count as they did then, so a resumed run replays the interrupted one exactly and then
//!   carries on.
//! - The evaluation budget is enforced inside the cost function: once `max_evals` points are
//!   recorded, it returns an error that ends the argmin run; the history decides the best. A
//!   batch that does not fit is evaluated up to the budget before the error.
//! - An argmin observer tracks the iteration each evaluation belongs to (0: the solver's
//!   initialisation) for the history.

use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Error, Executor, Gradient, State, KV};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use argmin::solver::quasinewton::LBFGS;
use rand::SeedableRng;
use rayon::prelude::*;

use super::bayes::{latin_hypercube, propose, Observation};
use super::cmaes::{default_lambda, Cmaes};
use super::history::{Evaluation, Journal, JournalError, Record};
use super::problem::{Method, SolverSettings};
use super::score::{Score, Scorer};
use crate::sampling::{derive_seed, rng_for};
use crate::study::tune_space::Space;

/// Weight of the squared distance outside the unit box added to the cost.
pub const PENALTY: f64 = 1.0;

/// Finite-difference step of the L-BFGS gradients, in normalised coordinates.
pub const FD_STEP: f64 = 1e-4;

/// What the optimiser evaluates: physical parameter values → metrics per scenario.
pub trait Evaluator: Sync {
    /// The metric names (columns of [`Evaluation::metrics`]).
    fn metrics(&self) -> &[String];
    /// Evaluate the point `x` (physical values, in parameter order).
    fn evaluate(&self, x: &[f64]) -> Evaluation;
    /// Evaluate `x` scenario by scenario in order, stopping after the first scenario at which
    /// `stop` (given the rows so far) is true: the evaluation then holds only the rows run
    /// (racing, [`Search::racing`]). The default runs every scenario.
    fn evaluate_until(&self, x: &[f64], stop: &(dyn Fn(&[Vec<f64>]) -> bool + Sync)) -> Evaluation {
        let _ = stop;
        self.evaluate(x)
    }
}

/// Bits of a point, the memory's key.
fn key(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

/// The shared, locked part of a search.
struct SearchState {
    records: Vec<Record>,
    memo: HashMap<Vec<u64>, Evaluation>,
    seen: HashSet<Vec<u64>>,
    scorer: Option<Scorer>,
    exhausted: bool,
    /// Records the current phase may reach: the budget, less a polish kept back
    /// ([`run_solver`]).
    limit: usize,
    run: usize,
    journal: Option<Journal>,
    journal_error: Option<JournalError>,
}

/// The cost function the solvers see (see the module docs).
pub struct Search<'a, E: Evaluator> {
    space: &'a Space,
    ev: &'a E,
    pool: Option<&'a rayon::ThreadPool>,
    budget: usize,
    iteration: Arc<AtomicU64>,
    on_record: &'a (dyn Fn(&Record) + Sync),
    /// Race the scenarios of each point against the incumbent ([`Search::racing`]).
    race: bool,
    state: Mutex<SearchState>,
}

/// One planned point of a batch.
struct Planned {
    u: Vec<f64>,
    x: Vec<f64>,
    d2: f64,
    key: Vec<u64>,
    fresh: bool,
}

impl<'a, E: Evaluator> Search<'a, E> {
    /// A search of `space` through `ev` on `pool` (`None`: on the calling thread), with at
    /// most `budget` fresh evaluations; `memo` holds the evaluations of an interrupted run,
    /// `journal` records new ones.
    pub fn new(
        space: &'a Space,
        ev: &'a E,
        pool: Option<&'a rayon::ThreadPool>,
        budget: usize,
        memo: HashMap<Vec<u64>, Evaluation>,
        journal: Option<Journal>,
        on_record: &'a (dyn Fn(&Record) + Sync),
    ) -> Self {
        Search {
            space,
            ev,
            pool,
            budget,
            iteration: Arc::new(AtomicU64::new(0)),
            on_record,
            race: false,
            state: Mutex::new(SearchState {
                records: Vec::new(),
                memo,
                seen: HashSet::new(),
                scorer: None,
                exhausted: false,
                limit: budget,
                run: 0,
                journal,
                journal_error: None,
            }),
        }
    }

    /// The same search, racing when `on`: each fresh point of a batch runs its scenarios in
    /// order and stops at the first after which it is certainly infeasible and certainly not
    /// ranked before the best record as the batch began ([`Scorer::cannot_rank_before`]).
    /// Its record then holds the scenarios run: its feasibility is exact, its objective and
    /// violation are partial (never ranked before the best). Exact for a solver that reads
    /// only the feasibility of infeasible points (Bayesian optimisation), not for one that
    /// ranks them by violation (the others); the incumbent is fixed per batch, so racing does
    /// not depend on the number of threads.
    pub fn racing(mut self, on: bool) -> Self {
        self.race = on;
        self
    }

    /// The scorer and the best score so far, when racing and a point has been scored.
    fn race_against(&self) -> Option<(Scorer, Score)> {
        if !self.race {
            return None;
        }
        let st = self.lock();
        let scorer = st.scorer.clone()?;
        let best = super::score::best_index(st.records.iter().map(|r| r.score))?;
        Some((scorer, st.records[best].score))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, SearchState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Evaluate the start point and fix the objective's scales from it.
    pub fn start(&self, make_scorer: impl FnOnce(&[Vec<f64>]) -> Scorer) -> Result<(), Error> {
        self.batch(&[self.space.start()])?;
        let mut st = self.lock();
        let scorer = make_scorer(&st.records[0].metrics);
        let score = scorer.score(&st.records[0].metrics);
        st.records[0].score = score;
        st.scorer = Some(scorer);
        (self.on_record)(&st.records[0]);
        Ok(())
    }

    /// Plan a batch: project, map, and mark fresh points, up to the budget (every recorded
    /// point counts, repeats included); returns the plan and whether the budget cut it short.
    fn plan<P: std::borrow::Borrow<Vec<f64>>>(
        &self,
        st: &SearchState,
        us: &[P],
    ) -> (Vec<Planned>, bool) {
        let mut fresh_keys: HashSet<Vec<u64>> = HashSet::new();
        let used = st.records.len();
        let mut plan = Vec::new();
        for u in us {
            if used + plan.len() >= st.limit.min(self.budget) {
                return (plan, true);
            }
            let (u, d2) = self.space.project(u.borrow());
            let x = self.space.values(&u);
            let key = key(&x);
            let fresh = !st.seen.contains(&key) && !fresh_keys.contains(&key);
            if fresh {
                fresh_keys.insert(key.clone());
            }
            plan.push(Planned {
                u,
                x,
                d2,
                key,
                fresh,
            });
        }
        (plan, false)
    }

    /// Whether evaluating `us` fits in what is left of the budget.
    fn fits(&self, us: &[Vec<f64>]) -> bool {
        let st = self.lock();
        !st.exhausted && !self.plan(&st, us).1
    }

    /// Evaluate a batch in order (see the module docs); the costs, or the budget error.
    fn batch<P: std::borrow::Borrow<Vec<f64>>>(&self, us: &[P]) -> Result<Vec<f64>, Error> {
        let (plan, cut) = {
            let st = self.lock();
            if st.exhausted {
                return Err(Error::msg("evaluation budget reached"));
            }
            self.plan(&st, us)
        };
        let todo: Vec<usize> = {
            let st = self.lock();
            let mut keys = HashSet::new();
            (0..plan.len())
                .filter(|&i| {
                    plan[i].fresh
                        && !st.memo.contains_key(&plan[i].key)
                        && keys.insert(&plan[i].key)
                })
                .collect()
        };
        let race = self.race_against();
        let evaluate = |&i: &usize| match &race {
            Some((scorer, best)) => self.ev.evaluate_until(&plan[i].x, &|rows: &[Vec<f64>]| {
                scorer.cannot_rank_before(rows, best)
            }),
            None => self.ev.evaluate(&plan[i].x),
        };
        let done: Vec<Evaluation> = match self.pool {
            Some(pool) => pool.install(|| todo.par_iter().map(evaluate).collect()),
            None => todo.iter().map(evaluate).collect(),
        };
        let mut st = self.lock();
        for (&i, e) in todo.iter().zip(done) {
            if let Some(j) = st.journal.as_mut() {
                if let Err(err) = j.append(&plan[i].x, &e) {
                    st.journal_error.get_or_insert(err);
                }
            }
            st.memo.insert(plan[i].key.clone(), e);
        }
        let iteration = self.iteration.load(Ordering::Relaxed);
        let mut costs = Vec::with_capacity(plan.len());
        for p in plan {
            let e = st.memo.get(&p.key).cloned().unwrap_or(Evaluation {
                metrics: Vec::new(),
                failure: Some("not evaluated".into()),
            });
            let score = match &st.scorer {
                Some(s) => s.score(&e.metrics),
                None => Score {
                    objective: f64::NAN,
                    violation: 0.0,
                    feasible: false,
                },
            };
            st.seen.insert(p.key);
            let record = Record {
                index: st.records.len(),
                run: st.run,
                iteration,
                u: p.u,
                x: p.x,
                metrics: e.metrics,
                failure: e.failure,
                repeat: !p.fresh,
                score,
            };
            if st.scorer.is_some() {
                (self.on_record)(&record);
            }
            st.records.push(record);
            costs.push(score.cost() + PENALTY * p.d2);
        }
        if cut {
            st.exhausted = true;
            return Err(Error::msg("evaluation budget reached"));
        }
        Ok(costs)
    }

    /// The records so far, the number of fresh evaluations, and any journal write error.
    pub fn finish(self) -> (Vec<Record>, Option<JournalError>) {
        let st = self.state.into_inner().unwrap_or_else(|e| e.into_inner());
        (st.records, st.journal_error)
    }

    fn best_u(&self) -> Vec<f64> {
        let st = self.lock();
        super::score::best_index(st.records.iter().map(|r| r.score))
            .map(|i| st.records[i].u.clone())
            .unwrap_or_else(|| self.space.start())
    }

    fn exhausted(&self) -> bool {
        self.lock().exhausted
    }

    /// Every recorded point so far as a surrogate's observation (repeats included once).
    fn observations(&self) -> Vec<Observation> {
        let st = self.lock();
        st.records
            .iter()
            .filter(|r| !r.repeat)
            .map(|r| Observation {
                u: r.u.clone(),
                objective: r.score.objective,
                feasible: r.score.feasible,
            })
            .collect()
    }
}

/// The problem handed to argmin (a reference: the search outlives each run).
struct Handle<'s, 'a, E: Evaluator>(&'s Search<'a, E>);

impl<E: Evaluator> CostFunction for Handle<'_, '_, E> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, u: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.0.batch(&[u])?[0])
    }

    fn bulk_cost<P>(&self, params: &[P]) -> Result<Vec<f64>, Error>
    where
        P: std::borrow::Borrow<Vec<f64>> + argmin::core::SyncAlias,
        f64: argmin::core::SendAlias,
        Self: argmin::core::SyncAlias,
    {
        self.0.batch(params)
    }
}

impl<E: Evaluator> Gradient for Handle<'_, '_, E> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;

    /// Central differences with step [`FD_STEP`], all 2n points in one batch.
    fn gradient(&self, u: &Vec<f64>) -> Result<Vec<f64>, Error> {
        let mut points = Vec::with_capacity(2 * u.len());
        for i in 0..u.len() {
            for s in [1.0, -1.0] {
                let mut p = u.clone();
                p[i] += s * FD_STEP;
                points.push(p);
            }
        }
        let c = self.0.batch(&points)?;
        Ok((0..u.len())
            .map(|i| (c[2 * i] - c[2 * i + 1]) / (2.0 * FD_STEP))
            .collect())
    }
}

/// The observer: after iteration `k` the next evaluations belong to iteration `k + 1`.
struct IterationObserver(Arc<AtomicU64>);

impl<I: State> Observe<I> for IterationObserver {
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), Error> {
        self.0.store(state.get_iter() + 1, Ordering::Relaxed);
        Ok(())
    }
}

/// Run the configured solver (and its restarts) on a started search, then its polish if
/// any; returns one line per run saying why it stopped.
///
/// With `[solver] polish = N` the method's runs end at `max_evals − N` records (their budget
/// error, as at the full budget); the last N go to a Nelder–Mead from the best point so far
/// with simplex edge `polish_step` (history run `restarts + 2`). The method's runs are those
/// of `max_evals − N` without a polish, bit for bit.
pub fn run_solver<E: Evaluator>(search: &Search<'_, E>, s: &SolverSettings) -> Vec<String> {
    let mut reasons = run_method(search, s);
    if let Some(p) = s.polish {
        let run = s.restarts + 2;
        {
            let mut st = search.lock();
            st.limit = search.budget;
            st.exhausted = false;
            st.run = run;
        }
        search.iteration.store(0, Ordering::Relaxed);
        let polish = SolverSettings {
            step: p.step,
            ..s.clone()
        };
        reasons.push(match nelder_mead(search, search.best_u(), &polish) {
            Ok(r) => format!("polish (run {run}): {r}"),
            Err(_) if search.exhausted() => {
                format!("polish (run {run}): evaluation budget reached")
            }
            Err(e) => format!("polish (run {run}): stopped: {e}"),
        });
    }
    reasons
}

/// The method's runs (the first and its restarts), within the budget less the polish.
fn run_method<E: Evaluator>(search: &Search<'_, E>, s: &SolverSettings) -> Vec<String> {
    if let Some(p) = s.polish {
        search.lock().limit = search.budget.saturating_sub(p.evals);
    }
    let mut reasons = Vec::new();
    for run in 0..=s.restarts {
        search.lock().run = run + 1;
        search.iteration.store(0, Ordering::Relaxed);
        let u0 = search.best_u();
        let result = match s.method {
            Method::NelderMead => nelder_mead(search, u0, s),
            Method::ParticleSwarm => particle_swarm(search, s, run as u64),
            Method::Lbfgs => lbfgs(search, u0, s),
            Method::Cmaes => cmaes(search, u0, s, run),
            Method::Bayes => bayes(search, s, run),
        };
        match result {
            Ok(r) => reasons.push(format!("run {}: {r}", run + 1)),
            Err(_) if search.exhausted() => {
                reasons.push(format!("run {}: evaluation budget reached", run + 1));
                break;
            }
            Err(e) => reasons.push(format!("run {}: stopped: {e}", run + 1)),
        }
    }
    reasons
}

fn observer<E: Evaluator>(search: &Search<'_, E>) -> IterationObserver {
    IterationObserver(search.iteration.clone())
}

/// Nelder–Mead from `u0`, initial simplex `u0 + step·e_i` (mirrored at the upper bound).
fn nelder_mead<E: Evaluator>(
    search: &Search<'_, E>,
    u0: Vec<f64>,
    s: &SolverSettings,
) -> Result<String, Error> {
    let mut simplex = vec![u0.clone()];
    for i in 0..u0.len() {
        let mut v = u0.clone();
        v[i] = if v[i] + s.step <= 1.0 {
            v[i] + s.step
        } else {
            v[i] - s.step
        };
        simplex.push(v);
    }
    // argmin's Nelder–Mead unwraps the costs of its initial simplex (it would panic on the
    // budget error): a budget that cannot cover the whole simplex spends what is left on its
    // new vertices (the first, `u0`, is a recorded point) and stops the search here.
    if !search.fits(&simplex) {
        search.batch(&simplex[1..])?;
        return Err(Error::msg("evaluation budget reached"));
    }
    let solver = NelderMead::new(simplex).with_sd_tolerance(s.tolerance)?;
    let res = Executor::new(Handle(search), solver)
        .configure(|st| st.max_iters(s.max_iters))
        .add_observer(observer(search), ObserverMode::Always)
        .run()?;
    Ok(res.state().get_termination_status().to_string())
}

/// Particle swarm in the unit box, seeded by `derive_seed(seed, run)` (ChaCha8).
fn particle_swarm<E: Evaluator>(
    search: &Search<'_, E>,
    s: &SolverSettings,
    run: u64,
) -> Result<String, Error> {
    let n = search.space.dim();
    let rng = rand_chacha::ChaCha8Rng::seed_from_u64(derive_seed(s.seed, run));
    let solver =
        ParticleSwarm::new((vec![0.0; n], vec![1.0; n]), s.particles).with_rng_generator(rng);
    let res = Executor::new(Handle(search), solver)
        .configure(|st| st.max_iters(s.max_iters))
        .add_observer(observer(search), ObserverMode::Always)
        .run()?;
    Ok(res.state().get_termination_status().to_string())
}

/// L-BFGS from `u0` (memory 7, Moré–Thuente line search, finite-difference gradients).
fn lbfgs<E: Evaluator>(
    search: &Search<'_, E>,
    u0: Vec<f64>,
    s: &SolverSettings,
) -> Result<String, Error> {
    let solver = LBFGS::new(MoreThuenteLineSearch::new(), 7)
        .with_tolerance_grad(s.tolerance)?
        .with_tolerance_cost(s.tolerance * 1e-3)?;
    let res = Executor::new(Handle(search), solver)
        .configure(|st| st.param(u0).max_iters(s.max_iters))
        .add_observer(observer(search), ObserverMode::Always)
        .run()?;
    Ok(res.state().get_termination_status().to_string())
}

/// CMA-ES from `u0` with σ0 = `step`, seeded by `(seed, run)`; run `r` (0-based) has the
/// population `λ = (4 + ⌊3 ln n⌋)·2^r` (IPOP). Each generation is one batch (evaluated on
/// `--jobs` threads, recorded in order) and one iteration of the history; the run ends after
/// `max_iters` generations, on [`Cmaes::stop`] with `tolerance`, or at the budget.
fn cmaes<E: Evaluator>(
    search: &Search<'_, E>,
    u0: Vec<f64>,
    s: &SolverSettings,
    run: usize,
) -> Result<String, Error> {
    // No larger than the budget could evaluate (the population is allocated up front).
    let lambda = default_lambda(u0.len())
        .saturating_mul(1 << run.min(20))
        .min(s.max_evals.max(2));
    let mut es = Cmaes::new(&u0, s.step, lambda, rng_for(s.seed, run as u64));
    for generation in 0..s.max_iters {
        search.iteration.store(generation + 1, Ordering::Relaxed);
        let population = es.ask();
        let costs = search.batch(&population)?;
        es.tell(&costs);
        if let Some(why) = es.stop(s.tolerance) {
            return Ok(format!("{why} after {} generations", generation + 1));
        }
    }
    Ok(format!("{} generations (max_iters)", s.max_iters))
}

/// Bayesian optimisation ([`super::bayes`]), seeded by `(seed, run)`: the first run evaluates
/// `max(d + 1, 2d)` Latin-hypercube points as one batch, then one proposal per iteration
/// (each an iteration of the history) until `max_iters`, the budget, or no proposal.
/// Restarts continue on every observation so far with a new seed.
fn bayes<E: Evaluator>(
    search: &Search<'_, E>,
    s: &SolverSettings,
    run: usize,
) -> Result<String, Error> {
    let d = search.space.dim();
    let mut rng = rng_for(s.seed, run as u64);
    if run == 0 {
        search.iteration.store(1, Ordering::Relaxed);
        search.batch(&latin_hypercube((d + 1).max(2 * d), d, &mut rng))?;
    }
    for it in 0..s.max_iters {
        search.iteration.store(it + 2, Ordering::Relaxed);
        let Some(u) = propose(&search.observations(), &mut rng) else {
            return Ok(format!(
                "no proposal after {it} iterations (surrogate not fitted)"
            ));
        };
        search.batch(&[u])?;
    }
    Ok(format!("{} iterations (max_iters)", s.max_iters))
}

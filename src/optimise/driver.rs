//! Running an optimisation: the start point, then the configured solver and its restarts
//! within the evaluation budget, with the resume journal; [`run`] for a problem file,
//! [`minimise`] for any [`Evaluator`].

use std::path::Path;

use super::history::{read_journal, Journal, JournalError, Record};
use super::problem::{Method, Problem, Spec};
use super::score::{best_index, Scorer};
use super::search::{run_solver, Evaluator, Search};

/// Why an optimisation could not run.
#[derive(Debug, thiserror::Error)]
pub enum OptimiseError {
    /// The resume journal could not be read or created, or belongs to another problem.
    #[error("journal: {0}")]
    Journal(#[from] JournalError),
    /// A line could not be appended to the journal (the first such error of the run).
    #[error("journal: {0}")]
    JournalWrite(#[source] JournalError),
    /// The thread pool could not be built.
    #[error("building the thread pool: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
    /// The start point could not be evaluated (the solver framework's error: an evaluation
    /// budget of zero).
    #[error("evaluating the start point: {0}")]
    Start(#[source] Box<dyn std::error::Error + Send + Sync>),
}

/// How to run an optimisation.
pub struct Options<'a> {
    /// Threads evaluating a batch (results do not depend on it).
    pub jobs: usize,
    /// The journal file (`None`: no journal, no resume).
    pub journal: Option<&'a Path>,
    /// Replay the journal of an interrupted run of the same problem, then carry on.
    pub resume: bool,
    /// Called for each evaluation, in order, once it is scored (progress display).
    pub on_record: &'a (dyn Fn(&Record) + Sync),
    /// Race each point's scenarios against the best so far (`[tune] race`,
    /// [`Search::racing`]): taken by Bayesian optimisation only, the one solver it leaves
    /// exactly unchanged; the others run every scenario of every point.
    pub race: bool,
}

/// The result of an optimisation.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Every evaluation, in order (index 0: the start point).
    pub records: Vec<Record>,
    /// Index of the best record (feasibility first).
    pub best: usize,
    /// The objective and constraints with the scales fixed at the start point.
    pub scorer: Scorer,
    /// The evaluator's metric names (columns of each record's metrics).
    pub metrics: Vec<String>,
    /// Why each solver run stopped.
    pub stops: Vec<String>,
    /// Evaluations served from the journal of an interrupted run.
    pub replayed: usize,
}

impl Outcome {
    /// The best record.
    pub fn best(&self) -> &Record {
        &self.records[self.best]
    }

    /// The start record.
    pub fn start(&self) -> &Record {
        &self.records[0]
    }

    /// Evaluations that ran (repeats excluded).
    pub fn fresh_evaluations(&self) -> usize {
        self.records.iter().filter(|r| !r.repeat).count()
    }

    /// Scenario runs the fresh evaluations used (fewer than evaluations × scenarios when
    /// raced).
    pub fn scenario_runs(&self) -> usize {
        self.records
            .iter()
            .filter(|r| !r.repeat)
            .map(|r| r.metrics.len())
            .sum()
    }
}

/// Optimise a problem file's parameters (see the module docs).
pub fn run(problem: &Problem, opts: &Options<'_>) -> Result<Outcome, OptimiseError> {
    let ev = super::evaluate::CaseEvaluator::new(problem);
    minimise(&problem.spec, &ev, &problem.study.hash, opts)
}

/// Minimise `spec`'s objective over its space through `ev`: the start point, then the
/// configured solver and its restarts within the evaluation budget. `hash` identifies the
/// problem in the journal.
pub fn minimise<E: Evaluator>(
    spec: &Spec,
    ev: &E,
    hash: &str,
    opts: &Options<'_>,
) -> Result<Outcome, OptimiseError> {
    // One job: evaluate on the calling thread. A pool of one would make a sweep worker that
    // tunes its case (`[tune]`) wait across pools, and a waiting rayon worker steals its own
    // pool's next case meanwhile: cases then nest on one thread while the other idles.
    let pool = match opts.jobs {
        1 => None,
        n => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n.max(1))
                .build()?,
        ),
    };
    let (memo, journal) = match opts.journal {
        Some(p) if opts.resume && p.is_file() => {
            (read_journal(p, hash)?, Some(Journal::append_to(p)?))
        }
        Some(p) => (Default::default(), Some(Journal::create(p, hash)?)),
        None => (Default::default(), None),
    };
    let replayable = memo.len();
    let search = Search::new(
        &spec.space,
        ev,
        pool.as_ref(),
        spec.solver.max_evals,
        memo,
        journal,
        opts.on_record,
    )
    // Racing is exact for a method that reads only the feasibility of infeasible points
    // (bayes), not for the Nelder–Mead of a polish.
    .racing(opts.race && spec.solver.method == Method::Bayes && spec.solver.polish.is_none());
    search
        .start(|m| Scorer::new(&spec.objective, &spec.constraints, ev.metrics(), m))
        .map_err(|e| OptimiseError::Start(e.into()))?;
    let stops = run_solver(&search, &spec.solver);
    let (records, journal_error) = search.finish();
    if let Some(e) = journal_error {
        return Err(OptimiseError::JournalWrite(e));
    }
    let scorer = Scorer::new(
        &spec.objective,
        &spec.constraints,
        ev.metrics(),
        &records[0].metrics,
    );
    let best = best_index(records.iter().map(|r| r.score)).unwrap_or(0);
    let replayed = records.iter().filter(|r| !r.repeat).count().min(replayable);
    Ok(Outcome {
        records,
        best,
        scorer,
        metrics: ev.metrics().to_vec(),
        stops,
        replayed,
    })
}

//! Optimisation of a design's or a scenario's parameters with argmin (`usm-study optimise`,
//! docs/optimise.md): gains, layouts, references — any key a sweep axis may edit — against a
//! weighted objective of named metrics under constraints, feasibility first.
//!
//! Modules in dependency order (this file only declares and re-exports):
//!
//! - [`problem`]: problem files → a validated [`Problem`] (study part + optimiser sections).
//!   The sections' types and their parser are the `study` room's (what to run), shared with a
//!   sweep's `[tune]`: [`crate::study::tune_space`] (parameters, bounds, scales, the unit box),
//!   [`crate::study::tune_solver`] (`[solver]`), [`crate::study::tune_spec`] and
//!   [`crate::study::tune_spec_parse`].
//! - [`score`]: objective normalisation, combination over scenarios, constraint violation and
//!   the feasibility-first ranking.
//! - [`history`]: evaluation records, the history table and the resume journal.
//! - [`cmaes`]: CMA-ES as an ask/tell state machine (pycma's defaults), driven by `search`.
//! - [`search`]: the argmin cost function, gradient, observer and the four solvers.
//! - [`evaluate`]: a problem's point → its metrics (through the one case evaluator,
//!   [`crate::evaluate`]).
//! - [`engine`]: [`run`] and [`minimise`]: start point, solver runs, outcome.
//! - [`tune`]: per-case tuning of a sweep (`[tune]`), wired into the sweep engine through its
//!   hook ([`tune::HOOK`]).
//!
//! The library API a caller (the `optimise` verb, a sweep tuning each case) uses is
//! [`run`] for a problem file, or [`minimise`] for any [`search::Evaluator`].

pub mod bayes;
pub mod case_tuner;
pub mod cmaes;
pub mod driver;
pub mod evaluate;
pub mod history;
pub mod problem;
pub mod score;
pub mod search;
mod tune_seeds;

pub use driver::{minimise, run, OptimiseError, Options, Outcome};
pub use problem::{load_problem, parse_problem, Problem, Spec};

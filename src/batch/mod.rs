//! Running a study (issue 37 item 1): the parallel sweep engine with resume, shards and case
//! budgets; one resolved case → one row (its worlds, validation variants, fault reruns, tuned
//! first through the tuning hook); the output directory, its lock, journal and manifest; the
//! rows, records and final tables (`worlds.csv`, ranking columns, the paired verdict).
//! What to run is [`crate::study`]'s; what a finished study says is [`crate::review`]'s.
//!
//! - [`records`]: rows (named metrics), columns of the raw and final tables.
//! - [`tuning_hook`]: the per-case tuning hook (`[tune]`): the optimiser's tuner reaches the
//!   sweep through it, handed in by the caller; [`report_hook`]: the review room's report
//!   (`summary.md`, plots) reaches a finished sweep or merge the same way.
//! - [`worlds`], [`faults`], [`adaptive`]: one case in its worlds and validation variants, its
//!   fault reruns, adaptive rounds of worlds.
//! - [`worker`]: one resolved case → one row through the case evaluator ([`crate::evaluate`]).
//! - [`conditions`], [`robust`]: the rows of each condition; the final tables and the verdict.
//! - [`manifest`], [`lock`], [`outdir`], [`journal`]: the output directory's files.
//! - [`engine`]: running, resuming and sharding a sweep; [`shards`]: merging shard outputs.

pub mod adaptive;
pub mod bound_hook;
pub mod conditions;
pub mod engine;
pub mod faults;
pub mod journal;
pub mod lock;
pub mod manifest;
pub mod outdir;
pub mod records;
pub mod report_hook;
pub mod robust;
pub mod shards;
pub mod tuning_hook;
pub mod worker;
pub mod worlds;

pub use engine::{run_sweep, ProgressEvent, SweepOptions, SweepOutcome};
pub use records::CaseStatus;
pub use report_hook::ReportHook;
pub use shards::merge;

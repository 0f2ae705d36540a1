//! Batch studies (docs/model.md §7): the study schema, designs of experiments, the parallel
//! sweep engine with resume and shards, and the sweep report.
//!
//! Modules in dependency order (each uses only modules above it):
//!
//! - [`error`]: [`InputError`] (located study-file problems) and [`StudyError`].
//! - [`hash`]: canonical text of TOML tables and the study and case hashes.
//! - [`runner`]: the single adapter to the scenario module's settings (modes, defaults).
//! - [`schema`]: the validated [`Study`] (axes, design of experiments, report settings).
//! - [`axes`]: the `[[axis]]` entries → validated axes, against the valid parameter names.
//! - [`parse`]: study files (TOML) → validated [`Study`].
//! - [`uncertainty`]: `[uncertainty]` and `[[validate]]`: uncertain parameters, the worlds
//!   every case meets (common random numbers), ranking settings, validation variants.
//! - [`doe`]: grid and sampled designs of experiments → cases.
//! - [`cases`]: a case's overrides applied, its seed and hashes.
//! - [`tune`]: the per-case tuning hook (`[tune]`): the optimiser's tuner reaches the sweep
//!   through it, handed in by the caller.
//! - [`records`]: rows (named metrics), columns of the raw and final tables.
//! - [`worker`]: one resolved case → one row through the case evaluator
//!   ([`crate::evaluate`]), tuned first through the hook.
//! - [`worlds`]: one case in the study's worlds and validation variants (summaries over
//!   worlds, success probability, the paired per-world values).
//! - [`robust`]: the study-level view of the worlds: `worlds.csv`, ranking columns, the
//!   paired verdict.
//! - [`dictionary`]: every output column's unit, type and meaning (`docs/columns.md`).
//! - [`manifest`]: the `manifest.json` of an output directory.
//! - [`lock`]: the output directory's lock (heartbeat, takeover on `--resume`, signals).
//! - [`outdir`]: the output directory resolved once, kept free of links out, owned by one
//!   study; the record of the files the tool wrote.
//! - [`journal`]: the journal (`cases.partial.csv`) checked before `--resume` trusts it.
//! - [`selection`], [`plots`], [`summary`]: the report (`summary.md` and plots);
//!   [`summary_robust`]: its verdict and sections over uncertain worlds.
//! - [`finish`]: the report step (best/worst reruns, summary) and `usm-study report`.
//! - [`rerank`]: `usm-study report --objective/--pareto`, re-ranking without re-running.
//! - [`engine`]: running, resuming and sharding a sweep.
//! - [`shards`]: merging shard outputs.

pub mod adaptive;
pub mod admit;
pub mod axes;
pub mod cases;
pub mod catalogue;
pub mod conditions;
pub mod dictionary;
pub mod directions;
pub mod doe;
pub mod engine;
pub mod error;
pub mod families;
pub mod fault_spec;
pub mod faults;
pub mod finish;
pub mod hash;
pub mod journal;
pub mod lock;
pub mod manifest;
pub mod outdir;
pub mod parse;
pub mod plots;
pub mod plots_ranked;
pub mod records;
pub mod rerank;
pub mod robust;
pub mod runner;
pub mod schema;
pub mod selection;
pub mod shards;
pub mod summary;
pub mod summary_robust;
pub mod tuning_hook;
pub mod uncertainty;
pub mod verdict_box;
pub mod verdict_firm;
pub mod worker;
pub mod worlds;

pub use engine::{run_sweep, ProgressEvent, SweepOptions, SweepOutcome};
pub use error::{InputError, StudyError};
pub use finish::{report, report_ranked, Reported};
pub use parse::{load_study, load_study_at, parse_study, with_seed};
pub use records::CaseStatus;
pub use rerank::Rerank;
pub use schema::{DoeKind, Study};
pub use shards::merge;

//! What to run (docs/model.md §7; issue 37 item 1): the study schema and its parsing in named
//! phases, the axes, uncertain worlds and validation variants as declared, the designs of
//! experiments, a case's overrides applied, the data dictionary of the output columns, and
//! the values checked where they enter. Running a study is [`crate::batch`]'s; what a
//! finished study says is [`crate::review`]'s.
//!
//! Modules in dependency order (each uses only modules above it):
//!
//! - [`error`]: [`InputError`] (located study-file problems) and [`StudyError`].
//! - [`hash`]: canonical text of TOML tables and the study and case hashes.
//! - [`runner`]: the single adapter to the scenario module's settings (modes, defaults).
//! - [`target`]: what a key path edits (design or scenario side).
//! - [`tune_space`], [`tune_solver`], [`tune_spec`]: the optimiser's sections typed —
//!   parameters and their normalised box, `[solver]`, objective, constraints, scenarios —
//!   shared by problem files and a sweep's `[tune]`.
//! - [`schema`]: the validated [`Study`] (axes, design of experiments, report settings, the
//!   typed `[tune]`).
//! - [`axes`]: the `[[axis]]` entries → validated axes, against the valid parameter names.
//! - [`catalogue`], [`directions`], [`dictionary`]: the metric catalogue, which way is
//!   better, every output column's unit, type and meaning (`docs/columns.md`).
//! - [`uncertainty`]: `[uncertainty]` and `[[validate]]`: uncertain parameters, ranking
//!   settings, validation variants; [`fault_spec`]: `[faults]`; [`ocp_section`]: `[ocp]`.
//! - [`doe`]: grid and sampled designs of experiments → cases.
//! - [`cases`]: a case's overrides applied, its seed and hashes.
//! - [`admit`]: every axis, world and variant value checked at load.
//! - [`tune_spec_parse`]: the optimiser's sections of any table → a validated spec;
//!   [`tune_section`]: a sweep's `[tune]` → the typed section, at load.
//! - [`parse`]: study files (TOML) → validated [`Study`].

pub mod admit;
pub mod axes;
pub mod cases;
pub mod catalogue;
pub mod dictionary;
pub mod directions;
pub mod doe;
pub mod error;
pub mod fault_spec;
pub mod hash;
pub mod ocp_section;
pub mod parse;
pub mod runner;
pub mod schema;
pub mod target;
pub mod tune_section;
pub mod tune_solver;
pub mod tune_space;
pub mod tune_spec;
pub mod tune_spec_parse;
pub mod uncertainty;

pub use error::{InputError, StudyError};
pub use parse::{load_study, load_study_at, parse_study, with_seed};
pub use schema::{DoeKind, Study};

//! Batch studies (SPEC §7): the study schema, designs of experiments, the parallel sweep
//! engine with resume and shards, the static configuration-space TCM analysis, and the sweep
//! report.
//!
//! - [`static_tcm`]: `usm-study tcm` — how often `T(q)` is singular over joint space.
//! - [`schema`]: study files (TOML) → validated [`Study`].
//! - [`doe`]: grid and sampled designs of experiments → cases.
//! - [`engine`]: running, resuming, sharding, merging; final tables and manifest.
//! - [`runner`]: the single adapter to the scenario module.
//! - [`summary`]: `summary.md` and plots.

pub mod doe;
pub mod engine;
pub mod runner;
pub mod schema;
pub mod static_tcm;
pub mod summary;

pub use engine::{merge, report, run_sweep, ProgressEvent, SweepOptions, SweepOutcome};
pub use schema::{load_study, InputError, Study};
pub use static_tcm::{analyse, StaticSpec, StaticSummary};

use std::path::PathBuf;

/// Errors of the batch engine. [`StudyError::is_input`] tells bad input (exit code 2) from
/// other failures.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A problem with the study file, with its position.
    #[error("{0}")]
    Study(#[from] InputError),
    /// Other bad input (command-line values, output directories that do not fit).
    #[error("{0}")]
    Input(String),
    /// Reading or writing a result file.
    #[error(transparent)]
    Report(#[from] crate::report::ReportError),
    /// File system.
    #[error("{path}: {message}", path = .path.display())]
    Io {
        /// The path concerned.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// Anything else.
    #[error("{0}")]
    Other(String),
}

impl StudyError {
    /// Whether this is bad input (study file or command line).
    pub fn is_input(&self) -> bool {
        matches!(self, StudyError::Study(_) | StudyError::Input(_))
    }
}

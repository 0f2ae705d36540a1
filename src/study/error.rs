//! Errors of the study room: [`InputError`] (a located problem with the study file) and
//! [`StudyError`] (everything a sweep, merge or report can fail with).

use std::path::{Path, PathBuf};

/// A problem with the study file or the command line (exit code 2), located by the input
/// layer (`file:line:col: key: message`).
pub use crate::input::located::InputError;

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
    #[error("{path}: {source}", path = .path.display())]
    Io {
        /// The path concerned.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
    /// The study's cases cannot be sampled (too many axes for Sobol, too many cases).
    #[error("{0}")]
    Plan(#[from] crate::sampling::SamplerError),
    /// The sweep's thread pool could not be built.
    #[error("thread pool: {0}")]
    Pool(#[source] rayon::ThreadPoolBuildError),
    /// The study has a `[tune]` section but the caller wired no tuner into the sweep.
    #[error("the study has a [tune] section but no tuner was wired into the sweep")]
    NoTuner,
    /// The study has an `[ocp]` section but the caller wired no bound solver into the sweep.
    #[error(
        "the study has an [ocp] section but no optimal-control solver was wired into the sweep"
    )]
    NoBounder,
    /// Anything else.
    #[error("{0}")]
    Other(String),
}

/// Messages for the user that a step returns beside its result (notes, warnings), one a line.
pub type Notes = Vec<String>;

impl StudyError {
    /// Whether this is bad input (study file or command line).
    pub fn is_input(&self) -> bool {
        matches!(
            self,
            StudyError::Study(_) | StudyError::Input(_) | StudyError::Plan(_)
        )
    }

    /// A file-system error at `path`.
    pub(crate) fn io(path: &Path, e: std::io::Error) -> Self {
        StudyError::Io {
            path: path.to_path_buf(),
            source: e,
        }
    }
}

//! Errors of the study room: [`InputError`] (a located problem with the study file) and
//! [`StudyError`] (everything a sweep, merge or report can fail with).

use std::fmt;
use std::path::{Path, PathBuf};

use crate::diag::write_located;
use crate::model::design::DesignError;

/// A problem with the study file or the command line (exit code 2).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct InputError {
    /// File (or other origin) of the problem.
    pub origin: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column, when known.
    pub column: Option<usize>,
    /// Key path, e.g. `axis[2].name`; empty when none.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_located(
            f,
            &self.origin,
            self.line,
            self.column,
            &self.key,
            &self.message,
        )
    }
}

impl From<DesignError> for InputError {
    fn from(e: DesignError) -> Self {
        InputError {
            origin: e.origin,
            line: e.line,
            column: e.column,
            key: e.key,
            message: e.message,
        }
    }
}

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

    /// A file-system error at `path`.
    pub(crate) fn io(path: &Path, e: std::io::Error) -> Self {
        StudyError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }
}

//! The error type of the output pipelines.

use std::path::PathBuf;

use crate::dynamics::DynError;
use crate::metrics::singularity::SingularityError;
use crate::model::design::DesignError;
use crate::optimise::evaluate::ResolveError;
use crate::report::ReportError;
use crate::scenario::ScenarioError;
use crate::statics::StaticError;

/// Why a pipeline stopped. Errors of the stages it calls pass through unchanged (same message,
/// same source chain); file-system errors name the path.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// A design could not be loaded.
    #[error(transparent)]
    Design(#[from] DesignError),
    /// A scenario could not be loaded, or its run could not start.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// An optimised point's parameters could not be applied to the problem's tables.
    #[error(transparent)]
    Resolve(#[from] ResolveError),
    /// The static analysis of `T(q)` failed.
    #[error(transparent)]
    Static(#[from] StaticError),
    /// A table or figure could not be built or written.
    #[error(transparent)]
    Report(#[from] ReportError),
    /// A summary could not be serialised.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// The design has no thrusters, so there is no `T(q)` to analyse.
    #[error("design `{design}` has no thrusters; there is no T(q) to analyse")]
    NoThrusters {
        /// Design name.
        design: String,
    },
    /// An operation on the file system failed.
    #[error("{action} {path}", path = .path.display())]
    Io {
        /// What was being done, e.g. "creating".
        action: &'static str,
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The singularity metrics of `T(q)` could not be evaluated.
    #[error("{what}")]
    Singularity {
        /// What was being analysed, e.g. "analysing T(q)".
        what: &'static str,
        /// The metric error.
        #[source]
        source: SingularityError,
    },
    /// The state puts the drawing's geometry out of range (a coordinate not finite or beyond
    /// [`crate::pipeline::draw::MAX_DRAWING_COORD`] m), so its SVG would hold NaN.
    #[error(
        "the state puts {what} at {value} m, beyond the ±{limit:e} m a drawing can show \
         (check the state's base position and joint angles)"
    )]
    DrawingRange {
        /// Which part of the drawing, e.g. "body B2".
        what: String,
        /// The offending coordinate [m].
        value: String,
        /// The limit [m].
        limit: f64,
    },
    /// The dynamics could not be evaluated at the given state.
    #[error("evaluating the dynamics at the state")]
    Dynamics(#[source] DynError),
}

/// Creates the output folder `dir` and its parents and removes the temporaries a killed run of
/// any verb left there (`report::prepare_dir`); errors name the directory.
pub fn create_dir(dir: &std::path::Path) -> Result<(), PipelineError> {
    crate::report::prepare_dir(dir)
        .map(drop)
        .map_err(|source| PipelineError::Io {
            action: "creating",
            path: dir.to_path_buf(),
            source,
        })
}

/// Creates `dir`, a folder inside an output, refusing a symbolic link at its name
/// (`report::create_subdir`); errors name the directory.
pub fn create_subdir(dir: &std::path::Path) -> Result<(), PipelineError> {
    crate::report::create_subdir(dir).map_err(|source| PipelineError::Io {
        action: "creating",
        path: dir.to_path_buf(),
        source,
    })
}

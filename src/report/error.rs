//! The error type of the report module.

use std::path::PathBuf;

use super::column_kind::ColumnKind;

/// Errors of the report module. Every variant that concerns a file names its path.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// An operating-system I/O operation on `path` failed.
    #[error("{action} {path}: {source}", path = .path.display())]
    Io {
        /// The file or directory concerned.
        path: PathBuf,
        /// What was being done, e.g. "writing", "renaming into place".
        action: &'static str,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// polars failed to write or read `path`.
    #[error("{action} {path}: {source}", path = .path.display())]
    Polars {
        /// The file concerned.
        path: PathBuf,
        /// What was being done, e.g. "writing CSV".
        action: &'static str,
        /// polars' error.
        #[source]
        source: polars::error::PolarsError,
    },
    /// A column was pushed whose length differs from the table's row count.
    #[error("column `{column}` has {found} rows, the table has {expected}")]
    LengthMismatch {
        /// The offending column.
        column: String,
        /// The table's row count.
        expected: usize,
        /// The column's length.
        found: usize,
    },
    /// A column name occurs twice.
    #[error("duplicate column `{name}`")]
    DuplicateColumn {
        /// The repeated name.
        name: String,
    },
    /// No column has this name.
    #[error("no column named `{name}`")]
    MissingColumn {
        /// The requested name.
        name: String,
    },
    /// A column has another type than the one requested.
    #[error("column `{column}` holds {found}, not {expected}")]
    TypeMismatch {
        /// The column.
        column: String,
        /// The requested type.
        expected: ColumnKind,
        /// The column's type.
        found: ColumnKind,
    },
    /// Two tables (or a table and a file header) do not share one schema.
    #[error("schema mismatch at column `{column}`: {detail}")]
    SchemaMismatch {
        /// The first column (by position or name) that differs.
        column: String,
        /// What differs.
        detail: String,
    },
    /// A file holds a column type the report tables cannot represent, or a missing value where
    /// none is allowed.
    #[error("{path}: column `{column}`: {detail}", path = .path.display())]
    UnsupportedColumn {
        /// The file.
        path: PathBuf,
        /// The column.
        column: String,
        /// What is wrong (e.g. "type date is not supported", "missing value in row 3").
        detail: String,
    },
    /// A row index is out of range.
    #[error("row index {index} out of range for a table of {rows} rows")]
    RowOutOfRange {
        /// The requested index.
        index: usize,
        /// The table's row count.
        rows: usize,
    },
    /// A row given to [`CsvAppender`] does not fit the header.
    #[error("{path}: row does not fit the header: {detail}", path = .path.display())]
    BadRow {
        /// The file being appended to.
        path: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// A figure specification is invalid (bad layout, mismatched lengths, bad range...).
    #[error("invalid figure `{figure}`: {detail}")]
    InvalidFigure {
        /// The figure's title.
        figure: String,
        /// What is wrong.
        detail: String,
    },
    /// plotters failed while drawing a figure.
    #[error("drawing figure `{figure}`: {message}")]
    Plot {
        /// The figure's title.
        figure: String,
        /// plotters' error message.
        message: String,
    },
    /// A figure's PDF could not be made.
    #[error("PDF of figure `{figure}`: {source}")]
    Pdf {
        /// The figure's title.
        figure: String,
        /// What is wrong.
        #[source]
        source: PdfError,
    },
}

/// Errors of the PDF writer ([`crate::report::pdf`]).
#[derive(Debug, thiserror::Error)]
pub enum PdfError {
    /// A page side is not finite or outside 1..=14400 pt.
    #[error("page size {width}×{height} pt must be finite and within 1..=14400 pt")]
    BadPage {
        /// The width asked for [pt].
        width: f64,
        /// The height asked for [pt].
        height: f64,
    },
}

/// Convenience alias for results of this module.
pub type Result<T, E = ReportError> = std::result::Result<T, E>;

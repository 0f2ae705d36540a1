//! Reporting: tables (CSV / Parquet through polars) and SVG figures (plotters).
//!
//! This module knows nothing of the physics. It turns result records, already flattened into
//! named columns by the caller, into files:
//!
//! - [`table`]: a small column-oriented [`Table`], deterministic CSV and Parquet writers and
//!   readers (atomic writes: temporary file in the same directory, then rename), [`Table::concat`]
//!   for merging shard tables, and a row-by-row [`CsvAppender`] for long sweeps.
//! - [`plot`]: data-driven figure specifications ([`Figure`], [`Panel`], [`Series`],
//!   [`Heatmap`]) rendered to SVG with native `<text>` elements (no font files), byte-identical
//!   between runs.
//! - [`pareto_front`]: the non-dominated subset of a set of 2-D points (minimise both).
//!
//! It is the only module of the crate that uses `polars` and `plotters`; neither leaks through
//! the public API (errors carry their messages as strings).

/// SVG figures.
pub mod figures;
pub mod plot;
/// Tables and their files.
pub mod table;

use std::io::Write;
use std::path::{Path, PathBuf};

pub use plot::{
    heatmap, histogram, scatter_labelled, Colour, ColourScale, Figure, Heatmap, LabelledPoint,
    LineStyle, Panel, PanelKind, Series,
};
pub use table::{
    format_f64, read_csv, read_csv_typed, read_parquet, write_csv, write_parquet, Column,
    ColumnData, ColumnKind, CsvAppender, Table, Value,
};

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
    #[error("{action} {path}: {message}", path = .path.display())]
    Polars {
        /// The file concerned.
        path: PathBuf,
        /// What was being done, e.g. "writing CSV".
        action: &'static str,
        /// polars' error message.
        message: String,
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
}

/// Convenience alias for results of this module.
pub type Result<T, E = ReportError> = std::result::Result<T, E>;

/// Writes `bytes` to `path` atomically: to a temporary file in the same directory, flushed and
/// synced, then renamed into place. A reader never sees a half-written file; an interrupted
/// write leaves at most a stray `.<name>.tmp-<pid>` file.
pub(crate) fn atomic_write(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |action: &'static str, p: &Path| {
        let p = p.to_path_buf();
        move |source| ReportError::Io {
            path: p,
            action,
            source,
        }
    };
    let file_name = path.file_name().ok_or_else(|| ReportError::Io {
        path: path.to_path_buf(),
        action: "writing",
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "path has no file name"),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp = dir.join(tmp_name);
    let result = (|| {
        let mut file = std::fs::File::create(&tmp).map_err(io("creating", &tmp))?;
        file.write_all(bytes).map_err(io("writing", &tmp))?;
        file.sync_all().map_err(io("syncing", &tmp))?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(io("renaming into place", path))
    })();
    if result.is_err() {
        // Best effort: do not leave the temporary file behind.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Indices of the non-dominated points of `points` when **both** coordinates are minimised
/// (the Pareto front).
///
/// A point `a` dominates `b` when `a.0 <= b.0`, `a.1 <= b.1` and at least one inequality is
/// strict. Points with a NaN coordinate are excluded (never on the front, never dominating).
/// Exact duplicates do not dominate each other; of a group of identical points only the one with
/// the smallest index is kept, so the result is deterministic. The returned indices are ordered
/// by increasing first coordinate (ties by index), i.e. along the front from left to right.
///
/// Cost: O(n log n).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .collect();
    // Sort by x, then y, then index: a point can only be dominated by one earlier in this order.
    // `+ 0.0` maps -0.0 to 0.0 so that the two zeros compare equal under `total_cmp`.
    let at = |i: usize| (points[i].0 + 0.0, points[i].1 + 0.0);
    order.sort_by(|&a, &b| {
        let (pa, pb) = (at(a), at(b));
        pa.0.total_cmp(&pb.0)
            .then(pa.1.total_cmp(&pb.1))
            .then(a.cmp(&b))
    });
    let mut front = Vec::new();
    let mut best_y = f64::INFINITY;
    let mut last: Option<(f64, f64)> = None;
    for i in order {
        let p = at(i);
        if let Some(l) = last {
            if l.0 == p.0 && l.1 == p.1 {
                continue; // duplicate of a kept point
            }
        }
        if p.1 < best_y || (front.is_empty() && p.1 == f64::INFINITY) {
            best_y = p.1;
            front.push(i);
            last = Some(p);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_hand_case() {
        let pts = [
            (1.0, 5.0),      // 0 front
            (2.0, 3.0),      // 1 front
            (3.0, 3.0),      // 2 dominated by 1
            (2.5, 4.0),      // 3 dominated by 1
            (4.0, 1.0),      // 4 front
            (f64::NAN, 0.0), // 5 excluded
            (2.0, 3.0),      // 6 duplicate of 1
            (5.0, 1.0),      // 7 dominated by 4
            (0.5, f64::NAN), // 8 excluded
            (1.0, 6.0),      // 9 dominated by 0 (same x)
        ];
        assert_eq!(pareto_front(&[(-0.0, 1.0), (0.0, 0.5)]), vec![1]);
        assert_eq!(pareto_front(&pts), vec![0, 1, 4]);
    }

    #[test]
    fn pareto_edge_cases() {
        assert!(pareto_front(&[]).is_empty());
        assert!(pareto_front(&[(f64::NAN, f64::NAN)]).is_empty());
        assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![0]);
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0]);
        assert_eq!(
            pareto_front(&[(f64::INFINITY, f64::INFINITY), (1.0, f64::INFINITY)]),
            vec![1]
        );
        assert_eq!(pareto_front(&[(f64::INFINITY, f64::INFINITY)]), vec![0]);
        assert_eq!(
            pareto_front(&[(f64::NEG_INFINITY, 3.0), (0.0, f64::NEG_INFINITY)]),
            vec![0, 1]
        );
    }

    #[test]
    fn atomic_write_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        atomic_write(&p, b"one").unwrap();
        atomic_write(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "no temporary file left behind");
        assert!(atomic_write(&dir.path().join("missing/x.txt"), b"x").is_err());
    }
}

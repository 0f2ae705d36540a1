//! The history of an optimisation: one [`Record`] per evaluation in evaluation order, its
//! table (`history.csv` / `history.parquet`), and the journal that lets `--resume` replay an
//! interrupted run.
//!
//! The journal (`journal.jsonl`) starts with a line naming the problem's hash; every later
//! line is one simulated point: its parameter values and metrics as the bits of each `f64`
//! (exact, whatever the float printer does) and the failure text. A torn last line (the
//! process was killed while writing) is ignored.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::score::{mean_of, Score};
use crate::report::{Column, ColumnData, Table};

/// Why the journal could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// Reading or writing the file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The journal file.
        path: PathBuf,
        /// The file-system error.
        #[source]
        source: std::io::Error,
    },
    /// A line could not be written as JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// The file has no header line.
    #[error("{}: not a journal (no header line)", path.display())]
    NoHeader {
        /// The journal file.
        path: PathBuf,
    },
    /// The journal belongs to another problem.
    #[error(
        "{}: the journal is of another problem or another build of usm-study (hash {found}, \
         this problem with this build {expected}; the hash includes the build's source \
         identity, so old results are never mixed with a changed model); run without \
         --resume to start afresh",
        path.display()
    )]
    OtherProblem {
        /// The journal file.
        path: PathBuf,
        /// The journal's problem hash.
        found: String,
        /// This problem's hash.
        expected: String,
    },
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> JournalError + '_ {
    move |source| JournalError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// File name of the journal in an output directory.
pub const JOURNAL_FILE: &str = "journal.jsonl";

/// The metrics of one point.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// One row per scenario, one value per metric (the evaluator's columns).
    pub metrics: Vec<Vec<f64>>,
    /// Why the evaluation (or one of its scenarios) failed, if it did.
    pub failure: Option<String>,
}

/// One evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Evaluation number (0: the start point).
    pub index: usize,
    /// Solver run (0: the start point; 1 the first run, then restarts).
    pub run: usize,
    /// argmin iteration within the run (0: the solver's initialisation).
    pub iteration: u64,
    /// Normalised coordinates (inside the unit box).
    pub u: Vec<f64>,
    /// Physical parameter values.
    pub x: Vec<f64>,
    /// Metrics, one row per scenario.
    pub metrics: Vec<Vec<f64>>,
    /// Why the evaluation failed, if it did.
    pub failure: Option<String>,
    /// Whether the point was evaluated before in this run (served from memory).
    pub repeat: bool,
    /// Its score.
    pub score: Score,
}

#[derive(Serialize, Deserialize)]
struct Header {
    problem_hash: String,
}

#[derive(Serialize, Deserialize)]
struct Line {
    x: Vec<u64>,
    m: Vec<Vec<u64>>,
    failure: Option<String>,
}

/// The journal being written.
pub struct Journal {
    path: PathBuf,
    file: std::fs::File,
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn floats(v: &[u64]) -> Vec<f64> {
    v.iter().map(|b| f64::from_bits(*b)).collect()
}

impl Journal {
    /// Start a new journal for the problem with hash `hash` (replacing any old one).
    pub fn create(path: &Path, hash: &str) -> Result<Journal, JournalError> {
        let mut file = crate::report::create_file(path).map_err(io_error(path))?;
        let h = serde_json::to_string(&Header {
            problem_hash: hash.to_string(),
        })?;
        writeln!(file, "{h}").map_err(io_error(path))?;
        Ok(Journal {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Append to an existing journal.
    pub fn append_to(path: &Path) -> Result<Journal, JournalError> {
        let file = crate::report::open_existing(path, true).map_err(io_error(path))?;
        Ok(Journal {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Record one simulated point (flushed line by line).
    pub fn append(&mut self, x: &[f64], e: &Evaluation) -> Result<(), JournalError> {
        let line = Line {
            x: bits(x),
            m: e.metrics.iter().map(|r| bits(r)).collect(),
            failure: e.failure.clone(),
        };
        let text = serde_json::to_string(&line)?;
        writeln!(self.file, "{text}")
            .and_then(|_| self.file.flush())
            .map_err(io_error(&self.path))
    }
}

/// The evaluations of a journal keyed by the bits of their parameter values; `Err` when the
/// journal belongs to another problem (its hash differs) or cannot be read.
pub fn read_journal(
    path: &Path,
    hash: &str,
) -> Result<HashMap<Vec<u64>, Evaluation>, JournalError> {
    let text = std::fs::read_to_string(path).map_err(io_error(path))?;
    let mut lines = text.lines();
    let header: Header = lines
        .next()
        .and_then(|l| serde_json::from_str(l).ok())
        .ok_or_else(|| JournalError::NoHeader {
            path: path.to_path_buf(),
        })?;
    if header.problem_hash != hash {
        return Err(JournalError::OtherProblem {
            path: path.to_path_buf(),
            found: header.problem_hash,
            expected: hash.to_string(),
        });
    }
    let mut memo = HashMap::new();
    for l in lines {
        let Ok(line) = serde_json::from_str::<Line>(l) else {
            break;
        };
        memo.insert(
            line.x,
            Evaluation {
                metrics: line.m.iter().map(|r| floats(r)).collect(),
                failure: line.failure,
            },
        );
    }
    Ok(memo)
}

/// The history table: `evaluation`, `run`, `iteration`, one column per parameter, each
/// metric (mean over the scenarios; with several scenarios also `metric@scenario`),
/// `objective`, `violation`, `feasible`, `best_so_far` (the objective of the best point up
/// to this row, NaN while none is feasible), `repeat`, `failure`.
pub fn history_table(
    records: &[Record],
    params: &[String],
    metrics: &[String],
    scenarios: &[String],
) -> Result<Table, crate::report::ReportError> {
    let mut cols: Vec<Column> = Vec::new();
    let col = |name: &str, data: ColumnData| Column {
        name: name.to_string(),
        data,
    };
    let ints = |f: &dyn Fn(&Record) -> i64| ColumnData::I64(records.iter().map(f).collect());
    let reals = |f: &dyn Fn(&Record) -> f64| ColumnData::F64(records.iter().map(f).collect());
    cols.push(col("evaluation", ints(&|r| r.index as i64)));
    cols.push(col("run", ints(&|r| r.run as i64)));
    cols.push(col("iteration", ints(&|r| r.iteration as i64)));
    for (k, p) in params.iter().enumerate() {
        cols.push(col(p, reals(&|r| r.x[k])));
    }
    for (k, m) in metrics.iter().enumerate() {
        cols.push(col(m, reals(&|r| mean_of(&r.metrics, k))));
        if scenarios.len() > 1 {
            for (v, name) in scenarios.iter().enumerate() {
                let one = |r: &Record| {
                    r.metrics
                        .get(v)
                        .and_then(|s| s.get(k))
                        .copied()
                        .unwrap_or(f64::NAN)
                };
                cols.push(col(&format!("{m}@{name}"), reals(&one)));
            }
        }
    }
    cols.push(col("objective", reals(&|r| r.score.objective)));
    cols.push(col("violation", reals(&|r| r.score.violation)));
    cols.push(col(
        "feasible",
        ColumnData::Bool(records.iter().map(|r| r.score.feasible).collect()),
    ));
    cols.push(col("best_so_far", ColumnData::F64(best_so_far(records))));
    cols.push(col(
        "repeat",
        ColumnData::Bool(records.iter().map(|r| r.repeat).collect()),
    ));
    cols.push(col(
        "failure",
        ColumnData::Str(
            records
                .iter()
                .map(|r| crate::batch::records::reason_cell(r.failure.as_deref().unwrap_or("")))
                .collect(),
        ),
    ));
    Table::from_columns(cols)
}

/// The objective of the best feasible point up to each record (NaN before the first).
pub fn best_so_far(records: &[Record]) -> Vec<f64> {
    let mut best: Option<Score> = None;
    records
        .iter()
        .map(|r| {
            if best.is_none_or(|b| r.score.better_than(&b)) {
                best = Some(r.score);
            }
            best.filter(|b| b.feasible)
                .map_or(f64::NAN, |b| b.objective)
        })
        .collect()
}

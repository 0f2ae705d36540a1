//! Result records of a sweep: the columns of the raw (partial) and final tables, one finished
//! case as a [`Row`] (its metrics by name), and the table operations between them (compaction
//! and the final table with the journal's run metrics unpacked). The case status and the
//! design and TCM column names are the evaluator's ([`crate::evaluate`]), re-exported here.
//!
//! The text of these tables is the contract with resumed runs, merges and reports: statuses
//! and column names are written and read only through the items here.

use std::collections::{HashMap, HashSet};

use crate::evaluate::{CaseResult, Metrics};
use crate::report::{format_f64, Column, ColumnData, ColumnKind, Table, Value};
use crate::study::error::StudyError;
use crate::study::schema::Study;

pub use crate::evaluate::metrics::{
    AUTHORITY_COLUMNS, DESIGN_COLUMNS, DESIGN_THRUSTERS, TCM_COLUMNS, TCM_SINGULAR_FRACTION,
    TCM_STRAIGHT_SIGMA_MIN,
};
pub use crate::evaluate::{CaseEnd, CaseStatus};

/// Cases by status.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatusCounts {
    /// `ok` cases.
    pub ok: usize,
    /// `unsuccessful` cases.
    pub unsuccessful: usize,
    /// `failed` cases.
    pub failed: usize,
    /// `skipped` cases.
    pub skipped: usize,
}

impl StatusCounts {
    /// Count one case.
    pub fn add(&mut self, s: CaseStatus) {
        match s {
            CaseStatus::Ok => self.ok += 1,
            CaseStatus::Unsuccessful => self.unsuccessful += 1,
            CaseStatus::Failed => self.failed += 1,
            CaseStatus::Skipped => self.skipped += 1,
        }
    }

    /// The counts of the `status` column of `table` (other texts are not counted).
    pub fn of_table(table: &Table) -> Result<Self, StudyError> {
        let mut c = StatusCounts::default();
        for s in table
            .str(STATUS)?
            .iter()
            .filter_map(|s| CaseStatus::parse(s))
        {
            c.add(s);
        }
        Ok(c)
    }
}

/// The raw rows, appended as cases finish, compacted at the end.
pub const PARTIAL_FILE: &str = "cases.partial.csv";
/// Beside the journal: the hash of the study that wrote it (which includes the build identity,
/// [`crate::study::hash::BUILD_ID`]). `--resume` reuses the journal only when it matches.
pub const PARTIAL_STUDY_FILE: &str = "cases.partial.study";
/// The final table as CSV.
pub const CASES_CSV: &str = "cases.csv";
/// The final table as Parquet.
pub const CASES_PARQUET: &str = "cases.parquet";
/// The copy of the study file in an output directory.
pub const STUDY_COPY: &str = "study.toml";

/// The best or the worst case by the objective (their trajectories are rerun for the report).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extreme {
    /// The best case.
    Best,
    /// The worst case.
    Worst,
}

impl Extreme {
    /// Both, best first.
    pub const BOTH: [Extreme; 2] = [Extreme::Best, Extreme::Worst];

    /// `best` or `worst` (series label and file-name part).
    pub fn label(self) -> &'static str {
        match self {
            Extreme::Best => "best",
            Extreme::Worst => "worst",
        }
    }

    /// The file holding the case's trajectory: `trajectory_<label>.csv`.
    pub fn trajectory_file(self) -> String {
        format!("trajectory_{}.csv", self.label())
    }
}

/// Case id column (i64, dense from 0).
pub const CASE_ID: &str = "case_id";
/// Case hash column (hex).
pub const HASH: &str = "hash";
/// Status column (see [`CaseStatus`]).
pub const STATUS: &str = "status";
/// Reason column (why a case failed or was skipped; one line).
pub const REASON: &str = "reason";

/// Fixed leading columns of the raw (partial) table; the final table has the first two
/// first and the last two last.
pub const RAW_HEAD: [&str; 4] = [CASE_ID, HASH, STATUS, REASON];

/// Raw column packing the scenario metrics of dynamic modes (`name=value;…`).
pub const SCENARIO_METRICS_COLUMN: &str = "scenario_metrics";

/// The raw (partial-file) schema of a study.
pub fn raw_schema(study: &Study) -> Vec<(String, ColumnKind)> {
    let mut s: Vec<(String, ColumnKind)> = vec![
        (CASE_ID.into(), ColumnKind::I64),
        (HASH.into(), ColumnKind::Str),
        (STATUS.into(), ColumnKind::Str),
        (REASON.into(), ColumnKind::Str),
    ];
    for a in &study.axes {
        let k = if a.numeric {
            ColumnKind::F64
        } else {
            ColumnKind::Str
        };
        s.push((a.name.clone(), k));
    }
    s.extend(
        DESIGN_COLUMNS
            .iter()
            .map(|c| (c.to_string(), ColumnKind::F64)),
    );
    if study.static_enabled {
        s.extend(
            TCM_COLUMNS
                .iter()
                .chain(&AUTHORITY_COLUMNS)
                .map(|c| (c.to_string(), ColumnKind::F64)),
        );
    }
    s.extend(
        study
            .tune_columns()
            .into_iter()
            .chain(study.ocp_columns())
            .map(|c| (c, ColumnKind::F64)),
    );
    if study.mode.is_dynamic() {
        s.push((SCENARIO_METRICS_COLUMN.into(), ColumnKind::Str));
    }
    s
}

/// The named metric columns of a study's raw rows, in raw-schema order: design, TCM (with
/// the static analysis), tuning and optimal-control bound columns. Every other metric of a row is a run metric,
/// packed into [`SCENARIO_METRICS_COLUMN`] in the journal.
pub fn metric_columns(study: &Study) -> Vec<String> {
    let mut c: Vec<String> = DESIGN_COLUMNS.iter().map(|n| n.to_string()).collect();
    if study.static_enabled {
        c.extend(
            TCM_COLUMNS
                .iter()
                .chain(&AUTHORITY_COLUMNS)
                .map(|n| n.to_string()),
        );
    }
    c.extend(study.tune_columns());
    c.extend(study.ocp_columns());
    c
}

/// Text of a non-numeric axis value.
pub fn axis_text(v: &toml::Value) -> String {
    crate::report::fmt_value(v)
}

fn axis_number(v: &toml::Value) -> f64 {
    match v {
        toml::Value::Float(f) => *f,
        toml::Value::Integer(i) => *i as f64,
        _ => f64::NAN,
    }
}

/// A message on one line (newlines become spaces), as the `reason` column holds it.
pub fn reason_cell(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

/// The journal's cell of a row's run metrics (those not in `columns`): `name=value;…`, with
/// `=`, `;` and white space in names replaced by `_` and values in the tables' float format.
/// It exists only in `cases.partial.csv` (decoded again by [`final_table`]): the journal's
/// columns are fixed before any case runs, the run metrics are not.
fn pack_metrics(metrics: &Metrics, columns: &[String]) -> String {
    let mut packed = String::new();
    for (name, x) in metrics
        .iter()
        .filter(|(n, _)| !columns.iter().any(|c| c == n))
    {
        let clean: String = name
            .chars()
            .map(|c| {
                if c == '=' || c == ';' || c.is_whitespace() {
                    '_'
                } else {
                    c
                }
            })
            .collect();
        if !packed.is_empty() {
            packed.push(';');
        }
        packed.push_str(&clean);
        packed.push('=');
        packed.push_str(&format_f64(x));
    }
    packed
}

/// One finished case, as written to the partial file.
#[derive(Clone, Debug)]
pub struct Row {
    /// Case id.
    pub id: usize,
    /// Case hash.
    pub hash: String,
    /// How the case ended ([`CaseEnd::status`] is its `status` cell).
    pub end: CaseEnd,
    /// Why it failed or was skipped (single line, for people).
    pub reason: String,
    /// Axis values.
    pub axes: Vec<toml::Value>,
    /// The case's metrics by name (design, TCM, run and tuning metrics; a column the case
    /// did not compute is NaN).
    pub metrics: Metrics,
}

impl Row {
    /// An `ok` row without metrics for case `id`.
    pub fn new(id: usize, hash: String, axes: Vec<toml::Value>) -> Self {
        Row {
            id,
            hash,
            end: CaseEnd::Ok,
            reason: String::new(),
            axes,
            metrics: Metrics::new(),
        }
    }

    /// The row of case `id` from its evaluation.
    pub fn from_result(id: usize, hash: String, axes: Vec<toml::Value>, r: CaseResult) -> Self {
        Row {
            id,
            hash,
            end: r.end,
            reason: reason_cell(&r.reason),
            axes,
            metrics: r.metrics,
        }
    }

    /// Mark the row as ended with `end` for `reason` (made one line).
    pub fn end(&mut self, end: CaseEnd, reason: &str) {
        self.end = end;
        self.reason = reason_cell(reason);
    }

    /// The journal's text of the row's run metrics (see [`pack_metrics`]; empty for static
    /// studies, which have no such column).
    pub fn packed(&self, study: &Study) -> String {
        if study.mode.is_dynamic() {
            pack_metrics(&self.metrics, &metric_columns(study))
        } else {
            String::new()
        }
    }

    /// The cells in raw-schema order; `texts` are the axis values as text, `packed` is
    /// [`Row::packed`].
    pub fn values<'a>(
        &'a self,
        study: &Study,
        texts: &'a [String],
        packed: &'a str,
    ) -> Vec<Value<'a>> {
        let mut v: Vec<Value<'a>> = vec![
            Value::I64(self.id as i64),
            Value::Str(&self.hash),
            Value::Str(self.end.status().as_str()),
            Value::Str(&self.reason),
        ];
        for ((a, x), t) in study.axes.iter().zip(&self.axes).zip(texts) {
            v.push(if a.numeric {
                Value::F64(axis_number(x))
            } else {
                Value::Str(t)
            });
        }
        v.extend(
            metric_columns(study)
                .iter()
                .map(|c| Value::F64(self.metrics.value(c))),
        );
        if study.mode.is_dynamic() {
            v.push(Value::Str(packed));
        }
        v
    }
}

/// Sort raw rows by case id, drop duplicates (by hash, first kept) and, when `keep` is
/// given, rows whose hash is not in it.
pub fn compact(raw: &Table, keep: Option<&HashSet<String>>) -> Result<Table, StudyError> {
    let ids = raw.i64(CASE_ID)?;
    let hashes = raw.str(HASH)?;
    let mut order: Vec<usize> = (0..raw.n_rows())
        .filter(|&i| keep.is_none_or(|k| k.contains(&hashes[i])))
        .collect();
    order.sort_by(|&a, &b| {
        ids[a]
            .cmp(&ids[b])
            .then(hashes[a].cmp(&hashes[b]))
            .then(a.cmp(&b))
    });
    let mut seen = HashSet::new();
    order.retain(|&i| seen.insert(hashes[i].as_str()));
    Ok(raw.select_rows(&order)?)
}

/// The final table from compacted raw rows: `case_id`, `hash`, axes and metrics (scenario
/// metrics unpacked into columns in order of first appearance), `status`, `reason`.
pub fn final_table(raw: Table) -> Result<Table, StudyError> {
    // Columns are moved, not copied: the raw and the final table of a large study never
    // coexist (issue 11: the 100 000-case static study's peak memory).
    let mut head: Vec<Option<Column>> = vec![None, None];
    let mut tail: Vec<Option<Column>> = vec![None, None];
    let mut cols: Vec<Column> = Vec::new();
    let mut packed: Option<Vec<String>> = None;
    for c in raw.columns {
        if let Some(k) = [CASE_ID, HASH].iter().position(|n| *n == c.name) {
            head[k] = Some(c);
        } else if let Some(k) = [STATUS, REASON].iter().position(|n| *n == c.name) {
            tail[k] = Some(c);
        } else if c.name == SCENARIO_METRICS_COLUMN {
            match c.data {
                ColumnData::Str(v) => packed = Some(v),
                _ => {
                    return Err(StudyError::Input(format!(
                        "column {SCENARIO_METRICS_COLUMN} is not text"
                    )))
                }
            }
        } else {
            cols.push(c);
        }
    }
    if let Some(p) = &packed {
        for (n, d) in unpack_metrics(p) {
            if cols.iter().any(|c| c.name == n)
                || [CASE_ID, HASH, STATUS, REASON].contains(&n.as_str())
            {
                continue;
            }
            cols.push(Column {
                name: n,
                data: ColumnData::F64(d),
            });
        }
    }
    let mut cols: Vec<Column> = head.into_iter().flatten().chain(cols).collect();
    cols.extend(tail.into_iter().flatten());
    Ok(Table::from_columns(cols)?)
}

/// Packed scenario metrics (one cell per row) as columns `(name, values)`, in order of first
/// appearance; NaN where a row lacks a metric or its value does not parse.
fn unpack_metrics(cells: &[String]) -> Vec<(String, Vec<f64>)> {
    let mut names: Vec<String> = Vec::new();
    let mut index: HashMap<String, usize> = HashMap::new();
    let parsed: Vec<Vec<(usize, f64)>> = cells
        .iter()
        .map(|s| {
            s.split(';')
                .filter(|x| !x.is_empty())
                .filter_map(|kv| {
                    let (k, v) = kv.split_once('=')?;
                    let i = *index.entry(k.to_string()).or_insert_with(|| {
                        names.push(k.to_string());
                        names.len() - 1
                    });
                    Some((i, v.parse::<f64>().unwrap_or(f64::NAN)))
                })
                .collect()
        })
        .collect();
    let mut data = vec![vec![f64::NAN; cells.len()]; names.len()];
    for (r, kvs) in parsed.iter().enumerate() {
        for &(i, x) in kvs {
            data[i][r] = x;
        }
    }
    names.into_iter().zip(data).collect()
}

//! Column-oriented result tables and their CSV / Parquet files.
//!
//! # File formats
//!
//! CSV files are written by polars with a header line, `,` as separator, `\n` line ends, and
//! quotes only where necessary (a string that is empty or holds `,`, `"`, `\n` or `\r`; inner
//! quotes are doubled). Values are formatted as:
//!
//! | type | format |
//! |---|---|
//! | `f64` | shortest decimal that round-trips ([`format_f64`]): positional when the decimal exponent is in `-5..=15` and always with a `.` (`1.0`, `-0.0`, `0.00001`, `123.45`), otherwise scientific (`1e-6`, `1.5e+16`, `5e-324`); `NaN`, `inf`, `-inf` |
//! | `i64` | decimal integer |
//! | `bool` | `true` / `false` |
//! | `str` | the text, quoted as above |
//!
//! This is the format of polars' own float writer (the `zmij` crate), so [`CsvAppender`] (plain
//! std I/O) and [`write_csv`] produce identical bytes for identical tables, and reading a file back
//! and writing it again is stable. Every `f64` (including NaN, ±inf, -0.0, subnormals, ±`f64::MAX`)
//! is read back bit-exactly except that all NaNs read back as the canonical quiet NaN.
//!
//! Because floats always carry a `.`, an `e` or a NaN/inf token, [`read_csv`] infers `f64`,
//! `i64`, `bool` and `str` columns correctly, except for a string column whose every value looks
//! like a number or a boolean, and for a file without rows (every column then reads as `str`).
//! Use [`read_csv_typed`] (explicit schema) or Parquet where that matters.
//!
//! Parquet files are written by polars with its default settings (zstd compression); they keep
//! the exact schema.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use polars::prelude::{
    Column as PlColumn, CsvReadOptions, CsvWriter, DataFrame, DataType, Field, ParquetReader,
    ParquetWriter, PlSmallStr, Schema, SerReader, SerWriter,
};

use super::{atomic_write, ReportError, Result};

/// The type of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ColumnKind {
    /// 64-bit floats.
    F64,
    /// 64-bit signed integers.
    I64,
    /// UTF-8 strings.
    Str,
    /// Booleans.
    Bool,
}

impl std::fmt::Display for ColumnKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ColumnKind::F64 => "f64",
            ColumnKind::I64 => "i64",
            ColumnKind::Str => "str",
            ColumnKind::Bool => "bool",
        })
    }
}

impl ColumnKind {
    fn dtype(self) -> DataType {
        match self {
            ColumnKind::F64 => DataType::Float64,
            ColumnKind::I64 => DataType::Int64,
            ColumnKind::Str => DataType::String,
            ColumnKind::Bool => DataType::Boolean,
        }
    }
}

/// The values of one column.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    /// 64-bit floats (NaN and ±inf allowed).
    F64(Vec<f64>),
    /// 64-bit signed integers.
    I64(Vec<i64>),
    /// UTF-8 strings.
    Str(Vec<String>),
    /// Booleans.
    Bool(Vec<bool>),
}

impl ColumnData {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            ColumnData::F64(v) => v.len(),
            ColumnData::I64(v) => v.len(),
            ColumnData::Str(v) => v.len(),
            ColumnData::Bool(v) => v.len(),
        }
    }

    /// Whether the column holds no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The column's type.
    pub fn kind(&self) -> ColumnKind {
        match self {
            ColumnData::F64(_) => ColumnKind::F64,
            ColumnData::I64(_) => ColumnKind::I64,
            ColumnData::Str(_) => ColumnKind::Str,
            ColumnData::Bool(_) => ColumnKind::Bool,
        }
    }

    /// An empty column of the given type.
    pub fn empty(kind: ColumnKind) -> Self {
        match kind {
            ColumnKind::F64 => ColumnData::F64(Vec::new()),
            ColumnKind::I64 => ColumnData::I64(Vec::new()),
            ColumnKind::Str => ColumnData::Str(Vec::new()),
            ColumnKind::Bool => ColumnData::Bool(Vec::new()),
        }
    }

    /// The value in row `i`, if any.
    pub fn get(&self, i: usize) -> Option<Value<'_>> {
        match self {
            ColumnData::F64(v) => v.get(i).map(|&x| Value::F64(x)),
            ColumnData::I64(v) => v.get(i).map(|&x| Value::I64(x)),
            ColumnData::Str(v) => v.get(i).map(|x| Value::Str(x)),
            ColumnData::Bool(v) => v.get(i).map(|&x| Value::Bool(x)),
        }
    }

    /// The values at `indices`, in that order (indices must be in range: checked by callers).
    fn take(&self, indices: &[usize]) -> Self {
        match self {
            ColumnData::F64(v) => ColumnData::F64(indices.iter().map(|&i| v[i]).collect()),
            ColumnData::I64(v) => ColumnData::I64(indices.iter().map(|&i| v[i]).collect()),
            ColumnData::Str(v) => ColumnData::Str(indices.iter().map(|&i| v[i].clone()).collect()),
            ColumnData::Bool(v) => ColumnData::Bool(indices.iter().map(|&i| v[i]).collect()),
        }
    }

    /// Appends the values of `other`, which must have the same kind (checked by callers).
    fn extend_from(&mut self, other: &ColumnData) {
        match (self, other) {
            (ColumnData::F64(a), ColumnData::F64(b)) => a.extend_from_slice(b),
            (ColumnData::I64(a), ColumnData::I64(b)) => a.extend_from_slice(b),
            (ColumnData::Str(a), ColumnData::Str(b)) => a.extend_from_slice(b),
            (ColumnData::Bool(a), ColumnData::Bool(b)) => a.extend_from_slice(b),
            _ => {}
        }
    }

    fn to_polars(&self, name: &str) -> PlColumn {
        let name = PlSmallStr::from_str(name);
        match self {
            ColumnData::F64(v) => PlColumn::new(name, v.as_slice()),
            ColumnData::I64(v) => PlColumn::new(name, v.as_slice()),
            ColumnData::Str(v) => PlColumn::new(name, v.as_slice()),
            ColumnData::Bool(v) => PlColumn::new(name, v.as_slice()),
        }
    }
}

impl From<Vec<f64>> for ColumnData {
    fn from(v: Vec<f64>) -> Self {
        ColumnData::F64(v)
    }
}
impl From<Vec<i64>> for ColumnData {
    fn from(v: Vec<i64>) -> Self {
        ColumnData::I64(v)
    }
}
impl From<Vec<String>> for ColumnData {
    fn from(v: Vec<String>) -> Self {
        ColumnData::Str(v)
    }
}
impl From<Vec<&str>> for ColumnData {
    fn from(v: Vec<&str>) -> Self {
        ColumnData::Str(v.into_iter().map(str::to_owned).collect())
    }
}
impl From<Vec<bool>> for ColumnData {
    fn from(v: Vec<bool>) -> Self {
        ColumnData::Bool(v)
    }
}

/// One value of a row (borrowed for strings).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value<'a> {
    /// A float.
    F64(f64),
    /// An integer.
    I64(i64),
    /// A string.
    Str(&'a str),
    /// A boolean.
    Bool(bool),
}

impl Value<'_> {
    /// The value's type.
    pub fn kind(&self) -> ColumnKind {
        match self {
            Value::F64(_) => ColumnKind::F64,
            Value::I64(_) => ColumnKind::I64,
            Value::Str(_) => ColumnKind::Str,
            Value::Bool(_) => ColumnKind::Bool,
        }
    }
}

impl From<f64> for Value<'_> {
    fn from(v: f64) -> Self {
        Value::F64(v)
    }
}
impl From<i64> for Value<'_> {
    fn from(v: i64) -> Self {
        Value::I64(v)
    }
}
impl<'a> From<&'a str> for Value<'a> {
    fn from(v: &'a str) -> Self {
        Value::Str(v)
    }
}
impl From<bool> for Value<'_> {
    fn from(v: bool) -> Self {
        Value::Bool(v)
    }
}

/// A named column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// The column name (unique within a table; put units in it, e.g. `energy_J`).
    pub name: String,
    /// The values.
    pub data: ColumnData,
}

/// A column-oriented table: named, typed columns of equal length.
///
/// Equality (`PartialEq`) is value equality, so tables holding NaN are never equal; use
/// [`Table::bit_eq`] to compare tables bit for bit.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// The columns, in file order.
    pub columns: Vec<Column>,
}

impl Table {
    /// An empty table (no columns, no rows).
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of rows (0 for a table without columns).
    pub fn n_rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.data.len())
    }

    /// Number of columns.
    pub fn n_cols(&self) -> usize {
        self.columns.len()
    }

    /// Appends a column. Errors if the name is taken or the length differs from the table's row
    /// count (the first column sets the row count).
    pub fn push(&mut self, name: impl Into<String>, data: impl Into<ColumnData>) -> Result<()> {
        let name = name.into();
        let data = data.into();
        if self.columns.iter().any(|c| c.name == name) {
            return Err(ReportError::DuplicateColumn { name });
        }
        if !self.columns.is_empty() && data.len() != self.n_rows() {
            return Err(ReportError::LengthMismatch {
                column: name,
                expected: self.n_rows(),
                found: data.len(),
            });
        }
        self.columns.push(Column { name, data });
        Ok(())
    }

    /// Builder form of [`Table::push`].
    pub fn with(mut self, name: impl Into<String>, data: impl Into<ColumnData>) -> Result<Self> {
        self.push(name, data)?;
        Ok(self)
    }

    /// Builds a table from columns, checking unique names and equal lengths.
    pub fn from_columns(columns: Vec<Column>) -> Result<Self> {
        let mut t = Table::new();
        for c in columns {
            t.push(c.name, c.data)?;
        }
        Ok(t)
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    fn require(&self, name: &str) -> Result<&Column> {
        self.column(name).ok_or_else(|| ReportError::MissingColumn {
            name: name.to_owned(),
        })
    }

    fn type_error(c: &Column, expected: ColumnKind) -> ReportError {
        ReportError::TypeMismatch {
            column: c.name.clone(),
            expected,
            found: c.data.kind(),
        }
    }

    /// The values of the `f64` column `name`.
    pub fn f64(&self, name: &str) -> Result<&[f64]> {
        let c = self.require(name)?;
        match &c.data {
            ColumnData::F64(v) => Ok(v),
            _ => Err(Self::type_error(c, ColumnKind::F64)),
        }
    }

    /// The values of the `i64` column `name`.
    pub fn i64(&self, name: &str) -> Result<&[i64]> {
        let c = self.require(name)?;
        match &c.data {
            ColumnData::I64(v) => Ok(v),
            _ => Err(Self::type_error(c, ColumnKind::I64)),
        }
    }

    /// The values of the string column `name`.
    pub fn str(&self, name: &str) -> Result<&[String]> {
        let c = self.require(name)?;
        match &c.data {
            ColumnData::Str(v) => Ok(v),
            _ => Err(Self::type_error(c, ColumnKind::Str)),
        }
    }

    /// The values of the boolean column `name`.
    pub fn bool(&self, name: &str) -> Result<&[bool]> {
        let c = self.require(name)?;
        match &c.data {
            ColumnData::Bool(v) => Ok(v),
            _ => Err(Self::type_error(c, ColumnKind::Bool)),
        }
    }

    /// Column names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.columns.iter().map(|c| c.name.as_str()).collect()
    }

    /// The schema: column names and types, in order.
    pub fn schema(&self) -> Vec<(String, ColumnKind)> {
        self.columns
            .iter()
            .map(|c| (c.name.clone(), c.data.kind()))
            .collect()
    }

    /// An empty table with the given schema.
    pub fn empty_with_schema(schema: &[(String, ColumnKind)]) -> Result<Self> {
        let mut t = Table::new();
        for (name, kind) in schema {
            t.push(name.clone(), ColumnData::empty(*kind))?;
        }
        Ok(t)
    }

    /// Row `i` as values, one per column.
    pub fn row(&self, i: usize) -> Result<Vec<Value<'_>>> {
        self.columns
            .iter()
            .map(|c| c.data.get(i))
            .collect::<Option<Vec<_>>>()
            .ok_or(ReportError::RowOutOfRange {
                index: i,
                rows: self.n_rows(),
            })
    }

    /// A new table with the rows at `indices`, in that order (repeats allowed).
    pub fn select_rows(&self, indices: &[usize]) -> Result<Table> {
        let rows = self.n_rows();
        if let Some(&index) = indices.iter().find(|&&i| i >= rows) {
            return Err(ReportError::RowOutOfRange { index, rows });
        }
        Ok(Table {
            columns: self
                .columns
                .iter()
                .map(|c| Column {
                    name: c.name.clone(),
                    data: c.data.take(indices),
                })
                .collect(),
        })
    }

    /// The row permutation that sorts the table by column `name`, ascending and stable.
    ///
    /// Floats are ordered by [`f64::total_cmp`] (so -0.0 before 0.0, NaN last unless negative),
    /// strings bytewise, `false` before `true`.
    pub fn argsort(&self, name: &str) -> Result<Vec<usize>> {
        let c = self.require(name)?;
        let mut idx: Vec<usize> = (0..c.data.len()).collect();
        match &c.data {
            ColumnData::F64(v) => idx.sort_by(|&a, &b| v[a].total_cmp(&v[b])),
            ColumnData::I64(v) => idx.sort_by_key(|&a| v[a]),
            ColumnData::Str(v) => idx.sort_by(|&a, &b| v[a].cmp(&v[b])),
            ColumnData::Bool(v) => idx.sort_by_key(|&a| v[a]),
        }
        Ok(idx)
    }

    /// Sorts the rows in place by column `name` (see [`Table::argsort`] for the order).
    pub fn sort_by_column(&mut self, name: &str) -> Result<()> {
        let idx = self.argsort(name)?;
        *self = self.select_rows(&idx)?;
        Ok(())
    }

    /// Concatenates tables row-wise. All tables must have the same column names and types in the
    /// same order; otherwise the error names the first differing column. An empty slice gives an
    /// empty table.
    pub fn concat(tables: &[Table]) -> Result<Table> {
        let Some(first) = tables.first() else {
            return Ok(Table::new());
        };
        let mut out = first.clone();
        for t in &tables[1..] {
            check_same_schema(&first.schema(), &t.schema())?;
            for (o, c) in out.columns.iter_mut().zip(&t.columns) {
                o.data.extend_from(&c.data);
            }
        }
        Ok(out)
    }

    /// Bitwise equality: same schema and every value identical (floats compared by bits, so
    /// NaN equals NaN with the same payload and -0.0 differs from 0.0).
    pub fn bit_eq(&self, other: &Table) -> bool {
        self.columns.len() == other.columns.len()
            && self.columns.iter().zip(&other.columns).all(|(a, b)| {
                a.name == b.name
                    && match (&a.data, &b.data) {
                        (ColumnData::F64(x), ColumnData::F64(y)) => {
                            x.len() == y.len()
                                && x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits())
                        }
                        (x, y) => x == y,
                    }
            })
    }

    fn to_dataframe(&self) -> std::result::Result<DataFrame, String> {
        let cols = self
            .columns
            .iter()
            .map(|c| c.data.to_polars(&c.name))
            .collect();
        DataFrame::new(self.n_rows(), cols).map_err(|e| e.to_string())
    }

    fn from_dataframe(df: &DataFrame, path: &Path) -> Result<Table> {
        let mut t = Table::new();
        for col in df.columns() {
            let name = col.name().as_str().to_owned();
            let bad = |detail: String| ReportError::UnsupportedColumn {
                path: path.to_path_buf(),
                column: name.clone(),
                detail,
            };
            let pl = |e: polars::prelude::PolarsError| bad(e.to_string());
            let missing = |row: usize| bad(format!("missing value in row {row}"));
            let data = match col.dtype() {
                DataType::Float64 | DataType::Float32 => {
                    let c = col.cast(&DataType::Float64).map_err(pl)?;
                    // A missing float (empty CSV field) reads as NaN.
                    let v = c.f64().map_err(pl)?.iter().map(|x| x.unwrap_or(f64::NAN));
                    ColumnData::F64(v.collect())
                }
                DataType::Int64
                | DataType::Int32
                | DataType::Int16
                | DataType::Int8
                | DataType::UInt32
                | DataType::UInt16
                | DataType::UInt8 => {
                    let c = col.cast(&DataType::Int64).map_err(pl)?;
                    let ca = c.i64().map_err(pl)?;
                    let mut v = Vec::with_capacity(ca.len());
                    for (row, x) in ca.iter().enumerate() {
                        v.push(x.ok_or_else(|| missing(row))?);
                    }
                    ColumnData::I64(v)
                }
                DataType::Boolean => {
                    let ca = col.bool().map_err(pl)?;
                    let mut v = Vec::with_capacity(ca.len());
                    for (row, x) in ca.iter().enumerate() {
                        v.push(x.ok_or_else(|| missing(row))?);
                    }
                    ColumnData::Bool(v)
                }
                DataType::String => {
                    // A missing string reads as the empty string.
                    let ca = col.str().map_err(pl)?;
                    ColumnData::Str(ca.iter().map(|x| x.unwrap_or("").to_owned()).collect())
                }
                DataType::Null => ColumnData::Str(vec![String::new(); col.len()]),
                other => return Err(bad(format!("type {other} is not supported"))),
            };
            t.push(name, data)?;
        }
        Ok(t)
    }
}

fn check_same_schema(
    expected: &[(String, ColumnKind)],
    found: &[(String, ColumnKind)],
) -> Result<()> {
    for i in 0..expected.len().max(found.len()) {
        match (expected.get(i), found.get(i)) {
            (Some(e), Some(f)) if e == f => {}
            (Some(e), Some(f)) if e.0 == f.0 => {
                return Err(ReportError::SchemaMismatch {
                    column: e.0.clone(),
                    detail: format!("type {} expected, found {}", e.1, f.1),
                })
            }
            (Some(e), Some(f)) => {
                return Err(ReportError::SchemaMismatch {
                    column: e.0.clone(),
                    detail: format!("column {} expected `{}`, found `{}`", i + 1, e.0, f.0),
                })
            }
            (Some(e), None) => {
                return Err(ReportError::SchemaMismatch {
                    column: e.0.clone(),
                    detail: "missing".to_owned(),
                })
            }
            (None, Some(f)) => {
                return Err(ReportError::SchemaMismatch {
                    column: f.0.clone(),
                    detail: "unexpected extra column".to_owned(),
                })
            }
            (None, None) => {}
        }
    }
    Ok(())
}

fn polars_err(path: &Path, action: &'static str) -> impl Fn(String) -> ReportError {
    let path = path.to_path_buf();
    move |message| ReportError::Polars {
        path: path.clone(),
        action,
        message,
    }
}

/// Writes `table` as CSV to `path` (atomically; format in the [module docs](self)).
/// The bytes depend only on the table's contents.
pub fn write_csv(table: &Table, path: &Path) -> Result<()> {
    let err = polars_err(path, "writing CSV");
    let mut df = table.to_dataframe().map_err(&err)?;
    let mut buf = Vec::new();
    CsvWriter::new(&mut buf)
        .include_header(true)
        .finish(&mut df)
        .map_err(|e| err(e.to_string()))?;
    atomic_write(path, &buf)
}

/// Writes `table` as Parquet to `path` (atomically, polars' default settings).
pub fn write_parquet(table: &Table, path: &Path) -> Result<()> {
    let err = polars_err(path, "writing Parquet");
    let mut df = table.to_dataframe().map_err(&err)?;
    let mut buf = Vec::new();
    ParquetWriter::new(&mut buf)
        .finish(&mut df)
        .map_err(|e| err(e.to_string()))?;
    atomic_write(path, &buf)
}

fn csv_options() -> CsvReadOptions {
    CsvReadOptions::default()
        .with_has_header(true)
        .with_infer_schema_length(None)
        .with_raise_if_empty(false)
}

fn read_csv_with(path: &Path, options: CsvReadOptions) -> Result<Table> {
    let err = polars_err(path, "reading CSV");
    // Open the file ourselves so that a missing file is a plain I/O error.
    let file = File::open(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        action: "opening",
        source,
    })?;
    let df = options
        .into_reader_with_file_handle(file)
        .finish()
        .map_err(|e| err(e.to_string()))?;
    Table::from_dataframe(&df, path)
}

/// Reads a CSV file with a header, inferring column types from all rows (see the
/// [module docs](self) for when inference can differ from the written types).
pub fn read_csv(path: &Path) -> Result<Table> {
    read_csv_with(path, csv_options())
}

/// Reads a CSV file and checks it against `schema` (names and order must match the header);
/// values are parsed as the given types, so string columns holding numbers stay strings and a
/// file without rows keeps its types.
pub fn read_csv_typed(path: &Path, schema: &[(String, ColumnKind)]) -> Result<Table> {
    let pl_schema: Schema = schema
        .iter()
        .map(|(n, k)| Field::new(PlSmallStr::from_str(n), k.dtype()))
        .collect();
    let options = csv_options().with_schema_overwrite(Some(Arc::new(pl_schema)));
    let t = read_csv_with(path, options)?;
    check_same_schema(schema, &t.schema()).map_err(|e| match e {
        ReportError::SchemaMismatch { column, detail } => ReportError::UnsupportedColumn {
            path: path.to_path_buf(),
            column,
            detail: format!("schema mismatch: {detail}"),
        },
        other => other,
    })?;
    Ok(t)
}

/// Reads a Parquet file (as written by [`write_parquet`] or any producer using the supported
/// types; other integer widths and `f32` are widened).
pub fn read_parquet(path: &Path) -> Result<Table> {
    let file = File::open(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        action: "opening",
        source,
    })?;
    let df = ParquetReader::new(file)
        .finish()
        .map_err(|e| polars_err(path, "reading Parquet")(e.to_string()))?;
    Table::from_dataframe(&df, path)
}

/// Formats a float exactly as the polars CSV writer does: the shortest decimal that parses back
/// to the same `f64`; positional with at least one fractional digit when the decimal exponent
/// `e` (value = d.ddd × 10^e) is in `-5..=15`, scientific `d.ddde±x` otherwise; `NaN`, `inf`,
/// `-inf` for the non-finite values; `-0.0` keeps its sign.
pub fn format_f64(v: f64) -> String {
    if v.is_nan() {
        return "NaN".to_owned();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf" } else { "-inf" }.to_owned();
    }
    // `{:e}` gives the shortest round-trip digits: "-1.2345e-7", "1e16", "0e0", "-0e0". When
    // several decimals of that length round-trip, polars (zmij) prints the one closest to the
    // exact binary value (ties to even), which is the correctly rounded one at that precision.
    let shortest = format!("{v:e}");
    let n_digits = shortest
        .split('e')
        .next()
        .unwrap_or("")
        .bytes()
        .filter(u8::is_ascii_digit)
        .count();
    let closest = format!("{v:.prec$e}", prec = n_digits.saturating_sub(1));
    let sci = if closest.parse::<f64>().map(f64::to_bits) == Ok(v.to_bits()) {
        closest
    } else {
        shortest
    };
    let (mantissa, exp) = sci.split_once('e').unwrap_or((sci.as_str(), "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let (sign, mantissa) = match mantissa.strip_prefix('-') {
        Some(m) => ("-", m),
        None => ("", mantissa),
    };
    if !(-5..=15).contains(&exp) {
        let exp_sign = if exp > 0 { "+" } else { "" };
        return format!("{sign}{mantissa}e{exp_sign}{exp}");
    }
    let digits: String = mantissa.chars().filter(|c| *c != '.').collect();
    let mut out = String::with_capacity(digits.len() + 8);
    out.push_str(sign);
    if exp >= 0 {
        let int_len = exp as usize + 1;
        if digits.len() <= int_len {
            out.push_str(&digits);
            out.extend(std::iter::repeat_n('0', int_len - digits.len()));
            out.push_str(".0");
        } else {
            out.push_str(&digits[..int_len]);
            out.push('.');
            out.push_str(&digits[int_len..]);
        }
    } else {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', (-exp - 1) as usize));
        out.push_str(&digits);
    }
    out
}

/// Appends `s` to `buf` quoted the way polars does with its default (`Necessary`) quote style.
fn push_csv_str(buf: &mut String, s: &str) {
    if s.is_empty() {
        buf.push_str("\"\"");
    } else if s.contains([',', '"', '\n', '\r']) {
        buf.push('"');
        buf.push_str(&s.replace('"', "\"\""));
        buf.push('"');
    } else {
        buf.push_str(s);
    }
}

fn push_csv_value(buf: &mut String, v: &Value<'_>) {
    match v {
        Value::F64(x) => buf.push_str(&format_f64(*x)),
        Value::I64(x) => buf.push_str(&x.to_string()),
        Value::Str(s) => push_csv_str(buf, s),
        Value::Bool(b) => buf.push_str(if *b { "true" } else { "false" }),
    }
}

fn csv_header_line(schema: &[(String, ColumnKind)]) -> String {
    let mut line = String::new();
    for (i, (name, _)) in schema.iter().enumerate() {
        if i > 0 {
            line.push(',');
        }
        push_csv_str(&mut line, name);
    }
    line.push('\n');
    line
}

/// Streams rows into a CSV file during a long sweep, so that an interrupted run keeps every
/// finished row.
///
/// Plain std I/O: each row is formatted into one line and written with a single `write_all`
/// on the unbuffered file (no data sits in a user-space buffer after [`CsvAppender::append`]
/// returns). The bytes are identical to [`write_csv`] of the same table (same header quoting,
/// float format [`format_f64`], `true`/`false`, integers in decimal), so reading the file back
/// and writing it with polars reproduces it exactly.
#[derive(Debug)]
pub struct CsvAppender {
    path: PathBuf,
    file: File,
    schema: Vec<(String, ColumnKind)>,
    rows: usize,
    line: String,
}

impl CsvAppender {
    /// Creates (or truncates) `path` and writes the header for `schema`.
    pub fn create(path: &Path, schema: &[(String, ColumnKind)]) -> Result<Self> {
        check_schema_names(schema)?;
        let mut file = File::create(path).map_err(|source| ReportError::Io {
            path: path.to_path_buf(),
            action: "creating",
            source,
        })?;
        file.write_all(csv_header_line(schema).as_bytes())
            .map_err(|source| ReportError::Io {
                path: path.to_path_buf(),
                action: "writing header to",
                source,
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            schema: schema.to_vec(),
            rows: 0,
            line: String::new(),
        })
    }

    /// Opens `path` to resume appending, or creates it if missing or empty.
    ///
    /// An existing file must start with exactly the header of `schema` (else
    /// [`ReportError::SchemaMismatch`]). A trailing partial line (a row cut off by an
    /// interruption) is removed. [`CsvAppender::rows_written`] then counts the complete rows
    /// already in the file (lines after the header; strings with embedded newlines count once
    /// per line, so prefer single-line strings in streamed tables).
    pub fn open_or_create(path: &Path, schema: &[(String, ColumnKind)]) -> Result<Self> {
        let io = |action: &'static str| {
            move |source| ReportError::Io {
                path: path.to_path_buf(),
                action,
                source,
            }
        };
        let existing = match std::fs::read(path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
            Err(e) => return Err(io("reading")(e)),
        };
        let header = csv_header_line(schema);
        if existing.len() < header.len() && header.as_bytes().starts_with(&existing) {
            // Missing, empty, or interrupted while writing the header.
            return Self::create(path, schema);
        }
        check_schema_names(schema)?;
        if !existing.starts_with(header.as_bytes()) {
            let found = existing.split(|&b| b == b'\n').next().unwrap_or(&[]);
            return Err(ReportError::SchemaMismatch {
                column: path.display().to_string(),
                detail: format!(
                    "existing header `{}` differs from `{}`",
                    String::from_utf8_lossy(found),
                    header.trim_end()
                ),
            });
        }
        let keep = existing
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |p| p + 1);
        let rows = existing[header.len()..keep]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(io("opening"))?;
        if keep < existing.len() {
            file.set_len(keep as u64).map_err(io("truncating"))?;
        }
        use std::io::{Seek, SeekFrom};
        file.seek(SeekFrom::End(0)).map_err(io("seeking"))?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            schema: schema.to_vec(),
            rows,
            line: String::new(),
        })
    }

    /// Appends one row; its values must match the schema's types in order.
    pub fn append(&mut self, row: &[Value<'_>]) -> Result<()> {
        if row.len() != self.schema.len() {
            return Err(ReportError::BadRow {
                path: self.path.clone(),
                detail: format!("{} values for {} columns", row.len(), self.schema.len()),
            });
        }
        for ((name, kind), v) in self.schema.iter().zip(row) {
            if v.kind() != *kind {
                return Err(ReportError::BadRow {
                    path: self.path.clone(),
                    detail: format!("column `{name}` is {kind}, got a {} value", v.kind()),
                });
            }
        }
        self.line.clear();
        for (i, v) in row.iter().enumerate() {
            if i > 0 {
                self.line.push(',');
            }
            push_csv_value(&mut self.line, v);
        }
        self.line.push('\n');
        self.file
            .write_all(self.line.as_bytes())
            .map_err(|source| ReportError::Io {
                path: self.path.clone(),
                action: "appending to",
                source,
            })?;
        self.rows += 1;
        Ok(())
    }

    /// Appends every row of `table`, whose schema must equal the appender's.
    pub fn append_table(&mut self, table: &Table) -> Result<()> {
        check_same_schema(&self.schema, &table.schema())?;
        for i in 0..table.n_rows() {
            let row = table.row(i)?;
            self.append(&row)?;
        }
        Ok(())
    }

    /// Forces the written rows to stable storage (`fsync`); rows are already handed to the
    /// operating system by [`CsvAppender::append`].
    pub fn sync(&self) -> Result<()> {
        self.file.sync_all().map_err(|source| ReportError::Io {
            path: self.path.clone(),
            action: "syncing",
            source,
        })
    }

    /// Number of complete data rows in the file.
    pub fn rows_written(&self) -> usize {
        self.rows
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The schema (header) of the file.
    pub fn schema(&self) -> &[(String, ColumnKind)] {
        &self.schema
    }
}

fn check_schema_names(schema: &[(String, ColumnKind)]) -> Result<()> {
    for (i, (name, _)) in schema.iter().enumerate() {
        if schema[..i].iter().any(|(n, _)| n == name) {
            return Err(ReportError::DuplicateColumn { name: name.clone() });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Table {
        Table::new()
            .with("case_id", vec![0_i64, 1, 2, 3, -4])
            .unwrap()
            .with(
                "energy_J",
                vec![1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0],
            )
            .unwrap()
            .with(
                "x_m",
                vec![f64::MAX, f64::MIN_POSITIVE, 5e-324, 0.1 + 0.2, -1.5e16],
            )
            .unwrap()
            .with(
                "status",
                vec!["ok", "failed: a, b", "say \"hi\"", "", "line\nbreak"],
            )
            .unwrap()
            .with("converged", vec![true, false, true, false, true])
            .unwrap()
    }

    fn read_back_schema() -> Vec<(String, ColumnKind)> {
        sample().schema()
    }

    #[test]
    fn builder_errors() {
        let t = Table::new().with("a", vec![1.0, 2.0]).unwrap();
        assert!(matches!(
            t.clone().with("b", vec![1_i64]),
            Err(ReportError::LengthMismatch { .. })
        ));
        assert!(matches!(
            t.clone().with("a", vec![1_i64, 2]),
            Err(ReportError::DuplicateColumn { .. })
        ));
        assert!(matches!(t.i64("a"), Err(ReportError::TypeMismatch { .. })));
        assert!(matches!(
            t.f64("zz"),
            Err(ReportError::MissingColumn { .. })
        ));
        assert_eq!(t.f64("a").unwrap(), &[1.0, 2.0]);
        assert!(t.row(2).is_err());
        assert!(t.select_rows(&[0, 2]).is_err());
    }

    #[test]
    fn csv_round_trip_exact() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        let t = sample();
        write_csv(&t, &p).unwrap();
        let back = read_csv(&p).unwrap();
        assert!(back.bit_eq(&t), "{back:?}\n{t:?}");
        let typed = read_csv_typed(&p, &read_back_schema()).unwrap();
        assert!(typed.bit_eq(&t));
        // Re-writing what was read gives identical bytes.
        let p2 = dir.path().join("t2.csv");
        write_csv(&back, &p2).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), std::fs::read(&p2).unwrap());
        // Deterministic.
        write_csv(&t, &p2).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), std::fs::read(&p2).unwrap());
    }

    #[test]
    fn csv_typed_keeps_numeric_strings_and_empty_tables() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        let t = Table::new()
            .with("label", vec!["1", "2.5", "true"])
            .unwrap()
            .with("v", vec![1.0, 2.0, 3.0])
            .unwrap();
        write_csv(&t, &p).unwrap();
        assert!(read_csv_typed(&p, &t.schema()).unwrap().bit_eq(&t));
        let empty = Table::empty_with_schema(&t.schema()).unwrap();
        write_csv(&empty, &p).unwrap();
        let back = read_csv_typed(&p, &t.schema()).unwrap();
        assert!(back.bit_eq(&empty), "{back:?}");
        assert_eq!(read_csv(&p).unwrap().n_rows(), 0);
        // Wrong schema is an error naming the column.
        let wrong = vec![
            ("label".to_owned(), ColumnKind::Str),
            ("w".to_owned(), ColumnKind::F64),
        ];
        let e = read_csv_typed(&p, &wrong).unwrap_err();
        assert!(e.to_string().contains('w'), "{e}");
        // Missing file is an I/O error naming the path.
        let e = read_csv(&dir.path().join("nope.csv")).unwrap_err();
        assert!(matches!(e, ReportError::Io { .. }));
        assert!(e.to_string().contains("nope.csv"));
    }

    #[test]
    fn parquet_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.parquet");
        let t = sample();
        write_parquet(&t, &p).unwrap();
        let back = read_parquet(&p).unwrap();
        assert_eq!(back.schema(), t.schema());
        // Non-NaN values are bit-exact; NaN stays NaN.
        let (a, b) = (back.f64("energy_J").unwrap(), t.f64("energy_J").unwrap());
        assert!(a[1].is_nan());
        assert!(back.bit_eq(&t));
        let p2 = dir.path().join("t2.parquet");
        write_parquet(&t, &p2).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), std::fs::read(&p2).unwrap());
        assert_eq!(a.len(), b.len());
        // Empty table.
        let empty = Table::empty_with_schema(&t.schema()).unwrap();
        write_parquet(&empty, &p).unwrap();
        assert!(read_parquet(&p).unwrap().bit_eq(&empty));
    }

    #[test]
    fn concat_sort_select() {
        let a = Table::new()
            .with("id", vec![3_i64, 1])
            .unwrap()
            .with("v", vec![0.3, 0.1])
            .unwrap();
        let b = Table::new()
            .with("id", vec![2_i64])
            .unwrap()
            .with("v", vec![0.2])
            .unwrap();
        let mut c = Table::concat(&[a.clone(), b.clone()]).unwrap();
        assert_eq!(c.n_rows(), 3);
        c.sort_by_column("id").unwrap();
        assert_eq!(c.i64("id").unwrap(), &[1, 2, 3]);
        assert_eq!(c.f64("v").unwrap(), &[0.1, 0.2, 0.3]);
        let s = c.select_rows(&[2, 0]).unwrap();
        assert_eq!(s.i64("id").unwrap(), &[3, 1]);
        assert_eq!(Table::concat(&[]).unwrap().n_rows(), 0);

        let wrong_type = Table::new()
            .with("id", vec![2_i64])
            .unwrap()
            .with("v", vec![2_i64])
            .unwrap();
        let e = Table::concat(&[a.clone(), wrong_type]).unwrap_err();
        assert!(
            matches!(&e, ReportError::SchemaMismatch { column, .. } if column == "v"),
            "{e}"
        );
        let wrong_name = Table::new()
            .with("id", vec![2_i64])
            .unwrap()
            .with("w", vec![2.0])
            .unwrap();
        let e = Table::concat(&[a.clone(), wrong_name]).unwrap_err();
        assert!(matches!(&e, ReportError::SchemaMismatch { column, .. } if column == "v"));
        let fewer = Table::new().with("id", vec![2_i64]).unwrap();
        assert!(Table::concat(&[a, fewer]).is_err());
    }

    #[test]
    fn appender_matches_polars_and_resumes() {
        let dir = tempfile::tempdir().unwrap();
        let t = sample();
        let streamed = dir.path().join("streamed.csv");
        let mut app = CsvAppender::create(&streamed, &t.schema()).unwrap();
        for i in 0..t.n_rows() {
            app.append(&t.row(i).unwrap()).unwrap();
        }
        assert_eq!(app.rows_written(), t.n_rows());
        drop(app);
        let whole = dir.path().join("whole.csv");
        write_csv(&t, &whole).unwrap();
        assert_eq!(
            std::fs::read_to_string(&streamed).unwrap(),
            std::fs::read_to_string(&whole).unwrap()
        );
        assert!(read_csv(&streamed).unwrap().bit_eq(&t));

        // Bad rows are typed errors.
        let mut app = CsvAppender::open_or_create(&streamed, &t.schema()).unwrap();
        assert!(app.append(&[Value::F64(1.0)]).is_err());
        let mut bad = t.row(0).unwrap();
        bad[0] = Value::F64(0.0);
        assert!(app.append(&bad).is_err());
        drop(app);

        // Resume after an interruption mid-row: the partial row is dropped.
        let simple = Table::new()
            .with("id", vec![0_i64, 1, 2])
            .unwrap()
            .with("v", vec![0.5, 1.5, 2.5])
            .unwrap();
        let p = dir.path().join("resume.csv");
        let mut app = CsvAppender::create(&p, &simple.schema()).unwrap();
        app.append(&simple.row(0).unwrap()).unwrap();
        drop(app);
        let mut f = std::fs::OpenOptions::new().append(true).open(&p).unwrap();
        f.write_all(b"1,1.").unwrap();
        drop(f);
        let mut app = CsvAppender::open_or_create(&p, &simple.schema()).unwrap();
        assert_eq!(app.rows_written(), 1);
        app.append(&simple.row(1).unwrap()).unwrap();
        app.append(&simple.row(2).unwrap()).unwrap();
        app.sync().unwrap();
        drop(app);
        assert!(read_csv(&p).unwrap().bit_eq(&simple));

        // A different header is refused.
        let other = vec![("id".to_owned(), ColumnKind::I64)];
        assert!(matches!(
            CsvAppender::open_or_create(&p, &other),
            Err(ReportError::SchemaMismatch { .. })
        ));
        // A missing file is created.
        let fresh = dir.path().join("fresh.csv");
        let mut app = CsvAppender::open_or_create(&fresh, &simple.schema()).unwrap();
        app.append_table(&simple).unwrap();
        drop(app);
        assert!(read_csv(&fresh).unwrap().bit_eq(&simple));
    }

    /// The appender's float format equals polars' on many values: random bit patterns, powers
    /// of ten around the positional/scientific switch, and special values.
    #[test]
    fn float_format_matches_polars() {
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1.0 / 3.0,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            f64::EPSILON,
            123456789012345680.0,
            9007199254740993.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for e in -330..=310 {
            let p = 10f64.powi(e);
            values.extend([p, 1.5 * p, -p, 9.999999 * p, p * (1.0 + f64::EPSILON)]);
        }
        // Deterministic pseudo-random bit patterns (SplitMix64).
        let mut s = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..20_000 {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            values.push(f64::from_bits(z));
            values.push((z >> 11) as f64 / (1u64 << 40) as f64);
        }
        let t = Table::new().with("x", values.clone()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.csv");
        write_csv(&t, &p).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("x"));
        assert_eq!(text.lines().count(), values.len() + 1);
        for (v, line) in values.iter().zip(lines) {
            assert_eq!(format_f64(*v), line, "value bits {:#x}", v.to_bits());
            if !v.is_nan() {
                assert_eq!(line.parse::<f64>().unwrap().to_bits(), v.to_bits());
            }
        }
        assert!(read_csv(&p)
            .unwrap()
            .bit_eq(&Table::new().with("x", canon_nan(&values)).unwrap()));
    }

    fn canon_nan(v: &[f64]) -> Vec<f64> {
        v.iter()
            .map(|x| if x.is_nan() { f64::NAN } else { *x })
            .collect()
    }
}

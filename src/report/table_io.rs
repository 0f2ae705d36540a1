//! CSV and Parquet files of [`Table`]s, read and written through polars.
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
//! the exact schema, and may carry file-level key/value metadata ([`write_parquet_with`]).

use std::fs::File;
use std::path::Path;
use std::sync::Arc;

use polars::prelude::{
    Column as PlColumn, CsvReadOptions, CsvWriter, DataFrame, DataType, Field, KeyValueMetadata,
    ParquetReader, ParquetWriter, PlSmallStr, PolarsError, Schema, SerReader, SerWriter,
};

use super::atomic::atomic_write;
use super::error::{ReportError, Result};
use super::table::{check_same_schema, ColumnData, ColumnKind, Table};

/// The polars type of a column kind.
fn dtype(kind: ColumnKind) -> DataType {
    match kind {
        ColumnKind::F64 => DataType::Float64,
        ColumnKind::I64 => DataType::Int64,
        ColumnKind::Str => DataType::String,
        ColumnKind::Bool => DataType::Boolean,
    }
}

/// A polars column named `name` holding `data`.
fn to_polars(data: &ColumnData, name: &str) -> PlColumn {
    let name = PlSmallStr::from_str(name);
    match data {
        ColumnData::F64(v) => PlColumn::new(name, v.as_slice()),
        ColumnData::I64(v) => PlColumn::new(name, v.as_slice()),
        ColumnData::Str(v) => PlColumn::new(name, v.as_slice()),
        ColumnData::Bool(v) => PlColumn::new(name, v.as_slice()),
    }
}

/// The table as a polars data frame.
fn to_dataframe(table: &Table) -> std::result::Result<DataFrame, PolarsError> {
    let cols = table
        .columns
        .iter()
        .map(|c| to_polars(&c.data, &c.name))
        .collect();
    DataFrame::new(table.n_rows(), cols)
}

/// A table from a polars data frame read from `path` (named in errors).
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

fn polars_err(path: &Path, action: &'static str) -> impl Fn(PolarsError) -> ReportError {
    let path = path.to_path_buf();
    move |source| ReportError::Polars {
        path: path.clone(),
        action,
        source,
    }
}

/// Writes `table` as CSV to `path` (atomically; format in the [module docs](self)).
/// The bytes depend only on the table's contents.
pub fn write_csv(table: &Table, path: &Path) -> Result<()> {
    let err = polars_err(path, "writing CSV");
    let mut df = to_dataframe(table).map_err(&err)?;
    let mut buf = Vec::new();
    CsvWriter::new(&mut buf)
        .include_header(true)
        .finish(&mut df)
        .map_err(&err)?;
    atomic_write(path, &buf)
}

/// Writes `table` as Parquet to `path` (atomically, polars' default settings).
pub fn write_parquet(table: &Table, path: &Path) -> Result<()> {
    write_parquet_with(table, path, &[])
}

/// [`write_parquet`] with file-level key/value metadata `meta` (e.g. a data dictionary; read
/// back with [`parquet_metadata`]).
pub fn write_parquet_with(table: &Table, path: &Path, meta: &[(String, String)]) -> Result<()> {
    let err = polars_err(path, "writing Parquet");
    let mut df = to_dataframe(table).map_err(&err)?;
    let mut buf = Vec::new();
    let kv = (!meta.is_empty()).then(|| KeyValueMetadata::from_static(meta.to_vec()));
    ParquetWriter::new(&mut buf)
        .with_key_value_metadata(kv)
        .finish(&mut df)
        .map_err(&err)?;
    atomic_write(path, &buf)
}

/// The file-level key/value metadata of a Parquet file (keys without a value left out).
pub fn parquet_metadata(path: &Path) -> Result<Vec<(String, String)>> {
    let file = File::open(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        action: "opening",
        source,
    })?;
    let mut reader = ParquetReader::new(file);
    let meta = reader
        .get_metadata()
        .map_err(polars_err(path, "reading Parquet"))?;
    Ok(meta
        .key_value_metadata()
        .iter()
        .flatten()
        .filter_map(|kv| Some((kv.key.clone(), kv.value.clone()?)))
        .collect())
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
        .map_err(&err)?;
    from_dataframe(&df, path)
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
        .map(|(n, k)| Field::new(PlSmallStr::from_str(n), dtype(*k)))
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
        .map_err(polars_err(path, "reading Parquet"))?;
    from_dataframe(&df, path)
}

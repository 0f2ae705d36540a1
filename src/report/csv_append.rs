//! [`CsvAppender`]: rows streamed into a CSV file with plain std I/O, byte-identical to
//! [`super::table_io::write_csv`] of the same table.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::error::{ReportError, Result};
use super::number::push_f64;
use super::table::{check_same_schema, check_schema_names, ColumnKind, Table, Value};

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
        Value::F64(x) => push_f64(buf, *x),
        Value::I64(x) => {
            use std::fmt::Write as _;
            let _ = write!(buf, "{x}");
        }
        Value::Str(s) => push_csv_str(buf, s),
        Value::Bool(b) => buf.push_str(if *b { "true" } else { "false" }),
    }
}

/// Appends one CSV row, cells separated by `,` and ended by a newline, exactly as
/// [`CsvAppender::append`] writes it: for callers that format rows themselves
/// ([`CsvAppender::append_lines`]).
pub fn push_csv_row<'v>(buf: &mut String, cells: impl IntoIterator<Item = Value<'v>>) {
    for (i, v) in cells.into_iter().enumerate() {
        if i > 0 {
            buf.push(',');
        }
        push_csv_value(buf, &v);
    }
    buf.push('\n');
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

/// Writes `table` to `path` (atomically) with the bytes of [`super::table_io::write_csv`],
/// formatted row by row into a buffered file: no polars frame and no whole-file buffer (a
/// 100 000-case table would otherwise be held three times: table, frame, text).
pub fn write_csv_streamed(table: &Table, path: &Path) -> Result<()> {
    let schema = table.schema();
    check_schema_names(&schema)?;
    super::atomic::atomic_write_with(path, |w| {
        w.write_all(csv_header_line(&schema).as_bytes())?;
        let mut line = String::new();
        for i in 0..table.n_rows() {
            let row = table.row(i).map_err(std::io::Error::other)?;
            line.clear();
            push_csv_row(&mut line, row);
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    })
}

/// Streams rows into a CSV file during a long sweep, so that an interrupted run keeps every
/// finished row.
///
/// Plain std I/O: each row is formatted into one line and written with a single `write_all`
/// on the unbuffered file (no data sits in a user-space buffer after [`CsvAppender::append`]
/// returns). The bytes are identical to [`write_csv`] of the same table (same header quoting,
/// float format [`super::number::format_f64`], `true`/`false`, integers in decimal), so reading the file back
/// and writing it with polars reproduces it exactly.
#[derive(Debug)]
pub struct CsvAppender {
    path: PathBuf,
    file: File,
    schema: Vec<(String, ColumnKind)>,
    rows: usize,
    line: String,
    /// Pending bytes at which `line` is written: 0 writes every row ([`CsvAppender::batched`]).
    batch: usize,
}

impl CsvAppender {
    /// Creates (or truncates) `path` and writes the header for `schema`.
    pub fn create(path: &Path, schema: &[(String, ColumnKind)]) -> Result<Self> {
        check_schema_names(schema)?;
        let mut file = super::atomic::create_file(path).map_err(|source| ReportError::Io {
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
            batch: 0,
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
        let mut file = super::atomic::open_existing(path, false).map_err(io("opening"))?;
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
            batch: 0,
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
        push_csv_row(&mut self.line, row.iter().copied());
        self.added(1)
    }

    /// Appends complete rows already formatted by the caller ([`push_csv_row`]) in the
    /// appender's schema: the rows of a parallel formatter, written in order. Counted by
    /// their newlines.
    pub fn append_lines(&mut self, text: &str) -> Result<()> {
        self.line.push_str(text);
        self.added(text.bytes().filter(|&b| b == b'\n').count())
    }

    /// `rows` more rows are pending: write them once a batch is full (at once unbatched).
    fn added(&mut self, rows: usize) -> Result<()> {
        self.rows += rows;
        if self.line.len() >= self.batch {
            self.write_pending()?;
        }
        Ok(())
    }

    /// The same appender writing rows in batches of about 64 KiB instead of one `write_all`
    /// per row: for large outputs that are not a journal (a crash may lose the last batch);
    /// [`CsvAppender::flush`] and [`CsvAppender::sync`] write what is pending. Dropping it
    /// without either loses the pending rows.
    pub fn batched(mut self) -> Self {
        self.batch = 1 << 16;
        self
    }

    fn write_pending(&mut self) -> Result<()> {
        self.file
            .write_all(self.line.as_bytes())
            .map_err(|source| ReportError::Io {
                path: self.path.clone(),
                action: "appending to",
                source,
            })?;
        self.line.clear();
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

    /// Hands the pending rows of a [`CsvAppender::batched`] appender to the operating system,
    /// without forcing them to stable storage: for a large output that is not a journal (its
    /// completion is marked by a file written after it), where an `fsync` of hundreds of MB
    /// would be serial waiting.
    pub fn flush(&mut self) -> Result<()> {
        self.write_pending()
    }

    /// Forces the written rows to stable storage (`fsync`); rows are already handed to the
    /// operating system by [`CsvAppender::append`] (in batches after
    /// [`CsvAppender::batched`], whose pending rows are written first).
    pub fn sync(&mut self) -> Result<()> {
        self.write_pending()?;
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

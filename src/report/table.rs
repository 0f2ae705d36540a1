//! Column-oriented result tables: typed, named columns of equal length ([`Table`]).
//!
//! Files: [`super::table_io`] reads and writes tables as CSV and Parquet (polars),
//! [`super::csv_append`] streams rows into a CSV file, [`super::number::format_f64`] is the float
//! format of both.

pub use super::column_kind::ColumnKind;
use super::error::{ReportError, Result};

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
}

/// `Ok` when `found` has the names and types of `expected`, in order; else the first difference.
pub(super) fn check_same_schema(
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

/// `Ok` when no column name occurs twice in `schema`.
pub(super) fn check_schema_names(schema: &[(String, ColumnKind)]) -> Result<()> {
    for (i, (name, _)) in schema.iter().enumerate() {
        if schema[..i].iter().any(|(n, _)| n == name) {
            return Err(ReportError::DuplicateColumn { name: name.clone() });
        }
    }
    Ok(())
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;

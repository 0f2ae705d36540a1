//! The type of a table column (shared by tables and their errors).

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

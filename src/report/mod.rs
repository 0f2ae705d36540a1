//! Reporting: tables (CSV / Parquet through polars), SVG figures (plotters), number formats and
//! Markdown tables.
//!
//! This module knows nothing of the physics. It turns result records, already flattened into
//! named columns by the caller, into files:
//!
//! - [`table`]: a small column-oriented [`Table`] ([`Table::concat`] merges shard tables);
//!   [`table_io`]: its deterministic CSV and Parquet writers and readers; [`csv_append`]: a
//!   row-by-row [`CsvAppender`] for long sweeps, byte-identical to [`write_csv`].
//! - [`number`]: the CSV float format ([`format_f64`], polars' own) and the short display format
//!   of printed reports ([`fmt_num`]); [`markdown`]: the one Markdown-table writer.
//! - [`plot`]: data-driven figure specifications ([`Figure`], [`Panel`], [`Series`],
//!   [`Heatmap`]) rendered to SVG with native `<text>` elements (no font files), byte-identical
//!   between runs.
//! - [`pdf`]: a small PDF 1.4 writer (one page, standard fonts Helvetica and Symbol from
//!   [`pdf_fonts`], not embedded); the figures' column-width PDFs are drawn through it.
//! - [`html`]: pieces of self-contained HTML pages (escaping, the summary's Markdown, inlined
//!   SVG).
//! - [`atomic`]: every whole-file write goes through [`atomic_write`] (temporary file in the
//!   same directory, then rename).
//! - [`pareto_front`]: the non-dominated subset of a set of 2-D points (minimise both).
//!
//! It is the only module of the crate that uses `polars` and `plotters`; neither leaks through
//! the public API (errors carry their messages as strings).

pub mod atomic;
pub mod column_kind;
pub mod csv_append;
pub mod drawing;
pub mod error;
pub mod html;
pub mod markdown;
pub mod number;
pub mod pareto;
pub mod pdf;
pub mod pdf_fonts;
pub mod plot;
pub mod table;
pub mod table_io;

pub use atomic::{
    atomic_write, create_file, create_subdir, file_stem_safe, open_existing, prepare_dir,
    process_alive, remove_dead_temporaries, run_token, temporary_suffix,
};
pub use csv_append::{push_csv_row, write_csv_streamed, CsvAppender};
pub use error::{PdfError, ReportError, Result};
pub use markdown::MarkdownTable;
pub use number::{fmt_num, fmt_short, fmt_value, format_f64};
pub use pareto::pareto_front;
pub use plot::{
    heatmap, histogram, rank_interval_pdf, rank_interval_svg, scatter_labelled, tornado_pdf,
    tornado_svg, Colour, ColourScale, Figure, Heatmap, LabelledPoint, LineStyle, Panel, PanelKind,
    RankRow, Scale, Series, TornadoRow, COLUMN_PT_PER_PX, COLUMN_PX,
};
pub use table::{Column, ColumnData, ColumnKind, Table, Value};
pub use table_io::{
    parquet_metadata, read_csv, read_csv_typed, read_parquet, write_csv, write_parquet,
    write_parquet_with,
};

//! Tests of the tables, their CSV / Parquet files and the CSV float format.

use super::*;
use crate::report::error::ReportError;
use crate::report::{
    read_csv, read_csv_typed, read_parquet, write_csv, write_csv_streamed, write_parquet,
    CsvAppender,
};
use std::io::Write;

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
    // The whole-table streamed writer too.
    let direct = dir.path().join("direct.csv");
    write_csv_streamed(&t, &direct).unwrap();
    assert_eq!(
        std::fs::read(&direct).unwrap(),
        std::fs::read(&whole).unwrap()
    );

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

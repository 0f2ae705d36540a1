//! The journal of a sweep (`cases.partial.csv`, one raw row per finished case) checked before
//! `--resume` trusts it: every complete line must have the raw schema's field count, values
//! that parse as their column's kind (no empty or garbled numbers read as NaN), a known status
//! and a hash. Bad lines are reported with their line number and dropped, so their cases run
//! again; the journal is rewritten without them (atomically). A trailing line without its
//! newline (a row cut off by a kill) is left to `CsvAppender::open_or_create`, which drops it.

use std::path::Path;

use super::records::{CaseStatus, HASH, SCENARIO_METRICS_COLUMN, STATUS};
use crate::report::{atomic_write, ColumnKind};
use crate::study::error::{Notes, StudyError};

/// Split one CSV line (quotes as written by `CsvAppender`: `"…"` with `""` inside) into its
/// fields; `None` for an unterminated quote.
fn split_fields(line: &str) -> Option<Vec<String>> {
    let mut fields = Vec::new();
    let mut cur = String::new();
    let mut chars = line.chars().peekable();
    let mut quoted = false;
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cur.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => cur.push(c),
            (false, '"') if cur.is_empty() => quoted = true,
            (false, ',') => fields.push(std::mem::take(&mut cur)),
            (false, c) => cur.push(c),
        }
    }
    if quoted {
        return None;
    }
    fields.push(cur);
    Some(fields)
}

/// Whether a packed metrics cell (`name=value;…`, `records::pack_metrics`) reads back: every
/// item a non-empty name and a number (`NaN` and `inf` as the float format writes them).
fn packed_ok(cell: &str) -> bool {
    cell.split(';').filter(|x| !x.is_empty()).all(|kv| {
        kv.split_once('=')
            .is_some_and(|(k, v)| !k.is_empty() && v.parse::<f64>().is_ok())
    })
}

/// What is wrong with one journal line, if anything.
fn check_line(line: &str, schema: &[(String, ColumnKind)]) -> Option<String> {
    let Some(fields) = split_fields(line) else {
        return Some("unterminated quoted field".into());
    };
    if fields.len() != schema.len() {
        return Some(format!(
            "{} fields for {} columns",
            fields.len(),
            schema.len()
        ));
    }
    for ((name, kind), f) in schema.iter().zip(&fields) {
        let ok = match kind {
            ColumnKind::F64 => f.parse::<f64>().is_ok(),
            ColumnKind::I64 => f.parse::<i64>().is_ok(),
            ColumnKind::Bool => f == "true" || f == "false",
            ColumnKind::Str if name == STATUS => CaseStatus::ALL.iter().any(|s| s.as_str() == f),
            ColumnKind::Str if name == HASH => {
                !f.is_empty() && f.bytes().all(|b| b.is_ascii_hexdigit())
            }
            ColumnKind::Str if name == SCENARIO_METRICS_COLUMN => packed_ok(f),
            ColumnKind::Str => true,
        };
        if !ok {
            return Some(format!("column `{name}`: `{f}` is not a valid {kind}"));
        }
    }
    None
}

/// Check the journal at `path` (whose first line is the header of `schema`, checked by the
/// caller's appender): drop its malformed complete lines, rewriting the file, and return one
/// warning per dropped line (`FILE:LINE: why; the case runs again`). A missing file is fine.
pub fn repair(path: &Path, schema: &[(String, ColumnKind)]) -> Result<Notes, StudyError> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(StudyError::io(path, e)),
    };
    let text = String::from_utf8_lossy(&bytes);
    let complete = text.rfind('\n').map_or(0, |i| i + 1);
    let mut warnings = Vec::new();
    let mut kept = String::with_capacity(complete);
    for (i, line) in text[..complete].split_inclusive('\n').enumerate() {
        let body = line.trim_end_matches('\n');
        let bad = if i == 0 {
            None
        } else {
            check_line(body, schema)
        };
        match bad {
            Some(why) => warnings.push(format!(
                "{}:{}: malformed journal row ({why}); dropped, the case runs again",
                path.display(),
                i + 1
            )),
            None => kept.push_str(line),
        }
    }
    if !warnings.is_empty() {
        kept.push_str(&text[complete..]);
        atomic_write(path, kept.as_bytes())?;
    }
    Ok(warnings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn schema() -> Vec<(String, ColumnKind)> {
        [
            ("case_id", ColumnKind::I64),
            ("hash", ColumnKind::Str),
            ("status", ColumnKind::Str),
            ("reason", ColumnKind::Str),
            ("x", ColumnKind::F64),
        ]
        .into_iter()
        .map(|(n, k)| (n.to_string(), k))
        .collect()
    }

    /// Issue 39: the packed run metrics were read as NaN when garbled
    /// (`world.0.mission_cost=abc`); now such a row is reported and its case runs again.
    #[test]
    fn garbled_packed_metrics_are_malformed() {
        let mut s = schema();
        s.push((SCENARIO_METRICS_COLUMN.to_string(), ColumnKind::Str));
        let ok = "0,ab12,ok,\"\",1.5,world.0.mission_cost=1.25;x=NaN;y=-inf";
        assert_eq!(check_line(ok, &s), None);
        assert_eq!(check_line("0,ab12,ok,\"\",1.5,", &s), None);
        for bad in ["world.0.mission_cost=abc", "x=1;=2", "x", "x=1;y="] {
            let line = format!("0,ab12,ok,\"\",1.5,{bad}");
            assert!(check_line(&line, &s).is_some(), "{bad}");
        }
    }

    #[test]
    fn quoted_fields_split_like_the_appender_writes_them() {
        assert_eq!(
            split_fields(r#"1,"a,b","say ""hi""",,NaN"#).unwrap(),
            ["1", "a,b", r#"say "hi""#, "", "NaN"]
        );
        assert!(split_fields(r#"1,"open"#).is_none());
    }

    #[test]
    fn malformed_rows_are_dropped_with_their_line_numbers() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("j.csv");
        let text = "case_id,hash,status,reason,x\n\
                    0,ab12,ok,\"\",1.5\n\
                    1,cd34,ok,\"\"\n\
                    2,ef56,ok,\"\",1.2.3\n\
                    3,0a0b,weird,\"\",1.0\n\
                    4,1a1b,failed,\"timeout: x\",NaN\n\
                    x,,ok,\"\",1.0\n\
                    5,2a2b,ok,\"\",2";
        std::fs::write(&p, text).unwrap();
        let w = repair(&p, &schema()).unwrap();
        assert_eq!(w.len(), 4, "{w:?}");
        assert!(w[0].contains("j.csv:3: ") && w[0].contains("4 fields for 5 columns"));
        assert!(w[1].contains(":4: ") && w[1].contains("`1.2.3` is not a valid f64"));
        assert!(w[2].contains(":5: ") && w[2].contains("status"));
        assert!(w[3].contains(":7: "));
        let kept = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            kept,
            "case_id,hash,status,reason,x\n0,ab12,ok,\"\",1.5\n\
             4,1a1b,failed,\"timeout: x\",NaN\n5,2a2b,ok,\"\",2"
        );
        // A clean journal is left untouched.
        assert!(repair(&p, &schema()).unwrap().is_empty());
    }
}

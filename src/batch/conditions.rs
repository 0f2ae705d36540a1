//! Conditions are not rivals (issue 42 item 3): an axis declared `condition = true` (a
//! payload, a current, a mission variant) is a circumstance the designs meet, not a design
//! choice. A study with condition axes is judged per condition — the rows sharing the values of
//! every condition axis — so "paper carrying 5 kg" is never ranked against "ends carrying
//! 2 kg": `p_best` and the rank quantiles are among the ranked designs of one condition
//! ([`super::robust::add_rank_columns`]), and `summary.md` opens with one verdict per condition
//! (`docs/study-format.md`, `[[axis]] condition`; `docs/statistics.md`).

use crate::report::{fmt_short, ColumnData, Table};

/// How the opening of `summary.md` starts for a study with condition axes (one of
/// [`crate::review::summary_robust::VERDICT_OPENINGS`]).
pub const PER_CONDITION: &str = "**Verdict per condition";

/// One condition of a study: the rows that share the values of every condition axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Condition {
    /// The condition axes with their values, as `` `mission.payload_mass` = 2 `` joined by
    /// `, ` (empty for a study without condition axes).
    pub label: String,
    /// Whether each row of the table is under this condition.
    pub rows: Vec<bool>,
}

/// The conditions of `table` for the condition axes `names`, in the order of their first row
/// (the case order); one condition holding every row when `names` is empty.
pub fn conditions(table: &Table, names: &[String]) -> Vec<Condition> {
    let n = table.n_rows();
    if names.is_empty() {
        return vec![Condition {
            label: String::new(),
            rows: vec![true; n],
        }];
    }
    let mut found: Vec<(Vec<String>, Vec<bool>)> = Vec::new();
    for r in 0..n {
        let key: Vec<String> = names.iter().map(|a| cell(table, a, r)).collect();
        match found.iter_mut().find(|(k, _)| *k == key) {
            Some((_, rows)) => rows[r] = true,
            None => {
                let mut rows = vec![false; n];
                rows[r] = true;
                found.push((key, rows));
            }
        }
    }
    found
        .into_iter()
        .map(|(key, rows)| Condition {
            label: names
                .iter()
                .zip(&key)
                .map(|(a, v)| format!("`{a}` = {v}"))
                .collect::<Vec<_>>()
                .join(", "),
            rows,
        })
        .collect()
}

/// Row `r` of column `col` as the tables print it (empty when there is no such column).
fn cell(table: &Table, col: &str, r: usize) -> String {
    match table.column(col).map(|c| &c.data) {
        Some(ColumnData::F64(v)) => fmt_short(v[r]),
        Some(ColumnData::I64(v)) => v[r].to_string(),
        Some(ColumnData::Str(v)) => v[r].clone(),
        Some(ColumnData::Bool(v)) => v[r].to_string(),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_grouped_by_every_condition_axis_in_case_order() {
        let t = Table::new()
            .with(
                "rule",
                ColumnData::Str(vec!["a".into(), "b".into(), "a".into()]),
            )
            .and_then(|t| t.with("payload", ColumnData::F64(vec![2.0, 2.0, 5.0])))
            .unwrap();
        let c = conditions(&t, &["payload".into()]);
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].rows, vec![true, true, false]);
        assert_eq!(c[1].rows, vec![false, false, true]);
        assert!(c[0].label.starts_with("`payload` = 2"), "{}", c[0].label);
        let all = conditions(&t, &[]);
        assert_eq!(all.len(), 1);
        assert_eq!(all[0].rows, vec![true; 3]);
    }
}

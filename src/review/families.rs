//! Families of ranked designs (issue 42 item 2): designs equal in every axis that matters and
//! different only in axes the study found not to matter are one *family*, so that "top 3"
//! compares distinct layouts instead of one layout at three values of a minor axis.
//!
//! An axis is *minor* when changing it alone (every other axis held) moves the nominal
//! objective of the ranked designs by less than [`MINOR_EFFECT`] (the median over the groups of
//! ranked designs that differ in that axis alone). A family is the set of ranked designs that
//! share the values of every other (major) axis; it is shown by its best-ranked member with the
//! range of its minor axes.

use super::selection::cell_text;
use crate::report::{fmt_short, ColumnData, Table};
use crate::stats::describe::quantile_sorted;

/// An axis whose change alone moves the nominal objective by less than this relative amount
/// (median over the ranked designs) is minor.
pub const MINOR_EFFECT: f64 = 0.01;

/// A minor axis and the median relative change of the nominal objective it makes.
#[derive(Clone, Debug, PartialEq)]
pub struct MinorAxis {
    /// The axis name (`design.longitudinal_offset`).
    pub name: String,
    /// Median over the groups of ranked designs equal in every other axis of
    /// (max − min) / |min| of the nominal objective.
    pub effect: f64,
    /// The largest such change over the groups.
    pub largest: f64,
}

/// The key of row `r` over `axes` (every axis but `skip`).
fn key(t: &Table, axes: &[&str], skip: &[&str], r: usize) -> Vec<String> {
    axes.iter()
        .filter(|a| !skip.contains(a))
        .map(|a| cell_text(t, a, r))
        .collect()
}

/// The rows of `rows` grouped by equal values of every axis except `skip`, in order of first
/// appearance.
fn groups(t: &Table, axes: &[&str], skip: &[&str], rows: &[usize]) -> Vec<Vec<usize>> {
    let mut out: Vec<(Vec<String>, Vec<usize>)> = Vec::new();
    for &r in rows {
        let k = key(t, axes, skip, r);
        match out.iter_mut().find(|(g, _)| *g == k) {
            Some((_, v)) => v.push(r),
            None => out.push((k, vec![r])),
        }
    }
    out.into_iter().map(|(_, v)| v).collect()
}

/// The minor axes among `axes` over the `ranked` rows by the nominal `objective`: at least one
/// group of two or more ranked designs differing in that axis alone, and the median relative
/// spread of the objective over such groups below [`MINOR_EFFECT`]. With a single axis there is
/// nothing to hold, so no axis is minor.
pub fn minor_axes(t: &Table, axes: &[&str], ranked: &[usize], objective: &str) -> Vec<MinorAxis> {
    let Ok(obj) = t.f64(objective) else {
        return Vec::new();
    };
    if axes.len() < 2 {
        return Vec::new();
    }
    let mut out = Vec::new();
    for a in axes {
        let mut spreads: Vec<f64> = groups(t, axes, &[a], ranked)
            .iter()
            .filter(|g| g.len() >= 2)
            .filter_map(|g| {
                let v: Vec<f64> = g
                    .iter()
                    .map(|&r| obj[r])
                    .filter(|x| x.is_finite())
                    .collect();
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                (v.len() >= 2 && lo.abs() > 0.0).then(|| (hi - lo) / lo.abs())
            })
            .collect();
        if spreads.is_empty() {
            continue;
        }
        spreads.sort_by(f64::total_cmp);
        let effect = quantile_sorted(&spreads, 0.5);
        if effect < MINOR_EFFECT {
            out.push(MinorAxis {
                name: a.to_string(),
                effect,
                largest: spreads[spreads.len() - 1],
            });
        }
    }
    out
}

/// The families of the `ranked` rows (best first): rows sharing every axis but the `minor`
/// ones, in the order of their best-ranked member; each family's rows in ranked order.
pub fn families(
    t: &Table,
    axes: &[&str],
    ranked: &[usize],
    minor: &[MinorAxis],
) -> Vec<Vec<usize>> {
    if minor.is_empty() {
        return ranked.iter().map(|&r| vec![r]).collect();
    }
    let skip: Vec<&str> = minor.iter().map(|m| m.name.as_str()).collect();
    groups(t, axes, &skip, ranked)
}

/// The values of axis `a` over `rows` as text: one value, or the range `lo–hi` of a numeric
/// axis, or the distinct values joined by `/`.
fn axis_range(t: &Table, a: &str, rows: &[usize]) -> String {
    if let Some(ColumnData::F64(v)) = t.column(a).map(|c| &c.data) {
        let x: Vec<f64> = rows
            .iter()
            .map(|&r| v[r])
            .filter(|x| x.is_finite())
            .collect();
        let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if x.is_empty() {
            return "–".into();
        }
        return if lo == hi {
            fmt_short(lo)
        } else {
            format!("{}–{}", fmt_short(lo), fmt_short(hi))
        };
    }
    let mut seen: Vec<String> = Vec::new();
    for &r in rows {
        let s = cell_text(t, a, r);
        if !seen.contains(&s) {
            seen.push(s);
        }
    }
    seen.join("/")
}

/// A family's name: its axis values in axis order, a minor axis as its range over the family
/// (`paper, 4, 0.06–0.14`).
pub fn family_name(t: &Table, axes: &[&str], rows: &[usize]) -> String {
    axes.iter()
        .map(|a| axis_range(t, a, rows))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The sentence that explains the families of a box: which axes are minor and by how much they
/// move the objective; `None` when no axis is minor.
pub fn families_note(minor: &[MinorAxis], objective: &str) -> Option<String> {
    if minor.is_empty() {
        return None;
    }
    let list: Vec<String> = minor
        .iter()
        .map(|m| {
            format!(
                "`{}` (median {:.2} %, at most {:.2} %)",
                m.name,
                100.0 * m.effect,
                100.0 * m.largest
            )
        })
        .collect();
    Some(format!(
        "A *family* is the ranked designs equal in every axis but {}: changing that axis alone \
         moves the nominal `{objective}` by less than {:.0} % (the median over the ranked designs that \
         differ in it alone; in brackets with the largest), so its values are one layout, not rivals. Each column \
         shows a family by its best-ranked member, with the range of the minor axis and every \
         member.",
        list.join(", "),
        100.0 * MINOR_EFFECT
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Table {
        let mut t = Table::new();
        let rule = ["a", "a", "a", "b", "b", "b"].map(String::from).to_vec();
        t.push("rule", ColumnData::Str(rule)).unwrap();
        t.push("off", ColumnData::F64(vec![0.1, 0.2, 0.3, 0.1, 0.2, 0.3]))
            .unwrap();
        t.push(
            "cost",
            ColumnData::F64(vec![10.0, 10.01, 10.02, 20.0, 20.1, 20.05]),
        )
        .unwrap();
        t
    }

    #[test]
    fn an_axis_that_moves_the_objective_little_is_minor_and_makes_families() {
        let t = table();
        let axes = ["rule", "off"];
        let ranked = [0, 1, 3, 2, 5, 4];
        let minor = minor_axes(&t, &axes, &ranked, "cost");
        assert_eq!(minor.len(), 1, "{minor:?}");
        assert_eq!(minor[0].name, "off");
        let f = families(&t, &axes, &ranked, &minor);
        assert_eq!(f, vec![vec![0, 1, 2], vec![3, 5, 4]]);
        assert_eq!(family_name(&t, &axes, &f[0]), "a, 0.1–0.3");
        assert!(families_note(&minor, "cost").unwrap().contains("`off`"));
        // One axis alone: nothing is held, nothing is minor.
        assert!(minor_axes(&t, &["off"], &ranked, "cost").is_empty());
    }
}

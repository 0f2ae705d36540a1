//! The review page's per-design sections (issue 42 item 5): the leader and its competitors
//! (the designs of the verdict box's side-by-side table) each with its drawing, its metrics
//! with units, its worlds (met, successful, criteria missed, objective quantiles), its single
//! thruster faults and its tuning curve; and the mark every case reference in the page's
//! tables gets: ranked, or why not.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::review_top::Drawing;
use crate::batch::records::CASE_ID;
use crate::report::html::{escape, inline_svg};
use crate::report::{fmt_short, read_csv, Table};
use crate::review::plots::{metric_title, unsuccessful_rows};
use crate::review::verdict_box::REVIEW_METRICS;
use crate::stats::describe::quantile_sorted;

/// Each case's rank mark (ranked, or why not) for the cases `ids`; empty for a study that
/// ranks nothing over worlds (no `p_best` column).
pub(super) fn rank_marks(
    t: &Table,
    ids: &[i64],
    min_success: f64,
) -> BTreeMap<i64, (bool, String)> {
    let (Ok(case), Ok(p)) = (t.i64(CASE_ID), t.f64("p_best")) else {
        return BTreeMap::new();
    };
    let bad = unsuccessful_rows(t);
    let col = |c: &str, r: usize| t.f64(c).map_or(f64::NAN, |v| v[r]);
    let mut out = BTreeMap::new();
    for r in (0..t.n_rows()).filter(|&r| ids.contains(&case[r])) {
        let sp = col("success_probability", r);
        let mark = if p[r].is_finite() {
            (true, "ranked".to_string())
        } else if sp.is_finite() {
            (
                false,
                format!(
                    "not ranked: success {} (95 % lower bound {} < {})",
                    fmt_short(sp),
                    fmt_short(col("success_probability_lower", r)),
                    fmt_short(min_success)
                ),
            )
        } else if bad[r] {
            (
                false,
                "not ranked: unsuccessful in the nominal world".to_string(),
            )
        } else {
            (false, "not ranked: did not run in the worlds".to_string())
        };
        out.insert(case[r], mark);
    }
    out
}

/// A small inline SVG of a tuning curve: best-so-far objective against the evaluation.
fn curve_svg(pts: &[(f64, f64)], objective: &str) -> String {
    let (w, h, l, b) = (360.0, 150.0, 52.0, 26.0);
    let (x0, x1) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.0), a.1.max(p.0))
    });
    let (y0, y1) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.1), a.1.max(p.1))
    });
    let sx = |x: f64| l + (w - l - 8.0) * if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.5 };
    let sy = |y: f64| 8.0 + (h - b - 8.0) * if y1 > y0 { (y1 - y) / (y1 - y0) } else { 0.5 };
    let path: Vec<String> = pts
        .iter()
        .map(|p| format!("{:.1},{:.1}", sx(p.0), sy(p.1)))
        .collect();
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\" \
         font-family=\"DejaVu Sans,sans-serif\" font-size=\"10\"><rect x=\"{l}\" y=\"8\" width=\"{}\" \
         height=\"{}\" fill=\"none\" stroke=\"#999\"/><polyline fill=\"none\" stroke=\"#1f77b4\" \
         stroke-width=\"1.5\" points=\"{}\"/><text x=\"{l}\" y=\"{}\">{}</text><text x=\"{}\" y=\"{}\" \
         text-anchor=\"end\">{}</text><text x=\"{}\" y=\"{}\" text-anchor=\"middle\">evaluation</text>\
         <text x=\"2\" y=\"14\">{}</text><text x=\"2\" y=\"{}\">{}</text></svg>",
        w - l - 8.0,
        h - b - 8.0,
        path.join(" "),
        h - b + 12.0,
        fmt_short(x0),
        w - 8.0,
        h - b + 12.0,
        fmt_short(x1),
        (w + l) / 2.0,
        h - 4.0,
        fmt_short(y1),
        h - b,
        fmt_short(y0),
    ) + &format!("<!-- best-so-far {objective} -->")
}

/// What the per-design sections read beside the case table.
pub(super) struct DesignInputs<'a> {
    /// The output directory (`worlds.csv`, `tuning.csv`).
    pub dir: &'a Path,
    /// The case table.
    pub table: &'a Table,
    /// The designs to show, leader first.
    pub ids: &'a [i64],
    /// The ranking objective.
    pub objective: &'a str,
    /// The designs drawn.
    pub drawings: &'a [Drawing],
    /// A case's name (axis values).
    pub name: &'a dyn Fn(i64) -> String,
}

/// The worlds paragraph of case `id` from `worlds.csv`.
fn worlds_text(w: &Table, id: i64, objective: &str) -> String {
    let (Ok(case), Ok(ok)) = (w.i64(CASE_ID), w.f64("success")) else {
        return "No per-world record.".into();
    };
    let obj = w.f64(objective).ok();
    let missed = w.str("missed").ok();
    let rows: Vec<usize> = (0..w.n_rows()).filter(|&r| case[r] == id).collect();
    if rows.is_empty() {
        return "Did not run in the worlds.".into();
    }
    let good: Vec<usize> = rows.iter().copied().filter(|&r| ok[r] == 1.0).collect();
    let mut by: BTreeMap<&str, usize> = BTreeMap::new();
    for &r in &rows {
        if let Some(m) = missed.map(|m| m[r].as_str()).filter(|m| !m.is_empty()) {
            *by.entry(m).or_default() += 1;
        }
    }
    let mut s = format!("Met {} worlds, successful in {}", rows.len(), good.len());
    if !by.is_empty() {
        let list: Vec<String> = by.iter().map(|(k, n)| format!("{k} {n}")).collect();
        let _ = write!(s, " (missed: {})", list.join(", "));
    }
    if let Some(o) = obj {
        let mut v: Vec<f64> = good
            .iter()
            .map(|&r| o[r])
            .filter(|x| x.is_finite())
            .collect();
        v.sort_by(f64::total_cmp);
        if !v.is_empty() {
            let _ = write!(
                s,
                "; {} over its successful worlds: median {}, 5–95 % {} … {}",
                metric_title(objective),
                fmt_short(quantile_sorted(&v, 0.5)),
                fmt_short(quantile_sorted(&v, 0.05)),
                fmt_short(quantile_sorted(&v, 0.95))
            );
        }
    }
    s + "."
}

/// The faults paragraph of row `r`: its fault tolerance and the faults it does not survive.
fn faults_text(t: &Table, r: usize) -> Option<String> {
    let tol = t.f64("fault_tolerance").ok()?[r];
    let mut lost = Vec::new();
    for c in &t.columns {
        let Some(th) = c
            .name
            .strip_prefix("fault.")
            .and_then(|n| n.strip_suffix(".success"))
        else {
            continue;
        };
        if t.f64(&c.name).is_ok_and(|v| v[r] == 0.0) {
            let why = t
                .str(&format!("fault.{th}.missed"))
                .map(|m| m[r].clone())
                .unwrap_or_default();
            lost.push(if why.is_empty() {
                th.to_string()
            } else {
                format!("{th} ({why})")
            });
        }
    }
    Some(format!(
        "Single thruster faults: `fault_tolerance` {}; not survived: {}.",
        fmt_short(tol),
        if lost.is_empty() {
            "none".into()
        } else {
            lost.join(", ")
        }
    ))
}

/// The per-design sections (`<section id="leader-designs">`), or `None` without designs.
pub(super) fn designs_html(inp: &DesignInputs) -> Option<String> {
    let ids = inp.table.i64(CASE_ID).ok()?;
    if inp.ids.is_empty() {
        return None;
    }
    let worlds = read_csv(&inp.dir.join("worlds.csv")).ok();
    let tuning = read_csv(&inp.dir.join("tuning.csv")).ok();
    let mut h = String::from(
        "<section id=\"leader-designs\">\n<h2>The leader and its competitors</h2>\n<p>One section per \
         design of the verdict box (the best-ranked member of each family): drawing, metrics with \
         units, worlds, faults and tuning curve.</p>\n",
    );
    let mut metrics = vec![
        inp.objective.to_string(),
        format!("{}_mean", inp.objective),
        format!("{}_p95", inp.objective),
        "success_probability_lower".into(),
        "worlds_met".into(),
        "rank_p50".into(),
        "design_length_m".into(),
        "design_mass_kg".into(),
    ];
    metrics.extend(REVIEW_METRICS.iter().map(|m| m.to_string()));
    metrics.extend(
        inp.table
            .columns
            .iter()
            .filter(|c| c.name.starts_with("tuned."))
            .map(|c| c.name.clone()),
    );
    for (k, &id) in inp.ids.iter().enumerate() {
        let Some(r) = ids.iter().position(|&c| c == id) else {
            continue;
        };
        let role = if k == 0 { "leader" } else { "competitor" };
        let _ = writeln!(
            h,
            "<div class=\"r-design\" id=\"design-{id}\"><h3>#{id} {} — {role}</h3><div class=\"r-cols\"><div>",
            escape(&(inp.name)(id))
        );
        if let Some(d) = inp.drawings.iter().find(|d| d.cases.contains(&id)) {
            h.push_str(&inline_svg(&d.svg, &format!("d{id}-")));
        }
        if let Some(w) = &worlds {
            let _ = writeln!(h, "<p>{}</p>", escape(&worlds_text(w, id, inp.objective)));
        }
        if let Some(f) = faults_text(inp.table, r) {
            let _ = writeln!(h, "<p>{}</p>", escape(&f).replace('`', ""));
        }
        if let Some(t) = &tuning {
            if let (Ok(c), Ok(e), Ok(b)) = (t.i64(CASE_ID), t.f64("evaluation"), t.f64("best")) {
                let pts: Vec<(f64, f64)> = (0..t.n_rows())
                    .filter(|&i| c[i] == id && b[i].is_finite())
                    .map(|i| (e[i], b[i]))
                    .collect();
                if pts.len() >= 2 {
                    let ranked = inp.table.f64("p_best").is_ok_and(|p| p[r].is_finite());
                    let _ = writeln!(
                        h,
                        "<figure class=\"r-plot\">{}<figcaption>tuning curve of #{id} ({}): \
                         best-so-far tuned {} against the evaluation</figcaption></figure>",
                        curve_svg(&pts, inp.objective),
                        if ranked {
                            "a ranked design"
                        } else {
                            "not ranked"
                        },
                        escape(&metric_title(inp.objective))
                    );
                }
            }
        }
        h.push_str("</div><div><div class=\"r-scroll\"><table><thead><tr><th>metric [unit]</th><th>value</th></tr></thead><tbody>\n");
        for m in &metrics {
            if let Ok(v) = inp.table.f64(m) {
                let _ = writeln!(
                    h,
                    "<tr><td><code>{}</code></td><td>{}</td></tr>",
                    escape(&metric_title(m)),
                    fmt_short(v[r])
                );
            }
        }
        h.push_str("</tbody></table></div></div></div></div>\n");
    }
    h.push_str("</section>\n");
    Some(h)
}

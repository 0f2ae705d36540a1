//! The physical-limit section of `summary.md` (issue 41, docs/ocp.md §6): with `[ocp]`, each
//! design's optimal-control bound beside its closed-loop cost on the same measure (thruster
//! energy at zero inflow plus joint energy, per metre), the plot of one against the other
//! (`plots/bound.svg`: the diagonal is the perfect controller), and the sentence on whether the
//! ranking by bound agrees with the closed-loop ranking — and where it does not, which designs
//! are limited by the controller rather than by the layout.
//!
//! A bound counts only where it is a trajectory the model can fly: primal residual (defects
//! and the leg's terminal rows) at most [`FEASIBLE`], and work balance on its grid within
//! [`OCP_WORK_TRUSTED`] (`ocp_work_error`: else the optimum swims on energy the integration
//! supplies). A design whose closed loop spends *less*
//! per metre than its bound (`controller_efficiency` > 1) is flagged, never dropped: one of the
//! two is wrong, or the two missions differ more than the comparison assumes (the leg is
//! straight from rest to rest; the run follows the study's path).

use std::fmt::Write as _;
use std::path::Path;

use super::plots::{case_name, metric_title};
use super::plots_ranked::ranked_mask;
use super::selection::Selection;
use crate::batch::records::CASE_ID;
use crate::report::{
    fmt_short, scatter_labelled, LabelledPoint, LineStyle, MarkdownTable, PanelKind, Series, Table,
};
use crate::study::schema::{
    CONTROLLER_EFFICIENCY, OCP_ENERGY_PER_METRE, OCP_PRIMAL, OCP_SPREAD, OCP_STATUS,
    OCP_WORK_ERROR, OCP_WORK_TRUSTED, OCP_WORLD_FEASIBLE, OCP_WORLD_GRID_REJECTED,
    OCP_WORLD_ITERATIONS, OCP_WORLD_MAX, OCP_WORLD_MIN,
};

/// A bound with a primal residual at most this is a trajectory the model can fly.
pub const FEASIBLE: f64 = 1e-6;

/// The words of an `ocp_status` code.
fn status_word(code: f64) -> &'static str {
    match code as i64 {
        0 if code == 0.0 => "converged",
        1 => "max iterations",
        2 => "stalled",
        3 => "infeasible",
        4 => "diverged",
        _ => "–",
    }
}

/// One design of the section.
struct Entry {
    row: usize,
    closed: f64,
    bound: f64,
    efficiency: f64,
    objective: f64,
}

/// The section, or `None` without `ocp_energy_per_metre` in the table. `rows` are the designs
/// compared (the successful ones; the ranked ones of a robust study), `objective` the study's
/// objective column (ascending is better unless `sel` maximises it).
pub(crate) fn bound_section(
    table: &Table,
    axes: &[&str],
    rows: &[usize],
    sel: &Selection,
    plots: &Path,
    warnings: &mut Vec<String>,
) -> Option<String> {
    let bound = table.f64(OCP_ENERGY_PER_METRE).ok()?;
    let col = |n: &str| table.f64(n).ok();
    let (ts, je, pp) = (
        col("thruster_energy_static")?,
        col("joint_energy")?,
        col("path_progress")?,
    );
    let eff = col(CONTROLLER_EFFICIENCY)?;
    let primal = col(OCP_PRIMAL)?;
    let status = col(OCP_STATUS)?;
    let spread = col(OCP_SPREAD);
    let work = col(OCP_WORK_ERROR);
    let worlds = world_columns(table);
    // Feasible and trusted on its grid (tables without the work column: feasible only).
    let counts = |r: usize| primal[r] <= FEASIBLE && work.is_none_or(|w| w[r] <= OCP_WORK_TRUSTED);
    let objective = sel.objective.as_deref();
    let obj = objective.and_then(col);
    let maximise = objective.is_some_and(|o| sel.maximise.contains(o));
    let mask = ranked_mask(table);
    let ranked: Vec<usize> = rows
        .iter()
        .copied()
        .filter(|&r| mask.as_ref().is_none_or(|m| m[r]))
        .collect();
    let mut md = String::from("## Physical limit: the optimal-control bound (`[ocp]`)\n\n");
    md.push_str(&intro(worlds.is_some()));
    md.push('\n');
    // A robust study that ranks no design still shows its successful designs' bounds (the
    // bound does not depend on the ranking), and says so.
    let rows = if ranked.is_empty() && mask.is_some() && !rows.is_empty() {
        md.push_str(
            "No design is ranked over the worlds: the table compares the designs that met \
             `[success]` in the nominal world.\n\n",
        );
        rows.to_vec()
    } else {
        ranked
    };
    let mut entries: Vec<Entry> = rows
        .iter()
        .map(|&r| Entry {
            row: r,
            closed: (ts[r] + je[r]) / pp[r],
            bound: bound[r],
            efficiency: eff[r],
            objective: obj.map_or(f64::NAN, |o| o[r]),
        })
        .collect();
    let key = |e: &Entry| if maximise { -e.objective } else { e.objective };
    entries.sort_by(|a, b| key(a).total_cmp(&key(b)).then(a.row.cmp(&b.row)));
    let ids = table.i64(CASE_ID).unwrap_or(&[]);
    let name = |r: usize| {
        format!(
            "#{} {}",
            ids.get(r).copied().unwrap_or(r as i64),
            case_name(table, axes, r)
        )
    };
    let mut t = MarkdownTable::new([
        "design",
        objective.unwrap_or("objective"),
        "closed loop J/m",
        "bound J/m",
        "controller_efficiency",
        "bound status",
        "bound spread",
        "bound in worlds J/m",
    ]);
    for e in &entries {
        let feasible = counts(e.row);
        let in_worlds = world_cell(worlds, e.row);
        t.row([
            name(e.row),
            fmt_short(e.objective),
            fmt_short(e.closed),
            bound_cell(e.bound, feasible, primal[e.row], work.map(|w| w[e.row])),
            if feasible {
                fmt_short(e.efficiency)
            } else {
                "–".into()
            },
            status_word(status[e.row]).to_string(),
            spread.map_or("–".into(), |s| fmt_short(s[e.row])),
            in_worlds,
        ]);
    }
    md.push_str(&t.finish());
    md.push('\n');
    let ok: Vec<&Entry> = entries
        .iter()
        .filter(|e| counts(e.row) && e.bound.is_finite() && e.closed.is_finite())
        .collect();
    md.push_str(&agreement(&ok, &name));
    let above: Vec<String> = ok
        .iter()
        .filter(|e| e.efficiency > 1.0)
        .map(|e| format!("{} ({})", name(e.row), fmt_short(e.efficiency)))
        .collect();
    if !above.is_empty() {
        let _ = writeln!(
            md,
            "\n**Flagged: closed loop below its bound** (`controller_efficiency` > 1, an error of \
             one of them or missions that differ more than assumed): {}.",
            above.join(", ")
        );
    }
    bound_plot(&ok, &name, plots, warnings);
    md.push_str("\n![closed loop against bound](plots/bound.svg)\n\n");
    Some(md)
}

/// The opening paragraph: what the bound is, what it carries (`in_worlds`: `[ocp] worlds`),
/// when it counts.
fn intro(in_worlds: bool) -> String {
    let carried = if in_worlds {
        "It is also solved in the study's first scoring worlds (`[ocp] worlds`: their damping, \
         drag, added mass, derating, buoyancy errors and current, warm-started from the nominal \
         optimum): the range over those worlds is shown. **What the bound does not carry:** the \
         path's turn and initial offset (the leg is straight), the other worlds."
    } else {
        "**What the bound does not carry:** the path's turn and initial offset (the leg is \
         straight), the worlds (`[ocp] worlds` solves it in the first scoring worlds too)."
    };
    format!(
        "Each design's **bound** is the least thruster energy (zero inflow) plus joint energy the \
         best local optimum found spends on the study's straight transport leg (`[ocp]`: from \
         rest to rest, thrusts and joint torques as controls on the full hydrodynamic model of \
         the case's plant, `[mission]` payload included; never claimed global), per metre. \
         Beside it the closed loop's `(thruster_energy_static + joint_energy) / path_progress` \
         in the nominal world, and `controller_efficiency` = bound / closed loop. {carried} A \
         bound counts where its trajectory is feasible (primal residual ≤ {}) and its work \
         balance holds on its grid (`ocp_work_error` ≤ {}: the controls integrated 10× finer; \
         above it the optimum swims on energy the integration supplies).\n",
        fmt_short(FEASIBLE),
        fmt_short(OCP_WORK_TRUSTED)
    )
}

/// The bound cell: the bound per metre, or in brackets with why it does not count.
fn bound_cell(bound: f64, counts: bool, primal: f64, work: Option<f64>) -> String {
    if counts {
        fmt_short(bound)
    } else if primal <= FEASIBLE {
        let w = fmt_short(work.unwrap_or(f64::NAN));
        format!("({}, off its grid: work error {w})", fmt_short(bound))
    } else {
        format!("({}, infeasible)", fmt_short(bound))
    }
}

/// The bound-in-worlds cell of row `r`: the range over the worlds whose bound counts, and how
/// many were rejected because the grid supplied their energy.
fn world_cell(worlds: Option<WorldColumns<'_>>, r: usize) -> String {
    let rejected = |g: Option<&[f64]>| match g.map(|g| g[r]) {
        Some(n) if n > 0.0 => format!("; {n} rejected: grid energy"),
        _ => String::new(),
    };
    match worlds {
        Some((a, b, c, _, g)) if c[r] > 0.0 => {
            format!(
                "{}–{} ({} feasible{})",
                fmt_short(a[r]),
                fmt_short(b[r]),
                c[r],
                rejected(g)
            )
        }
        // No nominal bound that counts: nothing to start the worlds from.
        Some((_, _, c, i, _)) if c[r] == 0.0 && i[r] == 0.0 => "not tried".into(),
        Some((_, _, c, i, g)) if c[r] == 0.0 => {
            format!("none feasible ({} iterations{})", i[r], rejected(g))
        }
        _ => "–".into(),
    }
}

/// The world columns: least, greatest, feasible count, iterations, and the grid-rejected
/// count (absent from tables written before it existed).
type WorldColumns<'a> = (
    &'a [f64],
    &'a [f64],
    &'a [f64],
    &'a [f64],
    Option<&'a [f64]>,
);

/// The world columns of `table` (`None` without `[ocp] worlds`).
fn world_columns(table: &Table) -> Option<WorldColumns<'_>> {
    let col = |n: &str| table.f64(n).ok();
    Some((
        col(OCP_WORLD_MIN)?,
        col(OCP_WORLD_MAX)?,
        col(OCP_WORLD_FEASIBLE)?,
        col(OCP_WORLD_ITERATIONS)?,
        col(OCP_WORLD_GRID_REJECTED),
    ))
}

/// The sentence on agreement: is the closed-loop leader also the design with the lowest
/// bound, the rank correlation of the two orders, and the designs limited by the controller
/// (bound below the leader's, closed loop above it). `ok` is sorted by the objective.
fn agreement(ok: &[&Entry], name: &dyn Fn(usize) -> String) -> String {
    let Some(leader) = ok.first() else {
        return "No design has both a feasible bound and a closed-loop run to compare.\n".into();
    };
    let lowest = ok
        .iter()
        .min_by(|a, b| a.bound.total_cmp(&b.bound).then(a.row.cmp(&b.row)))
        .expect("non-empty");
    let rho = spearman(
        &ok.iter().map(|e| e.closed).collect::<Vec<_>>(),
        &ok.iter().map(|e| e.bound).collect::<Vec<_>>(),
    );
    let mut s = if leader.row == lowest.row {
        format!(
            "**The ranking by bound agrees at the top:** the closed-loop leader {} also has the \
             lowest bound ({} J/m).",
            name(leader.row),
            fmt_short(leader.bound)
        )
    } else {
        format!(
            "**The ranking by bound disagrees at the top:** the closed-loop leader {} has bound {} \
             J/m; the lowest bound is {}'s ({} J/m).",
            name(leader.row),
            fmt_short(leader.bound),
            name(lowest.row),
            fmt_short(lowest.bound)
        )
    };
    let _ = write!(
        s,
        " Spearman rank correlation of closed-loop cost and bound over the {} designs: {}.",
        ok.len(),
        fmt_short(rho)
    );
    let limited: Vec<String> = ok
        .iter()
        .skip(1)
        .filter(|e| e.bound < leader.bound)
        .map(|e| name(e.row))
        .collect();
    if limited.is_empty() {
        s.push_str(" No design with a lower bound than the leader's ranks below it.\n");
    } else {
        let _ = writeln!(
            s,
            " Limited by the controller rather than by the layout (a lower bound than the \
             leader's, a worse closed loop): {}.",
            limited.join(", ")
        );
    }
    s
}

/// Spearman's rank correlation of `a` and `b` (average ranks on ties; NaN below 3 points).
pub(crate) fn spearman(a: &[f64], b: &[f64]) -> f64 {
    if a.len() < 3 || a.len() != b.len() {
        return f64::NAN;
    }
    let ranks = |v: &[f64]| {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&i, &j| v[i].total_cmp(&v[j]));
        let mut r = vec![0.0; v.len()];
        let mut i = 0;
        while i < idx.len() {
            let mut j = i;
            while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
                j += 1;
            }
            for k in i..=j {
                r[idx[k]] = (i + j) as f64 / 2.0;
            }
            i = j + 1;
        }
        r
    };
    let (ra, rb) = (ranks(a), ranks(b));
    let n = ra.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in ra.iter().zip(&rb) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// `plots/bound.svg` (and its PDF): closed loop (y) against bound (x) per design, the diagonal
/// y = x (the perfect controller) dashed.
fn bound_plot(
    ok: &[&Entry],
    name: &dyn Fn(usize) -> String,
    plots: &Path,
    warnings: &mut Vec<String>,
) {
    let points: Vec<LabelledPoint> = ok
        .iter()
        .map(|e| LabelledPoint {
            x: e.bound,
            y: e.closed,
            label: name(e.row),
        })
        .collect();
    let lead = if points.is_empty() { vec![] } else { vec![0] };
    let hi = ok
        .iter()
        .flat_map(|e| [e.bound, e.closed])
        .fold(0.0_f64, f64::max);
    let fig = scatter_labelled(
        &points,
        &lead,
        "Closed loop against the optimal-control bound",
        &format!("bound: {}", metric_title(OCP_ENERGY_PER_METRE)),
        "closed loop: (thruster_energy_static + joint_energy) / path_progress [J/m]",
    );
    let result = fig.and_then(|mut fig| {
        let p = &mut fig.panels[0];
        p.series[0].name = "designs (feasible bound)".into();
        if let Some(s) = p.series.get_mut(2) {
            s.name = "closed-loop leader".into();
        }
        let mut diag = Series::new("perfect controller (y = x)", vec![0.0, hi], vec![0.0, hi])
            .kind(PanelKind::Line);
        diag.style = LineStyle::Dashed;
        p.series.push(diag);
        fig.write_svg_pdf(&plots.join("bound.svg"))
    });
    if let Err(e) = result {
        warnings.push(e.to_string());
    }
}

#[cfg(test)]
mod tests {
    use super::spearman;

    #[test]
    fn spearman_matches_scipy_on_a_small_sample() {
        // scipy.stats.spearmanr([1, 2, 3, 4, 5], [5, 6, 7, 8, 7]).statistic = 0.8207826816681233
        let r = spearman(&[1.0, 2.0, 3.0, 4.0, 5.0], &[5.0, 6.0, 7.0, 8.0, 7.0]);
        assert!((r - 0.820_782_681_668_123_3).abs() < 1e-12, "{r}");
        assert!((spearman(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]) + 1.0).abs() < 1e-15);
        assert!(spearman(&[1.0, 2.0], &[1.0, 2.0]).is_nan());
    }
}

//! What the sweep report looks at: the metric columns, their direction, the objective and the
//! trade-off ([`Selection`]), and the helpers both the Markdown summary and the plots use
//! (number formatting, the levels of an axis, means over rows, thinning).
//!
//! Only successful cases (status `ok`: for a closed-loop run, every `[success]` criterion
//! met) are ranked, averaged or put on the Pareto front; signed metrics
//! ([`BY_MAGNITUDE`]) are ranked by their magnitude.

use std::collections::HashSet;

use crate::batch::manifest::Manifest;
use crate::batch::records::{
    CaseStatus, DESIGN_THRUSTERS, RAW_HEAD, STATUS, TCM_SINGULAR_FRACTION,
};
use crate::report::{fmt_short, pareto_front, ColumnData, ColumnKind, Table};
pub use crate::study::directions::{
    is_identifier, larger_is_better, BY_MAGNITUDE, ENERGY_PER_METRE, SUCCESS, TRANSPORT_OBJECTIVE,
    WORLD_SUFFIXES,
};

/// Relative difference below which two values of a metric tie in `Selection::best_row`
/// (far above rounding, far below any difference a design review would act on).
pub const TIE_REL: f64 = 1e-9;

/// Most points drawn per scatter panel (a deterministic stride through the rows beyond it),
/// so plots of 100 000-case sweeps stay small.
pub const MAX_PLOT_POINTS: usize = 4000;

/// Every `k`-th row so that at most [`MAX_PLOT_POINTS`] remain.
pub(crate) fn thin(rows: &[usize]) -> Vec<usize> {
    let k = rows.len().div_ceil(MAX_PLOT_POINTS).max(1);
    rows.iter().copied().step_by(k).collect()
}

/// Which metrics the report looks at and in which direction.
pub struct Selection {
    /// Every metric column (f64, not an axis, not an identifier or flag:
    /// [`is_identifier`]).
    pub metrics: Vec<String>,
    /// Metrics where larger is better.
    pub maximise: HashSet<String>,
    /// Signed metrics ranked by magnitude (smaller |x| is better), see [`BY_MAGNITUDE`].
    pub magnitude: HashSet<String>,
    /// Objective for best/worst.
    pub objective: Option<String>,
    /// Pareto trade-off `(x, y)`.
    pub pareto: Option<(String, String)>,
}

impl Selection {
    /// Resolve the settings of `manifest` against the columns of `table`.
    pub fn new(table: &Table, manifest: &Manifest) -> Self {
        let axes: HashSet<&str> = manifest.axes.iter().map(|a| a.name.as_str()).collect();
        let metrics: Vec<String> = table
            .columns
            .iter()
            .filter(|c| c.data.kind() == ColumnKind::F64)
            .map(|c| c.name.clone())
            .filter(|n| {
                !RAW_HEAD.contains(&n.as_str()) && !axes.contains(n.as_str()) && !is_identifier(n)
            })
            .collect();
        let has = |n: &str| metrics.iter().any(|m| m == n);
        let mut maximise: HashSet<String> = manifest.report.maximise.iter().cloned().collect();
        for m in &metrics {
            if larger_is_better(m) {
                maximise.insert(m.clone());
            }
        }
        let energy = metrics
            .iter()
            .find(|m| *m == TRANSPORT_OBJECTIVE)
            .or_else(|| metrics.iter().find(|m| *m == ENERGY_PER_METRE))
            .or_else(|| metrics.iter().find(|m| m.contains("energy")))
            .cloned();
        let magnitude: HashSet<String> = metrics
            .iter()
            .filter(|m| BY_MAGNITUDE.contains(&m.as_str()))
            .cloned()
            .collect();
        let objective = manifest
            .report
            .objective
            .clone()
            .filter(|o| has(o))
            .or_else(|| energy.clone())
            .or_else(|| has(TCM_SINGULAR_FRACTION).then(|| TCM_SINGULAR_FRACTION.to_string()))
            .or_else(|| metrics.first().cloned());
        let pareto = match &manifest.report.pareto {
            Some([x, y]) if has(x) && has(y) => Some((x.clone(), y.clone())),
            _ => {
                let x = energy.or_else(|| has(DESIGN_THRUSTERS).then(|| DESIGN_THRUSTERS.into()));
                let y = metrics
                    .iter()
                    .find(|m| m.contains("singular") && !m.starts_with("tcm_"))
                    .cloned()
                    .or_else(|| has(TCM_SINGULAR_FRACTION).then(|| TCM_SINGULAR_FRACTION.into()));
                x.zip(y)
            }
        };
        Selection {
            metrics,
            maximise,
            magnitude,
            objective,
            pareto,
        }
    }

    /// The value `x` of `metric` as ranked: |x| for a metric ranked by magnitude.
    pub(crate) fn ranked(&self, metric: &str, x: f64) -> f64 {
        if self.magnitude.contains(metric) {
            x.abs()
        } else {
            x
        }
    }

    /// The goal of `metric` as written in the report: `max`, `min` or `min abs` (no `|`: the
    /// goal sits in Markdown table cells).
    pub(crate) fn goal(&self, metric: &str) -> &'static str {
        if self.maximise.contains(metric) {
            "max"
        } else if self.magnitude.contains(metric) {
            "min abs"
        } else {
            "min"
        }
    }

    fn better(&self, metric: &str, a: f64, b: f64) -> bool {
        let (a, b) = (self.ranked(metric, a), self.ranked(metric, b));
        if self.maximise.contains(metric) {
            a > b
        } else {
            a < b
        }
    }

    /// Row of the best value of `metric` among the successful (`ok`) rows (first on ties).
    /// Values within [`TIE_REL`] of each other tie: two designs equal by symmetry do not
    /// swap places on rounding noise (e.g. a change of the eigenvalue kernel's last bits).
    pub(crate) fn best_row(&self, table: &Table, metric: &str, worst: bool) -> Option<usize> {
        let v = table.f64(metric).ok()?;
        let status = table.str(STATUS).ok()?;
        let mut best: Option<usize> = None;
        for i in 0..v.len() {
            if CaseStatus::parse(&status[i]) != Some(CaseStatus::Ok) || !v[i].is_finite() {
                continue;
            }
            let replace = match best {
                None => true,
                Some(b) => {
                    let tie = (v[i] - v[b]).abs() <= TIE_REL * v[i].abs().max(v[b].abs());
                    !tie && if worst {
                        self.better(metric, v[b], v[i])
                    } else {
                        self.better(metric, v[i], v[b])
                    }
                }
            };
            if replace {
                best = Some(i);
            }
        }
        best
    }

    /// `(best, worst)` rows by the objective.
    pub fn extremes(&self, table: &Table) -> Option<(usize, usize)> {
        let o = self.objective.as_ref()?;
        Some((
            self.best_row(table, o, false)?,
            self.best_row(table, o, true)?,
        ))
    }

    pub(crate) fn key_metrics(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        let mut push = |m: &String| {
            if !out.contains(m) && out.len() < 10 {
                out.push(m.clone());
            }
        };
        if let Some(o) = &self.objective {
            push(o);
        }
        if let Some((x, y)) = &self.pareto {
            push(x);
            push(y);
        }
        for e in [TRANSPORT_OBJECTIVE, ENERGY_PER_METRE] {
            if let Some(m) = self.metrics.iter().find(|x| *x == e) {
                push(m);
            }
        }
        for m in &self.metrics {
            if !m.starts_with("design_") && !m.starts_with("tcm_lost_") && m != SUCCESS {
                push(m);
            }
        }
        out
    }
}

/// The text of a cell in a Markdown table (`|` escaped).
pub(crate) fn cell_text(table: &Table, col: &str, row: usize) -> String {
    match table.column(col).map(|c| &c.data) {
        Some(ColumnData::F64(v)) => fmt_short(v[row]),
        Some(ColumnData::I64(v)) => v[row].to_string(),
        Some(ColumnData::Str(v)) => v[row].replace('|', "\\|"),
        Some(ColumnData::Bool(v)) => v[row].to_string(),
        None => String::new(),
    }
}

/// The levels of an axis over `rows`: `(label, x position, rows)`. Numeric axes with more than
/// 12 distinct values are binned into 6 equal-count bins.
pub(crate) fn levels(table: &Table, axis: &str, rows: &[usize]) -> Vec<(String, f64, Vec<usize>)> {
    match table.column(axis).map(|c| &c.data) {
        Some(ColumnData::F64(v)) => {
            let mut distinct: Vec<f64> = rows
                .iter()
                .map(|&r| v[r])
                .filter(|x| x.is_finite())
                .collect();
            distinct.sort_by(f64::total_cmp);
            distinct.dedup();
            if distinct.len() <= 12 {
                distinct
                    .iter()
                    .map(|&x| {
                        (
                            fmt_short(x),
                            x,
                            rows.iter().copied().filter(|&r| v[r] == x).collect(),
                        )
                    })
                    .collect()
            } else {
                let mut sorted: Vec<usize> =
                    rows.iter().copied().filter(|&r| v[r].is_finite()).collect();
                sorted.sort_by(|&a, &b| v[a].total_cmp(&v[b]).then(a.cmp(&b)));
                let k = 6;
                (0..k)
                    .filter_map(|b| {
                        let lo = b * sorted.len() / k;
                        let hi = (b + 1) * sorted.len() / k;
                        let rs: Vec<usize> = sorted[lo..hi].to_vec();
                        let (a, z) = (v[*rs.first()?], v[*rs.last()?]);
                        let mut rs = rs;
                        rs.sort_unstable();
                        Some((
                            format!("[{}, {}]", fmt_short(a), fmt_short(z)),
                            0.5 * (a + z),
                            rs,
                        ))
                    })
                    .collect()
            }
        }
        Some(ColumnData::Str(v)) => {
            let mut order: Vec<&str> = Vec::new();
            for &r in rows {
                if !order.contains(&v[r].as_str()) {
                    order.push(&v[r]);
                }
            }
            order
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    (
                        s.to_string(),
                        i as f64,
                        rows.iter().copied().filter(|&r| v[r] == *s).collect(),
                    )
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

/// Mean of the finite values of `v` at `rows` (NaN when none).
pub(crate) fn mean(v: &[f64], rows: &[usize]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for &r in rows {
        if v[r].is_finite() {
            s += v[r];
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

/// The rows whose status is `ok`: the successful cases, the only ones ranked.
pub(crate) fn ok_rows(table: &Table) -> Vec<usize> {
    let status = table.str(STATUS).unwrap_or(&[]);
    (0..table.n_rows())
        .filter(|&i| status.get(i).and_then(|s| CaseStatus::parse(s)) == Some(CaseStatus::Ok))
        .collect()
}

/// The Pareto-optimal `ok` cases of the trade-off `x` vs `y`.
pub(crate) struct Front<'a> {
    /// The metric along x.
    pub x: &'a str,
    /// The metric along y.
    pub y: &'a str,
    /// Values of `x` by table row.
    pub xs: &'a [f64],
    /// Values of `y` by table row.
    pub ys: &'a [f64],
    /// The `ok` rows with finite `x` and `y`.
    pub rows: Vec<usize>,
    /// Positions in `rows` of the non-dominated cases.
    pub front: Vec<usize>,
}

impl Selection {
    /// The Pareto front of the selection's trade-off over `ok_rows` (each metric minimised,
    /// maximised or minimised in magnitude as the selection says); `None` without a
    /// trade-off.
    pub(crate) fn front<'a>(&'a self, table: &'a Table, ok_rows: &[usize]) -> Option<Front<'a>> {
        let (x, y) = self.pareto.as_ref()?;
        let (xs, ys) = (table.f64(x).unwrap_or(&[]), table.f64(y).unwrap_or(&[]));
        // Minimise both: negate what is maximised, |x| for what is ranked by magnitude.
        let key = |mname: &str, v: f64| {
            let v = self.ranked(mname, v);
            if self.maximise.contains(mname) {
                -v
            } else {
                v
            }
        };
        let rows: Vec<usize> = ok_rows
            .iter()
            .copied()
            .filter(|&r| xs[r].is_finite() && ys[r].is_finite())
            .collect();
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .map(|&r| (key(x, xs[r]), key(y, ys[r])))
            .collect();
        let front = pareto_front(&pts);
        Some(Front {
            x,
            y,
            xs,
            ys,
            rows,
            front,
        })
    }
}

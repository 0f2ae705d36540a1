//! Single thruster faults of a study (`[faults]`, issue 24): after a case is tuned and run in
//! the nominal world, it is run again — same tuned values, nominal world, the one case
//! evaluator — once per thruster with that thruster failed (a scenario `[fault]`,
//! `crate::scenario::fault`), like a validation variant (`super::worlds`). Its row gains
//!
//! - per thruster `j` (numbered from 1, like the design's `T1`, `T2`, …): `fault.t<j>.success` (1/0), `fault.t<j>.objective` (the study's
//!   objective in the faulted run), `fault.t<j>.change` (its relative change from the nominal
//!   run, `(x − x₀)/|x₀|`) and `fault.t<j>.missed` (the first `[success]` criterion the faulted
//!   run missed, as its index in `Criterion::ALL`; `no_failure` for a run that failed or could
//!   not be set up; NaN when it met all);
//! - `fault_tolerance`: the fraction of single faults after which the run still succeeds;
//! - `worst_fault`: the thruster whose loss hurts most — an unsuccessful faulted run before any
//!   successful one, then the largest worsening of the objective (by its direction; a NaN
//!   objective counts as the worst), then the lowest index.
//!
//! The faulted runs of one case are independent: they run side by side and are collected in
//! thruster order, so the row does not depend on the thread count. A faulted run that fails
//! is recorded (its `missed` criterion is `no_failure`) and the batch goes on.

use super::records::DESIGN_THRUSTERS;
use super::worlds::{criterion_index, evaluate_varied, WorldTimeout};
use crate::evaluate::{Deadline, Evaluator, Metrics, Override, Phases};
use crate::input::keypath::Seg;
use crate::report::{fmt_short, MarkdownTable, Table};
use crate::scenario::criteria::Criterion;
use crate::study::cases::Resolved;
use crate::study::directions::{larger_is_better, BY_MAGNITUDE, SUCCESS};
use crate::study::schema::Study;
use rayon::prelude::*;

/// Prefix of the per-thruster fault columns (`fault.t<j>.<what>`).
pub const FAULT_PREFIX: &str = "fault.t";
/// Fraction of single thruster faults after which the case still succeeds.
pub const FAULT_TOLERANCE: &str = "fault_tolerance";
/// The thruster whose loss hurts most (see the module docs).
pub const WORST_FAULT: &str = "worst_fault";

/// The metric the fault columns report: `study.objective`, else the uncertain worlds'
/// objective, else `mission_cost` (as the validation variants).
pub fn fault_objective(study: &Study) -> String {
    (study.report.objective.clone())
        .or_else(|| {
            study
                .uncertainty
                .as_ref()
                .map(|u| u.objective().to_string())
        })
        .unwrap_or_else(|| crate::study::directions::TRANSPORT_OBJECTIVE.to_string())
}

/// One faulted run: success, objective, missed criterion index; whether it timed out.
struct FaultRun {
    ok: bool,
    objective: f64,
    missed: f64,
    timeout: bool,
}

/// Run resolved case `r` (at its tuned values, nominal world) once per thruster with the
/// study's single fault and add the fault columns to `metrics` (see the module docs).
pub fn score_faults(
    study: &Study,
    id: usize,
    r: &Resolved,
    deadline: Deadline,
    metrics: &mut Metrics,
) -> Result<(), WorldTimeout> {
    let Some(fs) = &study.faults else {
        return Ok(());
    };
    let n = metrics.value(DESIGN_THRUSTERS);
    let n = if n.is_finite() && n >= 0.0 {
        n as usize
    } else {
        0
    };
    let objective = fault_objective(study);
    let phases = Phases {
        static_analysis: false,
        closed_loop: true,
    };
    let runs: Vec<FaultRun> = (0..n)
        .into_par_iter()
        .map_init(Evaluator::new, |evaluator, j| {
            let Ok(spec @ toml::Value::Table(_)) = toml::Value::try_from(fs.spec(j)) else {
                return FaultRun::not_run();
            };
            // Thruster j's fault as the case's `[fault]` table (one override).
            let fault = [Override::scenario(
                vec![Seg::Key("fault".into())],
                spec,
                "fault",
            )];
            let res = evaluate_varied(evaluator, r, id, phases, false, deadline, &fault);
            FaultRun {
                ok: res.success(),
                objective: res.metrics.value(&objective),
                missed: res.end.missed_criterion().map_or(f64::NAN, criterion_index),
                timeout: res.end.timed_out(),
            }
        })
        .collect();
    if runs.iter().any(|f| f.timeout) {
        return Err(WorldTimeout { world: usize::MAX });
    }
    let nominal = metrics.value(&objective);
    let change = |x: f64| (x - nominal) / nominal.abs();
    for (j, f) in runs.iter().enumerate() {
        let col = |m: &str| format!("{FAULT_PREFIX}{}.{m}", j + 1);
        metrics.set(&col(SUCCESS), f64::from(u8::from(f.ok)));
        metrics.set(&col("objective"), f.objective);
        metrics.set(&col("change"), change(f.objective));
        metrics.set(&col("missed"), f.missed);
    }
    let tolerance = if n == 0 {
        f64::NAN
    } else {
        runs.iter().filter(|f| f.ok).count() as f64 / n as f64
    };
    metrics.set(FAULT_TOLERANCE, tolerance);
    metrics.set(WORST_FAULT, worst_fault(&objective, nominal, &runs));
    Ok(())
}

impl FaultRun {
    fn not_run() -> Self {
        FaultRun {
            ok: false,
            objective: f64::NAN,
            missed: criterion_index(Criterion::NoFailure),
            timeout: false,
        }
    }
}

/// How much worse `x` is than `nominal` for `objective` (larger = worse; NaN = +∞).
fn worsening(objective: &str, nominal: f64, x: f64) -> f64 {
    let d = if larger_is_better(objective) {
        nominal - x
    } else if BY_MAGNITUDE.contains(&objective) {
        x.abs() - nominal.abs()
    } else {
        x - nominal
    };
    if d.is_nan() {
        f64::INFINITY
    } else {
        d
    }
}

/// The worst single fault (see the module docs), numbered from 1 like the thrusters (`T1`)
/// and the `fault.t<j>` columns; NaN without thrusters.
fn worst_fault(objective: &str, nominal: f64, runs: &[FaultRun]) -> f64 {
    let key = |f: &FaultRun| (!f.ok, worsening(objective, nominal, f.objective));
    let mut best: Option<(usize, (bool, f64))> = None;
    for (j, f) in runs.iter().enumerate() {
        let k = key(f);
        let worse = match best {
            None => true,
            Some((_, b)) => k.0 && !b.0 || (k.0 == b.0 && k.1 > b.1),
        };
        if worse {
            best = Some((j, k));
        }
    }
    best.map_or(f64::NAN, |(j, _)| (j + 1) as f64)
}

/// The layouts × single faults table of `summary.md`: one row per ranked (successful) case
/// in `ranked` order, one column per thruster; a cell is ✓ or ✗ (with the criterion missed)
/// and the objective's relative change. `None` when the table has no fault columns.
pub fn fault_table(
    table: &Table,
    ranked: &[usize],
    ids: &[i64],
    objective: &str,
) -> Option<String> {
    let tol = table.f64(FAULT_TOLERANCE).ok()?;
    let worst = table.f64(WORST_FAULT).ok()?;
    let n = (0..)
        .take_while(|j| {
            table
                .f64(&format!("{FAULT_PREFIX}{}.{SUCCESS}", j + 1))
                .is_ok()
        })
        .count();
    let heads: Vec<String> = (1..=n).map(|j| format!("t{j}")).collect();
    let mut t = MarkdownTable::new(
        ["case", FAULT_TOLERANCE, WORST_FAULT]
            .into_iter()
            .chain(heads.iter().map(String::as_str)),
    );
    let col = |j: usize, m: &str| table.f64(&format!("{FAULT_PREFIX}{}.{m}", j + 1)).ok();
    for &r in ranked {
        let mut cells = vec![
            format!("#{}", ids.get(r).copied().unwrap_or(-1)),
            fmt_short(tol[r]),
            if worst[r].is_finite() {
                format!("t{}", worst[r])
            } else {
                "–".into()
            },
        ];
        for j in 0..n {
            let ok = col(j, SUCCESS).map_or(f64::NAN, |c| c[r]);
            let change = col(j, "change").map_or(f64::NAN, |c| c[r]);
            let missed = col(j, "missed").map_or(f64::NAN, |c| c[r]);
            // Changes that round to zero print as +0.0 % (not −0.0 %).
            let p = 100.0 * change;
            let pct = if change.is_finite() {
                format!(" {:+.1} %", if p.abs() < 0.05 { 0.0 } else { p })
            } else {
                String::new()
            };
            cells.push(if ok.is_nan() {
                "–".into()
            } else if ok == 1.0 {
                format!("✓{pct}")
            } else {
                let why = Criterion::ALL
                    .get(missed as usize)
                    .filter(|_| missed.is_finite())
                    .map_or("", |c| c.as_str());
                format!("✗ {why}{pct}")
            });
        }
        t.row(cells);
    }
    Some(format!(
        "## Single thruster faults\n\n\
         Each successful case re-run at its (tuned) values in the nominal world with one thruster \
         failed (`[faults]`), best `{objective}` first: ✓ still successful, ✗ not (the first \
         criterion missed), with the relative change of `{objective}`; `–` a thruster the \
         design does not have. `worst_fault`: an unsuccessful fault first, then the largest \
         worsening.\n\n{}\n",
        t.finish()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(ok: bool, objective: f64) -> FaultRun {
        FaultRun {
            ok,
            objective,
            missed: f64::NAN,
            timeout: false,
        }
    }

    #[test]
    fn the_worst_fault_is_a_failure_first_then_the_largest_worsening() {
        let e = "energy_per_metre";
        let runs = [run(true, 12.0), run(false, 10.5), run(true, 15.0)];
        assert_eq!(worst_fault(e, 10.0, &runs), 2.0);
        let runs = [run(true, 12.0), run(true, 15.0), run(true, 15.0)];
        assert_eq!(worst_fault(e, 10.0, &runs), 2.0, "ties: the lowest index");
        let runs = [run(true, 12.0), run(true, f64::NAN)];
        assert_eq!(
            worst_fault(e, 10.0, &runs),
            2.0,
            "a NaN objective is the worst"
        );
        let runs = [run(false, 20.0), run(false, 30.0)];
        assert_eq!(
            worst_fault(e, 10.0, &runs),
            2.0,
            "among failures, the worsening"
        );
        // A metric where larger is better: the largest drop.
        let runs = [run(true, 0.9), run(true, 0.5)];
        assert_eq!(worst_fault(SUCCESS, 1.0, &runs), 2.0);
        assert!(worst_fault(e, 10.0, &[]).is_nan());
    }
}

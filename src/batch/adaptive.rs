//! Adaptive worlds (issue 36 item 6; docs/statistics.md § Adaptive worlds): after every case
//! has met the study's first `worlds`, the designs still *in contention* meet further points of
//! the same Sobol sequence — the same added worlds for each (common random numbers kept) — and
//! the verdict is judged again, round after round, until it is decided or the budget
//! (`adaptive_worlds`, the most worlds a design meets) is spent.
//!
//! In contention after a round ([`contention`]): every design *pending* (it ran, its success
//! proportion meets `min_success_probability` but its Wilson lower bound does not yet) and
//! every ranked design the leader does not beat at the study's confidence whose median margin
//! is not inside the tie margin δ, `|margin| > δ` or NaN — the comparisons more worlds could
//! still change (a tie within δ is settled: more worlds would not separate it) — and, when any
//! of these exists, the leader itself (the paired tests need it in the same worlds). Nothing in
//! contention: *decided*. Each round brings every design in contention to
//! `min(budget, most worlds met among them + batch)` worlds.
//!
//! The added runs are a function of the table of the first worlds and the study only (each
//! round's contention is computed from the table, runs collected in (case, world) order), so
//! the tables are the same for any `--jobs`; `--resume` recomputes the rounds from the resumed
//! journal. Sharded sweeps are refused ([`refuse_shards`]): the contention needs every case.

use rayon::prelude::*;

use super::records::{CaseStatus, CASE_ID, REASON, STATUS};
use super::robust::{
    condition_verdicts, paired, split_worlds, AdaptiveInfo, RobustInfo, StudyVerdict,
};
use super::tuning_hook::{tuned_columns, CaseTuner};
use super::worlds::{push_world_columns, run_world, set_world_summaries, WORLD_PREFIX};
use crate::evaluate::{Deadline, Evaluator, Metrics};
use crate::report::{Column, ColumnData, Table};
use crate::stats::ranking::Verdict;
use crate::study::cases::resolve_case;
use crate::study::doe::Case;
use crate::study::error::StudyError;
use crate::study::schema::{Study, Uncertainty};

/// Column of a study with adaptive worlds: the worlds each case met.
pub const WORLDS_MET: &str = "worlds_met";

/// Why the adaptive rounds stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// Nothing is in contention: the verdict names a Winner, or no design is left that more
    /// worlds could rank or separate from the leader.
    Decided,
    /// Every design in contention met the budget.
    Budget,
}

impl Stop {
    /// The manifest's text (`decided`, `budget`).
    pub fn as_str(self) -> &'static str {
        match self {
            Stop::Decided => "decided",
            Stop::Budget => "budget",
        }
    }
}

/// A sharded sweep of a study with adaptive worlds is refused: which designs are in contention
/// depends on every case of the study.
pub fn refuse_shards(study: &Study, shard: Option<(usize, usize)>) -> Result<(), StudyError> {
    let adaptive = study.uncertainty.as_ref().and_then(|u| u.adaptive);
    match (adaptive, shard) {
        (Some(_), Some((i, n))) => Err(StudyError::Input(format!(
            "--shard {i}/{n}: {} has `adaptive_worlds` in [uncertainty]: which designs meet \
             further worlds depends on every case, so it cannot be sharded (run it unsharded, \
             or drop adaptive_worlds)",
            study.path.display()
        ))),
        _ => Ok(()),
    }
}

/// The rows in contention under verdict `sv` (see the module docs), in increasing order.
pub fn contention(sv: &StudyVerdict, delta: f64) -> Vec<usize> {
    let mut rows: Vec<usize> = sv.pending.iter().map(|p| p.row).collect();
    let (leader, unbeaten) = match &sv.verdict {
        Verdict::Tied { leader, tied } => (Some(*leader), tied.as_slice()),
        Verdict::Undecided { leader, open, .. } => (Some(*leader), open.as_slice()),
        Verdict::Winner { leader, .. } => (Some(*leader), &[][..]),
        Verdict::NoneEligible => (None, &[][..]),
    };
    rows.extend(
        unbeaten
            .iter()
            .filter(|c| c.margin.is_nan() || c.margin.abs() > delta)
            .map(|c| c.case),
    );
    if let (Some(l), false) = (leader, rows.is_empty()) {
        rows.push(l);
    }
    rows.sort_unstable();
    rows.dedup();
    rows
}

/// What the rounds need besides the table: the study, its cases (all of them, by id), the tuner
/// of a study with `[tune]` and the per-run wall-clock budget.
pub struct Rounds<'a> {
    /// The study.
    pub study: &'a Study,
    /// Every case of the study (`expand(study, None)`).
    pub cases: &'a [Case],
    /// The per-case tuner (`[tune]`): the added worlds run at the tuned values of the row.
    pub tuner: Option<&'a dyn CaseTuner>,
    /// Wall-clock budget of one added run (`None`: unlimited).
    pub budget: Option<std::time::Duration>,
}

/// Run the adaptive rounds on the final `table` (its per-world columns still in it): adds the
/// per-world columns of the worlds added, updates the summaries over worlds of the cases that
/// met them, adds [`WORLDS_MET`], and records the rounds in `info.adaptive` (trimming
/// `info.world_values` to the worlds used). A study without adaptive worlds is left as it is.
pub fn run_rounds(
    rounds: &Rounds,
    table: &mut Table,
    info: &mut RobustInfo,
) -> Result<(), StudyError> {
    let Some(u) = rounds.study.uncertainty.as_ref() else {
        return Ok(());
    };
    let Some(a) = u.adaptive else { return Ok(()) };
    let n = table.n_rows();
    // Worlds met and whether the case ran in worlds, as of the last verdict judged.
    let mut met = vec![u.worlds; n];
    let mut ran = vec![true; n];
    let delta = u.equivalence;
    let mut done = 0usize;
    let stop = loop {
        let mut t = table.clone();
        let Some(worlds) = split_worlds(&mut t, info) else {
            break Stop::Decided;
        };
        let (Some(svs), Some(pd)) = (
            condition_verdicts(&t, &worlds, info),
            paired(&t, &worlds, info),
        ) else {
            break Stop::Decided;
        };
        met.clone_from(&pd.met);
        ran.clone_from(&pd.ran);
        // The tie margin of each verdict: max(equivalence, tuning noise); the designs in
        // contention under any condition (one verdict without condition axes).
        let mut rows: Vec<usize> = svs
            .iter()
            .flat_map(|(_, sv)| contention(sv, delta.max(sv.noise)))
            .collect();
        rows.sort_unstable();
        if rows.is_empty() {
            break Stop::Decided;
        }
        let top = rows.iter().map(|&r| met[r]).max().unwrap_or(u.worlds);
        let target = (top + a.batch).min(a.budget);
        let todo: Vec<usize> = rows.into_iter().filter(|&r| met[r] < target).collect();
        if todo.is_empty() {
            break Stop::Budget;
        }
        one_round(rounds, u, table, &todo, &met, target)?;
        done += 1;
    };
    let used = met.iter().copied().max().unwrap_or(u.worlds).max(u.worlds);
    info.world_values.truncate(used);
    info.adaptive = Some(AdaptiveInfo {
        budget: a.budget,
        batch: a.batch,
        rounds: done,
        worlds_used: used,
        stopped: stop.as_str().into(),
    });
    let at = table
        .columns
        .iter()
        .position(|c| c.name == STATUS)
        .unwrap_or(table.columns.len());
    table.columns.insert(
        at,
        Column {
            name: WORLDS_MET.into(),
            // 0 for a case that did not run in worlds (failed, skipped, disqualified).
            data: ColumnData::F64(
                met.iter()
                    .zip(&ran)
                    .map(|(&m, &ran)| if ran { m as f64 } else { 0.0 })
                    .collect(),
            ),
        },
    );
    Ok(())
}

/// One round: rows `todo` of `table` (having met `met[r]` worlds) meet worlds up to `target`.
fn one_round(
    rounds: &Rounds,
    u: &Uncertainty,
    table: &mut Table,
    todo: &[usize],
    met: &[usize],
    target: usize,
) -> Result<(), StudyError> {
    let study = rounds.study;
    let ids = table.i64(CASE_ID)?.to_vec();
    let tuned: Vec<Vec<f64>> = tuned_columns(study)
        .iter()
        .map(|c| table.f64(c).map(<[f64]>::to_vec))
        .collect::<Result<_, _>>()?;
    let from = todo.iter().map(|&r| met[r]).min().unwrap_or(target);
    let worlds = u.sample_range(study.seed, from..target);
    // Each case at its values as scored (tuned values through the tuner).
    // Each case at its values as scored (tuned values through the tuner). A case that cannot be
    // rebuilt (its overrides or tuned values no longer apply) fails with the reason; the
    // others go on.
    let mut resolved = Vec::with_capacity(todo.len());
    for &r in todo {
        let case = usize::try_from(ids[r])
            .ok()
            .and_then(|id| rounds.cases.iter().find(|c| c.id == id))
            .ok_or_else(|| StudyError::Input(format!("case {} is not in the study", ids[r])))?;
        let rebuilt = resolve_case(study, case)
            .map_err(|e| e.to_string())
            .and_then(|res| match rounds.tuner {
                Some(t) => {
                    let x: Vec<f64> = tuned.iter().map(|c| c[r]).collect();
                    t.at(study, case, &res, &x).map_err(|e| e.to_string())
                }
                None => Ok(res),
            });
        match rebuilt {
            Ok(res) => resolved.push((r, case.id, res)),
            Err(e) => {
                set_str(table, STATUS, r, CaseStatus::Failed.as_str())?;
                set_str(table, REASON, r, &format!("adaptive worlds: {e}"))?;
            }
        }
    }
    let jobs: Vec<(usize, usize)> = (0..resolved.len())
        .flat_map(|i| {
            let start = met[resolved[i].0];
            (start..target).map(move |k| (i, k - from))
        })
        .collect();
    let runs: Vec<_> = jobs
        .par_iter()
        .with_max_len(1)
        .map_init(Evaluator::new, |ev, &(i, w)| {
            let (_, id, r) = &resolved[i];
            let deadline = Deadline::after(rounds.budget);
            run_world(ev, u, &worlds[w], *id, r, deadline)
        })
        .collect();
    for (i, (r, _, _)) in resolved.iter().enumerate() {
        let mine: Vec<_> = jobs
            .iter()
            .zip(&runs)
            .filter(|((j, _), _)| *j == i)
            .map(|((_, w), run)| (worlds[*w].index, run))
            .collect();
        if let Some((k, _)) = mine.iter().find(|(_, run)| run.timed_out()) {
            set_str(table, STATUS, *r, CaseStatus::Failed.as_str())?;
            set_str(
                table,
                REASON,
                *r,
                &format!(
                    "{} in adaptive world {k} (the case's wall-clock budget)",
                    crate::evaluate::TIMEOUT
                ),
            )?;
            continue;
        }
        for (k, run) in &mine {
            let mut m = Metrics::new();
            push_world_columns(u, *k, run, &mut m);
            for (name, x) in m.iter() {
                set_f64(table, name, *r, x);
            }
        }
        resummarise(u, table, *r, target);
    }
    Ok(())
}

/// The summaries over worlds of row `r`, which met worlds `0..n`, from its per-world columns.
fn resummarise(u: &Uncertainty, table: &mut Table, r: usize, n: usize) {
    let cell = |t: &Table, k: usize, m: &str| {
        t.f64(&format!("{WORLD_PREFIX}{k}.{m}"))
            .map_or(f64::NAN, |v| v[r])
    };
    let values: Vec<Vec<f64>> = u
        .metrics
        .iter()
        .map(|m| (0..n).map(|k| cell(table, k, m)).collect())
        .collect();
    let successes = (0..n)
        .filter(|&k| cell(table, k, crate::study::directions::SUCCESS) == 1.0)
        .count();
    set_world_summaries(u, &values, successes, |name, x| set_f64(table, name, r, x));
}

/// Set `table[name][r] = x`, adding the column (NaN elsewhere) when it is missing.
fn set_f64(table: &mut Table, name: &str, r: usize, x: f64) {
    let n = table.n_rows();
    if table.column(name).is_none() {
        table.columns.push(Column {
            name: name.into(),
            data: ColumnData::F64(vec![f64::NAN; n]),
        });
    }
    if let Some(Column {
        data: ColumnData::F64(v),
        ..
    }) = table.columns.iter_mut().find(|c| c.name == name)
    {
        v[r] = x;
    }
}

/// Set `table[name][r] = s` in a text column.
fn set_str(table: &mut Table, name: &str, r: usize, s: &str) -> Result<(), StudyError> {
    match table.columns.iter_mut().find(|c| c.name == name) {
        Some(Column {
            data: ColumnData::Str(v),
            ..
        }) => {
            v[r] = s.to_string();
            Ok(())
        }
        _ => Err(StudyError::Input(format!("no text column {name}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::robust::Pending;
    use crate::stats::ranking::Contender;
    use crate::study::schema::{UncertainParam, WorldDist, WorldSampling};

    fn contender(case: usize, margin: f64) -> Contender {
        Contender {
            case,
            p_beats: 0.5,
            margin,
            wins: 2,
            p_value: 0.5,
            p_adjusted: 0.5,
            needs_worlds: None,
        }
    }

    fn sv(verdict: Verdict, pending: &[usize]) -> StudyVerdict {
        StudyVerdict {
            verdict,
            noise: 0.0,
            noise_measured: false,
            below_requirement: 0,
            ranked: 3,
            pending: pending
                .iter()
                .map(|&row| Pending {
                    row,
                    worlds_needed: Some(7),
                    share: 1.0,
                    lower: 0.6,
                })
                .collect(),
        }
    }

    /// In contention: pending designs, unbeaten rivals beyond the tie margin (or with an
    /// unknown margin), and then the leader; ties within the margin and beaten rivals are not.
    #[test]
    fn contention_is_the_pending_the_unseparated_and_the_leader() {
        let d = 0.01;
        let winner = Verdict::Winner {
            leader: 2,
            runner_up: 1,
            p_beats: 1.0,
            margin: 0.1,
            p_value: 0.01,
        };
        assert!(contention(&sv(winner.clone(), &[]), d).is_empty());
        assert_eq!(contention(&sv(winner, &[4]), d), vec![2, 4]);
        let tied = Verdict::Tied {
            leader: 1,
            tied: vec![
                contender(0, 0.005),
                contender(3, -0.2),
                contender(5, f64::NAN),
            ],
        };
        assert_eq!(contention(&sv(tied, &[]), d), vec![1, 3, 5]);
        let within = Verdict::Tied {
            leader: 1,
            tied: vec![contender(0, 0.005)],
        };
        assert!(contention(&sv(within, &[]), d).is_empty());
        let open = Verdict::Undecided {
            leader: 0,
            open: vec![contender(2, 0.1)],
            needs_worlds: 7,
        };
        assert_eq!(contention(&sv(open, &[]), d), vec![0, 2]);
        assert_eq!(
            contention(&sv(Verdict::NoneEligible, &[3, 1]), d),
            vec![1, 3]
        );
        assert!(contention(&sv(Verdict::NoneEligible, &[]), d).is_empty());
    }

    /// Added worlds are the next points of the same sequence: worlds `0..n` sampled at once
    /// start with the study's first `worlds` and equal a study sampled with `worlds = n`.
    #[test]
    fn added_worlds_are_the_next_points_of_the_same_sequence() {
        let u = |worlds: usize| Uncertainty {
            worlds,
            sampling: WorldSampling::Points(crate::sampling::Sampling::Sobol),
            params: vec![UncertainParam {
                name: "hydro.linear_damping_scale".into(),
                target: crate::study::schema::Target::Scenario(
                    crate::input::keypath::KeyPath::parse("hydro.linear_damping_scale").unwrap(),
                ),
                dist: WorldDist::Uniform(0.5, 1.5),
                integer: false,
            }],
            metrics: vec!["energy_per_metre".into()],
            min_success_probability: 0.9,
            confidence: 0.95,
            equivalence: 0.01,
            adaptive: None,
        };
        let four = u(4);
        let all = four.sample_range(7, 0..12);
        assert_eq!(all[..4], four.sample(7)[..]);
        assert_eq!(all, u(12).sample(7));
        assert_eq!(four.sample_range(7, 4..12)[..], all[4..]);
        assert_eq!(all[9].index, 9);
    }
}

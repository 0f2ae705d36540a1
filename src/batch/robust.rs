//! The study-level view of uncertain worlds (issue 22): what `manifest.json` records about
//! them ([`RobustInfo`]), the per-world columns of the rows moved to `worlds.csv`
//! ([`split_worlds`]), the ranking columns `p_best`, `rank_p05`, `rank_p50`, `rank_p95`
//! ([`add_rank_columns`]) and the paired verdict the summary opens with ([`study_verdict`]).
//!
//! A case is ranked only when it ran and its `success_probability` reaches the study's
//! `min_success_probability`; ranks and `p_best` are among the ranked cases, world by world
//! (docs/statistics.md).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use std::path::Path;

use super::conditions::Condition;
use super::records::{
    final_table, CaseEnd, CaseStatus, CASES_CSV, CASES_PARQUET, CASE_ID, PARTIAL_FILE, REASON,
    STATUS,
};
use super::worlds::{MISSED, SUCCESS_PROBABILITY, WORLD_PREFIX};
use crate::report::{write_csv_streamed, write_parquet_with};
use crate::report::{Column, ColumnData, Table};
use crate::scenario::criteria::Criterion;
use crate::stats::confidence::{wilson_lower, wilson_worlds_needed, worlds_at_share};
use crate::stats::ranking::{rank_stats, verdict, Verdict, VerdictSettings};
use crate::study::directions::{larger_is_better, BY_MAGNITUDE, SUCCESS};
use crate::study::error::StudyError;
use crate::study::schema::{Study, TUNE_CURVE_PREFIX, TUNE_NOISE};
use crate::study::schema::{Uncertainty, WorldDist, WorldSampling};

/// The per-world table of a study output (long format: one row per case and world).
pub const WORLDS_CSV: &str = "worlds.csv";
/// Column of the ranking: fraction of worlds in which the case is best.
pub const P_BEST: &str = "p_best";
/// The one-sided Wilson lower bound of `success_probability` at the study's confidence, the
/// figure eligibility is judged by (docs/statistics.md, "Eligibility").
pub const SUCCESS_LOWER: &str = "success_probability_lower";
/// Rank columns (5 %, 50 %, 95 % quantiles over the worlds).
pub const RANK_COLUMNS: [&str; 3] = ["rank_p05", "rank_p50", "rank_p95"];
/// The best-so-far tuning curves of a tuned study (long format: case, evaluation, best).
pub const TUNING_CSV: &str = "tuning.csv";

/// An uncertain parameter as the manifest records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamInfo {
    /// Its key.
    pub name: String,
    /// Its distribution, as text.
    pub distribution: String,
}

/// What `manifest.json` records of a study's worlds and ranking rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobustInfo {
    /// Worlds each case met (besides the nominal one).
    pub worlds: usize,
    /// How they were drawn (`sobol`, `lhs`, `random`, `saltelli`).
    pub sampling: String,
    /// The uncertain parameters.
    pub params: Vec<ParamInfo>,
    /// Each world's parameter values (numbers; a `choice` of text by its index), by world.
    /// Beyond [`super::manifest::MAX_LISTED_WORLD_VALUES`] numbers `manifest.json` leaves them
    /// out and names the file that holds them (`world_values_in`, issue 39 item 3).
    #[serde(default)]
    pub world_values: Vec<Vec<f64>>,
    /// The file of the output directory holding the worlds' values when `manifest.json` does
    /// not list them (`worlds.csv`); absent when they are listed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub world_values_in: Option<String>,
    /// Metrics summarised over worlds; the first is the ranking objective.
    pub metrics: Vec<String>,
    /// Least success probability of a ranked case.
    pub min_success_probability: f64,
    /// Fraction of paired worlds a winner must win.
    pub confidence: f64,
    /// Relative margin called a tie.
    pub equivalence: f64,
    /// The validation variants' names.
    pub validate: Vec<String>,
    /// Adaptive worlds (`adaptive_worlds`): the budget, the batch, the rounds run and why
    /// they stopped; absent without the key.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<AdaptiveInfo>,
    /// The condition axes (`condition = true`), in file order: designs are ranked and judged
    /// only against designs under the same values of these ([`super::conditions`]); absent
    /// without any.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub conditions: Vec<String>,
}

/// What `manifest.json` records of a study's adaptive worlds (docs/statistics.md § Adaptive
/// worlds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdaptiveInfo {
    /// Most worlds a design may meet (`adaptive_worlds`).
    pub budget: usize,
    /// Worlds added per round (`adaptive_batch`).
    pub batch: usize,
    /// Rounds of added worlds run.
    pub rounds: usize,
    /// Most worlds any design met.
    pub worlds_used: usize,
    /// Why the rounds stopped ([`super::adaptive::Stop`] as text).
    pub stopped: String,
}

impl RobustInfo {
    /// The record of `study`'s `[uncertainty]` (`None` without it).
    pub fn of(study: &Study) -> Option<RobustInfo> {
        let u: &Uncertainty = study.uncertainty.as_ref()?;
        // With adaptive worlds, every world the budget allows (the sweep trims the list to the
        // worlds used).
        let world_values = u
            .sample_range(study.seed, 0..u.max_worlds())
            .iter()
            .map(|w| {
                w.values
                    .iter()
                    .zip(&u.params)
                    .map(|(v, p)| numeric(v, &p.dist))
                    .collect()
            })
            .collect();
        Some(RobustInfo {
            worlds: u.n_worlds(),
            sampling: match u.sampling {
                WorldSampling::Saltelli => "saltelli".into(),
                WorldSampling::Points(s) => s.to_string(),
            },
            params: u
                .params
                .iter()
                .map(|p| ParamInfo {
                    name: p.name.clone(),
                    distribution: p.dist.range_text(),
                })
                .collect(),
            world_values,
            world_values_in: None,
            metrics: u.metrics.clone(),
            min_success_probability: u.min_success_probability,
            confidence: u.confidence,
            equivalence: u.equivalence,
            validate: study.validate.iter().map(|v| v.name.clone()).collect(),
            adaptive: u.adaptive.map(|a| AdaptiveInfo {
                budget: a.budget,
                batch: a.batch,
                rounds: 0,
                worlds_used: u.worlds,
                stopped: String::new(),
            }),
            conditions: study
                .axes
                .iter()
                .filter(|a| a.condition)
                .map(|a| a.name.clone())
                .collect(),
        })
    }

    /// The ranking objective.
    pub fn objective(&self) -> &str {
        &self.metrics[0]
    }
}

/// The assumption ledger ([`crate::model::ledger`]) as `manifest.json` records it for a study
/// with `[uncertainty]`: every entry, plus `study_range`, the distribution this study gives
/// its key (null when the study holds it at its nominal value).
pub fn study_ledger(study: &Study) -> Option<serde_json::Value> {
    let u = study.uncertainty.as_ref()?;
    let mut v = crate::model::ledger::ledger_json();
    for e in v.as_array_mut()? {
        let key = e["key"].as_str().unwrap_or_default().to_string();
        let used = u
            .params
            .iter()
            .find(|p| !key.is_empty() && p.name == key)
            .map(|p| p.dist.range_text());
        e["study_range"] = used.map_or(serde_json::Value::Null, serde_json::Value::String);
    }
    Some(v)
}

/// A world value as a number: numbers as they are, a choice of text or booleans by index.
fn numeric(v: &toml::Value, d: &WorldDist) -> f64 {
    match v {
        toml::Value::Float(x) => *x,
        toml::Value::Integer(i) => *i as f64,
        _ => match d {
            WorldDist::Choice(c) => c.iter().position(|x| x == v).map_or(f64::NAN, |i| i as f64),
            _ => f64::NAN,
        },
    }
}

/// Moves the `f64` columns whose name `key` maps to a key out of `table`, by key (the journal's
/// per-world and per-tuning-run columns, which become long tables of their own).
fn take_columns<K: Ord>(
    table: &mut Table,
    key: impl Fn(&str) -> Option<K>,
) -> BTreeMap<K, Vec<f64>> {
    let mut taken = BTreeMap::new();
    let mut kept = Vec::with_capacity(table.columns.len());
    for c in std::mem::take(&mut table.columns) {
        match (key(&c.name), c.data) {
            (Some(k), ColumnData::F64(v)) => {
                taken.insert(k, v);
            }
            (_, data) => kept.push(Column { name: c.name, data }),
        }
    }
    table.columns = kept;
    taken
}

/// Move the per-world columns (`world.<k>.<metric>`) out of `table` into a long table
/// `world`, `case_id`, the parameter values, then each metric; `None` when there are none.
pub fn split_worlds(table: &mut Table, info: &RobustInfo) -> Option<Table> {
    let per = take_columns(table, |name| {
        let (k, m) = name.strip_prefix(WORLD_PREFIX)?.split_once('.')?;
        Some((k.parse::<usize>().ok()?, m.to_string()))
    });
    if per.is_empty() {
        return None;
    }
    let ids = table.i64(CASE_ID).ok()?.to_vec();
    let n_worlds = per.keys().map(|(k, _)| k + 1).max().unwrap_or(0);
    let mut metric_names: Vec<String> = info.metrics.clone();
    metric_names.push(SUCCESS.into());
    // With adaptive worlds, a case meets the worlds beyond the first `worlds` only while it is
    // in contention: those it did not meet (success NaN) are not rows.
    let base = if info.adaptive.is_some() {
        info.worlds
    } else {
        usize::MAX
    };
    let kept: Vec<(usize, usize)> = (0..n_worlds)
        .flat_map(|k| (0..ids.len()).map(move |r| (k, r)))
        .filter(|&(k, r)| {
            k < base
                || per
                    .get(&(k, SUCCESS.to_string()))
                    .is_some_and(|v| !v[r].is_nan())
        })
        .collect();
    let rows = kept.len();
    let mut world_col = Vec::with_capacity(rows);
    let mut case_col = Vec::with_capacity(rows);
    let mut params: Vec<Vec<f64>> = vec![Vec::with_capacity(rows); info.params.len()];
    let mut metrics: Vec<Vec<f64>> = vec![Vec::with_capacity(rows); metric_names.len()];
    for &(k, r) in &kept {
        world_col.push(k as i64);
        case_col.push(ids[r]);
        for (j, p) in params.iter_mut().enumerate() {
            p.push(
                info.world_values
                    .get(k)
                    .and_then(|w| w.get(j))
                    .copied()
                    .unwrap_or(f64::NAN),
            );
        }
        for (m, col) in metric_names.iter().zip(metrics.iter_mut()) {
            col.push(per.get(&(k, m.clone())).map_or(f64::NAN, |v| v[r]));
        }
    }
    let mut cols = vec![
        Column {
            name: "world".into(),
            data: ColumnData::I64(world_col),
        },
        Column {
            name: CASE_ID.into(),
            data: ColumnData::I64(case_col),
        },
    ];
    for (p, v) in info.params.iter().zip(params) {
        cols.push(Column {
            name: p.name.clone(),
            data: ColumnData::F64(v),
        });
    }
    for (m, v) in metric_names.into_iter().zip(metrics) {
        cols.push(Column {
            name: m,
            data: ColumnData::F64(v),
        });
    }
    let missed: Vec<String> = kept
        .iter()
        .map(|&(k, r)| {
            per.get(&(k, MISSED.to_string()))
                .and_then(|v| v[r].is_finite().then(|| v[r] as usize))
                .and_then(|i| Criterion::ALL.get(i))
                .map_or(String::new(), |c| c.as_str().to_string())
        })
        .collect();
    cols.push(Column {
        name: MISSED.into(),
        data: ColumnData::Str(missed),
    });
    Table::from_columns(cols).ok()
}

/// Move the best-so-far tuning curves (`tune_curve.<k>`) out of `table` into a long table
/// `case_id`, `evaluation`, `best` (rows past a case's last evaluation left out); `None`
/// when there are none.
pub fn split_tuning(table: &mut Table) -> Option<Table> {
    let curves = take_columns(table, |name| {
        name.strip_prefix(TUNE_CURVE_PREFIX)?.parse::<usize>().ok()
    });
    if curves.is_empty() {
        return None;
    }
    let ids = table.i64(CASE_ID).ok()?.to_vec();
    let (mut case, mut eval, mut best) = (Vec::new(), Vec::new(), Vec::new());
    for (r, id) in ids.iter().enumerate() {
        for (k, v) in &curves {
            // A curve shorter than the longest reads NaN past its end: not a row.
            if r < v.len() && !(v[r].is_nan() && curves.range(k..).all(|(_, w)| w[r].is_nan())) {
                case.push(*id);
                eval.push(*k as i64 + 1);
                best.push(v[r]);
            }
        }
    }
    Table::new()
        .with(CASE_ID, ColumnData::I64(case))
        .and_then(|t| t.with("evaluation", ColumnData::I64(eval)))
        .and_then(|t| t.with("best", ColumnData::F64(best)))
        .ok()
}

/// The paired data of the ranking: per case of `table` (in row order), its objective (as
/// ranked: smaller is better) and success in each world, and whether it is ranked.
pub struct Paired {
    /// `obj[c][w]`.
    pub obj: Vec<Vec<f64>>,
    /// `ok[c][w]`.
    pub ok: Vec<Vec<bool>>,
    /// Whether case `c` ran (`ok` or `unsuccessful`): it met its worlds.
    pub ran: Vec<bool>,
    /// Whether case `c` is ranked: it ran and the Wilson lower bound of its success
    /// probability reaches the requirement.
    pub eligible: Vec<bool>,
    /// Worlds in which case `c` succeeded with a finite objective.
    pub successes: Vec<usize>,
    /// The one-sided Wilson lower bound of case `c`'s success probability at the study's
    /// confidence ([`wilson_lower`]).
    pub lower: Vec<f64>,
    /// Worlds case `c` met: the length of its rows `obj[c]`, `ok[c]` (the same for every case
    /// but with adaptive worlds, which give the designs in contention more).
    pub met: Vec<usize>,
}

/// The paired data of `table`'s cases from `worlds` (see [`Paired`]).
pub fn paired(table: &Table, worlds: &Table, info: &RobustInfo) -> Option<Paired> {
    let objective = info.objective();
    let ids = table.i64(CASE_ID).ok()?;
    let status = table.str(STATUS).ok()?;
    // Present in every robust table (the point estimate beside the bound below).
    table.f64(SUCCESS_PROBABILITY).ok()?;
    let row_of: BTreeMap<i64, usize> = ids.iter().enumerate().map(|(r, id)| (*id, r)).collect();
    let n_worlds = worlds
        .i64("world")
        .ok()?
        .iter()
        .max()
        .map_or(0, |m| *m as usize + 1);
    let (wc, cc) = (worlds.i64("world").ok()?, worlds.i64(CASE_ID).ok()?);
    // Every case met worlds 0..met (a prefix of the sequence): all `n_worlds` without adaptive
    // worlds.
    let mut met = vec![0usize; ids.len()];
    for (w, c) in wc.iter().zip(cc) {
        if let Some(&r) = row_of.get(c) {
            met[r] = met[r].max(*w as usize + 1);
        }
    }
    debug_assert!(met.iter().all(|m| *m <= n_worlds));
    let mut obj: Vec<Vec<f64>> = met.iter().map(|&m| vec![f64::NAN; m]).collect();
    let mut ok: Vec<Vec<bool>> = met.iter().map(|&m| vec![false; m]).collect();
    let (wo, ws) = (worlds.f64(objective).ok()?, worlds.f64(SUCCESS).ok()?);
    let sign = if larger_is_better(objective) {
        -1.0
    } else {
        1.0
    };
    let magnitude = BY_MAGNITUDE.contains(&objective);
    for i in 0..wc.len() {
        let Some(&r) = row_of.get(&cc[i]) else {
            continue;
        };
        let x = if magnitude { wo[i].abs() } else { wo[i] };
        obj[r][wc[i] as usize] = sign * x;
        ok[r][wc[i] as usize] = ws[i] == 1.0;
    }
    // A disqualified design (out of reach, under-actuated) never ran in worlds.
    let reason = table.str(REASON).ok();
    let ran: Vec<bool> = status
        .iter()
        .enumerate()
        .map(|(r, s)| {
            matches!(
                CaseStatus::parse(s),
                Some(CaseStatus::Ok | CaseStatus::Unsuccessful)
            ) && !reason.is_some_and(|x| {
                CaseStatus::parse(s)
                    .and_then(|s| CaseEnd::read(s, &x[r]))
                    .is_some_and(|e| e.disqualified())
            })
        })
        .collect();
    // Eligibility by confidence, not by the proportion (issue 36 item 6): the one-sided Wilson
    // lower bound of the success probability at the study's confidence must reach the
    // requirement (docs/statistics.md, "Eligibility").
    let successes: Vec<usize> = ok
        .iter()
        .zip(&obj)
        .map(|(o, v)| {
            o.iter()
                .zip(v)
                .filter(|(s, x)| **s && x.is_finite())
                .count()
        })
        .collect();
    let lower: Vec<f64> = successes
        .iter()
        .zip(&met)
        .map(|(&k, &n)| wilson_lower(k, n, info.confidence))
        .collect();
    let eligible = (0..ids.len())
        .map(|r| ran[r] && lower[r] >= info.min_success_probability)
        .collect();
    Some(Paired {
        obj,
        ok,
        ran,
        eligible,
        successes,
        lower,
        met,
    })
}

/// Add `p_best` and the rank quantiles (NaN for unranked cases) before `status`.
pub fn add_rank_columns(table: &mut Table, worlds: &Table, info: &RobustInfo) {
    let Some(pd) = paired(table, worlds, info) else {
        return;
    };
    let n = table.n_rows();
    let mut cols = vec![vec![f64::NAN; n]; 4];
    // Ranks and p_best among the ranked designs under the same condition, never across them.
    for cond in super::conditions::conditions(table, &info.conditions) {
        let idx: Vec<usize> = (0..pd.eligible.len())
            .filter(|&c| pd.eligible[c] && cond.rows[c])
            .collect();
        let obj: Vec<Vec<f64>> = idx.iter().map(|&c| pd.obj[c].clone()).collect();
        let ok: Vec<Vec<bool>> = idx.iter().map(|&c| pd.ok[c].clone()).collect();
        let stats = rank_stats(&obj, &ok);
        for (s, &c) in stats.iter().zip(&idx) {
            for (col, x) in cols
                .iter_mut()
                .zip([s.p_best, s.rank_p05, s.rank_p50, s.rank_p95])
            {
                col[c] = x;
            }
        }
    }
    // The Wilson lower bound beside the point estimate, for every case that ran.
    cols.insert(
        0,
        (0..n)
            .map(|r| if pd.ran[r] { pd.lower[r] } else { f64::NAN })
            .collect(),
    );
    let at = table
        .columns
        .iter()
        .position(|c| c.name == STATUS)
        .unwrap_or(table.columns.len());
    for (name, v) in [
        SUCCESS_LOWER,
        P_BEST,
        RANK_COLUMNS[0],
        RANK_COLUMNS[1],
        RANK_COLUMNS[2],
    ]
    .into_iter()
    .zip(cols)
    .rev()
    {
        table.columns.insert(
            at,
            Column {
                name: name.into(),
                data: ColumnData::F64(v),
            },
        );
    }
}

/// The verdict of a study's output, in terms of its table's rows, with the noise used.
pub struct StudyVerdict {
    /// The verdict (case indices are rows of the table).
    pub verdict: Verdict,
    /// Median relative tuning noise of the ranked cases (0 without tuning starts to compare).
    pub noise: f64,
    /// Whether the tuning noise was measured (a study with `[tune] starts` ≥ 2).
    pub noise_measured: bool,
    /// Cases not ranked for a success probability below the requirement.
    pub below_requirement: usize,
    /// Cases ranked.
    pub ranked: usize,
    /// Cases that ran whose success proportion meets the requirement but whose lower bound
    /// does not yet (too few worlds).
    pub pending: Vec<Pending>,
}

/// A case not ranked only for too few worlds: its success proportion meets the requirement,
/// its Wilson lower bound does not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pending {
    /// The case's row.
    pub row: usize,
    /// Worlds it would need at the same proportion (`None`: not reachable).
    pub worlds_needed: Option<usize>,
    /// Its success proportion over the worlds.
    pub share: f64,
    /// Its Wilson lower bound.
    pub lower: f64,
}

/// The fewest worlds in which a success proportion `share` gives a Wilson lower bound at the
/// study's confidence that reaches its requirement (`None` beyond 65 536 worlds or when the
/// share itself is below the requirement).
fn worlds_for_share(share: f64, info: &RobustInfo) -> Option<usize> {
    let need = info.min_success_probability;
    if share >= 1.0 {
        return wilson_worlds_needed(need, info.confidence);
    }
    if share <= need {
        return None;
    }
    worlds_at_share(share, 1, |k, n| wilson_lower(k, n, info.confidence) >= need)
}

/// The paired verdict of `table` (rows) with `worlds` under `info`'s rule, the tuning noise
/// (median `tune_noise` of the ranked cases) counted as a tie margin.
pub fn study_verdict(table: &Table, worlds: &Table, info: &RobustInfo) -> Option<StudyVerdict> {
    study_verdict_in(table, worlds, info, None)
}

/// [`study_verdict`] among the rows `within[r]` only (one condition,
/// [`super::conditions`]): the others are neither ranked, pending nor counted.
pub fn study_verdict_in(
    table: &Table,
    worlds: &Table,
    info: &RobustInfo,
    within: Option<&[bool]>,
) -> Option<StudyVerdict> {
    let mut pd = paired(table, worlds, info)?;
    if let Some(w) = within {
        for r in (0..pd.ran.len()).filter(|&r| !w.get(r).copied().unwrap_or(false)) {
            (pd.ran[r], pd.eligible[r]) = (false, false);
        }
    }
    let mut noise: Vec<f64> = table
        .f64(TUNE_NOISE)
        .map(|v| {
            v.iter()
                .zip(&pd.eligible)
                .filter(|(x, e)| **e && x.is_finite())
                .map(|(x, _)| *x)
                .collect()
        })
        .unwrap_or_default();
    noise.sort_by(f64::total_cmp);
    let noise_measured = !noise.is_empty();
    let noise = if noise.is_empty() {
        0.0
    } else {
        crate::stats::describe::quantile_sorted(&noise, 0.5)
    };
    let settings = VerdictSettings {
        confidence: info.confidence,
        equivalence: info.equivalence,
        noise,
    };
    let below_requirement = (0..pd.eligible.len())
        .filter(|&r| pd.ran[r] && !pd.eligible[r])
        .count();
    let pending = (0..pd.eligible.len())
        .filter(|&r| {
            pd.ran[r]
                && !pd.eligible[r]
                && pd.met[r] > 0
                && pd.successes[r] as f64 >= info.min_success_probability * pd.met[r] as f64
        })
        .map(|r| {
            let share = pd.successes[r] as f64 / pd.met[r] as f64;
            Pending {
                row: r,
                worlds_needed: worlds_for_share(share, info),
                share,
                lower: pd.lower[r],
            }
        })
        .collect();
    Some(StudyVerdict {
        verdict: verdict(&pd.obj, &pd.ok, &pd.eligible, &settings),
        noise,
        noise_measured,
        below_requirement,
        ranked: pd.eligible.iter().filter(|e| **e).count(),
        pending,
    })
}

/// The verdict of each condition of `table` ([`super::conditions::conditions`] of `info.conditions`), each among
/// its own rows only; one verdict over every row for a study without condition axes.
pub fn condition_verdicts(
    table: &Table,
    worlds: &Table,
    info: &RobustInfo,
) -> Option<Vec<(Condition, StudyVerdict)>> {
    super::conditions::conditions(table, &info.conditions)
        .into_iter()
        .map(|c| {
            let v = study_verdict_in(table, worlds, info, Some(&c.rows))?;
            Some((c, v))
        })
        .collect()
}

/// Write compacted raw rows to the partial file of `out` and the final table to
/// [`CASES_CSV`] and [`CASES_PARQUET`]; returns the final table (built from `raw`'s columns).
///
/// With uncertain worlds (`robust`), the per-world columns move to
/// [`WORLDS_CSV`] and the ranking columns are added
/// ([`add_rank_columns`]). `cases.parquet` carries the data dictionary of its columns
/// (`axes` named as such) in its metadata ([`crate::study::dictionary::parquet_metadata`]).
pub fn write_tables(
    raw: Table,
    out: &Path,
    robust: Option<&RobustInfo>,
    axes: &[&str],
) -> Result<Table, StudyError> {
    write_tables_with(raw, out, robust.cloned(), axes, |_, _| Ok(())).map(|(t, _)| t)
}

/// [`write_tables`] with `extend` run on the final table (its per-world columns still in it)
/// and the record of the worlds before the worlds are split off — the adaptive rounds of a
/// study with `adaptive_worlds` (`super::adaptive::run_rounds`); returns the table and the
/// record of the worlds.
pub fn write_tables_with(
    raw: Table,
    out: &Path,
    mut robust: Option<RobustInfo>,
    axes: &[&str],
    extend: impl FnOnce(&mut Table, &mut RobustInfo) -> Result<(), StudyError>,
) -> Result<(Table, Option<RobustInfo>), StudyError> {
    write_csv_streamed(&raw, &out.join(PARTIAL_FILE))?;
    let mut table = final_table(raw)?;
    if let Some(curves) = split_tuning(&mut table) {
        write_csv_streamed(&curves, &out.join(TUNING_CSV))?;
    }
    if let Some(info) = robust.as_mut() {
        extend(&mut table, info)?;
        if let Some(worlds) = split_worlds(&mut table, info) {
            write_csv_streamed(&worlds, &out.join(WORLDS_CSV))?;
            add_rank_columns(&mut table, &worlds, info);
        }
    }
    write_case_files(&mut table, out, axes)?;
    Ok((table, robust))
}

/// Write `table` to [`CASES_CSV`] and [`CASES_PARQUET`] in `out`: whole-number columns as
/// integers ([`crate::study::dictionary::integers_for_files`]; `table` is left as it was), the
/// dictionary of the columns in the Parquet file's metadata.
pub fn write_case_files(table: &mut Table, out: &Path, axes: &[&str]) -> Result<(), StudyError> {
    crate::study::dictionary::integers_for_files(table, true);
    let meta = crate::study::dictionary::parquet_metadata(table, axes);
    let written = write_csv_streamed(table, &out.join(CASES_CSV))
        .and_then(|()| write_parquet_with(table, &out.join(CASES_PARQUET), &meta));
    crate::study::dictionary::integers_for_files(table, false);
    Ok(written?)
}

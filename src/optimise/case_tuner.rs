//! Per-case tuning of a sweep (`[tune]`, `docs/study-format.md`): every case is first tuned —
//! its own design, its own axis values — by the optimiser ([`minimise`] over the case's
//! resolved tables), then scored at the tuned values like any case. The sweep reaches this
//! tuner through its hook ([`HOOK`], a [`TuningHook`] the caller hands to the sweep, the
//! merge and the report): `study` never imports `optimise`.
//!
//! `[tune]` holds the sections of a problem file (`[[tune.param]]`, `[tune.objective]`,
//! `[[tune.constraint]]`, `[tune.solver]`; `docs/optimise.md`), read by
//! [`crate::study::tune_spec_parse::parse_spec`] and validated when the study is loaded
//! ([`crate::study::tune_section`]; the typed section is [`Study::tuning`]). A parameter without
//! `start` starts from the case's own value of its key (clamped to the bounds), so an axis
//! over `control.method` starts each method from its own Table III row.
//!
//! Determinism: the tuning of a case runs serially (one thread), every evaluation as the
//! case itself (its seed), so the tuned values and the row depend only on the study and the
//! case id — identical for any `--jobs` and any sharding. The case's [`Deadline`]
//! (`--case-timeout`) covers tuning and scoring: a run past it fails `timeout`.

use super::evaluate::CaseEvaluator;
use super::history::Record;
use super::tune_seeds::{
    compare_in_pooled_worlds, raw_metrics_objective, relative_spread, tune_worlds_seed, SeedResult,
    WorldsOf, SEEDS_STREAM,
};
use super::{minimise, Options, Problem, Spec};
use crate::batch::tuning_hook::{CaseTuner, TuneError, Tuned, TuningHook};
use crate::evaluate::{Deadline, AUTHORITY_COLUMNS, TCM_COLUMNS};
use crate::input::keypath::get;
use crate::sampling::{derive_seed, Sampler, Sampling};
use crate::study::cases::Resolved;
use crate::study::doe::Case;
use crate::study::error::InputError;
use crate::study::schema::{Study, Target, TuneSection};
pub use crate::study::tune_section::{MAX_SEEDS, MAX_STARTS, MAX_TUNE_WORLDS};
use crate::study::tune_spec_parse::in_worlds;
use rayon::prelude::*;

/// The hook wiring this tuner into sweeps, merges and reports.
pub const HOOK: TuningHook = TuningHook(boxed);

fn boxed(study: &Study) -> Result<Option<Box<dyn CaseTuner>>, InputError> {
    Ok(Tuner::new(study).map(|t| Box::new(t) as Box<dyn CaseTuner>))
}

/// A study's validated `[tune]` section.
#[derive(Clone, Debug)]
pub struct Tuner {
    /// The `[tune]` section as the study read it (spec, starts, worlds, seeds, race, screen).
    section: TuneSection,
    /// Whether the tuning objective or constraints read static TCM metrics.
    static_needed: bool,
}

/// Seed stream of the tuning starts' Sobol points (shared by every case).
const STARTS_STREAM: u64 = 0x5354_4152_5453; // "STARTS"

/// A parameter within this fraction of the unit box from a bound counts as on the bound.
pub const BOUND_TOLERANCE: f64 = 1e-3;

impl Tuner {
    /// The tuner of `study`'s `[tune]` section (`None` without one): the section typed and
    /// validated when the study was read ([`Study::tuning`], `crate::study::tune_section`);
    /// nothing is parsed here.
    pub fn new(study: &Study) -> Option<Tuner> {
        let t = study.tuning.as_ref()?;
        let static_needed = study.static_enabled
            && t.spec.metrics().iter().any(|m| {
                TCM_COLUMNS.contains(&m.as_str()) || AUTHORITY_COLUMNS.contains(&m.as_str())
            });
        Some(Tuner {
            section: t.clone(),
            static_needed,
        })
    }

    /// The problem tuning one case: the study with the case's resolved tables as its base
    /// and no axes; each parameter without `start` starts from the case's value. Public for
    /// the solver benchmark (`examples/solver_efficiency.rs`).
    pub fn case_problem(&self, study: &Study, r: &Resolved) -> Problem {
        self.case_problem_in(study, r, true)
    }

    /// [`Tuner::case_problem`], in the tuning worlds (`[tune] worlds`) or, with `in_worlds_too`
    /// false, in the nominal world alone (the scenario the tuned case is scored in).
    fn case_problem_in(&self, study: &Study, r: &Resolved, in_worlds_too: bool) -> Problem {
        let worlds = if in_worlds_too {
            WorldsOf::Seed(0)
        } else {
            WorldsOf::Nominal
        };
        self.case_problem_with(study, r, worlds)
    }

    /// [`Tuner::case_problem`] in the worlds `which` names: none (nominal), one tuning seed's,
    /// or every seed's pooled.
    fn case_problem_with(&self, study: &Study, r: &Resolved, which: WorldsOf) -> Problem {
        let mut cs = study.clone();
        cs.design = r.design.clone();
        cs.scenario_full = r.scenario.clone();
        cs.axes.clear();
        cs.tune = None;
        cs.tuning = None;
        cs.static_enabled = self.static_needed;
        let mut spec = self.section.spec.clone();
        for (p, explicit) in spec
            .space
            .params
            .iter_mut()
            .zip(&self.section.explicit_start)
        {
            if !explicit {
                if let Some(x) = case_value(&p.target, r) {
                    p.start = x.clamp(p.lower, p.upper);
                }
            }
        }
        if let Some(u) = &self.section.worlds {
            // Every candidate in every tuning world: the objective combines the worlds
            // (`[tune.objective] combine`, default the mean) and each constraint must hold in
            // each of them, as in a problem file's `[uncertainty]`.
            let seeds: Vec<usize> = match which {
                WorldsOf::Nominal => Vec::new(),
                WorldsOf::Seed(k) => vec![k],
                WorldsOf::Pooled => (0..self.section.seeds).collect(),
            };
            if !seeds.is_empty() {
                let variants = std::mem::take(&mut spec.variants);
                for k in seeds {
                    let mut v = in_worlds(variants.clone(), u, tune_worlds_seed(study.seed, k));
                    if matches!(which, WorldsOf::Pooled) {
                        for x in &mut v {
                            x.name = format!("s{k}/{}", x.name);
                        }
                    }
                    spec.variants.extend(v);
                }
            }
        }
        Problem { study: cs, spec }
    }

    /// One tuning seed's search of case `case`: the seed's tuning worlds, its starts side by
    /// side. Seed 0 is the tuning of a study without `seeds` exactly.
    fn tune_seed(
        &self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        deadline: Deadline,
        k: usize,
    ) -> Result<SeedResult, TuneError> {
        let mut problem = self.case_problem_with(study, r, WorldsOf::Seed(k));
        if self.section.screen {
            screen_with_rk4(&mut problem.study.scenario_full);
        }
        let ev = CaseEvaluator::new(&problem).for_case(case.id, deadline);
        let mut spec = problem.spec.clone();
        if k > 0 {
            spec.solver.seed = derive_seed(spec.solver.seed, SEEDS_STREAM ^ k as u64);
        }
        let quiet = |_: &Record| {};
        let opts = Options {
            jobs: 1,
            journal: None,
            resume: false,
            on_record: &quiet,
            race: self.section.race,
        };
        let d = spec.space.dim();
        let starts_seed = if k == 0 {
            derive_seed(study.seed, STARTS_STREAM)
        } else {
            derive_seed(derive_seed(study.seed, STARTS_STREAM), k as u64)
        };
        let sobol = Sampler::new(Sampling::Sobol, self.section.starts.max(2), d, starts_seed)
            .map_err(TuneError::from_error)?;
        spec.solver.max_evals = self.section.spec.solver.max_evals / self.section.starts;
        // The starts' points depend only on the Sobol stream, so the starts are independent
        // runs: side by side (a case tuned last, or alone, keeps every thread busy), their
        // outcomes combined in start order so nothing depends on the thread count.
        let specs = if k == 0 {
            start_specs(&spec, self.section.starts, &sobol)
        } else {
            // A later seed starts every start from the Sobol stream (its start 0 too), so it
            // does not retrace seed 0's first start from the case's own values.
            let mut v = start_specs(&spec, self.section.starts + 1, &sobol);
            v.remove(0);
            v
        };
        let outs: Vec<_> = specs
            .par_iter()
            .with_max_len(1)
            .map(|s| minimise(s, &ev, &study.hash, &opts))
            .collect();
        let (mut best, mut bests, mut curve) = (None, Vec::new(), Vec::new());
        let (mut evaluations, mut runs) = (0, 0);
        for out in outs {
            let out = out.map_err(TuneError::from_error)?;
            evaluations += out.fresh_evaluations();
            runs += out.scenario_runs();
            best_so_far(&out.records, &mut curve);
            // Each start normalises its objective by its own start point: compare starts by
            // the unnormalised objective, not by their scores.
            let b = out.best().clone();
            let raw = raw_objective(&out.scorer, &b);
            bests.push(if b.score.feasible { raw } else { f64::NAN });
            let better = |x: &(Record, f64)| match (b.score.feasible, x.0.score.feasible) {
                (true, true) => raw < x.1,
                _ => b.score.better_than(&x.0.score),
            };
            if best.as_ref().is_none_or(better) {
                best = Some((b, raw));
            }
        }
        let (best, _) = best.ok_or_else(|| TuneError::msg("no tuning start ran"))?;
        Ok(SeedResult {
            best,
            noise: relative_spread(&bests),
            curve,
            evaluations,
            runs,
        })
    }
}

impl CaseTuner for Tuner {
    /// Tune case `case` (resolved as `r`) within `deadline`: the case at the best point.
    ///
    /// With `[tune] seeds = S > 1`, each seed tunes afresh ([`Tuner::tune_seed`]); the seeds'
    /// best points are then run in the pooled tuning worlds of every seed (the nominal world
    /// without `[tune] worlds`), and the case takes the point that is feasible there (or
    /// least infeasible) with the lowest objective. `tune_noise` is then the relative spread
    /// of the seeds' pooled objectives and `tune_success_spread` the spread of the fraction
    /// of pooled worlds in which each seed's point meets every constraint: the seeds'
    /// disagreement on what the verdict uses.
    fn tune(
        &self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        deadline: Deadline,
    ) -> Result<Tuned, TuneError> {
        let runs: Vec<Result<SeedResult, TuneError>> = (0..self.section.seeds)
            .into_par_iter()
            .with_max_len(1)
            .map(|k| self.tune_seed(study, case, r, deadline, k))
            .collect();
        let mut seeds = Vec::with_capacity(runs.len());
        for run in runs {
            seeds.push(run?);
        }
        let mut evaluations: usize = seeds.iter().map(|s| s.evaluations).sum();
        let mut runs: usize = seeds.iter().map(|s| s.runs).sum();
        let mut curve = Vec::new();
        for s in &seeds {
            // Each seed's curve carries the earlier seeds' best on (as starts do).
            let carried = curve.last().copied().unwrap_or(f64::NAN);
            curve.extend(
                s.curve
                    .iter()
                    .map(|&c| match (c.is_nan(), carried.is_nan()) {
                        (true, _) => carried,
                        (false, true) => c,
                        (false, false) => c.min(carried),
                    }),
            );
        }
        let (pick, feasible, noise, success_spread) = if seeds.len() == 1 {
            let s = &seeds[0];
            (0, s.best.score.feasible, s.noise, f64::NAN)
        } else {
            let pooled = self.case_problem_with(study, r, WorldsOf::Pooled);
            let p = compare_in_pooled_worlds(&pooled, case.id, deadline, &seeds);
            evaluations += p.evaluations;
            runs += p.evaluations * pooled.spec.variants.len();
            (p.pick, p.feasible, p.noise, p.success_spread)
        };
        let best = &seeds[pick].best;
        let best_x = best.x.clone();
        // Scored as the case itself at the tuned point: in the nominal world ([`CaseTuner::at`]).
        let resolved = self.at(study, case, r, &best_x)?;
        let bound_hits = best
            .u
            .iter()
            .filter(|u| **u <= BOUND_TOLERANCE || **u >= 1.0 - BOUND_TOLERANCE)
            .count();
        Ok(Tuned {
            resolved,
            x: best_x,
            evaluations,
            runs,
            feasible,
            noise,
            success_spread,
            bound_hits,
            curve,
        })
    }

    fn at(
        &self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        x: &[f64],
    ) -> Result<Resolved, TuneError> {
        // The case as scored: the nominal world (variant 0 of the tuning problem is its first
        // tuning world when `[tune] worlds` is set).
        let problem = self.case_problem_in(study, r, false);
        let mut s = CaseEvaluator::new(&problem)
            .for_case(case.id, Deadline::NONE)
            .resolve(x, 0)
            .map_err(TuneError::from_error)?;
        s.hash = r.hash.clone();
        Ok(s)
    }
}

/// Set `scenario` to run with RK4 at its control period (`[tune] screen = "rk4"`): physics
/// steps of `scenario.control_dt` (default [`crate::scenario::config::DEFAULT_CONTROL_DT`]),
/// one per control period, instead of the adaptive Dormand–Prince steps.
fn screen_with_rk4(scenario: &mut toml::Table) {
    let sc = scenario
        .entry("scenario")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(sc) = sc.as_table_mut() {
        let control_dt = sc
            .get("control_dt")
            .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
            .unwrap_or(crate::scenario::config::DEFAULT_CONTROL_DT);
        sc.insert("dt".into(), toml::Value::Float(control_dt));
    }
    let ph = scenario
        .entry("physics")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let Some(ph) = ph.as_table_mut() {
        ph.insert("integrator".into(), toml::Value::String("rk4".into()));
    }
}

/// The specs of a tuning's `starts` independent starts: start 0 from `spec` as it is, start
/// `k > 0` from the `k−1`-th point of `sobol` (the unit box of the parameters) and, for a
/// seeded solver (swarm, CMA-ES, Bayesian optimisation), its own seed `derive_seed(seed, k)`.
/// With the study's seed in every start, Bayesian optimisation drew the same Latin hypercube
/// in each and its tuning noise (the spread of the starts' bests) read 0; Nelder–Mead uses no
/// seed, so its tunings are unchanged.
fn start_specs(spec: &Spec, starts: usize, sobol: &Sampler) -> Vec<Spec> {
    let d = spec.space.dim();
    (0..starts)
        .map(|k| {
            let mut s = spec.clone();
            if k > 0 {
                s.solver.seed = derive_seed(spec.solver.seed, k as u64);
                let mut u = vec![0.0; d];
                sobol.point(k - 1, &mut u);
                for (p, u) in s.space.params.iter_mut().zip(&u) {
                    p.start = p.value(*u);
                }
            }
            s
        })
        .collect()
}

/// Append the best feasible objective so far after each fresh evaluation of `records` to
/// `curve` (NaN until one is feasible); a later start carries the earlier starts' best on.
fn best_so_far(records: &[Record], curve: &mut Vec<f64>) {
    let mut best = curve.last().copied().unwrap_or(f64::NAN);
    for r in records.iter().filter(|r| !r.repeat) {
        if r.score.feasible && (best.is_nan() || r.score.objective < best) {
            best = r.score.objective;
        }
        curve.push(best);
    }
}

/// The unnormalised objective of `r`: `Σ w_i · m_i` with each term's metric averaged over the
/// scenarios. The starts of a tuning normalise by their own start points, so their scores are
/// not comparable; this is.
fn raw_objective(scorer: &super::score::Scorer, r: &Record) -> f64 {
    raw_metrics_objective(scorer, &r.metrics)
}

/// The case's value of a parameter's key (a number), if it has one.
fn case_value(target: &Target, r: &Resolved) -> Option<f64> {
    let v = match target {
        Target::Design(p) => get(&r.design, &p.0),
        Target::Scenario(p) => get(&r.scenario, &p.0),
    }?;
    match v {
        toml::Value::Float(x) => Some(*x),
        toml::Value::Integer(n) => Some(*n as f64),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::super::problem::{Combine, Objective, Term};
    use super::super::score::{Score, Scorer};
    use super::{raw_objective, start_specs, Record, Tuner};
    use crate::sampling::{Sampler, Sampling};

    /// Independent starts are independent for seeded solvers too: each start after the first
    /// has its own seed (before, Bayesian optimisation drew the same Latin hypercube in every
    /// start and its tuning noise read 0), while start 0 keeps the study's seed and start
    /// point, so a one-start tuning and Nelder–Mead (no seed) are unchanged.
    #[test]
    fn each_tuning_start_after_the_first_has_its_own_seed_and_start_point() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/thrusters.toml");
        let study = crate::study::parse::load_study(&path).unwrap();
        let tuner = Tuner::new(&study).unwrap();
        let spec = &tuner.section.spec;
        let d = spec.space.dim();
        let sobol = Sampler::new(Sampling::Sobol, 3, d, 11).unwrap();
        let specs = start_specs(spec, 4, &sobol);
        assert_eq!(specs.len(), 4);
        assert_eq!(specs[0].solver.seed, spec.solver.seed);
        let starts = |s: &super::Spec| s.space.params.iter().map(|p| p.start).collect::<Vec<_>>();
        assert_eq!(starts(&specs[0]), starts(spec));
        for (i, a) in specs.iter().enumerate() {
            for b in &specs[i + 1..] {
                assert_ne!(a.solver.seed, b.solver.seed);
                assert_ne!(starts(a), starts(b));
            }
            for p in &a.space.params {
                assert!(
                    p.start >= p.lower && p.start <= p.upper,
                    "{}: {}",
                    p.name,
                    p.start
                );
            }
            // Only the seed and the start point differ between starts.
            assert_eq!(a.solver.max_evals, spec.solver.max_evals);
            assert_eq!(a.solver.method, spec.solver.method);
        }
    }

    /// `[tune] worlds = N` scores every candidate in N worlds of the study's `[uncertainty]`
    /// (every uncertain key set in each), drawn from their own seed stream: not the scoring
    /// worlds, the same for every case, none without the key.
    #[test]
    fn tuning_worlds_are_the_uncertain_keys_drawn_apart_from_the_scoring_worlds() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/thrusters.toml");
        // The main study tunes in 4 worlds: its text without them is the nominal tuning.
        let text = std::fs::read_to_string(&path).unwrap().replacen(
            "\nworlds = 4\nseeds = 2\n",
            "\nseeds = 2\n",
            1,
        );
        let with = text.replacen("[tune]\n", "[tune]\nworlds = 3\n", 1);
        assert_ne!(with, text);
        let nominal = crate::study::parse::parse_study(&text, &path).unwrap();
        let study = crate::study::parse::parse_study(&with, &path).unwrap();
        let cases = crate::study::doe::expand(&study, None).unwrap();
        let problem = |s: &crate::study::schema::Study, id: usize| {
            let r = crate::study::cases::resolve_case(s, &cases[id]).unwrap();
            Tuner::new(s).unwrap().case_problem(s, &r)
        };
        assert_eq!(problem(&nominal, 0).spec.variants.len(), 1);
        let p = problem(&study, 0);
        let u = study.uncertainty.as_ref().unwrap();
        let names: Vec<_> = p.spec.variants.iter().map(|v| v.name.as_str()).collect();
        assert_eq!(names, ["w0", "w1", "w2"]);
        let scoring = u.sample(study.seed);
        for (v, w) in p.spec.variants.iter().zip(&scoring) {
            let keys: Vec<_> = v.set.iter().map(|(k, _)| k.as_str()).collect();
            let want: Vec<_> = u.params.iter().map(|q| q.name.as_str()).collect();
            assert_eq!(keys, want);
            let values: Vec<_> = v.set.iter().map(|(_, x)| x.clone()).collect();
            assert_ne!(values, w.values, "a tuning world is a scoring world");
        }
        // Common random numbers: another case meets the same tuning worlds.
        assert_eq!(problem(&study, 5).spec.variants, p.spec.variants);
        // The tuned case is scored in the nominal world: resolved at a point, it equals the
        // nominal-tuning study's case at that point (not tuning world w0).
        use crate::batch::tuning_hook::CaseTuner;
        let x: Vec<f64> = p.spec.space.params.iter().map(|q| q.start).collect();
        let at = |s: &crate::study::schema::Study| {
            let r = crate::study::cases::resolve_case(s, &cases[5]).unwrap();
            Tuner::new(s).unwrap().at(s, &cases[5], &r, &x).unwrap()
        };
        let (tuned, plain) = (at(&study), at(&nominal));
        assert_eq!(tuned.scenario, plain.scenario);
        assert_eq!(tuned.design, plain.design);
    }

    #[test]
    fn starts_normalised_at_different_points_compare_by_their_raw_objective() {
        let objective = Objective {
            terms: vec![Term {
                metric: "e".into(),
                weight: 2.0,
            }],
            combine: Combine::Mean,
            normalise: true,
        };
        let names = vec!["e".to_string()];
        // Two starts normalised by start points 10 and 100: scores 0.5 and 0.1 hide that the
        // first found 5 and the second 10.
        let a = Scorer::new(&objective, &[], &names, &[vec![10.0]]);
        let b = Scorer::new(&objective, &[], &names, &[vec![100.0]]);
        let rec = |m: f64| Record {
            index: 1,
            run: 1,
            iteration: 0,
            u: vec![],
            x: vec![],
            metrics: vec![vec![m]],
            failure: None,
            repeat: false,
            score: Score {
                objective: 0.0,
                violation: 0.0,
                feasible: true,
            },
        };
        assert_eq!(a.scenario_objective(&[5.0]), 1.0);
        assert_eq!(b.scenario_objective(&[10.0]), 0.2);
        assert_eq!(raw_objective(&a, &rec(5.0)), 10.0);
        assert_eq!(raw_objective(&b, &rec(10.0)), 20.0);
    }
}

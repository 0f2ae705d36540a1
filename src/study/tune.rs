//! Per-case tuning of a sweep (`[tune]`, `docs/study-format.md`): every case is first tuned —
//! its own design, its own axis values — by the optimiser ([`crate::optimise::minimise`] over
//! the case's resolved tables), then scored at the tuned values like any case; its row
//! carries the tuned values (`tuned.<param>`), the evaluations used (`tune_evaluations`) and
//! whether the tuned point met every `[[tune.constraint]]` (`tune_feasible`).
//!
//! `[tune]` holds the sections of a problem file (`[[tune.param]]`, `[tune.objective]`,
//! `[[tune.constraint]]`, `[tune.solver]`; `docs/optimise.md`), read by
//! [`crate::optimise::problem::parse_spec`] and validated before any case runs. A parameter
//! without `start` starts from the case's own value of its key (clamped to the bounds), so
//! an axis over `control.method` starts each method from its own Table III row.
//!
//! Determinism: the tuning of a case runs serially (one thread), every evaluation as the
//! case itself (its seed), so the tuned values and the row depend only on the study and the
//! case id — identical for any `--jobs` and any sharding. The case's wall-clock budget
//! (`--case-timeout`) covers tuning and scoring: a run past it fails `timeout`.

use std::time::Instant;

use super::cases::Resolved;
use super::doe::Case;
use super::error::InputError;
use super::records::{metric_count, CaseStatus, Row, TCM_COLUMNS};
use super::schema::{Study, Target};
use super::worker::Worker;
use crate::input::document::Document;
use crate::input::keypath::get;
use crate::optimise::evaluate::CaseEvaluator;
use crate::optimise::history::Record;
use crate::optimise::problem::parse_spec;
use crate::optimise::{minimise, Options, Problem, Spec};

/// A study's validated `[tune]` section.
#[derive(Clone, Debug)]
pub struct Tuner {
    spec: Spec,
    /// Per parameter: whether `start` is written (otherwise the case's own value).
    explicit_start: Vec<bool>,
    /// Whether the tuning objective or constraints read static TCM metrics.
    static_needed: bool,
}

impl Tuner {
    /// The tuner of `study`'s `[tune]` section (`None` without one). Every check of a
    /// problem file applies (`docs/optimise.md`), and: no `[[tune.variant]]` (a case is
    /// scored in its own scenario), no parameter that is also a sweep axis. Errors name the
    /// file, the line and the key (`tune.param[1].upper`).
    pub fn new(study: &Study) -> Result<Option<Tuner>, InputError> {
        let Some(t) = &study.tune else {
            return Ok(None);
        };
        let doc = Document::parse(&study.text, &study.path.display().to_string())?;
        if t.contains_key("variant") {
            return Err(doc.err(
                "tune.variant",
                "not allowed in [tune]: each case is tuned and scored in its own scenario",
            ));
        }
        let params = t.get("param").and_then(|p| p.as_array());
        for (i, p) in params.into_iter().flatten().enumerate() {
            let name = p.get("name").and_then(|n| n.as_str()).unwrap_or_default();
            if study.axes.iter().any(|a| a.name == name) {
                return Err(doc.err(
                    &format!("tune.param[{i}].name"),
                    format!("`{name}` is also a sweep axis: tune it or sweep it"),
                ));
            }
        }
        let spec = parse_spec(&doc, t, "tune", study)?;
        let explicit_start = params
            .map(|ps| ps.iter().map(|p| p.get("start").is_some()).collect())
            .unwrap_or_default();
        let static_needed = study.static_enabled
            && spec
                .metrics()
                .iter()
                .any(|m| TCM_COLUMNS.contains(&m.as_str()));
        Ok(Some(Tuner {
            spec,
            explicit_start,
            static_needed,
        }))
    }

    /// The problem tuning one case: the study with the case's resolved tables as its base
    /// and no axes; each parameter without `start` starts from the case's value.
    fn case_problem(&self, study: &Study, r: &Resolved) -> Problem {
        let mut cs = study.clone();
        cs.design = r.design.clone();
        cs.scenario_full = r.scenario.clone();
        cs.axes.clear();
        cs.tune = None;
        cs.static_enabled = self.static_needed;
        let mut spec = self.spec.clone();
        for (p, explicit) in spec.space.params.iter_mut().zip(&self.explicit_start) {
            if !explicit {
                if let Some(x) = case_value(&p.target, r) {
                    p.start = x.clamp(p.lower, p.upper);
                }
            }
        }
        Problem { study: cs, spec }
    }

    /// Tune case `case` (resolved as `r`) within `deadline`, then score it at the tuned
    /// values with `w`: its row, tuned columns filled in. A tuning that cannot run makes
    /// the case `failed` with a reason starting `tune:`.
    pub fn evaluate(
        &self,
        w: &mut Worker,
        study: &Study,
        case: &Case,
        r: &Resolved,
        deadline: Option<Instant>,
    ) -> Row {
        let problem = self.case_problem(study, r);
        let ev = CaseEvaluator::new(&problem).for_case(case.id, deadline);
        let quiet = |_: &Record| {};
        let opts = Options {
            jobs: 1,
            journal: None,
            resume: false,
            on_record: &quiet,
        };
        let failed = |reason: String| {
            let mut row = Row::new(study, case.id, r.hash.clone(), case.values.clone());
            row.end(CaseStatus::Failed, &reason);
            row
        };
        let out = match minimise(&problem.spec, &ev, &study.hash, &opts) {
            Ok(o) => o,
            Err(e) => return failed(format!("tune: {e}")),
        };
        let best = out.best();
        let mut scored = match ev.resolve(&best.x, 0) {
            Ok(s) => s,
            Err(m) => return failed(format!("tune: {m}")),
        };
        scored.hash = r.hash.clone();
        let (mut row, _) = w.evaluate_until(study, case, &scored, false, deadline);
        let dim = best.x.len();
        let at = metric_count(study) - dim - 2;
        row.metrics[at..at + dim].copy_from_slice(&best.x);
        row.metrics[at + dim] = out.fresh_evaluations() as f64;
        row.metrics[at + dim + 1] = f64::from(u8::from(best.score.feasible));
        row
    }

    /// Case `r` at tuned values `x` (in `[[tune.param]]` order, as a row records them): the
    /// report's reruns of the best and worst cases.
    pub fn at(
        &self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        x: &[f64],
    ) -> Result<Resolved, String> {
        let problem = self.case_problem(study, r);
        let mut s = CaseEvaluator::new(&problem)
            .for_case(case.id, None)
            .resolve(x, 0)?;
        s.hash = r.hash.clone();
        Ok(s)
    }
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

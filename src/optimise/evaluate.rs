//! Evaluating a problem's point: the parameters (and each scenario's settings) applied to the
//! study's tables exactly as a sweep applies axis values ([`resolve_case`]), then the design
//! columns, the static TCM analysis when the study enables it, and the closed-loop run of a
//! dynamic mode — the metrics a sweep row holds, by name. A panic or an invalid design is
//! the evaluation's failure (its metrics NaN), never the optimiser's.
//!
//! Every evaluation uses one case id (0; a sweep's own id for a case tuned in place,
//! [`CaseEvaluator::for_case`]) and so the same seed (`derive_seed(study.seed, id)`): the
//! static analysis samples the same joint configurations at every point, and the objective
//! is a deterministic function of the parameters.

use std::time::Instant;

use super::history::Evaluation;
use super::problem::Problem;
use super::search::Evaluator;
use crate::model::design::parse_design_table;
use crate::report::Table;
use crate::sampling::derive_seed;
use crate::statics::analyse;
use crate::study::axes::study_target;
use crate::study::cases::{resolve_case, Resolved};
use crate::study::doe::Case;
use crate::study::records::{DESIGN_COLUMNS, TCM_COLUMNS};
use crate::study::runner;
use crate::study::schema::{Axis, AxisSpec, Study};
use crate::study::static_table::{static_spec, STATIC_TABLE};
use crate::study::worker::{design_metrics, tcm_metrics};

/// The metrics of one case (one scenario at one point).
#[derive(Clone, Debug, Default)]
pub struct CaseMetrics {
    /// Named metrics: design columns, TCM columns (static), run metrics (dynamic).
    pub named: Vec<(String, f64)>,
    /// Why the case failed, if it did.
    pub failure: Option<String>,
    /// The trajectory (dynamic modes, when asked for).
    pub trajectory: Option<Table>,
}

/// The evaluator of a problem file's points.
pub struct CaseEvaluator<'a> {
    problem: &'a Problem,
    /// The study with one axis per parameter, then one per key a scenario sets.
    study: Study,
    /// Per scenario, the values of the scenario-key axes.
    variant_values: Vec<Vec<toml::Value>>,
    metrics: Vec<String>,
    /// The case id every evaluation runs as (its seed `derive_seed(study.seed, id)`).
    case_id: usize,
    /// Wall-clock deadline of every run (`None`: unlimited).
    deadline: Option<Instant>,
}

impl<'a> CaseEvaluator<'a> {
    /// The evaluator of `problem` (validated: every key resolves).
    pub fn new(problem: &'a Problem) -> Self {
        let spec = &problem.spec;
        let mut study = problem.study.clone();
        study.axes = spec
            .space
            .params
            .iter()
            .map(|p| Axis {
                name: p.name.clone(),
                target: p.target.clone(),
                spec: AxisSpec::Range {
                    start: p.lower,
                    stop: p.upper,
                    steps: None,
                    log: p.scale == super::space::Scale::Log,
                },
                numeric: true,
                integer: p.integer,
            })
            .collect();
        let mut keys: Vec<&str> = Vec::new();
        for v in &spec.variants {
            for (k, _) in &v.set {
                if !keys.contains(&k.as_str()) {
                    keys.push(k);
                }
            }
        }
        let mut variant_values = vec![Vec::new(); spec.variants.len()];
        for k in keys {
            // Every key resolved when the problem was parsed.
            let Some((target, base)) = study_target(&problem.study, k).ok().flatten() else {
                continue;
            };
            for (vals, v) in variant_values.iter_mut().zip(&spec.variants) {
                let own = v.set.iter().find(|(p, _)| p == k).map(|(_, x)| x.clone());
                vals.push(
                    own.or_else(|| base.clone())
                        .unwrap_or(toml::Value::Float(f64::NAN)),
                );
            }
            study.axes.push(Axis {
                name: k.to_string(),
                target,
                spec: AxisSpec::Values(Vec::new()),
                numeric: false,
                integer: false,
            });
        }
        CaseEvaluator {
            problem,
            study,
            variant_values,
            metrics: spec.metrics(),
            case_id: 0,
            deadline: None,
        }
    }

    /// The same evaluator running every point as case `id` of its study (a sweep's case
    /// tuned in place: the case's seed) within `deadline` (a run past it fails `timeout`).
    pub fn for_case(self, id: usize, deadline: Option<Instant>) -> Self {
        CaseEvaluator {
            case_id: id,
            deadline,
            ..self
        }
    }

    /// The tables of scenario `variant` at physical parameter values `x`.
    pub fn resolve(&self, x: &[f64], variant: usize) -> Result<Resolved, String> {
        let mut values: Vec<toml::Value> = x.iter().map(|v| toml::Value::Float(*v)).collect();
        values.extend(self.variant_values[variant].iter().cloned());
        resolve_case(
            &self.study,
            &Case {
                id: self.case_id,
                values,
            },
        )
    }

    /// Run one resolved case (with its trajectory when `log`).
    pub fn run_case(&self, r: &Resolved, log: bool) -> CaseMetrics {
        let study = &self.problem.study;
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            case_metrics(study, r, log, self.deadline)
        }));
        outcome.unwrap_or_else(|p| {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            CaseMetrics {
                failure: Some(format!("panic: {msg}")),
                ..CaseMetrics::default()
            }
        })
    }
}

impl Evaluator for CaseEvaluator<'_> {
    fn metrics(&self) -> &[String] {
        &self.metrics
    }

    fn evaluate(&self, x: &[f64]) -> Evaluation {
        let mut rows = Vec::new();
        let mut failures = Vec::new();
        for (v, variant) in self.problem.spec.variants.iter().enumerate() {
            let case = match self.resolve(x, v) {
                Ok(r) => self.run_case(&r, false),
                Err(m) => CaseMetrics {
                    failure: Some(m),
                    ..CaseMetrics::default()
                },
            };
            rows.push(pick(&case.named, &self.metrics));
            if let Some(f) = case.failure {
                failures.push(if variant.name.is_empty() {
                    f
                } else {
                    format!("{}: {f}", variant.name)
                });
            }
        }
        Evaluation {
            metrics: rows,
            failure: (!failures.is_empty()).then(|| failures.join("; ")),
        }
    }
}

/// The values of `names` among `named` (NaN when absent).
pub fn pick(named: &[(String, f64)], names: &[String]) -> Vec<f64> {
    names
        .iter()
        .map(|n| {
            named
                .iter()
                .find(|(k, _)| k == n)
                .map_or(f64::NAN, |(_, x)| *x)
        })
        .collect()
}

/// The named metrics of a resolved case (see the module docs).
fn case_metrics(study: &Study, r: &Resolved, log: bool, deadline: Option<Instant>) -> CaseMetrics {
    let mut out = CaseMetrics::default();
    let v = match parse_design_table(&r.design, "optimised design") {
        Ok(v) => v,
        Err(e) => {
            out.failure = Some(format!("invalid design: {e}"));
            return out;
        }
    };
    let named = |names: &[&str], values: &[f64]| -> Vec<(String, f64)> {
        names
            .iter()
            .map(|n| n.to_string())
            .zip(values.iter().copied())
            .collect()
    };
    out.named = named(&DESIGN_COLUMNS, &design_metrics(&v));
    if study.static_enabled {
        let s = static_spec(&r.scenario, derive_seed(r.seed, 1))
            .map_err(|m| m.to_string())
            .and_then(|spec| {
                analyse(&v, &spec, 1, &mut |_, _, _| Ok(()), &|_| {}).map_err(|e| e.to_string())
            });
        match s {
            Ok(s) => out.named.extend(named(&TCM_COLUMNS, &tcm_metrics(&s))),
            Err(m) => {
                out.failure = Some(m);
                return out;
            }
        }
    }
    if study.mode.is_dynamic() {
        let mut sc = r.scenario.clone();
        sc.remove(STATIC_TABLE);
        match runner::run_case_until(&v, &sc, r.seed, log, deadline) {
            Ok(run) => {
                out.named.extend(run.metrics);
                out.failure = run.failure;
                out.trajectory = run.trajectory;
            }
            Err(m) => out.failure = Some(m),
        }
    }
    out
}

//! Evaluating a problem's point: the parameters (and each scenario's settings) applied to the
//! study's tables exactly as a sweep applies axis values ([`resolve_case`]), then scored by the
//! one case evaluator ([`crate::evaluate`]) — design columns, the static TCM analysis when the
//! study enables it, the closed-loop run of a dynamic mode: the metrics a sweep row holds, by
//! name. A panic or an invalid design is the evaluation's failure, never the optimiser's.
//!
//! Every evaluation uses one case id (0; a sweep's own id for a case tuned in place,
//! [`CaseEvaluator::for_case`]) and so the same seed (`derive_seed(study.seed, id)`): the
//! static analysis samples the same joint configurations at every point, and the objective
//! is a deterministic function of the parameters.

use super::history::Evaluation;
use super::problem::Problem;
use super::search::Evaluator;
use crate::evaluate::{self as case_eval, CaseInput, CaseResult, Deadline, Metrics, Phases};
use crate::study::axes::study_target;
use crate::study::cases::{resolve_case, CaseError, Resolved};
use crate::study::doe::Case;
use crate::study::schema::{Axis, AxisSpec, Study};

/// A point's parameters could not be applied to the study's tables (an index beyond an
/// array, a design the generator cannot build).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ResolveError(#[source] pub CaseError);

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
    /// Wall-clock deadline of every run.
    deadline: Deadline,
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
                condition: false,
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
                condition: false,
            });
        }
        CaseEvaluator {
            problem,
            study,
            variant_values,
            metrics: spec.metrics(),
            case_id: 0,
            deadline: Deadline::NONE,
        }
    }

    /// The same evaluator running every point as case `id` of its study (a sweep's case
    /// tuned in place: the case's seed) within `deadline` (a run past it fails `timeout`).
    pub fn for_case(self, id: usize, deadline: Deadline) -> Self {
        CaseEvaluator {
            case_id: id,
            deadline,
            ..self
        }
    }

    /// The tables of scenario `variant` at physical parameter values `x`.
    pub fn resolve(&self, x: &[f64], variant: usize) -> Result<Resolved, ResolveError> {
        let mut values: Vec<toml::Value> = x.iter().map(|v| toml::Value::Float(*v)).collect();
        values.extend(self.variant_values[variant].iter().cloned());
        resolve_case(
            &self.study,
            &Case {
                id: self.case_id,
                values,
            },
        )
        .map_err(ResolveError)
    }

    /// Run one resolved case (with its trajectory when `log`) through the case evaluator, to
    /// its end whatever its verdict ([`whole_run`]).
    pub fn run_case(&self, r: &Resolved, log: bool) -> CaseResult {
        let study = &self.problem.study;
        let scenario = whole_run(&r.scenario);
        case_eval::Evaluator::new().evaluate(&CaseInput {
            design: &r.design,
            design_hash: &r.design_hash,
            scenario: &scenario,
            overrides: &[],
            seed: r.seed,
            deadline: self.deadline,
            phases: phases(study),
            trajectory: log,
            label: "optimised design",
        })
    }
}

/// The scenario-side table `scenario` with `[success] stop_on_failure = false`: an optimiser's
/// point (a tuning candidate) runs to its end. The solvers rank infeasible points by their
/// total constraint violation, computed from the run's metrics; a run stopped at a certain
/// miss has other metric values than the whole run, so stopping it would change which
/// infeasible point ranks first and with it the search path and the tuned values (measured:
/// docs/study-format.md "Stopping a failed run").
fn whole_run(scenario: &toml::Table) -> toml::Table {
    let mut t = scenario.clone();
    let success = t
        .entry("success")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    if let toml::Value::Table(s) = success {
        s.insert("stop_on_failure".into(), toml::Value::Boolean(false));
    }
    t
}

/// The phases a point of `study` runs.
fn phases(study: &Study) -> Phases {
    Phases {
        static_analysis: study.static_enabled,
        closed_loop: study.mode.is_dynamic(),
    }
}

impl Evaluator for CaseEvaluator<'_> {
    fn metrics(&self) -> &[String] {
        &self.metrics
    }

    fn evaluate(&self, x: &[f64]) -> Evaluation {
        self.evaluate_until(x, &|_: &[Vec<f64>]| false)
    }

    /// The scenarios run in order (a tuning's worlds: `w0`, `w1`, …); after each, `stop` sees
    /// the rows so far. A failed run is a row like any other (its metrics, NaN where the run
    /// gave none): racing stops on it when its metrics break a constraint. A raced evaluation
    /// says so in its failure (`raced: stopped after k of n scenarios`).
    fn evaluate_until(&self, x: &[f64], stop: &(dyn Fn(&[Vec<f64>]) -> bool + Sync)) -> Evaluation {
        let mut rows = Vec::new();
        let mut failures = Vec::new();
        let n = self.problem.spec.variants.len();
        for (v, variant) in self.problem.spec.variants.iter().enumerate() {
            let (metrics, failure) = match self.resolve(x, v) {
                Ok(r) => {
                    let res = self.run_case(&r, false);
                    let failure = res.failure().map(str::to_string);
                    (res.metrics, failure)
                }
                Err(e) => (Metrics::new(), Some(e.to_string())),
            };
            rows.push(metrics.pick(&self.metrics));
            if let Some(f) = failure {
                failures.push(if variant.name.is_empty() {
                    f
                } else {
                    format!("{}: {f}", variant.name)
                });
            }
            if v + 1 < n && stop(&rows) {
                failures.push(format!("raced: stopped after {} of {n} scenarios", v + 1));
                break;
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
    named.iter().cloned().collect::<Metrics>().pick(names)
}

#[cfg(test)]
mod tests {
    use super::whole_run;

    #[test]
    fn an_optimisers_point_runs_to_its_end_whatever_the_study_says() {
        let stop = |t: &toml::Table| t["success"]["stop_on_failure"].as_bool();
        let none = toml::Table::new();
        assert_eq!(stop(&whole_run(&none)), Some(false));
        let study: toml::Table =
            toml::from_str("[success]\nstop_on_failure = true\nmax_roll_deg = 20.0\n").unwrap();
        assert_eq!(stop(&whole_run(&study)), Some(false));
        // The other bounds are kept; the table given is not touched.
        assert_eq!(
            whole_run(&study)["success"]["max_roll_deg"].as_float(),
            Some(20.0)
        );
        assert_eq!(stop(&study), Some(true));
    }
}

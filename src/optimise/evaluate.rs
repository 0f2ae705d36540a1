//! Evaluating a problem's point: the parameters (and each scenario's settings) are typed
//! overrides on the study's tables ([`crate::evaluate::overrides`], the one road a sweep's axis
//! values, worlds and validation variants take too), applied by the one case evaluator
//! ([`crate::evaluate`]) — design columns, the static TCM analysis when the study enables it,
//! the closed-loop run of a dynamic mode: the metrics a sweep row holds, by name. A panic or an
//! invalid design is the evaluation's failure, never the optimiser's.
//!
//! Every evaluation uses one case id (0; a sweep's own id for a case tuned in place,
//! [`CaseEvaluator::for_case`]) and so the same seed (`derive_seed(study.seed, id)`): the
//! static analysis samples the same joint configurations at every point, and the objective
//! is a deterministic function of the parameters.

use super::history::Evaluation;
use super::problem::Problem;
use super::search::Evaluator;
use crate::evaluate::{
    self as case_eval, apply_overrides, CaseInput, CaseResult, Deadline, Metrics, Override, Phases,
};
use crate::input::keypath::Seg;
use crate::study::axes::study_target;
use crate::study::cases::{base_case, method_control_of, override_of, CaseError, Resolved};
use crate::study::hash::case_hashes;
use crate::study::schema::{Study, Target};

/// A point's parameters could not be applied to the study's tables (an index beyond an
/// array, a design the generator cannot build).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ResolveError(#[source] pub CaseError);

/// The evaluator of a problem file's points.
pub struct CaseEvaluator<'a> {
    problem: &'a Problem,
    /// The study's own case (no axes) as the case id every evaluation runs as (its seed
    /// `derive_seed(study.seed, id)`, [`CaseEvaluator::for_case`]): the tables every
    /// point's overrides go on top of.
    base: Resolved,
    /// What the parameters, then each scenario's keys, set: `(name, target)`.
    keys: Vec<(String, Target)>,
    /// Per scenario, the values of the scenario keys (every key a scenario sets, in order of
    /// first use; a scenario that does not set one keeps the study's value).
    variant_values: Vec<Vec<toml::Value>>,
    metrics: Vec<String>,
    /// Wall-clock deadline of every run.
    deadline: Deadline,
}

impl<'a> CaseEvaluator<'a> {
    /// The evaluator of `problem` (validated: every key resolves).
    pub fn new(problem: &'a Problem) -> Self {
        let spec = &problem.spec;
        let mut keys: Vec<(String, Target)> = spec
            .space
            .params
            .iter()
            .map(|p| (p.name.clone(), p.target.clone()))
            .collect();
        let mut set_keys: Vec<&str> = Vec::new();
        for v in &spec.variants {
            for (k, _) in &v.set {
                if !set_keys.contains(&k.as_str()) {
                    set_keys.push(k);
                }
            }
        }
        let mut variant_values = vec![Vec::new(); spec.variants.len()];
        for k in set_keys {
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
            keys.push((k.to_string(), target));
        }
        CaseEvaluator {
            problem,
            base: base_case(&problem.study, 0),
            keys,
            variant_values,
            metrics: spec.metrics(),
            deadline: Deadline::NONE,
        }
    }

    /// The same evaluator running every point as case `id` of its study (a sweep's case
    /// tuned in place: the case's seed) within `deadline` (a run past it fails `timeout`).
    pub fn for_case(self, id: usize, deadline: Deadline) -> Self {
        CaseEvaluator {
            base: base_case(&self.problem.study, id),
            deadline,
            ..self
        }
    }

    /// The overrides of scenario `variant` at physical parameter values `x`: the parameters,
    /// the scenario's keys, and, when one of them is `control.method`, that method's
    /// `[control]` written out ([`method_control_of`], as a sweep's method axis does).
    fn overrides(&self, x: &[f64], variant: usize) -> Result<Vec<Override>, ResolveError> {
        let values: Vec<toml::Value> = x
            .iter()
            .map(|v| toml::Value::Float(*v))
            .chain(self.variant_values[variant].iter().cloned())
            .collect();
        let items = || {
            self.keys
                .iter()
                .zip(&values)
                .map(|((n, t), v)| (n.as_str(), t, v))
        };
        let mut out: Vec<Override> = items().map(|(n, t, v)| override_of(n, t, v)).collect();
        if let Some(c) = method_control_of(&self.problem.study, items()).map_err(ResolveError)? {
            out.push(Override::scenario(
                vec![Seg::Key("control".into())],
                toml::Value::Table(c),
                "control",
            ));
        }
        Ok(out)
    }

    /// The tables of scenario `variant` at physical parameter values `x` (the files of the
    /// best point, the tuned case a sweep scores).
    pub fn resolve(&self, x: &[f64], variant: usize) -> Result<Resolved, ResolveError> {
        let overrides = self.overrides(x, variant)?;
        let mut r = self.base.clone();
        let design_changed = apply_overrides(&mut r.design, &mut r.scenario, &overrides)
            .map_err(|e| ResolveError(e.into()))?;
        if design_changed {
            r.design_hash = case_hashes(&r.design, &r.scenario, r.seed).1;
        }
        Ok(r)
    }

    /// Run one resolved case (with its trajectory when `log`) through the case evaluator, to
    /// its end whatever its verdict ([`whole_run`]).
    pub fn run_case(&self, r: &Resolved, log: bool) -> CaseResult {
        self.run_with(r, &[], log)
    }

    /// Run the base case with `overrides` on top (a point of scenario `variant`), to its end.
    fn run_with(&self, r: &Resolved, overrides: &[Override], log: bool) -> CaseResult {
        let study = &self.problem.study;
        let mut all = overrides.to_vec();
        all.push(whole_run());
        case_eval::Evaluator::new().evaluate(&CaseInput {
            design: &r.design,
            design_hash: &r.design_hash,
            scenario: &r.scenario,
            overrides: &all,
            seed: r.seed,
            deadline: self.deadline,
            phases: phases(study),
            trajectory: log,
            label: "optimised design",
        })
    }

    /// Scenario `variant` at physical parameter values `x`, run to its end: the point's
    /// overrides applied by the case evaluator on the base case.
    fn run_point(&self, x: &[f64], variant: usize) -> Result<CaseResult, ResolveError> {
        let overrides = self.overrides(x, variant)?;
        Ok(self.run_with(&self.base, &overrides, false))
    }
}

/// `[success] stop_on_failure = false` as an override: an optimiser's point (a tuning
/// candidate) runs to its end. The solvers rank infeasible points by their total constraint
/// violation, computed from the run's metrics; a run stopped at a certain miss has other
/// metric values than the whole run, so stopping it would change which infeasible point ranks
/// first and with it the search path and the tuned values (measured: docs/study-format.md
/// "Stopping a failed run").
fn whole_run() -> Override {
    Override::scenario(
        vec![
            Seg::Key("success".into()),
            Seg::Key("stop_on_failure".into()),
        ],
        toml::Value::Boolean(false),
        "success.stop_on_failure",
    )
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
            let (metrics, failure) = match self.run_point(x, v) {
                Ok(res) => {
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
    use crate::evaluate::apply_overrides;

    #[test]
    fn an_optimisers_point_runs_to_its_end_whatever_the_study_says() {
        let stopped = |t: &toml::Table| {
            let mut s = t.clone();
            apply_overrides(&mut toml::Table::new(), &mut s, &[whole_run()]).unwrap();
            s
        };
        let stop = |t: &toml::Table| t["success"]["stop_on_failure"].as_bool();
        let none = toml::Table::new();
        assert_eq!(stop(&stopped(&none)), Some(false));
        let study: toml::Table =
            toml::from_str("[success]\nstop_on_failure = true\nmax_roll_deg = 20.0\n").unwrap();
        assert_eq!(stop(&stopped(&study)), Some(false));
        // The other bounds are kept.
        assert_eq!(
            stopped(&study)["success"]["max_roll_deg"].as_float(),
            Some(20.0)
        );
    }
}

//! The ask/tell `Problem`: a problem file's parameter space, and the evaluation of any point
//! an outside optimiser proposes through the same evaluator and scoring as `usm-study
//! optimise` (objective scales fixed at the file's start point).

use std::path::PathBuf;
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use usm_study::input::keypath::did_you_mean;
use usm_study::optimise::evaluate::CaseEvaluator;
use usm_study::optimise::history::Evaluation;
use usm_study::optimise::score::Scorer;
use usm_study::optimise::search::Evaluator;
use usm_study::optimise::{load_problem, Problem as Loaded};
use usm_study::study::tune_space::Scale;

use crate::convert::{err, msg, Failure};

/// A problem file for an outside optimiser (see the Python wrapper's docstring).
#[pyclass(frozen, module = "usm_study._native")]
pub struct Problem {
    problem: Loaded,
    /// The scorer, fixed by the start point's evaluation (made on first use).
    scorer: Mutex<Option<Scorer>>,
}

impl Problem {
    fn evaluation(&self, x: &[f64]) -> Evaluation {
        CaseEvaluator::new(&self.problem).evaluate(x)
    }

    /// The scorer, evaluating the start point first if it is not fixed yet.
    fn scorer(&self) -> Scorer {
        let mut guard = self.scorer.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(s) = guard.as_ref() {
            return s.clone();
        }
        let spec = &self.problem.spec;
        let start = spec.space.values(&spec.space.start());
        let e = self.evaluation(&start);
        let ev = CaseEvaluator::new(&self.problem);
        let s = Scorer::new(&spec.objective, &spec.constraints, ev.metrics(), &e.metrics);
        *guard = Some(s.clone());
        s
    }

    /// The point of `params` in parameter order, checked against the space.
    fn point(&self, params: &Bound<'_, PyDict>) -> PyResult<Vec<f64>> {
        let space = &self.problem.spec.space;
        let names: Vec<&str> = space.params.iter().map(|p| p.name.as_str()).collect();
        for k in params.keys() {
            let k: String = k.extract()?;
            if !names.contains(&k.as_str()) {
                let hint = did_you_mean(&k, names.iter().copied());
                return Err(msg(format!("params: unknown parameter '{k}'{hint}")).into());
            }
        }
        let mut x = Vec::with_capacity(names.len());
        for p in &space.params {
            let v: f64 = match params.get_item(&p.name)? {
                Some(v) => v.extract().map_err(|_| {
                    PyErr::from(msg(format!("params: {}: must be a number", p.name)))
                })?,
                None => return Err(msg(format!("params: missing parameter '{}'", p.name)).into()),
            };
            if !(p.lower..=p.upper).contains(&v) {
                return Err(msg(format!(
                    "params: {} = {v} is outside its bounds [{}, {}]",
                    p.name, p.lower, p.upper
                ))
                .into());
            }
            x.push(if p.integer { v.round() } else { v });
        }
        Ok(x)
    }
}

#[pymethods]
impl Problem {
    #[new]
    fn new(path: PathBuf) -> PyResult<Self> {
        let problem = load_problem(&path).map_err(|e| PyErr::from(err(&e)))?;
        Ok(Problem {
            problem,
            scorer: Mutex::new(None),
        })
    }

    /// The problem's name (`study.name`).
    #[getter]
    fn name(&self) -> &str {
        &self.problem.study.name
    }

    /// The parameters, in file order: `[{name, lower, upper, scale, start, integer}]`.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for p in &self.problem.spec.space.params {
            let d = PyDict::new(py);
            d.set_item("name", &p.name)?;
            d.set_item("lower", p.lower)?;
            d.set_item("upper", p.upper)?;
            d.set_item(
                "scale",
                match p.scale {
                    Scale::Lin => "lin",
                    Scale::Log => "log",
                },
            )?;
            d.set_item("start", p.start)?;
            d.set_item("integer", p.integer)?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The scenario names of the problem (`[""]` for a problem of one scenario).
    #[getter]
    fn scenarios(&self) -> Vec<String> {
        self.problem
            .spec
            .variants
            .iter()
            .map(|v| v.name.clone())
            .collect()
    }

    /// The metric names an evaluation returns.
    #[getter]
    fn metric_names(&self) -> Vec<String> {
        self.problem.spec.metrics()
    }

    /// The evaluation budget of the file's own solver (`[solver] max_evals`).
    #[getter]
    fn max_evals(&self) -> usize {
        self.problem.spec.solver.max_evals
    }

    /// Evaluate `params` (`{name: physical value}`): `(metrics, objective, violation,
    /// failure)`, metrics one dict per scenario.
    #[allow(clippy::type_complexity)]
    fn _evaluate<'py>(
        &self,
        py: Python<'py>,
        params: &Bound<'py, PyDict>,
    ) -> PyResult<(Vec<Vec<(String, f64)>>, f64, f64, Option<String>)> {
        let x = self.point(params)?;
        let (e, score) = py.detach(|| -> Result<_, Failure> {
            let scorer = self.scorer();
            let e = self.evaluation(&x);
            let score = scorer.score(&e.metrics);
            Ok((e, score))
        })?;
        let names = self.problem.spec.metrics();
        let metrics = e
            .metrics
            .iter()
            .map(|row| names.iter().cloned().zip(row.iter().copied()).collect())
            .collect();
        Ok((metrics, score.objective, score.violation, e.failure))
    }
}

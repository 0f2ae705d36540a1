//! `simulate`, `simulate_many` and the `Run` class: one closed-loop run exactly as
//! `usm-study simulate` runs it (scenario file or preset, `--set` overrides, the scenario's
//! design), so a run's metrics are bit for bit those of the command's `summary.json`.

use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use rayon::prelude::*;
use usm_study::model::Vehicle;
use usm_study::outcome::{run_scenario, RunResult};
use usm_study::scenario::config::ScenarioFile;
use usm_study::scenario::{load_table, parse_table, resolve_design, Source};

use crate::convert::{apply, err, msg, Failure, Set};

/// A scenario's table as `simulate` reads it: file or preset, `[uncertainty]` dropped (the
/// nominal run), the design replaced when one is given.
pub fn base_table(scenario: &str, design: Option<&str>) -> Result<(toml::Table, Source), Failure> {
    let (mut table, src) = load_table(scenario).map_err(|e| err(&e))?;
    table.remove("uncertainty");
    if let Some(d) = design {
        // A design file given from Python is found from the caller's directory, not the
        // scenario's: make it absolute.
        let d = match std::fs::canonicalize(d) {
            Ok(p) if p.is_file() => p.display().to_string(),
            _ => d.to_string(),
        };
        table.remove("design");
        let sc = table
            .entry("scenario")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        match sc.as_table_mut() {
            Some(t) => {
                t.insert("design".into(), toml::Value::String(d));
            }
            None => return Err(msg(format!("{}: scenario: must be a table", src.origin))),
        }
    }
    Ok((table, src))
}

/// The validated scenario and its vehicle, after `sets`.
pub fn prepare(
    table: &toml::Table,
    src: &Source,
    sets: &[Set],
) -> Result<(ScenarioFile, Vehicle), Failure> {
    let mut table = table.clone();
    apply(&mut table, sets)?;
    let file = parse_table(&table, src).map_err(|e| err(&e))?;
    let vehicle = resolve_design(&file, src).map_err(|e| err(&e))?;
    Ok((file, vehicle))
}

/// The result of one closed-loop run.
#[pyclass(frozen, module = "usm_study._native")]
pub struct Run {
    name: String,
    mode: String,
    design: String,
    metrics: Vec<(String, f64)>,
    failure: Option<(f64, String)>,
    missed: Option<String>,
    columns: Vec<(String, Vec<f64>)>,
}

impl Run {
    fn new(r: RunResult, design: String) -> Self {
        Run {
            columns: r
                .trajectory
                .iter()
                .map(|(c, x)| (c.name(), x.to_vec()))
                .collect(),
            name: r.name,
            mode: r.mode.to_string(),
            design,
            metrics: r.metrics,
            failure: r.failure,
            missed: r.missed.map(|m| m.to_string()),
        }
    }
}

/// `xs` as the bytes of native-endian f64 values (numpy's `frombuffer(b, float64)`).
fn f64_bytes<'py>(py: Python<'py>, xs: &[f64]) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = xs.iter().flat_map(|x| x.to_ne_bytes()).collect();
    PyBytes::new(py, &bytes)
}

#[pymethods]
impl Run {
    /// Scenario name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }
    /// Mode: `transport` or `work`.
    #[getter]
    fn mode(&self) -> &str {
        &self.mode
    }
    /// Name of the design that ran.
    #[getter]
    fn design(&self) -> &str {
        &self.design
    }
    /// The summary metrics in the mode's order (SI units), as `summary.json` holds them.
    #[getter]
    fn metrics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.metrics {
            d.set_item(k, v)?;
        }
        Ok(d)
    }
    /// Whether every `[success]` criterion was met.
    #[getter]
    fn success(&self) -> bool {
        self.missed.is_none()
    }
    /// The first `[success]` criterion missed, `criterion: detail`, or None.
    #[getter]
    fn missed(&self) -> Option<&str> {
        self.missed.as_deref()
    }
    /// Why the run stopped early, `(time [s], cause)`, or None.
    #[getter]
    fn failure(&self) -> Option<(f64, String)> {
        self.failure.clone()
    }
    /// The time series as `[(column, f64 bytes)]` (the wrapper builds the DataFrame).
    fn _columns<'py>(&self, py: Python<'py>) -> Vec<(String, Bound<'py, PyBytes>)> {
        self.columns
            .iter()
            .map(|(n, x)| (n.clone(), f64_bytes(py, x)))
            .collect()
    }
    fn __repr__(&self) -> String {
        format!(
            "Run({:?}, mode={}, design={:?}, success={}{})",
            self.name,
            self.mode,
            self.design,
            self.missed.is_none(),
            self.failure
                .as_ref()
                .map_or(String::new(), |(t, c)| format!(
                    ", failed at t = {t} s: {c}"
                ))
        )
    }
}

/// One closed-loop run (see the Python wrapper's docstring).
#[pyfunction]
#[pyo3(signature = (scenario, design=None, overrides=None))]
pub fn simulate(
    py: Python<'_>,
    scenario: &str,
    design: Option<&str>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<Run> {
    let sets = crate::convert::overrides(overrides)?;
    let scenario = scenario.to_string();
    let design = design.map(str::to_string);
    let run = py.detach(move || -> Result<Run, Failure> {
        let (table, src) = base_table(&scenario, design.as_deref())?;
        let (file, vehicle) = prepare(&table, &src, &sets)?;
        let r = run_scenario(&vehicle, &file).map_err(|e| err(&e))?;
        Ok(Run::new(r, vehicle.name.clone()))
    })?;
    Ok(run)
}

/// Threads per core `jobs` may ask for, as on the command line: more only adds thread
/// start-up and memory (the rows do not depend on the thread count).
const JOBS_PER_CORE: usize = 4;

/// `jobs` capped at [`JOBS_PER_CORE`] × the cores (at least 8); 0 (all cores) is kept.
fn capped(jobs: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    jobs.min((JOBS_PER_CORE * cores).max(8))
}

/// One row of `simulate_many`: named metrics, whether it met `[success]`, why it failed.
type Row = (Vec<(String, f64)>, bool, Option<String>);

/// Runs of one scenario, one per override dict, on a pool of `jobs` threads (0: all cores),
/// in input order: `(metric names, one f64 bytes column per metric, success, failure)`.
#[pyfunction]
#[pyo3(signature = (scenario, params, design=None, overrides=None, jobs=0))]
#[allow(clippy::type_complexity)]
pub fn simulate_many<'py>(
    py: Python<'py>,
    scenario: &str,
    params: &Bound<'py, PyList>,
    design: Option<&str>,
    overrides: Option<&Bound<'py, PyDict>>,
    jobs: usize,
) -> PyResult<(
    Vec<String>,
    Vec<Bound<'py, PyBytes>>,
    Vec<bool>,
    Vec<Option<String>>,
)> {
    let common = crate::convert::overrides(overrides)?;
    let mut per_row: Vec<Vec<Set>> = Vec::with_capacity(params.len());
    for (i, p) in params.iter().enumerate() {
        let d = p
            .cast::<PyDict>()
            .map_err(|_| PyErr::from(msg(format!("params[{i}]: must be a dict of key: value"))))?;
        let mut sets = common.clone();
        sets.extend(crate::convert::overrides(Some(d))?);
        per_row.push(sets);
    }
    let scenario = scenario.to_string();
    let design = design.map(str::to_string);
    let rows: Vec<Row> = py.detach(move || -> Result<Vec<Row>, Failure> {
        let (table, src) = base_table(&scenario, design.as_deref())?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(capped(jobs))
            .build()
            .map_err(|e| err(&e))?;
        let results: Vec<Result<Row, Failure>> = pool.install(|| {
            per_row
                .par_iter()
                .map(|sets| {
                    let (file, vehicle) = prepare(&table, &src, sets)?;
                    let r = run_scenario(&vehicle, &file).map_err(|e| err(&e))?;
                    let failure = r
                        .failure
                        .map(|(t, c)| format!("run stopped at t = {t:.3} s: {c}"));
                    Ok((r.metrics, r.missed.is_none(), failure))
                })
                .collect()
        });
        results
            .into_iter()
            .enumerate()
            .map(|(i, r)| r.map_err(|e| msg(format!("params[{i}]: {}", e.0))))
            .collect()
    })?;
    let mut names: Vec<String> = Vec::new();
    for (m, _, _) in &rows {
        for (k, _) in m {
            if !names.contains(k) {
                names.push(k.clone());
            }
        }
    }
    let columns = names
        .iter()
        .map(|n| {
            let col: Vec<f64> = rows
                .iter()
                .map(|(m, _, _)| m.iter().find(|(k, _)| k == n).map_or(f64::NAN, |x| x.1))
                .collect();
            f64_bytes(py, &col)
        })
        .collect();
    let success = rows.iter().map(|r| r.1).collect();
    let failure = rows.into_iter().map(|r| r.2).collect();
    Ok((names, columns, success, failure))
}

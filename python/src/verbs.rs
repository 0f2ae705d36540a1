//! The other verbs: `design`, `scenario_info`, `sweep`, `optimise`, `tcm` and `ocp`, each calling the
//! library as the command of the same name does and writing the same files.

use std::path::{Path, PathBuf};
use std::time::Duration;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use usm_study::batch::{outdir, run_sweep, SweepOptions};
use usm_study::metrics::singularity::DEFAULT_RANK_REL_TOL;
use usm_study::model::design::{design_to_toml, load_design};
use usm_study::optimise::case_tuner::HOOK as TUNING;
use usm_study::optimise::{load_problem, run as run_problem, Options};
use usm_study::pipeline::create_dir;
use usm_study::pipeline::optimise::{write_outputs, OptimiseFiles};
use usm_study::pipeline::review::write_review;
use usm_study::pipeline::tcm::{run_tcm, TcmConfig};
use usm_study::sampling::Sampling;
use usm_study::scenario::Mode;
use usm_study::statics::StaticSpec;
use usm_study::study::load_study;

use crate::convert::{err, msg, Failure};
use crate::run::{base_table, prepare};

/// A design (preset or file) as `{name, joints, thrusters, toml}` (`toml`: the explicit form).
#[pyfunction]
pub fn design<'py>(py: Python<'py>, name_or_path: &str) -> PyResult<Bound<'py, PyDict>> {
    let v = load_design(name_or_path).map_err(|e| PyErr::from(err(&e)))?;
    let d = PyDict::new(py);
    d.set_item("name", &v.name)?;
    d.set_item("joints", v.n_joints())?;
    d.set_item("thrusters", v.n_thrusters())?;
    d.set_item("toml", design_to_toml(&v))?;
    Ok(d)
}

/// A scenario (preset or file) with a design and overrides, validated as `simulate` would:
/// `{name, mode, duration, dt, control_dt, design, allocation}`.
#[pyfunction]
#[pyo3(signature = (name_or_path, design=None, overrides=None))]
pub fn scenario_info<'py>(
    py: Python<'py>,
    name_or_path: &str,
    design: Option<&str>,
    overrides: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let sets = crate::convert::overrides(overrides)?;
    let (table, src) = base_table(name_or_path, design)?;
    let (file, vehicle) = prepare(&table, &src, &sets)?;
    let d = PyDict::new(py);
    let s = &file.scenario;
    d.set_item("name", &s.name)?;
    d.set_item("mode", s.mode.to_string())?;
    d.set_item("duration", s.duration)?;
    d.set_item("dt", s.dt)?;
    d.set_item("control_dt", s.control_dt)?;
    d.set_item("design", &vehicle.name)?;
    d.set_item("allocation", file.allocation.method.name())?;
    Ok(d)
}

/// `usm-study sweep STUDY [--out DIR] [--jobs N] [--resume] [--force] [--case-timeout S]`:
/// the study's files and `report.html`; returns the output directory and the case counts.
#[pyfunction]
#[pyo3(signature = (study, out=None, jobs=0, resume=false, force=false, case_timeout=600.0))]
pub fn sweep<'py>(
    py: Python<'py>,
    study: PathBuf,
    out: Option<PathBuf>,
    jobs: usize,
    resume: bool,
    force: bool,
    case_timeout: f64,
) -> PyResult<Bound<'py, PyDict>> {
    if !(0.0..=1e9).contains(&case_timeout) {
        return Err(msg(format!(
            "case_timeout: must be a number of seconds in 0..=1e9 (0: none), got {case_timeout}"
        ))
        .into());
    }
    let o = py.detach(move || -> Result<_, Failure> {
        let study = load_study(&study).map_err(|e| err(&e))?;
        let opts = SweepOptions {
            jobs,
            resume,
            shard: None,
            out,
            max_cases: None,
            case_timeout: (case_timeout > 0.0).then(|| Duration::from_secs_f64(case_timeout)),
            force,
            tuning: Some(TUNING),
            bound: Some(usm_study::ocp::study_bound::HOOK),
            report: Some(usm_study::review::HOOK),
        };
        let o = run_sweep(&study, &opts, &mut |_| {}).map_err(|e| err(&e))?;
        let review = write_review(&o.out).map_err(|e| err(&e))?;
        Ok((o, review.warnings))
    })?;
    let (o, review_warnings) = o;
    let d = PyDict::new(py);
    d.set_item("out", o.out.display().to_string())?;
    d.set_item("cases", o.in_shard)?;
    d.set_item("ok", o.ok)?;
    d.set_item("unsuccessful", o.unsuccessful)?;
    d.set_item("failed", o.failed)?;
    d.set_item("skipped", o.skipped)?;
    d.set_item("resumed", o.resumed)?;
    d.set_item("ran", o.ran)?;
    d.set_item("timeouts", o.timeouts)?;
    d.set_item("elapsed_s", o.elapsed_s)?;
    let mut warnings = o.warnings;
    warnings.extend(review_warnings);
    d.set_item("warnings", warnings)?;
    Ok(d)
}

/// Refuse an output directory that holds a sweep's output or another problem's optimisation
/// (the checks of `usm-study optimise`).
fn check_output(out: &Path, problem: &str) -> Result<(), Failure> {
    outdir::check_contained(out).map_err(|e| err(&e))?;
    for f in [
        "cases.csv",
        "cases.parquet",
        "cases.partial.csv",
        "study.toml",
    ] {
        if out.join(f).exists() {
            return Err(msg(format!(
                "{} holds a sweep's output ({f}): an optimisation needs its own directory",
                out.display()
            )));
        }
    }
    if let Ok(text) = std::fs::read_to_string(out.join("manifest.json")) {
        let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
        if v["problem"].as_str() != Some(problem) {
            return Err(msg(format!(
                "{} holds the output of another run (manifest.json); use another out",
                out.display()
            )));
        }
    }
    Ok(())
}

/// `usm-study optimise PROBLEM [--out DIR] [--jobs N] [--resume] [--no-plots]`: the history,
/// `best.toml`, summary, plots and `report.html`; returns the start and best points.
#[pyfunction]
#[pyo3(signature = (problem, out=None, jobs=0, resume=false, plots=true))]
pub fn optimise<'py>(
    py: Python<'py>,
    problem: PathBuf,
    out: Option<PathBuf>,
    jobs: usize,
    resume: bool,
    plots: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (problem, outcome, out) = py.detach(move || -> Result<_, Failure> {
        let problem = load_problem(&problem).map_err(|e| err(&e))?;
        let s = &problem.study;
        let out = out.unwrap_or_else(|| {
            if s.output == Path::new("results/sweeps").join(&s.name) {
                Path::new("results/optimise").join(&s.name)
            } else {
                s.output.clone()
            }
        });
        create_dir(&out).map_err(|e| err(&e))?;
        let out = outdir::resolve(&out).map_err(|e| err(&e))?;
        let owner = outdir::LockOwner {
            study: &s.hash,
            resume,
        };
        let lock = outdir::lock(&out, &owner).map_err(|e| err(&e))?;
        check_output(&out, &s.name)?;
        let jobs = match jobs {
            0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
            n => n,
        };
        let journal = out.join(usm_study::optimise::history::JOURNAL_FILE);
        let opts = Options {
            jobs,
            journal: Some(&journal),
            resume,
            on_record: &|_| {},
            race: false,
        };
        let outcome = run_problem(&problem, &opts).map_err(|e| err(&e))?;
        write_outputs(&problem, &outcome, &out, OptimiseFiles { plots }).map_err(|e| err(&e))?;
        write_review(&out).map_err(|e| err(&e))?;
        outdir::record_owned(&out, lock.created, &["report.html"]).map_err(|e| err(&e))?;
        drop(lock);
        Ok((problem, outcome, out))
    })?;
    let d = PyDict::new(py);
    let point = |x: &[f64]| -> PyResult<Bound<'py, PyDict>> {
        let p = PyDict::new(py);
        for (param, v) in problem.spec.space.params.iter().zip(x) {
            p.set_item(&param.name, v)?;
        }
        Ok(p)
    };
    let (start, best) = (outcome.start(), outcome.best());
    d.set_item("out", out.display().to_string())?;
    d.set_item("evaluations", outcome.records.len())?;
    d.set_item("fresh_evaluations", outcome.fresh_evaluations())?;
    d.set_item("start", point(&start.x)?)?;
    d.set_item("start_objective", start.score.objective)?;
    d.set_item("best", point(&best.x)?)?;
    d.set_item("best_index", best.index)?;
    d.set_item("objective", best.score.objective)?;
    d.set_item("violation", best.score.violation)?;
    d.set_item("feasible", best.score.feasible)?;
    Ok(d)
}

/// `usm-study tcm DESIGN …`: the static T(q) analysis and its files; returns `summary.json`'s
/// text and the output directory.
#[pyfunction]
#[pyo3(signature = (design, samples=None, seed=0, threshold=None, sampling="sobol", out=None, char_length=None, jobs=0, mode="transport", worst=None))]
#[allow(clippy::too_many_arguments)]
pub fn tcm(
    py: Python<'_>,
    design: &str,
    samples: Option<usize>,
    seed: u64,
    threshold: Option<f64>,
    sampling: &str,
    out: Option<PathBuf>,
    char_length: Option<f64>,
    jobs: usize,
    mode: &str,
    worst: Option<usize>,
) -> PyResult<(String, String)> {
    let sampling: Sampling = sampling
        .parse()
        .map_err(|e| PyErr::from(msg(format!("sampling: {e}"))))?;
    let mode: Mode = toml::Value::String(mode.into()).try_into().map_err(|_| {
        PyErr::from(msg(format!(
            "mode: unknown mode '{mode}'; valid: transport, work"
        )))
    })?;
    let design = design.to_string();
    let r = py.detach(move || -> Result<_, Failure> {
        let vehicle = load_design(&design).map_err(|e| err(&e))?;
        let defaults = StaticSpec::default();
        let samples = samples.unwrap_or(usm_study::statics::DEFAULT_SAMPLES);
        if samples > 50_000_000 {
            return Err(msg(format!("samples: at most 50000000, got {samples}")));
        }
        let config = TcmConfig {
            spec: StaticSpec {
                samples,
                seed,
                threshold: threshold.unwrap_or(usm_study::statics::DEFAULT_THRESHOLD),
                sampling,
                char_length,
                rank_rel_tol: DEFAULT_RANK_REL_TOL,
                worst: worst.unwrap_or(usm_study::statics::DEFAULT_WORST),
                ..defaults
            }
            .for_mode(mode),
            out: out.unwrap_or_else(|| {
                Path::new("results/tcm").join(usm_study::report::file_stem_safe(&vehicle.name))
            }),
            jobs,
            slice: None,
            resolution: 41,
        };
        run_tcm(&vehicle, &config, &|_| {}).map_err(|e| err(&e))?;
        let text = std::fs::read_to_string(config.out.join("summary.json")).map_err(|e| {
            msg(format!(
                "{}: {e}",
                config.out.join("summary.json").display()
            ))
        })?;
        Ok((text, config.out.display().to_string()))
    })?;
    Ok(r)
}

/// `usm-study ocp PROBLEM --out DIR`: solve an optimal-control problem file and write
/// `trajectory.csv`, `iterations.csv` and `summary.json` into `out`; returns
/// `(out, summary.json's text)` (the solve's status is data: a solve that did not converge
/// is not an error).
#[pyfunction]
pub fn ocp(py: Python<'_>, problem: PathBuf, out: PathBuf) -> PyResult<(String, String)> {
    let r = py.detach(move || -> Result<(String, String), Failure> {
        let spec = usm_study::ocp::load_problem(&problem).map_err(|e| err(&e))?;
        let mut run = usm_study::ocp::solve_spec(&spec).map_err(|e| err(&e))?;
        usm_study::ocp::write_outputs(&out, &spec, &mut run).map_err(|e| err(&e))?;
        let summary = std::fs::read_to_string(out.join("summary.json"))
            .map_err(|e| msg(format!("{}: {e}", out.display())))?;
        Ok((out.display().to_string(), summary))
    })?;
    Ok(r)
}

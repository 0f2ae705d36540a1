//! Helpers shared by the integration tests (ripgrep's `tests/util.rs` idea): running the
//! binary, writing input files, reading outputs. Each test file takes what it needs, so some
//! helpers are unused in some files.
#![allow(dead_code)]

pub mod leader;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Four quick static cases (a 5-link generator body, 32 static samples, 4 to 7 links): the
/// study the reliability tests run and corrupt.
pub const QUICK: &str = r#"
[study]
name = "quick"

[design.generator]
links = 5

[static]
samples = 32

[[axis]]
name = "design.links"
values = [4, 5, 6, 7]
"#;

/// The `usm-study` binary built for these tests.
pub fn usm_study() -> Command {
    Command::new(env!("CARGO_BIN_EXE_usm-study"))
}

/// Run `usm-study ARGS…` to completion.
pub fn run(args: &[&str]) -> Output {
    usm_study().args(args).output().expect("run usm-study")
}

/// Run `usm-study ARGS…`, require success and parse its standard output as JSON.
pub fn json(args: &[&str]) -> serde_json::Value {
    let out = run(args);
    assert!(out.status.success(), "{args:?} failed: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// Write `text` to `dir/name` and return the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    p
}

/// A path as the `&str` argument the command line takes.
pub fn arg(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// Standard error of a finished run, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The bytes of a file that must exist.
pub fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The `summary.json` of a `simulate` output directory.
pub fn summary(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("valid JSON")
}

/// A metric of a `summary.json`.
pub fn metric(s: &serde_json::Value, k: &str) -> f64 {
    s["metrics"][k]
        .as_f64()
        .unwrap_or_else(|| panic!("metric {k} in {s}"))
}

/// `usm-study sweep STUDY --out OUT EXTRA…`.
pub fn sweep(study: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut a = vec![
        "sweep",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    run(&a)
}

fn quiet_record(_: &usm_study::optimise::history::Record) {}

/// Load the shipped optimisation study `file` (relative to the repository root), cut its budget
/// to `max_evals` evaluations (a polish keeps its share of the budget) and run it on two
/// threads, quietly; returns the problem and the outcome.
pub fn optimise_study(
    file: &str,
    max_evals: usize,
) -> (usm_study::optimise::Problem, usm_study::optimise::Outcome) {
    optimise_study_with(file, max_evals, |_| {})
}

/// [`optimise_study`] with the solver settings edited by `edit` after the cut.
pub fn optimise_study_with(
    file: &str,
    max_evals: usize,
    edit: impl FnOnce(&mut usm_study::optimise::problem::SolverSettings),
) -> (usm_study::optimise::Problem, usm_study::optimise::Outcome) {
    let mut p = usm_study::optimise::load_problem(Path::new(file)).unwrap();
    let full = p.spec.solver.max_evals;
    p.spec.solver.max_evals = max_evals;
    if let Some(polish) = p.spec.solver.polish.as_mut() {
        polish.evals = polish.evals * max_evals / full;
    }
    edit(&mut p.spec.solver);
    let opts = usm_study::optimise::Options {
        jobs: 2,
        journal: None,
        resume: false,
        on_record: &quiet_record,
        race: false,
    };
    let o = usm_study::optimise::run(&p, &opts).unwrap();
    (p, o)
}

/// The headless-browser binary of the browser tests (`chromium` or `chromium-browser`);
/// panics when neither runs (the tests call it only with `USM_BROWSER_TEST` set).
pub fn chromium_bin() -> &'static str {
    ["chromium", "chromium-browser"]
        .into_iter()
        .find(|b| Command::new(b).arg("--version").output().is_ok())
        .expect("USM_BROWSER_TEST is set but neither chromium nor chromium-browser runs")
}

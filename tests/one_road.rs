//! One road for variation (issue 37 item 2): a world, a validation variant, a fault rerun and a
//! tuning point are typed overrides the case evaluator applies on top of the case's tables, so
//! each of those runs is exactly the run of a study that writes the same values into its file.
//!
//! One tuned case of a small transport study meets one world (a `choice` of a single current,
//! so its value is known), one `[[validate]]` variant and a fault of each thruster; then four
//! one-case studies without any of it write the tuned gain and, in turn, the world's current,
//! the variant's key and thruster 1's fault into their files. Each nominal objective must equal
//! the corresponding column of the first study bit for bit.

mod common;

use std::path::Path;

use common::{stderr, sweep, write};

const HEAD: &str = r#"[study]
name = "one_road"
seed = 5
objective = "energy_per_metre"

[design.generator]
links = 3
link_length = 0.6
thrust_limit = 40.0

[scenario]
mode = "transport"
duration = 30.0

[allocation]
method = "pinv"
lambda = 0.1

[success]
cross_track_bound = 3.0
"#;

const VARIED: &str = r#"
[tune]
[[tune.param]]
name = "control.k_psi"
lower = 0.3
upper = 0.9
[tune.solver]
method = "nelder-mead"
max_evals = 3
[tune.objective]
[[tune.objective.term]]
metric = "energy_per_metre"
weight = 1.0

[uncertainty]
worlds = 2
[[uncertainty.param]]
name = "physics.current_speed"
distribution = { kind = "choice", values = [0.01] }

[[validate]]
name = "damped"
set = { "hydro.linear_damping_scale" = 1.25 }

[faults]
single = true
at = 10.0
kind = "dead"
informed = true
"#;

/// The header and the first row of `file` in `out`, by column name.
fn row(out: &Path, file: &str) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(out.join(file)).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let first: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    head.into_iter().zip(first).collect()
}

/// The value of column `name` of `row`.
fn cell(row: &[(String, String)], name: &str) -> String {
    row.iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.clone())
        .unwrap_or_else(|| {
            panic!(
                "no column {name} in {:?}",
                row.iter().map(|c| &c.0).collect::<Vec<_>>()
            )
        })
}

/// Sweep the study `text` (written to `dir/name.toml`) into `dir/name`; its output folder.
fn run(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let study = write(dir, &format!("{name}.toml"), text);
    let out = dir.join(name);
    let o = sweep(&study, &out, &["--jobs", "2"]);
    assert!(
        o.status.code().is_some_and(|c| c <= 1),
        "{name}: {}",
        stderr(&o)
    );
    out
}

#[test]
fn every_variation_of_a_case_equals_the_study_that_writes_it_out() {
    let dir = tempfile::tempdir().unwrap();
    let varied = run(dir.path(), "varied", &format!("{HEAD}{VARIED}"));
    let cases = row(&varied, "cases.csv");
    let k_psi = cell(&cases, "tuned.control.k_psi");
    let tuned: f64 = k_psi.parse().unwrap();
    assert!((0.3..=0.9).contains(&tuned), "{k_psi}");
    let written = |extra: &str| format!("{HEAD}\n[control]\nk_psi = {tuned:?}\n{extra}");

    // The tuned point: the case's own row is the run at the tuned gain.
    let nominal = run(dir.path(), "nominal", &written(""));
    assert_eq!(
        cell(&row(&nominal, "cases.csv"), "energy_per_metre"),
        cell(&cases, "energy_per_metre"),
        "the tuned row"
    );

    // The world: its one value of the current written into [physics].
    let world = run(
        dir.path(),
        "world",
        &written("[physics]\ncurrent_speed = 0.01\n"),
    );
    let worlds = std::fs::read_to_string(varied.join("worlds.csv")).unwrap();
    let head: Vec<&str> = worlds.lines().next().unwrap().split(',').collect();
    let first: Vec<&str> = worlds.lines().nth(1).unwrap().split(',').collect();
    let at = head
        .iter()
        .position(|h| *h == "energy_per_metre")
        .unwrap_or_else(|| panic!("worlds.csv: {head:?}"));
    assert_eq!(
        first[at],
        cell(&row(&world, "cases.csv"), "energy_per_metre"),
        "the world"
    );

    // The validation variant: its key written into [hydro].
    let variant = run(
        dir.path(),
        "variant",
        &written("[hydro]\nlinear_damping_scale = 1.25\n"),
    );
    assert_eq!(
        cell(&cases, "validate.damped.energy_per_metre"),
        cell(&row(&variant, "cases.csv"), "energy_per_metre"),
        "the validation variant"
    );

    // The first thruster's fault: written as the scenario's [fault].
    let fault = run(
        dir.path(),
        "fault",
        &written("[fault]\nthruster = 0\nat = 10.0\nkind = \"dead\"\ninformed = true\n"),
    );
    assert_eq!(
        cell(&cases, "fault.t1.objective"),
        cell(&row(&fault, "cases.csv"), "energy_per_metre"),
        "the fault of thruster 1"
    );
}

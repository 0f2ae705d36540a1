//! Reliability of the input layer (issues 20 and 21): bounds checked before anything runs
//! (optimiser budgets, `--jobs`, input file sizes), conflicting or ignored input refused with
//! exit 2 and `file:line:col: key:`, and the low items (scenario names, durations, drawings out
//! of range, long numbers, control characters in axis values, unknown report metrics).

mod common;

use std::sync::atomic::{AtomicUsize, Ordering};

use common::{arg, run, stderr, sweep, write};
use usm_study::input::keypath::KeyPath;
use usm_study::optimise::history::{Evaluation, Record};
use usm_study::optimise::problem::{
    Combine, Method, Objective, SolverSettings, Spec, Term, Variant,
};
use usm_study::optimise::search::Evaluator;
use usm_study::optimise::{minimise, Options};
use usm_study::study::schema::Target;
use usm_study::study::tune_space::{Param, Scale, Space};

/// Four quick static cases.
const QUICK: &str = r#"[study]
name = "quick"

[design.generator]
links = 5

[static]
samples = 16

[[axis]]
name = "design.links"
values = [4, 5]
"#;

/// A tiny transport problem (parsed only: every test refuses it before any run).
const PROBLEM: &str = r#"[study]
name = "tiny"
seed = 1

[design]
preset = "usm-paper"

[scenario]
mode = "transport"
duration = 8.0

[[param]]
name = "control.k_psi"
lower = 0.1
upper = 1.0

[objective]
[[objective.term]]
metric = "thruster_energy"
weight = 1.0

[solver]
method = "nelder-mead"
max_evals = 5
"#;

/// The 1-based line of the first line of `text` that starts with `start`.
fn line_of(text: &str, start: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.starts_with(start))
        .unwrap_or_else(|| panic!("no line starts with {start}"))
}

/// `usm-study ARGS` exits 2 and its message holds every piece of `parts`.
fn refused(args: &[&str], parts: &[&str]) {
    let o = run(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    for p in parts {
        assert!(e.contains(p), "{args:?}: `{p}` not in: {e}");
    }
}

/// A study file `text` refused by `sweep` (with and without `--dry-run`) at `line` and `key`.
fn sweep_refuses(dir: &std::path::Path, name: &str, text: &str, line: usize, parts: &[&str]) {
    let p = write(dir, name, text);
    let at = format!("{}:{line}:", p.display());
    let mut all = vec![at.as_str()];
    all.extend_from_slice(parts);
    refused(&["sweep", arg(&p), "--dry-run"], &all);
    let out = dir.join(format!("{name}.out"));
    refused(&["sweep", arg(&p), "--out", arg(&out)], &all);
    assert!(!out.exists(), "a refused study writes nothing");
}

#[test]
fn unknown_or_empty_report_metrics_are_refused_with_a_hint() {
    let d = tempfile::tempdir().unwrap();
    let with = |line: &str| QUICK.replace("name = \"quick\"", &format!("name = \"quick\"\n{line}"));
    let t = with("objective = \"tcm_singular_fracton\"");
    sweep_refuses(
        d.path(),
        "obj.toml",
        &t,
        3,
        &[
            "study.objective: unknown metric `tcm_singular_fracton`",
            "did you mean `tcm_singular_fraction`?",
        ],
    );
    let t = with("objective = \"no_such_metric\"");
    let p = write(d.path(), "far.toml", &t);
    let o = run(&["sweep", arg(&p), "--dry-run"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!stderr(&o).contains("did you mean"), "{}", stderr(&o));
    let t = with("pareto = [\"design_thrusters\", \"energy_per_meter\"]");
    sweep_refuses(
        d.path(),
        "pareto.toml",
        &t,
        3,
        &["study.pareto[1]: unknown metric `energy_per_meter`"],
    );
    let t = with("maximise = [\"bogus\"]");
    sweep_refuses(d.path(), "max.toml", &t, 3, &["study.maximise[0]"]);
    let t = with("objective = \"\"");
    sweep_refuses(
        d.path(),
        "empty.toml",
        &t,
        3,
        &["study.objective: is empty"],
    );
    // A closed-loop metric is not one of a static study's.
    let t = with("objective = \"thruster_energy\"");
    sweep_refuses(d.path(), "mode.toml", &t, 3, &["for mode \"static\""]);
    // The known names pass.
    let t = with("objective = \"tcm_singular_fraction\"\nmaximise = [\"design_thrusters\"]");
    let p = write(d.path(), "good.toml", &t);
    let o = run(&["sweep", arg(&p), "--dry-run"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn sections_a_problem_file_would_ignore_or_override_are_refused() {
    let d = tempfile::tempdir().unwrap();
    let cases = [
        (
            format!("{PROBLEM}\n[[axis]]\nname = \"control.look_ahead\"\nvalues = [1.0, 2.0]\n"),
            "[[axis]]",
            "axis: [[axis]] belongs to a sweep's study file",
        ),
        (
            format!("{PROBLEM}\n[[variant]]\nname = \"a\"\nset = {{\"control.k_psi\" = 0.3}}\n"),
            "set = ",
            "variant[0].set: `control.k_psi` is the parameter `control.k_psi`",
        ),
        (
            PROBLEM.replace("seed = 1", "seed = 1\nmaximise = [\"bogus\"]"),
            "maximise",
            "study.maximise[0]: unknown metric `bogus`",
        ),
        (
            PROBLEM.replace("seed = 1", "seed = 1\nobjective = \"\""),
            "objective = \"\"",
            "study.objective: is empty",
        ),
    ];
    for (i, (text, start, message)) in cases.iter().enumerate() {
        let p = write(d.path(), &format!("p{i}.toml"), text);
        let out = d.path().join(format!("o{i}"));
        let at = format!("{}:{}:", p.display(), line_of(text, start));
        refused(&["optimise", arg(&p), "--out", arg(&out)], &[&at, message]);
        assert!(!out.exists(), "nothing written for case {i}");
    }
}

#[test]
fn a_tuned_key_aliasing_an_axis_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let text = r#"[study]
name = "alias"

[design.generator]
links = 5

[scenario]
mode = "transport"
duration = 8.0

[[axis]]
name = "design.generator.longitudinal_offset"
values = [0.06, 0.14]

[[tune.param]]
name = "design.longitudinal_offset"
lower = 0.0
upper = 0.2
start = 0.1

[tune.objective]
[[tune.objective.term]]
metric = "thruster_energy"
weight = 1.0

[tune.solver]
method = "nelder-mead"
max_evals = 3
"#;
    let p = write(d.path(), "alias.toml", text);
    let out = d.path().join("o");
    let at = format!(
        "{}:{}:",
        p.display(),
        line_of(text, "name = \"design.longitudinal")
    );
    refused(
        &["sweep", arg(&p), "--out", arg(&out)],
        &[
            &at,
            "tune.param[0].name: `design.longitudinal_offset` sets the same key as the sweep \
             axis `design.generator.longitudinal_offset`",
        ],
    );
}

#[test]
fn optimiser_budgets_are_bounded_before_running() {
    let d = tempfile::tempdir().unwrap();
    let cases = [
        (
            "method = \"particle-swarm\"\nparticles = 1000000000",
            "solver.particles: must be in 2..=10000",
        ),
        (
            "method = \"particle-swarm\"\nparticles = 50",
            "solver.particles: a swarm of 50 particles cannot be evaluated once within max_evals = 5",
        ),
        (
            "method = \"nelder-mead\"\nmax_iters = 1\nrestarts = 1000000000",
            "solver.restarts: 1000000000 restarts cannot run within max_evals = 5",
        ),
        (
            "method = \"bayes\"\nrestarts = 1\npolish = 4",
            "solver.polish: a polish of 4 evaluations leaves the method's 2 run(s) nothing of \
             max_evals = 5",
        ),
        (
            "method = \"bayes\"\npolish = 2\npolish_step = 0.9",
            "solver.polish_step: must be in (0, 0.5]",
        ),
    ];
    for (i, (solver, message)) in cases.iter().enumerate() {
        let text = PROBLEM.replace("method = \"nelder-mead\"", solver);
        let p = write(d.path(), &format!("b{i}.toml"), &text);
        let out = d.path().join(format!("o{i}"));
        refused(&["optimise", arg(&p), "--out", arg(&out)], &[message]);
        assert!(!out.exists());
    }
    let text = PROBLEM.replace("max_evals = 5", "max_evals = 1000000000");
    let p = write(d.path(), "evals.toml", &text);
    refused(
        &["optimise", arg(&p), "--out", arg(&d.path().join("oe"))],
        &["solver.max_evals: must be in 2..=1000000"],
    );
}

/// `f(x) = Σ x²`, counting its evaluations.
struct Bowl(AtomicUsize, Vec<String>);

impl Evaluator for Bowl {
    fn metrics(&self) -> &[String] {
        &self.1
    }
    fn evaluate(&self, x: &[f64]) -> Evaluation {
        self.0.fetch_add(1, Ordering::Relaxed);
        Evaluation {
            metrics: vec![vec![x.iter().map(|v| v * v).sum()]],
            failure: None,
        }
    }
}

fn bowl_spec(dims: usize, solver: SolverSettings) -> Spec {
    let params = (0..dims)
        .map(|i| Param {
            name: format!("a.x{i}"),
            target: Target::Scenario(KeyPath::parse(&format!("a.x{i}")).unwrap()),
            lower: -1.0,
            upper: 1.0,
            scale: Scale::Lin,
            start: 0.5,
            integer: false,
        })
        .collect();
    Spec {
        space: Space::new(params),
        variants: vec![Variant {
            name: String::new(),
            set: Vec::new(),
        }],
        objective: Objective {
            terms: vec![Term {
                metric: "f".into(),
                weight: 1.0,
            }],
            combine: Combine::Mean,
            normalise: false,
        },
        constraints: Vec::new(),
        solver,
    }
}

fn settings(method: Method, max_iters: u64, max_evals: usize, restarts: usize) -> SolverSettings {
    SolverSettings {
        method,
        max_iters,
        max_evals,
        tolerance: 1e-12,
        restarts,
        seed: 3,
        particles: 4,
        step: 0.1,
        polish: None,
    }
}

fn quiet(_: &Record) {}

fn bowl(spec: &Spec) -> (usm_study::optimise::Outcome, usize) {
    let ev = Bowl(AtomicUsize::new(0), vec!["f".into()]);
    let opts = Options {
        jobs: 1,
        journal: None,
        resume: false,
        on_record: &quiet,
        race: false,
    };
    let o = minimise(spec, &ev, "bowl", &opts).unwrap();
    (o, ev.0.load(Ordering::Relaxed))
}

#[test]
fn nelder_mead_spends_a_small_budget_honestly() {
    // Three parameters: the simplex needs three new vertices beside the start; max_evals = 4
    // covers exactly them (before: one evaluation, then "budget reached").
    let (o, calls) = bowl(&bowl_spec(3, settings(Method::NelderMead, 100, 4, 0)));
    assert_eq!(o.records.len(), 4);
    assert_eq!(calls, 4, "start and three vertices simulated");
    assert!(o.records.iter().all(|r| !r.repeat));
    assert!(o.stops[0].contains("budget"), "{:?}", o.stops);
    // max_evals = 3: the start and two of the three vertices, then the budget.
    let (o, calls) = bowl(&bowl_spec(3, settings(Method::NelderMead, 100, 3, 0)));
    assert_eq!((o.records.len(), calls), (3, 3));
}

#[test]
fn repeated_points_count_against_the_budget() {
    // One iteration per run and many restarts from the best point: each run proposes mostly
    // points seen before. Repeats count, so the search ends at max_evals records.
    for method in [Method::NelderMead, Method::Lbfgs, Method::ParticleSwarm] {
        let (o, calls) = bowl(&bowl_spec(2, settings(method, 1, 40, 39)));
        assert!(o.records.len() <= 40, "{method:?}: {}", o.records.len());
        assert!(calls <= o.records.len(), "{method:?}");
        assert!(o.stops.len() <= 40, "{method:?}: {:?}", o.stops);
    }
}

#[test]
fn an_endless_input_file_fails_fast_with_a_clear_message() {
    if !std::path::Path::new("/dev/zero").exists() {
        return;
    }
    for verb in [["sweep", "--dry-run"], ["optimise", "--no-plots"]] {
        refused(
            &[verb[0], "/dev/zero", verb[1]],
            &["/dev/zero", "larger than 16 MiB"],
        );
    }
    // A design argument must be a regular file or a preset: refused before reading.
    refused(&["inspect", "/dev/zero"], &["/dev/zero"]);
    let d = tempfile::tempdir().unwrap();
    let big = d.path().join("big.toml");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(17 << 20).unwrap();
    refused(&["sweep", arg(&big), "--dry-run"], &["larger than 16 MiB"]);
}

#[test]
fn too_many_jobs_are_capped_with_a_note() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "q.toml", QUICK);
    let o = run(&["sweep", arg(&p), "--dry-run", "--jobs", "100000"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("note: --jobs 100000 capped to"),
        "{}",
        stderr(&o)
    );
    let o = run(&["sweep", arg(&p), "--dry-run", "--jobs", "2"]);
    assert!(!stderr(&o).contains("capped"), "{}", stderr(&o));
}

#[test]
fn scenario_names_that_are_not_directory_names_are_refused() {
    let d = tempfile::tempdir().unwrap();
    for name in ["", ".", "..", "~", "a/b", ".hidden"] {
        let out = d.path().join("o");
        let set = format!("scenario.name={name:?}");
        refused(
            &[
                "simulate",
                "transport-method2",
                "--set",
                &set,
                "--out",
                arg(&out),
            ],
            &["scenario.name", "it names the output directory"],
        );
        assert!(!out.exists(), "{name:?}");
    }
}

#[test]
fn a_run_shorter_than_one_control_period_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o");
    refused(
        &[
            "simulate",
            "transport-method2",
            "--set",
            "scenario.duration=0.02",
            "--out",
            arg(&out),
        ],
        &[
            "scenario.duration",
            "0.02 s is shorter than one control period (scenario.control_dt = 0.05 s)",
        ],
    );
    // Long numbers stay short in messages.
    refused(
        &[
            "simulate",
            "transport-method2",
            "--set",
            "scenario.duration=1e200",
            "--out",
            arg(&out),
        ],
        &["scenario.duration", "gives 1e202 steps"],
    );
}

#[test]
fn a_drawing_out_of_range_is_an_error_not_a_nan_svg() {
    let d = tempfile::tempdir().unwrap();
    let state = write(
        d.path(),
        "far.json",
        r#"{"base_position": [1e308, 0.0, 0.0]}"#,
    );
    let out = d.path().join("far.svg");
    refused(
        &[
            "design",
            "draw",
            "usm-paper",
            "--state",
            arg(&state),
            "--out",
            arg(&out),
        ],
        &["1e308", "beyond the ±1e9 m a drawing can show"],
    );
    assert!(!out.exists());
}

#[test]
fn axis_strings_with_control_characters_are_refused_and_long_numbers_print_short() {
    let d = tempfile::tempdir().unwrap();
    let text = QUICK.replace(
        "name = \"design.links\"\nvalues = [4, 5]",
        "name = \"design.thruster_rule\"\nvalues = [\"paper\", \"a\\nb\"]",
    );
    sweep_refuses(
        d.path(),
        "nl.toml",
        &text,
        line_of(&text, "values"),
        &["axis[0].values[1]: a string value may not hold a newline"],
    );
    let text = QUICK.replace(
        "name = \"design.links\"\nvalues = [4, 5]",
        "name = \"static.threshold\"\nvalues = [1e200, 0.05]",
    );
    let p = write(d.path(), "big.toml", &text);
    let o = run(&["sweep", arg(&p), "--dry-run"]);
    let listing = String::from_utf8_lossy(&o.stdout);
    assert!(listing.contains("static.threshold=1e+200"), "{listing}");
    assert!(!listing.contains("0000000000"), "{listing}");
}

#[test]
fn design_show_points_at_real_commands() {
    let o = run(&["design", "show", "usm-paper"]);
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(!text.contains("--design"), "{text}");
    assert!(text.contains("usm-study inspect my_design.toml"), "{text}");
}

#[test]
fn authority_keys_of_static_are_accepted_and_bad_ones_refused_at_their_line() {
    let d = tempfile::tempdir().unwrap();
    let with = |line: &str| QUICK.replace("samples = 16", &format!("samples = 16\n{line}"));
    let t = with("authority_reference = \"tail\"");
    sweep_refuses(
        d.path(),
        "ref.toml",
        &t,
        9,
        &["static.authority_reference", "tail"],
    );
    let t = with("joint_range = -0.5");
    sweep_refuses(d.path(), "range.toml", &t, 9, &["joint_range", ">= 0"]);
    let t = with("authority_reference = [0.1, 0.0, 0.0]\njoint_range = 0.3\nn1_samples = 4")
        .replace(
            "name = \"quick\"",
            "name = \"quick\"\nobjective = \"authority_min_force\"",
        );
    let p = write(d.path(), "good.toml", &t);
    let o = run(&["sweep", arg(&p), "--dry-run"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// A quick static sweep still runs (the new checks refuse nothing valid).
#[test]
fn a_valid_study_still_runs() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "q.toml", QUICK);
    let o = sweep(&p, &d.path().join("o"), &["--jobs", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// A misspelt axis name or scenario key gets the closest valid name, not the whole catalogue.
#[test]
fn misspelt_axis_names_and_keys_get_a_did_you_mean() {
    let d = tempfile::tempdir().unwrap();
    let t = QUICK.replace("name = \"design.links\"", "name = \"design.linsk\"");
    sweep_refuses(
        d.path(),
        "axis.toml",
        &t,
        11,
        &["axis[0].name: unknown parameter `design.linsk`; did you mean `design.links`?"],
    );
    let o = run(&["sweep", arg(&write(d.path(), "a2.toml", &t)), "--dry-run"]);
    assert!(stderr(&o).len() < 300, "no catalogue dump: {}", stderr(&o));
    let o = run(&[
        "simulate",
        "transport-method1",
        "--set",
        "control.k_pis=0.3",
        "--out",
        arg(&d.path().join("s")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("control.k_pis: unknown field `k_pis`")
            && stderr(&o).contains("did you mean `k_psi`?"),
        "{}",
        stderr(&o)
    );
}

/// A transport study whose worlds, variants or axes hand a key a value it refuses (issue 39):
/// the head of every case below.
const VALUES_HEAD: &str = r#"[study]
name = "values"
seed = 1

[design]
preset = "usm-paper"

[scenario]
mode = "transport"
duration = 8.0

"#;

#[test]
fn values_a_key_refuses_are_refused_at_load_with_file_line_and_key() {
    let d = tempfile::tempdir().unwrap();
    let world = |name: &str, dist: &str| {
        format!(
            "[uncertainty]\nworlds = 4\n\n[[uncertainty.param]]\nname = \"{name}\"\n\
             distribution = {dist}\n"
        )
    };
    let cases: Vec<(&str, String, &str, &str)> = vec![
        (
            "string_choice",
            world(
                "physics.current_speed",
                r#"{ kind = "choice", values = [0.1, "fast"] }"#,
            ),
            "distribution = ",
            "uncertainty.param[0].distribution: the value \"fast\" of `physics.current_speed` is refused",
        ),
        (
            "huge_uniform",
            world(
                "physics.current_speed",
                r#"{ kind = "uniform", low = -1e308, high = 1e308 }"#,
            ),
            "distribution = ",
            "must be a finite number",
        ),
        (
            "duration_world",
            world(
                "scenario.duration",
                r#"{ kind = "uniform", low = -1.0, high = 8.0 }"#,
            ),
            "distribution = ",
            "of `scenario.duration` is refused: must be a finite number > 0",
        ),
        (
            "duration_axis",
            "[[axis]]\nname = \"scenario.duration\"\nvalues = [8.0, 0.0]\n".to_string(),
            "values = ",
            "axis[0].values: the value 0.0 of `scenario.duration` is refused",
        ),
        // Issue 42 item 6: a payload axis with a value of the wrong type or range.
        (
            "payload_axis_2kg",
            "[[axis]]\nname = \"mission.payload_mass\"\nvalues = [2.0, \"2kg\"]\n".to_string(),
            "values = ",
            "axis[0].values: the value \"2kg\" of `mission.payload_mass` is refused: invalid type",
        ),
        (
            "payload_axis_negative",
            "[[axis]]\nname = \"mission.payload_mass\"\nvalues = [2.0, -1.0]\n".to_string(),
            "values = ",
            "axis[0].values: the value -1.0 of `mission.payload_mass` is refused: must be a finite number >= 0",
        ),
        (
            "negative_payload",
            world(
                "mission.payload_mass",
                r#"{ kind = "uniform", low = -1.0, high = 1.0 }"#,
            ),
            "distribution = ",
            "of `mission.payload_mass` is refused: must be a finite number >= 0",
        ),
        (
            "validate_fast",
            "[[validate]]\nname = \"fast\"\nset = { \"physics.current_speed\" = \"fast\" }\n"
                .to_string(),
            "set = ",
            "validate[0].set.physics.current_speed: the value \"fast\" of `physics.current_speed` is refused",
        ),
        (
            "nan_choice",
            world(
                "physics.current_speed",
                r#"{ kind = "choice", values = [0.1, nan] }"#,
            ),
            "distribution = ",
            "the value nan of `physics.current_speed` is refused: must be a finite number",
        ),
        (
            "scale_tail",
            world(
                "hydro.linear_damping_scale",
                r#"{ kind = "normal", mean = 1.0, std = 0.5 }"#,
            ),
            "distribution = ",
            "of `hydro.linear_damping_scale` is refused: must be finite and >= 0",
        ),
    ];
    for (name, tail, line_start, message) in cases {
        let text = format!("{VALUES_HEAD}{tail}");
        let line = line_of(&text, line_start);
        sweep_refuses(d.path(), &format!("{name}.toml"), &text, line, &[message]);
    }
    // A valid world and variant still load.
    let text = format!(
        "{VALUES_HEAD}{}[[validate]]\nname = \"calm\"\nset = {{ \"physics.current_speed\" = 0.0 }}\n",
        world(
            "physics.current_speed",
            r#"{ kind = "uniform", low = 0.0, high = 0.2 }"#
        )
    );
    let p = write(d.path(), "valid.toml", &text);
    let o = run(&["sweep", arg(&p), "--dry-run"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

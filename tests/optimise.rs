//! The optimiser's library API (`usm_study::optimise`): each solver as configured finds the
//! known optimum of analytic functions through the same wiring the verb uses (`minimise`);
//! results do not depend on the number of threads; a resumed run equals an uninterrupted one;
//! the metric catalogue names every metric a run reports; `best.toml` reproduces the best
//! objective.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use usm_study::input::keypath::KeyPath;
use usm_study::optimise::evaluate::pick;
use usm_study::optimise::history::{history_table, Evaluation, Record, JOURNAL_FILE};
use usm_study::optimise::problem::{
    Combine, Method, Objective, Polish, SolverSettings, Spec, Term, Variant,
};
use usm_study::optimise::search::Evaluator;
use usm_study::optimise::{minimise, parse_problem, run, Options, Outcome};
use usm_study::study::schema::Target;
use usm_study::study::tune_space::{Param, Scale, Space};

/// An analytic objective `f` of the physical parameters, counting its evaluations.
struct Analytic {
    f: fn(&[f64]) -> f64,
    names: Vec<String>,
    calls: AtomicUsize,
}

impl Analytic {
    fn new(f: fn(&[f64]) -> f64) -> Self {
        Analytic {
            f,
            names: vec!["f".into()],
            calls: AtomicUsize::new(0),
        }
    }
}

impl Evaluator for Analytic {
    fn metrics(&self) -> &[String] {
        &self.names
    }
    fn evaluate(&self, x: &[f64]) -> Evaluation {
        self.calls.fetch_add(1, Ordering::Relaxed);
        Evaluation {
            metrics: vec![vec![(self.f)(x)]],
            failure: None,
        }
    }
}

fn rosenbrock(x: &[f64]) -> f64 {
    (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
}

/// Minimum at (0.3, 1.0): the second coordinate's unconstrained optimum 1.5 is outside the box.
fn bounded_quadratic(x: &[f64]) -> f64 {
    (x[0] - 0.3).powi(2) + 2.0 * (x[1] - 1.5).powi(2)
}

fn param(name: &str, lower: f64, upper: f64, start: f64) -> Param {
    Param {
        name: name.into(),
        target: Target::Scenario(KeyPath::parse(name).unwrap()),
        lower,
        upper,
        scale: Scale::Lin,
        start,
        integer: false,
    }
}

fn spec(params: Vec<Param>, solver: SolverSettings) -> Spec {
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
            normalise: true,
        },
        constraints: Vec::new(),
        solver,
    }
}

fn solver(method: Method, max_iters: u64, max_evals: usize, tolerance: f64) -> SolverSettings {
    SolverSettings {
        method,
        max_iters,
        max_evals,
        tolerance,
        restarts: 0,
        seed: 11,
        particles: 24,
        step: 0.1,
        polish: None,
    }
}

/// CMA-ES with σ0 = 0.3 (the problem files' default for it).
fn cmaes_solver(max_evals: usize, tolerance: f64) -> SolverSettings {
    SolverSettings {
        step: 0.3,
        ..solver(Method::Cmaes, 1000, max_evals, tolerance)
    }
}

fn quiet(_: &Record) {}

fn options(jobs: usize) -> Options<'static> {
    Options {
        jobs,
        journal: None,
        resume: false,
        on_record: &quiet,
        race: false,
    }
}

fn solve(f: fn(&[f64]) -> f64, spec: &Spec, jobs: usize) -> Outcome {
    minimise(spec, &Analytic::new(f), "analytic", &options(jobs)).unwrap()
}

#[test]
fn each_solver_finds_the_rosenbrock_minimum() {
    let box2 = || vec![param("a.x", -2.0, 2.0, -1.2), param("a.y", -2.0, 2.0, 1.0)];
    let cases = [
        (
            Method::NelderMead,
            solver(Method::NelderMead, 2000, 3000, 1e-14),
            1e-3,
        ),
        (Method::Lbfgs, solver(Method::Lbfgs, 500, 5000, 1e-10), 1e-3),
        (
            Method::ParticleSwarm,
            solver(Method::ParticleSwarm, 400, 20_000, 1e-6),
            5e-2,
        ),
        (Method::Cmaes, cmaes_solver(3000, 1e-14), 1e-3),
        // A surrogate method: a small budget, a looser tolerance (its strength is the first
        // tens of evaluations, not the last digits).
        (Method::Bayes, solver(Method::Bayes, 1000, 150, 1e-6), 5e-2),
    ];
    for (m, s, tol) in cases {
        let o = solve(rosenbrock, &spec(box2(), s), 2);
        let b = &o.best().x;
        assert!(
            (b[0] - 1.0).abs() < tol && (b[1] - 1.0).abs() < 2.0 * tol,
            "{m:?}: best {b:?} after {} evaluations ({:?})",
            o.records.len(),
            o.stops
        );
        // The objective is normalised by its start value 24.2.
        assert!((o.scorer.scales[0] - 24.2).abs() < 1e-9, "{m:?}");
    }
}

#[test]
fn each_solver_finds_the_bounded_quadratic_minimum_on_the_bound() {
    let box2 = || vec![param("a.x", 0.0, 1.0, 0.8), param("a.y", 0.0, 1.0, 0.2)];
    for m in [
        Method::NelderMead,
        Method::Lbfgs,
        Method::ParticleSwarm,
        Method::Cmaes,
        Method::Bayes,
    ] {
        let s = SolverSettings {
            step: if m == Method::Cmaes { 0.3 } else { 0.1 },
            ..solver(m, 300, if m == Method::Bayes { 120 } else { 3000 }, 1e-12)
        };
        let o = solve(bounded_quadratic, &spec(box2(), s), 1);
        let b = &o.best().x;
        assert!(
            (b[0] - 0.3).abs() < 1e-3 && (b[1] - 1.0).abs() < 1e-3,
            "{m:?}: best {b:?} ({:?})",
            o.stops
        );
        // Every evaluated point lies inside the bounds.
        assert!(o
            .records
            .iter()
            .all(|r| r.x.iter().all(|x| (0.0..=1.0).contains(x))));
    }
}

#[test]
fn the_evaluation_budget_is_exact() {
    // 37 is no multiple of the swarm (24) nor of CMA-ES's generation (λ = 6 for n = 2), and
    // CMA-ES's restarts (IPOP, λ 12, 24, …) cannot run past it either.
    let mut cm = cmaes_solver(37, 1e-12);
    cm.restarts = 5;
    for s in [solver(Method::ParticleSwarm, 1000, 37, 1e-12), cm] {
        let o = solve(
            rosenbrock,
            &spec(
                vec![param("a.x", -2.0, 2.0, 0.0), param("a.y", -2.0, 2.0, 0.0)],
                s.clone(),
            ),
            2,
        );
        // Every recorded point counts, repeats (served from memory, not simulated) included.
        assert_eq!(o.records.len(), 37, "{:?}", s.method);
        assert!(o.fresh_evaluations() <= 37);
        assert!(
            o.stops.iter().any(|s| s.contains("budget")),
            "{:?}",
            o.stops
        );
    }
}

/// An evaluator that records every point it is asked to evaluate.
struct Recording {
    inner: Analytic,
    seen: std::sync::Mutex<Vec<Vec<f64>>>,
}

impl Evaluator for Recording {
    fn metrics(&self) -> &[String] {
        self.inner.metrics()
    }
    fn evaluate(&self, x: &[f64]) -> Evaluation {
        self.seen.lock().unwrap().push(x.to_vec());
        self.inner.evaluate(x)
    }
}

/// Pulls every coordinate towards (−1, 5, 5), far outside the box's lower x and upper y, z.
fn outward(x: &[f64]) -> f64 {
    (x[0] + 1.0).powi(2) + (x[1] - 5.0).powi(2) + (x[2] - 5.0).powi(2) + 1.0
}

#[test]
fn no_solver_evaluates_outside_the_bounds() {
    // Optimum far outside a narrow box: every solver's proposals leave it; the evaluator sees
    // only projected points, and the best is the corner (0, 1, 1) of the box.
    let box3 = || {
        vec![
            param("a.x", 0.0, 0.2, 0.1),
            param("a.y", 0.0, 1.0, 0.5),
            param("a.z", 0.5, 1.0, 0.9),
        ]
    };
    for (m, step) in [
        (Method::NelderMead, 0.1),
        (Method::Lbfgs, 0.1),
        (Method::ParticleSwarm, 0.1),
        (Method::Cmaes, 0.5),
        (Method::Bayes, 0.1),
    ] {
        let mut s = SolverSettings {
            step,
            ..solver(m, 200, if m == Method::Bayes { 100 } else { 400 }, 1e-9)
        };
        s.restarts = 2;
        let ev = Recording {
            inner: Analytic::new(outward),
            seen: Default::default(),
        };
        let p = spec(box3(), s);
        let o = minimise(&p, &ev, "analytic", &options(2)).unwrap();
        let seen = ev.seen.into_inner().unwrap();
        assert!(seen.len() > 10, "{m:?}: {} points", seen.len());
        for x in &seen {
            for (v, q) in x.iter().zip(&p.space.params) {
                assert!((q.lower..=q.upper).contains(v), "{m:?}: {x:?} outside");
            }
        }
        let b = &o.best().x;
        assert!(
            b[0] < 1e-3 && b[1] > 1.0 - 1e-3 && b[2] > 1.0 - 1e-3,
            "{m:?}: best {b:?}"
        );
    }
}

#[test]
fn a_budget_smaller_than_the_simplex_stops_nelder_mead_without_a_panic() {
    // Three parameters need a simplex of four points; the start point and one more are all
    // the budget allows, for the first run and for a restart.
    for (max_evals, restarts) in [(2, 0), (5, 1)] {
        let mut s = solver(Method::NelderMead, 100, max_evals, 1e-12);
        s.restarts = restarts;
        let o = solve(
            rosenbrock,
            &spec(
                vec![
                    param("a.x", -2.0, 2.0, 0.0),
                    param("a.y", -2.0, 2.0, 0.0),
                    param("a.z", -2.0, 2.0, 0.0),
                ],
                s,
            ),
            1,
        );
        assert!(o.fresh_evaluations() <= max_evals);
        assert!(
            o.stops.iter().any(|s| s.contains("budget")),
            "{:?}",
            o.stops
        );
    }
}

fn table(o: &Outcome, spec: &Spec) -> usm_study::report::Table {
    let params: Vec<String> = spec.space.params.iter().map(|p| p.name.clone()).collect();
    history_table(&o.records, &params, &o.metrics, &[String::new()]).unwrap()
}

#[test]
fn resume_after_an_interruption_equals_the_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let mut cm = cmaes_solver(120, 1e-12);
    cm.restarts = 2;
    for s in [solver(Method::ParticleSwarm, 50, 120, 1e-12), cm] {
        let journal = dir.path().join(format!("{:?}-{JOURNAL_FILE}", s.method));
        resume_case(&journal, s);
    }
}

/// Run, cut the journal in the middle of its 52nd line, resume: the same history.
fn resume_case(journal: &Path, s: SolverSettings) {
    let journal = journal.to_path_buf();
    let sp = spec(
        vec![param("a.x", -2.0, 2.0, -1.2), param("a.y", -2.0, 2.0, 1.0)],
        s,
    );
    let full_ev = Analytic::new(rosenbrock);
    let opts = Options {
        journal: Some(&journal),
        ..options(2)
    };
    let full = minimise(&sp, &full_ev, "h", &opts).unwrap();
    assert_eq!(full.records.len(), 120);
    let fresh = full.fresh_evaluations();
    assert_eq!(full_ev.calls.load(Ordering::Relaxed), fresh);
    // Kill after 50 journal lines, in the middle of writing the 51st.
    let text = std::fs::read_to_string(&journal).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let torn = format!("{}\n{}", lines[..51].join("\n"), &lines[51][..10]);
    std::fs::write(&journal, torn).unwrap();
    let resumed_ev = Analytic::new(rosenbrock);
    let resumed = minimise(
        &sp,
        &resumed_ev,
        "h",
        &Options {
            resume: true,
            ..opts
        },
    )
    .unwrap();
    assert_eq!(resumed_ev.calls.load(Ordering::Relaxed), fresh - 50);
    assert_eq!(resumed.replayed, 50);
    assert!(table(&full, &sp).bit_eq(&table(&resumed, &sp)));
    assert_eq!(full.best, resumed.best);
    // A journal of another problem is refused.
    let other = minimise(
        &sp,
        &Analytic::new(rosenbrock),
        "another",
        &Options {
            resume: true,
            ..opts
        },
    );
    assert!(other.is_err());
}

/// A small closed-loop problem: two gains of transport Method 2, a 12 s run, two scenarios
/// (with and without a 0.2 m/s cross current), objective energy + overshoot, worst case.
const SMALL: &str = r#"
[study]
name = "small"
seed = 3

[design]
preset = "usm-paper"

[scenario]
mode = "transport"
duration = 12.0

[allocation]
method = "pinv"
lambda = 0.1

[[variant]]
name = "calm"

[[variant]]
name = "current"
set = { "physics.current" = [0.0, 0.2, 0.0] }

[[param]]
name = "control.k_psi"
lower = 0.1
upper = 1.0
scale = "log"

[[param]]
name = "control.k_6p"
lower = 0.002
upper = 0.05
scale = "log"

[objective]
combine = "worst"

[[objective.term]]
metric = "thruster_energy"
weight = 1.0

[[objective.term]]
metric = "overshoot"
weight = 0.5

[[constraint]]
metric = "completed"
op = "=="
value = 1

[[constraint]]
metric = "peak_thrust"
op = "<="
value = 40.0

[solver]
method = "particle-swarm"
particles = 5
max_evals = 16
seed = 9
"#;

#[test]
fn history_and_best_do_not_depend_on_the_number_of_threads() {
    let cmaes = SMALL.replace(
        "method = \"particle-swarm\"\nparticles = 5",
        "method = \"cmaes\"\nrestarts = 1",
    );
    assert_ne!(cmaes, SMALL);
    let bayes = SMALL.replace(
        "method = \"particle-swarm\"\nparticles = 5",
        "method = \"bayes\"",
    );
    for text in [SMALL, cmaes.as_str(), bayes.as_str()] {
        let p = parse_problem(text, Path::new("small.toml")).unwrap();
        if p.spec.solver.method == Method::Cmaes {
            assert_eq!(p.spec.solver.step, 0.3, "CMA-ES's default σ0");
        }
        let runs: Vec<Outcome> = [1, 2, 3]
            .iter()
            .map(|&j| run(&p, &options(j)).unwrap())
            .collect();
        let params: Vec<String> = p.spec.space.params.iter().map(|q| q.name.clone()).collect();
        let names = ["calm".to_string(), "current".to_string()];
        let t0 = history_table(&runs[0].records, &params, &runs[0].metrics, &names).unwrap();
        assert_eq!(
            runs[0].fresh_evaluations(),
            16,
            "{:?}",
            p.spec.solver.method
        );
        for o in &runs[1..] {
            let t = history_table(&o.records, &params, &o.metrics, &names).unwrap();
            assert!(t0.bit_eq(&t));
            assert_eq!(o.best, runs[0].best);
        }
    }
}

#[test]
fn best_toml_reproduces_the_best_objective() {
    use usm_study::outcome::run_scenario;
    use usm_study::pipeline::optimise::{write_outputs, OptimiseFiles};
    use usm_study::scenario::{load_table, parse_table, resolve_design};
    let p = parse_problem(SMALL, Path::new("small.toml")).unwrap();
    let o = run(&p, &options(2)).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write_outputs(&p, &o, dir.path(), OptimiseFiles { plots: false }).unwrap();
    let mut rows = Vec::new();
    for file in ["best.toml", "best_current.toml"] {
        let path = dir.path().join(file);
        let (t, src) = load_table(path.to_str().unwrap()).unwrap();
        let f = parse_table(&t, &src).unwrap();
        let v = resolve_design(&f, &src).unwrap();
        rows.push(pick(&run_scenario(&v, &f).unwrap().metrics, &o.metrics));
    }
    let again = o.scorer.score(&rows).objective;
    let best = o.best().score.objective;
    assert!(
        ((again - best) / best).abs() <= 1e-9,
        "simulate best.toml: {again}, optimiser: {best}"
    );
}

#[test]
fn the_metric_catalogue_names_every_metric_a_run_reports() {
    use usm_study::outcome::run_scenario;
    use usm_study::outcome::run_summary::is_run_metric;
    use usm_study::scenario::{load_table, parse_table, resolve_design, Mode};
    for (preset, mode) in [
        ("transport-method2", Mode::Transport),
        ("work-setpoint", Mode::Work),
    ] {
        let (mut t, src) = load_table(preset).unwrap();
        t["scenario"]["duration"] = toml::Value::Float(2.0);
        let f = parse_table(&t, &src).unwrap();
        let v = resolve_design(&f, &src).unwrap();
        let r = run_scenario(&v, &f).unwrap();
        for (name, _) in &r.metrics {
            assert!(
                is_run_metric(mode, name),
                "{preset}: {name} is not in the catalogue"
            );
        }
        assert!(!is_run_metric(mode, "no_such_metric"));
    }
}

/// A problem file with `[uncertainty]` (issue 22 item 4): every variant meets every world
/// (`calm/w0` …), the objective combines by CVaR, and a chance constraint on
/// `success_probability` is judged once over the worlds, not in each.
#[test]
fn uncertain_worlds_make_a_robust_problem_with_cvar_and_a_chance_constraint() {
    let text = SMALL
        .replace("combine = \"worst\"", "combine = \"cvar\"\nalpha = 0.5")
        .replace("max_evals = 16", "max_evals = 6")
        + r#"
[[constraint]]
metric = "success_probability"
op = ">="
value = 0.5

[uncertainty]
worlds = 3
[[uncertainty.param]]
name = "hydro.linear_damping_scale"
distribution = { kind = "uniform", low = 0.0, high = 2.0 }
"#;
    let p = parse_problem(&text, Path::new("robust.toml")).unwrap();
    let names: Vec<&str> = p.spec.variants.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "calm/w0",
            "calm/w1",
            "calm/w2",
            "current/w0",
            "current/w1",
            "current/w2"
        ]
    );
    // The same world values under both variants (common random numbers).
    let world = |i: usize| p.spec.variants[i].set.last().unwrap().clone();
    assert_eq!(world(0), world(3));
    assert_ne!(world(0), world(1));
    assert!(p.spec.metrics().contains(&"success".to_string()));
    let chance = p.spec.constraints.last().unwrap();
    assert!(chance.chance);
    let o = run(&p, &options(2)).unwrap();
    assert_eq!(o.records[0].metrics.len(), 6);
    // CVaR with α = 0.5 over 6 scenarios: the mean of the worst 3 scenario objectives.
    let s = &o.scorer;
    let mut js: Vec<f64> = o.records[0]
        .metrics
        .iter()
        .map(|m| s.scenario_objective(m))
        .collect();
    js.sort_by(|a, b| b.total_cmp(a));
    let expected = (js[0] + js[1] + js[2]) / 3.0;
    assert!((o.records[0].score.objective - expected).abs() <= 1e-12 * expected.abs());

    let bad = text.replace("alpha = 0.5", "alpha = 1.5");
    let e = parse_problem(&bad, Path::new("robust.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("objective.alpha"), "{e}");
}

#[test]
fn a_polish_keeps_the_methods_runs_and_spends_the_rest_on_nelder_mead() {
    // Bayesian optimisation of the bounded quadratic: 40 evaluations, then 40 of a
    // Nelder–Mead polish from its best point.
    let box2 = || vec![param("a.x", 0.0, 1.0, 0.8), param("a.y", 0.0, 1.0, 0.2)];
    let alone = solver(Method::Bayes, 1000, 40, 1e-12);
    let polished = SolverSettings {
        polish: Some(Polish {
            evals: 40,
            step: 0.05,
        }),
        ..solver(Method::Bayes, 1000, 80, 1e-12)
    };
    let a = solve(bounded_quadratic, &spec(box2(), alone), 1);
    let runs: Vec<Outcome> = [1, 2]
        .iter()
        .map(|&j| solve(bounded_quadratic, &spec(box2(), polished.clone()), j))
        .collect();
    let p = &runs[0];
    assert_eq!(p.records.len(), 80, "{:?}", p.stops);
    // The method's runs are those of its 40 evaluations without a polish, bit for bit.
    for (r, q) in a.records.iter().zip(&p.records[..40]) {
        assert_eq!((r.run, r.iteration), (q.run, q.iteration));
        assert_eq!(
            r.x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            q.x.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }
    // The polish is run 2 (one method run, no restarts) and starts from the best point.
    assert!(p.records[40..].iter().all(|r| r.run == 2));
    assert_eq!(p.records[40].x, a.best().x, "first vertex: the best so far");
    assert!(
        p.stops.last().unwrap().starts_with("polish (run 2)"),
        "{:?}",
        p.stops
    );
    let b = &p.best().x;
    assert!(p.best().score.objective <= a.best().score.objective);
    assert!(
        (b[0] - 0.3).abs() < 1e-3 && (b[1] - 1.0).abs() < 1e-3,
        "best {b:?}, without the polish {:?}",
        a.best().x
    );
    // Any number of threads: the same history.
    for (r, q) in p.records.iter().zip(&runs[1].records) {
        assert_eq!(r.x, q.x);
        assert_eq!(r.score.objective.to_bits(), q.score.objective.to_bits());
    }
}

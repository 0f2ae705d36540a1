//! Sample efficiency of the optimiser's solvers on the main study's per-design tuning problem
//! (issue 23 item 2): `studies/thrusters.toml`'s `[tune]` (k_ψ, Δ, k_6p, k_6d; `mission_cost`
//! subject to success, the cross-track bounds and the segments' convergence times) for every
//! design of the study (63; `DESIGNS=nine` for the 9 of the first table: rules paper /
//! distributed / ends × links 3 / 5 / 7, offset 0.10 m).
//!
//! Per design: each solver from the case's own start with `BUDGET` evaluations (Nelder–Mead
//! once, the seeded solvers with `SEEDS` seeds), then a reference optimum: the best feasible
//! objective of every run, a 300-evaluation particle swarm (unless `REFERENCE_SWARM=0`) and a
//! 120-evaluation Nelder–Mead polish from the best point found (unless `POLISH=0`). Every
//! objective is normalised at the case's own start point. Reported: the evaluations (simulated
//! runs, the start included) each run needs to come within 1 % of the reference with a
//! feasible point, its gap to the reference after 30 evaluations and at the end, and its
//! seconds. A design with no feasible point in any run, or one that cannot reach the mission
//! (the sweep tunes neither), is left out. One thread per process, deterministic; `SHARD=i/n`
//! runs the cases whose id is `i` modulo `n` (one process per core).
//!
//! ```sh
//! cargo run --release --example solver_efficiency [OUT.csv]   # default benches/solver_efficiency.csv
//! SOLVERS=nelder-mead,bayes BUDGET=75 cargo run --release --example solver_efficiency out.csv
//! # the 63-design table of benches/README.md, in two processes:
//! for i in 0 1; do SOLVERS=nelder-mead,particle-swarm,cmaes,bayes SEEDS=2 BUDGET=100 \
//!   REFERENCE_SWARM=0 POLISH=0 SHARD=$i/2 cargo run --release --example solver_efficiency \
//!   benches/solver_efficiency_63_$i.csv & done; wait
//! ```
//!
//! `SOLVERS` (comma-separated labels: nelder-mead, particle-swarm, cmaes, cmaes-0.2, bayes;
//! default all) and `BUDGET` (evaluations per run, default 120) cut the work.

mod common;

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use usm_study::evaluate::{out_of_reach, Deadline};
use usm_study::optimise::case_tuner::Tuner;
use usm_study::optimise::evaluate::CaseEvaluator;
use usm_study::optimise::history::Record;
use usm_study::optimise::problem::{Method, SolverSettings};
use usm_study::optimise::{minimise, Options, Spec};
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::expand;
use usm_study::study::parse::load_study;

/// Evaluations per solver run unless `BUDGET` says otherwise.
const DEFAULT_BUDGET: usize = 120;

/// Best feasible objective after each fresh evaluation (NaN before the first feasible one).
fn curve(records: &[Record]) -> Vec<f64> {
    let mut best = f64::NAN;
    let mut out = Vec::new();
    for r in records.iter().filter(|r| !r.repeat) {
        if r.score.feasible && (best.is_nan() || r.score.objective < best) {
            best = r.score.objective;
        }
        out.push(best);
    }
    out
}

fn settings(
    method: Method,
    max_evals: usize,
    restarts: usize,
    step: f64,
    seed: u64,
) -> SolverSettings {
    SolverSettings {
        method,
        max_iters: 1000,
        max_evals,
        tolerance: 1e-6,
        restarts,
        seed,
        particles: 12,
        step,
        polish: None,
    }
}

/// The `q`-quantile by nearest rank of `xs` (None: not reached, ranked last).
fn quantile(xs: &[Option<usize>], q: f64) -> Option<usize> {
    let mut v: Vec<usize> = xs.iter().map(|x| x.unwrap_or(usize::MAX)).collect();
    v.sort_unstable();
    let k = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    Some(v[k - 1]).filter(|x| *x != usize::MAX)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "benches/solver_efficiency.csv".into());
    let study = load_study(Path::new("studies/thrusters.toml"))?;
    let tuner = Tuner::new(&study).ok_or("no [tune] in studies/thrusters.toml")?;
    let cases = expand(&study, None)?;
    let quiet = |_: &Record| {};
    let opts = Options {
        jobs: 1,
        journal: None,
        resume: false,
        on_record: &quiet,
        race: false,
    };
    let seed = study.seed;
    let budget: usize = std::env::var("BUDGET")
        .ok()
        .and_then(|b| b.parse().ok())
        .unwrap_or(DEFAULT_BUDGET);
    let chosen = std::env::var("SOLVERS").ok();
    // DESIGNS=nine: the 9 designs of the first table (offset 0.10 m, links 3/5/7); default all.
    let nine = std::env::var("DESIGNS").is_ok_and(|d| d == "nine");
    // SHARD=i/n: only the cases whose id is i modulo n (to split the work across processes).
    let shard = common::shard()?;
    // SEEDS: seeds per seeded solver (default 3).
    let seeds: u64 = std::env::var("SEEDS")
        .ok()
        .and_then(|b| b.parse().ok())
        .unwrap_or(3);
    // REFERENCE_SWARM=0 leaves the 300-evaluation swarm out of the reference search.
    let swarm_ref = std::env::var("REFERENCE_SWARM").map_or(true, |v| v != "0");
    // POLISH=0 leaves the 120-evaluation Nelder–Mead polish out of the reference search.
    let polish = std::env::var("POLISH").map_or(true, |v| v != "0");
    // (label, settings, seeds): Nelder–Mead is deterministic, the others get `SEEDS`.
    let mut solvers: Vec<(&str, SolverSettings, u64)> = vec![
        (
            "nelder-mead",
            settings(Method::NelderMead, budget, 4, 0.2, seed),
            1,
        ),
        (
            "particle-swarm",
            settings(Method::ParticleSwarm, budget, 0, 0.1, seed),
            seeds,
        ),
        (
            "cmaes",
            settings(Method::Cmaes, budget, 3, 0.3, seed),
            seeds,
        ),
        (
            "cmaes-0.2",
            settings(Method::Cmaes, budget, 3, 0.2, seed),
            seeds,
        ),
        (
            "bayes",
            settings(Method::Bayes, budget, 0, 0.1, seed),
            seeds,
        ),
    ];
    if let Some(list) = &chosen {
        solvers.retain(|(name, _, _)| list.split(',').any(|c| c.trim() == *name));
    }
    let mut csv = String::from(
        "design,solver,seed,evaluations,best,best_at_30,reference,evals_to_1pct,seconds\n",
    );
    let mut hits: Vec<(String, Option<usize>, f64)> = Vec::new();
    let t0 = Instant::now();
    for case in &cases {
        let (rule, links, offset) = common::design_axes(case);
        if nine && (![3, 5, 7].contains(&links) || (offset - 0.10).abs() > 1e-9) {
            continue;
        }
        if case.id % shard.1 != shard.0 {
            continue;
        }
        let design = if nine {
            format!("{rule}-{links}")
        } else {
            format!("{rule}-{links}-{offset:.2}")
        };
        let r = resolve_case(&study, case)?;
        // The sweep neither tunes nor scores a design that cannot reach the mission: its
        // tuning problem has no feasible point.
        if out_of_reach(&r.design, &r.scenario, &study.name) {
            eprintln!("{design:16} cannot reach the mission: left out");
            continue;
        }
        let problem = tuner.case_problem(&study, &r);
        let ev = CaseEvaluator::new(&problem).for_case(case.id, Deadline::NONE);
        let run = |s: SolverSettings, start: Option<&[f64]>| {
            let mut spec: Spec = problem.spec.clone();
            spec.solver = s;
            if let Some(x) = start {
                for (p, v) in spec.space.params.iter_mut().zip(x) {
                    p.start = *v;
                }
            }
            minimise(&spec, &ev, &study.hash, &opts)
        };
        let mut reference = f64::INFINITY;
        let mut runs = Vec::new();
        for (name, s, seeds) in &solvers {
            for k in 0..*seeds {
                let t = Instant::now();
                let o = run(
                    SolverSettings {
                        seed: s.seed + k,
                        ..s.clone()
                    },
                    None,
                )?;
                let secs = t.elapsed().as_secs_f64();
                runs.push((*name, k, curve(&o.records), o.best().x.clone(), secs));
            }
        }
        // The reference: the best of every run above, a 300-evaluation swarm, and a
        // Nelder–Mead polish (120 evaluations, restarts) from the best point found.
        let mut best_x = problem.spec.space.params.iter().map(|p| p.start).collect();
        if swarm_ref {
            let swarm = run(
                settings(Method::ParticleSwarm, 300, 0, 0.1, seed ^ 0xA5),
                None,
            )?;
            if swarm.best().score.feasible {
                reference = swarm.best().score.objective;
                best_x = swarm.best().x.clone();
            }
        }
        for (_, _, c, x, _) in &runs {
            if let Some(b) = c.last().filter(|b| b.is_finite() && **b < reference) {
                reference = *b;
                best_x = x.clone();
            }
        }
        // The polish starts at `best_x`, and a run's objective is normalised at its own start
        // point: its scores are relative to `best_x`'s, whose value in the case-start
        // normalisation is `reference`. (Before this rescaling the polish's scores were
        // compared as they were and never set the reference: the committed 63-design CSV was
        // made with POLISH=0, which gives the same references.)
        if polish && reference.is_finite() {
            let p = run(
                settings(Method::NelderMead, 120, 4, 0.05, seed),
                Some(&best_x),
            )?;
            if p.best().score.feasible {
                reference = reference.min(p.best().score.objective * reference);
            }
        }
        if !reference.is_finite() {
            // No feasible point anywhere (e.g. a design the mission's reach rules out):
            // nothing to come within 1 % of.
            eprintln!("{design:16} no feasible point in any run: left out");
            continue;
        }
        for (name, k, c, _, secs) in &runs {
            let hit = c.iter().position(|b| *b <= reference * 1.01).map(|i| i + 1);
            let best = c.last().copied().unwrap_or(f64::NAN);
            let at30 = c.get(29).or(c.last()).copied().unwrap_or(f64::NAN);
            writeln!(
                csv,
                "{design},{name},{k},{},{best},{at30},{reference},{},{secs:.2}",
                c.len(),
                hit.map_or("".into(), |h| h.to_string())
            )?;
            eprintln!(
                "{design:16} {name:15} {k} best {best:.5} @30 {at30:.5} ref {reference:.5} hit {hit:?}"
            );
            hits.push((name.to_string(), hit, at30 / reference - 1.0));
        }
        eprintln!("  ({:.0} s so far)", t0.elapsed().as_secs_f64());
        std::fs::write(&out, &csv)?;
    }
    std::fs::write(&out, csv)?;
    eprintln!("wrote {out} in {:.0} s", t0.elapsed().as_secs_f64());
    println!("| solver | runs | reached 1 % within 40 | within {budget} | median | 90th percentile | median gap at 30 |");
    println!("|---|---|---|---|---|---|---|");
    let show = |x: Option<usize>| x.map_or(format!("> {budget}"), |v| v.to_string());
    for (name, _, _) in &solvers {
        let h: Vec<Option<usize>> = hits.iter().filter(|x| x.0 == *name).map(|x| x.1).collect();
        let mut gaps: Vec<f64> = hits.iter().filter(|x| x.0 == *name).map(|x| x.2).collect();
        gaps.sort_by(|a, b| a.total_cmp(b));
        let gap = gaps.get(gaps.len() / 2).copied().unwrap_or(f64::NAN);
        println!(
            "| {name} | {} | {} | {} | {} | {} | {:.1} % |",
            h.len(),
            h.iter().filter(|x| x.is_some_and(|v| v <= 40)).count(),
            h.iter().filter(|x| x.is_some()).count(),
            show(quantile(&h, 0.5)),
            show(quantile(&h, 0.9)),
            100.0 * gap
        );
    }
    Ok(())
}

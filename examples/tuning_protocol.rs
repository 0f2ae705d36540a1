//! The main study's tuning as the sweep runs it, per solver (issue 23 item 2): for every design
//! of `studies/thrusters.toml` with a reference optimum (from `examples/solver_efficiency.rs`'s
//! CSV), the study's own `[tune]` — its independent starts, its budget split between them, its
//! start points — with only `[tune.solver] method` (and the budget split) changed. Reported per
//! design and protocol: the tuned objective's gap to the reference (both normalised at the
//! case's own start point, as the reference is), whether the tuned point is feasible, the
//! tuning noise and the seconds taken. One thread per process, deterministic.
//!
//! ```sh
//! cargo run --release --example tuning_protocol OUT.csv REFERENCE.csv...
//! PROTOCOLS=nelder-mead:3x25,bayes:1x75 SHARD=0/2 cargo run --release --example tuning_protocol out.csv ref.csv
//! ```
//!
//! `PROTOCOLS`: comma-separated `method:STARTSxEVALS` (default
//! `nelder-mead:3x25,particle-swarm:3x25,bayes:3x25,bayes:1x75`); `SHARD=i/n` takes the cases
//! whose id is `i` modulo `n`.

mod common;

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use usm_study::batch::tuning_hook::CaseTuner;
use usm_study::evaluate::Deadline;
use usm_study::optimise::case_tuner::Tuner;
use usm_study::optimise::evaluate::CaseEvaluator;
use usm_study::optimise::search::Evaluator;
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::expand;
use usm_study::study::parse::parse_study;

const STUDY: &str = "studies/thrusters.toml";

/// The study's text with `[tune] starts` and the keys of `[tune.solver]` (up to the blank line
/// that ends the section) set for one protocol; `None` when the study has no such sections.
fn protocol_text(text: &str, method: &str, starts: usize, evals: usize) -> Option<String> {
    let starts_line = "[tune]\nstarts = ";
    let a = text.find(starts_line)? + starts_line.len();
    let a_end = a + text[a..].find('\n')?;
    let solver = "[tune.solver]\n";
    let b = text.find(solver)? + solver.len();
    let b_end = text[b..].find("\n\n").map_or(text.len(), |e| b + e + 1);
    // Each solver with the settings of examples/solver_efficiency.rs: Nelder–Mead's step is
    // the study's own (0.2), the swarm has 12 particles, the others their defaults.
    let extra = match method {
        "nelder-mead" => "step = 0.2\n",
        "particle-swarm" => "particles = 12\n",
        _ => "",
    };
    Some(format!(
        "{}{starts}{}method = \"{method}\"\nmax_evals = {}\n{extra}{}",
        &text[..a],
        &text[a_end..b],
        starts * evals,
        &text[b_end..]
    ))
}

/// Mean over the scenario rows of metric column `c`.
fn mean(rows: &[Vec<f64>], c: usize) -> f64 {
    rows.iter().map(|r| r[c]).sum::<f64>() / rows.len() as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args
        .next()
        .ok_or("usage: tuning_protocol OUT.csv REFERENCE.csv...")?;
    // design → reference optimum (normalised at the case's start).
    let mut reference: HashMap<String, f64> = HashMap::new();
    for f in args {
        let text = std::fs::read_to_string(&f)?;
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
        let col = |n: &str| {
            head.iter()
                .position(|h| *h == n)
                .ok_or(format!("{f}: no {n}"))
        };
        let (d, r) = (col("design")?, col("reference")?);
        for l in lines {
            let cells: Vec<&str> = l.split(',').collect();
            reference.insert(cells[d].to_string(), cells[r].parse()?);
        }
    }
    let protocols: Vec<(String, usize, usize)> = std::env::var("PROTOCOLS")
        .unwrap_or_else(|_| "nelder-mead:3x25,particle-swarm:3x25,bayes:3x25,bayes:1x75".into())
        .split(',')
        .map(|p| {
            let (m, se) = p.split_once(':')?;
            let (s, e) = se.split_once('x')?;
            Some((m.to_string(), s.parse().ok()?, e.parse().ok()?))
        })
        .collect::<Option<_>>()
        .ok_or("PROTOCOLS: method:STARTSxEVALS, comma-separated")?;
    let shard = common::shard()?;
    let text = std::fs::read_to_string(STUDY)?;
    let mut csv =
        String::from("design,protocol,evaluations,feasible,tuned,reference,gap,noise,seconds\n");
    let t0 = Instant::now();
    for (method, starts, evals) in &protocols {
        let label = format!("{method}:{starts}x{evals}");
        let t = protocol_text(&text, method, *starts, *evals)
            .ok_or("studies/thrusters.toml has no `[tune] starts = …` or no [tune.solver]")?;
        let study = parse_study(&t, Path::new(STUDY))?;
        let tuner = Tuner::new(&study).ok_or("no [tune]")?;
        for case in expand(&study, None)? {
            if case.id % shard.1 != shard.0 {
                continue;
            }
            let (rule, links, offset) = common::design_axes(&case);
            let design = format!("{rule}-{links}-{offset:.2}");
            let Some(&reference) = reference.get(&design) else {
                continue;
            };
            let r = resolve_case(&study, &case)?;
            let ts = Instant::now();
            let tuned = tuner.tune(&study, &case, &r, Deadline::NONE)?;
            let secs = ts.elapsed().as_secs_f64();
            let problem = tuner.case_problem(&study, &r);
            let ev = CaseEvaluator::new(&problem).for_case(case.id, Deadline::NONE);
            let c = ev
                .metrics()
                .iter()
                .position(|m| m == "mission_cost")
                .ok_or("no mission_cost column")?;
            let start: Vec<f64> = problem.spec.space.params.iter().map(|p| p.start).collect();
            let scale = mean(&ev.evaluate(&start).metrics, c).abs();
            let scale = if scale.is_finite() && scale > 0.0 {
                scale
            } else {
                1.0
            };
            let value = mean(&ev.evaluate(&tuned.x).metrics, c) / scale;
            let gap = if tuned.feasible {
                value / reference - 1.0
            } else {
                f64::NAN
            };
            writeln!(
                csv,
                "{design},{label},{},{},{value},{reference},{gap},{},{secs:.2}",
                tuned.evaluations, tuned.feasible as u8, tuned.noise
            )?;
            eprintln!(
                "{design:18} {label:22} gap {:6.2} % feasible {} noise {:.3} ({secs:.1} s; {:.0} s so far)",
                100.0 * gap,
                tuned.feasible,
                tuned.noise,
                t0.elapsed().as_secs_f64()
            );
            std::fs::write(&out, &csv)?;
        }
    }
    std::fs::write(&out, &csv)?;
    Ok(())
}

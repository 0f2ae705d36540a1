//! `usm-study optimise PROBLEM.toml [--jobs N] [--resume] [--out DIR]`: optimise a problem
//! file's parameters with argmin (docs/optimise.md) and write the history, the best point as
//! a runnable file, a summary and plots.
//!
//! Exit codes: 0 the best point is feasible, 1 no evaluated point met the constraints (the
//! outputs are still written), 2 bad input (problem file, command line) or an I/O error —
//! problem-file errors are reported before any evaluation.

use super::progress::Progress;
use anyhow::bail;
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use usm_study::batch::outdir;
use usm_study::optimise::history::{Record, JOURNAL_FILE};
use usm_study::optimise::{load_problem, run, Options};
use usm_study::pipeline::create_dir;
use usm_study::pipeline::optimise::{write_outputs, OptimiseFiles, BEST_FILE};
use usm_study::report::fmt_num;

/// Arguments of `optimise`.
#[derive(Debug, Args)]
pub struct OptimiseArgs {
    /// Problem file (TOML): a study file with [[param]], [objective], [[constraint]] and
    /// [solver] instead of sweep axes.
    pub problem: PathBuf,
    /// Threads evaluating a batch (0: all cores). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
    /// Replay the journal of an interrupted run in the output directory, then carry on
    /// (same result as an uninterrupted run).
    #[arg(long)]
    pub resume: bool,
    /// Output directory (default: the problem's `study.output`, else
    /// results/optimise/<name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Do not write the SVG plots (and skip the reruns they need).
    #[arg(long)]
    pub no_plots: bool,
}

/// Refuse an output directory that a link leads out of, that holds a sweep's output, or the
/// optimisation of another problem (its `manifest.json` names it).
fn check_output(out: &Path, problem: &str) -> anyhow::Result<()> {
    outdir::check_contained(out)?;
    let sweep_files = [
        "cases.csv",
        "cases.parquet",
        "cases.partial.csv",
        "study.toml",
    ];
    if let Some(f) = sweep_files.iter().find(|f| out.join(f).exists()) {
        bail!(
            "{} holds a sweep's output ({f}): an optimisation needs its own directory; use \
             another --out",
            out.display()
        );
    }
    let manifest = out.join("manifest.json");
    if let Ok(text) = std::fs::read_to_string(&manifest) {
        let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
        match v["problem"].as_str() {
            Some(p) if p == problem => {}
            Some(p) => bail!(
                "{} holds the optimisation of another problem ({p}); use another --out",
                out.display()
            ),
            None => bail!(
                "{} holds a manifest.json that is not an optimisation's; use another --out",
                out.display()
            ),
        }
    }
    Ok(())
}

/// Run `usm-study optimise`.
pub fn run_optimise(a: &OptimiseArgs) -> anyhow::Result<ExitCode> {
    let problem = load_problem(&a.problem)?;
    let s = &problem.study;
    let out = a.out.clone().unwrap_or_else(|| {
        if s.output == Path::new("results/sweeps").join(&s.name) {
            Path::new("results/optimise").join(&s.name)
        } else {
            s.output.clone()
        }
    });
    create_dir(&out)?;
    // The same lock and output checks as `sweep`: one run per directory, no link out of it,
    // no other output mixed in.
    let out = outdir::resolve(&out)?;
    let lock = outdir::lock(
        &out,
        &outdir::LockOwner {
            study: &s.hash,
            resume: a.resume,
        },
    )?;
    if let Some(t) = &lock.takeover {
        eprintln!("[optimise] {t}");
    }
    check_output(&out, &s.name)?;
    let spec = &problem.spec;
    eprintln!(
        "[optimise] {} ({} mode, {} parameters, {} scenario{}, {} metrics): {} up to {} evaluations, output {}",
        s.name,
        s.mode,
        spec.space.dim(),
        spec.variants.len(),
        if spec.variants.len() == 1 { "" } else { "s" },
        spec.metrics().len(),
        spec.solver.method.as_str(),
        spec.solver.max_evals,
        out.display()
    );
    let jobs = if a.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        a.jobs
    };
    let progress = Progress::new("optimise", "evaluations", spec.solver.max_evals, true);
    let fresh = AtomicUsize::new(0);
    let on_record = |r: &Record| {
        if !r.repeat {
            let n = fresh.fetch_add(1, Ordering::Relaxed) + 1;
            progress.update(n, n);
        }
    };
    let journal = out.join(JOURNAL_FILE);
    let opts = Options {
        jobs,
        journal: Some(&journal),
        resume: a.resume,
        on_record: &on_record,
        race: false,
    };
    let outcome = run(&problem, &opts)?;
    progress.finish();
    write_outputs(
        &problem,
        &outcome,
        &out,
        OptimiseFiles { plots: !a.no_plots },
    )?;
    let (st, b) = (outcome.start(), outcome.best());
    println!(
        "{} ({} evaluations, {} fresh, {} replayed)",
        s.name,
        outcome.records.len(),
        outcome.fresh_evaluations(),
        outcome.replayed
    );
    for (k, p) in spec.space.params.iter().enumerate() {
        println!(
            "  {:<34} {:>12} -> {:>12}",
            p.name,
            fmt_num(st.x[k]),
            fmt_num(b.x[k])
        );
    }
    println!(
        "  objective {} -> {} (best at evaluation {}, {})",
        fmt_num(st.score.objective),
        fmt_num(b.score.objective),
        b.index,
        if b.score.feasible {
            "feasible"
        } else {
            "infeasible"
        }
    );
    eprintln!(
        "[optimise] wrote {} (best point: {})",
        out.display(),
        out.join(BEST_FILE).display()
    );
    super::sweep::review("optimise", &out)?;
    outdir::record_owned(&out, lock.created, &["report.html"])?;
    drop(lock);
    Ok(if b.score.feasible {
        ExitCode::SUCCESS
    } else {
        eprintln!(
            "error: no evaluated point meets every constraint (violation {})",
            fmt_num(b.score.violation)
        );
        ExitCode::from(1)
    })
}

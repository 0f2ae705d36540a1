//! `usm-study sweep STUDY.toml`, `usm-study merge DIR... --out DIR`, `usm-study report DIR`:
//! the batch engine's commands (docs/model.md §7; schema in `docs/study-format.md`).
//!
//! Each writes the output directory's `report.html` (the design-review page) last.
//!
//! Exit codes: 0 all cases ok or skipped, 1 some cases failed (the batch still completes),
//! 2 bad input (study file, command line) or an I/O error (including an unwritable report).

use super::progress::Progress;
use anyhow::{anyhow, bail, Context};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;
use usm_study::batch::engine::output_dir;
use usm_study::batch::outdir;
use usm_study::batch::records::{axis_text, CASES_PARQUET, PARTIAL_FILE};
use usm_study::batch::shards::{read_shard_list, slurm_script, MergeOptions, SlurmPlan};
use usm_study::batch::{merge, run_sweep, SweepOptions};
use usm_study::optimise::case_tuner::HOOK as TUNING;
use usm_study::pipeline::review::write_review;
use usm_study::review::{report_ranked, Reported, Rerank, HOOK as REPORT};
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::expand;
use usm_study::study::{load_study_at, StudyError};

/// Arguments of `sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Study file (TOML).
    pub study: PathBuf,
    /// Worker threads (0: all cores). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
    /// List the cases (id, hash, axis values) without running them.
    #[arg(long)]
    pub dry_run: bool,
    /// Keep the cases already in the output's cases.partial.csv (matched by hash) and run the
    /// rest.
    #[arg(long)]
    pub resume: bool,
    /// Run only the cases with id mod N == I: `I/N`, or `slurm` to read
    /// SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT (minus SLURM_ARRAY_TASK_MIN).
    #[arg(long, value_parser = parse_shard)]
    pub shard: Option<ShardArg>,
    /// Output directory (default: the study's `output`, plus `shard-I-of-N` for shards).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Stop after running K cases, without final outputs (simulates an interruption).
    #[arg(long, hide = true)]
    pub max_cases: Option<usize>,
    /// Wall-clock budget of one case in seconds (0: none). A case still running after it is
    /// recorded as failed with reason `timeout: …` and the batch goes on.
    #[arg(long, default_value_t = DEFAULT_CASE_TIMEOUT_S, value_name = "SECONDS")]
    pub case_timeout: f64,
    /// Replace another study's output in the output directory (its tables, manifest, summary
    /// and plots are removed first).
    #[arg(long)]
    pub force: bool,
    /// Write a Slurm submission script for the study to FILE instead of running it: a job
    /// array (`--shard slurm`, one shard per task) and a merge job after it. Run it with bash.
    #[arg(long, value_name = "FILE")]
    pub emit_slurm: Option<PathBuf>,
    /// Cases per Slurm array task (with --emit-slurm).
    #[arg(long, default_value_t = 10, value_name = "K")]
    pub cases_per_task: usize,
    /// Run the study at another `[study] seed` (the worlds, the tuning and every seeded draw
    /// change; the study file is not edited). Without --out the output goes to the study's
    /// `output` plus `-seed-N`, so the committed output of the file's own seed is kept.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(0..=i64::MAX as u64))]
    pub seed: Option<u64>,
}

/// Write the Slurm submission script of `--emit-slurm`.
fn emit_slurm(a: &SweepArgs, study: &usm_study::study::Study, file: &Path) -> anyhow::Result<()> {
    if a.cases_per_task == 0 {
        bail!("--cases-per-task: must be >= 1");
    }
    if a.shard.is_some() || a.resume || a.dry_run {
        bail!("--emit-slurm: the script shards and resumes itself; drop --shard, --resume and --dry-run");
    }
    let cwd = std::env::current_dir()?;
    let out = cwd.join(a.out.as_ref().unwrap_or(&study.output));
    let plan = SlurmPlan {
        exe: std::env::current_exe()?,
        study: std::fs::canonicalize(&a.study)?,
        out,
        cases: usm_study::study::doe::case_count(study),
        cases_per_task: a.cases_per_task,
        cpus: if a.jobs == 0 { 1 } else { a.jobs },
        case_timeout_s: a.case_timeout,
        name: study.name.clone(),
        force: a.force,
    };
    usm_study::report::atomic_write(file, slurm_script(&plan).as_bytes())?;
    eprintln!(
        "[sweep] wrote {}: {} array tasks of {} cases, merged into {}; submit with `bash {}`",
        file.display(),
        plan.tasks(),
        plan.cases_per_task,
        plan.out.display(),
        file.display()
    );
    Ok(())
}

/// Default `--case-timeout` [s]: ten times the longest shipped case (a 170 s transport run,
/// about 30 s of wall time on one loaded core).
pub const DEFAULT_CASE_TIMEOUT_S: f64 = 600.0;

/// The `--case-timeout` value as a budget (`None` for 0).
fn case_budget(seconds: f64) -> anyhow::Result<Option<Duration>> {
    if !(0.0..=1e9).contains(&seconds) {
        bail!("--case-timeout: must be a number of seconds in 0..=1e9 (0: none), got {seconds}");
    }
    Ok((seconds > 0.0).then(|| Duration::from_secs_f64(seconds)))
}

/// A `--shard` value.
#[derive(Clone, Debug)]
pub enum ShardArg {
    /// Explicit `I/N`.
    Fixed(usize, usize),
    /// From the Slurm array environment.
    Slurm,
}

/// A `--shard` value that is neither `I/N` with `0 <= I < N` nor `slurm`.
#[derive(Debug, thiserror::Error)]
enum ShardArgError {
    #[error("expected I/N (e.g. 0/4) or `slurm`, got '{0}'")]
    Form(String),
    #[error("'{0}' is not a non-negative integer")]
    NotIndex(String),
    #[error("shard {0}/{1}: need 0 <= I < N")]
    Range(usize, usize),
}

fn parse_shard(s: &str) -> Result<ShardArg, ShardArgError> {
    if s == "slurm" {
        return Ok(ShardArg::Slurm);
    }
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| ShardArgError::Form(s.to_string()))?;
    let p = |x: &str| {
        x.trim()
            .parse::<usize>()
            .map_err(|_| ShardArgError::NotIndex(x.to_string()))
    };
    let (i, n) = (p(i)?, p(n)?);
    if n == 0 || i >= n {
        return Err(ShardArgError::Range(i, n));
    }
    Ok(ShardArg::Fixed(i, n))
}

fn slurm_shard() -> anyhow::Result<(usize, usize)> {
    let var = |k: &str| -> anyhow::Result<usize> {
        std::env::var(k)
            .map_err(|_| anyhow!("--shard slurm: {k} is not set (run inside `sbatch --array`)"))?
            .trim()
            .parse()
            .map_err(|_| anyhow!("--shard slurm: {k} is not an integer"))
    };
    let id = var("SLURM_ARRAY_TASK_ID")?;
    let count = var("SLURM_ARRAY_TASK_COUNT")?;
    let min = var("SLURM_ARRAY_TASK_MIN").unwrap_or(0);
    let i = id
        .checked_sub(min)
        .ok_or_else(|| anyhow!("--shard slurm: task id below the array minimum"))?;
    if count == 0 || i >= count {
        bail!("--shard slurm: task {i} of {count} (the array must be contiguous)");
    }
    Ok((i, count))
}

/// A study error with its causes (the command line prints the chain on one line).
fn study_err(e: StudyError) -> anyhow::Error {
    anyhow::Error::new(e)
}

/// Run `usm-study sweep`.
pub fn run(a: &SweepArgs) -> anyhow::Result<ExitCode> {
    let study = load_study_at(&a.study, a.seed)?;
    // `[tune]` was checked when the study was read (also for --dry-run and --emit-slurm).
    // Worlds a case cannot run within its budget are refused here, not timed out case by case.
    let threads = match a.jobs {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        j => j,
    };
    usm_study::study::admit::check_world_budget(&study, a.case_timeout, threads)?;
    let shard = match &a.shard {
        None => None,
        Some(ShardArg::Fixed(i, n)) => Some((*i, *n)),
        Some(ShardArg::Slurm) => Some(slurm_shard()?),
    };
    if let Some(file) = &a.emit_slurm {
        emit_slurm(a, &study, file)?;
        return Ok(ExitCode::SUCCESS);
    }
    let opts = SweepOptions {
        jobs: a.jobs,
        resume: a.resume,
        shard,
        out: a.out.clone().or_else(|| {
            a.seed
                .map(|n| PathBuf::from(format!("{}-seed-{n}", study.output.display())))
        }),
        max_cases: a.max_cases,
        case_timeout: case_budget(a.case_timeout)?,
        force: a.force,
        tuning: Some(TUNING),
        bound: Some(usm_study::ocp::study_bound::HOOK),
        report: Some(REPORT),
    };
    if a.dry_run {
        let cases = expand(&study, shard)?;
        println!(
            "study {} ({} mode{}): {} cases{}, output {}",
            study.name,
            study.mode,
            if study.static_enabled {
                " + static TCM"
            } else {
                ""
            },
            cases.len(),
            shard.map_or(String::new(), |(i, n)| format!(" in shard {i}/{n}")),
            output_dir(&study, &opts).display()
        );
        for c in &cases {
            let vals: Vec<String> = study
                .axes
                .iter()
                .zip(&c.values)
                .map(|(ax, v)| format!("{}={}", ax.name, axis_text(v)))
                .collect();
            let hash = match resolve_case(&study, c) {
                Ok(r) => r.hash,
                Err(reason) => format!("(skipped: {reason})"),
            };
            println!("{:>6} {} {}", c.id, hash, vals.join(" "));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let total = expand(&study, shard).map(|c| c.len()).unwrap_or(0);
    let progress = Progress::new("sweep", "cases", total, true);
    let outcome = run_sweep(&study, &opts, &mut |ev| {
        progress.update(ev.finished, ev.ran)
    })
    .map_err(study_err)?;
    progress.finish();
    for w in &outcome.warnings {
        eprintln!("[sweep] warning: {w}");
    }
    eprintln!(
        "[sweep] resumed {} cases, ran {}",
        outcome.resumed, outcome.ran
    );
    if outcome.timeouts > 0 {
        eprintln!(
            "[sweep] {} cases ran out of their --case-timeout of {} s (failed, reason `timeout`)",
            outcome.timeouts, a.case_timeout
        );
    }
    if outcome.interrupted {
        eprintln!(
            "[sweep] stopped after {} cases (--max-cases); rerun with --resume to finish {}",
            outcome.ran,
            outcome.out.display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    review("sweep", &outcome.out)?;
    eprintln!(
        "[sweep] {} cases: {} ok, {} unsuccessful, {} failed, {} skipped; {:.1} s ({}); wrote {}",
        outcome.in_shard,
        outcome.ok,
        outcome.unsuccessful,
        outcome.failed,
        outcome.skipped,
        outcome.elapsed_s,
        super::progress::rate_text(
            if outcome.elapsed_s > 0.0 {
                outcome.ran as f64 / outcome.elapsed_s
            } else {
                0.0
            },
            "cases"
        ),
        outcome.out.display()
    );
    print_verdict("sweep", &outcome.out);
    Ok(if outcome.failed > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// Arguments of `merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Shard output directories (each with manifest.json and cases.partial.csv).
    #[arg(required_unless_present = "list")]
    pub dirs: Vec<PathBuf>,
    /// Read the shard directories from FILE, one a line (relative to the file's directory),
    /// after those given as arguments.
    #[arg(long, value_name = "FILE")]
    pub list: Option<PathBuf>,
    /// Output directory of the merged study.
    #[arg(long)]
    pub out: PathBuf,
    /// Merge what is there although shards are missing, given twice or of different shard
    /// counts (without it: exit 2 naming them).
    #[arg(long)]
    pub partial: bool,
    /// Replace another study's output in the output directory (only files usm-study wrote).
    #[arg(long)]
    pub force: bool,
}

/// Run `usm-study merge`.
pub fn run_merge(a: &MergeArgs) -> anyhow::Result<ExitCode> {
    let mut dirs = a.dirs.clone();
    if let Some(list) = &a.list {
        dirs.extend(read_shard_list(list).map_err(study_err)?);
    }
    let opts = MergeOptions {
        partial: a.partial,
        force: a.force,
    };
    let (m, warnings) =
        merge(&dirs, &a.out, opts, Some(TUNING), Some(REPORT)).map_err(study_err)?;
    for w in &warnings {
        eprintln!("[merge] warning: {w}");
    }
    review("merge", &a.out)?;
    eprintln!(
        "[merge] {} directories: {} cases ({} ok, {} unsuccessful, {} failed, {} skipped); wrote {}",
        dirs.len(),
        m.cases.in_output,
        m.cases.ok,
        m.cases.unsuccessful,
        m.cases.failed,
        m.cases.skipped,
        a.out.display()
    );
    Ok(if m.cases.failed > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// Arguments of `report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// A study output directory: of `sweep`, `merge` or `optimise` (one with manifest.json).
    pub dir: PathBuf,
    /// Re-rank by this metric (a column of cases.csv) without re-running: the verdict,
    /// summary.md, the plots and report.html pick the best case by it; larger or smaller is
    /// better as for a study's `objective`. With [uncertainty], one of the metrics the worlds
    /// recorded (p_best and the ranks are recomputed). Recorded in manifest.json.
    #[arg(long, value_name = "METRIC")]
    pub objective: Option<String>,
    /// Plot this trade-off as the Pareto front, `X,Y` (two metric columns), without
    /// re-running. Recorded in manifest.json.
    #[arg(long, value_name = "X,Y", value_parser = parse_pareto)]
    pub pareto: Option<[String; 2]>,
}

/// A `--pareto X,Y` value.
fn parse_pareto(s: &str) -> Result<[String; 2], String> {
    match s.split(',').map(str::trim).collect::<Vec<_>>()[..] {
        [x, y] if !x.is_empty() && !y.is_empty() => Ok([x.to_string(), y.to_string()]),
        _ => Err(format!("expected two metric names X,Y, got '{s}'")),
    }
}

/// The verdict `summary.md` opens with (a study with uncertain worlds) as plain text, else the
/// best case by the objective, and where the review page is.
fn print_verdict(verb: &str, dir: &Path) {
    let Ok(md) = std::fs::read_to_string(dir.join("summary.md")) else {
        return;
    };
    let plain = |s: &str| s.replace("**", "").replace('`', "");
    if let Some(v) = usm_study::review::summary_robust::summary_verdict(&md) {
        eprintln!("[{verb}] {}", plain(v));
    } else if let Some(best) = usm_study::review::finish::best_case_line(dir) {
        eprintln!("[{verb}] {best}");
    }
    // The leader's caveats, as the box lists them (each condition's verdict first, with
    // condition axes).
    let opening = usm_study::review::summary_robust::summary_opening(&md).unwrap_or("");
    for l in opening.lines() {
        if let Some(c) = l.strip_prefix("- ") {
            eprintln!("[{verb}]   caveat: {}", plain(c));
        } else if l.starts_with("**Under ") {
            eprintln!("[{verb}] {}", plain(l));
        }
    }
    eprintln!(
        "[{verb}] review: {}",
        dir.join(usm_study::pipeline::review::REPORT_HTML).display()
    );
}

/// Hands the heap memory freed by the phases before (the case table, its polars frame, the
/// Parquet buffers) back to the operating system, so that the page built next does not add
/// its own peak on top of theirs in the resident set (glibc keeps freed memory otherwise;
/// this took the 100 000-case static study's peak from 199 to 181 MB).
fn release_free_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases unused heap pages; it has no preconditions.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Writes `report.html` into `dir`, printing what it holds; an unwritable page is an error.
pub(crate) fn review(verb: &str, dir: &Path) -> anyhow::Result<()> {
    release_free_memory();
    let r = write_review(dir)
        .with_context(|| format!("writing the design review of {}", dir.display()))?;
    for w in &r.warnings {
        eprintln!("[{verb}] report.html: {w}");
    }
    eprintln!(
        "[{verb}] wrote {} ({} design drawings, {} plots)",
        r.path.display(),
        r.drawings,
        r.plots
    );
    Ok(())
}

/// Run `usm-study report`: regenerate `summary.md` and the plots of a sweep directory (one
/// with a case table), then `report.html`. Refused (exit 2) for a folder that is not a
/// finished output (no `manifest.json` or `summary.json`) and while another run holds its
/// lock (the report takes the lock itself).
pub fn run_report(a: &ReportArgs) -> anyhow::Result<ExitCode> {
    if !a.dir.is_dir() {
        bail!("{} is not a directory", a.dir.display());
    }
    let dir = &outdir::resolve(&a.dir).map_err(study_err)?;
    let lock = outdir::lock(
        dir,
        &outdir::LockOwner {
            study: "",
            resume: false,
        },
    )
    .map_err(study_err)?;
    outdir::check_contained(dir).map_err(study_err)?;
    let stale = usm_study::report::remove_dead_temporaries(dir);
    if stale > 0 {
        eprintln!(
            "[report] removed {stale} temporary files of killed runs in {}",
            a.dir.display()
        );
    }
    if !dir.join("manifest.json").is_file() {
        let hint = if dir.join("summary.json").is_file() {
            "it holds a single run's summary.json (a `simulate`, `tcm` or `paper` folder: its \
             figures are already written there); `report` reviews the output of `sweep` or \
             `optimise`"
                .to_string()
        } else {
            format!(
                "no manifest.json; an interrupted sweep is finished with `sweep STUDY --out {} \
                 --resume`",
                a.dir.display()
            )
        };
        bail!("{} is not a study output: {hint}", a.dir.display());
    }
    if let Some([i, n]) = usm_study::batch::manifest::read_manifest(dir)
        .ok()
        .and_then(|m| m.shard)
    {
        bail!(
            "{} is shard {i}/{n} of a sweep: its raw rows are what `merge` reads, and a report \
             here would be of {} shard only; merge the shards (`usm-study merge …`) and report \
             the merged output",
            a.dir.display(),
            if n > 1 { "one" } else { "this" }
        );
    }
    let rerank = Rerank {
        objective: a.objective.clone(),
        pareto: a.pareto.clone(),
    };
    if dir.join(CASES_PARQUET).is_file() || dir.join(PARTIAL_FILE).is_file() {
        let Reported { warnings, notes } = report_ranked(dir, &rerank).map_err(study_err)?;
        for n in &notes {
            eprintln!("[report] {n}");
        }
        for w in &warnings {
            eprintln!("[report] warning: {w}");
        }
        if !warnings.is_empty() {
            bail!(
                "the report in {} is incomplete: {} outputs could not be written",
                a.dir.display(),
                warnings.len()
            );
        }
        outdir::record_owned(dir, lock.created, &outdir::SWEEP_FILES).map_err(study_err)?;
        eprintln!("[report] wrote {}/summary.md and plots/", a.dir.display());
    } else if !rerank.is_empty() {
        bail!(
            "--objective/--pareto: {} has no case table (cases.parquet) to re-rank",
            a.dir.display()
        );
    }
    review("report", dir)?;
    drop(lock);
    if dir.join(CASES_PARQUET).is_file() {
        print_verdict("report", dir);
    }
    Ok(ExitCode::SUCCESS)
}

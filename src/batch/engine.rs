//! The sweep: resolving cases, running them in parallel, streaming rows, resuming and
//! sharding, then the final tables, the manifest and the report.
//!
//! Files in the output directory:
//! - `cases.partial.csv`: the journal, one raw row per finished case, appended and flushed as
//!   cases complete (in completion order; scenario metrics packed in one `scenario_metrics`
//!   column as `name=value;…`). `--resume` reads it (malformed rows are reported with their
//!   line and run again, see [`super::journal`]); at the end it is compacted (sorted by case
//!   id, deduplicated by hash, rows of other study versions dropped). A finished unsharded
//!   sweep removes it (its rows are in `cases.csv`); a shard keeps it as its raw output, which
//!   `merge` reads.
//! - `cases.csv`, `cases.parquet`: the final table, sorted by case id: `case_id`, `hash`, one
//!   column per axis, the metrics, `status` (`ok`, `unsuccessful`, `failed`, `skipped`),
//!   `reason`. No times.
//! - `manifest.json`: provenance, counts, timings, the raw schema and the report settings.
//! - `study.toml`: a copy of the study file.
//! - `.usm-study.lock`: held while the sweep runs ([`super::outdir`]): one run per directory.
//!
//! With `[tune]`, every case is first tuned, then scored at its tuned values
//! ([`super::tuning_hook`]).
//!
//! Every case has a wall-clock budget (`case_timeout`), checked cooperatively inside the
//! simulation loop (see [`super::worker`]): a case past it is recorded `failed` with a reason
//! starting `timeout`, and the batch goes on. Timed-out rows depend on the machine's speed;
//! every other row does not.
//!
//! With `adaptive_worlds` in `[uncertainty]`, the designs in contention then meet further
//! worlds before the final tables are written ([`super::adaptive`]); such a study is not
//! sharded, and `--resume` runs the rounds again from the resumed cases.
//!
//! Determinism: a case's row depends only on the study and the case id (per-case seed
//! `derive_seed(study_seed, case_id)`, no parallel reductions), and rows are sorted by id,
//! so `cases.csv` is bit-identical for any `--jobs` and any sharding.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::bound_hook::{case_bound, BoundHook, CaseBound};
use super::journal;
use super::lock;
use super::manifest::{
    cpu_model, git_commit, git_dirty, now_rfc3339, read_manifest, relative_path, rustc_version,
    write_manifest, AxisInfo, Counts, Manifest,
};
use super::outdir;
use super::records::{
    axis_text, compact, raw_schema, CaseEnd, Row, StatusCounts, HASH, PARTIAL_FILE,
    PARTIAL_STUDY_FILE, STUDY_COPY,
};
use super::report_hook::ReportHook;
use super::robust::{write_tables_with, RobustInfo};
use super::tuning_hook::{case_tuner, CaseTuner, TuningHook};
use super::worker::Worker;
use crate::report::{read_csv_typed, ColumnKind, CsvAppender};
use crate::study::cases::{case_hash, resolve_case};
use crate::study::doe::{case_count, expand, Case};
use crate::study::error::StudyError;
use crate::study::schema::Study;

/// Options of a sweep run.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Worker threads (0: all cores).
    pub jobs: usize,
    /// Skip cases already in the partial file.
    pub resume: bool,
    /// Run only case ids `≡ index (mod count)`: `(index, count)`.
    pub shard: Option<(usize, usize)>,
    /// Output directory (default: the study's, with `shard-I-of-N` appended for shards).
    pub out: Option<PathBuf>,
    /// Stop after running this many cases (testing interruptions; no final outputs).
    pub max_cases: Option<usize>,
    /// Wall-clock budget of one case (`None`: unlimited); a case past it is `failed` with
    /// reason `timeout: …`.
    pub case_timeout: Option<Duration>,
    /// Replace the output of another study in the output directory.
    pub force: bool,
    /// How cases of a study with `[tune]` are tuned (the optimiser's tuner, wired in by the
    /// caller); a study with `[tune]` and no hook is refused.
    pub tuning: Option<TuningHook>,
    /// How cases of a study with `[ocp]` get their design's optimal-control bound (the `ocp`
    /// room's solver, wired in by the caller); a study with `[ocp]` and no hook is refused.
    pub bound: Option<BoundHook>,
    /// How the finished sweep writes `summary.md` and its plots (the review room's report,
    /// wired in by the caller); `None` writes the tables and the manifest only.
    pub report: Option<ReportHook>,
}

/// Progress of a sweep, reported after every finished case.
#[derive(Clone, Copy, Debug)]
pub struct ProgressEvent {
    /// Cases finished, including resumed ones.
    pub finished: usize,
    /// Cases of this run (shard).
    pub total: usize,
    /// Cases actually run.
    pub ran: usize,
    /// Cases taken from a previous run.
    pub resumed: usize,
}

/// The outcome of a sweep.
#[derive(Clone, Debug, Default)]
pub struct SweepOutcome {
    /// Output directory.
    pub out: PathBuf,
    /// Cases of the study.
    pub planned: usize,
    /// Cases of this shard.
    pub in_shard: usize,
    /// Counts by status.
    pub ok: usize,
    /// Cases that ran but missed a success criterion.
    pub unsuccessful: usize,
    /// Failed cases.
    pub failed: usize,
    /// Skipped cases.
    pub skipped: usize,
    /// Cases taken from a previous run.
    pub resumed: usize,
    /// Cases run now.
    pub ran: usize,
    /// Stopped early by `max_cases` (no final outputs written).
    pub interrupted: bool,
    /// Wall time [s].
    pub elapsed_s: f64,
    /// Cases stopped by their time budget (failed, reason `timeout: …`), of those run now.
    pub timeouts: usize,
    /// Problems with the report (plots etc.) and notes on the output directory (malformed
    /// journal rows dropped, `--force` removals, stale temporary files), not fatal.
    pub warnings: Vec<String>,
}

/// The output directory of a sweep.
pub fn output_dir(study: &Study, opts: &SweepOptions) -> PathBuf {
    match (&opts.out, opts.shard) {
        (Some(o), _) => o.clone(),
        (None, Some((i, n))) => study.output.join(format!("shard-{i}-of-{n}")),
        (None, None) => study.output.clone(),
    }
}

enum Msg {
    Resumed(String),
    Row(Box<Row>),
    NotRun,
}

/// Run a sweep: every case of the study (or shard) in parallel, streaming rows to
/// `cases.partial.csv`, then the final tables, the manifest and (unless sharded) the report.
pub fn run_sweep(
    study: &Study,
    opts: &SweepOptions,
    progress: &mut dyn FnMut(&ProgressEvent),
) -> Result<SweepOutcome, StudyError> {
    let t0 = Instant::now();
    let start_time = now_rfc3339();
    if let Some((i, n)) = opts.shard.filter(|&(i, n)| n == 0 || i >= n) {
        return Err(StudyError::Input(format!(
            "--shard {i}/{n}: need 0 <= I < N"
        )));
    }
    super::adaptive::refuse_shards(study, opts.shard)?;
    let tuner = case_tuner(study, opts.tuning)?;
    let bounder = case_bound(study, opts.bound)?;
    let cases = expand(study, opts.shard)?;
    let out = outdir::resolve(&output_dir(study, opts))?;
    let owner = outdir::LockOwner {
        study: &study.hash,
        resume: opts.resume,
    };
    let lock = outdir::lock(&out, &owner)?;
    let claim = outdir::Claim {
        study: &study.name,
        force: opts.force,
        resume: opts.resume,
    };
    let mut notes = outdir::claim(&out, &lock, &claim)?;
    outdir::record_owned(&out, lock.created, &outdir::SWEEP_FILES)?;
    let partial = out.join(PARTIAL_FILE);
    if opts.resume && !partial.exists() {
        if let Some(done) = already_complete(study, opts, &out, cases.len()) {
            return Ok(done);
        }
    }
    let schema = raw_schema(study);
    let (mut appender, done) = open_journal(study, &out, &schema, opts.resume, &mut notes)?;
    let jobs = match opts.jobs {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        j => j,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(StudyError::Pool)?;
    let run = RunSpec {
        study,
        done: &done,
        max: opts.max_cases.unwrap_or(usize::MAX),
        budget: opts.case_timeout,
        tuner: tuner.as_deref(),
        bounder: bounder.as_deref(),
    };
    let streamed = stream_cases(&run, &cases, &pool, &mut appender, progress)?;
    let _ = appender.sync();
    drop(appender);
    let ev = streamed.progress;
    let mut outcome = SweepOutcome {
        out: out.clone(),
        planned: case_count(study),
        in_shard: cases.len(),
        resumed: ev.resumed,
        ran: ev.ran,
        interrupted: streamed.not_run > 0,
        timeouts: streamed.timeouts,
        warnings: notes,
        ..Default::default()
    };
    if outcome.interrupted {
        outcome.set_counts(streamed.counts);
        outcome.elapsed_s = t0.elapsed().as_secs_f64();
        return Ok(outcome);
    }
    let raw = compact(
        &read_csv_typed(&partial, &schema)?,
        Some(&streamed.plan_hashes),
    )?;
    let rounds = super::adaptive::Rounds {
        study,
        cases: &cases,
        tuner: tuner.as_deref(),
        budget: opts.case_timeout,
    };
    let (table, robust) = final_tables(&rounds, raw, &out, &pool)?;
    outcome.set_counts(StatusCounts::of_table(&table)?);
    let elapsed = t0.elapsed().as_secs_f64();
    outcome.elapsed_s = elapsed;
    let mut manifest = sweep_manifest(study, &out, &schema, start_time, elapsed, jobs);
    manifest.robust = robust;
    manifest.case_timeout_s = opts.case_timeout.map(|d| d.as_secs_f64());
    manifest.shard = opts.shard.map(|(i, n)| [i, n]);
    manifest.throughput_cases_per_s = per_second(ev.ran, elapsed);
    manifest.cases = Counts {
        planned: outcome.planned,
        in_output: table.n_rows(),
        resumed: ev.resumed,
        ran: ev.ran,
        ..Default::default()
    }
    .with_status(StatusCounts {
        ok: outcome.ok,
        unsuccessful: outcome.unsuccessful,
        failed: outcome.failed,
        skipped: outcome.skipped,
    });
    write_manifest(&out, &manifest)?;
    if opts.shard.is_none() {
        // Inside the sweep's pool, so the best/worst reruns respect --jobs.
        if let Some(report) = opts.report {
            let w =
                pool.install(|| report.write(&out, &table, &manifest, Some(study), opts.tuning));
            outcome.warnings.extend(w);
        }
        outdir::record_owned(&out, lock.created, &outdir::SWEEP_FILES)?;
        // Last: a kill before this leaves a journal that --resume completes from.
        std::fs::remove_file(&partial).map_err(|e| StudyError::io(&partial, e))?;
    }
    Ok(outcome)
}

/// The final tables of a sweep (`write_tables_with`), the adaptive rounds of a study with
/// `adaptive_worlds` run inside the sweep's pool (`--jobs`) on the way; the table and the
/// record of the worlds for the manifest.
fn final_tables(
    rounds: &super::adaptive::Rounds,
    raw: crate::report::Table,
    out: &Path,
    pool: &rayon::ThreadPool,
) -> Result<(crate::report::Table, Option<RobustInfo>), StudyError> {
    let study = rounds.study;
    let axes: Vec<&str> = study.axes.iter().map(|a| a.name.as_str()).collect();
    pool.install(|| {
        write_tables_with(raw, out, RobustInfo::of(study), &axes, |t, info| {
            super::adaptive::run_rounds(rounds, t, info)
        })
    })
}

/// With `--resume` and no journal: the outcome of an output that is already complete for
/// this study (its manifest has this study's hash and every case of the run), else `None`.
fn already_complete(
    study: &Study,
    opts: &SweepOptions,
    out: &Path,
    in_shard: usize,
) -> Option<SweepOutcome> {
    let m = read_manifest(out).ok()?;
    let complete = m.study_hash == study.hash
        && m.shard == opts.shard.map(|(i, n)| [i, n])
        && m.cases.in_output == in_shard
        && out.join(super::records::CASES_CSV).is_file();
    complete.then(|| SweepOutcome {
        out: out.to_path_buf(),
        planned: m.cases.planned,
        in_shard,
        ok: m.cases.ok,
        failed: m.cases.failed,
        skipped: m.cases.skipped,
        resumed: m.cases.in_output,
        warnings: vec![format!("{} is already complete", out.display())],
        ..Default::default()
    })
}

impl SweepOutcome {
    fn set_counts(&mut self, c: StatusCounts) {
        self.ok = c.ok;
        self.unsuccessful = c.unsuccessful;
        self.failed = c.failed;
        self.skipped = c.skipped;
    }
}

/// The study's copy and its journal in `out`: the copy written (atomic and link-safe, issue
/// 39), the journal resumed (`resume`) only when this study and build wrote it (issue 39 item 4)
/// and repaired, else created; its record of the study written. The appender and the hashes of
/// the cases it already holds.
fn open_journal(
    study: &Study,
    out: &Path,
    schema: &[(String, ColumnKind)],
    resume: bool,
    notes: &mut crate::study::error::Notes,
) -> Result<(CsvAppender, DoneHashes), StudyError> {
    crate::report::atomic_write(&out.join(STUDY_COPY), study.text.as_bytes())?;
    let partial = out.join(PARTIAL_FILE);
    let resume = resume && journal_of_this_study(out, &partial, study, notes);
    if resume {
        notes.extend(journal::repair(&partial, schema)?);
    }
    let opened = open_partial(&partial, schema, resume)?;
    crate::report::atomic_write(&out.join(PARTIAL_STUDY_FILE), study.hash.as_bytes())?;
    Ok(opened)
}

/// Whether the journal in `out` was written by this study and build: its record
/// ([`PARTIAL_STUDY_FILE`]) holds this study's hash, which includes the build identity. A
/// journal of another study text or another build is not resumed (a model fix would otherwise
/// mix with old results): a note says so and the cases run afresh. A journal without a record
/// (written before the record existed) is resumed with a note saying it could not be checked.
fn journal_of_this_study(
    out: &Path,
    partial: &Path,
    study: &Study,
    notes: &mut crate::study::error::Notes,
) -> bool {
    if !partial.is_file() {
        return true;
    }
    match std::fs::read_to_string(out.join(PARTIAL_STUDY_FILE)) {
        Ok(h) if h.trim() == study.hash => true,
        Ok(_) => {
            notes.push(format!(
                "{} was written by another study text or another build of usm-study (build {} \
                 now): not resumed; every case runs afresh",
                partial.display(),
                &crate::study::hash::BUILD_ID[..12]
            ));
            false
        }
        Err(_) => {
            notes.push(format!(
                "{} has no record of the study and build that wrote it ({PARTIAL_STUDY_FILE}, \
                 written since issue 39): resumed without that check",
                partial.display()
            ));
            true
        }
    }
}

/// The partial file, created (or, with `resume`, opened) with the raw schema, and the hashes
/// of the cases already in it.
/// The hashes of the cases a journal already holds (skipped on `--resume`).
type DoneHashes = HashSet<String>;

fn open_partial(
    partial: &Path,
    schema: &[(String, ColumnKind)],
    resume: bool,
) -> Result<(CsvAppender, DoneHashes), StudyError> {
    let mut done: HashSet<String> = HashSet::new();
    if !resume {
        return Ok((CsvAppender::create(partial, schema)?, done));
    }
    let app = CsvAppender::open_or_create(partial, schema).map_err(|e| {
        StudyError::Input(format!(
            "cannot resume from {}: {e} (the study's axes or mode changed? run without --resume or use another --out)",
            partial.display()
        ))
    })?;
    if app.rows_written() > 0 {
        let t = read_csv_typed(partial, schema)?;
        done.extend(t.str(HASH)?.iter().cloned());
    }
    Ok((app, done))
}

/// What streaming the cases produced.
struct Streamed {
    progress: ProgressEvent,
    /// Hashes of the cases of this run's plan (resumed or run).
    plan_hashes: HashSet<String>,
    /// Cases not run (cancelled or beyond `max_cases`).
    not_run: usize,
    /// Status counts of the cases run now.
    counts: StatusCounts,
    /// Cases run now that ran out of time.
    timeouts: usize,
}

/// What every case of one run shares: the study, the hashes already done, the cap on cases
/// run (`max_cases`), the per-case time budget and the per-case tuning (`[tune]`).
struct RunSpec<'a> {
    study: &'a Study,
    done: &'a HashSet<String>,
    max: usize,
    budget: Option<Duration>,
    tuner: Option<&'a dyn CaseTuner>,
    bounder: Option<&'a dyn CaseBound>,
}

/// Run `cases` on `pool` (skipping hashes in `done`, at most `max` runs, each within the
/// budget), appending each row to the partial file as it arrives and reporting progress after
/// each.
fn stream_cases(
    run: &RunSpec,
    cases: &[Case],
    pool: &rayon::ThreadPool,
    appender: &mut CsvAppender,
    progress: &mut dyn FnMut(&ProgressEvent),
) -> Result<Streamed, StudyError> {
    let cancel = AtomicBool::new(false);
    let started = AtomicUsize::new(0);
    let mut st = Streamed {
        progress: ProgressEvent {
            finished: 0,
            total: cases.len(),
            ran: 0,
            resumed: 0,
        },
        plan_hashes: HashSet::with_capacity(cases.len()),
        not_run: 0,
        counts: StatusCounts::default(),
        timeouts: 0,
    };
    let mut write_error: Option<StudyError> = None;
    std::thread::scope(|s| {
        let (tx, rx) = mpsc::channel::<Msg>();
        let (cancel, started) = (&cancel, &started);
        s.spawn(move || {
            // A closed-loop case takes seconds and cases differ several-fold (links,
            // tuning): one case per stealable job, else rayon runs a block of neighbouring
            // cases on one thread while the other idles (the thrusters study's last 38 s ran on
            // one core). Static cases take a fraction of a millisecond: default splitting
            // keeps a worker's design cache across neighbours.
            let max_len = if run.study.mode.is_dynamic() {
                1
            } else {
                usize::MAX
            };
            pool.install(|| {
                cases.par_iter().with_max_len(max_len).for_each_init(
                    || (tx.clone(), Worker::with_budget(run.budget)),
                    |(tx, w), case| {
                        let msg = process(run, case, w, cancel, started);
                        let _ = tx.send(msg);
                    },
                );
            });
            drop(tx);
        });
        // A SIGTERM/SIGINT is acted on between rows: the journal is synced, then the lock
        // released (see `super::lock`).
        lock::set_graceful(true);
        loop {
            let msg = match rx.recv_timeout(Duration::from_millis(100)) {
                Ok(m) => m,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if let Some(sig) = lock::pending_signal() {
                        let _ = appender.sync();
                        lock::exit_interrupted(sig);
                    }
                    continue;
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            };
            if let Some(sig) = lock::pending_signal() {
                let _ = appender.sync();
                lock::exit_interrupted(sig);
            }
            match msg {
                Msg::Resumed(h) => {
                    st.plan_hashes.insert(h);
                    st.progress.resumed += 1;
                }
                Msg::Row(row) => {
                    st.plan_hashes.insert(row.hash.clone());
                    st.progress.ran += 1;
                    st.counts.add(row.end.status());
                    if row.end.timed_out() {
                        st.timeouts += 1;
                    }
                    if write_error.is_none() {
                        let texts: Vec<String> = row.axes.iter().map(axis_text).collect();
                        let packed = row.packed(run.study);
                        if let Err(e) = appender.append(&row.values(run.study, &texts, &packed)) {
                            write_error = Some(e.into());
                            cancel.store(true, Ordering::Relaxed);
                        }
                    }
                }
                Msg::NotRun => {
                    st.not_run += 1;
                    continue;
                }
            }
            st.progress.finished = st.progress.ran + st.progress.resumed;
            progress(&st.progress);
        }
        lock::set_graceful(false);
    });
    match write_error {
        Some(e) => Err(e),
        None => Ok(st),
    }
}

fn process(
    run: &RunSpec,
    case: &Case,
    w: &mut Worker,
    cancel: &AtomicBool,
    started: &AtomicUsize,
) -> Msg {
    if cancel.load(Ordering::Relaxed) {
        return Msg::NotRun;
    }
    let study = run.study;
    let resolved = resolve_case(study, case);
    let hash = case_hash(study, case, &resolved);
    if run.done.contains(&hash) {
        return Msg::Resumed(hash);
    }
    if started.fetch_add(1, Ordering::Relaxed) >= run.max {
        return Msg::NotRun;
    }
    let row = match resolved {
        Ok(r) => w.evaluate(study, case, &r, run.tuner, run.bounder),
        Err(reason) => {
            let mut row = Row::new(case.id, hash, case.values.clone());
            row.end(CaseEnd::Skipped, &reason.to_string());
            row
        }
    };
    Msg::Row(Box::new(row))
}

/// The manifest of a finished sweep, without its shard, throughput and counts.
fn sweep_manifest(
    study: &Study,
    out: &Path,
    schema: &[(String, ColumnKind)],
    start_time: String,
    elapsed: f64,
    jobs: usize,
) -> Manifest {
    Manifest {
        tool: "usm-study".into(),
        tool_version: env!("CARGO_PKG_VERSION").into(),
        build_id: Some(crate::study::hash::BUILD_ID.into()),
        git_commit: git_commit(),
        git_dirty: git_dirty(),
        rustc: rustc_version(),
        cpu: cpu_model(),
        study_name: study.name.clone(),
        description: study.description.clone(),
        study_file: relative_path(&study.path, out),
        study_hash: study.hash.clone(),
        seed: study.seed,
        mode: study.mode,
        static_analysis: study.static_enabled,
        doe: study.doe.kind(),
        start_time,
        end_time: now_rfc3339(),
        elapsed_s: elapsed,
        throughput_cases_per_s: 0.0,
        jobs,
        shard: None,
        merged_from: Vec::new(),
        cases: Counts::default(),
        columns: Manifest::columns_of(schema),
        axes: study
            .axes
            .iter()
            .map(|a| AxisInfo {
                name: a.name.clone(),
                numeric: a.numeric,
            })
            .collect(),
        report: study.report.clone(),
        robust: RobustInfo::of(study),
        case_timeout_s: None,
        ledger: super::robust::study_ledger(study),
    }
}

/// `n` events in `elapsed` seconds, per second (0 for no elapsed time).
fn per_second(n: usize, elapsed: f64) -> f64 {
    if elapsed > 0.0 {
        n as f64 / elapsed
    } else {
        0.0
    }
}

//! Kill/resume soak: a sweep SIGKILLed at random points (while running cases, while writing
//! the final tables, the manifest and the report, while resuming) and resumed until it
//! completes must end with the same bytes as an uninterrupted run, leaving no journal, lock
//! or temporary file behind. The same with SIGTERM (the lock released by the run itself), and
//! with a SIGKILLed run "requeued on another host": its lock rewritten with another host name
//! and a Slurm job id, and resumed with that `SLURM_JOB_ID` and `SLURM_RESTART_COUNT=1`.
//!
//! CI runs `SOAK_KILLS` = 5 kills (the default). The long run, documented in
//! `docs/reliability.md`:
//!
//! ```text
//! SOAK_KILLS=50 cargo test --release --test reliability_soak -- --nocapture
//! ```
//!
//! Kill times are drawn (seeded by `SOAK_SEED`) from `[0, 1.2 × T]`, with `T` the wall time
//! of the uninterrupted run, measured first; nothing is asserted about times.

mod common;

use common::{read, usm_study, write};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use std::time::{Duration, Instant};

/// 24 static cases of a few milliseconds each: long enough to be killed mid-run.
const STUDY: &str = r#"
[study]
name = "soak"
seed = 5

[design.generator]
links = 5

[static]
samples = 600
sampling = "sobol"

[[axis]]
name = "design.links"
values = [4, 5, 6, 7]

[[axis]]
name = "design.thruster_rule"
values = ["paper", "distributed"]

[[axis]]
name = "design.generator.longitudinal_offset"
range = { start = 0.1, stop = 0.3, steps = 3 }
"#;

fn env_u64(key: &str, default: u64) -> u64 {
    std::env::var(key)
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(default)
}

/// How a run of [`sweep_killed_after`] ended.
#[derive(Debug, PartialEq)]
enum End {
    /// Exited by itself with this code.
    Exited(i32),
    /// Killed while running cases.
    Killed,
    /// Killed during the final writes (the final table already written, the journal not yet
    /// removed).
    KilledFinishing,
}

/// How a run is stopped, and the environment of the next.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stop {
    /// SIGKILL.
    Kill,
    /// SIGTERM: the run releases its lock itself (exit 143).
    Term,
    /// SIGKILL, then the lock moved to another host as a requeued Slurm job would find it.
    Requeue,
}

/// The Slurm job id of the requeue rounds.
const JOB: &str = "777";

/// Start a sweep of `study` into `out` (with `--resume` when asked); kill it after `after`
/// unless it ended first.
fn sweep_killed_after(study: &Path, out: &Path, resume: bool, after: Duration) -> End {
    sweep_stopped_after(study, out, resume, after, Stop::Kill)
}

/// [`sweep_killed_after`] with the given way of stopping (and, for `Requeue`, the Slurm
/// environment of a requeued job).
fn sweep_stopped_after(study: &Path, out: &Path, resume: bool, after: Duration, stop: Stop) -> End {
    let mut cmd = usm_study();
    cmd.args([
        "sweep",
        study.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    cmd.args(["--jobs", "2"]);
    if resume {
        cmd.arg("--resume");
    }
    if stop == Stop::Requeue {
        cmd.env("SLURM_JOB_ID", JOB).env("SLURM_RESTART_COUNT", "1");
    }
    cmd.stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    let mut child = cmd.spawn().expect("spawn usm-study");
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return End::Exited(status.code().unwrap_or(-1));
        }
        if start.elapsed() >= after {
            if stop == Stop::Term {
                // SAFETY: signalling our own child process.
                unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
                let status = child.wait().unwrap();
                match status.code() {
                    Some(0) => return End::Exited(0), // finished before the signal landed
                    Some(code) => {
                        assert_eq!(code, 143, "SIGTERM: exit 128 + 15");
                        assert!(!out.join(".usm-study.lock").exists(), "lock released");
                    }
                    // Before the handler was installed (the lock not yet held): the default
                    // action, like a kill.
                    None => {}
                }
            } else {
                child.kill().unwrap(); // SIGKILL
                child.wait().unwrap();
                let lock = out.join(".usm-study.lock");
                if stop == Stop::Requeue && lock.exists() {
                    // The node died: the lock names another host and this Slurm job.
                    let text = std::fs::read_to_string(&lock).unwrap();
                    let moved: String = text
                        .lines()
                        .filter(|l| !l.starts_with("host=") && !l.starts_with("slurm_job="))
                        .map(|l| format!("{l}\n"))
                        .collect();
                    std::fs::write(&lock, format!("{moved}host=dead-node\nslurm_job={JOB}\n"))
                        .unwrap();
                }
            }
            let finishing =
                out.join("cases.csv").exists() && out.join("cases.partial.csv").exists();
            return if finishing {
                End::KilledFinishing
            } else {
                End::Killed
            };
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Files left in `dir` that a finished run must not leave: the journal, the lock, temporaries.
fn leftovers(dir: &Path) -> Vec<String> {
    let mut v = Vec::new();
    for d in [dir.to_path_buf(), dir.join("plots")] {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let n = e.file_name().to_string_lossy().to_string();
            if n == "cases.partial.csv" || (n.starts_with('.') && n != ".usm-study.files") {
                v.push(n);
            }
        }
    }
    v
}

#[test]
fn killed_sweeps_resume_to_the_uninterrupted_bytes() {
    let kills_wanted = env_u64("SOAK_KILLS", 5);
    let mut rng = ChaCha8Rng::seed_from_u64(env_u64("SOAK_SEED", 15));
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "soak.toml", STUDY);
    let full = d.path().join("full");
    let t0 = Instant::now();
    let end = sweep_killed_after(&s, &full, false, Duration::from_secs(3600));
    let t_full = t0.elapsed();
    assert_eq!(end, End::Exited(0));
    let want_csv = read(&full.join("cases.csv"));
    let want_pq = read(&full.join("cases.parquet"));
    assert!(leftovers(&full).is_empty(), "{:?}", leftovers(&full));
    let (mut kills, mut finishing, mut rounds) = (0u64, 0u64, 0u64);
    while kills < kills_wanted {
        rounds += 1;
        let out = d.path().join(format!("r{rounds}"));
        let mut resume = false;
        // Rounds alternate SIGKILL, SIGTERM and a requeue on another host.
        let stop = [Stop::Kill, Stop::Term, Stop::Requeue][(rounds % 3) as usize];
        // Kill, resume, kill again … until a run completes (at most 4 kills per round).
        for attempt in 0.. {
            let after = if attempt < 4 {
                t_full.mul_f64(rng.random_range(0.0..1.2))
            } else {
                Duration::from_secs(3600)
            };
            match sweep_stopped_after(&s, &out, resume, after, stop) {
                End::Exited(code) => {
                    assert_eq!(code, 0, "round {rounds}, attempt {attempt}");
                    break;
                }
                End::Killed => {}
                End::KilledFinishing => finishing += 1,
            }
            kills += 1;
            resume = true;
        }
        assert_eq!(read(&out.join("cases.csv")), want_csv, "round {rounds}");
        assert_eq!(read(&out.join("cases.parquet")), want_pq, "round {rounds}");
        assert!(
            leftovers(&out).is_empty(),
            "round {rounds}: {:?}",
            leftovers(&out)
        );
        std::fs::remove_dir_all(&out).unwrap();
    }
    eprintln!(
        "[soak] {kills} kills ({finishing} during the final writes) in {rounds} rounds; \
         uninterrupted run {:.2} s; every round ended byte-identical",
        t_full.as_secs_f64()
    );
}

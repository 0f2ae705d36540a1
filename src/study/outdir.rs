//! Ownership of an output directory: one run at a time, one study per directory, nothing
//! temporary left behind.
//!
//! - [`OutputLock`]: `.usm-study.lock` holds the pid, host and start time of the run writing
//!   the directory; a second run exits with code 2 naming the holder. A lock whose pid is dead
//!   on this host (a killed run) is stale and is replaced. The lock is removed when the run
//!   ends (dropped), also on errors.
//! - [`claim`]: a directory holding another study's output (its `study.toml` names another
//!   study) is refused unless `force`, which first removes that study's tables, manifest,
//!   journal, summary, trajectories and plots (only files this tool writes; nothing else).
//!   Temporary files of killed runs (`.NAME.tmp-PID`, see `report::atomic_write`) are removed
//!   and reported.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::error::StudyError;
use super::manifest::{now_rfc3339, MANIFEST_FILE};
use super::records::{CASES_CSV, CASES_PARQUET, PARTIAL_FILE, STUDY_COPY};

/// The lock file's name in an output directory.
pub const LOCK_FILE: &str = ".usm-study.lock";

/// Files of a sweep output (besides `plots/`), removed by `--force` for another study.
const OUTPUT_FILES: [&str; 8] = [
    CASES_CSV,
    CASES_PARQUET,
    PARTIAL_FILE,
    MANIFEST_FILE,
    STUDY_COPY,
    "summary.md",
    "trajectory_best.csv",
    "trajectory_worst.csv",
];

/// The held lock of an output directory; removed on drop.
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Who holds a lock, as written in the lock file (`pid=…`, `host=…`, `since=…` lines).
#[derive(Clone, Debug, Default, PartialEq)]
struct Holder {
    pid: Option<u32>,
    host: String,
    since: String,
}

impl Holder {
    fn parse(text: &str) -> Holder {
        let mut h = Holder::default();
        for line in text.lines() {
            match line.split_once('=') {
                Some(("pid", v)) => h.pid = v.trim().parse().ok(),
                Some(("host", v)) => h.host = v.trim().to_string(),
                Some(("since", v)) => h.since = v.trim().to_string(),
                _ => {}
            }
        }
        h
    }

    /// Whether the holder is certainly gone: same host, and no process with its pid. A lock
    /// without a readable pid (cut off while being written) is stale too.
    fn is_stale(&self) -> bool {
        match self.pid {
            None => true,
            Some(pid) => self.host == host_name() && !process_alive(pid),
        }
    }
}

/// This machine's host name (`/proc/sys/kernel/hostname`, else `$HOSTNAME`, else `?`).
pub fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_else(|| "?".into())
}

/// Whether a process `pid` exists on this host (signal 0; a process of another user counts).
fn process_alive(pid: u32) -> bool {
    #[cfg(unix)]
    {
        let Ok(p) = libc::pid_t::try_from(pid) else {
            return false;
        };
        // SAFETY: signal 0 only checks that `p` exists and may be signalled; nothing is sent.
        let r = unsafe { libc::kill(p, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        let _ = pid;
        true
    }
}

/// Take the lock of `dir` (created if missing) for this process. Another live holder is an
/// input error (exit code 2) naming its pid, host and start; a stale lock is replaced.
pub fn lock(dir: &Path) -> Result<OutputLock, StudyError> {
    std::fs::create_dir_all(dir).map_err(|e| StudyError::io(dir, e))?;
    let path = dir.join(LOCK_FILE);
    // Two attempts: the second after removing a stale lock.
    for _ in 0..2 {
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(mut f) => {
                let text = format!(
                    "pid={}\nhost={}\nsince={}\n",
                    std::process::id(),
                    host_name(),
                    now_rfc3339()
                );
                f.write_all(text.as_bytes())
                    .and_then(|()| f.sync_all())
                    .map_err(|e| StudyError::io(&path, e))?;
                return Ok(OutputLock { path });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let holder = Holder::parse(&std::fs::read_to_string(&path).unwrap_or_default());
                if !holder.is_stale() {
                    return Err(StudyError::Input(format!(
                        "{} is in use by another run (pid {}, host {}, since {}; lock file {}): \
                         wait for it to finish, use another --out, or remove the lock file if \
                         that run is gone",
                        dir.display(),
                        holder.pid.map_or("?".into(), |p| p.to_string()),
                        holder.host,
                        holder.since,
                        path.display()
                    )));
                }
                std::fs::remove_file(&path).map_err(|e| StudyError::io(&path, e))?;
            }
            Err(e) => return Err(StudyError::io(&path, e)),
        }
    }
    Err(StudyError::Input(format!(
        "{}: could not take the lock (another run keeps replacing it)",
        path.display()
    )))
}

/// The study name recorded in an output directory (its `study.toml` copy), if any.
fn recorded_study(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join(STUDY_COPY)).ok()?;
    let t: toml::Table = text.parse().ok()?;
    t.get("study")?.get("name")?.as_str().map(str::to_string)
}

/// Make `dir` (locked by the caller) ready for study `name`: refuse another study's output
/// unless `force` (which then removes that output's files), and remove temporary files left
/// by killed runs. Returns notes for the user.
pub fn claim(dir: &Path, name: &str, force: bool) -> Result<Vec<String>, StudyError> {
    let mut notes = Vec::new();
    let other = recorded_study(dir)
        .filter(|n| n != name)
        .or_else(|| (!dir.join(STUDY_COPY).exists() && has_output(dir)).then(|| "?".into()));
    if let Some(other) = other {
        if !force {
            return Err(StudyError::Input(format!(
                "{} holds the output of another study ({other}); use another --out, or --force \
                 to replace it",
                dir.display()
            )));
        }
        let removed = remove_output(dir)?;
        notes.push(format!(
            "--force: removed {removed} files of study {other} from {}",
            dir.display()
        ));
    }
    let stale = remove_temporaries(dir)? + remove_temporaries(&dir.join("plots"))?;
    if stale > 0 {
        notes.push(format!(
            "removed {stale} temporary files left by an interrupted run in {}",
            dir.display()
        ));
    }
    Ok(notes)
}

/// Whether `dir` holds any file of a sweep output.
fn has_output(dir: &Path) -> bool {
    OUTPUT_FILES.iter().any(|f| dir.join(f).exists())
}

/// Remove the files of a sweep output (and the SVGs of `plots/`); their count.
fn remove_output(dir: &Path) -> Result<usize, StudyError> {
    let mut n = 0;
    for f in OUTPUT_FILES {
        let p = dir.join(f);
        if p.is_file() {
            std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
            n += 1;
        }
    }
    let plots = dir.join("plots");
    if let Ok(entries) = std::fs::read_dir(&plots) {
        for e in entries.flatten() {
            let p = e.path();
            if p.extension().is_some_and(|x| x == "svg") && p.is_file() {
                std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
                n += 1;
            }
        }
    }
    Ok(n)
}

/// Remove the temporary files of `report::atomic_write` (`.NAME.tmp-PID`) in `dir` (under
/// the directory's lock they belong to dead runs); their count.
fn remove_temporaries(dir: &Path) -> Result<usize, StudyError> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(0);
    };
    let mut n = 0;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let is_tmp = name.starts_with('.')
            && name
                .rsplit_once(".tmp-")
                .is_some_and(|(_, pid)| !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()));
        if is_tmp && e.path().is_file() {
            std::fs::remove_file(e.path()).map_err(|err| StudyError::io(&e.path(), err))?;
            n += 1;
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_names_the_holder_and_a_dead_holder_is_replaced() {
        let d = tempfile::tempdir().unwrap();
        let held = lock(d.path()).unwrap();
        let e = lock(d.path()).unwrap_err().to_string();
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        assert!(e.contains("in use by another run"), "{e}");
        drop(held);
        assert!(!d.path().join(LOCK_FILE).exists());
        // A lock of a pid that cannot exist (above the kernel's pid_max) is stale.
        let text = format!("pid=4194305\nhost={}\nsince=x\n", host_name());
        std::fs::write(d.path().join(LOCK_FILE), text).unwrap();
        let held = lock(d.path()).unwrap();
        drop(held);
        // Another host's lock is never judged stale from here.
        std::fs::write(d.path().join(LOCK_FILE), "pid=4194305\nhost=elsewhere\n").unwrap();
        assert!(lock(d.path()).is_err());
    }

    #[test]
    fn another_studys_output_needs_force_and_is_then_removed() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path();
        std::fs::write(p.join(STUDY_COPY), "[study]\nname = \"a\"\n").unwrap();
        std::fs::write(p.join(CASES_CSV), "x\n").unwrap();
        std::fs::create_dir(p.join("plots")).unwrap();
        std::fs::write(p.join("plots/axis_x.svg"), "<svg/>").unwrap();
        std::fs::write(p.join("plots/.axis_y.svg.tmp-12"), "").unwrap();
        std::fs::write(p.join("notes.txt"), "mine").unwrap();
        assert!(claim(p, "a", false).unwrap().len() == 1); // the temporary file
        std::fs::write(p.join("plots/.axis_y.svg.tmp-12"), "").unwrap();
        let e = claim(p, "b", false).unwrap_err().to_string();
        assert!(
            e.contains("another study (a)") && e.contains("--force"),
            "{e}"
        );
        let notes = claim(p, "b", true).unwrap();
        assert!(notes[0].contains("removed 3 files of study a"), "{notes:?}");
        assert!(!p.join(CASES_CSV).exists() && !p.join("plots/axis_x.svg").exists());
        assert!(!p.join("plots/.axis_y.svg.tmp-12").exists());
        assert!(
            p.join("notes.txt").exists(),
            "files the tool did not write stay"
        );
    }
}

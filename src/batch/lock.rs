//! The lock of an output directory (`.usm-study.lock`): one run at a time per directory, safe
//! on a cluster.
//!
//! - The lock file holds the pid, host, start time, run token (see
//!   [`crate::report::run_token`]), the study and the Slurm job id of the run writing the
//!   directory. A second run exits with code 2 naming the holder.
//! - A lock whose pid is dead on this host (a killed run) is stale and is replaced; the
//!   temporaries of that run (named with its token) are then removed by
//!   [`super::outdir::claim`].
//! - A held lock is touched every [`HEARTBEAT`]. With `--resume` and the same study, a lock of
//!   another host is taken over when it has not been touched for [`TAKEOVER_AGE`] (its run is
//!   gone), or at once when `SLURM_JOB_ID` is the holder's and the job was requeued
//!   (`SLURM_RESTART_COUNT` ≥ 1, or another node).
//! - SIGTERM and SIGINT: the lock is removed and the process exits with `128 + signal`,
//!   printing how to resume. A sweep streaming its journal asks for a graceful stop
//!   ([`set_graceful`]): the signal is then only recorded, the sweep flushes its journal and
//!   calls [`exit_interrupted`]. A second signal exits at once.

use std::ffi::CString;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicPtr, Ordering};
use std::sync::mpsc;
use std::time::{Duration, SystemTime};

use super::manifest::now_rfc3339;
use crate::report::process_alive;
use crate::study::error::StudyError;

/// The lock file's name in an output directory.
pub const LOCK_FILE: &str = ".usm-study.lock";

/// What a run stopped by SIGTERM/SIGINT renames its lock file to (releasing the lock): the
/// next run reads the stopped run's token from it, removes that run's temporaries and this
/// file ([`super::outdir::claim`]).
pub const RELEASED_FILE: &str = ".usm-study.lock.released";

/// How often a held lock file is touched (its modification time is the holder's heartbeat).
pub const HEARTBEAT: Duration = Duration::from_secs(60);

/// A lock of another host untouched for this long belongs to a run that is gone: `--resume`
/// of the same study takes it over.
pub const TAKEOVER_AGE: Duration = Duration::from_secs(10 * 60);

/// Who asks for the lock of an output directory.
#[derive(Clone, Copy, Debug)]
pub struct LockOwner<'a> {
    /// The study (or problem) writing the directory, as recorded in the lock: its hash.
    pub study: &'a str,
    /// The run resumes (`--resume`): it may take over the lock of a run that is gone.
    pub resume: bool,
}

/// Who holds a lock, as written in the lock file (`key=value` lines).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Holder {
    /// Process id.
    pub pid: Option<u32>,
    /// Host name.
    pub host: String,
    /// Start time (RFC 3339).
    pub since: String,
    /// The run's token (names its temporary files); empty for locks of older versions.
    pub token: String,
    /// The study hash of the run; empty for locks of older versions.
    pub study: String,
    /// `SLURM_JOB_ID` of the run, if any.
    pub slurm_job: String,
}

impl Holder {
    fn parse(text: &str) -> Holder {
        let mut h = Holder::default();
        for line in text.lines() {
            let Some((k, v)) = line.split_once('=') else {
                continue;
            };
            let v = v.trim().to_string();
            match k {
                "pid" => h.pid = v.parse().ok(),
                "host" => h.host = v,
                "since" => h.since = v,
                "token" => h.token = v,
                "study" => h.study = v,
                "slurm_job" => h.slurm_job = v,
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

    /// The suffix of the temporary files of the holder's run (`.NAME.tmp-SUFFIX`).
    pub fn temporary_suffix(&self) -> Option<String> {
        if !self.token.is_empty() {
            Some(self.token.clone())
        } else {
            self.pid.map(|p| p.to_string())
        }
    }
}

/// The held lock of an output directory; removed on drop (also on SIGTERM/SIGINT).
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
    /// The holder whose stale or abandoned lock this one replaced.
    pub replaced: Option<Holder>,
    /// Why the lock of another run was taken over (for the user), if it was.
    pub takeover: Option<String>,
    /// Modification time of the fresh lock file (the file system's clock): files of the
    /// directory modified since were written by this run.
    pub created: SystemTime,
    heartbeat: Option<mpsc::Sender<()>>,
    slot: Option<usize>,
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        if let Some(i) = self.slot {
            SLOTS[i].store(std::ptr::null_mut(), Ordering::SeqCst);
        }
        drop(self.heartbeat.take());
        let _ = std::fs::remove_file(&self.path);
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

fn env_nonempty(k: &str) -> Option<String> {
    std::env::var(k).ok().filter(|v| !v.trim().is_empty())
}

/// Why `owner` may take over the live-looking lock of `holder` (whose file was last touched
/// `age` ago), if it may: only with `--resume` of the same study, after a Slurm requeue of the
/// same job or when the holder's heartbeat stopped for [`TAKEOVER_AGE`].
fn takeover_reason(holder: &Holder, age: Option<Duration>, owner: &LockOwner) -> Option<String> {
    if !owner.resume || holder.study.is_empty() || holder.study != owner.study {
        return None;
    }
    let job = env_nonempty("SLURM_JOB_ID");
    let restarts: u64 = env_nonempty("SLURM_RESTART_COUNT")
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(0);
    if let Some(job) = job.filter(|j| *j == holder.slurm_job) {
        if restarts >= 1 || holder.host != host_name() {
            return Some(format!(
                "took over the lock of Slurm job {job} (requeued: restart count {restarts}, \
                 previous host {})",
                holder.host
            ));
        }
    }
    match age {
        Some(a) if a >= TAKEOVER_AGE => Some(format!(
            "took over the lock of pid {} on host {} (not touched for {} s, more than {} s)",
            holder.pid.map_or("?".into(), |p| p.to_string()),
            holder.host,
            a.as_secs(),
            TAKEOVER_AGE.as_secs()
        )),
        _ => None,
    }
}

/// Take the lock of `dir` (which must exist) for this process. Another live holder is an input
/// error (exit code 2) naming its pid, host and start; a stale lock is replaced, an abandoned
/// one taken over (see the module documentation).
pub fn lock(dir: &Path, owner: &LockOwner) -> Result<OutputLock, StudyError> {
    let path = dir.join(LOCK_FILE);
    let mut replaced = None;
    let mut takeover = None;
    // Two attempts: the second after removing a stale or abandoned lock.
    for _ in 0..2 {
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&path)
        {
            Ok(mut f) => {
                let mut text = format!(
                    "pid={}\nhost={}\nsince={}\ntoken={}\nstudy={}\n",
                    std::process::id(),
                    host_name(),
                    now_rfc3339(),
                    crate::report::run_token(),
                    owner.study
                );
                if let Some(job) = env_nonempty("SLURM_JOB_ID") {
                    text.push_str(&format!("slurm_job={}\n", job.trim()));
                }
                f.write_all(text.as_bytes())
                    .and_then(|()| f.sync_all())
                    .map_err(|e| StudyError::io(&path, e))?;
                if replaced.is_none() {
                    // A run stopped by a signal: its temporaries are removed by `claim`.
                    replaced = std::fs::read_to_string(dir.join(RELEASED_FILE))
                        .ok()
                        .map(|t| Holder::parse(&t));
                }
                let created = f
                    .metadata()
                    .and_then(|m| m.modified())
                    .unwrap_or_else(|_| SystemTime::now());
                return Ok(OutputLock {
                    slot: register(&path, dir),
                    heartbeat: Some(heartbeat(f)),
                    path,
                    replaced,
                    takeover,
                    created,
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                let holder = Holder::parse(&std::fs::read_to_string(&path).unwrap_or_default());
                let age = std::fs::metadata(&path)
                    .and_then(|m| m.modified())
                    .ok()
                    .and_then(|t| SystemTime::now().duration_since(t).ok());
                if !holder.is_stale() {
                    takeover = takeover_reason(&holder, age, owner);
                    if takeover.is_none() {
                        return Err(in_use(dir, &path, &holder));
                    }
                }
                std::fs::remove_file(&path).map_err(|e| StudyError::io(&path, e))?;
                replaced = Some(holder);
            }
            Err(e) => return Err(StudyError::io(&path, e)),
        }
    }
    Err(StudyError::Input(format!(
        "{}: could not take the lock (another run keeps replacing it)",
        path.display()
    )))
}

fn in_use(dir: &Path, path: &Path, holder: &Holder) -> StudyError {
    StudyError::Input(format!(
        "{} is in use by another run (pid {}, host {}, since {}; lock file {}): wait for it to \
         finish or use another --out; if that run is gone, --resume takes the lock over once it \
         has not been touched for {} minutes (at once for a requeued Slurm job), or remove the \
         lock file",
        dir.display(),
        holder.pid.map_or("?".into(), |p| p.to_string()),
        holder.host,
        holder.since,
        path.display(),
        TAKEOVER_AGE.as_secs() / 60
    ))
}

/// Touch the lock file every [`HEARTBEAT`] until the returned sender is dropped.
fn heartbeat(file: std::fs::File) -> mpsc::Sender<()> {
    let (tx, rx) = mpsc::channel::<()>();
    std::thread::spawn(move || {
        while let Err(mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(HEARTBEAT) {
            let _ = file.set_modified(SystemTime::now());
        }
    });
    tx
}

// ---- SIGTERM / SIGINT ----------------------------------------------------------------------

/// A held lock as the signal handler sees it: the lock file's path and the message to print.
struct Slot {
    path: CString,
    released: CString,
    message: Vec<u8>,
}

/// The held locks (at most a few per process); leaked, so the handler never sees freed memory.
static SLOTS: [AtomicPtr<Slot>; 8] = [const { AtomicPtr::new(std::ptr::null_mut()) }; 8];
/// The signal received, 0 for none.
static SIGNAL: AtomicI32 = AtomicI32::new(0);
/// A sweep stops by itself on a signal (after flushing its journal).
static GRACEFUL: AtomicBool = AtomicBool::new(false);
static INSTALLED: std::sync::Once = std::sync::Once::new();

/// Record a held lock for the signal handler (installing it on first use); its slot.
fn register(path: &Path, dir: &Path) -> Option<usize> {
    use std::os::unix::ffi::OsStrExt;
    let released = CString::new(dir.join(RELEASED_FILE).as_os_str().as_bytes()).ok()?;
    let path = CString::new(path.as_os_str().as_bytes()).ok()?;
    let message = format!(
        "\nusm-study: interrupted; the lock of {} is released and its finished work kept: run \
         the same command with --resume to continue\n",
        dir.display()
    )
    .into_bytes();
    let slot = Box::into_raw(Box::new(Slot {
        path,
        released,
        message,
    }));
    INSTALLED.call_once(install_handlers);
    for (i, s) in SLOTS.iter().enumerate() {
        if s.compare_exchange(
            std::ptr::null_mut(),
            slot,
            Ordering::SeqCst,
            Ordering::SeqCst,
        )
        .is_ok()
        {
            return Some(i);
        }
    }
    None
}

fn install_handlers() {
    for sig in [libc::SIGTERM, libc::SIGINT] {
        // SAFETY: `on_signal` only performs async-signal-safe operations (atomics, unlink,
        // write, _exit); a signal the parent set to be ignored stays ignored.
        unsafe {
            let handler = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            let old = libc::signal(sig, handler);
            if old == libc::SIG_IGN {
                libc::signal(sig, libc::SIG_IGN);
            }
        }
    }
}

extern "C" fn on_signal(sig: libc::c_int) {
    let first = SIGNAL.swap(sig, Ordering::SeqCst) == 0;
    if first && GRACEFUL.load(Ordering::SeqCst) {
        return;
    }
    exit_interrupted(sig);
}

/// While `on`, a signal is only recorded ([`pending_signal`]) for the caller to stop by
/// itself; a signal that came in meanwhile is acted on when it is switched off.
pub fn set_graceful(on: bool) {
    GRACEFUL.store(on, Ordering::SeqCst);
    if !on {
        if let Some(sig) = pending_signal() {
            exit_interrupted(sig);
        }
    }
}

/// The signal received while graceful, if any.
pub fn pending_signal() -> Option<i32> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// Release every held lock (renamed to [`RELEASED_FILE`], which keeps the run's token for the
/// next run), print how to resume and exit with `128 + sig` (async-signal-safe).
pub fn exit_interrupted(sig: i32) -> ! {
    for s in &SLOTS {
        let p = s.load(Ordering::SeqCst);
        if !p.is_null() {
            // SAFETY: slots are leaked boxes, never freed; unlink and write are
            // async-signal-safe.
            unsafe {
                let slot = &*p;
                if libc::rename(slot.path.as_ptr(), slot.released.as_ptr()) != 0 {
                    libc::unlink(slot.path.as_ptr());
                }
                libc::write(2, slot.message.as_ptr().cast(), slot.message.len());
            }
        }
    }
    // SAFETY: _exit ends the process without running anything else.
    unsafe { libc::_exit(128 + sig) }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ME: LockOwner = LockOwner {
        study: "abc",
        resume: false,
    };

    #[test]
    fn a_second_lock_names_the_holder_and_a_dead_holder_is_replaced() {
        let d = tempfile::tempdir().unwrap();
        let held = lock(d.path(), &ME).unwrap();
        let text = std::fs::read_to_string(d.path().join(LOCK_FILE)).unwrap();
        assert!(
            text.contains("study=abc\n") && text.contains("token="),
            "{text}"
        );
        let e = lock(d.path(), &ME).unwrap_err().to_string();
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        assert!(e.contains("in use by another run"), "{e}");
        drop(held);
        assert!(!d.path().join(LOCK_FILE).exists());
        // A lock of a pid that cannot exist (above the kernel's pid_max) is stale.
        let text = format!("pid=4194305\nhost={}\nsince=x\ntoken=t1\n", host_name());
        std::fs::write(d.path().join(LOCK_FILE), text).unwrap();
        let held = lock(d.path(), &ME).unwrap();
        assert_eq!(held.replaced.as_ref().unwrap().token, "t1");
        drop(held);
        // Another host's lock is not judged stale from here, fresh or without --resume.
        std::fs::write(
            d.path().join(LOCK_FILE),
            "pid=4194305\nhost=elsewhere\nstudy=abc\n",
        )
        .unwrap();
        assert!(lock(d.path(), &ME).is_err());
        let resume = LockOwner { resume: true, ..ME };
        assert!(lock(d.path(), &resume).is_err(), "touched just now");
    }

    #[test]
    fn resume_takes_over_an_abandoned_lock_of_the_same_study_only() {
        let holder = Holder::parse("pid=7\nhost=node-a\nstudy=abc\nslurm_job=\n");
        let old = Some(TAKEOVER_AGE + Duration::from_secs(1));
        let young = Some(Duration::from_secs(5));
        let resume = LockOwner {
            study: "abc",
            resume: true,
        };
        assert!(takeover_reason(&holder, old, &resume).is_some());
        assert!(takeover_reason(&holder, young, &resume).is_none());
        assert!(takeover_reason(&holder, old, &ME).is_none(), "no --resume");
        let other = LockOwner {
            study: "xyz",
            resume: true,
        };
        assert!(
            takeover_reason(&holder, old, &other).is_none(),
            "other study"
        );
    }
}

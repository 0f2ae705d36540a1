//! Output file names and the one writer of output files: [`atomic_write`] replaces a whole
//! file, [`create_file`] / [`open_existing`] open a streamed one (a journal), both link-safe (a
//! symbolic link at the name is replaced, never followed); [`prepare_dir`] creates an output
//! folder and removes the temporaries a killed run of any verb left there
//! ([`remove_dead_temporaries`]); [`file_stem_safe`] for names that become file names.

use std::io::Write;
use std::path::{Path, PathBuf};

use super::error::{ReportError, Result};

/// Writes `bytes` to `path` atomically: to a temporary file in the same directory, flushed and
/// synced, then renamed into place. A reader never sees a half-written file; an interrupted
/// write leaves at most a stray `.<name>.tmp-<token>` file ([`run_token`]), which the next run
/// holding the output directory's lock removes (only that token's files).
pub fn atomic_write(path: &Path, bytes: &[u8]) -> Result<()> {
    atomic_write_with(path, |w| w.write_all(bytes))
}

/// This process's run token, `PID-HEX` (pid and clock at first use): names its temporary
/// files and is recorded in the output directory's lock, so that only a dead run's own
/// temporaries are ever removed.
pub fn run_token() -> &'static str {
    static TOKEN: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TOKEN.get_or_init(|| {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        format!("{}-{:x}", std::process::id(), nanos & 0xffff_ffff_ffff)
    })
}

/// The suffix of this run's temporary files: `.tmp-TOKEN`.
pub fn temporary_suffix() -> String {
    format!(".tmp-{}", run_token())
}

/// [`atomic_write`] of what `fill` writes (through a 64 KiB buffer) into the temporary file:
/// for large files produced piece by piece, without holding them in memory.
pub fn atomic_write_with(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<&mut std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    let io = |action: &'static str, p: &Path| {
        let p = p.to_path_buf();
        move |source| ReportError::Io {
            path: p,
            action,
            source,
        }
    };
    let file_name = path.file_name().ok_or_else(|| ReportError::Io {
        path: path.to_path_buf(),
        action: "writing",
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "path has no file name"),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(temporary_suffix());
    let tmp = dir.join(tmp_name);
    let result = (|| {
        // `create_new`: never through a link (or another run's file) at the temporary name.
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io("creating", &tmp))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 16, &mut file);
        fill(&mut w).map_err(io("writing", &tmp))?;
        w.flush().map_err(io("writing", &tmp))?;
        drop(w);
        file.sync_all().map_err(io("syncing", &tmp))?;
        drop(file);
        std::fs::rename(&tmp, path).map_err(io("renaming into place", path))
    })();
    if result.is_err() {
        // Best effort: do not leave the temporary file behind.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Opens `flags` on `path` without following a symbolic link at its last component
/// (`O_NOFOLLOW`).
fn open_nofollow(path: &Path, o: &mut std::fs::OpenOptions) -> std::io::Result<std::fs::File> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        o.custom_flags(libc::O_NOFOLLOW);
    }
    o.open(path)
}

/// Creates (or truncates) `path` for a streamed output (a journal, rows appended one by one):
/// a symbolic link at the name — pointing out of the folder, or dangling — is removed first,
/// so the file is always created at the name itself, never at the link's target.
pub fn create_file(path: &Path) -> std::io::Result<std::fs::File> {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        std::fs::remove_file(path)?;
    }
    open_nofollow(
        path,
        std::fs::OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(true),
    )
}

/// Opens an existing streamed output `path` to write (append after a seek) without following
/// a symbolic link at the name (an error `ELOOP` instead).
pub fn open_existing(path: &Path, append: bool) -> std::io::Result<std::fs::File> {
    let mut o = std::fs::OpenOptions::new();
    if append {
        o.append(true);
    } else {
        o.write(true);
    }
    open_nofollow(path, &mut o)
}

/// Whether a process `pid` exists on this host (signal 0; a process of another user counts).
pub fn process_alive(pid: u32) -> bool {
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

/// The pid of a temporary file's name `.NAME.tmp-PID-HEX` (the form [`atomic_write`] and the
/// streamed writers use), if it has that form.
fn temporary_pid(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?;
    let (stem, token) = rest.rsplit_once(".tmp-")?;
    let (pid, hex) = token.split_once('-')?;
    let hex_ok = !hex.is_empty() && hex.len() <= 16 && hex.bytes().all(|b| b.is_ascii_hexdigit());
    (!stem.is_empty() && hex_ok && !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()))
        .then(|| pid.parse().ok())
        .flatten()
}

/// Removes the temporary files (`.NAME.tmp-PID-HEX`, regular files only, never through a link)
/// in `dir` and its subfolders (two levels: `plots/`, a paper's run folders) whose process no
/// longer exists on this host: what a killed run of any verb left (a killed `tcm` leaves
/// `.samples.csv.tmp-PID-HEX`). A live process's temporaries stay. Returns their count.
pub fn remove_dead_temporaries(dir: &Path) -> usize {
    let mut n = 0;
    let mut stack = vec![(dir.to_path_buf(), 0usize)];
    while let Some((d, depth)) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let Ok(ft) = e.file_type() else { continue };
            let name = e.file_name().to_string_lossy().to_string();
            if ft.is_dir() && depth < 2 {
                stack.push((e.path(), depth + 1));
            } else if ft.is_file()
                && temporary_pid(&name).is_some_and(|pid| !process_alive(pid))
                && std::fs::remove_file(e.path()).is_ok()
            {
                n += 1;
            }
        }
    }
    n
}

/// Creates the output folder `dir` (and its parents) of any verb and removes the temporaries
/// a killed run left in it ([`remove_dead_temporaries`]); their count.
pub fn prepare_dir(dir: &Path) -> std::io::Result<usize> {
    std::fs::create_dir_all(dir)?;
    Ok(remove_dead_temporaries(dir))
}

/// Creates `dir`, a folder inside an output (a paper's run folder), refusing a symbolic link at
/// its name: files written below it would land wherever the link leads.
pub fn create_subdir(dir: &Path) -> std::io::Result<()> {
    if std::fs::symlink_metadata(dir).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "a symbolic link stands at this folder's name: refusing to write through it; \
             remove the link or use another --out",
        ));
    }
    std::fs::create_dir_all(dir)
}

/// A name made safe for a file name: ASCII letters, digits, `-` and `_` kept, anything else
/// replaced by `_`.
pub fn file_stem_safe(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        atomic_write(&p, b"one").unwrap();
        atomic_write(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "no temporary file left behind");
        assert!(atomic_write(&dir.path().join("missing/x.txt"), b"x").is_err());
    }
}

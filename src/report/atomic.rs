//! Output file names and atomic writes ([`atomic_write`]): the one way the crate replaces a whole
//! file, and [`file_stem_safe`] for names that become file names.

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
        let mut file = std::fs::File::create(&tmp).map_err(io("creating", &tmp))?;
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

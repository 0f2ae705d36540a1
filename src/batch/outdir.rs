//! Ownership of an output directory: one run at a time ([`super::lock`]), one study per
//! directory, writes only inside it, deletes only what the tool wrote.
//!
//! - [`resolve`]: the output directory is created and resolved once (canonical path); every
//!   later write goes below that path.
//! - [`check_contained`]: a symbolic link inside the directory that leads out of it (e.g. a
//!   `plots/` linked elsewhere) is refused (exit code 2) before anything is written or removed.
//! - [`OWNED_FILE`] (`.usm-study.files`): the tool's own record of the files it wrote into the
//!   directory, one relative path a line ([`record_owned`]). `--force` removes only files
//!   listed there (a directory written by an older version without the record: only the fixed
//!   names of a sweep output, and only when its `manifest.json` says `usm-study` wrote it);
//!   a user's own files are never removed, and files named like outputs that the tool did not
//!   write are refused even with `--force`. A report removes the figures of the record under
//!   `plots/` before it draws its own ([`remove_owned_plots`]), so none of an earlier version
//!   of the study survives onto the review page.
//! - [`claim`]: a directory holding another study's output is refused unless `--force`; one
//!   holding finished cases of the same study is refused unless `--resume` (keep them) or
//!   `--force` (start over). Temporary files of a killed run that held the lock
//!   (`.NAME.tmp-TOKEN`, its token from its lock file) are removed and reported.

use std::collections::BTreeSet;
use std::io::BufRead;
use std::path::{Component, Path, PathBuf};
use std::time::SystemTime;

use super::manifest::MANIFEST_FILE;
use super::records::{CASES_CSV, CASES_PARQUET, PARTIAL_FILE, PARTIAL_STUDY_FILE, STUDY_COPY};
use crate::study::error::{Notes, StudyError};

pub use super::lock::{host_name, lock, LockOwner, OutputLock, LOCK_FILE, RELEASED_FILE};

/// The tool's record of the files it wrote into an output directory.
pub const OWNED_FILE: &str = ".usm-study.files";

/// Files of a sweep output (besides `plots/`).
pub const SWEEP_FILES: [&str; 10] = [
    CASES_CSV,
    CASES_PARQUET,
    PARTIAL_FILE,
    PARTIAL_STUDY_FILE,
    MANIFEST_FILE,
    STUDY_COPY,
    "summary.md",
    "trajectory_best.csv",
    "trajectory_worst.csv",
    "report.html",
];

/// Extensions of the files the tool writes (at the top of an output and in `plots/`).
const OUTPUT_EXTENSIONS: [&str; 9] = [
    "csv", "parquet", "json", "jsonl", "md", "html", "toml", "svg", "pdf",
];

/// Create `dir` if missing and return its canonical path: the one path every later write of
/// the run goes below.
pub fn resolve(dir: &Path) -> Result<PathBuf, StudyError> {
    std::fs::create_dir_all(dir).map_err(|e| StudyError::io(dir, e))?;
    std::fs::canonicalize(dir).map_err(|e| StudyError::io(dir, e))
}

/// Refuse any symbolic link inside `root` (canonical) whose target is outside it or missing
/// (a write through it would land outside); links are not followed while looking.
pub fn check_contained(root: &Path) -> Result<(), StudyError> {
    let mut stack = vec![(root.to_path_buf(), 0usize)];
    while let Some((dir, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let Ok(ft) = e.file_type() else { continue };
            let p = e.path();
            if ft.is_symlink() {
                match std::fs::canonicalize(&p) {
                    Ok(t) if t.starts_with(root) => {}
                    target => {
                        return Err(StudyError::Input(format!(
                            "{} is a symbolic link leading out of the output directory {} \
                             (to {}): refusing to write or delete through it; remove the link \
                             or use another --out",
                            p.display(),
                            root.display(),
                            target.map_or_else(
                                |_| std::fs::read_link(&p)
                                    .map_or("?".into(), |t| t.display().to_string()),
                                |t| t.display().to_string()
                            )
                        )))
                    }
                }
            } else if ft.is_dir() && depth < 3 {
                stack.push((p, depth + 1));
            }
        }
    }
    Ok(())
}

/// What a run asks of its output directory in [`claim`].
#[derive(Clone, Copy, Debug)]
pub struct Claim<'a> {
    /// The study's name (recorded in the output's `study.toml`).
    pub study: &'a str,
    /// Replace another study's output, or this study's finished cases.
    pub force: bool,
    /// Keep this study's finished cases (`--resume`, or a merge).
    pub resume: bool,
}

/// The study name recorded in an output directory (its `study.toml` copy), if any.
fn recorded_study(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join(STUDY_COPY)).ok()?;
    let t: toml::Table = text.parse().ok()?;
    t.get("study")?.get("name")?.as_str().map(str::to_string)
}

/// Make `dir` (canonical, locked by the caller with `lock`) ready for the run `c`: refuse a
/// symbolic link out of it, another study's output unless `force` (which then removes that
/// output's own files), this study's finished cases unless `resume` or `force`; remove the
/// temporaries of the run whose lock `lock` replaced. Returns notes for the user.
pub fn claim(dir: &Path, lock: &OutputLock, c: &Claim) -> Result<Notes, StudyError> {
    check_contained(dir)?;
    let mut notes: Vec<String> = lock.takeover.iter().cloned().collect();
    let recorded = recorded_study(dir);
    let other = match &recorded {
        Some(n) if n != c.study => Some(n.clone()),
        Some(_) => None,
        None => has_output(dir).then(|| "?".to_string()),
    };
    if let Some(other) = other {
        if !c.force {
            return Err(StudyError::Input(format!(
                "{} holds the output of another study ({other}); use another --out, or --force \
                 to replace it",
                dir.display()
            )));
        }
        let removed = remove_owned(dir)?;
        notes.push(format!(
            "--force: removed {removed} files of study {other} from {}",
            dir.display()
        ));
    } else if recorded.is_some() && !c.resume {
        if let Some(what) = finished_cases(dir) {
            if !c.force {
                return Err(StudyError::Input(format!(
                    "{} holds {what} of study {}: rerun with --resume to keep them and run the \
                     rest, or with --force to start over",
                    dir.display(),
                    c.study
                )));
            }
            let removed = remove_owned(dir)?;
            notes.push(format!(
                "--force: removed {removed} files of the previous run of study {} from {}",
                c.study,
                dir.display()
            ));
        }
    }
    if let Some(suffix) = lock.replaced.as_ref().and_then(|h| h.temporary_suffix()) {
        let stale =
            remove_temporaries(dir, &suffix)? + remove_temporaries(&dir.join("plots"), &suffix)?;
        if stale > 0 {
            notes.push(format!(
                "removed {stale} temporary files left by an interrupted run in {}",
                dir.display()
            ));
        }
    }
    // And those of a killed run of any other verb (no lock: `tcm`, `simulate`, …).
    let dead = crate::report::remove_dead_temporaries(dir);
    if dead > 0 {
        notes.push(format!(
            "removed {dead} temporary files of killed runs (their process is gone) in {}",
            dir.display()
        ));
    }
    let released = dir.join(RELEASED_FILE);
    if released.exists() {
        std::fs::remove_file(&released).map_err(|e| StudyError::io(&released, e))?;
    }
    Ok(notes)
}

/// What finished work of a study `dir` holds that a rerun would lose: the rows of an
/// interrupted run's journal. A complete run's tables (cases.csv) are not counted: the same
/// study file recomputes them bit for bit, and the README's main command reruns the study into
/// its committed reference output.
fn finished_cases(dir: &Path) -> Option<&'static str> {
    let f = std::fs::File::open(dir.join(PARTIAL_FILE)).ok()?;
    // A header and at least one complete row.
    let mut lines = std::io::BufReader::new(f).split(b'\n');
    let complete = |l: Option<std::io::Result<Vec<u8>>>| l.is_some_and(|l| l.is_ok());
    (complete(lines.next()) && complete(lines.next()))
        .then_some("finished cases in its journal (cases.partial.csv)")
}

/// Whether `dir` holds any file named like a sweep output.
fn has_output(dir: &Path) -> bool {
    SWEEP_FILES.iter().any(|f| dir.join(f).exists())
}

/// A relative path of the record that stays inside the directory (`NAME` or `plots/NAME`).
fn safe_entry(line: &str) -> Option<&str> {
    let p = Path::new(line);
    let parts: Vec<Component> = p.components().collect();
    let plain = parts.iter().all(|c| matches!(c, Component::Normal(_)));
    (plain && (1..=2).contains(&parts.len())).then_some(line)
}

/// The record of files the tool wrote into `dir`, if there is one.
fn read_owned(dir: &Path) -> Option<BTreeSet<String>> {
    let text = std::fs::read_to_string(dir.join(OWNED_FILE)).ok()?;
    Some(
        text.lines()
            .filter_map(safe_entry)
            .map(str::to_string)
            .collect(),
    )
}

/// Whether `manifest.json` of `dir` says this tool wrote it.
fn written_by_us(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join(MANIFEST_FILE))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| v["tool"] == "usm-study")
}

/// Remove the files the tool wrote into `dir` (its record; see the module documentation) and
/// refuse files named like outputs that it did not write. Their count.
fn remove_owned(dir: &Path) -> Result<usize, StudyError> {
    let owned = match read_owned(dir) {
        Some(o) => o,
        None if written_by_us(dir) => SWEEP_FILES.iter().map(|s| s.to_string()).collect(),
        None => BTreeSet::new(),
    };
    let foreign: Vec<&str> = SWEEP_FILES
        .iter()
        .copied()
        .filter(|f| dir.join(f).exists() && !owned.contains(*f))
        .collect();
    if !foreign.is_empty() {
        return Err(StudyError::Input(format!(
            "{} holds {} that usm-study did not write (not in its record {OWNED_FILE}): \
             refusing to replace them, even with --force; move them or use another --out",
            dir.display(),
            foreign.join(", ")
        )));
    }
    let mut n = 0;
    for f in &owned {
        let p = dir.join(f);
        if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file()) {
            std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
            n += 1;
        }
    }
    let record = dir.join(OWNED_FILE);
    if record.exists() {
        std::fs::remove_file(&record).map_err(|e| StudyError::io(&record, e))?;
    }
    Ok(n)
}

/// Add to `dir`'s record ([`OWNED_FILE`]) the files this run wrote: output files (by
/// extension) at the top and in `plots/` modified after the run took the lock (`since`,
/// [`OutputLock::created`]), plus `always` (names the run writes whether or not they exist
/// yet); entries of the record whose files are gone are dropped.
pub fn record_owned(dir: &Path, since: SystemTime, always: &[&str]) -> Result<(), StudyError> {
    let mut owned = read_owned(dir).unwrap_or_default();
    owned.retain(|f| dir.join(f).exists());
    owned.extend(always.iter().map(|s| s.to_string()));
    for (sub, prefix) in [(dir.to_path_buf(), ""), (dir.join("plots"), "plots/")] {
        for e in std::fs::read_dir(&sub).into_iter().flatten().flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            let fresh = e
                .metadata()
                .ok()
                .filter(|m| m.is_file())
                .and_then(|m| m.modified().ok())
                .is_some_and(|t| t > since);
            let ext_ok = Path::new(&name)
                .extension()
                .is_some_and(|x| OUTPUT_EXTENSIONS.iter().any(|o| x == *o));
            if fresh && ext_ok && !name.starts_with('.') {
                owned.insert(format!("{prefix}{name}"));
            }
        }
    }
    let text: String = owned.iter().map(|f| format!("{f}\n")).collect();
    crate::report::atomic_write(&dir.join(OWNED_FILE), text.as_bytes())?;
    Ok(())
}

/// Remove the figures a report wrote into `dir/plots` before (`plots/NAME.svg` and their
/// column-width `plots/NAME.pdf` entries of the record, [`OWNED_FILE`]), so that the report about to be written leaves only its own: a
/// figure an earlier version of the study drew (a metric since dropped) would otherwise stay
/// beside the new ones and be shown on the review page. Only regular files named in the
/// record go, and nothing when `plots` is not a real directory (a symbolic link is never
/// followed); a user's own figures are not in the record. Their count.
pub fn remove_owned_plots(dir: &Path) -> Result<usize, StudyError> {
    let plots = dir.join("plots");
    if !std::fs::symlink_metadata(&plots).is_ok_and(|m| m.is_dir()) {
        return Ok(0);
    }
    let mut n = 0;
    for f in read_owned(dir).unwrap_or_default() {
        let Some(name) = f.strip_prefix("plots/") else {
            continue;
        };
        if !(name.ends_with(".svg") || name.ends_with(".pdf")) {
            continue;
        }
        let p = plots.join(name);
        if std::fs::symlink_metadata(&p).is_ok_and(|m| m.is_file()) {
            std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
            n += 1;
        }
    }
    Ok(n)
}

/// Remove the temporary files `.NAME.tmp-SUFFIX` of one dead run in `dir`; their count.
fn remove_temporaries(dir: &Path, suffix: &str) -> Result<usize, StudyError> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(0);
    };
    let tail = format!(".tmp-{suffix}");
    let mut n = 0;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let is_tmp = name.starts_with('.') && name.ends_with(&tail) && name.len() > tail.len() + 1;
        if is_tmp && e.file_type().is_ok_and(|t| t.is_file()) {
            std::fs::remove_file(e.path()).map_err(|err| StudyError::io(&e.path(), err))?;
            n += 1;
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn owner() -> LockOwner<'static> {
        LockOwner {
            study: "h",
            resume: false,
        }
    }

    #[test]
    fn a_report_removes_only_the_figures_the_record_names() {
        let d = tempfile::tempdir().unwrap();
        let p = &resolve(d.path()).unwrap();
        let outside = tempfile::tempdir().unwrap();
        let victim = outside.path().join("victim.svg");
        std::fs::write(&victim, "<svg/>").unwrap();
        std::fs::create_dir(p.join("plots")).unwrap();
        for f in ["old_metric.svg", "axis_x.svg", "mine.svg"] {
            std::fs::write(p.join("plots").join(f), "<svg/>").unwrap();
        }
        std::os::unix::fs::symlink(&victim, p.join("plots/link.svg")).unwrap();
        std::fs::write(p.join(CASES_CSV), "x\n").unwrap();
        let record = "cases.csv\nplots/old_metric.svg\nplots/axis_x.svg\nplots/link.svg\n\
                      plots/../escape.svg\n";
        std::fs::write(p.join(OWNED_FILE), record).unwrap();
        assert_eq!(remove_owned_plots(p).unwrap(), 2);
        assert!(!p.join("plots/old_metric.svg").exists() && !p.join("plots/axis_x.svg").exists());
        // The user's figure, the table, the link and what it points to stay.
        assert!(p.join("plots/mine.svg").exists() && p.join(CASES_CSV).exists());
        assert!(std::fs::symlink_metadata(p.join("plots/link.svg")).is_ok() && victim.exists());
        // A `plots` that is a link out of the directory is not touched at all.
        let q = &resolve(&p.join("sub")).unwrap();
        std::fs::write(outside.path().join("axis_y.svg"), "<svg/>").unwrap();
        std::os::unix::fs::symlink(outside.path(), q.join("plots")).unwrap();
        std::fs::write(q.join(OWNED_FILE), "plots/axis_y.svg\n").unwrap();
        assert_eq!(remove_owned_plots(q).unwrap(), 0);
        assert!(outside.path().join("axis_y.svg").exists());
    }

    #[test]
    fn another_studys_output_needs_force_and_only_its_own_files_go() {
        let d = tempfile::tempdir().unwrap();
        let p = &resolve(d.path()).unwrap();
        std::fs::create_dir(p.join("plots")).unwrap();
        std::fs::write(p.join("plots/user_diagram.svg"), "<svg/>").unwrap();
        std::fs::write(p.join("notes.txt"), "mine").unwrap();
        let l = lock(p, &owner()).unwrap();
        // File times have the kernel's coarse clock: the run's files come later.
        std::thread::sleep(std::time::Duration::from_millis(30));
        std::fs::write(p.join(STUDY_COPY), "[study]\nname = \"a\"\n").unwrap();
        std::fs::write(p.join(CASES_CSV), "x\n").unwrap();
        std::fs::write(p.join(PARTIAL_FILE), "id\n0\n").unwrap();
        std::fs::write(p.join("plots/axis_x.svg"), "<svg/>").unwrap();
        record_owned(p, l.created, &[]).unwrap();
        drop(l);
        let l = lock(p, &owner()).unwrap();
        let c = |study, force| Claim {
            study,
            force,
            resume: false,
        };
        let e = claim(p, &l, &c("b", false)).unwrap_err().to_string();
        assert!(
            e.contains("another study (a)") && e.contains("--force"),
            "{e}"
        );
        let e = claim(p, &l, &c("a", false)).unwrap_err().to_string();
        assert!(e.contains("--resume") && e.contains("--force"), "{e}");
        let notes = claim(p, &l, &c("b", true)).unwrap();
        assert!(notes[0].contains("removed 4 files of study a"), "{notes:?}");
        assert!(!p.join(CASES_CSV).exists() && !p.join("plots/axis_x.svg").exists());
        assert!(p.join("notes.txt").exists() && p.join("plots/user_diagram.svg").exists());
    }

    #[test]
    fn files_named_like_outputs_but_not_written_by_the_tool_are_refused_even_with_force() {
        let d = tempfile::tempdir().unwrap();
        let p = &resolve(d.path()).unwrap();
        std::fs::write(p.join(MANIFEST_FILE), "{\"mine\": 1}").unwrap();
        std::fs::write(p.join("summary.md"), "# my notes").unwrap();
        let l = lock(p, &owner()).unwrap();
        let c = Claim {
            study: "b",
            force: true,
            resume: false,
        };
        let e = claim(p, &l, &c).unwrap_err().to_string();
        assert!(
            e.contains("manifest.json, summary.md that usm-study did not write"),
            "{e}"
        );
        assert!(p.join("summary.md").exists());
    }

    #[test]
    fn a_symlink_out_of_the_output_is_refused_and_only_a_dead_runs_temporaries_go() {
        let d = tempfile::tempdir().unwrap();
        let out = resolve(&d.path().join("o")).unwrap();
        let victim = d.path().join("victim");
        std::fs::create_dir(&victim).unwrap();
        std::fs::write(victim.join(".data.tmp-42"), "precious").unwrap();
        std::os::unix::fs::symlink(&victim, out.join("plots")).unwrap();
        let e = check_contained(&out).unwrap_err().to_string();
        assert!(e.contains("symbolic link leading out"), "{e}");
        std::fs::remove_file(out.join("plots")).unwrap();
        std::os::unix::fs::symlink(out.join("inside"), out.join("dangling")).unwrap();
        assert!(
            check_contained(&out).is_err(),
            "a dangling link could be created outside"
        );
        std::fs::remove_file(out.join("dangling")).unwrap();
        std::fs::create_dir(out.join("real")).unwrap();
        std::os::unix::fs::symlink(out.join("real"), out.join("plots")).unwrap();
        assert!(check_contained(&out).is_ok(), "a link inside is fine");
        // Temporaries: only those of the dead holder's token.
        std::fs::write(out.join(".a.csv.tmp-99-ab"), "").unwrap();
        std::fs::write(out.join(".b.csv.tmp-42"), "").unwrap();
        let text = format!("pid=4194305\nhost={}\ntoken=99-ab\n", host_name());
        std::fs::write(out.join(LOCK_FILE), text).unwrap();
        let l = lock(&out, &owner()).unwrap();
        let c = Claim {
            study: "s",
            force: false,
            resume: false,
        };
        let notes = claim(&out, &l, &c).unwrap();
        assert!(notes[0].contains("removed 1 temporary"), "{notes:?}");
        assert!(!out.join(".a.csv.tmp-99-ab").exists() && out.join(".b.csv.tmp-42").exists());
    }
}

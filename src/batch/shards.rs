//! Merging shard outputs into one: same study, raw rows concatenated, sorted by case id,
//! deduplicated by hash; then the final tables, the manifest and the report (under the output
//! directory's lock, see [`super::outdir`]). The merged output keeps no journal of its own; an
//! input's journal is never removed (also when `--out` is one of the inputs).
//!
//! A merge is complete or refused: shards missing, given twice, or of different shard counts
//! (or outputs that are not shards) are an input error (exit code 2) naming them, unless
//! `--partial`, which merges what is there with a warning.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::manifest::{
    now_rfc3339, read_manifest, relative_path, study_path, write_manifest, Counts, Manifest,
};
use super::outdir;
use super::records::{compact, StatusCounts, PARTIAL_FILE, STUDY_COPY};
use super::report_hook::ReportHook;
use super::robust::write_tables;
use super::tuning_hook::TuningHook;
use crate::report::{read_csv_typed, Table};
use crate::study::error::{Notes, StudyError};
use crate::study::parse::load_study;

/// Options of [`merge`].
#[derive(Clone, Copy, Debug, Default)]
pub struct MergeOptions {
    /// Merge what is there when shards are missing, duplicated or mismatched (a warning).
    pub partial: bool,
    /// Replace another study's output in the output directory (see [`outdir::claim`]).
    pub force: bool,
}

/// Merge shard outputs into `out`: check they come from the same study and form one whole set
/// of shards (unless `opts.partial`), concatenate their raw rows, sort by case id, deduplicate
/// by hash, and write the final tables, manifest and, through `report`, the report (the
/// best/worst reruns of a study with `[tune]` at their tuned values through `tuning`).
pub fn merge(
    dirs: &[PathBuf],
    out: &Path,
    opts: MergeOptions,
    tuning: Option<TuningHook>,
    report: Option<ReportHook>,
) -> Result<(Manifest, Notes), StudyError> {
    let start_time = now_rfc3339();
    let first_dir = dirs
        .first()
        .ok_or_else(|| StudyError::Input("merge needs at least one directory".into()))?;
    let manifests: Vec<Manifest> = dirs
        .iter()
        .map(|d| read_manifest(d))
        .collect::<Result<_, _>>()?;
    let m0 = &with_every_world(&manifests);
    let canonical = |d: &Path| std::fs::canonicalize(d).ok();
    if let Some(o) = canonical(out) {
        if let Some(d) = dirs.iter().find(|d| canonical(d).as_ref() == Some(&o)) {
            return Err(StudyError::Input(format!(
                "merge --out {}: is one of the shards being merged ({}); its manifest would be \
                 replaced and the shards could not be merged again: use another --out",
                out.display(),
                d.display()
            )));
        }
    }
    check_same_study(dirs, &manifests)?;
    let mut warnings = check_shard_set(dirs, &manifests, opts.partial)?;
    let schema = m0.schema()?;
    let mut tables = Vec::new();
    for d in dirs {
        tables.push(read_csv_typed(&d.join(PARTIAL_FILE), &schema)?);
    }
    let raw = compact(&Table::concat(&tables)?, None)?;
    let out = &outdir::resolve(out)?;
    let owner = outdir::LockOwner {
        study: &m0.study_hash,
        resume: false,
    };
    let lock = outdir::lock(out, &owner)?;
    let claim = outdir::Claim {
        study: &m0.study_name,
        force: opts.force,
        resume: true,
    };
    warnings.extend(outdir::claim(out, &lock, &claim)?);
    outdir::record_owned(out, lock.created, &outdir::SWEEP_FILES)?;
    let axes: Vec<&str> = m0.axes.iter().map(|a| a.name.as_str()).collect();
    let table = write_tables(raw, out, m0.robust.as_ref(), &axes)?;
    if let Ok(text) = std::fs::read_to_string(first_dir.join(STUDY_COPY)) {
        crate::report::atomic_write(&out.join(STUDY_COPY), text.as_bytes())?;
    }
    let mut m = m0.clone();
    m.start_time = start_time;
    m.end_time = now_rfc3339();
    m.shard = None;
    // Paths relative to the merged output, as a sweep records them (issue 42 item 6).
    m.merged_from = dirs.iter().map(|d| relative_path(d, out)).collect();
    m.study_file = relative_path(&study_path(first_dir, m0), out);
    m.cases = Counts {
        planned: m0.cases.planned,
        in_output: table.n_rows(),
        resumed: manifests.iter().map(|m| m.cases.resumed).sum(),
        ran: manifests.iter().map(|m| m.cases.ran).sum(),
        ..Default::default()
    }
    .with_status(StatusCounts::of_table(&table)?);
    // Shards run side by side: the merged wall time is the longest shard's.
    m.elapsed_s = manifests.iter().map(|m| m.elapsed_s).fold(0.0, f64::max);
    m.throughput_cases_per_s = manifests.iter().map(|m| m.throughput_cases_per_s).sum();
    write_manifest(out, &m)?;
    if table.n_rows() < m.cases.planned {
        warnings.push(format!(
            "merged {} of {} cases: some shards are missing or unfinished",
            table.n_rows(),
            m.cases.planned
        ));
    }
    // The study itself (for reruns of the best/worst case), when it is still where it was.
    let study = load_study(&study_path(out, &m))
        .ok()
        .filter(|s| s.hash == m.study_hash);
    if let Some(report) = report {
        warnings.extend(report.write(out, &table, &m, study.as_ref(), tuning));
    }
    outdir::record_owned(out, lock.created, &outdir::SWEEP_FILES)?;
    // The merged rows are in cases.csv: no journal is left behind, unless the output is one
    // of the inputs (the journal is that shard's raw output).
    let is_input = dirs
        .iter()
        .any(|d| std::fs::canonicalize(d).is_ok_and(|d| d == *out));
    let journal = out.join(PARTIAL_FILE);
    if !is_input && journal.exists() {
        std::fs::remove_file(&journal).map_err(|e| StudyError::io(&journal, e))?;
    }
    Ok((m, warnings))
}

/// The inputs must be the shards `0..N` of one `N`, each once: else an input error naming the
/// missing, repeated and mismatched ones, or with `partial` the same as a warning.
fn check_shard_set(
    dirs: &[PathBuf],
    manifests: &[Manifest],
    partial: bool,
) -> Result<Notes, StudyError> {
    let mut problems = Vec::new();
    let mut counts: BTreeMap<usize, Vec<String>> = BTreeMap::new();
    let mut seen: BTreeMap<usize, Vec<String>> = BTreeMap::new();
    for (d, m) in dirs.iter().zip(manifests) {
        match m.shard {
            Some([i, n]) => {
                counts.entry(n).or_default().push(d.display().to_string());
                seen.entry(i).or_default().push(d.display().to_string());
            }
            None => problems.push(format!("{} is not a shard output", d.display())),
        }
    }
    if counts.len() > 1 {
        let parts: Vec<String> = counts
            .iter()
            .map(|(n, ds)| format!("{} of {n} shards", ds.join(", ")))
            .collect();
        problems.push(format!("mismatched shard counts: {}", parts.join("; ")));
    }
    for (i, ds) in seen.iter().filter(|(_, ds)| ds.len() > 1) {
        problems.push(format!(
            "shard {i} given {} times ({})",
            ds.len(),
            ds.join(", ")
        ));
    }
    if let Some((&n, _)) = counts.iter().next_back() {
        let missing: Vec<String> = (0..n)
            .filter(|i| !seen.contains_key(i))
            .map(|i| format!("shard-{i}-of-{n}"))
            .collect();
        if !missing.is_empty() {
            problems.push(format!(
                "missing {} of {n} shards: {}",
                missing.len(),
                missing.join(", ")
            ));
        }
    }
    if problems.is_empty() {
        return Ok(Vec::new());
    }
    if partial {
        return Ok(problems
            .into_iter()
            .map(|p| format!("--partial: {p}"))
            .collect());
    }
    Err(StudyError::Input(format!(
        "merge: {}; pass --partial to merge what is there",
        problems.join("; ")
    )))
}

/// The first manifest with the worlds' values the others know and it does not: a manifest
/// that leaves them to its shard's `worlds.csv` knows only the worlds its cases met (NaN for
/// the rest); the shards' worlds are the same draws, so their union is the study's.
fn with_every_world(manifests: &[Manifest]) -> Manifest {
    let mut m0 = manifests[0].clone();
    if let Some(r0) = m0.robust.as_mut() {
        for r in manifests[1..].iter().filter_map(|m| m.robust.as_ref()) {
            if r.world_values.len() > r0.world_values.len() {
                let width = r0.params.len();
                r0.world_values
                    .resize(r.world_values.len(), vec![f64::NAN; width]);
            }
            for (w0, w) in r0.world_values.iter_mut().zip(&r.world_values) {
                for (x0, x) in w0.iter_mut().zip(w) {
                    if x0.is_nan() {
                        *x0 = *x;
                    }
                }
            }
        }
    }
    m0
}

/// Every shard must come from the first one's study and have its columns.
fn check_same_study(dirs: &[PathBuf], manifests: &[Manifest]) -> Result<(), StudyError> {
    let (first_dir, m0) = (&dirs[0], &manifests[0]);
    for (d, m) in dirs.iter().zip(manifests) {
        if m.study_hash != m0.study_hash {
            return Err(StudyError::Input(format!(
                "{} comes from another study (hash {}…) than {} ({}…)",
                d.display(),
                &m.study_hash[..12.min(m.study_hash.len())],
                first_dir.display(),
                &m0.study_hash[..12.min(m0.study_hash.len())]
            )));
        }
        if m.columns != m0.columns {
            return Err(StudyError::Input(format!(
                "{}: columns differ from {}",
                d.display(),
                first_dir.display()
            )));
        }
        if m.report != m0.report {
            // The merged report would take whichever shard came first's.
            return Err(StudyError::Input(format!(
                "{}: its report settings ({:?}) differ from {}'s ({:?}); the merged report \
                 would depend on the order of the shards: rerun the shard or give the same \
                 `[report]`",
                d.display(),
                m.report,
                first_dir.display(),
                m0.report
            )));
        }
    }
    Ok(())
}

/// The shard directories listed in `file`, one a line (relative ones relative to the file's
/// directory); blank lines are skipped.
pub fn read_shard_list(file: &Path) -> Result<Vec<PathBuf>, StudyError> {
    let text = std::fs::read_to_string(file).map_err(|e| StudyError::io(file, e))?;
    let base = file.parent().unwrap_or(Path::new("."));
    Ok(text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| base.join(l))
        .collect())
}

/// What a Slurm submission of a study needs besides the study.
#[derive(Clone, Debug)]
pub struct SlurmPlan {
    /// The `usm-study` executable the jobs run (absolute).
    pub exe: PathBuf,
    /// The study file (absolute).
    pub study: PathBuf,
    /// The merged output directory (absolute); shard `i` writes `OUT/shard-i-of-N`.
    pub out: PathBuf,
    /// Cases of the study.
    pub cases: usize,
    /// Cases per array task (≥ 1): the array has `⌈cases / cases_per_task⌉` tasks.
    pub cases_per_task: usize,
    /// Threads per task (`--cpus-per-task`, `--jobs`).
    pub cpus: usize,
    /// Per-case budget [s] (0: none); sets each task's `--time` with a margin.
    pub case_timeout_s: f64,
    /// Job name.
    pub name: String,
    /// `--force` for the tasks and the merge (replace another study's output).
    pub force: bool,
}

impl SlurmPlan {
    /// Array tasks: `⌈cases / cases_per_task⌉`, at least 1.
    pub fn tasks(&self) -> usize {
        self.cases.div_ceil(self.cases_per_task.max(1)).max(1)
    }
}

/// The file (in the merged output directory) listing the shard directories for the merge job.
pub const SHARD_LIST: &str = "shards.txt";

/// A shell word quoted for bash (`'…'`, with `'` as `'\''`): nothing inside is interpreted.
fn sh_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The submission script of a study on Slurm: a job array of [`SlurmPlan::tasks`] tasks, each
/// `usm-study sweep STUDY --shard slurm` into `OUT/shard-I-of-N` (resuming, so a requeued
/// task keeps its finished cases), then the merge into `OUT` as a job depending on the whole
/// array (`afterok`), which reads its shards from `OUT/shards.txt`. Run it with `bash`; it
/// prints the two job ids. `SBATCH_*` environment variables (e.g. `SBATCH_PARTITION`) apply
/// to both jobs as usual.
///
/// No user data is ever interpreted by a shell: the paths are single-quoted assignments of
/// environment variables (`USM_EXE`, `USM_STUDY`, `USM_OUT`) that the jobs' fixed,
/// single-quoted command text only expands (`--export=ALL`); the study name appears only as
/// [`crate::report::file_stem_safe`] text.
pub fn slurm_script(p: &SlurmPlan) -> String {
    let n = p.tasks();
    let time = if p.case_timeout_s > 0.0 {
        let minutes = (p.case_timeout_s * p.cases_per_task as f64 / 60.0).ceil() as u64 + 5;
        format!(" --time={minutes}")
    } else {
        String::new()
    };
    let force = if p.force { " --force" } else { "" };
    format!(
        r#"#!/usr/bin/env bash
# Slurm submission of study {jname}: {cases} cases in a job array of {n} tasks
# ({cpt} cases per task), then a merge job after the whole array succeeded.
# Written by `usm-study sweep --emit-slurm`; run it with bash on a Slurm login node.
# The paths reach the jobs as environment variables, never as command text.
set -euo pipefail
export USM_EXE={exe}
export USM_STUDY={study}
export USM_OUT={out}
mkdir -p -- "$USM_OUT"
# sbatch expands %A, %a, %j, … in --output: a % of the path itself is written %%.
log_dir=${{USM_OUT//'%'/%%}}
for ((i = 0; i < {n}; i++)); do printf 'shard-%d-of-{n}\n' "$i"; done >"$USM_OUT/{list}"
array=$(sbatch --parsable --export=ALL --job-name={jname}-sweep --array=0-{last} \
  --cpus-per-task={cpus}{time} --output="$log_dir/slurm-%A_%a.log" \
  --wrap='exec "$USM_EXE" sweep "$USM_STUDY" --shard slurm --resume{force} --jobs {cpus} --case-timeout {timeout} --out "$USM_OUT/shard-$SLURM_ARRAY_TASK_ID-of-{n}"')
array=${{array%%;*}}
merge=$(sbatch --parsable --export=ALL --job-name={jname}-merge --dependency=afterok:"$array" \
  --output="$log_dir/slurm-merge-%j.log" \
  --wrap='exec "$USM_EXE" merge --list "$USM_OUT/{list}" --out "$USM_OUT"{force}')
printf 'array job %s ({n} tasks), merge job %s; merged output in %s\n' "$array" "${{merge%%;*}}" "$USM_OUT"
"#,
        exe = sh_quote(&p.exe.display().to_string()),
        study = sh_quote(&p.study.display().to_string()),
        out = sh_quote(&p.out.display().to_string()),
        cases = p.cases,
        cpt = p.cases_per_task,
        jname = crate::report::file_stem_safe(&p.name),
        last = n - 1,
        cpus = p.cpus.max(1),
        timeout = p.case_timeout_s,
        list = SHARD_LIST,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slurm_script_quotes_paths_once_and_lists_shards_in_a_file() {
        let p = SlurmPlan {
            exe: "/opt/usm study/usm-study".into(),
            study: "/w/it's $(x).toml".into(),
            out: "/w/out".into(),
            cases: 25,
            cases_per_task: 10,
            cpus: 2,
            case_timeout_s: 600.0,
            name: "gains\n$(x)".into(),
            force: true,
        };
        assert_eq!(p.tasks(), 3);
        let s = slurm_script(&p);
        assert!(
            s.contains("export USM_EXE='/opt/usm study/usm-study'\n"),
            "{s}"
        );
        assert!(
            s.contains(r"export USM_STUDY='/w/it'\''s $(x).toml'"),
            "{s}"
        );
        assert!(s.contains("--array=0-2 "), "{s}");
        assert!(s.contains("--time=105"), "{s}");
        assert!(s.contains("--shard slurm --resume --force --jobs 2"), "{s}");
        assert!(s.contains("shard-$SLURM_ARRAY_TASK_ID-of-3\"')"), "{s}");
        assert!(s.contains("--dependency=afterok:\"$array\""), "{s}");
        assert!(s.contains("merge --list \"$USM_OUT/shards.txt\" --out \"$USM_OUT\" --force'"));
        assert!(s.contains("# Slurm submission of study gains___x_:"), "{s}");
        assert_eq!(
            s.matches("$(x)").count(),
            1,
            "only inside the quoted study path: {s}"
        );
    }

    /// Issue 39: sbatch expands `%A`, `%a`, `%j` in `--output`; a `%` of the output path must
    /// reach it as `%%`, and every `--output` goes through that escaped folder.
    #[test]
    fn a_percent_in_the_output_path_is_escaped_for_sbatch() {
        let p = SlurmPlan {
            exe: "/x/usm-study".into(),
            study: "/w/s.toml".into(),
            out: "/w/50%A_%j it's".into(),
            cases: 4,
            cases_per_task: 2,
            cpus: 1,
            case_timeout_s: 0.0,
            name: "s".into(),
            force: false,
        };
        let s = slurm_script(&p);
        let lines: Vec<&str> = s
            .lines()
            .filter(|l| l.starts_with("export USM_OUT=") || l.starts_with("log_dir="))
            .collect();
        assert_eq!(lines.len(), 2, "{s}");
        let o = std::process::Command::new("bash")
            .arg("-c")
            .arg(format!(
                "{}
printf %s \"$log_dir\"",
                lines.join("\n")
            ))
            .output()
            .unwrap();
        assert_eq!(String::from_utf8_lossy(&o.stdout), "/w/50%%A_%%j it's");
        assert_eq!(s.matches("--output=\"$log_dir/").count(), 2, "{s}");
        assert!(!s.contains("--output=\"$USM_OUT"), "{s}");
    }

    #[test]
    fn a_shard_list_is_read_relative_to_its_file() {
        let d = tempfile::tempdir().unwrap();
        let f = d.path().join(SHARD_LIST);
        std::fs::write(&f, "shard-0-of-2\n\nshard-1-of-2\n/abs/x\n").unwrap();
        let v = read_shard_list(&f).unwrap();
        assert_eq!(v[0], d.path().join("shard-0-of-2"));
        assert_eq!(v[1], d.path().join("shard-1-of-2"));
        assert_eq!(v[2], Path::new("/abs/x"));
    }
}

//! Merging shard outputs into one: same study, raw rows concatenated, sorted by case id,
//! deduplicated by hash; then the final tables, the manifest and the report (under the output
//! directory's lock, see [`super::outdir`]; the merged output keeps no journal).

use std::path::{Path, PathBuf};

use super::error::StudyError;
use super::finish::finish_report;
use super::manifest::{now_rfc3339, read_manifest, write_manifest, Counts, Manifest};
use super::outdir;
use super::parse::load_study;
use super::records::{compact, write_tables, StatusCounts, PARTIAL_FILE, STUDY_COPY};
use super::tune::TuningHook;
use crate::report::{read_csv_typed, Table};

/// Merge shard outputs into `out`: check they come from the same study, concatenate their raw
/// rows, sort by case id, deduplicate by hash, and write the final tables, manifest and report
/// (the best/worst reruns of a study with `[tune]` at their tuned values through `tuning`).
pub fn merge(
    dirs: &[PathBuf],
    out: &Path,
    tuning: Option<TuningHook>,
) -> Result<(Manifest, Vec<String>), StudyError> {
    let start_time = now_rfc3339();
    let first_dir = dirs
        .first()
        .ok_or_else(|| StudyError::Input("merge needs at least one directory".into()))?;
    let manifests: Vec<Manifest> = dirs
        .iter()
        .map(|d| read_manifest(d))
        .collect::<Result<_, _>>()?;
    let m0 = &manifests[0];
    check_same_study(dirs, &manifests)?;
    let schema = m0.schema().map_err(StudyError::Input)?;
    let mut tables = Vec::new();
    for d in dirs {
        tables.push(read_csv_typed(&d.join(PARTIAL_FILE), &schema)?);
    }
    let raw = compact(&Table::concat(&tables)?, None)?;
    let _lock = outdir::lock(out)?;
    let mut warnings = outdir::claim(out, &m0.study_name, false)?;
    let table = write_tables(raw, out)?;
    if let Ok(text) = std::fs::read_to_string(first_dir.join(STUDY_COPY)) {
        std::fs::write(out.join(STUDY_COPY), text).map_err(|e| StudyError::io(out, e))?;
    }
    let mut m = m0.clone();
    m.start_time = start_time;
    m.end_time = now_rfc3339();
    m.shard = None;
    m.merged_from = dirs.iter().map(|d| d.display().to_string()).collect();
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
    let study = load_study(Path::new(&m.study_file))
        .ok()
        .filter(|s| s.hash == m.study_hash);
    warnings.extend(finish_report(out, &table, &m, study.as_ref(), tuning));
    // The merged rows are in cases.csv: no journal is left behind.
    let journal = out.join(PARTIAL_FILE);
    std::fs::remove_file(&journal).map_err(|e| StudyError::io(&journal, e))?;
    Ok((m, warnings))
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
    }
    Ok(())
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
}

impl SlurmPlan {
    /// Array tasks: `⌈cases / cases_per_task⌉`, at least 1.
    pub fn tasks(&self) -> usize {
        self.cases.div_ceil(self.cases_per_task.max(1)).max(1)
    }
}

/// A shell word quoted for bash (`'…'`, with `'` as `'\''`).
fn sh_quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

/// The submission script of a study on Slurm: a job array of [`SlurmPlan::tasks`] tasks, each
/// `usm-study sweep STUDY --shard slurm` into `OUT/shard-I-of-N` (resuming, so a requeued
/// task keeps its finished cases), then the merge into `OUT` as a job depending on the whole
/// array (`afterok`). Run it with `bash`; it prints the two job ids. `SBATCH_*` environment
/// variables (e.g. `SBATCH_PARTITION`) apply to both jobs as usual.
pub fn slurm_script(p: &SlurmPlan) -> String {
    let n = p.tasks();
    let exe = sh_quote(&p.exe.display().to_string());
    let study = sh_quote(&p.study.display().to_string());
    let out = sh_quote(&p.out.display().to_string());
    let time = if p.case_timeout_s > 0.0 {
        let minutes = (p.case_timeout_s * p.cases_per_task as f64 / 60.0).ceil() as u64 + 5;
        format!(" --time={minutes}")
    } else {
        String::new()
    };
    let shards: Vec<String> = (0..n)
        .map(|i| format!("\"$OUT\"/shard-{i}-of-{n}"))
        .collect();
    format!(
        r#"#!/usr/bin/env bash
# Slurm submission of study `{name}`: {cases} cases in a job array of {n} tasks
# ({cpt} cases per task), then a merge job after the whole array succeeded.
# Written by `usm-study sweep --emit-slurm`; run it with bash on a Slurm login node.
set -euo pipefail
EXE={exe}
STUDY={study}
OUT={out}
mkdir -p "$OUT"
array=$(sbatch --parsable --job-name={jname}-sweep --array=0-{last} \
  --cpus-per-task={cpus}{time} --output="$OUT/slurm-%A_%a.log" \
  --wrap="exec \"$EXE\" sweep \"$STUDY\" --shard slurm --resume --jobs {cpus} \
--case-timeout {timeout} --out \"$OUT/shard-\${{SLURM_ARRAY_TASK_ID}}-of-{n}\"")
array=${{array%%;*}}
merge=$(sbatch --parsable --job-name={jname}-merge --dependency=afterok:"$array" \
  --output="$OUT/slurm-merge-%j.log" \
  --wrap="exec \"$EXE\" merge {shards} --out \"$OUT\"")
echo "array job $array ({n} tasks), merge job ${{merge%%;*}}; merged output in $OUT"
"#,
        name = p.name,
        cases = p.cases,
        cpt = p.cases_per_task,
        jname = crate::report::file_stem_safe(&p.name),
        last = n - 1,
        cpus = p.cpus.max(1),
        timeout = p.case_timeout_s,
        shards = shards.join(" ").replace('"', "\\\""),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slurm_script_names_every_shard_once_and_merges_after_the_array() {
        let p = SlurmPlan {
            exe: "/opt/usm study/usm-study".into(),
            study: "/w/s.toml".into(),
            out: "/w/out".into(),
            cases: 25,
            cases_per_task: 10,
            cpus: 2,
            case_timeout_s: 600.0,
            name: "gains".into(),
        };
        assert_eq!(p.tasks(), 3);
        let s = slurm_script(&p);
        assert!(s.contains("EXE='/opt/usm study/usm-study'"), "{s}");
        assert!(s.contains("--array=0-2 "), "{s}");
        assert!(s.contains("--time=105"), "{s}");
        assert!(s.contains("--shard slurm --resume --jobs 2"), "{s}");
        assert!(s.contains("shard-\\${SLURM_ARRAY_TASK_ID}-of-3"), "{s}");
        assert!(s.contains("--dependency=afterok:\"$array\""), "{s}");
        for i in 0..3 {
            assert_eq!(s.matches(&format!("shard-{i}-of-3")).count(), 1, "{s}");
        }
    }
}

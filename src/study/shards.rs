//! Merging shard outputs into one: same study, raw rows concatenated, sorted by case id,
//! deduplicated by hash; then the final tables, the manifest and the report.

use std::path::{Path, PathBuf};

use super::error::StudyError;
use super::finish::finish_report;
use super::manifest::{now_rfc3339, read_manifest, write_manifest, Counts, Manifest};
use super::parse::load_study;
use super::records::{compact, write_tables, StatusCounts, PARTIAL_FILE, STUDY_COPY};
use crate::report::{read_csv_typed, Table};

/// Merge shard outputs into `out`: check they come from the same study, concatenate their raw
/// rows, sort by case id, deduplicate by hash, and write the final tables, manifest and report.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<(Manifest, Vec<String>), StudyError> {
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
    std::fs::create_dir_all(out).map_err(|e| StudyError::io(out, e))?;
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
    let mut warnings = Vec::new();
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
    warnings.extend(finish_report(out, &table, &m, study.as_ref()));
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

//! `simulate` of a scenario file with `[uncertainty]` (issue 22 item 1): after the nominal run,
//! the scenario in every sampled world, as a one-case study would run it (the same keys,
//! distributions and seeded worlds; docs/study-format.md). Writes `worlds.csv` (one row per
//! world: the parameter values, the tracked metrics, `success`, `missed`) and
//! `uncertainty.json` (the summaries `m_mean`, `m_std`, `m_p05`, `m_p95`, `m_worst` and
//! `success_probability`) beside the nominal run's outputs.

use std::path::Path;

use anyhow::Context;
use usm_study::batch::records::CASE_ID;
use usm_study::batch::robust::{split_worlds, RobustInfo, WORLDS_CSV};
use usm_study::batch::worker::Worker;
use usm_study::batch::worlds::SUCCESS_PROBABILITY;
use usm_study::report::{file_stem_safe, write_csv, ColumnData, Table};
use usm_study::scenario::Source;
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::expand;
use usm_study::study::parse::parse_study_table;

/// The file of the summaries over the worlds.
pub const UNCERTAINTY_JSON: &str = "uncertainty.json";

/// The scenario as a one-case study with its worlds, checked before anything runs.
pub struct Worlds {
    study: usm_study::study::Study,
    info: RobustInfo,
}

/// The scenario `table` (its `--set` overrides applied, `[uncertainty]` taken out as
/// `uncertainty`) as a one-case study: every error of the section, located in the file, before
/// the nominal run.
pub fn prepare(
    table: &toml::Table,
    uncertainty: toml::Table,
    src: &Source,
    name: &str,
) -> anyhow::Result<Worlds> {
    let mut study = toml::Table::new();
    let mut meta = toml::Table::new();
    meta.insert("name".into(), toml::Value::String(file_stem_safe(name)));
    study.insert("study".into(), toml::Value::Table(meta));
    let mut scenario_side = table.clone();
    let design = match scenario_side.remove("design") {
        Some(d) => d,
        None => {
            // `scenario.design`: a preset or a file relative to the scenario file.
            let d = table
                .get("scenario")
                .and_then(|s| s.get("design"))
                .and_then(|d| d.as_str())
                .unwrap_or("usm-paper");
            let rel = src.dir.join(d);
            let mut t = toml::Table::new();
            if rel.is_file() {
                t.insert(
                    "file".into(),
                    toml::Value::String(rel.display().to_string()),
                );
            } else {
                t.insert("preset".into(), toml::Value::String(d.to_string()));
            }
            toml::Value::Table(t)
        }
    };
    study.insert("design".into(), design);
    for (k, v) in scenario_side {
        study.insert(k, v);
    }
    study.insert("uncertainty".into(), toml::Value::Table(uncertainty));
    let study = parse_study_table(&src.doc, &study, Path::new(&src.origin))?;
    if study
        .uncertainty
        .as_ref()
        .is_some_and(|u| u.adaptive.is_some())
    {
        // One scenario has no verdict to decide: adaptive worlds are a study's.
        return Err(src
            .doc
            .err(
                "uncertainty.adaptive_worlds",
                "is for studies (more worlds for the designs whose verdict is not decided); a \
                 scenario file runs its `worlds`",
            )
            .into());
    }
    let info = RobustInfo::of(&study).context("the [uncertainty] section")?;
    Ok(Worlds { study, info })
}

/// Run the prepared scenario in its worlds; write `worlds.csv` and `uncertainty.json` into
/// `out`.
pub fn run_worlds(w: &Worlds, out: &Path) -> anyhow::Result<()> {
    let (study, info) = (&w.study, &w.info);
    let case = expand(study, None)?
        .into_iter()
        .next()
        .context("the scenario as a study has no case")?;
    let resolved = resolve_case(study, &case)?;
    let row = Worker::new().evaluate(study, &case, &resolved, None, None);
    let mut cases = Table::new().with(CASE_ID, ColumnData::I64(vec![0]))?;
    for (k, x) in row.metrics.iter() {
        cases.push(k, ColumnData::F64(vec![x]))?;
    }
    let worlds = split_worlds(&mut cases, info).context("no world ran")?;
    write_csv(&worlds, &out.join(WORLDS_CSV))?;
    let mut summary = serde_json::Map::new();
    for m in &info.metrics {
        for s in ["mean", "std", "p05", "p95", "worst"] {
            let k = format!("{m}_{s}");
            summary.insert(k.clone(), json_number(row.metrics.value(&k)));
        }
    }
    let p = row.metrics.value(SUCCESS_PROBABILITY);
    summary.insert(SUCCESS_PROBABILITY.into(), json_number(p));
    let doc = serde_json::json!({
        "worlds": info.worlds,
        "sampling": info.sampling,
        "params": info.params,
        "metrics": summary,
        "status": row.end.status().as_str(),
        "reason": row.reason,
    });
    // The one writer (issue 39): atomic and link-safe, like every other output.
    usm_study::report::atomic_write(
        &out.join(UNCERTAINTY_JSON),
        (serde_json::to_string_pretty(&doc)? + "\n").as_bytes(),
    )?;
    eprintln!(
        "[simulate] {} worlds: success probability {p:.3}; wrote {} and {}",
        info.worlds, WORLDS_CSV, UNCERTAINTY_JSON
    );
    Ok(())
}

/// A JSON number, or null for NaN and infinities.
fn json_number(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

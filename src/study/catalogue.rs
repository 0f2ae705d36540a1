//! The metric catalogue of a study: which metric names its cases report (design, static
//! `T(q)`, run and tuning columns), and the located error for a name that is none of them.

use super::runner::StudyMode;
use super::schema::Study;
use crate::evaluate::metrics::{AUTHORITY_COLUMNS, DESIGN_COLUMNS, TCM_COLUMNS};
use crate::evaluate::AUTHORITY_MARGIN;
use crate::input::document::Document;
use crate::input::keypath::did_you_mean;
use crate::input::located::InputError;

/// Whether `name` is a metric column the cases of `study` report: a design descriptor, a
/// static `T(q)` metric (with `[static]`), a run metric of the mode (`seg{k}_…` included) or a
/// per-case tuning column or an optimal-control bound column (`[ocp]`).
pub fn known_metric(name: &str, study: &Study) -> bool {
    DESIGN_COLUMNS.contains(&name)
        || (study.static_enabled
            && (TCM_COLUMNS.contains(&name) || AUTHORITY_COLUMNS.contains(&name)))
        || (study.static_enabled && study.mode.is_dynamic() && name == AUTHORITY_MARGIN)
        || scenario_mode(study.mode)
            .is_some_and(|m| crate::outcome::run_summary::is_run_metric(m, name))
        || study.tune_columns().iter().any(|c| c == name)
        || study.ocp_columns().iter().any(|c| c == name)
}

/// The closed-loop mode of a study mode (`None` for static studies).
fn scenario_mode(mode: StudyMode) -> Option<crate::scenario::Mode> {
    match mode {
        StudyMode::Static => None,
        StudyMode::Transport => Some(crate::scenario::Mode::Transport),
        StudyMode::Work => Some(crate::scenario::Mode::Work),
    }
}

/// The metric catalogue of a study (see [`known_metric`]), for messages.
pub fn metric_catalogue(study: &Study) -> Vec<String> {
    let mut v: Vec<String> = DESIGN_COLUMNS.iter().map(|s| s.to_string()).collect();
    if study.static_enabled {
        v.extend(
            TCM_COLUMNS
                .iter()
                .chain(&AUTHORITY_COLUMNS)
                .map(|s| s.to_string()),
        );
    }
    if let Some(m) = scenario_mode(study.mode) {
        v.extend(crate::outcome::run_summary::metric_catalogue(m));
    }
    if study.static_enabled && study.mode.is_dynamic() {
        v.push(AUTHORITY_MARGIN.to_string());
    }
    v.extend(study.tune_columns());
    v.extend(study.ocp_columns());
    v
}

/// The error for a metric name `name` at `key` that the study's cases do not report: the
/// mode, a "did you mean" hint when a catalogue name is close, and the catalogue.
pub fn unknown_metric(name: &str, key: &str, study: &Study, doc: &Document) -> InputError {
    let catalogue = metric_catalogue(study);
    if name.is_empty() {
        return doc.err(
            key,
            "is empty: name a metric, or leave the key out for the default",
        );
    }
    doc.err(
        key,
        format!(
            "unknown metric `{name}` for mode \"{}\"{}{}; valid: {}",
            study.mode,
            if study.static_enabled {
                " with [static]"
            } else {
                ""
            },
            did_you_mean(name, catalogue.iter().map(String::as_str)),
            catalogue.join(", ")
        ),
    )
}

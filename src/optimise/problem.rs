//! Problem files → a validated [`Problem`]: a study file (`[study]`, `[design]`, the scenario
//! side) whose sweep axes are replaced by the optimiser's sections, read by
//! [`crate::study::tune_spec_parse::parse_spec`]: `[[param]]`, `[[variant]]`, `[objective]` with
//! `[[objective.term]]`, `[[constraint]]` and `[solver]`. The format is documented in
//! `docs/optimise.md`; the sections' types live in `study` (what to run), shared with a
//! sweep's `[tune]`.

use std::path::Path;

use crate::input::document::Document;
use crate::input::located::{InputError, Location};
pub use crate::study::parse::metric_catalogue;
use crate::study::parse::parse_study_table;
pub use crate::study::tune_spec::{
    Combine, Constraint, Method, Objective, Op, Polish, SolverSettings, Spec, Term, Variant,
    MAX_EVALS, MAX_PARTICLES, SPEC_KEYS, SUCCESS_PROBABILITY,
};
pub use crate::study::tune_spec_parse::parse_spec;
use crate::study::Study;

/// A validated problem file.
#[derive(Clone, Debug)]
pub struct Problem {
    /// The study part (design, scenario side, name, seed, output); no axes.
    pub study: Study,
    /// The optimiser's sections.
    pub spec: Spec,
}

/// Read and validate a problem file.
pub fn load_problem(path: &Path) -> Result<Problem, InputError> {
    let origin = path.display().to_string();
    let text = crate::input::document::read_text(path).map_err(|e| InputError {
        at: Location::origin(&origin),
        error: format!("cannot read the problem file: {e}"),
    })?;
    parse_problem(&text, path)
}

/// Parse and validate problem text; `path` names the origin and anchors relative files.
pub fn parse_problem(text: &str, path: &Path) -> Result<Problem, InputError> {
    let doc = Document::parse(text, &path.display().to_string())?;
    let mut table: toml::Table = doc.deserialize()?;
    let mut spec_table = toml::Table::new();
    for k in SPEC_KEYS {
        if let Some(v) = table.remove(k) {
            spec_table.insert(k.to_string(), v);
        }
    }
    if table.contains_key("tune") {
        return Err(doc.err(
            "tune",
            "[tune] tunes each case of a sweep; a problem file optimises its own [[param]]",
        ));
    }
    for (k, what) in [("axis", "[[axis]]"), ("doe", "[doe]")] {
        if table.contains_key(k) {
            return Err(doc.err(
                k,
                format!(
                    "{what} belongs to a sweep's study file; a problem file varies its \
                     [[param]] entries (and [[variant]] scenarios) and would ignore it"
                ),
            ));
        }
    }
    let study = parse_study_table(&doc, &table, path)?;
    let spec = parse_spec(&doc, &spec_table, "", &study)?;
    Ok(Problem { study, spec })
}

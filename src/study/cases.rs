//! Resolving a case: the study's design and scenario-side tables with the case's axis values
//! applied, its seed and its hashes.

use super::doe::Case;
use super::hash::{case_hashes, unresolved_case_hash};
use super::runner::{method_control, SettingsError};
use super::schema::{Study, Target};
use crate::evaluate::{apply_overrides, Override, OverrideError, Side};
use crate::input::keypath::{set, Seg, SetError};
use crate::model::design::DesignError;
use crate::sampling::derive_seed;

/// A case with every override applied.
#[derive(Clone, Debug, PartialEq)]
pub struct Resolved {
    /// Design table.
    pub design: toml::Table,
    /// Scenario-side table (defaults filled in).
    pub scenario: toml::Table,
    /// Case seed `derive_seed(study_seed, case_id)`.
    pub seed: u64,
    /// Stable case hash (hex, 128 bits).
    pub hash: String,
    /// Hash of the design table alone (vehicle cache key).
    pub design_hash: String,
}

/// Why a case's overrides do not apply to the study's tables: the reason the case is skipped.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// An axis value cannot be set (an index beyond an array, a value of the wrong shape).
    #[error(transparent)]
    Set(#[from] SetError),
    /// The generator cannot build the design whose thrusters the case edits.
    #[error("{0}")]
    Design(#[source] DesignError),
    /// The case's `control.method` gives no valid `[control]` table.
    #[error(transparent)]
    Control(#[from] SettingsError),
}

/// `value` written at `target` (as named `name`): the typed override of an axis value, a
/// world's parameter or a validation variant's key ([`crate::evaluate::overrides`]).
pub fn override_of(name: &str, target: &Target, value: &toml::Value) -> Override {
    let (side, path) = match target {
        Target::Design(p) => (Side::Design, &p.0),
        Target::Scenario(p) => (Side::Scenario, &p.0),
    };
    Override {
        side,
        path: path.clone(),
        value: value.clone(),
        shown: name.to_string(),
    }
}

/// The typed overrides of `(name, target, value)` triples, in order.
pub fn overrides_of<'a>(
    items: impl IntoIterator<Item = (&'a str, &'a Target, &'a toml::Value)>,
) -> Vec<Override> {
    items
        .into_iter()
        .map(|(n, t, v)| override_of(n, t, v))
        .collect()
}

impl From<OverrideError> for CaseError {
    fn from(e: OverrideError) -> Self {
        match e {
            OverrideError::Set(e) => CaseError::Set(e),
            OverrideError::Design(e) => CaseError::Design(e),
        }
    }
}

/// Apply a case's overrides to the study's tables. `Err` is the reason the case is skipped
/// (an index beyond an array, a design the generator cannot build for thruster overrides).
/// The axis values are applied by the one road for variation
/// ([`crate::evaluate::apply_overrides`]), then a `control.method` axis writes out its
/// method's `[control]` ([`method_axis_control`]).
pub fn resolve_case(study: &Study, case: &Case) -> Result<Resolved, CaseError> {
    let mut design = study.design.clone();
    let mut scenario = study.scenario_full.clone();
    let overrides = overrides_of(
        study
            .axes
            .iter()
            .zip(&case.values)
            .map(|(a, v)| (a.name.as_str(), &a.target, v)),
    );
    apply_overrides(&mut design, &mut scenario, &overrides)?;
    if let Some(c) = method_axis_control(study, case)? {
        scenario.insert("control".into(), toml::Value::Table(c));
    }
    Ok(resolved(study, design, scenario, case.id))
}

/// The study's own tables as case `id`, no axis value applied (the base an optimiser's point
/// varies, [`crate::optimise`]).
pub fn base_case(study: &Study, id: usize) -> Resolved {
    resolved(study, study.design.clone(), study.scenario_full.clone(), id)
}

/// Case `id` of `study` with tables `design` and `scenario`: its seed and hashes.
fn resolved(study: &Study, design: toml::Table, scenario: toml::Table, id: usize) -> Resolved {
    let seed = derive_seed(study.seed, id as u64);
    let (hash, design_hash) = match (&study.tune, study.robust_table.is_empty()) {
        (None, true) => case_hashes(&design, &scenario, seed),
        (t, _) => {
            // A case is tuned by the study's `[tune]` and meets its worlds and validation
            // variants: its row depends on them.
            let mut hashed = scenario.clone();
            if let Some(t) = t {
                // `[tune] race` changes what a tuning costs, never what it finds: not hashed.
                let mut t = t.clone();
                t.remove("race");
                hashed.insert("tune".into(), toml::Value::Table(t));
            }
            if !study.robust_table.is_empty() {
                hashed.insert(
                    "robust".into(),
                    toml::Value::Table(study.robust_table.clone()),
                );
            }
            (
                case_hashes(&design, &hashed, seed).0,
                case_hashes(&design, &scenario, seed).1,
            )
        }
    };
    Resolved {
        design,
        scenario,
        seed,
        hash,
        design_hash,
    }
}

/// With an axis over `control.method` (transport): the case's `[control]` written out from
/// its method's Table III row, with the study's own `[control]` keys and the case's other
/// `control.…` values on top ([`method_control`]); `None` without such an axis (the study's
/// own method was resolved when the file was parsed).
fn method_axis_control(study: &Study, case: &Case) -> Result<Option<toml::Table>, CaseError> {
    method_control_of(
        study,
        study
            .axes
            .iter()
            .zip(&case.values)
            .map(|(a, v)| (a.name.as_str(), &a.target, v)),
    )
}

/// [`method_axis_control`] of the varied keys `values` (`(name, target, value)`, in order) on
/// top of `study`'s tables: when one of them is `control.method`, that method's `[control]`
/// with the study's own `[control]` keys and the other `control.…` values on top; else `None`.
/// The optimiser's points and scenarios vary a case this way ([`crate::optimise`]).
pub fn method_control_of<'a>(
    study: &Study,
    values: impl IntoIterator<Item = (&'a str, &'a Target, &'a toml::Value)> + Clone,
) -> Result<Option<toml::Table>, CaseError> {
    let on_control = |t: &Target| match t {
        Target::Scenario(p) => matches!(p.0.first(), Some(Seg::Key(k)) if k == "control"),
        Target::Design(_) => false,
    };
    let method_axis = values.clone().into_iter().any(|(_, t, _)| {
        on_control(t) && matches!(t, Target::Scenario(p) if p.0.len() == 2 && matches!(&p.0[1], Seg::Key(k) if k == "method"))
    });
    if !method_axis {
        return Ok(None);
    }
    let mut own = toml::Table::new();
    own.insert(
        "control".into(),
        study
            .scenario
            .get("control")
            .cloned()
            .unwrap_or_else(|| toml::Value::Table(toml::Table::new())),
    );
    for (name, t, v) in values {
        if let (true, Target::Scenario(p)) = (on_control(t), t) {
            set(&mut own, &p.0, v.clone(), name)?;
        }
    }
    Ok(method_control(study.mode, own.get("control")).transpose()?)
}

/// The hash of a case: its resolved hash, or for a case whose overrides do not apply a hash
/// of the study, the id and the axis values.
pub fn case_hash(study: &Study, case: &Case, resolved: &Result<Resolved, CaseError>) -> String {
    match resolved {
        Ok(r) => r.hash.clone(),
        Err(_) => unresolved_case_hash(&study.hash, case.id, &case.values),
    }
}

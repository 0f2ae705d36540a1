//! Resolving a case: the study's design and scenario-side tables with the case's axis values
//! applied, its seed and its hashes.

use super::doe::Case;
use super::hash::{case_hashes, unresolved_case_hash};
use super::runner::{method_control, SettingsError};
use super::schema::{Study, Target};
use crate::input::keypath::{set, Seg, SetError};
use crate::model::design::{parse_design_table, thrusters_to_toml, DesignError};
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

/// Apply a case's overrides to the study's tables. `Err` is the reason the case is skipped
/// (an index beyond an array, a design the generator cannot build for thruster overrides).
pub fn resolve_case(study: &Study, case: &Case) -> Result<Resolved, CaseError> {
    let mut design = study.design.clone();
    let mut scenario = study.scenario_full.clone();
    let mut thruster_edits = Vec::new();
    for (a, v) in study.axes.iter().zip(&case.values) {
        match &a.target {
            Target::Design(p) => {
                if matches!(p.0.first(), Some(Seg::Key(k)) if k == "thruster") {
                    thruster_edits.push((a, p, v));
                } else {
                    set(&mut design, &p.0, v.clone(), &a.name)?;
                }
            }
            Target::Scenario(p) => set(&mut scenario, &p.0, v.clone(), &a.name)?,
        }
    }
    if !thruster_edits.is_empty() && study.generator && !design.contains_key("thruster") {
        // Write the generated thrusters out so that they can be edited one by one.
        let v = parse_design_table(&design, "generated design").map_err(CaseError::Design)?;
        design.insert("thruster".into(), thrusters_to_toml(&v));
    }
    for (a, p, v) in thruster_edits {
        set(&mut design, &p.0, v.clone(), &a.name)?;
    }
    if let Some(c) = method_axis_control(study, case)? {
        scenario.insert("control".into(), toml::Value::Table(c));
    }
    let seed = derive_seed(study.seed, case.id as u64);
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
    Ok(Resolved {
        design,
        scenario,
        seed,
        hash,
        design_hash,
    })
}

/// With an axis over `control.method` (transport): the case's `[control]` written out from
/// its method's Table III row, with the study's own `[control]` keys and the case's other
/// `control.…` values on top ([`method_control`]); `None` without such an axis (the study's
/// own method was resolved when the file was parsed).
fn method_axis_control(study: &Study, case: &Case) -> Result<Option<toml::Table>, CaseError> {
    let on_control = |t: &Target| match t {
        Target::Scenario(p) => matches!(p.0.first(), Some(Seg::Key(k)) if k == "control"),
        Target::Design(_) => false,
    };
    let method_axis = study.axes.iter().any(|a| {
        on_control(&a.target) && matches!(&a.target, Target::Scenario(p) if p.0.len() == 2 && matches!(&p.0[1], Seg::Key(k) if k == "method"))
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
    for (a, v) in study.axes.iter().zip(&case.values) {
        if let (true, Target::Scenario(p)) = (on_control(&a.target), &a.target) {
            set(&mut own, &p.0, v.clone(), &a.name)?;
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

/// Case `r` with overrides applied (a world's values, a validation variant's keys): new
/// tables and a new design hash (the vehicle cache key), the case hash and seed unchanged.
pub fn apply_overrides<'a>(
    r: &Resolved,
    overrides: impl IntoIterator<Item = (&'a str, &'a Target, &'a toml::Value)>,
) -> Result<Resolved, SetError> {
    let mut out = r.clone();
    let mut design_changed = false;
    for (name, target, value) in overrides {
        match target {
            Target::Design(p) => {
                set(&mut out.design, &p.0, value.clone(), name)?;
                design_changed = true;
            }
            Target::Scenario(p) => set(&mut out.scenario, &p.0, value.clone(), name)?,
        }
    }
    if design_changed {
        out.design_hash = case_hashes(&out.design, &out.scenario, out.seed).1;
    }
    Ok(out)
}

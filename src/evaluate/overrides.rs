//! One road for variation (issue 37 item 2): whatever varies a case — a sweep axis, a sampled
//! world, a validation variant, a fault rerun, a tuning or optimiser point, `--set` — is a list
//! of typed [`Override`]s on the case's design and scenario-side tables, applied here, in
//! order, by [`apply_overrides`]. The evaluator applies a case's list before it builds the
//! vehicle ([`super::CaseInput::overrides`]); the study applies its axis values with the same
//! function when it resolves a case, and checks every list against a reference case when the
//! study is loaded (`study::admit`), so a key that does not apply is refused by `--dry-run`.

use crate::input::keypath::{set, Seg, SetError};
use crate::model::design::{parse_design_table, thrusters_to_toml, DesignError};

/// Which table an override edits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The design table.
    Design,
    /// The scenario-side table.
    Scenario,
}

/// One edit applied on top of a case's tables before it is evaluated: `path` in the `side`
/// table set to `value` (`crate::input::keypath::set`: an integer written where a float is
/// becomes a float; missing tables on the way are created; an index must exist).
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// The table edited.
    pub side: Side,
    /// The key path inside it.
    pub path: Vec<Seg>,
    /// The value written.
    pub value: toml::Value,
    /// The key as a user wrote it (for messages).
    pub shown: String,
}

impl Override {
    /// `path` of the scenario-side table set to `value`, shown as `shown`.
    pub fn scenario(path: Vec<Seg>, value: toml::Value, shown: impl Into<String>) -> Self {
        Override {
            side: Side::Scenario,
            path,
            value,
            shown: shown.into(),
        }
    }

    /// Whether it edits a thruster of the design (`design.thruster[i]…`): applied after the
    /// design's other edits, on the thrusters a generator writes out ([`apply_overrides`]).
    fn edits_thrusters(&self) -> bool {
        self.side == Side::Design
            && matches!(self.path.first(), Some(Seg::Key(k)) if k == "thruster")
    }
}

/// An override list that does not apply to a case's tables (the case is skipped; the text
/// names the key).
#[derive(Debug, thiserror::Error)]
pub enum OverrideError {
    /// A value cannot be set (an index beyond an array, a value of the wrong shape).
    #[error(transparent)]
    Set(#[from] SetError),
    /// The generator cannot build the design whose thrusters an override edits.
    #[error("{0}")]
    Design(#[source] DesignError),
}

/// Edits applied on top of a case's tables; empty for a nominal case.
pub type Overrides = [Override];

/// Apply `overrides` to `design` and `scenario`, in order, except that edits of the design's
/// thrusters come after its other edits: when the base design uses the generator form and
/// lists no thrusters, the generated thrusters are first written out (`[[thruster]]`) so that
/// they can be edited one by one. Returns whether the design table changed. On `Err` the
/// tables are partly edited and must be dropped.
pub fn apply_overrides(
    design: &mut toml::Table,
    scenario: &mut toml::Table,
    overrides: &Overrides,
) -> Result<bool, OverrideError> {
    let generator = design.contains_key("generator");
    let mut design_changed = false;
    for o in overrides.iter().filter(|o| !o.edits_thrusters()) {
        let t = match o.side {
            Side::Design => {
                design_changed = true;
                &mut *design
            }
            Side::Scenario => &mut *scenario,
        };
        set(t, &o.path, o.value.clone(), &o.shown)?;
    }
    let mut thrusters = overrides.iter().filter(|o| o.edits_thrusters()).peekable();
    if thrusters.peek().is_some() && generator && !design.contains_key("thruster") {
        let v = parse_design_table(design, "generated design").map_err(OverrideError::Design)?;
        design.insert("thruster".into(), thrusters_to_toml(&v));
    }
    for o in thrusters {
        design_changed = true;
        set(design, &o.path, o.value.clone(), &o.shown)?;
    }
    Ok(design_changed)
}

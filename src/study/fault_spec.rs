//! The `[faults]` section of a study file (issue 24): the single fault every thruster of every
//! case gets in its fault reruns (`crate::batch::faults`), as a scenario `[fault]`
//! (`crate::scenario::fault`) for thruster `j`.
//!
//! ```toml
//! [faults]
//! single = true      # one thruster at a time (the only form)
//! at = 30.0          # fault time [s] (required)
//! kind = "dead"      # dead | stuck | derated
//! # value = 0.5      # stuck: thrust [N] (default: the thrust at the fault); derated: factor
//! informed = true    # the allocator is reconfigured at the fault
//! ```

use crate::input::document::{deserialize_table, Document};
use crate::input::located::InputError;
use crate::scenario::fault::{FaultKind, FaultSpec, ThrusterRef};
use serde::Deserialize;

/// The `[faults]` section of a study: which single fault every thruster of every case gets.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultStudy {
    /// Fault time [s].
    pub at: f64,
    /// What the fault does.
    pub kind: FaultKind,
    /// `stuck`: the thrust [N] (default: the thrust at the fault time); `derated`: the factor.
    pub value: Option<f64>,
    /// Whether the allocator is reconfigured at the fault.
    pub informed: bool,
}

/// The keys of a scenario `[fault]` table, which studies may set (`fault.<key>`).
pub const FAULT_KEYS: [&str; 5] = ["thruster", "at", "kind", "value", "informed"];

fn yes() -> bool {
    true
}

fn dead() -> FaultKind {
    FaultKind::Dead
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FaultsFile {
    #[serde(default = "yes")]
    single: bool,
    at: f64,
    #[serde(default = "dead")]
    kind: FaultKind,
    value: Option<f64>,
    #[serde(default = "yes")]
    informed: bool,
}

impl FaultStudy {
    /// The scenario `[fault]` of thruster `j`.
    pub fn spec(&self, j: usize) -> FaultSpec {
        FaultSpec {
            thruster: ThrusterRef::Index(j as i64),
            at: self.at,
            kind: self.kind,
            value: self.value,
            informed: self.informed,
        }
    }
}

/// Parse `[faults]` of a study file (`None` without one) of a closed-loop mode (`dynamic`);
/// errors are placed in `doc`.
pub fn parse_faults(
    table: Option<&toml::Table>,
    dynamic: bool,
    doc: &Document,
) -> Result<Option<FaultStudy>, InputError> {
    let Some(t) = table else {
        return Ok(None);
    };
    if !dynamic {
        return Err(doc.err("faults", "thruster faults need a closed-loop mode"));
    }
    let f: FaultsFile = deserialize_table(t, "faults").map_err(|e| doc.place(e))?;
    if !f.single {
        return Err(doc.err(
            "faults.single",
            "only single faults are supported (single = true)",
        ));
    }
    let fs = FaultStudy {
        at: f.at,
        kind: f.kind,
        value: f.value,
        informed: f.informed,
    };
    fs.spec(0).validate().map_err(|mut e| {
        e.key = e.key.replacen("fault.", "faults.", 1);
        doc.place(e)
    })?;
    Ok(Some(fs))
}

//! What a key path edits: the design table or the scenario side ([`Target`]), the resolved
//! form of every axis, uncertain parameter, variant key and tuning parameter.

use crate::input::keypath::KeyPath;

/// Which table an axis edits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// A key of the design table (path relative to the design table, aliases resolved).
    Design(KeyPath),
    /// A key of the scenario-side table (`scenario`, `static`, `control`, …).
    Scenario(KeyPath),
}

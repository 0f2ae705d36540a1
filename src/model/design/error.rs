//! What a design error says: its kind and message, with the [`Location`] around it.

use crate::input::located::{InputError, Located, Location};

/// What kind of problem a [`DesignError`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DesignErrorKind {
    /// The file could not be read.
    Io,
    /// The argument is neither an existing file nor a preset name.
    NotFound,
    /// The text is not valid TOML.
    Syntax,
    /// Valid TOML that does not fit the schema: unknown key, wrong type, missing key,
    /// non-finite number, conflicting forms.
    Schema,
    /// Fits the schema but describes an invalid vehicle (e.g. negative mass, zero thrust
    /// direction, a thruster on a body that does not exist).
    Invalid,
}

/// What is wrong with a design (its place is the [`Located`] around it).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct DesignFault {
    /// What kind of problem this is.
    pub kind: DesignErrorKind,
    /// What is wrong.
    pub message: String,
}

/// An error in a design file: where it is ([`Location`]: origin, line and column when
/// known, key path in file terms such as `thruster[2].direction`) and what is wrong.
///
/// Displays as `origin:line:column: key: message`, omitting the position when unknown
/// (e.g. for designs built from an in-memory table) and the key when there is none.
pub type DesignError = Located<DesignFault>;

/// A design error of `kind` tied to no key or line of `origin`.
pub(super) fn unplaced(kind: DesignErrorKind, origin: &str, message: String) -> DesignError {
    Located {
        at: Location::origin(origin),
        error: DesignFault { kind, message },
    }
}

/// A TOML syntax error from the input layer as a design error.
pub(super) fn syntax(e: InputError) -> DesignError {
    e.map(|message| DesignFault {
        kind: DesignErrorKind::Syntax,
        message,
    })
}

impl From<DesignError> for InputError {
    /// The same place, the message alone (the kind matters only to the design's own tests).
    fn from(e: DesignError) -> Self {
        e.map(|f| f.message)
    }
}

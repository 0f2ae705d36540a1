//! The import's error ([`UrdfError`]: file, line, element) and its ledger entries
//! ([`Inferred`]).

use thiserror::Error;

/// A bad URDF: the file, the 1-based line of the element, the element and what is wrong.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{file}:{line}: {element}: {message}")]
pub struct UrdfError {
    /// File name (or origin label).
    pub file: String,
    /// 1-based line the element starts on.
    pub line: usize,
    /// The element, e.g. `<joint name="q1">`.
    pub element: String,
    /// What is wrong.
    pub message: String,
}

/// One value of an imported design the file did not give: filled by the project's rules.
#[derive(Clone, Debug, PartialEq)]
pub struct Inferred {
    /// What (e.g. `body[0].volume (base_link)`).
    pub key: String,
    /// The rule applied.
    pub note: String,
}

impl Inferred {
    pub(crate) fn new(key: impl Into<String>, note: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            note: note.into(),
        }
    }
}

//! The input layer: every user file (design, scenario, study TOML) and every command-line
//! override goes through here, so that errors read the same way everywhere:
//! `file:line:col: key: message`.
//!
//! - [`located`]: [`located::Location`] and [`located::Located`], the location wrapped
//!   around any error; [`located::KeyError`] for a problem at a key not yet placed in a file.
//! - [`document`]: [`document::Document`], a TOML text as a located tree (the span of every
//!   key path), mapping serde error spans to key paths and key paths back to lines.
//! - [`keypath`]: [`keypath::KeyPath`], the one key-path grammar (sweep axes, `--set`,
//!   error keys) and the table operations on it.

pub mod document;
pub mod keypath;
pub mod located;

//! Key positions in a study file, for located error messages: a line scanner over table
//! headers (`[a.b]`, `[[a]]` with array indices) and `key = value` lines. Keys inside inline
//! tables and multi-line values resolve to their parent's line.

use std::collections::HashMap;

use super::error::InputError;
use crate::diag::{line_col, one_line};

/// Key paths of a document with their positions: a line scanner over table headers
/// (`[a.b]`, `[[a]]` with array indices) and `key = value` lines. Keys inside inline tables
/// and multi-line values resolve to their parent's line.
pub(crate) struct Spans {
    /// The file (or other origin) the positions refer to.
    pub(crate) origin: String,
    text: String,
    /// `(path, byte offset of the key)`.
    entries: Vec<(String, usize)>,
}

fn strip_key(k: &str) -> String {
    k.split('.')
        .map(|p| p.trim().trim_matches('"').trim_matches('\''))
        .collect::<Vec<_>>()
        .join(".")
}

impl Spans {
    /// Index `text` (which must be valid TOML: a syntax error is returned located).
    pub(crate) fn parse(text: &str, origin: &str) -> Result<Spans, InputError> {
        let mut s = Spans {
            origin: origin.to_string(),
            text: text.to_string(),
            entries: Vec::new(),
        };
        if let Err(e) = toml::from_str::<toml::Table>(text) {
            return Err(s.at_offset(
                e.span().map(|r| r.start),
                "",
                format!("TOML syntax error: {}", one_line(e.message())),
            ));
        }
        s.scan();
        Ok(s)
    }

    fn scan(&mut self) {
        let mut header = String::new();
        let mut arrays: HashMap<String, usize> = Default::default();
        let mut depth: i64 = 0;
        let mut offset = 0usize;
        let translate = |name: &str, arrays: &HashMap<String, usize>| {
            let mut out = String::new();
            let mut plain = String::new();
            for part in name.split('.') {
                if !plain.is_empty() {
                    plain.push('.');
                    out.push('.');
                }
                plain.push_str(part);
                out.push_str(part);
                if let Some(i) = arrays.get(&plain) {
                    out.push_str(&format!("[{i}]"));
                }
            }
            out
        };
        for line in self.text.split_inclusive('\n') {
            let start = offset;
            offset += line.len();
            let code = line.split('#').next().unwrap_or("");
            if depth > 0 {
                depth += code.matches(['[', '{']).count() as i64
                    - code.matches([']', '}']).count() as i64;
                continue;
            }
            let t = code.trim_start();
            let lead = code.len() - t.len();
            let t = t.trim_end();
            if t.is_empty() {
                continue;
            }
            if let Some(name) = t.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
                let name = strip_key(name);
                let base = translate(&name, &arrays);
                let base = base
                    .strip_suffix(&format!("[{}]", arrays.get(&name).copied().unwrap_or(0)))
                    .map(str::to_string)
                    .unwrap_or(base);
                let idx = arrays
                    .entry(name.clone())
                    .and_modify(|i| *i += 1)
                    .or_insert(0);
                header = format!("{base}[{idx}]");
                self.entries.push((header.clone(), start + lead));
                continue;
            }
            if let Some(name) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
                header = translate(&strip_key(name), &arrays);
                self.entries.push((header.clone(), start + lead));
                continue;
            }
            if let Some((k, v)) = t.split_once('=') {
                let key = strip_key(k);
                let path = if header.is_empty() {
                    key
                } else {
                    format!("{header}.{key}")
                };
                self.entries.push((path, start + lead));
                depth +=
                    v.matches(['[', '{']).count() as i64 - v.matches([']', '}']).count() as i64;
                depth = depth.max(0);
            }
        }
    }

    fn at_offset(&self, offset: Option<usize>, key: &str, message: String) -> InputError {
        let (line, column) = match offset {
            Some(o) => {
                let (l, c) = line_col(&self.text, o);
                (Some(l), Some(c))
            }
            None => (None, None),
        };
        InputError {
            origin: self.origin.clone(),
            line,
            column,
            key: key.to_string(),
            message,
        }
    }

    /// An error at `key` (positioned at the key or its nearest ancestor in the document).
    pub(crate) fn err(&self, key: &str, message: impl Into<String>) -> InputError {
        let mut p = key;
        let offset = loop {
            if let Some(e) = self.entries.iter().find(|e| e.0 == p) {
                break Some(e.1);
            }
            match p.rfind(['.', '[']) {
                Some(i) => p = &p[..i],
                None => break None,
            }
        };
        self.at_offset(offset, key, message.into())
    }

    /// A serde error: positioned by its span, keyed by the last entry starting at or before it.
    pub(crate) fn serde(&self, e: &toml::de::Error) -> InputError {
        let offset = e.span().map(|s| s.start);
        let key = offset
            .and_then(|o| {
                self.entries
                    .iter()
                    .filter(|(_, s)| *s <= o)
                    .max_by_key(|(_, s)| *s)
                    .map(|(p, _)| p.clone())
            })
            .unwrap_or_default();
        self.at_offset(offset, &key, one_line(e.message()))
    }
}

#[cfg(test)]
#[path = "spans_tests.rs"]
mod tests;

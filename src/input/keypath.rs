//! Key paths into TOML tables (`design.thruster[2].position[0]`, `control.W[3]`): the one
//! grammar behind sweep axes, `--set KEY=VALUE` overrides, error locations and the optimiser's
//! parameters, with the `toml::Table` operations on them: look-up, assignment with type
//! coercion, and the flattened list of valid paths of a table.
//!
//! Grammar: `segment ('.' segment)*`, `segment = key ('[' index ']')*`, `key` made of ASCII
//! letters, digits, `_` and `-`, `index` a decimal integer. A *pattern* is a path with every
//! index replaced by `[]`; valid-name checks compare patterns, and index ranges are checked
//! per case (an index beyond an array's length skips that case).

use std::collections::BTreeSet;
use std::fmt;

/// One step of a path.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Seg {
    /// A table key.
    Key(String),
    /// An array index.
    Index(usize),
}

/// A parsed parameter path.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct KeyPath(pub Vec<Seg>);

impl fmt::Display for KeyPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Seg::Key(k) if i == 0 => f.write_str(k)?,
                Seg::Key(k) => write!(f, ".{k}")?,
                Seg::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// Longest accepted path (characters) and largest accepted index.
const MAX_LEN: usize = 512;
const MAX_INDEX: usize = 1_000_000;

/// Why a key path does not parse (positions are 1-based characters of `path`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum KeyPathError {
    /// The path is empty.
    #[error("empty parameter path")]
    Empty,
    /// The path is longer than the limit.
    #[error("parameter path longer than {MAX_LEN} characters")]
    TooLong,
    /// A key name was expected.
    #[error("`{path}`: expected a key name at character {at}")]
    ExpectedKey {
        /// The path as written.
        path: String,
        /// Position.
        at: usize,
    },
    /// `[` not followed by digits and `]`.
    #[error("`{path}`: expected `[index]` with a non-negative integer at character {at}")]
    BadIndex {
        /// The path as written.
        path: String,
        /// Position of the `[`.
        at: usize,
    },
    /// An index beyond the limit.
    #[error("`{path}`: index too large at character {at}")]
    IndexTooLarge {
        /// The path as written.
        path: String,
        /// Position of the first digit.
        at: usize,
    },
    /// A character that no rule of the grammar accepts there.
    #[error("`{path}`: unexpected character `{found}` at position {at}")]
    Unexpected {
        /// The path as written.
        path: String,
        /// The character.
        found: char,
        /// Position.
        at: usize,
    },
}

/// Why [`set`] cannot assign a path in a table.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SetError {
    /// The path does not start with a key.
    #[error("`{shown}`: a path starts with a key")]
    NoKey {
        /// The path as the user wrote it.
        shown: String,
    },
    /// An index beyond the array.
    #[error("`{shown}`: index {index} is out of range, `{at}` has {len} element{}", if *.len == 1 { "" } else { "s" })]
    OutOfRange {
        /// The path as the user wrote it.
        shown: String,
        /// The index.
        index: usize,
        /// The array's path.
        at: String,
        /// The array's length.
        len: usize,
    },
    /// A key below something that is not a table.
    #[error("`{shown}`: `{at}` is a {found}, not a table with key `{key}`")]
    NotATable {
        /// The path as the user wrote it.
        shown: String,
        /// The path of the value.
        at: String,
        /// Its TOML type.
        found: &'static str,
        /// The key asked for.
        key: String,
    },
    /// An index into something that is not an array.
    #[error("`{shown}`: `{at}` is a {found}, not an array to index with [{index}]")]
    NotAnArray {
        /// The path as the user wrote it.
        shown: String,
        /// The path of the value.
        at: String,
        /// Its TOML type.
        found: &'static str,
        /// The index asked for.
        index: usize,
    },
}

/// The message of a key-path error, for callers that report messages (a located
/// [`crate::input::located::InputError`], a skipped case's reason).
impl From<KeyPathError> for String {
    fn from(e: KeyPathError) -> String {
        e.to_string()
    }
}

/// The message of a [`SetError`] (see `From<KeyPathError> for String`).
impl From<SetError> for String {
    fn from(e: SetError) -> String {
        e.to_string()
    }
}

impl KeyPath {
    /// Parse a path; the error says what is wrong and where. Never panics.
    pub fn parse(s: &str) -> Result<KeyPath, KeyPathError> {
        if s.is_empty() {
            return Err(KeyPathError::Empty);
        }
        if s.len() > MAX_LEN {
            return Err(KeyPathError::TooLong);
        }
        let bytes = s.as_bytes();
        let mut segs = Vec::new();
        let mut i = 0;
        let is_key = |b: u8| b.is_ascii_alphanumeric() || b == b'_' || b == b'-';
        loop {
            let start = i;
            while i < bytes.len() && is_key(bytes[i]) {
                i += 1;
            }
            if i == start {
                return Err(KeyPathError::ExpectedKey {
                    path: s.to_string(),
                    at: start + 1,
                });
            }
            segs.push(Seg::Key(s[start..i].to_string()));
            while i < bytes.len() && bytes[i] == b'[' {
                let open = i;
                i += 1;
                let d0 = i;
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
                if i == d0 || i >= bytes.len() || bytes[i] != b']' {
                    return Err(KeyPathError::BadIndex {
                        path: s.to_string(),
                        at: open + 1,
                    });
                }
                let n: usize = s[d0..i]
                    .parse()
                    .ok()
                    .filter(|n| *n <= MAX_INDEX)
                    .ok_or_else(|| KeyPathError::IndexTooLarge {
                        path: s.to_string(),
                        at: d0 + 1,
                    })?;
                segs.push(Seg::Index(n));
                i += 1;
            }
            if i == bytes.len() {
                break;
            }
            if bytes[i] != b'.' {
                return Err(KeyPathError::Unexpected {
                    path: s.to_string(),
                    found: s[i..].chars().next().unwrap_or('?'),
                    at: i + 1,
                });
            }
            i += 1;
        }
        Ok(KeyPath(segs))
    }

    /// The path with every index replaced by `[]`.
    pub fn pattern(&self) -> String {
        pattern_of(&self.0)
    }

    /// The first key.
    pub fn head(&self) -> &str {
        match self.0.first() {
            Some(Seg::Key(k)) => k,
            _ => "",
        }
    }

    /// The path without its first segment.
    pub fn tail(&self) -> KeyPath {
        KeyPath(self.0.iter().skip(1).cloned().collect())
    }
}

/// Pattern of a segment list (indices as `[]`).
pub fn pattern_of(segs: &[Seg]) -> String {
    let mut out = String::new();
    for (i, s) in segs.iter().enumerate() {
        match s {
            Seg::Key(k) => {
                if i > 0 {
                    out.push('.');
                }
                out.push_str(k);
            }
            Seg::Index(_) => out.push_str("[]"),
        }
    }
    out
}

/// The value at `path` in `table`, if any.
pub fn get<'a>(table: &'a toml::Table, path: &[Seg]) -> Option<&'a toml::Value> {
    let (first, rest) = path.split_first()?;
    let Seg::Key(k) = first else { return None };
    let mut v = table.get(k)?;
    for s in rest {
        v = match (s, v) {
            (Seg::Key(k), toml::Value::Table(t)) => t.get(k)?,
            (Seg::Index(i), toml::Value::Array(a)) => a.get(*i)?,
            _ => return None,
        };
    }
    Some(v)
}

/// Make `value` the type of `reference`: integral floats become integers where the reference
/// is an integer, integers become floats where it is a float.
pub fn coerce(value: toml::Value, reference: Option<&toml::Value>) -> toml::Value {
    match (value, reference) {
        (toml::Value::Float(x), Some(toml::Value::Integer(_)))
            if x.fract() == 0.0 && x.abs() < 9.0e15 =>
        {
            toml::Value::Integer(x as i64)
        }
        (toml::Value::Integer(n), Some(toml::Value::Float(_))) => toml::Value::Float(n as f64),
        (v, _) => v,
    }
}

/// Set `path` in `table` to `value` (coerced to the type of the value it replaces). Missing
/// tables along the way are created; an index must address an existing array element.
/// `shown` is the path as the user wrote it, for messages.
pub fn set(
    table: &mut toml::Table,
    path: &[Seg],
    value: toml::Value,
    shown: &str,
) -> Result<(), SetError> {
    let Some((Seg::Key(first), rest)) = path.split_first() else {
        return Err(SetError::NoKey {
            shown: shown.to_string(),
        });
    };
    if rest.is_empty() {
        let old = table.get(first);
        let v = coerce(value, old);
        table.insert(first.clone(), v);
        return Ok(());
    }
    let next = table.entry(first.clone()).or_insert_with(|| match rest[0] {
        Seg::Key(_) => toml::Value::Table(toml::Table::new()),
        Seg::Index(_) => toml::Value::Array(Vec::new()),
    });
    set_in(next, rest, value, shown, first)
}

fn set_in(
    node: &mut toml::Value,
    path: &[Seg],
    value: toml::Value,
    shown: &str,
    at: &str,
) -> Result<(), SetError> {
    let Some((seg, rest)) = path.split_first() else {
        let v = coerce(value, Some(node));
        *node = v;
        return Ok(());
    };
    match (seg, node) {
        (Seg::Key(k), toml::Value::Table(t)) => {
            if rest.is_empty() {
                let v = coerce(value, t.get(k));
                t.insert(k.clone(), v);
                return Ok(());
            }
            let next = t.entry(k.clone()).or_insert_with(|| match rest[0] {
                Seg::Key(_) => toml::Value::Table(toml::Table::new()),
                Seg::Index(_) => toml::Value::Array(Vec::new()),
            });
            set_in(next, rest, value, shown, &format!("{at}.{k}"))
        }
        (Seg::Index(i), toml::Value::Array(a)) => {
            let len = a.len();
            let Some(el) = a.get_mut(*i) else {
                return Err(SetError::OutOfRange {
                    shown: shown.to_string(),
                    index: *i,
                    at: at.to_string(),
                    len,
                });
            };
            set_in(el, rest, value, shown, &format!("{at}[{i}]"))
        }
        (Seg::Key(k), other) => Err(SetError::NotATable {
            shown: shown.to_string(),
            at: at.to_string(),
            found: other.type_str(),
            key: k.clone(),
        }),
        (Seg::Index(i), other) => Err(SetError::NotAnArray {
            shown: shown.to_string(),
            at: at.to_string(),
            found: other.type_str(),
            index: *i,
        }),
    }
}

/// `parent.key`, or `key` at the top.
pub fn join_key(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// The parent of a key path: `a.b[2].c` → `a.b[2]` → `a.b` → `a` → none.
pub fn parent_path(p: &str) -> Option<&str> {
    if p.ends_with(']') {
        return p.rfind('[').map(|i| &p[..i]);
    }
    p.rfind('.').map(|i| &p[..i])
}

/// A `--set KEY=VALUE` argument that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OverrideError {
    /// No `=` in the argument.
    #[error("--set {0}: expected KEY=VALUE")]
    NoEquals(String),
    /// The key is not a valid path.
    #[error("--set {arg}: {reason}")]
    BadPath {
        /// The argument as given.
        arg: String,
        /// Why the path does not parse (in the message, so not also a source).
        reason: KeyPathError,
    },
}

/// Parse a `KEY=VALUE` override: a path and a TOML value (numbers, strings, arrays; bare
/// words become strings).
pub fn parse_override(s: &str) -> Result<(KeyPath, toml::Value), OverrideError> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| OverrideError::NoEquals(s.to_string()))?;
    let path = KeyPath::parse(k.trim()).map_err(|reason| OverrideError::BadPath {
        arg: s.to_string(),
        reason,
    })?;
    let text = v.trim();
    let value = toml::from_str::<toml::Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()));
    Ok((path, value))
}

/// Every pattern of `table` (tables recursed, arrays as `name` and `name[]…`), prefixed with
/// `prefix`. Array patterns (those whose value is an array) are also put in `arrays`.
pub fn flatten(
    table: &toml::Table,
    prefix: &str,
    out: &mut BTreeSet<String>,
    arrays: &mut BTreeSet<String>,
) {
    for (k, v) in table {
        flatten_value(v, join_key(prefix, k), out, arrays);
    }
}

fn flatten_value(
    v: &toml::Value,
    p: String,
    out: &mut BTreeSet<String>,
    arrays: &mut BTreeSet<String>,
) {
    match v {
        toml::Value::Table(t) => {
            out.insert(p.clone());
            flatten(t, &p, out, arrays);
        }
        toml::Value::Array(a) => {
            out.insert(p.clone());
            arrays.insert(p.clone());
            for el in a {
                flatten_value(el, format!("{p}[]"), out, arrays);
            }
        }
        _ => {
            out.insert(p);
        }
    }
}

/// Whether `pattern` is valid: in `names`, or below an array pattern (free-form arrays).
pub fn pattern_allowed(pattern: &str, names: &BTreeSet<String>, arrays: &BTreeSet<String>) -> bool {
    if names.contains(pattern) {
        return true;
    }
    let mut p = pattern;
    while let Some(i) = p.rfind(['.', '[']) {
        p = &p[..i];
        if arrays.contains(p) {
            return true;
        }
    }
    false
}

/// The candidate closest to `name` by edit distance, when it is close enough to be a likely
/// typo (at most a third of the name's characters, and at least one, differ); for "did you
/// mean" hints. Ties go to the earlier candidate.
pub fn closest<'c>(name: &str, candidates: impl IntoIterator<Item = &'c str>) -> Option<&'c str> {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (edit_distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Edit distance in characters with adjacent transpositions counting one edit (optimal string
/// alignment: `k_pis` is one typo from `k_psi`). Names are short: O(nm) rows are fine.
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut prev2: Vec<usize> = vec![0; b.len() + 1];
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut row = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            row[j] = (prev[j - 1] + cost).min(prev[j] + 1).min(row[j - 1] + 1);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                row[j] = row[j].min(prev2[j - 2] + 1);
            }
        }
        prev2 = std::mem::replace(&mut prev, row);
    }
    prev[b.len()]
}

/// `; did you mean `x`?` for the candidate [`closest`] to `name`, or nothing.
pub fn did_you_mean<'c>(name: &str, candidates: impl IntoIterator<Item = &'c str>) -> String {
    closest(name, candidates)
        .map(|c| format!("; did you mean `{c}`?"))
        .unwrap_or_default()
}

/// A pattern for display: `[]` shown as `[i]`.
pub fn display_pattern(p: &str) -> String {
    p.replace("[]", "[i]")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_display() {
        let p = KeyPath::parse("design.thruster[2].position[0]").unwrap();
        assert_eq!(p.to_string(), "design.thruster[2].position[0]");
        assert_eq!(p.pattern(), "design.thruster[].position[]");
        for bad in [
            "", ".a", "a.", "a[", "a[x]", "a[1", "a..b", "a b", "a[1]x", "é",
        ] {
            assert!(KeyPath::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn set_get_coerce() {
        let mut t: toml::Table = toml::from_str("a = 1\nb = [1.0, 2.0]\n[c]\nd = 0.5").unwrap();
        set(
            &mut t,
            &KeyPath::parse("a").unwrap().0,
            toml::Value::Float(3.0),
            "a",
        )
        .unwrap();
        assert_eq!(t["a"], toml::Value::Integer(3));
        set(
            &mut t,
            &KeyPath::parse("b[1]").unwrap().0,
            toml::Value::Integer(5),
            "b[1]",
        )
        .unwrap();
        assert_eq!(t["b"][1], toml::Value::Float(5.0));
        assert!(set(
            &mut t,
            &KeyPath::parse("b[2]").unwrap().0,
            toml::Value::Integer(5),
            "b"
        )
        .is_err());
        set(
            &mut t,
            &KeyPath::parse("x.y").unwrap().0,
            toml::Value::Integer(5),
            "x.y",
        )
        .unwrap();
        assert_eq!(
            get(&t, &KeyPath::parse("x.y").unwrap().0),
            Some(&toml::Value::Integer(5))
        );
        assert!(set(
            &mut t,
            &KeyPath::parse("a.b").unwrap().0,
            toml::Value::Integer(5),
            "a.b"
        )
        .is_err());
        let (mut names, mut arrays) = (BTreeSet::new(), BTreeSet::new());
        flatten(&t, "", &mut names, &mut arrays);
        assert!(names.contains("b[]") && names.contains("c.d") && arrays.contains("b"));
        assert!(pattern_allowed("b[][]", &names, &arrays));
        assert!(!pattern_allowed("c.e", &names, &arrays));
    }

    #[test]
    fn overrides_and_parents() {
        let (p, v) = parse_override("control.k_psi = 0.3").unwrap();
        assert_eq!(
            (p.to_string(), v),
            ("control.k_psi".into(), toml::Value::Float(0.3))
        );
        let (_, v) = parse_override("allocation.method=qp").unwrap();
        assert_eq!(v, toml::Value::String("qp".into()));
        assert!(matches!(
            parse_override("x"),
            Err(OverrideError::NoEquals(_))
        ));
        let e = parse_override("a..b=1").unwrap_err();
        assert!(e.to_string().starts_with("--set a..b=1: "), "{e}");
        assert_eq!(parent_path("a.b[2].c"), Some("a.b[2]"));
        assert_eq!(parent_path("a.b[2]"), Some("a.b"));
        assert_eq!(parent_path("a"), None);
        assert_eq!(join_key("", "a"), "a");
    }

    #[test]
    fn close_names_are_suggested_and_far_ones_not() {
        let names = ["energy_per_metre", "thruster_energy", "success"];
        assert_eq!(closest("energy_per_meter", names), Some("energy_per_metre"));
        assert_eq!(closest("sucess", names), Some("success"));
        assert_eq!(closest("no_such_metric", names), None);
        assert_eq!(closest("", names), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(did_you_mean("sucess", names), "; did you mean `success`?");
        assert_eq!(did_you_mean("zzz", names), "");
    }
}

//! A TOML document as a located tree: every key path with the byte span of its key and
//! value, read from `toml_edit`'s parse tree (the parser `toml` itself uses, so serde error
//! spans and these spans agree; `toml::Spanned` cannot be used for keys of implicit tables
//! such as `a.b = 1`). It maps a serde error span to the key path it falls in, and a key
//! path of a later semantic check back to its line, so design, scenario and study files
//! report errors the same way.

use super::keypath::{did_you_mean, join_key, parent_path};
use super::located::{line_col, one_line, InputError, KeyError, Located, Location};
use serde::de::DeserializeOwned;
use std::ops::Range;
use toml_edit::{ImDocument, Item, Key, Table, Value};

/// One node of the document: its key path, value span and key span.
#[derive(Clone, Debug)]
struct Entry {
    path: String,
    value: Option<Range<usize>>,
    key: Option<Range<usize>>,
}

/// A parsed TOML text with the span of every key path, for locating errors.
#[derive(Clone, Debug)]
pub struct Document {
    origin: String,
    text: String,
    /// Whether byte offsets refer to a file the user wrote (line numbers meaningful).
    positions: bool,
    entries: Vec<Entry>,
    /// Non-finite floats found while indexing: (path, value).
    non_finite: Vec<(String, f64)>,
}

impl Document {
    /// Parse `text` written by the user (errors will carry lines); `origin` names it in
    /// messages. A TOML syntax error is located at its line and column.
    pub fn parse(text: &str, origin: &str) -> Result<Document, InputError> {
        Self::build(text, origin, true)
    }

    /// Parse a text the program printed from an in-memory table: errors carry key paths
    /// but no lines (they would point into text the user never saw).
    pub fn parse_generated(text: &str, origin: &str) -> Result<Document, InputError> {
        Self::build(text, origin, false)
    }

    /// A document that knows nothing but its origin (errors carry neither keys nor lines).
    pub fn unplaced(origin: &str) -> Document {
        Document {
            origin: origin.to_string(),
            text: String::new(),
            positions: false,
            entries: Vec::new(),
            non_finite: Vec::new(),
        }
    }

    fn build(text: &str, origin: &str, positions: bool) -> Result<Document, InputError> {
        let mut doc = Document {
            origin: origin.to_string(),
            text: text.to_string(),
            positions,
            entries: Vec::new(),
            non_finite: Vec::new(),
        };
        if let Err((offset, message)) = check_cost(text) {
            return Err(doc.at_offset(Some(offset), String::new(), message));
        }
        match ImDocument::parse(text) {
            Ok(root) => {
                doc.index_table("", root.as_table());
                Ok(doc)
            }
            Err(e) => Err(doc.at_offset(
                e.span().map(|s| s.start),
                String::new(),
                format!("TOML syntax error: {}", one_line(e.message())),
            )),
        }
    }

    fn push(&mut self, path: &str, value: Option<Range<usize>>, key: Option<&Key>) {
        self.entries.push(Entry {
            path: path.to_string(),
            value,
            key: key.and_then(Key::span),
        });
    }

    fn index_table(&mut self, path: &str, t: &Table) {
        for (k, item) in t.iter() {
            self.index_item(&join_key(path, k), item, t.key(k));
        }
    }

    fn index_item(&mut self, path: &str, item: &Item, key: Option<&Key>) {
        match item {
            Item::None => {}
            Item::Value(v) => self.index_value(path, v, key),
            Item::Table(t) => {
                self.push(path, t.span(), key);
                self.index_table(path, t);
            }
            Item::ArrayOfTables(a) => {
                self.push(path, a.span(), key);
                for (i, t) in a.iter().enumerate() {
                    let p = format!("{path}[{i}]");
                    self.push(&p, t.span(), None);
                    self.index_table(&p, t);
                }
            }
        }
    }

    fn index_value(&mut self, path: &str, v: &Value, key: Option<&Key>) {
        self.push(path, v.span(), key);
        match v {
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    self.index_value(&format!("{path}[{i}]"), x, None);
                }
            }
            Value::InlineTable(t) => {
                for (k, x) in t.iter() {
                    self.index_value(&join_key(path, k), x, t.key(k));
                }
            }
            Value::Float(x) if !x.value().is_finite() => {
                self.non_finite.push((path.to_string(), *x.value()));
            }
            _ => {}
        }
    }

    /// The origin given at parsing.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// The text the document was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Whether `key` (a key path such as `thruster[2].direction`) is in the document.
    pub fn contains(&self, key: &str) -> bool {
        self.entries.iter().any(|e| e.path == key)
    }

    /// The first NaN or infinite float of the document: its key path and value.
    pub fn first_non_finite(&self) -> Option<(&str, f64)> {
        self.non_finite.first().map(|(p, x)| (p.as_str(), *x))
    }

    /// Byte offset of the key `path`, or of its nearest ancestor present in the document.
    pub fn locate(&self, path: &str) -> Option<usize> {
        let mut p = path;
        loop {
            let found = self.entries.iter().find(|e| e.path == p);
            if let Some(span) = found.and_then(|e| e.key.as_ref().or(e.value.as_ref())) {
                return Some(span.start);
            }
            p = parent_path(p)?;
        }
    }

    /// Key path of the smallest node whose key or value span contains `offset`.
    pub fn path_at(&self, offset: usize) -> Option<&str> {
        self.entries
            .iter()
            .flat_map(|e| {
                e.value
                    .as_ref()
                    .into_iter()
                    .chain(e.key.as_ref())
                    .map(move |s| (e, s))
            })
            .filter(|(_, s)| s.start <= offset && offset < s.end.max(s.start + 1))
            .min_by_key(|(_, s)| s.end - s.start)
            .map(|(e, _)| e.path.as_str())
    }

    fn position(&self, offset: Option<usize>) -> (Option<usize>, Option<usize>) {
        match offset {
            Some(o) if self.positions => {
                let (l, c) = line_col(&self.text, o);
                (Some(l), Some(c))
            }
            _ => (None, None),
        }
    }

    fn at_offset<E>(&self, offset: Option<usize>, key: String, error: E) -> Located<E> {
        let (line, column) = self.position(offset);
        Located {
            at: Location {
                origin: self.origin.clone(),
                line,
                column,
                key,
            },
            error,
        }
    }

    /// The location of `key`: its line and column are those of the key, or of its nearest
    /// ancestor present in the document.
    pub fn location(&self, key: &str) -> Location {
        let (line, column) = self.position(self.locate(key));
        Location {
            origin: self.origin.clone(),
            line,
            column,
            key: key.to_string(),
        }
    }

    /// Wrap `error` with the location of `key`.
    pub fn error_at<E>(&self, key: &str, error: E) -> Located<E> {
        Located {
            at: self.location(key),
            error,
        }
    }

    /// A message at `key`, located like [`Document::error_at`].
    pub fn err(&self, key: &str, message: impl Into<String>) -> InputError {
        self.error_at(key, message.into())
    }

    /// Place a [`KeyError`] in this document.
    pub fn place(&self, e: KeyError) -> InputError {
        self.error_at(&e.key, e.message)
    }

    /// A serde error from deserialising this document's text: located by its span, keyed by
    /// the key path the span falls in.
    pub fn serde_error(&self, e: &toml::de::Error) -> InputError {
        let offset = e.span().map(|s| s.start);
        let key = offset
            .and_then(|o| self.path_at(o))
            .unwrap_or_default()
            .to_string();
        self.at_offset(offset, key, suggest(one_line(e.message())))
    }

    /// Deserialise the document's text into `T`; an error names its key path (and line).
    pub fn deserialize<T: DeserializeOwned>(&self) -> Result<T, InputError> {
        toml::from_str(&self.text).map_err(|e| self.serde_error(&e))
    }
}

/// Most tables (`[headers]`, `[[arrays of tables]]` and `{ inline tables }`) an input text may
/// hold: hand-written input has a few dozen; a 15 MiB file of a million one-key tables took
/// 31 s and 2.9 GB to parse before its first error (issue 39).
pub const MAX_TABLES: usize = 10_000;
/// Most `key = value` pairs an input text may hold.
pub const MAX_KEYS: usize = 200_000;
/// Deepest nesting of arrays and inline tables in an input text.
pub const MAX_NESTING: usize = 64;

/// The scanner state of [`check_cost`].
#[derive(Clone, Copy, PartialEq)]
enum Lex {
    Normal,
    Basic,
    Literal,
    MultiBasic,
    MultiLiteral,
}

/// Bound the cost of parsing `text` before it is parsed: one pass over its bytes counting
/// tables, keys and nesting outside strings and comments ([`MAX_TABLES`], [`MAX_KEYS`],
/// [`MAX_NESTING`]). The byte offset and message of the first excess.
fn check_cost(text: &str) -> Result<(), (usize, String)> {
    let b = text.as_bytes();
    let (mut tables, mut keys, mut depth) = (0usize, 0usize, 0usize);
    let mut line_start = true;
    let mut lex = Lex::Normal;
    let mut i = 0;
    let triple = |i: usize, c: u8| b.get(i + 1) == Some(&c) && b.get(i + 2) == Some(&c);
    let over = |i: usize, what: &str, limit: usize| {
        Err((
            i,
            format!(
                "the text holds more than {limit} {what}, the limit of an input file (its cost \
                 to parse is bounded, not only its size); is it the right file?"
            ),
        ))
    };
    while i < b.len() {
        let c = b[i];
        match lex {
            Lex::Normal => match c {
                b'#' => {
                    while i < b.len() && b[i] != b'\n' {
                        i += 1;
                    }
                    continue;
                }
                b'"' | b'\'' => {
                    let multi = triple(i, c);
                    lex = match (c, multi) {
                        (b'"', false) => Lex::Basic,
                        (b'"', true) => Lex::MultiBasic,
                        (_, false) => Lex::Literal,
                        (_, true) => Lex::MultiLiteral,
                    };
                    i += if multi { 3 } else { 1 };
                    line_start = false;
                    continue;
                }
                b'[' if line_start && depth == 0 => {
                    tables += 1;
                    // The header's keys: up to its closing bracket (or the line's end).
                    while i < b.len() && b[i] != b'\n' && b[i] != b']' {
                        i += 1;
                    }
                    while i < b.len() && b[i] == b']' {
                        i += 1;
                    }
                    line_start = false;
                    continue;
                }
                b'[' | b'{' => {
                    tables += usize::from(c == b'{');
                    depth += 1;
                }
                b']' | b'}' => depth = depth.saturating_sub(1),
                b'=' => keys += 1,
                _ => {}
            },
            Lex::Basic | Lex::MultiBasic if c == b'\\' => i += 1,
            Lex::Basic if c == b'"' || c == b'\n' => lex = Lex::Normal,
            Lex::Literal if c == b'\'' || c == b'\n' => lex = Lex::Normal,
            Lex::MultiBasic if c == b'"' && triple(i, c) => {
                lex = Lex::Normal;
                i += 2;
            }
            Lex::MultiLiteral if c == b'\'' && triple(i, c) => {
                lex = Lex::Normal;
                i += 2;
            }
            _ => {}
        }
        if tables > MAX_TABLES {
            return over(i, "tables", MAX_TABLES);
        }
        if keys > MAX_KEYS {
            return over(i, "keys", MAX_KEYS);
        }
        if depth > MAX_NESTING {
            return over(i, "levels of nested arrays and inline tables", MAX_NESTING);
        }
        if c == b'\n' {
            line_start = true;
        } else if !c.is_ascii_whitespace() {
            line_start = false;
        }
        i += 1;
    }
    Ok(())
}

/// Largest input file (study, problem, design, scenario, state, case file) read [bytes]:
/// hand-written input is a few kB; anything past this is refused before it fills memory.
pub const MAX_INPUT_BYTES: u64 = 16 << 20;

/// The text of the input file `path`, as `std::fs::read_to_string` returns it, but refused
/// before reading when the file is larger than [`MAX_INPUT_BYTES`], and after reading that many
/// bytes from anything that is not a regular file (`/dev/zero`, a FIFO): an input file never
/// fills memory. The error names the limit.
pub fn read_text(path: &std::path::Path) -> Result<String, std::io::Error> {
    use std::io::Read;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(std::io::Error::other("is a directory, not a file"));
    }
    let too_large = || {
        std::io::Error::other(format!(
            "larger than {} MiB, the limit of an input file (is it the right file?)",
            MAX_INPUT_BYTES >> 20
        ))
    };
    if meta.len() > MAX_INPUT_BYTES {
        return Err(too_large());
    }
    let mut bytes = Vec::new();
    file.take(MAX_INPUT_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(too_large());
    }
    String::from_utf8(bytes)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "is not UTF-8 text"))
}

/// Deserialise an in-memory table into `T`. On failure the table is printed and parsed
/// again so that the error names its key path (keys under `prefix`, e.g. `control`);
/// A serde message naming an unknown field or variant among the expected ones
/// (`` unknown field `k_pis`, expected one of `method`, `k_psi`, … ``) with a "did you mean"
/// for the closest expected name appended; any other message unchanged.
pub fn suggest(message: String) -> String {
    let unknown = ["unknown field `", "unknown variant `"]
        .iter()
        .find_map(|p| message.split_once(p).map(|x| x.1));
    let Some(rest) = unknown else {
        return message;
    };
    let Some((name, expected)) = rest.split_once('`') else {
        return message;
    };
    let candidates: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    let hint = did_you_mean(name, candidates);
    if hint.is_empty() {
        return message;
    }
    format!("{message}{hint}")
}
/// the success path is a plain `T::deserialize` of the table.
pub fn deserialize_table<T: DeserializeOwned>(
    table: &toml::Table,
    prefix: &str,
) -> Result<T, KeyError> {
    let err = match T::deserialize(toml::Value::Table(table.clone())) {
        Ok(t) => return Ok(t),
        Err(e) => e,
    };
    let fallback = || KeyError::new(prefix, suggest(one_line(err.message())));
    let Ok(text) = toml::to_string(table) else {
        return Err(fallback());
    };
    let Ok(doc) = Document::parse_generated(&text, "") else {
        return Err(fallback());
    };
    match doc.deserialize::<T>() {
        Ok(_) => Err(fallback()),
        Err(e) => Err(KeyError::new(join_key(prefix, &e.at.key), e.error)),
    }
}

#[cfg(test)]
mod tests {
    /// Issue 39: a 15 MiB file of a million one-key tables took 31 s and 2.9 GB before its
    /// first error; it is now refused by a scan before parsing, at the first table too many.
    /// Brackets, braces and `=` inside strings and comments do not count.
    #[test]
    fn a_text_costly_to_parse_is_refused_before_parsing() {
        let mut text = String::new();
        for i in 0..1_000_000 {
            text.push_str(&format!("[t{i}]\nk = 1\n"));
        }
        let e = super::Document::parse(&text, "big.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("more than 10000 tables") && e.contains("big.toml:20001:"),
            "{e}"
        );
        let keys: String = (0..200_001).map(|i| format!("k{i} = 1\n")).collect();
        let e = super::Document::parse(&keys, "k.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 200000 keys"), "{e}");
        let deep = format!("a = {}{}", "[".repeat(65), "]".repeat(65));
        let e = super::Document::parse(&deep, "d.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("levels of nested"), "{e}");
        let quoted = format!(
            "s = \"{}\"\nl = '{}'\nm = \"\"\"\n{}\"\"\"\n# {}\n[x]\ny = {{ a = [1, [2]] }}\n",
            "[{=".repeat(20_000),
            "[{=".repeat(20_000),
            "\n[t]\n{=".repeat(20_000),
            "[{=".repeat(20_000),
        );
        let d = super::Document::parse(&quoted, "q.toml").unwrap();
        assert!(d.text.len() > 100_000);
        for f in ["studies/thrusters.toml", "studies/gains.toml"] {
            let t = std::fs::read_to_string(f).unwrap();
            assert!(super::check_cost(&t).is_ok(), "{f}");
        }
    }

    #[test]
    fn an_unknown_field_gets_the_closest_expected_name() {
        let m = "unknown field `k_pis`, expected one of `method`, `u0`, `k_psi`, `k_6p`";
        assert_eq!(
            suggest(m.to_string()),
            format!("{m}; did you mean `k_psi`?")
        );
        let m = "unknown variant `qpp`, expected one of `pinv`, `qp`, `minimax`";
        assert!(suggest(m.to_string()).ends_with("did you mean `qp`?"));
        // Nothing close, or another message: unchanged.
        let m = "unknown field `zzzzzz`, expected `a` or `b`";
        assert_eq!(suggest(m.to_string()), m);
        assert_eq!(suggest("invalid type".into()), "invalid type");
    }

    use super::*;

    const TEXT: &str = "a = 1\n[b]\nc = [1.0, 2.0]\n\n[[d]]\ne = \"x\"\n[[d]]\ne = nan\n";

    #[test]
    fn keys_resolve_to_their_lines() {
        let doc = Document::parse(TEXT, "f.toml").unwrap();
        assert_eq!(doc.location("b.c").line, Some(3));
        assert_eq!(doc.location("b.c[1]").line, Some(3));
        assert_eq!(doc.location("d[1].e").line, Some(8));
        // A missing key resolves to its nearest ancestor.
        assert_eq!(doc.location("b.zzz").line, Some(2));
        assert_eq!(doc.location("zzz").line, None);
        assert_eq!(doc.first_non_finite().map(|x| x.0), Some("d[1].e"));
        let e = doc.error_at("b.c", "bad".to_string());
        assert_eq!(e.to_string(), "f.toml:3:1: b.c: bad");
        let generated = Document::parse_generated(TEXT, "mem").unwrap();
        assert_eq!(generated.location("b.c").line, None);
        // Keys of implicit tables (dotted keys and headers) are located too.
        let doc = Document::parse("x.y = 1\n[p.q]\nr = 2\n[[s.t]]\nu = 3\n", "f").unwrap();
        for (key, line) in [("x.y", 1), ("p.q.r", 3), ("s.t[0].u", 5), ("s.t[0]", 4)] {
            assert_eq!(doc.location(key).line, Some(line), "{key}");
        }
    }

    #[test]
    fn syntax_and_serde_errors_are_located() {
        let e = Document::parse("a = 1\nb = [1,\n", "f.toml").unwrap_err();
        assert_eq!(e.at.line, Some(3));
        assert!(e.error.starts_with("TOML syntax error"), "{e}");
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct B {
            c: [f64; 3],
        }
        #[derive(serde::Deserialize, Debug)]
        #[allow(dead_code)]
        struct F {
            b: B,
        }
        let doc = Document::parse("[b]\nc = [1.0, 2.0]\n", "f.toml").unwrap();
        let e = doc.deserialize::<F>().unwrap_err();
        assert_eq!((e.at.key.as_str(), e.at.line), ("b.c", Some(2)), "{e}");
        let table: toml::Table = toml::from_str("c = [1.0, 2.0]").unwrap();
        let e = deserialize_table::<B>(&table, "b").unwrap_err();
        assert_eq!(e.key, "b.c", "{e}");
    }
}

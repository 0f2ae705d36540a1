//! Where an input error is: [`Location`] (file, line, column, key path) wrapped around any
//! error by [`Located`], so that error types say *what* is wrong and never copy location
//! fields (ripgrep's `ignore::Error::WithPath` / `WithLineNumber` idea). Every input error
//! then reads `file:line:col: key: message`.

use std::fmt;

/// 1-based line and column (in characters) of byte `offset` in `text`; offsets past the end
/// or inside a multi-byte character are clamped to the nearest character boundary before.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut o = offset.min(text.len());
    while !text.is_char_boundary(o) {
        o -= 1;
    }
    let before = &text[..o];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[start..].chars().count() + 1)
}

/// A message collapsed to one line (errors are printed as one-line cause chains).
pub fn one_line(s: &str) -> String {
    s.trim().replace('\n', "; ")
}

/// A number for messages: the shortest digits that read back to `x`, positional for
/// `1e-5 <= |x| < 1e16` (and 0), scientific beyond (`1e200`, `-2.5e-9`), so that no message
/// prints a 200-digit decimal.
pub fn fmt_exact(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A number with `decimals` decimals for a run's reason (`reach = 0.812 m`), scientific with
/// three beyond `1e-3 <= |x| < 1e6` (`1.000e308`, `1.000e-300`): never hundreds of digits, nor
/// a small value shown as `0.000`.
pub fn fmt_fixed(x: f64, decimals: usize) -> String {
    if x == 0.0 || !x.is_finite() || (1e-3..1e6).contains(&x.abs()) {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Where in the user's input a problem is.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// The file (or other origin: a preset name, `case 3 design`) the input came from.
    pub origin: String,
    /// 1-based line, when known (never for tables built in memory).
    pub line: Option<usize>,
    /// 1-based column in characters, when known.
    pub column: Option<usize>,
    /// Key path of the offending entry (`thruster[2].direction`); empty when none.
    pub key: String,
}

impl Location {
    /// A location with an origin only.
    pub fn origin(origin: &str) -> Self {
        Location {
            origin: origin.to_string(),
            ..Location::default()
        }
    }
}

/// Any error `E` with its [`Location`]; displays as `origin[:line[:col]][: key]: error`.
#[derive(Clone, Debug, PartialEq)]
pub struct Located<E> {
    /// Where the problem is.
    pub at: Location,
    /// What is wrong.
    pub error: E,
}

impl<E> Located<E> {
    /// The same location around `f(error)`.
    pub fn map<F>(self, f: impl FnOnce(E) -> F) -> Located<F> {
        Located {
            at: self.at,
            error: f(self.error),
        }
    }
}

/// An input error whose cause is a message (syntax, schema or semantic problem of a file).
pub type InputError = Located<String>;

impl<E: fmt::Display> fmt::Display for Located<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = &self.at;
        f.write_str(&at.origin)?;
        if let Some(line) = at.line {
            write!(f, ":{line}")?;
            if let Some(col) = at.column {
                write!(f, ":{col}")?;
            }
        }
        if !at.key.is_empty() {
            write!(f, ": {}", at.key)?;
        }
        write!(f, ": {}", self.error)
    }
}

impl<E: fmt::Debug + fmt::Display> std::error::Error for Located<E> {}

/// A problem at a key path, not yet placed in a file: what checks of a parsed value
/// (`validate`) return; [`crate::input::document::Document::place`] turns it into an [`InputError`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct KeyError {
    /// Key path in file terms (`scenario.duration`, `allocation.weights`).
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl KeyError {
    /// A problem `message` at `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        KeyError {
            key: key.into(),
            message: message.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_characters_from_one() {
        let t = "a = 1\nbé = [2,\n  3]\n";
        assert_eq!(line_col(t, 0), (1, 1));
        assert_eq!(line_col(t, 6), (2, 1));
        // 'é' is two bytes: the '=' of line 2 is byte 10 but the 4th character.
        assert_eq!(&t[10..11], "=");
        assert_eq!(line_col(t, 10), (2, 4));
        assert_eq!(line_col(t, 8), (2, 2)); // inside 'é': clamped back
        assert_eq!(line_col(t, 999).0, 4);
    }

    #[test]
    fn reason_numbers_stay_short() {
        assert_eq!(fmt_fixed(1e308, 3), "1.000e308");
        assert_eq!(fmt_fixed(-1.08, 3), "-1.080");
        assert_eq!(fmt_fixed(1e-300, 1), "1.000e-300");
        assert_eq!(fmt_fixed(f64::INFINITY, 1), "inf");
        assert_eq!(fmt_exact(1e308), "1e308");
        assert_eq!(fmt_exact(200.0), "200");
    }

    #[test]
    fn message_numbers_stay_short() {
        assert_eq!(fmt_exact(1e200), "1e200");
        assert_eq!(fmt_exact(-2.5e-9), "-2.5e-9");
        assert_eq!(fmt_exact(0.05), "0.05");
        assert_eq!(fmt_exact(140.0), "140");
        assert_eq!(fmt_exact(f64::INFINITY), "inf");
        assert_eq!(fmt_exact(0.0), "0");
    }

    #[test]
    fn located_errors_print_what_is_known() {
        let mut e = Located {
            at: Location::origin("f.toml"),
            error: "bad".to_string(),
        };
        assert_eq!(e.to_string(), "f.toml: bad");
        e.at.key = "a.b".into();
        assert_eq!(e.to_string(), "f.toml: a.b: bad");
        e.at.line = Some(3);
        e.at.column = Some(7);
        assert_eq!(e.to_string(), "f.toml:3:7: a.b: bad");
    }
}

//! Source positions for error messages on user files (design, scenario and study TOML):
//! `file:line:col: key: message`, shared so that every input error reads the same way.

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

/// Write `origin[:line[:col]][: key]: message`.
pub fn write_located(
    f: &mut fmt::Formatter<'_>,
    origin: &str,
    line: Option<usize>,
    column: Option<usize>,
    key: &str,
    message: &str,
) -> fmt::Result {
    f.write_str(origin)?;
    if let Some(line) = line {
        write!(f, ":{line}")?;
        if let Some(col) = column {
            write!(f, ":{col}")?;
        }
    }
    if !key.is_empty() {
        write!(f, ": {key}")?;
    }
    write!(f, ": {message}")
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
}

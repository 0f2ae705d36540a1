//! The one Markdown-table writer of the crate (GitHub-flavoured pipe tables).
//!
//! ```text
//! | metric | a | b |
//! |---|---|---|
//! | `x` | 1 | 2 |
//! ```
//!
//! Cells are written as given: callers escape a `|` inside a cell (`\|`) themselves.

/// A Markdown table under construction: a header row, the `|---|` rule, then body rows.
#[derive(Debug, Clone)]
pub struct MarkdownTable {
    text: String,
}

impl MarkdownTable {
    /// A table with these column headers (and no rows yet).
    pub fn new<S: AsRef<str>>(header: impl IntoIterator<Item = S>) -> Self {
        let mut table = Self {
            text: String::new(),
        };
        let mut columns = 0;
        table.push_line(header.into_iter().inspect(|_| columns += 1));
        table.text.push('|');
        for _ in 0..columns {
            table.text.push_str("---|");
        }
        table.text.push('\n');
        table
    }

    /// Appends one body row.
    pub fn row<S: AsRef<str>>(&mut self, cells: impl IntoIterator<Item = S>) {
        self.push_line(cells);
    }

    /// The table's text, every line (the last included) ending in `\n`.
    pub fn finish(self) -> String {
        self.text
    }

    fn push_line<S: AsRef<str>>(&mut self, cells: impl IntoIterator<Item = S>) {
        self.text.push('|');
        for c in cells {
            self.text.push(' ');
            self.text.push_str(c.as_ref());
            self.text.push_str(" |");
        }
        self.text.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_header_rule_and_rows() {
        let mut t = MarkdownTable::new(["metric", "a", "b"]);
        t.row(["`x`", "1", "-"]);
        t.row(vec![String::from("`y`"), "2".into(), "3".into()]);
        assert_eq!(
            t.finish(),
            "| metric | a | b |\n|---|---|---|\n| `x` | 1 | - |\n| `y` | 2 | 3 |\n"
        );
    }
}

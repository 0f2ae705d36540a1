//! Tests of the key-position index of study files.

use super::*;

#[test]
fn spans_locate_keys() {
    let text = "[study]\nname = \"a\"\n\n[[axis]]\nname = \"x\"\nvalues = [1, 2]\n\n[[axis]]\nname = \"y\"\nrange = { start = 0.1, stop = 0.2, steps = 2 }\n\n[[axis]]\nname = \"z\"\n";
    let s = Spans::parse(text, "f.toml").unwrap();
    let e = s.err("axis[2].name", "m");
    assert_eq!((e.line, e.column), (Some(13), Some(1)), "{:?}", s.entries);
    let e = s.err("axis[1].range.steps", "m");
    assert_eq!(e.line, Some(10));
}

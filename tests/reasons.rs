//! Meaning never travels as text (issue 37 item 3): a case's `reason` is for people; what it
//! means is the evaluator's typed `CaseEnd`. The only code that may read a reason for meaning
//! is `src/evaluate/status.rs`, beside the writers of those reasons (`CaseEnd::read`, for
//! tables read back from disk). Test files may assert on reason texts.

use std::path::{Path, PathBuf};

/// Where a reason may be decoded.
const DECODER: &str = "src/evaluate/status.rs";

/// The string methods that read meaning out of a text.
const READERS: [&str; 6] = [
    ".contains(",
    ".starts_with(",
    ".ends_with(",
    ".strip_prefix(",
    ".split_once(",
    ".find(",
];

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// A test file: `tests.rs`, `*_tests.rs` or under a `tests/` directory.
fn is_test_file(rel: &str) -> bool {
    let name = rel.rsplit('/').next().unwrap_or(rel);
    name == "tests.rs" || name.ends_with("_tests.rs") || rel.contains("/tests/")
}

/// The lines of `text` (before its `#[cfg(test)]` module) where an identifier naming a reason
/// (`reason`, `res.reason`, `reasons[i]`, …) is read with one of the [`READERS`].
fn reason_reads(text: &str) -> Vec<(usize, String)> {
    let body = text.split("#[cfg(test)]").next().unwrap_or(text);
    let mut found = Vec::new();
    for (i, line) in body.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for r in READERS {
            let mut from = 0;
            while let Some(k) = code[from..].find(r) {
                let at = from + k;
                let before = code[..at].trim_end_matches([']', ')']);
                let before = before.trim_end_matches(|c: char| c.is_alphanumeric() || c == '_');
                let receiver = &code[before.len()..at];
                let ident = receiver
                    .rsplit(|c: char| !(c.is_alphanumeric() || c == '_'))
                    .find(|s| !s.is_empty())
                    .unwrap_or("");
                // `reasons[i].starts_with(…)`: the identifier before the index.
                let indexed = code[..at].ends_with(']').then(|| {
                    let open = code[..at].rfind('[').unwrap_or(0);
                    let head = &code[..open];
                    let start = head
                        .rfind(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .map_or(0, |i| i + 1);
                    &head[start..]
                });
                let named = indexed
                    .unwrap_or(ident)
                    .to_ascii_lowercase()
                    .contains("reason");
                if named {
                    found.push((i + 1, line.trim().to_string()));
                }
                from = at + r.len();
            }
        }
    }
    found
}

#[test]
fn no_reason_string_is_read_for_meaning() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    rust_files(&root.join("python/src"), &mut files);
    files.sort();
    let mut bad = Vec::new();
    for p in &files {
        let rel = p
            .strip_prefix(root)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if rel == DECODER || is_test_file(&rel) {
            continue;
        }
        let text = std::fs::read_to_string(p).unwrap();
        for (line, code) in reason_reads(&text) {
            bad.push(format!("{rel}:{line}: {code}"));
        }
    }
    assert!(
        files.len() > 100,
        "the scan found only {} files",
        files.len()
    );
    assert!(
        bad.is_empty(),
        "reasons read for meaning outside {DECODER} (use the case's CaseEnd):\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_scan_sees_the_reads_it_forbids() {
    let planted = "fn f() {\n\
        if res.reason.starts_with(TIMEOUT) {}\n\
        let d = reason.contains(\"mission.reach:\");\n\
        let x = reasons[i].split_once(':');\n\
        let ok = name.starts_with(\"t_\"); // reason.contains( in a comment\n\
        let known = [STATUS, REASON].contains(&n);\n\
        }\n\
        #[cfg(test)]\n\
        mod tests { fn g() { assert!(r.reason.contains(\"x\")); } }\n";
    let lines: Vec<usize> = reason_reads(planted).iter().map(|x| x.0).collect();
    assert_eq!(lines, vec![2, 3, 4]);
    assert_eq!(reason_reads("let y = r.reason.find(': ');").len(), 1);
}

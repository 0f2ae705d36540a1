//! The shape of the house, checked on the source itself (issues 9, 20): dependencies between
//! the files of `src/` run one way (no import cycles) and down the rooms in the order
//! `docs/architecture.md` declares (its rooms table, read here), every file of `src/` is in
//! that document's file map, no source file grows past the size we can read in one sitting,
//! and the library exposes no command-line layer.
//!
//! File X depends on file Y when X names an item defined in Y, through a `use` or a path in
//! code (`crate::…`, `super::…`, a module alias). Re-exports (`pub use`) are followed to the
//! file that defines the item, so a facade `mod.rs` is not a dependency of itself. Run with
//! `cargo test --release --test architecture -- --nocapture` to see the graph's size.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Longest source file we accept in `src/` (test files included), in lines.
const MAX_FILE_LINES: usize = 700;

/// Blank out comments, string and character literals, keeping line structure.
fn strip(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            i += 2;
            while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                if b[i] == b'\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 2;
        } else if c == b'r' && (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#')) {
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&b'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&b'"') {
                out.push('r');
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == b'"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&b'#')) {
                    j += 1 + hashes;
                    break;
                }
                if b[j] == b'\n' {
                    out.push('\n');
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j;
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                if i < b.len() && b[i] == b'\n' {
                    out.push('\n');
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == b'\'' {
            // A character literal ('x', '\n', '\u{..}') or a lifetime ('a).
            let close = if b.get(i + 1) == Some(&b'\\') {
                (i + 2..b.len().min(i + 12)).find(|&k| b[k] == b'\'')
            } else if b.get(i + 2) == Some(&b'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(k) => {
                    out.push_str("' '");
                    i = k + 1;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            // Copy one whole UTF-8 character.
            let len = match c {
                0x00..=0x7f => 1,
                0xc0..=0xdf => 2,
                0xe0..=0xef => 3,
                _ => 4,
            };
            out.push_str(&text[i..(i + len).min(text.len())]);
            i += len;
        }
    }
    out
}

/// Identifiers, `::` and single punctuation characters.
fn tokens(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let cs: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < cs.len() {
        let c = cs[i];
        if c.is_alphanumeric() || c == '_' {
            let s = i;
            while i < cs.len() && (cs[i].is_alphanumeric() || cs[i] == '_') {
                i += 1;
            }
            out.push(cs[s..i].iter().collect());
        } else if c == ':' && cs.get(i + 1) == Some(&':') {
            out.push("::".into());
            i += 2;
        } else {
            if !c.is_whitespace() {
                out.push(c.to_string());
            }
            i += 1;
        }
    }
    out
}

fn is_ident(s: &str) -> bool {
    s.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
}

type ModPath = Vec<String>;

struct SourceFile {
    module: ModPath,
    toks: Vec<String>,
    defs: BTreeSet<String>,
}

/// Walk `mod` declarations from a crate root, mapping each file to its module path.
fn load_tree(path: &Path, module: ModPath, files: &mut BTreeMap<PathBuf, SourceFile>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let toks = tokens(&strip(&text));
    let owner = matches!(
        path.file_name().and_then(|f| f.to_str()),
        Some("mod.rs" | "lib.rs" | "main.rs")
    );
    let dir = path.parent().unwrap().to_path_buf();
    let base = if owner {
        dir.clone()
    } else {
        path.with_extension("")
    };
    let mut defs = BTreeSet::new();
    let mut children = Vec::new();
    for (i, t) in toks.iter().enumerate() {
        let next = toks.get(i + 1).map(String::as_str).unwrap_or("");
        let item = matches!(
            t.as_str(),
            "struct" | "enum" | "fn" | "trait" | "type" | "const" | "static" | "union" | "mod"
        );
        if item && is_ident(next) && !matches!(next, "fn" | "mut" | "unsafe" | "extern") {
            defs.insert(next.to_string());
        }
        if t == "macro_rules" && next == "!" {
            if let Some(n) = toks.get(i + 2) {
                defs.insert(n.clone());
            }
        }
        if t == "mod" && is_ident(next) && toks.get(i + 2).map(String::as_str) == Some(";") {
            // `#[path = "x"]` just before: the attribute's string is blanked, so read the
            // original text of this declaration's line range instead.
            children.push(next.to_string());
        }
    }
    // #[path] attributes, from the raw text.
    let mut path_attr: BTreeMap<String, PathBuf> = BTreeMap::new();
    let raw: Vec<&str> = text.lines().collect();
    for (i, line) in raw.iter().enumerate() {
        let l = line.trim();
        if let Some(rest) = l.strip_prefix("#[path = \"") {
            let p = rest.split('"').next().unwrap();
            for decl in raw.iter().skip(i + 1).take(3) {
                let d = decl
                    .trim()
                    .trim_start_matches("pub ")
                    .trim_start_matches("pub(crate) ");
                if let Some(name) = d.strip_prefix("mod ").and_then(|n| n.strip_suffix(';')) {
                    path_attr.insert(name.trim().to_string(), dir.join(p));
                    break;
                }
            }
        }
    }
    files.insert(
        path.to_path_buf(),
        SourceFile {
            module: module.clone(),
            toks,
            defs,
        },
    );
    for name in children {
        let child = path_attr.get(&name).cloned().unwrap_or_else(|| {
            let flat = base.join(format!("{name}.rs"));
            if flat.exists() {
                flat
            } else {
                base.join(&name).join("mod.rs")
            }
        });
        if child.exists() {
            let mut m = module.clone();
            m.push(name);
            load_tree(&child, m, files);
        }
    }
}

/// One leaf of a `use` tree: its segments and the name it binds.
fn use_leaves(toks: &[String], prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
    // Split at top-level commas.
    let mut depth = 0;
    let mut start = 0;
    let mut parts = Vec::new();
    for (i, t) in toks.iter().enumerate() {
        match t.as_str() {
            "{" => depth += 1,
            "}" => depth -= 1,
            "," if depth == 0 => {
                parts.push(&toks[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&toks[start..]);
    for part in parts {
        let mut segs = prefix.to_vec();
        let mut k = 0;
        while k < part.len() {
            match part[k].as_str() {
                "::" => {}
                "{" => {
                    let end = part.len() - 1; // the matching '}' closes the part
                    use_leaves(&part[k + 1..end], &segs, out);
                    segs.clear();
                    break;
                }
                "as" => {
                    if let Some(alias) = part.get(k + 1) {
                        if segs.last().map(String::as_str) == Some("self") {
                            segs.pop();
                        }
                        out.push((segs.clone(), alias.clone()));
                    }
                    segs.clear();
                    break;
                }
                s => segs.push(s.to_string()),
            }
            k += 1;
        }
        if segs.len() > prefix.len() || (!segs.is_empty() && segs.last().unwrap() == "self") {
            if segs.last().map(String::as_str) == Some("self") {
                segs.pop();
            }
            let name = segs.last().cloned().unwrap_or_default();
            out.push((segs, name));
        }
    }
}

struct Graph {
    files: BTreeMap<PathBuf, SourceFile>,
    by_module: BTreeMap<ModPath, PathBuf>,
    reexports: BTreeMap<PathBuf, BTreeMap<String, ModPath>>,
}

impl Graph {
    fn absolute(&self, segs: &[String], module: &ModPath) -> Option<ModPath> {
        let first = segs.first()?.as_str();
        if first == "crate" {
            return Some(segs.to_vec());
        }
        let mut cur = module.clone();
        let mut rest = segs;
        if first == "self" || first == "super" {
            while let Some(s) = rest.first() {
                match s.as_str() {
                    "super" => {
                        cur.pop();
                    }
                    "self" => {}
                    _ => break,
                }
                rest = &rest[1..];
            }
            cur.extend(rest.iter().cloned());
            return Some(cur);
        }
        let mut child = cur.clone();
        child.push(first.to_string());
        if self.by_module.contains_key(&child) {
            cur.extend(segs.iter().cloned());
            return Some(cur);
        }
        None
    }

    /// The file defining the item at an absolute path (None for a module or an unknown name).
    fn resolve(&self, path: &[String], depth: usize) -> Option<PathBuf> {
        if depth > 16 || self.by_module.contains_key(path) {
            return None;
        }
        let k = (1..path.len())
            .rev()
            .find(|&k| self.by_module.contains_key(&path[..k]))?;
        let file = &self.by_module[&path[..k]];
        let name = &path[k];
        if self.files[file].defs.contains(name) || name == "*" {
            return Some(file.clone());
        }
        let target = self.reexports.get(file)?.get(name)?;
        let mut full = target.clone();
        full.extend(path[k + 1..].iter().cloned());
        self.resolve(&full, depth + 1)
    }
}

/// Build the file-level dependency graph of the crate rooted at `root`.
fn dependency_graph(root: &Path) -> (BTreeMap<PathBuf, BTreeSet<PathBuf>>, usize) {
    let mut files = BTreeMap::new();
    load_tree(root, vec!["crate".into()], &mut files);
    let by_module = files
        .iter()
        .map(|(p, f)| (f.module.clone(), p.clone()))
        .collect();
    let mut g = Graph {
        files,
        by_module,
        reexports: BTreeMap::new(),
    };
    // Pass 1: use statements, aliases and re-exports.
    let mut uses: BTreeMap<PathBuf, Vec<(ModPath, String, bool)>> = BTreeMap::new();
    for (p, f) in &g.files {
        let t = &f.toks;
        let mut list = Vec::new();
        for i in 0..t.len() {
            if t[i] != "use" || (i > 0 && t[i - 1] == "::") {
                continue;
            }
            let public =
                i > 0 && (t[i - 1] == "pub" || (t[i - 1] == ")" && i >= 4 && t[i - 4] == "pub"));
            let end = (i..t.len()).find(|&k| t[k] == ";").unwrap_or(t.len());
            let mut leaves = Vec::new();
            use_leaves(&t[i + 1..end], &[], &mut leaves);
            for (segs, alias) in leaves {
                if let Some(abs) = g.absolute(&segs, &f.module) {
                    list.push((abs, alias, public));
                }
            }
        }
        uses.insert(p.clone(), list);
    }
    for (p, list) in &uses {
        let map = list
            .iter()
            .filter(|(_, _, public)| *public)
            .map(|(abs, alias, _)| (alias.clone(), abs.clone()))
            .collect();
        g.reexports.insert(p.clone(), map);
    }
    // Pass 2: edges.
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    let mut n_edges = 0;
    for (p, f) in &g.files {
        let t = &f.toks;
        // Token ranges of use statements, to tell a re-export's own mention from a use in code.
        let mut in_use = vec![false; t.len()];
        for i in 0..t.len() {
            if t[i] == "use" && (i == 0 || t[i - 1] != "::") {
                let end = (i..t.len()).find(|&k| t[k] == ";").unwrap_or(t.len());
                in_use[i..end].iter_mut().for_each(|x| *x = true);
            }
        }
        let mut paths: Vec<ModPath> = Vec::new();
        let mut aliases: BTreeMap<&str, &ModPath> = BTreeMap::new();
        for (abs, alias, public) in &uses[p] {
            let used_in_code =
                (0..t.len()).any(|k| !in_use[k] && t[k] == *alias && (k == 0 || t[k - 1] != "::"));
            if !public || used_in_code {
                paths.push(abs.clone());
            }
            if g.by_module.contains_key(abs) {
                aliases.insert(alias.as_str(), abs);
            }
        }
        // Paths in code: crate::/super::/self:: and module aliases.
        let mut k = 0;
        while k < t.len() {
            let head = t[k].as_str();
            let starts = !in_use[k]
                && (k == 0 || t[k - 1] != "::")
                && t.get(k + 1).map(String::as_str) == Some("::")
                && (matches!(head, "crate" | "super" | "self") || aliases.contains_key(head));
            if !starts {
                k += 1;
                continue;
            }
            let mut segs = vec![head.to_string()];
            let mut j = k + 1;
            while t.get(j).map(String::as_str) == Some("::")
                && t.get(j + 1).is_some_and(|s| is_ident(s))
            {
                segs.push(t[j + 1].clone());
                j += 2;
            }
            let abs = match aliases.get(head) {
                Some(m) if !matches!(head, "crate" | "super" | "self") => {
                    let mut a = (*m).clone();
                    a.extend(segs[1..].iter().cloned());
                    Some(a)
                }
                _ => g.absolute(&segs, &f.module),
            };
            if let Some(a) = abs {
                paths.push(a);
            }
            k = j;
        }
        let set = edges.entry(p.clone()).or_default();
        for path in paths {
            if let Some(d) = g.resolve(&path, 0) {
                if d != *p && set.insert(d) {
                    n_edges += 1;
                }
            }
        }
    }
    (edges, n_edges)
}

/// Strongly connected components of more than one file (Tarjan).
fn cycles(edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct T<'a> {
        e: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<PathBuf>>,
    }
    fn visit<'a>(s: &mut T<'a>, v: &'a PathBuf) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on.insert(v);
        if let Some(ws) = s.e.get(v) {
            for w in ws {
                if !s.index.contains_key(w) {
                    visit(s, w);
                    let lw = s.low[w];
                    let lv = s.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if s.on.contains(w) {
                    let iw = s.index[w];
                    let lv = s.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on.remove(w);
                comp.push(w.clone());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = T {
        e: edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: vec![],
        on: BTreeSet::new(),
        out: vec![],
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn describe(edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>, found: &[Vec<PathBuf>]) -> String {
    let mut msg = String::new();
    for comp in found {
        msg.push_str("cycle:\n");
        for f in comp {
            for d in edges[f].iter().filter(|d| comp.contains(d)) {
                msg.push_str(&format!("    {} -> {}\n", f.display(), d.display()));
            }
        }
    }
    msg
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn no_import_cycles_between_library_files() {
    let (edges, n) = dependency_graph(&root().join("src/lib.rs"));
    println!("library: {} files, {n} edges", edges.len());
    if std::env::var_os("USM_PRINT_EDGES").is_some() {
        for (f, ds) in &edges {
            for d in ds {
                println!("{} -> {}", f.display(), d.display());
            }
        }
    }
    assert!(
        edges.len() > 20,
        "the module walk found only {} files",
        edges.len()
    );
    let found = cycles(&edges);
    assert!(found.is_empty(), "{}", describe(&edges, &found));
}

#[test]
fn no_import_cycles_between_binary_files() {
    let (edges, _) = dependency_graph(&root().join("src/main.rs"));
    let found = cycles(&edges);
    assert!(found.is_empty(), "{}", describe(&edges, &found));
}

#[test]
fn the_checker_sees_a_cycle_when_there_is_one() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    std::fs::create_dir_all(src.join("a")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod a;\npub mod b;\n").unwrap();
    std::fs::write(src.join("a/mod.rs"), "pub mod x;\npub use x::X;\n").unwrap();
    std::fs::write(
        src.join("a/x.rs"),
        "use crate::b::{self, Y};\npub struct X(Y);\n",
    )
    .unwrap();
    std::fs::write(
        src.join("b.rs"),
        "pub struct Y;\npub fn f(_: crate::a::X) {}\n",
    )
    .unwrap();
    let (edges, n) = dependency_graph(&src.join("lib.rs"));
    assert_eq!(n, 2, "{edges:?}");
    assert_eq!(cycles(&edges).len(), 1);
    // Without the back edge the re-export alone is no dependency.
    std::fs::write(src.join("b.rs"), "pub struct Y;\n").unwrap();
    let (edges, n) = dependency_graph(&src.join("lib.rs"));
    assert_eq!(n, 1, "{edges:?}");
    assert!(cycles(&edges).is_empty());
}

#[test]
fn no_source_file_over_the_size_limit() {
    let (edges, _) = dependency_graph(&root().join("src/lib.rs"));
    let (bin, _) = dependency_graph(&root().join("src/main.rs"));
    let long: Vec<String> = edges
        .keys()
        .chain(bin.keys())
        .filter_map(|p| {
            let n = std::fs::read_to_string(p).unwrap().lines().count();
            (n > MAX_FILE_LINES).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_FILE_LINES} lines: {long:?}"
    );
}

#[test]
fn the_library_has_no_command_line_layer() {
    let (edges, _) = dependency_graph(&root().join("src/lib.rs"));
    for p in edges.keys() {
        let text = strip(&std::fs::read_to_string(p).unwrap());
        let toks = tokens(&text);
        for w in toks.windows(2) {
            let uses_crate =
                w[1] == "::" && matches!(w[0].as_str(), "clap" | "anyhow" | "indicatif");
            assert!(
                !uses_crate,
                "{} uses {} (only the binary may)",
                p.display(),
                w[0]
            );
        }
        assert!(
            !p.starts_with(root().join("src/cli")),
            "{} is in the library",
            p.display()
        );
    }
}

/// The rooms of the physics: `report` imports none of them (issue 37 item 5; its module docs
/// say it knows nothing of the physics — geometry from `spatial` is drawing, not physics).
const PHYSICS_ROOMS: &[&str] = &[
    "model",
    "kinematics",
    "dynamics",
    "allocation",
    "control",
    "scenario",
    "outcome",
    "statics",
    "evaluate",
];

#[test]
fn the_report_room_imports_no_physics() {
    let (edges, _) = dependency_graph(&root().join("src/lib.rs"));
    let report = root().join("src/report");
    let mut seen = 0;
    for p in edges.keys().filter(|p| p.starts_with(&report)) {
        seen += 1;
        let toks = tokens(&strip(&std::fs::read_to_string(p).unwrap()));
        for w in toks.windows(3) {
            let physics = w[0] == "crate" && w[1] == "::" && PHYSICS_ROOMS.contains(&w[2].as_str());
            assert!(!physics, "{} imports crate::{}", p.display(), w[2]);
        }
    }
    assert!(seen > 10, "the walk found {seen} report files");
}

/// Issue 37 item 1: study files are read by the `study` room alone. No file of the running
/// (`batch`) or review (`review`) rooms parses study-file text or defines its schema: none names
/// the located-text reader (`Document`, `deserialize_table`) or the serde attribute of study
/// tables (`deny_unknown_fields`).
#[test]
fn only_the_study_room_reads_study_files() {
    let mut seen = 0;
    for room in ["src/batch", "src/review"] {
        for p in rs_files_under(&root().join(room)) {
            seen += 1;
            let toks = tokens(&strip(&std::fs::read_to_string(&p).unwrap()));
            for t in ["Document", "deserialize_table", "deny_unknown_fields"] {
                assert!(
                    !toks.iter().any(|x| x == t),
                    "{} names {t}: study-file schema belongs to src/study",
                    p.display()
                );
            }
        }
    }
    assert!(seen > 20, "the walk found {seen} files");
}

/// Every `.rs` file under `dir` (recursively), sorted.
fn rs_files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Issue 37 item 5: no `pub fn` of the library that nothing calls — its name appears nowhere
/// but its definition in the library, the tests, benchmarks, examples and Python bindings
/// (a lower bound: a name shared with another item counts as used).
#[test]
fn no_public_function_that_nothing_calls() {
    let r = root();
    let mut words: BTreeMap<String, usize> = BTreeMap::new();
    let mut defs: Vec<(PathBuf, String)> = Vec::new();
    for dir in ["src", "tests", "benches", "examples", "python/src"] {
        for p in rs_files_under(&r.join(dir)) {
            let toks = tokens(&strip(&std::fs::read_to_string(&p).unwrap()));
            for (i, t) in toks.iter().enumerate() {
                *words.entry(t.clone()).or_default() += 1;
                let public_fn = t == "fn"
                    && i >= 1
                    && (toks[i - 1] == "pub"
                        || (toks[i - 1] == ")" && i >= 4 && toks[i - 4] == "pub"));
                if dir == "src" && public_fn {
                    if let Some(name) = toks.get(i + 1) {
                        defs.push((p.clone(), name.clone()));
                    }
                }
            }
        }
    }
    let unused: Vec<String> = defs
        .iter()
        .filter(|(_, n)| words.get(n).copied().unwrap_or(0) <= 1)
        .map(|(p, n)| format!("{}: {n}", p.strip_prefix(&r).unwrap_or(p).display()))
        .collect();
    assert!(defs.len() > 500, "found {} public functions", defs.len());
    assert!(
        unused.is_empty(),
        "public functions nothing calls:\n{}",
        unused.join("\n")
    );
}

/// Longest non-test function we accept, in lines.
const MAX_FN_LINES: usize = 120;

/// Flat checklists allowed past the limit: one check per line, nothing to name in between.
const LONG_FN_ALLOWED: &[(&str, &str)] = &[("src/model/mod.rs", "validate")];

/// `(name, first line, line count)` of every function of a file outside test code.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let s = strip(text);
    let lines: Vec<&str> = s.lines().collect();
    let mut out = Vec::new();
    let mut test_depth: Option<i64> = None; // brace depth at which a `mod tests {` opened
    let mut depth: i64 = 0;
    for (i, line) in lines.iter().enumerate() {
        let toks = tokens(line);
        let is_test_mod =
            toks.windows(2).any(|w| w[0] == "mod" && w[1] == "tests") && line.contains('{');
        if is_test_mod && test_depth.is_none() {
            test_depth = Some(depth);
        }
        let fn_at = toks
            .windows(2)
            .position(|w| w[0] == "fn" && is_ident(&w[1]));
        let attr_test = lines[i.saturating_sub(3)..i]
            .iter()
            .any(|l| l.contains("#[test]"));
        if let (Some(p), None, false) = (fn_at, test_depth, attr_test) {
            // Find the body's opening brace (or a `;` for a declaration) and match it.
            let mut d = 0i64;
            let mut opened = false;
            let start = line.find(&format!("fn {}", toks[p + 1])).unwrap_or(0);
            'scan: for (j, l) in lines.iter().enumerate().skip(i) {
                let from = if j == i { start } else { 0 };
                for c in l[from..].chars() {
                    match c {
                        '{' => {
                            d += 1;
                            opened = true;
                        }
                        '}' => d -= 1,
                        ';' if !opened => break 'scan,
                        _ => {}
                    }
                    if opened && d == 0 {
                        out.push((toks[p + 1].clone(), i + 1, j - i + 1));
                        break 'scan;
                    }
                }
            }
        }
        for c in line.chars() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if test_depth == Some(depth) {
                        test_depth = None;
                    }
                }
                _ => {}
            }
        }
    }
    out
}

fn is_test_file(p: &Path) -> bool {
    let name = p.file_name().and_then(|f| f.to_str()).unwrap_or("");
    name == "tests.rs"
        || name.ends_with("_tests.rs")
        || p.components().any(|c| c.as_os_str() == "tests")
}

#[test]
fn no_function_over_the_size_limit() {
    let (lib, _) = dependency_graph(&root().join("src/lib.rs"));
    let (bin, _) = dependency_graph(&root().join("src/main.rs"));
    let mut long = Vec::new();
    for p in lib.keys().chain(bin.keys()).filter(|p| !is_test_file(p)) {
        let rel = p
            .strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .to_string();
        for (name, line, n) in functions(&std::fs::read_to_string(p).unwrap()) {
            let allowed = LONG_FN_ALLOWED.iter().any(|(f, g)| *f == rel && *g == name);
            if n > MAX_FN_LINES && !allowed {
                long.push(format!("{rel}:{line} {name} ({n} lines)"));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FN_LINES} lines: {long:#?}"
    );
}

#[test]
fn the_function_measure_skips_tests_and_counts_bodies() {
    let src = "fn a() {\n    let x = 1;\n}\ntrait T { fn d(&self); }\n#[cfg(test)]\nmod tests {\n    fn b() {\n    }\n}\nfn c() { }\n";
    let f = functions(src);
    assert_eq!(f, vec![("a".to_string(), 1, 3), ("c".to_string(), 10, 1)]);
}

// ---------------------------------------------------------------------------------------------
// Rooms in their declared order (issue 20): the order and the file map are read from
// docs/architecture.md, so the document and the code cannot drift apart.

/// Imports against the room order tolerated during a move; each entry is (importing file,
/// imported room). The check fails on an entry no longer needed, so the list can only shrink.
/// Empty since issue 37 item 1: the sweep engine and the shard merge reach the review room's
/// report through a hook (`batch::report_hook::ReportHook`) instead of importing it.
const PENDING_EXCEPTIONS: &[(&str, &str)] = &[];

/// The rooms of the document's `## Rooms` table, lowest first: `room → rank`. A row may name
/// several rooms (`state`, `sampling`): they share a rank and may not import each other.
fn room_ranks(doc: &str) -> BTreeMap<String, usize> {
    let mut ranks = BTreeMap::new();
    let mut in_section = false;
    let mut rank = 0;
    for line in doc.lines() {
        if line.starts_with("## ") {
            in_section = line.trim() == "## Rooms";
            continue;
        }
        if !in_section || !line.starts_with("| `") {
            continue;
        }
        let first = line.split('|').nth(1).unwrap_or("");
        for (i, name) in first.split('`').enumerate() {
            if i % 2 == 1 {
                ranks.insert(name.to_string(), rank);
            }
        }
        rank += 1;
    }
    ranks
}

/// The files the document's `## Files` block lists, as `src/…` paths: a line `src/dir/` opens
/// a directory, a line indented by two spaces names a file in it (`name.rs` or `sub/name.rs`),
/// an unindented `src/name.rs` a file at the top; the rest of each line describes it.
fn listed_files(doc: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut in_section = false;
    let mut in_block = false;
    let mut dir: Option<String> = None;
    for line in doc.lines() {
        if line.starts_with("## ") {
            in_section = line.trim() == "## Files";
            continue;
        }
        if !in_section {
            continue;
        }
        if line.starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if !in_block {
            continue;
        }
        let first = line.split_whitespace().next().unwrap_or("");
        if !line.starts_with(' ') {
            if first.starts_with("src/") && first.ends_with('/') {
                dir = Some(first.to_string());
            } else {
                dir = None;
                if first.starts_with("src/") && first.ends_with(".rs") {
                    out.insert(first.to_string());
                }
            }
        } else if line.starts_with("  ") && !line.starts_with("   ") && first.ends_with(".rs") {
            if let Some(d) = &dir {
                out.insert(format!("{d}{first}"));
            }
        }
    }
    out
}

/// The room of a file given as `src/…`: the first component under `src/` (`src/kinematics.rs`
/// → `kinematics`); the binary's `main.rs` is the `cli` room; `lib.rs` is no room.
fn room_of(rel: &str) -> Option<String> {
    let rest = rel.strip_prefix("src/")?;
    match rest {
        "lib.rs" => None,
        "main.rs" => Some("cli".into()),
        _ => {
            let head = rest.split('/').next()?;
            Some(head.trim_end_matches(".rs").to_string())
        }
    }
}

/// `src/…` form of a path under `base` (the directory holding `src/`).
fn rel(base: &Path, p: &Path) -> String {
    p.strip_prefix(base)
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

/// Every import between two rooms that does not run down the declared order, for the crate
/// roots `lib.rs` and `main.rs` under `base/src` (those that exist); `exceptions` as
/// [`PENDING_EXCEPTIONS`]. Returns the violations and the exceptions actually used.
fn order_violations(
    base: &Path,
    ranks: &BTreeMap<String, usize>,
    exceptions: &[(&str, &str)],
) -> (Vec<String>, BTreeSet<(String, String)>) {
    let mut bad = Vec::new();
    let mut used = BTreeSet::new();
    for root in ["src/lib.rs", "src/main.rs"] {
        if !base.join(root).exists() {
            continue;
        }
        let (edges, _) = dependency_graph(&base.join(root));
        for (from, tos) in &edges {
            let f = rel(base, from);
            let Some(rf) = room_of(&f) else { continue };
            let Some(&kf) = ranks.get(&rf) else {
                bad.push(format!("{f}: room `{rf}` is not in the rooms table"));
                continue;
            };
            for to in tos {
                let t = rel(base, to);
                let Some(rt) = room_of(&t) else { continue };
                if rt == rf {
                    continue;
                }
                let above = ranks.get(&rt).is_some_and(|&kt| kt < kf);
                if above {
                    continue;
                }
                if exceptions.iter().any(|(ef, er)| *ef == f && *er == rt) {
                    used.insert((f.clone(), rt.clone()));
                    continue;
                }
                bad.push(format!(
                    "{f} (room `{rf}`) imports {t} (room `{rt}`), which is not above it"
                ));
            }
        }
    }
    (bad, used)
}

/// Files of `base/src` the document does not list, and listed files that do not exist.
fn map_mismatches(base: &Path, listed: &BTreeSet<String>) -> Vec<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().collect();
        entries.sort_by_key(|e| e.path());
        for e in entries {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let mut found = Vec::new();
    walk(&base.join("src"), &mut found);
    let found: BTreeSet<String> = found.iter().map(|p| rel(base, p)).collect();
    let mut out: Vec<String> = found
        .difference(listed)
        .map(|f| format!("{f} is not in the file map"))
        .collect();
    out.extend(
        listed
            .difference(&found)
            .map(|f| format!("{f} is in the file map but does not exist")),
    );
    out
}

fn architecture_doc() -> String {
    std::fs::read_to_string(root().join("docs/architecture.md")).unwrap()
}

#[test]
fn imports_run_down_the_declared_room_order() {
    let doc = architecture_doc();
    let ranks = room_ranks(&doc);
    assert!(ranks.len() >= 15, "rooms table not found: {ranks:?}");
    let (bad, used) = order_violations(&root(), &ranks, PENDING_EXCEPTIONS);
    assert!(
        bad.is_empty(),
        "imports against the room order:\n{}",
        bad.join("\n")
    );
    let stale: Vec<_> = PENDING_EXCEPTIONS
        .iter()
        .filter(|(f, r)| !used.contains(&(f.to_string(), r.to_string())))
        .collect();
    assert!(
        stale.is_empty(),
        "exceptions no longer needed (remove them): {stale:?}"
    );
}

#[test]
fn every_source_file_is_in_the_file_map() {
    let listed = listed_files(&architecture_doc());
    assert!(
        listed.len() > 100,
        "file map not found: {} files",
        listed.len()
    );
    let bad = map_mismatches(&root(), &listed);
    assert!(
        bad.is_empty(),
        "docs/architecture.md file map:\n{}",
        bad.join("\n")
    );
}

/// A small crate (`low` below `high`) and its document, in a temporary directory.
fn planted_tree() -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("high")).unwrap();
    std::fs::write(src.join("lib.rs"), "pub mod high;\npub mod low;\n").unwrap();
    std::fs::write(src.join("low.rs"), "pub struct L;\n").unwrap();
    std::fs::write(src.join("high/mod.rs"), "pub mod h;\n").unwrap();
    std::fs::write(
        src.join("high/h.rs"),
        "use crate::low::L;\npub struct H(pub L);\n",
    )
    .unwrap();
    let doc = "# Shape\n\n## Rooms\n\n| room | holds |\n|---|---|\n| `low` | below |\n\
               | `high` | above |\n\n## Files\n\n```\nsrc/lib.rs   the rooms\nsrc/low.rs   L\n\
               src/high/\n  mod.rs     declarations\n  h.rs       H, over L\n```\n"
        .to_string();
    (dir, doc)
}

#[test]
fn the_room_check_sees_an_import_against_the_order() {
    let (dir, doc) = planted_tree();
    let base = dir.path();
    let ranks = room_ranks(&doc);
    assert_eq!(ranks.len(), 2, "{ranks:?}");
    assert_eq!(
        map_mismatches(base, &listed_files(&doc)),
        Vec::<String>::new()
    );
    assert_eq!(order_violations(base, &ranks, &[]).0, Vec::<String>::new());
    // Plant an import of the higher room in the lower one.
    std::fs::write(
        base.join("src/low.rs"),
        "pub struct L;\npub fn f(_: &crate::high::h::H) {}\n",
    )
    .unwrap();
    let (bad, _) = order_violations(base, &ranks, &[]);
    assert_eq!(bad.len(), 1, "{bad:?}");
    assert!(
        bad[0].starts_with("src/low.rs (room `low`) imports src/high/h.rs"),
        "{bad:?}"
    );
    // An exception covers it and is reported as used.
    let (bad, used) = order_violations(base, &ranks, &[("src/low.rs", "high")]);
    assert!(bad.is_empty() && used.len() == 1, "{bad:?} {used:?}");
    // The same tree under the document's reversed order: the original import is the bad one.
    let reversed = doc
        .replace("| `low` | below |", "| `tmp` |")
        .replace("| `high` | above |", "| `low` | below |")
        .replace("| `tmp` |", "| `high` | above |");
    std::fs::write(base.join("src/low.rs"), "pub struct L;\n").unwrap();
    let (bad, _) = order_violations(base, &room_ranks(&reversed), &[]);
    assert_eq!(bad.len(), 1, "{bad:?}");
    // A room the table does not name.
    std::fs::write(
        base.join("src/lib.rs"),
        "pub mod high;\npub mod low;\npub mod odd;\n",
    )
    .unwrap();
    std::fs::write(base.join("src/odd.rs"), "pub fn g(_: crate::low::L) {}\n").unwrap();
    let (bad, _) = order_violations(base, &ranks, &[]);
    assert!(
        bad.iter()
            .any(|b| b.contains("room `odd` is not in the rooms table")),
        "{bad:?}"
    );
}

#[test]
fn the_file_map_check_sees_an_unlisted_and_a_missing_file() {
    let (dir, doc) = planted_tree();
    let base = dir.path();
    std::fs::write(base.join("src/high/extra.rs"), "pub struct E;\n").unwrap();
    let bad = map_mismatches(base, &listed_files(&doc));
    assert_eq!(
        bad,
        vec!["src/high/extra.rs is not in the file map".to_string()]
    );
    std::fs::remove_file(base.join("src/low.rs")).unwrap();
    std::fs::remove_file(base.join("src/high/extra.rs")).unwrap();
    let bad = map_mismatches(base, &listed_files(&doc));
    assert_eq!(
        bad,
        vec!["src/low.rs is in the file map but does not exist".to_string()]
    );
    // Continuation lines (deeper indent) never name files.
    let doc2 = doc.replace(
        "  h.rs       H, over L\n",
        "  h.rs       H, over L,\n             x.rs is a word here\n",
    );
    assert!(!listed_files(&doc2).contains("src/high/x.rs"));
}

// ---------------------------------------------------------------------------------------------
// The repository stands on its own (issue 20 item 6): the formulation is docs/model.md.

/// Equation ids cited in `text`: `USM-28`, and the ranges and alternatives written
/// `USM-28…32`, `USM-28–32`, `AC-8/9` expanded to every id they name.
fn cited_equations(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let cs: Vec<char> = text.chars().collect();
    let number = |i: &mut usize| -> Option<u32> {
        let s = *i;
        while *i < cs.len() && cs[*i].is_ascii_digit() {
            *i += 1;
        }
        cs[s..*i].iter().collect::<String>().parse().ok()
    };
    for prefix in ["USM-", "AC-"] {
        let p: Vec<char> = prefix.chars().collect();
        let mut i = 0;
        while i + p.len() < cs.len() {
            let boundary = i == 0 || !cs[i - 1].is_alphanumeric();
            if !(boundary && cs[i..i + p.len()] == p[..]) {
                i += 1;
                continue;
            }
            i += p.len();
            let Some(a) = number(&mut i) else { continue };
            out.insert(format!("{prefix}{a}"));
            match cs.get(i) {
                Some('…' | '–') => {
                    i += 1;
                    if let Some(b) = number(&mut i) {
                        out.extend((a..=b.min(a + 60)).map(|k| format!("{prefix}{k}")));
                    }
                }
                Some('/') => {
                    i += 1;
                    if let Some(b) = number(&mut i) {
                        out.insert(format!("{prefix}{b}"));
                    }
                }
                _ => {}
            }
        }
    }
    out
}

#[test]
fn every_cited_equation_is_in_docs_model() {
    let model = std::fs::read_to_string(root().join("docs/model.md")).expect("docs/model.md");
    let stated = cited_equations(&model);
    let mut cited = BTreeMap::new();
    let (lib, _) = dependency_graph(&root().join("src/lib.rs"));
    let (bin, _) = dependency_graph(&root().join("src/main.rs"));
    for p in lib.keys().chain(bin.keys()) {
        for id in cited_equations(&std::fs::read_to_string(p).unwrap()) {
            cited.entry(id).or_insert_with(|| rel(&root(), p));
        }
    }
    assert!(cited.len() > 30, "only {} citations found", cited.len());
    let missing: Vec<String> = cited
        .iter()
        .filter(|(id, _)| !stated.contains(*id))
        .map(|(id, f)| format!("{id} (cited in {f})"))
        .collect();
    assert!(
        missing.is_empty(),
        "cited in src/ but not in docs/model.md: {missing:?}"
    );
}

#[test]
fn citations_are_read_with_their_ranges() {
    let ids = cited_equations("USM-28…31, AC-8/9 and USM-42; not XUSM-5, USM-, AC-10–11");
    let want = [
        "USM-28", "USM-29", "USM-30", "USM-31", "AC-8", "AC-9", "USM-42", "AC-10", "AC-11",
    ];
    assert_eq!(
        ids,
        want.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>()
    );
}

#[test]
fn sources_cite_the_repository_formulation() {
    // README.md and the library's front page send readers to docs/model.md, not to a SPEC
    // outside the repository.
    for f in ["README.md", "src/lib.rs"] {
        let text = std::fs::read_to_string(root().join(f)).unwrap();
        assert!(
            text.contains("docs/model.md"),
            "{f} does not point to docs/model.md"
        );
        assert!(!text.contains("SPEC.md"), "{f} still points to SPEC.md");
    }
    let (lib, _) = dependency_graph(&root().join("src/lib.rs"));
    let (bin, _) = dependency_graph(&root().join("src/main.rs"));
    // In comments only: string literals that reach output files (summary.json's `source`, a
    // preset's TOML) keep their text so that outputs stay byte-identical.
    let cites_spec = |text: &str| {
        text.lines()
            .any(|l| l.find("//").is_some_and(|i| l[i..].contains("SPEC §")))
    };
    let outside: Vec<String> = lib
        .keys()
        .chain(bin.keys())
        .filter(|p| cites_spec(&std::fs::read_to_string(p).unwrap()))
        .map(|p| rel(&root(), p))
        .collect();
    assert!(
        outside.is_empty(),
        "cite docs/model.md, not SPEC: {outside:?}"
    );
}

/// The items `error.rs` of a room defines (`struct`, `enum`, `fn`, `type` names).
fn error_items(text: &str) -> BTreeSet<String> {
    let toks = tokens(&strip(text));
    toks.windows(2)
        .filter(|w| matches!(w[0].as_str(), "struct" | "enum" | "fn" | "type"))
        .map(|w| w[1].clone())
        .collect()
}

/// Errors live in `error.rs` (issue 37 item 5): the `mod.rs` of no room directory defines an
/// error type (`thiserror::Error`), and no file of a room with an `error.rs` imports one of its
/// items through the room's `mod.rs` (`super::X`, `crate::room::X`) instead of `error::X`.
fn error_placement(base: &Path) -> Vec<String> {
    let mut bad = Vec::new();
    let mut dirs = vec![base.join("src")];
    while let Some(d) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            if e.path().is_dir() {
                dirs.push(e.path());
            }
        }
        let modrs = d.join("mod.rs");
        if let Ok(t) = std::fs::read_to_string(&modrs) {
            let s = strip(&t);
            if s.contains("thiserror::Error") || s.contains("thiserror :: Error") {
                bad.push(format!(
                    "{}: defines an error (move it to error.rs)",
                    rel(base, &modrs)
                ));
            }
        }
        let Ok(err) = std::fs::read_to_string(d.join("error.rs")) else {
            continue;
        };
        let items = error_items(&err);
        let room = rel(&base.join("src"), &d).replace('/', "::");
        let mut children = Vec::new();
        let mut stack = vec![d.clone()];
        while let Some(p) = stack.pop() {
            if p.is_dir() {
                if let Ok(es) = std::fs::read_dir(&p) {
                    stack.extend(es.flatten().map(|e| e.path()));
                }
            } else if p.extension().is_some_and(|x| x == "rs") {
                children.push(p);
            }
        }
        for p in children {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if name == "mod.rs" && p.parent() == Some(d.as_path()) || name == "error.rs" {
                continue;
            }
            let text = strip(&std::fs::read_to_string(&p).unwrap());
            let direct = p.parent() == Some(d.as_path());
            let mut prefixes = vec![format!("crate::{room}::")];
            prefixes.push(if direct { "super::" } else { "super::super::" }.to_string());
            for stmt in text.split(';') {
                let Some(u) = stmt.trim().strip_prefix("use ") else {
                    continue;
                };
                let u: String = u.chars().filter(|c| !c.is_whitespace()).collect();
                let Some(rest) = prefixes.iter().find_map(|pre| u.strip_prefix(pre.as_str()))
                else {
                    continue;
                };
                if rest.starts_with("error::") || (!direct && rest.starts_with("super::")) {
                    continue;
                }
                let top: Vec<&str> = rest
                    .trim_start_matches('{')
                    .trim_end_matches('}')
                    .split(',')
                    .map(|x| x.split("::").next().unwrap_or(x))
                    .collect();
                for x in top.iter().filter(|x| items.contains(**x)) {
                    bad.push(format!(
                        "{}: imports `{x}` through the room's mod.rs (use {}error::{x})",
                        rel(base, &p),
                        prefixes[1]
                    ));
                }
            }
        }
    }
    bad.sort();
    bad.dedup();
    bad
}

#[test]
fn errors_live_in_error_rs_and_are_imported_from_there() {
    let bad = error_placement(&root());
    assert!(bad.is_empty(), "errors out of place:\n{}", bad.join("\n"));
}

#[test]
fn the_error_check_sees_an_error_in_mod_rs_and_an_import_through_it() {
    let dir = tempfile::tempdir().unwrap();
    let room = dir.path().join("src/room");
    std::fs::create_dir_all(&room).unwrap();
    std::fs::write(
        room.join("mod.rs"),
        "mod error;\npub use error::RoomError;\n#[derive(thiserror::Error, Debug)]\n#[error(\"x\")]\npub struct Other;\n",
    )
    .unwrap();
    std::fs::write(room.join("error.rs"), "pub struct RoomError;\n").unwrap();
    std::fs::write(
        room.join("child.rs"),
        "use super::{Other, RoomError};\nuse super::error::RoomError as E;\n",
    )
    .unwrap();
    let bad = error_placement(dir.path());
    assert_eq!(bad.len(), 2, "{bad:?}");
    assert!(
        bad[0].contains("child.rs") && bad[0].contains("RoomError"),
        "{bad:?}"
    );
    assert!(bad[1].contains("mod.rs: defines an error"), "{bad:?}");
}

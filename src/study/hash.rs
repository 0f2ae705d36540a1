//! Stable hashes of studies and cases: a canonical text of TOML tables (keys sorted, floats by
//! their bits) fed to SHA-256. The recipes are part of the resume contract: a case whose hash
//! is in `cases.partial.csv` is not run again, so changing a recipe reruns every study.

use sha2::{Digest, Sha256};

/// Canonical text of a table: keys sorted, floats by their bits; stable across runs and
/// platforms and independent of map ordering.
pub fn canonical_table(t: &toml::Table, out: &mut String) {
    let mut keys: Vec<&String> = t.keys().collect();
    keys.sort();
    out.push('{');
    for k in keys {
        out.push_str(&format!("{k:?}="));
        canonical_value(&t[k], out);
        out.push(';');
    }
    out.push('}');
}

/// Canonical text of a value (see [`canonical_table`]).
pub fn canonical_value(v: &toml::Value, out: &mut String) {
    match v {
        toml::Value::String(s) => out.push_str(&format!("s{s:?}")),
        toml::Value::Integer(i) => out.push_str(&format!("i{i}")),
        toml::Value::Float(f) => out.push_str(&format!("f{:016x}", f.to_bits())),
        toml::Value::Boolean(b) => out.push_str(if *b { "T" } else { "F" }),
        toml::Value::Datetime(d) => out.push_str(&format!("d{d}")),
        toml::Value::Array(a) => {
            out.push('[');
            for x in a {
                canonical_value(x, out);
                out.push(',');
            }
            out.push(']');
        }
        toml::Value::Table(t) => canonical_table(t, out),
    }
}

/// Lower-case hex of bytes.
fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// SHA-256 of `parts`, each followed by a zero byte, truncated to 128 bits (hex).
fn sha_hex(parts: &[&[u8]]) -> String {
    let mut h = Sha256::new();
    for p in parts {
        h.update(p);
        h.update([0]);
    }
    hex(&h.finalize()[..16])
}

/// The identity of this build: a hash of the crate's sources, `Cargo.toml` and `Cargo.lock`
/// computed by `build.rs` (issue 39 item 4). Two builds from different sources have different
/// identities, so a study's hash ([`study_hash`]) — and with it a resumed sweep's or
/// optimisation's journal — changes with any change of the code that could change results.
pub const BUILD_ID: &str = env!("USM_BUILD_ID");

/// SHA-256 (hex, full length) of the study text, the canonical base design, the tool version
/// and the build identity ([`BUILD_ID`]).
pub fn study_hash(text: &str, design: &toml::Table) -> String {
    let mut h = Sha256::new();
    h.update(b"usm-study study v1\0");
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    h.update([0]);
    h.update(BUILD_ID.as_bytes());
    h.update([0]);
    h.update(text.as_bytes());
    h.update([0]);
    let mut buf = String::new();
    canonical_table(design, &mut buf);
    h.update(buf.as_bytes());
    hex(&h.finalize())
}

/// Hashes of a resolved case: `(case hash, design hash)`. The case hash covers the tool
/// version, the design, the scenario-side table and the case seed; the design hash (the
/// vehicle cache key) the design alone.
pub fn case_hashes(design: &toml::Table, scenario: &toml::Table, seed: u64) -> (String, String) {
    let mut d = String::new();
    canonical_table(design, &mut d);
    let mut s = String::new();
    canonical_table(scenario, &mut s);
    let version = env!("CARGO_PKG_VERSION").as_bytes();
    let hash = sha_hex(&[
        b"usm-study case v1",
        version,
        d.as_bytes(),
        s.as_bytes(),
        &seed.to_le_bytes(),
    ]);
    let design_hash = sha_hex(&[b"design", d.as_bytes()]);
    (hash, design_hash)
}

/// Hash of a case whose overrides could not be applied: the study hash, the case id and the
/// axis values.
pub fn unresolved_case_hash(study_hash: &str, id: usize, values: &[toml::Value]) -> String {
    let mut s = String::new();
    for v in values {
        canonical_value(v, &mut s);
    }
    sha_hex(&[
        b"usm-study unresolved case v1",
        study_hash.as_bytes(),
        &(id as u64).to_le_bytes(),
        s.as_bytes(),
    ])
}

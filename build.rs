//! The build identity (issue 39 item 4): a hash of the crate's sources, `Cargo.toml` and
//! `Cargo.lock`, exported as `USM_BUILD_ID`. Study hashes include it, so a journal written by a
//! build with other sources is never resumed silently (`src/study/hash.rs`). Also the
//! compiler's `rustc --version` as `USM_RUSTC_VERSION`, recorded in `manifest.json`.

use std::path::{Path, PathBuf};

fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// FNV-1a over `bytes`, continuing from `h`.
fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn main() {
    let mut files = Vec::new();
    collect(Path::new("src"), &mut files);
    files.push(PathBuf::from("Cargo.toml"));
    files.push(PathBuf::from("Cargo.lock"));
    files.sort();
    // Two FNV-1a streams with different offsets: 128 bits of identity (not a cryptographic
    // hash: it tells builds apart, it does not authenticate them).
    let (mut a, mut b) = (0xcbf2_9ce4_8422_2325u64, 0x6c62_272e_07bb_0142u64);
    for f in &files {
        let name = f.to_string_lossy().replace('\\', "/");
        let body = std::fs::read(f).unwrap_or_default();
        for part in [name.as_bytes(), &[0], &body, &[0]] {
            a = fnv(a, part);
            b = fnv(b, part);
        }
    }
    println!("cargo:rustc-env=USM_BUILD_ID={a:016x}{b:016x}");
    // The compiler's version for the manifest (issue 42 item 6); empty when it cannot be asked.
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = std::process::Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    println!("cargo:rustc-env=USM_RUSTC_VERSION={version}");
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=Cargo.toml");
    println!("cargo:rerun-if-changed=Cargo.lock");
}

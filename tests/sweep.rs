//! End-to-end tests of `usm-study sweep`, `merge`, `report` and `tcm` on small static studies,
//! and of the success criteria on a small transport study.

mod common;

use common::{read, run, stderr, sweep, write};
use proptest::prelude::*;

/// 12 cases: 3 link counts × 2 rules × 2 offsets, all valid.
const STUDY12: &str = r#"
[study]
name = "t12"
seed = 11

[design.generator]
links = 5

[static]
samples = 48
sampling = "lhs"

[[axis]]
name = "design.links"
values = [4, 5, 6]

[[axis]]
name = "design.thruster_rule"
values = ["paper", "distributed"]

[[axis]]
name = "design.generator.longitudinal_offset"
range = { start = 0.1, stop = 0.2, steps = 2 }
"#;

#[test]
fn jobs_do_not_change_results() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "study.toml", STUDY12);
    let o1 = sweep(&s, &d.path().join("j1"), &["--jobs", "1"]);
    assert_eq!(o1.status.code(), Some(0), "{}", stderr(&o1));
    let o2 = sweep(&s, &d.path().join("j2"), &["--jobs", "2"]);
    assert_eq!(o2.status.code(), Some(0), "{}", stderr(&o2));
    let a = read(&d.path().join("j1/cases.csv"));
    assert_eq!(a, read(&d.path().join("j2/cases.csv")));
    let text = String::from_utf8(a).unwrap();
    assert_eq!(text.lines().count(), 13);
    assert!(
        text.lines().skip(1).all(|l| l.ends_with(",ok,\"\"")),
        "{text}"
    );
    for f in [
        "cases.parquet",
        "summary.md",
        "manifest.json",
        "study.toml",
        "plots/pareto.svg",
    ] {
        assert!(d.path().join("j1").join(f).is_file(), "{f}");
    }
    let m: serde_json::Value =
        serde_json::from_slice(&read(&d.path().join("j2/manifest.json"))).unwrap();
    assert_eq!(m["cases"]["ok"], 12);
    assert_eq!(m["jobs"], 2);
}

#[test]
fn shards_merged_equal_unsharded() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "study.toml", STUDY12);
    let full = d.path().join("full");
    assert_eq!(sweep(&s, &full, &["--jobs", "2"]).status.code(), Some(0));
    let mut dirs = Vec::new();
    for i in 0..3 {
        let out = d.path().join(format!("s{i}"));
        let o = sweep(&s, &out, &["--shard", &format!("{i}/3"), "--jobs", "1"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        dirs.push(out.to_str().unwrap().to_string());
    }
    let merged = d.path().join("merged");
    let mut args = vec!["merge"];
    args.extend(dirs.iter().map(String::as_str));
    args.extend(["--out", merged.to_str().unwrap()]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        read(&full.join("cases.csv")),
        read(&merged.join("cases.csv"))
    );
    assert!(merged.join("summary.md").is_file());
    // Issue 42 item 6: the manifests name no path of this machine — the study and the shards
    // relative to the output directory — and record the compiler, the CPU and the checkout.
    let root = std::fs::canonicalize(d.path()).unwrap();
    for dir in [&full, &merged] {
        let text = String::from_utf8(read(&dir.join("manifest.json"))).unwrap();
        assert!(!text.contains(root.to_str().unwrap()), "{text}");
        assert!(!text.contains(d.path().to_str().unwrap()), "{text}");
        let m: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(m["study_file"], "../study.toml");
        assert!(m["rustc"].as_str().unwrap().starts_with("rustc "), "{text}");
        assert!(m["cpu"].as_str().unwrap().contains("logical CPU"), "{text}");
    }
    let m: serde_json::Value =
        serde_json::from_slice(&read(&merged.join("manifest.json"))).unwrap();
    assert_eq!(
        m["merged_from"],
        serde_json::json!(["../s0", "../s1", "../s2"])
    );
    // Regenerating the report works from the directory alone.
    std::fs::remove_file(merged.join("summary.md")).unwrap();
    let o = run(&["report", merged.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(merged.join("summary.md").is_file());
    // Shards of another study are refused.
    let other = write(
        d.path(),
        "other.toml",
        &STUDY12.replace("seed = 11", "seed = 12"),
    );
    let od = d.path().join("o0");
    assert_eq!(
        sweep(&other, &od, &["--shard", "0/3"]).status.code(),
        Some(0)
    );
    let o = run(&[
        "merge",
        &dirs[1],
        od.to_str().unwrap(),
        "--out",
        d.path().join("bad").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("another study"), "{}", stderr(&o));
}

#[test]
fn interrupted_sweep_resumes_without_recomputing() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "study.toml", STUDY12);
    let out = d.path().join("r");
    let o = sweep(&s, &out, &["--jobs", "2", "--max-cases", "5"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!out.join("cases.csv").exists());
    let partial = std::fs::read_to_string(out.join("cases.partial.csv")).unwrap();
    assert_eq!(partial.lines().count(), 6);
    // Simulate a row cut off by the interruption.
    std::fs::write(out.join("cases.partial.csv"), format!("{partial}7,abc")).unwrap();
    let o = sweep(&s, &out, &["--jobs", "2", "--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("resumed 5 cases, ran 7"),
        "{}",
        stderr(&o)
    );
    let m: serde_json::Value = serde_json::from_slice(&read(&out.join("manifest.json"))).unwrap();
    assert_eq!(m["cases"]["resumed"], 5);
    assert_eq!(m["cases"]["ran"], 7);
    let full = d.path().join("full");
    assert_eq!(sweep(&s, &full, &["--jobs", "1"]).status.code(), Some(0));
    assert_eq!(read(&full.join("cases.csv")), read(&out.join("cases.csv")));
    // A second resume recomputes nothing.
    let o = sweep(&s, &out, &["--resume"]);
    assert!(
        stderr(&o).contains("resumed 12 cases, ran 0"),
        "{}",
        stderr(&o)
    );
    assert_eq!(read(&full.join("cases.csv")), read(&out.join("cases.csv")));
}

#[test]
fn unknown_parameter_fails_before_running() {
    let d = tempfile::tempdir().unwrap();
    let s = write(
        d.path(),
        "study.toml",
        &STUDY12.replace("design.generator.longitudinal_offset", "control.k_nope"),
    );
    let out = d.path().join("o");
    let o = sweep(&s, &out, &[]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("unknown parameter `control.k_nope`"), "{e}");
    assert!(
        e.contains("valid names")
            && e.contains("design.generator.links")
            && e.contains("static.samples"),
        "{e}"
    );
    assert!(e.contains("study.toml:22:1"), "{e}");
    assert!(!out.exists(), "nothing may run");
}

#[test]
fn malformed_files_name_file_line_and_key() {
    let d = tempfile::tempdir().unwrap();
    let s = write(
        d.path(),
        "bad.toml",
        &format!("{STUDY12}\n[doe]\nkind = \"grid\"\ncases = 4\n"),
    );
    let o = sweep(&s, &d.path().join("o"), &[]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("bad.toml:") && e.contains("doe.cases"), "{e}");
    let s = write(
        d.path(),
        "bad2.toml",
        &STUDY12.replace("values = [4, 5, 6]", "values = [4, 5, 6"),
    );
    let o = sweep(&s, &d.path().join("o"), &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("bad2.toml:"), "{}", stderr(&o));
    let s = write(
        d.path(),
        "bad3.toml",
        &STUDY12.replace("sampling = \"lhs\"", "sampling = \"lhs\"\nsampels = 3"),
    );
    let o = sweep(&s, &d.path().join("o"), &[]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("bad3.toml:12:1") && e.contains("static.sampels"),
        "{e}"
    );
}

#[test]
fn failing_and_invalid_cases_are_recorded() {
    let d = tempfile::tempdir().unwrap();
    let text = r#"
[study]
name = "f"

[design.generator]
links = 4

[static]
samples = 16

[[axis]]
name = "design.thruster_rule"
values = ["paper", "none"]

[[axis]]
name = "design.radius"
values = [0.085, 0.07]
"#;
    // A value its key refuses is refused when the study is loaded (issue 39), not recorded
    // as a skipped case.
    let bad = write(
        d.path(),
        "bad.toml",
        &text.replace("[0.085, 0.07]", "[0.085, -1.0]"),
    );
    let o = sweep(&bad, &d.path().join("bad"), &["--dry-run"]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("bad.toml:17:1: axis[1].values: the value -1.0 of `design.radius`"),
        "{e}"
    );
    let s = write(d.path(), "f.toml", text);
    let out = d.path().join("o");
    let o = sweep(&s, &out, &["--jobs", "2"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 4);
    assert!(rows[0].ends_with(",ok,\"\""), "{csv}");
    assert!(
        rows[2].contains(",failed,") && rows[2].contains("thruster"),
        "{csv}"
    );
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        md.contains("## Cases left out") && md.contains("| failed | no_failure | 2 |"),
        "{md}"
    );
}

#[test]
fn dry_run_lists_cases() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "study.toml", STUDY12);
    let out = d.path().join("o");
    let o = sweep(&s, &out, &["--dry-run"]);
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(text.lines().count(), 13, "{text}");
    assert!(text.contains("design.thruster_rule=distributed"), "{text}");
    assert!(!out.exists());
}

#[test]
fn another_seed_changes_the_cases_and_not_the_file() {
    // `--seed N` runs the study at another [study] seed: every case hash changes (the
    // seed is part of it), the file is untouched, and without --out the output is the
    // study's own plus `-seed-N` (the committed output of the file's seed is kept).
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "study.toml", STUDY12);
    let hashes = |extra: &[&str]| -> Vec<String> {
        let mut args = vec!["sweep", s.to_str().unwrap(), "--dry-run"];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .map(str::to_string)
            .collect()
    };
    let (own, other) = (hashes(&[]), hashes(&["--seed", "7"]));
    assert_eq!(own.len(), other.len());
    assert!(other[0].ends_with("-seed-7"), "{}", other[0]);
    for (a, b) in own.iter().zip(&other).skip(1) {
        assert_ne!(a.split_whitespace().nth(1), b.split_whitespace().nth(1));
    }
    // The file's own seed given explicitly is the file itself.
    assert_eq!(own[1..], hashes(&["--seed", "11"])[1..]);
    assert_eq!(std::fs::read_to_string(&s).unwrap(), STUDY12);
    // An edited seed keeps every line where it was (error locations stay true).
    let edited = usm_study::study::with_seed(STUDY12, 7).unwrap();
    assert_eq!(edited.lines().count(), STUDY12.lines().count());
    assert!(edited.contains("seed = 7\n"), "{edited}");
}

#[test]
fn tcm_on_the_paper_design() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("tcm");
    let o = run(&[
        "tcm",
        "usm-paper",
        "--samples",
        "300",
        "--seed",
        "5",
        "--out",
        out.to_str().unwrap(),
        "--jobs",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for f in [
        "samples.csv",
        "samples.parquet",
        "summary.json",
        "sigma_min_hist.svg",
        "sigma_min_slice.svg",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let s: serde_json::Value = serde_json::from_slice(&read(&out.join("summary.json"))).unwrap();
    assert_eq!(
        s["straight"]["rank"], 5,
        "the straight configuration is singular"
    );
    assert_eq!(s["straight"]["lost_axis"], "roll");
    let f = s["singular_fraction"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&f));
    assert_eq!(s["samples"], 300);
    assert_eq!(
        std::fs::read_to_string(out.join("samples.csv"))
            .unwrap()
            .lines()
            .count(),
        301
    );
    // Same result with one thread.
    let out1 = d.path().join("tcm1");
    let o = run(&[
        "tcm",
        "usm-paper",
        "--samples",
        "300",
        "--seed",
        "5",
        "--out",
        out1.to_str().unwrap(),
        "--jobs",
        "1",
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        read(&out.join("samples.csv")),
        read(&out1.join("samples.csv"))
    );
    assert_eq!(
        read(&out.join("summary.json")),
        read(&out1.join("summary.json"))
    );
}

proptest! {
    #[test]
    fn axis_path_parser_never_panics(s in "\\PC{0,40}") {
        let _ = usm_study::input::keypath::KeyPath::parse(&s);
    }

    #[test]
    fn axis_path_roundtrip(s in "[a-z_]{1,6}(\\[[0-9]{1,3}\\])?(\\.[a-z_]{1,6}(\\[[0-9]{1,2}\\]){0,2}){0,3}") {
        let p = usm_study::input::keypath::KeyPath::parse(&s).unwrap();
        let again = usm_study::input::keypath::KeyPath::parse(&p.to_string()).unwrap();
        prop_assert_eq!(p, again);
    }
}

/// `usm-study … | head -1`: once the reader has gone, the program ends quietly (SIGPIPE's
/// default action), never with a panic and exit code 101. The dry run of the 100 000-case
/// study prints far more than a pipe holds, so it must write after the reader is gone.
#[test]
fn closed_output_pipe_ends_quietly() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let mut child = common::usm_study()
        .args(["sweep", "studies/static_large.toml", "--dry-run"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn usm-study");
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with("study"), "{first}");
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(out.status.code(), Some(101), "{err}");
}

/// 6 short transport cases: three start offsets (final cross-track errors of both signs) ×
/// two final cross-track bounds, the tight one missed by every case. `metrics.band` is wide,
/// so every segment counts as converged at once and the bound alone decides success.
const SIGNED: &str = r#"
[study]
name = "signed"
seed = 3
pareto = ["energy_per_metre", "final_cross_track"]

[design]
preset = "usm-paper"

[scenario]
mode = "transport"
duration = 20.0

[metrics]
band = 100.0

[[axis]]
name = "initial.position"
values = [[0.0, -3.0, 0.0], [0.0, -1.0, 0.0], [0.0, 2.0, 0.0]]

[[axis]]
name = "success.cross_track_bound"
values = [10.0, 1e-6]
"#;

/// The case ids (`#id` in the third cell) of the table rows of `section` of `md` (up to the
/// next `## ` heading), skipping the header row.
fn section_ids(md: &str, section: &str) -> Vec<i64> {
    let start = md
        .find(section)
        .unwrap_or_else(|| panic!("{section} in {md}"));
    let body = &md[start + section.len()..];
    let body = &body[..body.find("\n## ").unwrap_or(body.len())];
    body.lines()
        .filter(|l| l.starts_with('|'))
        .filter_map(|l| {
            let cell = l.split('|').map(str::trim).find(|c| c.starts_with('#'))?;
            cell[1..].parse().ok()
        })
        .collect()
}

#[test]
fn unsuccessful_cases_are_left_out_of_the_ranking() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "signed.toml", SIGNED);
    let out = d.path().join("o");
    let o = sweep(&s, &out, &["--jobs", "2"]);
    // Unsuccessful cases are not failures: exit 0.
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("3 ok, 3 unsuccessful, 0 failed"),
        "{}",
        stderr(&o)
    );
    let csv = String::from_utf8(read(&out.join("cases.csv"))).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    // Rows without the quoted axis arrays (their commas), so that columns line up.
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let mut cells = Vec::new();
            let mut rest = l;
            while !rest.is_empty() {
                let (cell, tail) = if let Some(r) = rest.strip_prefix('"') {
                    let end = r.find('"').unwrap();
                    (&r[..end], r[end + 1..].strip_prefix(',').unwrap_or(""))
                } else {
                    rest.split_once(',').unwrap_or((rest, ""))
                };
                cells.push(cell.to_string());
                rest = tail;
            }
            cells
        })
        .collect();
    let (status, reason, ct) = (col("status"), col("reason"), col("final_cross_track"));
    let ok: Vec<i64> = (0..6)
        .filter(|&i| rows[i as usize][status] == "ok")
        .collect();
    assert_eq!(ok, vec![0, 2, 4], "{csv}");
    for i in [1, 3, 5] {
        assert_eq!(rows[i][status], "unsuccessful", "{csv}");
        assert!(
            rows[i][reason].starts_with("cross_track_bound: |final_cross_track| = "),
            "{csv}"
        );
        // A flag with a value in every case: stored as a boolean.
        assert_eq!(rows[i][col("success")], "false");
    }
    let m: serde_json::Value = serde_json::from_slice(&read(&out.join("manifest.json"))).unwrap();
    assert_eq!(m["cases"]["unsuccessful"], 3);

    let md = String::from_utf8(read(&out.join("summary.md"))).unwrap();
    assert!(
        md.contains("3 left out: 3 missed `cross_track_bound`"),
        "{md}"
    );
    let best = section_ids(&md, "## Best case by each metric");
    assert!(
        !best.is_empty() && best.iter().all(|i| ok.contains(i)),
        "{best:?}\n{md}"
    );
    let front = section_ids(&md, "## Pareto-optimal cases");
    assert!(
        !front.is_empty() && front.iter().all(|i| ok.contains(i)),
        "{front:?}\n{md}"
    );
    let left = section_ids(&md, "## Cases left out");
    assert_eq!(left, vec![1, 3, 5], "{md}");
    assert!(
        md.contains("| unsuccessful | cross_track_bound | 3 |"),
        "{md}"
    );

    // The signed final cross-track error is ranked by magnitude: the best case is the one
    // nearest the path, not the most negative one (a precondition checks they differ).
    let x = |i: i64| rows[i as usize][ct].parse::<f64>().unwrap();
    let by_value = *ok.iter().min_by(|a, b| x(**a).total_cmp(&x(**b))).unwrap();
    let by_abs = *ok
        .iter()
        .min_by(|a, b| x(**a).abs().total_cmp(&x(**b).abs()))
        .unwrap();
    assert_ne!(by_value, by_abs, "{csv}");
    let line = md
        .lines()
        .find(|l| l.starts_with("| `final_cross_track` |"))
        .unwrap();
    assert!(line.contains(&format!("| min abs | #{by_abs} |")), "{line}");
    // On the front too: |x| makes the case nearest the path dominate the most negative one.
    assert!(
        !front.contains(&by_value) || by_value == by_abs,
        "{front:?}"
    );
}

#[test]
fn bad_success_definitions_name_file_line_and_key() {
    let d = tempfile::tempdir().unwrap();
    for (name, line, key) in [
        (
            "neg.toml",
            "convergence_window = -1.0",
            "success.convergence_window",
        ),
        (
            "text.toml",
            "cross_track_bound = \"far\"",
            "success.cross_track_bound",
        ),
        (
            "frac.toml",
            "max_saturation_fraction = 1.5",
            "success.max_saturation_fraction",
        ),
    ] {
        let text = SIGNED.replace("[metrics]", &format!("[success]\n{line}\n\n[metrics]"));
        let n = text.lines().position(|l| l == line).unwrap() + 1;
        let s = write(d.path(), name, &text);
        let out = d.path().join(name);
        let o = sweep(&s, &out.with_extension("out"), &[]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains(&format!("{name}:{n}:")) && e.contains(key),
            "{e}"
        );
        assert!(!out.with_extension("out").exists(), "nothing may run: {e}");
    }
}

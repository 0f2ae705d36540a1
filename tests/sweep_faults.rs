//! Single thruster faults of a study (`[faults]`): every case is re-run once per thruster with
//! that thruster dead at 30 s, the fault columns and the layouts × single-faults table follow,
//! and the table is the same for any thread count.

mod common;

use common::{read, stderr, sweep, write};

const STUDY: &str = r#"
[study]
name = "faults"
[design]
preset = "usm-paper"
[scenario]
mode = "transport"
duration = 170.0
[success]
cross_track_bound = 0.2
convergence_window = 90.0
[faults]
single = true
at = 30.0
kind = "dead"
informed = true
[[axis]]
name = "allocation.method"
values = ["pinv", "qp"]
"#;

/// The column `name` of a `cases.csv` whose rows have no commas inside cells.
fn column(csv: &str, name: &str) -> Vec<String> {
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = head
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name}"));
    lines
        .map(|l| l.split(',').nth(i).unwrap().to_string())
        .collect()
}

#[test]
fn every_thruster_fails_once_and_the_summary_tables_the_outcome() {
    let d = tempfile::tempdir().unwrap();
    let study = write(d.path(), "faults.toml", STUDY);
    let (one, two) = (d.path().join("j1"), d.path().join("j2"));
    for (out, jobs) in [(&one, "1"), (&two, "2")] {
        let o = sweep(&study, out, &["--jobs", jobs]);
        assert!(o.status.success(), "{}", stderr(&o));
        // The end of a sweep names its answer and where the review page is.
        let err = stderr(&o);
        assert!(
            err.contains("[sweep] best by `") && err.contains(" at "),
            "{err}"
        );
        assert!(
            err.contains("[sweep] review: ") && err.contains("report.html"),
            "{err}"
        );
    }
    let csv = String::from_utf8(read(&one.join("cases.csv"))).unwrap();
    assert_eq!(read(&one.join("cases.csv")), read(&two.join("cases.csv")));
    assert_eq!(column(&csv, "status"), ["ok", "ok"]);
    // usm-paper has 7 thrusters (T1 … T7, numbered from 1 in the columns too): each case ran
    // 7 faulted runs. Measured: losing T2 (a main longitudinal thruster) fails the mission
    // with either allocator — pinv misses the cross-track bound (final cross-track beyond
    // 0.2 m), qp saturates; the other six are survived (T1, T5 and T7 are idle on this planar
    // path: objective change 0).
    for j in 1..=7 {
        let ok = column(&csv, &format!("fault.t{j}.success"));
        let want = if j == 2 { "false" } else { "true" };
        assert_eq!(ok, [want, want], "thruster T{j}");
    }
    assert!(!csv.contains("fault.t0.") && !csv.contains("fault.t8."));
    for x in column(&csv, "fault_tolerance") {
        assert_eq!(x.parse::<f64>().unwrap(), 6.0 / 7.0);
    }
    // A thruster number: written as an integer.
    assert_eq!(column(&csv, "worst_fault"), ["2", "2"]);
    assert_eq!(column(&csv, "design_thrusters"), ["7", "7"]);
    // pinv misses cross_track_bound (index 3 in Criterion::ALL), qp max_saturation_fraction (2).
    assert_eq!(column(&csv, "fault.t2.missed"), ["3.0", "2.0"]);
    assert_eq!(column(&csv, "fault.t1.change"), ["0.0", "0.0"]);
    assert_eq!(column(&csv, "fault.t4.missed"), ["NaN", "NaN"]);
    let md = std::fs::read_to_string(one.join("summary.md")).unwrap();
    assert!(md.contains("## Single thruster faults"), "{md}");
    assert!(
        md.contains("| case | fault_tolerance | worst_fault | t1 | t2 | t3 | t4 | t5 | t6 | t7 |")
    );
    assert!(md.contains("| 0.8571 | t2 | ✓ +0.0 % | ✗ "), "{md}");
    let html = std::fs::read_to_string(one.join("report.html")).unwrap();
    assert!(html.contains("Single thruster faults"));
}

#[test]
fn a_bad_faults_section_is_a_located_error() {
    let d = tempfile::tempdir().unwrap();
    for (bad, key) in [
        ("kind = \"dead\"\nat = -1.0", "faults.at"),
        ("at = 30.0\nkind = \"melted\"", "faults.kind"),
        ("at = 30.0\nsingle = false", "faults.single"),
        ("at = 30.0\nkind = \"derated\"", "faults.value"),
        // Issue 39: a fault after the run's end (170 s) never strikes.
        ("at = 170.0", "faults.at"),
        ("at = 500.0", "not within the run"),
    ] {
        let text = STUDY.replace(
            "single = true\nat = 30.0\nkind = \"dead\"\ninformed = true",
            bad,
        );
        let study = write(d.path(), "bad.toml", &text);
        let o = sweep(&study, &d.path().join("out"), &["--dry-run"]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        let e = stderr(&o);
        assert!(e.contains("bad.toml:") && e.contains(key), "{bad}: {e}");
    }
}

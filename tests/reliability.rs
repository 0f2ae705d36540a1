//! Reliability of the batch commands (issue 15), through the binary: per-case time budgets,
//! refusals before running (sizes, aliased axes, an invalid base scenario), the output
//! directory's lock and ownership, the journal on `--resume`, and write failures.

mod common;

use common::{read, run, stderr, sweep, write};

/// Three work-mode cases of 60 s simulated time (about a second of wall time each).
const SLOW: &str = r#"
[study]
name = "slow"

[design]
preset = "usm-paper"

[scenario]
mode = "work"
duration = 60.0

[[axis]]
name = "control.damping"
values = [0.1, 0.2, 0.3]
"#;

/// Four quick static cases.
const QUICK: &str = r#"
[study]
name = "quick"

[design.generator]
links = 5

[static]
samples = 32

[[axis]]
name = "design.links"
values = [4, 5, 6, 7]
"#;

#[test]
fn a_case_past_its_budget_fails_with_timeout_and_the_batch_goes_on() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "slow.toml", SLOW);
    let out = d.path().join("o");
    // A budget far below one case's run: every case stops at its first check past it.
    let o = sweep(&s, &out, &["--case-timeout", "0.001", "--jobs", "2"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("3 cases ran out of their --case-timeout"),
        "{}",
        stderr(&o)
    );
    let csv = String::from_utf8(read(&out.join("cases.csv"))).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 3, "{csv}");
    for r in rows {
        assert!(
            r.contains(",failed,timeout: the case's wall-clock budget ran out at t = "),
            "{r}"
        );
    }
    assert!(!out.join("cases.partial.csv").exists(), "journal removed");
    let o = run(&["sweep", s.to_str().unwrap(), "--case-timeout=-1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--case-timeout"), "{}", stderr(&o));
}

#[test]
fn sizes_aliases_and_a_bad_base_are_refused_before_running() {
    let d = tempfile::tempdir().unwrap();
    let cases = [
        (
            QUICK.replace("samples = 32", "samples = 1000000000000"),
            "static.samples: 1000000000000 samples per case would keep 16000.0 GB",
        ),
        (
            format!("{QUICK}\n[[axis]]\nname = \"design.generator.links\"\nvalues = [3]\n"),
            "axis[1].name: `design.generator.links` sets the same parameter as axis[0] \
             `design.links`",
        ),
        (
            SLOW.replace("duration = 60.0", "duration = -2.0"),
            "scenario.duration: must be a finite number > 0, got -2 (in the base scenario",
        ),
        (
            SLOW.replace("duration = 60.0", "duration = 500000.0\nlog_dt = 0.05\ncontrol_dt = 0.05"),
            "scenario.log_dt: the log would hold 10000002 rows",
        ),
        (
            SLOW.replace("duration = 60.0", "duration = 60.0\ncontrol_dt = 60.0\ndt = 0.0001\nlog_dt = 60.0"),
            "scenario.control_dt: gives 600000 steps of scenario.dt per control period",
        ),
        (
            format!("{QUICK}\n[doe]\nkind = \"sobol\"\ncases = 10000000\n")
                .replace("values = [4, 5, 6, 7]", "values = [4, 5]\n[[axis]]\nname = \"static.threshold\"\nvalues = [0.1]\n[[axis]]\nname = \"static.rank_rel_tol\"\nvalues = [1e-6]\n[[axis]]\nname = \"static.char_length\"\nvalues = [1.0]"),
            "doe.cases: 10000000 cases × 4 axes need about",
        ),
    ];
    for (i, (text, message)) in cases.iter().enumerate() {
        let s = write(d.path(), &format!("s{i}.toml"), text);
        let out = d.path().join(format!("o{i}"));
        for extra in [&["--dry-run"][..], &[]] {
            let o = sweep(&s, &out, extra);
            assert_eq!(o.status.code(), Some(2), "{message}: {}", stderr(&o));
            assert!(stderr(&o).contains(message), "{}", stderr(&o));
            assert!(
                stderr(&o).contains(&format!("s{i}.toml:")),
                "{}",
                stderr(&o)
            );
        }
        assert!(!out.exists(), "nothing may run");
    }
}

#[test]
fn one_run_per_output_directory_and_another_study_needs_force() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    std::fs::create_dir(&out).unwrap();
    // A live holder (this test process) keeps the directory.
    let me = format!(
        "pid={}\nhost={}\nsince=now\n",
        std::process::id(),
        usm_study::study::outdir::host_name()
    );
    std::fs::write(out.join(".usm-study.lock"), &me).unwrap();
    let o = sweep(&s, &out, &[]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("is in use by another run")
            && e.contains(&format!("pid {}", std::process::id())),
        "{e}"
    );
    // A dead holder's lock is stale: removed, and the run goes ahead.
    let dead = me.replace(&std::process::id().to_string(), "4194305");
    std::fs::write(out.join(".usm-study.lock"), dead).unwrap();
    let o = sweep(&s, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!out.join(".usm-study.lock").exists());
    // Another study into the same directory: refused, then replaced with --force.
    let other = write(
        d.path(),
        "other.toml",
        &QUICK.replace("name = \"quick\"", "name = \"other\""),
    );
    let o = sweep(&other, &out, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("another study (quick)"),
        "{}",
        stderr(&o)
    );
    std::fs::write(out.join("plots/axis_stale.svg"), "<svg/>").unwrap();
    let o = sweep(&other, &out, &["--force"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("--force: removed"), "{}", stderr(&o));
    assert!(!out.join("plots/axis_stale.svg").exists());
}

#[test]
fn malformed_journal_rows_are_reported_and_run_again() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let full = d.path().join("full");
    assert_eq!(sweep(&s, &full, &[]).status.code(), Some(0));
    let out = d.path().join("r");
    let o = sweep(&s, &out, &["--max-cases", "3", "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let j = out.join("cases.partial.csv");
    let text = std::fs::read_to_string(&j).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    assert_eq!(lines.len(), 4);
    // Line 3: a field lost; line 4: a number garbled.
    lines[2] = lines[2].rsplit_once(',').unwrap().0.to_string();
    let mut fields: Vec<&str> = lines[3].split(',').collect();
    fields[4] = "4.0.1"; // the axis value
    lines[3] = fields.join(",");
    std::fs::write(&j, lines.join("\n") + "\n").unwrap();
    let o = sweep(&s, &out, &["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("cases.partial.csv:3: malformed journal row"),
        "{e}"
    );
    assert!(
        e.contains("cases.partial.csv:4: malformed journal row"),
        "{e}"
    );
    assert!(e.contains("resumed 1 cases, ran 3"), "{e}");
    assert_eq!(read(&out.join("cases.csv")), read(&full.join("cases.csv")));
    // A finished output resumed again: nothing to do.
    let o = sweep(&s, &out, &["--resume"]);
    assert!(stderr(&o).contains("already complete"), "{}", stderr(&o));
}

#[test]
fn report_exits_non_zero_when_it_cannot_write() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    assert_eq!(sweep(&s, &out, &[]).status.code(), Some(0));
    // summary.md replaced by a directory: the report cannot write it (even as root).
    std::fs::remove_file(out.join("summary.md")).unwrap();
    std::fs::create_dir(out.join("summary.md")).unwrap();
    let o = run(&["report", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("is incomplete"), "{}", stderr(&o));
}

#[test]
fn a_scenario_name_cannot_lead_the_output_out_of_its_root() {
    let d = tempfile::tempdir().unwrap();
    let text = usm_study::scenario::preset_text("work-setpoint")
        .unwrap()
        .replace("name = \"work-setpoint\"", "name = \"../../escaped\"")
        .replace("duration = 80.0", "duration = 0.5");
    let s = write(d.path(), "s.toml", &text);
    let o = common::usm_study()
        .current_dir(d.path())
        .args(["simulate", s.to_str().unwrap(), "--no-plots"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.path().join("out/______escaped").is_dir());
    assert!(!d.path().parent().unwrap().join("escaped").exists());
}

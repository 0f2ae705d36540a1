//! Reliability of the batch commands (issues 15 and 21), through the binary: per-case time
//! budgets, refusals before running (sizes, aliased axes, an invalid base scenario), the output
//! directory's lock and ownership, the journal on `--resume`, and write failures; issue 21:
//! links out of the output, `--force` by provenance, Slurm scripts under a stand-in `sbatch`,
//! complete-or-refused merges, `tcm` and `allocate` results that cannot look complete,
//! `report` refusals, signals and lock takeover, `optimise`'s lock and output checks.

mod common;

use common::{read, run, stderr, sweep, write, QUICK};

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
        usm_study::batch::outdir::host_name()
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
    let written = std::fs::read_dir(out.join("plots")).unwrap().count();
    assert!(written > 0);
    // A user's own files in the output: --force leaves them alone.
    std::fs::write(out.join("plots/user_diagram.svg"), "<svg/>").unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let o = sweep(&other, &out, &["--force"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("--force: removed"), "{}", stderr(&o));
    assert_eq!(read(&out.join("plots/user_diagram.svg")), b"<svg/>");
    assert_eq!(read(&out.join("notes.txt")), b"mine");
    let record = String::from_utf8(read(&out.join(".usm-study.files"))).unwrap();
    assert!(
        record.contains("cases.csv\n") && record.contains("plots/"),
        "{record}"
    );
    assert!(
        !record.contains("user_diagram") && !record.contains("notes"),
        "{record}"
    );
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
    // Refused since issue 21 (a name is a single safe path component), naming file, line, key.
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("s.toml:3:1: scenario.name"),
        "{}",
        stderr(&o)
    );
    assert!(!d.path().join("out").exists());
    assert!(!d.path().parent().unwrap().join("escaped").exists());
}

// ---- issue 21 ------------------------------------------------------------------------------

/// The `study_hash` of a finished output.
fn study_hash(out: &std::path::Path) -> String {
    let m: serde_json::Value = serde_json::from_slice(&read(&out.join("manifest.json"))).unwrap();
    m["study_hash"].as_str().unwrap().to_string()
}

/// Every file under `dir` (following nothing), as sorted relative paths.
fn tree(dir: &std::path::Path) -> Vec<String> {
    let mut v = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if e.file_type().unwrap().is_dir() {
                stack.push(p.clone());
            }
            v.push(p.strip_prefix(dir).unwrap().display().to_string());
        }
    }
    v.sort();
    v
}

#[test]
fn a_symlink_leading_out_of_the_output_is_refused_and_nothing_outside_is_touched() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    assert_eq!(sweep(&s, &out, &[]).status.code(), Some(0));
    let victim = d.path().join("victim_dir");
    std::fs::create_dir(&victim).unwrap();
    std::fs::write(victim.join("precious.svg"), "<svg>mine</svg>").unwrap();
    std::fs::write(victim.join(".data.tmp-42"), "mine too").unwrap();
    std::fs::remove_dir_all(out.join("plots")).unwrap();
    std::os::unix::fs::symlink(&victim, out.join("plots")).unwrap();
    let before = tree(&victim);
    for extra in [&["--force"][..], &[], &["--resume"]] {
        let o = sweep(&s, &out, extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("symbolic link leading out of the output directory"),
            "{}",
            stderr(&o)
        );
        assert_eq!(tree(&victim), before, "{extra:?}");
        assert_eq!(read(&victim.join("precious.svg")), b"<svg>mine</svg>");
        assert!(!out.join(".usm-study.lock").exists());
    }
    let o = run(&["report", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(tree(&victim), before);
}

#[test]
fn force_never_removes_files_the_tool_did_not_write() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    // A plain project directory with the user's own files named like outputs.
    let proj = d.path().join("proj");
    std::fs::create_dir(&proj).unwrap();
    for f in ["manifest.json", "summary.md", "cases.csv"] {
        std::fs::write(proj.join(f), "mine").unwrap();
    }
    let o = sweep(&s, &proj, &["--force"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("that usm-study did not write"),
        "{}",
        stderr(&o)
    );
    for f in ["manifest.json", "summary.md", "cases.csv"] {
        assert_eq!(read(&proj.join(f)), b"mine", "{f}");
    }
}

#[test]
fn a_rerun_without_resume_keeps_every_finished_case() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    let o = sweep(&s, &out, &["--max-cases", "2", "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let journal = read(&out.join("cases.partial.csv"));
    let o = sweep(&s, &out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("--resume") && e.contains("--force") && e.contains("finished cases"),
        "{e}"
    );
    assert_eq!(
        read(&out.join("cases.partial.csv")),
        journal,
        "finished cases kept"
    );
    let o = sweep(&s, &out, &["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("resumed 2 cases, ran 2"),
        "{}",
        stderr(&o)
    );
    // A complete output of the same study is recomputed bit for bit (the README's main command
    // reruns the study into its committed reference output); --force starts over too.
    let table = read(&out.join("cases.csv"));
    let o = sweep(&s, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        read(&out.join("cases.csv")),
        table,
        "same study, same table"
    );
    let o = sweep(&s, &out, &["--force"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("resumed 0 cases, ran 4"),
        "{}",
        stderr(&o)
    );
}

/// A stand-in `sbatch` on PATH: logs its arguments (one per line, then `--`), and with
/// `RUN_JOBS=1` runs `--wrap` like Slurm would (each array task in turn, `sh -c`).
const SBATCH: &str = r#"#!/usr/bin/env bash
set -u
{ for a in "$@"; do printf '%s\n' "$a"; done; echo --; } >>"$SBATCH_LOG"
wrap= array=
for a in "$@"; do
  case "$a" in --wrap=*) wrap=${a#--wrap=};; --array=*) array=${a#--array=};; esac
done
if [ "${RUN_JOBS:-0}" = 1 ]; then
  if [ -n "$array" ]; then
    n=$(( ${array#0-} + 1 ))
    for ((i = 0; i < n; i++)); do
      SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$n SLURM_ARRAY_TASK_MIN=0 sh -c "$wrap" || exit 1
    done
  else
    sh -c "$wrap" || exit 1
  fi
fi
if [ -n "$array" ]; then echo 1001; else echo 1002; fi
"#;

/// A temporary directory with the stand-in `sbatch`; returns it and a PATH with it first.
fn stand_in_sbatch(d: &std::path::Path) -> String {
    let bin = d.join("bin");
    std::fs::create_dir(&bin).unwrap();
    let p = write(&bin, "sbatch", SBATCH);
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
    format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    )
}

#[test]
fn the_emitted_slurm_script_runs_nothing_from_hostile_paths() {
    let d = tempfile::tempdir().unwrap();
    let path = stand_in_sbatch(d.path());
    let hostile = d.path().join("$(touch PWNED1) `touch PWNED2` it's");
    std::fs::create_dir(&hostile).unwrap();
    let s = write(&hostile, "quick $(touch PWNED3).toml", QUICK);
    let out = hostile.join("out `touch PWNED4` $(touch PWNED5)");
    let script = d.path().join("submit.sh");
    let o = common::usm_study()
        .current_dir(d.path())
        .args(["sweep", s.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .args([
            "--emit-slurm",
            script.to_str().unwrap(),
            "--cases-per-task",
            "2",
            "--force",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8(read(&script)).unwrap();
    assert!(
        text.contains("--resume --force --jobs 1"),
        "--force kept: {text}"
    );
    let log = d.path().join("sbatch.log");
    let o = std::process::Command::new("bash")
        .arg(&script)
        .current_dir(d.path())
        .env("PATH", &path)
        .env("SBATCH_LOG", &log)
        .env("RUN_JOBS", "1")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for dir in [d.path(), &hostile, &out] {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let n = e.file_name().to_string_lossy().to_string();
            assert!(
                !n.starts_with("PWNED"),
                "{n} was created in {}",
                dir.display()
            );
        }
    }
    let calls = String::from_utf8(read(&log)).unwrap();
    assert_eq!(
        calls.matches("\n--\n").count(),
        2,
        "array and merge: {calls}"
    );
    // The jobs ran for real: the merged table equals an unsharded local run.
    let local = d.path().join("local");
    assert_eq!(sweep(&s, &local, &[]).status.code(), Some(0));
    assert_eq!(read(&out.join("cases.csv")), read(&local.join("cases.csv")));
}

#[test]
fn the_merge_job_of_a_3000_task_array_submits() {
    let d = tempfile::tempdir().unwrap();
    let path = stand_in_sbatch(d.path());
    let big = QUICK.replace(
        "values = [4, 5, 6, 7]",
        "values = [4, 5, 6]\n[[axis]]\nname = \"static.threshold\"\nrange = { start = 0.01, stop = 0.1, steps = 1000 }",
    );
    let s = write(d.path(), "big.toml", &big);
    let script = d.path().join("submit.sh");
    let o = run(&[
        "sweep",
        s.to_str().unwrap(),
        "--out",
        d.path().join("o").to_str().unwrap(),
        "--emit-slurm",
        script.to_str().unwrap(),
        "--cases-per-task",
        "1",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("3000 array tasks"), "{}", stderr(&o));
    let log = d.path().join("sbatch.log");
    let o = std::process::Command::new("bash")
        .arg(&script)
        .env("PATH", &path)
        .env("SBATCH_LOG", &log)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("merge job 1002"));
    let calls = String::from_utf8(read(&log)).unwrap();
    let merge = calls.split("\n--\n").nth(1).unwrap();
    assert!(merge.contains("--dependency=afterok:1001"), "{merge}");
    assert!(merge.len() < 1000, "the merge command stays short: {merge}");
    let list = String::from_utf8(read(&d.path().join("o/shards.txt"))).unwrap();
    assert_eq!(list.lines().count(), 3000);
    assert_eq!(list.lines().nth(2999), Some("shard-2999-of-3000"));
}

#[test]
fn merge_refuses_missing_repeated_and_mismatched_shards_and_keeps_input_journals() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let sh = |i: usize, n: usize| {
        let o = d.path().join(format!("s{i}of{n}"));
        let r = sweep(&s, &o, &["--shard", &format!("{i}/{n}")]);
        assert_eq!(r.status.code(), Some(0), "{}", stderr(&r));
        o.to_str().unwrap().to_string()
    };
    let (s0, s1, s2) = (sh(0, 3), sh(1, 3), sh(2, 3));
    let other = sh(0, 2);
    let out = d.path().join("m").to_str().unwrap().to_string();
    let merge = |dirs: &[&str], extra: &[&str]| {
        let mut a = vec!["merge"];
        a.extend_from_slice(dirs);
        a.extend_from_slice(&["--out", &out]);
        a.extend_from_slice(extra);
        run(&a)
    };
    let o = merge(&[&s0, &s1], &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("missing 1 of 3 shards: shard-2-of-3"),
        "{}",
        stderr(&o)
    );
    let o = merge(&[&s0, &s0, &s0, &s1, &s2], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("shard 0 given 3 times"),
        "{}",
        stderr(&o)
    );
    let o = merge(&[&s0, &s1, &s2, &other], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("mismatched shard counts"),
        "{}",
        stderr(&o)
    );
    let o = merge(&[&s0, &s1], &["--partial"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--partial: missing 1 of 3 shards"),
        "{}",
        stderr(&o)
    );
    // --out = an input (issue 39): refused before anything is written, so the shards can be
    // merged again; the shard's manifest and journal are unchanged.
    let j0 = std::path::Path::new(&s0).join("cases.partial.csv");
    let m0 = std::path::Path::new(&s0).join("manifest.json");
    let (journal, manifest) = (read(&j0), read(&m0));
    let o = run(&["merge", &s0, &s1, &s2, "--out", &format!("{s0}/.")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is one of the shards being merged"),
        "{}",
        stderr(&o)
    );
    assert_eq!((read(&j0), read(&m0)), (journal, manifest));
    let o = merge(&[&s0, &s1, &s2], &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn tcm_never_leaves_an_old_summary_beside_new_rows() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("t");
    let tcm = |seed: &str| {
        run(&[
            "tcm",
            "usm-paper",
            "--out",
            out.to_str().unwrap(),
            "--samples",
            "64",
            "--seed",
            seed,
            "--resolution",
            "5",
        ])
    };
    let o = tcm("1");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.join("summary.json").is_file());
    // samples.csv cannot be replaced (a directory in its place): the rerun fails, leaving no
    // summary.json of the previous run and no temporary file.
    std::fs::remove_file(out.join("samples.csv")).unwrap();
    std::fs::create_dir(out.join("samples.csv")).unwrap();
    std::fs::write(out.join("samples.csv/x"), "").unwrap();
    let o = tcm("2");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        !out.join("summary.json").exists(),
        "an incomplete output has no summary"
    );
    let leftovers: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn non_finite_allocation_results_are_a_status_never_solved() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        d.path(),
        "huge.json",
        r#"{"T": [[1,1,0,0,0,0,0.6],[0,0,1,1,0,0,0],[0,0,0,0,1,1,0.8],
            [0,0,0,0,0,0,0],[0,0,0,0,-0.6,-1.4,-0.8],[0,0,0.4,1.6,0,0,0]],
            "tau": [1e308, -1e308, 1e308, 0, -1e308, 1e308]}"#,
    );
    let o = run(&[
        "allocate",
        "--input",
        p.to_str().unwrap(),
        "--method",
        "pinv",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(v["pinv"]["status"], "non_finite", "{v}");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
}

#[test]
fn report_refuses_a_folder_that_is_not_a_finished_output_or_is_locked() {
    let d = tempfile::tempdir().unwrap();
    let empty = d.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let o = run(&["report", empty.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is not a study output"),
        "{}",
        stderr(&o)
    );
    assert!(!empty.join("report.html").exists());
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    assert_eq!(sweep(&s, &out, &[]).status.code(), Some(0));
    let me = format!(
        "pid={}\nhost={}\nsince=now\n",
        std::process::id(),
        usm_study::batch::outdir::host_name()
    );
    std::fs::write(out.join(".usm-study.lock"), me).unwrap();
    let o = run(&["report", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("in use by another run"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_file(out.join(".usm-study.lock")).unwrap();
    assert_eq!(
        run(&["report", out.to_str().unwrap()]).status.code(),
        Some(0)
    );
    assert!(!out.join(".usm-study.lock").exists());
}

#[test]
fn sigterm_and_sigint_release_the_lock_after_the_journal_and_say_how_to_resume() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "slow.toml", SLOW);
    for (sig, code) in [(libc::SIGTERM, 143), (libc::SIGINT, 130)] {
        let out = d.path().join(format!("o{sig}"));
        let mut child = common::usm_study()
            .args([
                "sweep",
                s.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--jobs",
                "1",
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Wait for the first finished case in the journal (no time is asserted).
        let journal = out.join("cases.partial.csv");
        while std::fs::read_to_string(&journal).map_or(0, |t| t.lines().count()) < 2 {
            assert!(child.try_wait().unwrap().is_none(), "ended before a signal");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        // SAFETY: signalling our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, sig) };
        let o = child.wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(code), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("--resume to continue"),
            "{}",
            stderr(&o)
        );
        assert!(!out.join(".usm-study.lock").exists(), "lock released");
        let rows = std::fs::read_to_string(&journal).unwrap().lines().count() - 1;
        assert!(rows >= 1);
        let o = sweep(&s, &out, &["--resume", "--case-timeout", "0.001"]);
        assert!(
            o.status.code() == Some(0) || o.status.code() == Some(1),
            "{}",
            stderr(&o)
        );
        assert!(
            stderr(&o).contains(&format!("resumed {rows} cases")),
            "{}",
            stderr(&o)
        );
    }
}

#[test]
fn resume_takes_over_an_abandoned_or_requeued_lock_of_another_host() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let full = d.path().join("full");
    assert_eq!(sweep(&s, &full, &[]).status.code(), Some(0));
    let hash = study_hash(&full);
    let out = d.path().join("o");
    assert_eq!(
        sweep(&s, &out, &["--max-cases", "1"]).status.code(),
        Some(0)
    );
    let lock = out.join(".usm-study.lock");
    let held = |extra: &str| {
        let text = format!("pid=1\nhost=node-that-died\nsince=x\ntoken=1-a\nstudy={hash}\n{extra}");
        std::fs::write(&lock, text).unwrap();
    };
    // A fresh lock of another host: refused, also with --resume.
    held("");
    assert_eq!(sweep(&s, &out, &["--resume"]).status.code(), Some(2));
    // Untouched for longer than the takeover age: --resume takes it over; without: refused.
    let old = std::time::SystemTime::now() - std::time::Duration::from_secs(11 * 60);
    std::fs::File::options()
        .write(true)
        .open(&lock)
        .unwrap()
        .set_modified(old)
        .unwrap();
    assert_eq!(sweep(&s, &out, &[]).status.code(), Some(2));
    let o = sweep(&s, &out, &["--resume", "--max-cases", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("took over the lock of pid 1 on host node-that-died"),
        "{}",
        stderr(&o)
    );
    // A requeued Slurm job on another node: taken over at once.
    held("slurm_job=4242\n");
    let o = common::usm_study()
        .args([
            "sweep",
            s.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--resume",
        ])
        .env("SLURM_JOB_ID", "4242")
        .env("SLURM_RESTART_COUNT", "1")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("took over the lock of Slurm job 4242"),
        "{}",
        stderr(&o)
    );
    assert_eq!(read(&out.join("cases.csv")), read(&full.join("cases.csv")));
    // Another study's hash is never taken over.
    held("");
    std::fs::File::options()
        .write(true)
        .open(&lock)
        .unwrap()
        .set_modified(old)
        .unwrap();
    let text = std::fs::read_to_string(&lock)
        .unwrap()
        .replace(&hash, "0123");
    std::fs::write(&lock, text).unwrap();
    std::fs::File::options()
        .write(true)
        .open(&lock)
        .unwrap()
        .set_modified(old)
        .unwrap();
    assert_eq!(sweep(&s, &out, &["--resume"]).status.code(), Some(2));
}

#[test]
fn optimise_holds_the_lock_and_refuses_a_sweeps_output() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    assert_eq!(sweep(&s, &out, &[]).status.code(), Some(0));
    let problem = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/layout.toml");
    let o = run(&[
        "optimise",
        problem.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("holds a sweep's output"),
        "{}",
        stderr(&o)
    );
    let busy = d.path().join("busy");
    std::fs::create_dir(&busy).unwrap();
    let me = format!(
        "pid={}\nhost={}\nsince=now\n",
        std::process::id(),
        usm_study::batch::outdir::host_name()
    );
    std::fs::write(busy.join(".usm-study.lock"), me).unwrap();
    let o = run(&[
        "optimise",
        problem.to_str().unwrap(),
        "--out",
        busy.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("in use by another run"),
        "{}",
        stderr(&o)
    );
}

/// Issue 39 (high): `simulate` of a scenario with `[uncertainty]` wrote `uncertainty.json`
/// through a planted link (a plain write), and a sweep wrote its `study.toml` copy the same
/// way. Both now go through the one atomic writer: a link in the output folder is replaced by
/// the tool's own file, never followed, and a dangling link creates nothing outside.
#[test]
fn planted_links_at_uncertainty_json_and_the_study_copy_are_replaced_not_followed() {
    let d = tempfile::tempdir().unwrap();
    let scenario = write(
        d.path(),
        "worlds_scenario.toml",
        r#"[scenario]
name = "w"
mode = "transport"
design = "usm-paper"
duration = 5.0

[path]
segments = [ { from = [0.0, 0.0], to = [200.0, 0.0] } ]

[uncertainty]
worlds = 2
[[uncertainty.param]]
name = "hydro.linear_damping_scale"
distribution = { kind = "uniform", low = 0.5, high = 1.5 }
"#,
    );
    let notes = write(d.path(), "notes.txt", "mine\n");
    let dangling = d.path().join("created_outside.json");
    for (name, target) in [
        ("uncertainty.json", &notes),
        ("uncertainty.json", &dangling),
    ] {
        let out = d.path().join(format!(
            "o_{}",
            target.file_name().unwrap().to_str().unwrap()
        ));
        std::fs::create_dir_all(&out).unwrap();
        std::os::unix::fs::symlink(target, out.join(name)).unwrap();
        let o = run(&[
            "simulate",
            scenario.to_str().unwrap(),
            "--no-plots",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let meta = std::fs::symlink_metadata(out.join(name)).unwrap();
        assert!(meta.file_type().is_file(), "{name} is still a link");
        assert!(read(&out.join(name)).starts_with(b"{"));
    }
    assert_eq!(read(&notes), b"mine\n");
    assert!(!dangling.exists(), "a dangling link created a file outside");

    // The sweep's copy of the study: a sweep refuses a link leading out of its output before
    // anything runs (and, inside, writes `study.toml` through the same atomic writer).
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("sweep_out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(&notes, out.join("study.toml")).unwrap();
    let o = sweep(&s, &out, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("symbolic link leading out of the output directory"),
        "{}",
        stderr(&o)
    );
    assert_eq!(read(&notes), b"mine\n");
}

/// Issue 39 item 4: a journal written by a build with other sources is not resumed silently.
/// The study hash includes the build identity (a hash of the sources, `build.rs`), and the
/// journal's record beside it (`cases.partial.study`) holds the hash of the study and build that
/// wrote it; a record from another build (here: another hash planted in the record, as another
/// build would have written) makes `--resume` start afresh and say why. The same build resumes.
#[test]
fn a_journal_of_another_build_is_not_resumed_silently() {
    let d = tempfile::tempdir().unwrap();
    let s = write(d.path(), "quick.toml", QUICK);
    let out = d.path().join("o");
    let o = sweep(&s, &out, &["--max-cases", "2", "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let record = out.join("cases.partial.study");
    let ours = String::from_utf8(read(&record)).unwrap();
    assert_eq!(ours.len(), 64, "{ours}");
    std::fs::write(&record, "0".repeat(64)).unwrap();
    let o = sweep(&s, &out, &["--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("another build of usm-study") && e.contains("not resumed"),
        "{e}"
    );
    assert!(e.contains("resumed 0 cases, ran 4"), "{e}");
    assert_eq!(read(&record), ours.as_bytes());
    // The manifest names the build.
    let m: serde_json::Value = serde_json::from_slice(&read(&out.join("manifest.json"))).unwrap();
    assert_eq!(m["build_id"].as_str().map(str::len), Some(32), "{m}");
    // This build's own journal resumes as before.
    let o = sweep(&s, &out, &["--force", "--max-cases", "2", "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = sweep(&s, &out, &["--resume"]);
    assert!(
        stderr(&o).contains("resumed 2 cases, ran 2"),
        "{}",
        stderr(&o)
    );
}

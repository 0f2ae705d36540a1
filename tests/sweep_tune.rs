//! Per-case tuning inside sweeps (`[tune]`, issue 12 deliverable 3) and the transport method
//! of a study's scenario side selecting its own USM Table III gains.
//!
//! A tiny tuned sweep (two designs, a 45 s transport run, six evaluations of energy per metre per case): rows
//! carry the tuned values, the evaluations used and the tuning's feasibility; `cases.csv` is
//! identical for `--jobs 1` and `--jobs 2` and after an interrupted run resumed; every case
//! scores at least as well as at its start gains (its row is the tuned run), and the summary
//! names the winner at tuned values. Bad `[tune]` sections exit 2 naming file, line and key
//! before any case runs.

mod common;

use std::path::Path;

use common::{arg, run, stderr, write};
use usm_study::study::cases::resolve_case;
use usm_study::study::doe::expand;
use usm_study::study::parse::parse_study;

const BASE: &str = r#"[study]
name = "tiny_tune"
seed = 5

[design.generator]
links = 3
link_length = 0.6
thrust_limit = 40.0

[scenario]
mode = "transport"
duration = 45.0

[allocation]
method = "pinv"
lambda = 0.1

[success]
# 45 s: the vehicle converges to the path (3 m off at the start), not yet fully settled.
cross_track_bound = 1.0

[[axis]]
name = "design.links"
values = [3, 4]
"#;

const TUNE: &str = r#"
[tune]
[[tune.param]]
name = "control.k_psi"
lower = 0.15
upper = 1.35
scale = "log"

[[tune.param]]
name = "control.k_6p"
lower = 0.002
upper = 0.5
scale = "log"

[tune.objective]
[[tune.objective.term]]
metric = "energy_per_metre"
weight = 1.0

[[tune.constraint]]
metric = "completed"
op = "=="
value = 1

[tune.solver]
method = "nelder-mead"
max_evals = 6
step = 0.3
"#;

/// Rows of a `cases.csv` as (header, rows of cells).
fn table(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(dir.join("cases.csv")).unwrap();
    let mut lines = text.lines();
    let split = |l: &str| l.split(',').map(str::to_string).collect::<Vec<_>>();
    let head = split(lines.next().unwrap());
    (head, lines.map(split).collect())
}

fn column(head: &[String], rows: &[Vec<String>], name: &str) -> Vec<f64> {
    let c = head
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("{name}: {head:?}"));
    // Flags (`success`, `tune_feasible`, …) are written as true/false when every case has one.
    rows.iter()
        .map(|r| match r[c].as_str() {
            "true" => 1.0,
            "false" => 0.0,
            x => x.parse().unwrap(),
        })
        .collect()
}

fn sweep(study: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec!["sweep", arg(study), "--out", arg(out)];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// Sweep the one-case study `text` (written to `dir/name`) with `--jobs 1` into `dir/j1` and
/// `--jobs 2` into `dir/j2`; the two `cases.csv` must be identical. `j1`, its header and rows.
fn one_case_at_jobs_1_and_2(
    dir: &Path,
    name: &str,
    text: &str,
) -> (std::path::PathBuf, Vec<String>, Vec<Vec<String>>) {
    let study = write(dir, name, text);
    let (j1, j2) = (dir.join("j1"), dir.join("j2"));
    sweep(&study, &j1, &["--jobs", "1"]);
    sweep(&study, &j2, &["--jobs", "2"]);
    let a = std::fs::read_to_string(j1.join("cases.csv")).unwrap();
    assert_eq!(a, std::fs::read_to_string(j2.join("cases.csv")).unwrap());
    let (head, rows) = table(&j1);
    assert_eq!(rows.len(), 1);
    (j1, head, rows)
}

#[test]
fn tuned_sweep_rows_carry_tuned_values_and_do_not_depend_on_jobs_or_resume() {
    let dir = tempfile::tempdir().unwrap();
    let tuned = write(dir.path(), "tuned.toml", &format!("{BASE}{TUNE}"));
    let plain = write(dir.path(), "plain.toml", BASE);
    let (j1, j2, res, un) = (
        dir.path().join("j1"),
        dir.path().join("j2"),
        dir.path().join("res"),
        dir.path().join("plain"),
    );
    sweep(&tuned, &j1, &["--jobs", "1"]);
    sweep(&tuned, &j2, &["--jobs", "2"]);
    let a = std::fs::read_to_string(j1.join("cases.csv")).unwrap();
    assert_eq!(a, std::fs::read_to_string(j2.join("cases.csv")).unwrap());
    // Interrupted after one case, then resumed: the uninterrupted table.
    sweep(&tuned, &res, &["--jobs", "1", "--max-cases", "1"]);
    sweep(&tuned, &res, &["--jobs", "2", "--resume"]);
    assert_eq!(a, std::fs::read_to_string(res.join("cases.csv")).unwrap());

    let (head, rows) = table(&j1);
    assert_eq!(rows.len(), 2);
    let k_psi = column(&head, &rows, "tuned.control.k_psi");
    let k_6p = column(&head, &rows, "tuned.control.k_6p");
    let evals = column(&head, &rows, "tune_evaluations");
    let feasible = column(&head, &rows, "tune_feasible");
    for i in 0..2 {
        assert!((0.15..=1.35).contains(&k_psi[i]), "{k_psi:?}");
        assert!((0.002..=0.5).contains(&k_6p[i]), "{k_6p:?}");
        assert!(evals[i] >= 2.0 && evals[i] <= 6.0, "{evals:?}");
        assert_eq!(feasible[i], 1.0, "every run completes");
    }
    // Each row is scored at its tuned gains: never worse than at the start gains (the
    // defaults, Method 2 of Table III), which the untuned sweep scores.
    sweep(&plain, &un, &[]);
    let (ph, pr) = table(&un);
    let before = column(&ph, &pr, "energy_per_metre");
    let after = column(&head, &rows, "energy_per_metre");
    for i in 0..2 {
        assert!(after[i] <= before[i], "case {i}: {after:?} vs {before:?}");
    }
    assert!(
        after.iter().zip(&before).any(|(a, b)| a < b),
        "tuning improved nothing"
    );
    let md = std::fs::read_to_string(j1.join("summary.md")).unwrap();
    assert!(md.contains("## Per-design tuning"), "{md}");
    assert!(md.contains("**Winner at tuned values**"), "{md}");
    assert!(md.contains("`control.k_psi` = "), "{md}");
}

/// One design tuned in three independent starts: the starts run side by side when threads
/// are free (issue 23 item 3), and the row, the tuning noise and the summary are the same as
/// when they run one after another.
#[test]
fn tuning_starts_side_by_side_give_the_one_thread_rows() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!("{BASE}{TUNE}")
        .replace("values = [3, 4]", "values = [4]")
        .replace("[tune]\n", "[tune]\nstarts = 3\n")
        .replace("max_evals = 6", "max_evals = 9");
    let (j1, head, rows) = one_case_at_jobs_1_and_2(dir.path(), "starts.toml", &text);
    // Three starts of three evaluations each; their spread is the tuning noise.
    let evals = column(&head, &rows, "tune_evaluations");
    assert!(evals[0] > 3.0 && evals[0] <= 9.0, "{evals:?}");
    let noise = column(&head, &rows, "tune_noise");
    assert!(noise[0].is_finite() && noise[0] >= 0.0, "{noise:?}");
    let summary = |d: &Path| std::fs::read_to_string(d.join("summary.md")).unwrap();
    assert_eq!(summary(&j1), summary(&dir.path().join("j2")));
}

#[test]
fn bad_tune_sections_exit_2_naming_file_line_and_key_before_any_case() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!("{BASE}{TUNE}");
    let line_of =
        |s: &str, needle: &str| s.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    let bad = [
        (
            text.replace("name = \"control.k_6p\"", "name = \"control.k_6q\""),
            "name = \"control.k_6q\"",
            "tune.param[1].name",
            "unknown parameter",
        ),
        (
            text.replace("upper = 1.35", "upper = 0.1"),
            "upper = 0.1",
            "tune.param[0].upper",
            "needs lower < upper",
        ),
        (
            text.replace(
                "metric = \"energy_per_metre\"",
                "metric = \"energy_per_meter\"",
            ),
            "metric = \"energy_per_meter\"",
            "tune.objective.term[0].metric",
            "unknown metric",
        ),
        (
            text.replace("name = \"control.k_6p\"", "name = \"design.links\""),
            "name = \"design.links\"",
            "tune.param[1].name",
            "also a sweep axis",
        ),
        (
            text.replace("[tune]\n", "[tune]\nworlds = 4\n"),
            "worlds = 4",
            "tune.worlds",
            "needs the study's [uncertainty]",
        ),
        (
            text.replace("[tune]\n", "[tune]\nworlds = 0\n"),
            "worlds = 0",
            "tune.worlds",
            "from 1 to 64",
        ),
        (
            text.replace("[tune]\n", "[tune]\nscreen = \"euler\"\n"),
            "screen = \"euler\"",
            "tune.screen",
            "must be \"rk4\" or \"none\"",
        ),
    ];
    for (i, (t, needle, key, message)) in bad.iter().enumerate() {
        let p = write(dir.path(), &format!("bad{i}.toml"), t);
        let out = dir.path().join(format!("out{i}"));
        let o = run(&["sweep", arg(&p), "--out", arg(&out)]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{e}");
        // The line of the offending key (the last match: the axis has the same name).
        let line = t
            .lines()
            .enumerate()
            .filter(|(_, l)| l.starts_with(needle))
            .map(|(n, _)| n + 1)
            .last()
            .unwrap_or_else(|| line_of(t, needle));
        assert!(
            e.contains(&format!("{}:{line}:", p.display())),
            "case {i}: {e}"
        );
        assert!(e.contains(&format!(": {key}: ")), "case {i}: {e}");
        assert!(e.contains(message), "case {i}: {e}");
        assert!(!out.exists(), "case {i}: nothing may run");
    }
}

/// Issue 37 item 1: `[tune]` is typed when the study is read — the loader itself refuses a bad
/// section at its key (no tuner needed), and a good one arrives as `Study::tuning` with its
/// parameters resolved, its defaults filled in and the raw table kept for the case hash.
#[test]
fn the_tune_section_is_typed_and_checked_at_load() {
    let text = format!("{BASE}{TUNE}");
    let study = parse_study(&text, Path::new("t.toml")).unwrap();
    let t = study.tuning.as_ref().expect("typed [tune]");
    let names: Vec<&str> = t
        .spec
        .space
        .params
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(names, ["control.k_psi", "control.k_6p"]);
    assert_eq!((t.starts, t.seeds, t.race, t.screen), (1, 1, true, false));
    assert_eq!(t.explicit_start, [false, false]);
    assert!(t.worlds.is_none());
    assert_eq!(t.spec.solver.max_evals, 6);
    assert!(
        study.tune.is_some(),
        "the section as written stays for the hash"
    );
    for (edit, key) in [
        (
            text.replace("max_evals = 6", "max_evals = 6\n[tune.bogus]"),
            "tune",
        ),
        (
            text.replace("[tune]\n", "[tune]\nstarts = 0\n"),
            "tune.starts",
        ),
        (
            text.replace("[tune]\n", "[tune]\nscreen = \"rk5\"\n"),
            "tune.screen",
        ),
        (
            text.replace("upper = 0.5", "upper = 0.001"),
            "tune.param[1].upper",
        ),
    ] {
        let e = parse_study(&edit, Path::new("t.toml")).unwrap_err();
        assert!(
            e.at.key.starts_with(key) && e.at.line.is_some(),
            "{key}: got {e}"
        );
    }
    let plain = parse_study(BASE, Path::new("t.toml")).unwrap();
    assert!(plain.tuning.is_none() && plain.tune.is_none());
}

/// The one-design study tuned in two worlds of a drag-scale `[uncertainty]`.
fn tuned_in_two_worlds() -> String {
    let uncertainty = "
[uncertainty]
worlds = 2
[[uncertainty.param]]
name = \"hydro.drag_scale\"
distribution = { kind = \"uniform\", low = 0.8, high = 1.2 }
";
    format!("{BASE}{TUNE}{uncertainty}")
        .replace("values = [3, 4]", "values = [4]")
        .replace("[tune]\n", "[tune]\nworlds = 2\n")
}

/// `[tune] worlds = 2`: each case is tuned over two worlds of the study's `[uncertainty]`, then
/// scored in the nominal world and its own worlds as before; rows identical for any `--jobs`.
#[test]
fn tuning_in_worlds_runs_and_gives_the_same_rows_for_any_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let text = tuned_in_two_worlds();
    let (_, head, rows) = one_case_at_jobs_1_and_2(dir.path(), "worlds.toml", &text);
    let k = column(&head, &rows, "tuned.control.k_psi");
    assert!(k[0] >= 0.15 && k[0] <= 1.35, "{k:?}");
    assert_eq!(column(&head, &rows, "tune_feasible"), [1.0]);
}

/// `[tune] seeds = 2` (issue 36 item 5): two independent tunings in their own tuning worlds,
/// their best points compared in the pooled worlds of both. Rows are identical for any
/// `--jobs`; the row carries `tune_success_spread` (a share difference in [0, 1]) and a
/// `tune_noise` measured between the seeds; the evaluations are both seeds' plus the pooled
/// runs (one evaluation per seed); the tuned point is one of the two seeds' bests, so the
/// case's tuned cost is no worse than seed 0's alone in the pooled comparison.
#[test]
fn two_tuning_seeds_compare_their_bests_in_the_pooled_worlds() {
    let dir = tempfile::tempdir().unwrap();
    let one = tuned_in_two_worlds();
    let two = one.replace("[tune]\n", "[tune]\nseeds = 2\n");
    for d in ["one", "two"] {
        std::fs::create_dir_all(dir.path().join(d)).unwrap();
    }
    let (_, head1, rows1) = one_case_at_jobs_1_and_2(&dir.path().join("one"), "one.toml", &one);
    let (_, head2, rows2) = one_case_at_jobs_1_and_2(&dir.path().join("two"), "two.toml", &two);
    assert!(!head1.iter().any(|h| h == "tune_success_spread"));
    let spread = column(&head2, &rows2, "tune_success_spread");
    assert!((0.0..=1.0).contains(&spread[0]), "{spread:?}");
    let noise = column(&head2, &rows2, "tune_noise");
    assert!(noise[0].is_nan() || noise[0] >= 0.0, "{noise:?}");
    let (e1, e2) = (
        column(&head1, &rows1, "tune_evaluations")[0],
        column(&head2, &rows2, "tune_evaluations")[0],
    );
    // Seed 1 has its own full budget (6) and each seed's best runs once more, pooled.
    assert!(e2 > e1 && e2 <= 2.0 * 6.0 + 2.0, "{e1} {e2}");
    assert_eq!(column(&head2, &rows2, "tune_feasible"), [1.0]);
    // A tuned key that the worlds or a validation variant also set is refused (issue 39): the
    // world's value would replace the tuned one in every run.
    for (extra, key) in [
        (
            "[[uncertainty.param]]\nname = \"control.k_psi\"\ndistribution = { kind = \"uniform\", low = 0.2, high = 0.4 }\n",
            "uncertain parameter `control.k_psi`",
        ),
        (
            "[[validate]]\nname = \"v\"\nset = { \"control.k_6p\" = 0.1 }\n",
            "validation variant `v`",
        ),
    ] {
        let p = write(dir.path(), "both.toml", &format!("{one}{extra}"));
        let o = run(&["sweep", arg(&p), "--dry-run"]);
        assert_eq!(o.status.code(), Some(2), "{extra}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("tune.param[") && e.contains(key), "{e}");
    }
    // Bad values are refused with the key.
    for bad in ["seeds = 0", "seeds = 9", "seeds = \"two\""] {
        let p = write(
            dir.path(),
            "bad.toml",
            &one.replace("[tune]\n", &format!("[tune]\n{bad}\n")),
        );
        let o = run(&["sweep", arg(&p), "--dry-run"]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("tune.seeds"), "{bad}: {}", stderr(&o));
    }
}

#[test]
fn control_method_selects_its_table_iii_gains_unless_the_file_sets_them() {
    let control = |text: &str, case: usize| {
        let study = parse_study(text, Path::new("m.toml")).unwrap();
        let cases = expand(&study, None).unwrap();
        let r = resolve_case(&study, &cases[case]).unwrap();
        r.scenario["control"].as_table().unwrap().clone()
    };
    let head = "[study]\nname = \"m\"\n[design]\npreset = \"usm-paper\"\n[scenario]\nmode = \"transport\"\n";
    // The file names Method 1: its Δ = 3, k_6p = 0.13, k_6d = 0.12, end-effector surge.
    let c = control(&format!("{head}[control]\nmethod = \"method1\"\n"), 0);
    assert_eq!(c["look_ahead"].as_float(), Some(3.0));
    assert_eq!(c["k_6p"].as_float(), Some(0.13));
    assert_eq!(c["k_6d"].as_float(), Some(0.12));
    assert_eq!(c["surge_source"].as_str(), Some("end_effector"));
    // A gain the file sets explicitly wins over the method's row.
    let c = control(
        &format!("{head}[control]\nmethod = \"method1\"\nlook_ahead = 2.5\n"),
        0,
    );
    assert_eq!(c["look_ahead"].as_float(), Some(2.5));
    assert_eq!(c["k_6p"].as_float(), Some(0.13));
    // An axis over the method: each case gets its own row, explicit keys still win.
    let swept = format!(
        "{head}[control]\nk_psi = 0.5\n[[axis]]\nname = \"control.method\"\nvalues = [\"method1\", \"method2\"]\n"
    );
    let (m1, m2) = (control(&swept, 0), control(&swept, 1));
    assert_eq!(m1["surge_source"].as_str(), Some("end_effector"));
    assert_eq!(m1["look_ahead"].as_float(), Some(3.0));
    assert_eq!(m2["surge_source"].as_str(), Some("base"));
    assert_eq!(m2["look_ahead"].as_float(), Some(2.0));
    assert_eq!(m1["k_psi"].as_float(), Some(0.5));
    assert_eq!(m2["k_psi"].as_float(), Some(0.5));
}

/// `[tune] race` (issue 38 item 2): Bayesian optimisation in three tuning worlds, racing on
/// (the default) and off. A candidate raced out is certainly infeasible and certainly not the
/// best, and Bayesian optimisation reads only the feasibility of infeasible points, so the two
/// tunings agree bit for bit — tuned gains, feasibility, evaluations, noise, curve — and so do
/// the sweeps' `cases.csv` (the key is not hashed), while racing runs fewer worlds.
#[test]
fn racing_the_tuning_worlds_finds_what_the_full_evaluation_finds_in_fewer_runs() {
    use usm_study::batch::tuning_hook::CaseTuner;
    use usm_study::evaluate::Deadline;
    use usm_study::optimise::case_tuner::Tuner;
    let dir = tempfile::tempdir().unwrap();
    let on = tuned_in_two_worlds()
        .replace("[tune]\nworlds = 2\n", "[tune]\nworlds = 3\n")
        .replace("method = \"nelder-mead\"", "method = \"bayes\"")
        .replace("max_evals = 6", "max_evals = 9")
        .replace(
            "[tune.solver]",
            "[[tune.constraint]]\nmetric = \"convergence_time\"\nop = \"<=\"\nvalue = 25.0\n\n[tune.solver]",
        );
    let off = on.replace("[tune]\n", "[tune]\nrace = false\n");
    assert_ne!(on, off);
    let tuned = |text: &str| {
        let path = write(dir.path(), "race.toml", text);
        let study = parse_study(text, &path).unwrap();
        let case = &expand(&study, None).unwrap()[0];
        let r = resolve_case(&study, case).unwrap();
        let tuner = Tuner::new(&study).unwrap();
        tuner.tune(&study, case, &r, Deadline::NONE).unwrap()
    };
    let (a, b) = (tuned(&on), tuned(&off));
    eprintln!(
        "raced {} runs, full {} runs, {} evaluations",
        a.runs, b.runs, b.evaluations
    );
    assert_eq!(a.x, b.x);
    assert_eq!(a.feasible, b.feasible);
    assert_eq!(a.evaluations, b.evaluations);
    assert_eq!(a.noise.to_bits(), b.noise.to_bits());
    let bits = |c: &[f64]| c.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.curve), bits(&b.curve));
    assert_eq!(b.runs, 3 * b.evaluations);
    assert!(a.runs < b.runs, "nothing raced: {} runs", a.runs);
    // The sweeps' tables: identical, hashes included.
    let (p_on, p_off) = (
        write(dir.path(), "on.toml", &on),
        write(dir.path(), "off.toml", &off),
    );
    sweep(&p_on, &dir.path().join("on"), &[]);
    sweep(&p_off, &dir.path().join("off"), &[]);
    let csv = |d: &str| std::fs::read_to_string(dir.path().join(d).join("cases.csv")).unwrap();
    assert_eq!(csv("on"), csv("off"));
}

/// `[tune] screen = "rk4"` (issue 38 item 3): the candidates run with RK4 at the control period,
/// the tuned case is scored at the scenario's own integrator. The screened tuning finds a
/// feasible point with the same number of evaluations; its row's metrics are those of the
/// case at its tuned values with Dormand–Prince: a sweep that fixes the tuned values as the
/// case's own (no tuning) gives the same energy to the last bit.
#[test]
fn screened_tuning_scores_the_tuned_point_at_full_accuracy() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!("{BASE}{TUNE}")
        .replace("values = [3, 4]", "values = [4]")
        .replace("[tune]\n", "[tune]\nscreen = \"rk4\"\n");
    let p = write(dir.path(), "screen.toml", &text);
    let out = dir.path().join("screen");
    sweep(&p, &out, &[]);
    let (head, rows) = table(&out);
    assert_eq!(column(&head, &rows, "tune_feasible"), [1.0]);
    let tuned: Vec<(String, f64)> = head
        .iter()
        .filter(|h| h.starts_with("tuned."))
        .map(|h| (h["tuned.".len()..].to_string(), column(&head, &rows, h)[0]))
        .collect();
    assert!(!tuned.is_empty());
    // The same case, untuned, at the tuned values (written in shortest round-trip form).
    let mut fixed = BASE.replace("values = [3, 4]", "values = [4]");
    let mut control = String::from("\n[control]\n");
    for (k, v) in &tuned {
        control.push_str(&format!("{} = {v:?}\n", k.trim_start_matches("control.")));
    }
    fixed = fixed.replacen("[allocation]", &format!("{control}\n[allocation]"), 1);
    let q = write(dir.path(), "fixed.toml", &fixed);
    let out2 = dir.path().join("fixed");
    sweep(&q, &out2, &[]);
    let (head2, rows2) = table(&out2);
    assert_eq!(
        column(&head, &rows, "energy_per_metre"),
        column(&head2, &rows2, "energy_per_metre"),
        "{fixed}"
    );
}

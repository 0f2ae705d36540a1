//! Uncertain worlds in sweeps (issue 22): the verdict a summary opens with, and common random
//! numbers.
//!
//! Small transport studies (3 links, a 45 s run, eight worlds over the linear-damping scale and
//! a weak current) whose cases differ only in `metrics.efficiency`, which divides the thruster
//! energy and nothing else: a known margin in energy per metre that is the same in every world.
//! - a 10 % margin names the winner; a 0.1 % margin (inside the 1 % equivalence margin) is a
//!   tie; two cases differing only in a key no metric depends on are tied with `p_best` 0.5;
//! - `worlds.csv` and `cases.csv` are identical for `--jobs 1` and `--jobs 2`, for two shards
//!   merged, and for an interrupted run resumed: every case meets the same worlds.

mod common;

use std::path::Path;

use common::{arg, run, stderr, sweep, write};

const BASE: &str = r#"[study]
name = "tiny_worlds"
seed = 11
# Thruster energy alone: the efficiency axis sets a known margin in it.
objective = "energy_per_metre"

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

[uncertainty]
worlds = 8
sampling = "sobol"
# Eight worlds, all successful, show a success probability ≥ 0.7 at 95 % (Wilson lower bound
# 8/(8 + 1.645²) = 0.747) and let a sign test reach 95 % (8 of 8: p = 2⁻⁸).
min_success_probability = 0.7

[[uncertainty.param]]
name = "hydro.linear_damping_scale"
distribution = { kind = "uniform", low = 0.5, high = 1.5 }

[[uncertainty.param]]
name = "physics.current_speed"
distribution = { kind = "uniform", low = 0.0, high = 0.02 }

[[validate]]
name = "late_turn"
set = { "initial.position[1]" = 2.0 }
"#;

fn study(dir: &Path, name: &str, axis: &str) -> std::path::PathBuf {
    write(dir, name, &format!("{BASE}\n{axis}"))
}

fn summary(out: &Path) -> String {
    std::fs::read_to_string(out.join("summary.md")).unwrap()
}

/// The first line after the title of `summary.md`.
fn verdict(out: &Path) -> String {
    summary(out)
        .lines()
        .skip(1)
        .find(|l| !l.is_empty())
        .unwrap_or_default()
        .to_string()
}

fn column(out: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let c = head
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("{name}: {head:?}"));
    lines
        .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
        .collect()
}

fn ok(o: &std::process::Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

#[test]
fn a_ten_percent_margin_names_the_winner_and_a_tenth_of_a_percent_is_a_tie() {
    let dir = tempfile::tempdir().unwrap();
    let wide = study(
        dir.path(),
        "wide.toml",
        "[[axis]]\nname = \"metrics.efficiency\"\nvalues = [0.5, 0.55]\n",
    );
    let out = dir.path().join("wide");
    ok(&sweep(&wide, &out, &["--jobs", "2"]));
    let v = verdict(&out);
    assert!(v.starts_with("**Winner: #1"), "{v}");
    assert_eq!(column(&out, "p_best"), vec![0.0, 1.0]);
    assert_eq!(column(&out, "success_probability"), vec![1.0, 1.0]);
    // The margin is the same in every world: 0.55 / 0.5 − 1 = 10 %.
    let m = column(&out, "energy_per_metre_mean");
    assert!((m[0] / m[1] - 1.1).abs() < 1e-9, "{m:?}");
    for c in [
        "energy_per_metre_p05",
        "energy_per_metre_p95",
        "energy_per_metre_worst",
    ] {
        let x = column(&out, c);
        assert!(x.iter().all(|x| x.is_finite()), "{c}: {x:?}");
    }
    let gap = column(&out, "validate.late_turn.gap");
    assert!(gap.iter().all(|g| g.is_finite()), "{gap:?}");
    // The same 10 % margin over 4 worlds decides nothing at 95 % (issue 36 item 6): no design
    // can be shown to succeed with probability ≥ 0.7 (4 of 4: lower bound 0.596), so the study
    // is undecided and says how many worlds it needs (7), never a Winner.
    let four = write(
        dir.path(),
        "wide4.toml",
        &std::fs::read_to_string(&wide)
            .unwrap()
            .replace("worlds = 8", "worlds = 4"),
    );
    let out4 = dir.path().join("wide4");
    ok(&sweep(&four, &out4, &["--jobs", "2"]));
    let v = verdict(&out4);
    assert!(v.starts_with("**Undecided: needs ≥ 7 worlds**"), "{v}");
    // The review page opens with that verdict too (it is a verdict, not a missing one).
    let html = std::fs::read_to_string(out4.join("report.html")).unwrap();
    assert!(
        html.contains("<h2>Verdict") && html.contains("Undecided: needs"),
        "report.html has no verdict section"
    );
    assert!(column(&out4, "p_best").iter().all(|p| p.is_nan()));
    let lower = column(&out4, "success_probability_lower");
    assert!(lower.iter().all(|l| (l - 0.5965).abs() < 1e-3), "{lower:?}");
    // With 4 worlds the sensitivity section is withheld, not printed as ±1.
    let md = summary(&out4);
    assert!(md.contains("Withheld: 4 worlds are too few"), "{md}");

    let narrow = study(
        dir.path(),
        "narrow.toml",
        "[[axis]]\nname = \"metrics.efficiency\"\nvalues = [0.5, 0.5005]\n",
    );
    let out = dir.path().join("narrow");
    ok(&sweep(&narrow, &out, &["--jobs", "2"]));
    let v = verdict(&out);
    assert!(v.starts_with("**Statistically tied: #1, #0"), "{v}");
    // Paired worlds: the 0.1 % better case is best in every world, yet not a winner.
    assert_eq!(column(&out, "p_best"), vec![0.0, 1.0]);
}

#[test]
fn cases_differing_in_a_key_no_metric_reads_are_tied_never_a_winner() {
    let dir = tempfile::tempdir().unwrap();
    let s = study(
        dir.path(),
        "same.toml",
        "[[axis]]\nname = \"metrics.divergence_distance\"\nvalues = [50.0, 60.0]\n",
    );
    let out = dir.path().join("same");
    ok(&sweep(&s, &out, &["--jobs", "2"]));
    let v = verdict(&out);
    assert!(v.starts_with("**Statistically tied: #0, #1"), "{v}");
    assert_eq!(column(&out, "p_best"), vec![0.5, 0.5]);
    let s = summary(&out);
    assert!(s.contains("## Ranking over 8 uncertain worlds"), "{s}");
    assert!(s.contains("## Sensitivity"), "{s}");
    assert!(s.contains("## Held-out validation"), "{s}");
}

#[test]
fn every_case_meets_the_same_worlds_for_any_jobs_shards_and_resume() {
    let dir = tempfile::tempdir().unwrap();
    let s = study(
        dir.path(),
        "s.toml",
        "[[axis]]\nname = \"design.links\"\nvalues = [3, 4]\n\n[[axis]]\nname = \"metrics.efficiency\"\nvalues = [0.5, 0.6]\n",
    );
    // Four worlds are enough to check that every case meets the same ones.
    let s = write(
        dir.path(),
        "s.toml",
        &std::fs::read_to_string(&s)
            .unwrap()
            .replace("worlds = 8", "worlds = 4"),
    );
    let read = |out: &Path, f: &str| std::fs::read(out.join(f)).unwrap();
    let j1 = dir.path().join("j1");
    let j2 = dir.path().join("j2");
    ok(&sweep(&s, &j1, &["--jobs", "1"]));
    ok(&sweep(&s, &j2, &["--jobs", "2"]));
    for f in ["worlds.csv", "cases.csv"] {
        assert!(
            read(&j1, f) == read(&j2, f),
            "{f} differs between --jobs 1 and 2"
        );
    }
    // The parameter values of a world are the same for every case.
    let w = std::fs::read_to_string(j1.join("worlds.csv")).unwrap();
    let mut by_world: std::collections::BTreeMap<String, String> = Default::default();
    for l in w.lines().skip(1) {
        let c: Vec<&str> = l.split(',').collect();
        let params = format!("{},{}", c[2], c[3]);
        let prev = by_world
            .entry(c[0].to_string())
            .or_insert_with(|| params.clone());
        assert_eq!(*prev, params, "world {} differs between cases", c[0]);
    }
    assert_eq!(by_world.len(), 4);

    let (a, b, merged) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("m"),
    );
    ok(&sweep(&s, &a, &["--shard", "0/2"]));
    ok(&sweep(&s, &b, &["--shard", "1/2"]));
    ok(&run(&["merge", arg(&a), arg(&b), "--out", arg(&merged)]));
    for f in ["worlds.csv", "cases.csv"] {
        assert!(
            read(&j1, f) == read(&merged, f),
            "{f} differs after a shard merge"
        );
    }

    let res = dir.path().join("res");
    ok(&sweep(&s, &res, &["--jobs", "1", "--max-cases", "1"]));
    ok(&sweep(&s, &res, &["--jobs", "2", "--resume"]));
    for f in ["worlds.csv", "cases.csv"] {
        assert!(read(&j1, f) == read(&res, f), "{f} differs after a resume");
    }
}

#[test]
fn bad_uncertainty_sections_exit_2_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let axis = "[[axis]]\nname = \"design.links\"\nvalues = [3]\n";
    for (edit, key) in [
        (
            (
                "hydro.linear_damping_scale\"",
                "hydro.linear_damping_scael\"",
            ),
            "uncertainty.param[0].name",
        ),
        (
            (
                "kind = \"uniform\", low = 0.5",
                "kind = \"gamma\", low = 0.5",
            ),
            "kind",
        ),
        (("worlds = 8", "worlds = 1"), "uncertainty.worlds"),
        (
            ("min_success_probability = 0.7", "confidence = 1.0"),
            "uncertainty.confidence",
        ),
        (("low = 0.0, high = 0.02", "low = 0.0, mean = 0.02"), "mean"),
        (
            ("name = \"late_turn\"", "name = \"late turn\""),
            "validate[0].name",
        ),
    ] {
        let text = format!("{BASE}\n{axis}").replacen(edit.0, edit.1, 1);
        let p = write(dir.path(), "bad.toml", &text);
        let o = run(&["sweep", arg(&p), "--out", arg(&dir.path().join("bad"))]);
        assert_eq!(o.status.code(), Some(2), "{edit:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("bad.toml:") && e.contains(key), "{edit:?}: {e}");
    }
}

#[test]
fn a_saltelli_design_of_worlds_gives_sobol_indices_in_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!("{BASE}\n[[axis]]\nname = \"metrics.efficiency\"\nvalues = [0.5, 0.6]\n")
        .replace("sampling = \"sobol\"", "sampling = \"saltelli\"")
        .replace("worlds = 8", "worlds = 3");
    let s = write(dir.path(), "saltelli.toml", &text);
    let out = dir.path().join("saltelli");
    ok(&sweep(&s, &out, &["--jobs", "2"]));
    // 3 base samples × (2 parameters + 2) = 12 worlds per case.
    let w = std::fs::read_to_string(out.join("worlds.csv")).unwrap();
    assert_eq!(w.lines().count(), 1 + 12 * 2);
    let md = summary(&out);
    assert!(md.contains("## Ranking over 12 uncertain worlds"), "{md}");
    assert!(md.contains("Sobol total index"), "{md}");
}

/// `report DIR --objective M` re-ranks a study over its worlds without re-running: `p_best`,
/// the ranks and the verdict follow the new objective (one the worlds recorded), and going
/// back gives the original ranking; an objective the worlds did not record is refused.
#[test]
fn report_re_ranks_over_the_worlds_by_another_recorded_metric() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{}\n[[axis]]\nname = \"metrics.efficiency\"\nvalues = [0.5, 0.55]\n",
        BASE.replace(
            "sampling = \"sobol\"",
            "sampling = \"sobol\"\nmetrics = [\"energy_per_metre\", \"peak_thrust\"]"
        )
    );
    let path = write(dir.path(), "two.toml", &text);
    let out = dir.path().join("two");
    ok(&sweep(&path, &out, &["--jobs", "2"]));
    assert!(verdict(&out).starts_with("**Winner: #1"));
    assert_eq!(column(&out, "p_best"), vec![0.0, 1.0]);
    let report = |objective: &str| run(&["report", arg(&out), "--objective", objective]);
    // The efficiency changes the energy, not the thrust: by peak thrust the two tie.
    ok(&report("peak_thrust"));
    let v = verdict(&out);
    assert!(
        v.starts_with("**Statistically tied") && v.contains("peak_thrust"),
        "{v}"
    );
    assert_eq!(column(&out, "p_best"), vec![0.5, 0.5]);
    let o = report("thruster_energy");
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("was not recorded over the uncertain worlds"),
        "{}",
        stderr(&o)
    );
    ok(&report("energy_per_metre"));
    assert!(verdict(&out).starts_with("**Winner: #1"));
    assert_eq!(column(&out, "p_best"), vec![0.0, 1.0]);
}

/// Issue 42 item 3: a payload declared a condition is a circumstance, not a rival. The same
/// 10 % efficiency margin under two payloads: one verdict per payload (the better efficiency
/// wins under each), `p_best` among the designs of one payload (1 and 0 under each, not 1 of
/// 4 across), labels without the payload; and a held-out variant the leader fails is one of the
/// verdict's caveats.
#[test]
fn a_payload_declared_a_condition_gets_a_verdict_per_payload() {
    let dir = tempfile::tempdir().unwrap();
    let s = study(
        dir.path(),
        "cond.toml",
        "[[axis]]\nname = \"mission.payload_mass\"\nvalues = [0.5, 1.0]\ncondition = true\n\n\
         [[axis]]\nname = \"metrics.efficiency\"\nvalues = [0.5, 0.55]\n\n\
         [[validate]]\nname = \"impossible\"\nset = { \"success.cross_track_bound\" = 1e-6 }\n",
    );
    let out = dir.path().join("cond");
    ok(&sweep(&s, &out, &["--jobs", "2"]));
    let md = summary(&out);
    let v = verdict(&out);
    assert!(
        v.starts_with("**Verdict per condition** (2 conditions"),
        "{v}"
    );
    for (payload, winner) in [("0.5", 1), ("1", 3)] {
        let line =
            format!("**Under `mission.payload_mass` = {payload}:** **Winner: #{winner} (0.55)**");
        assert!(md.contains(&line), "no `{line}` in:\n{md}");
    }
    // Ranked within each payload: each condition has its best design.
    assert_eq!(column(&out, "p_best"), vec![0.0, 1.0, 0.0, 1.0]);
    assert!(md.contains("### Under `mission.payload_mass` = 0.5: ranking over 8 worlds"));
    // The failing held-out variant reaches the caveats of each verdict.
    let caveat = "- `impossible`: unsuccessful (`validate.impossible.success` = 0";
    assert_eq!(md.matches(caveat).count(), 2, "{md}");
    // The manifest records the condition, so `report` regenerates the same summary.
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["robust"]["conditions"][0], "mission.payload_mass");
    ok(&run(&["report", arg(&out)]));
    assert_eq!(summary(&out), md);
}

/// A condition axis needs a list of values (each value one condition), and a study with
/// `[uncertainty]` (the verdict it splits): else exit 2 at the key.
#[test]
fn a_condition_axis_without_values_or_worlds_exits_2_at_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let s = study(
        dir.path(),
        "range.toml",
        "[[axis]]\nname = \"mission.payload_mass\"\nrange = { start = 0.5, stop = 1.0, steps = 2 }\ncondition = true\n",
    );
    let o = run(&["sweep", arg(&s), "--dry-run"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("axis[0].condition"), "{}", stderr(&o));
    let plain = write(
        dir.path(),
        "plain.toml",
        "[study]\nname = \"plain\"\n[design.generator]\nlinks = 5\n[static]\nsamples = 32\n\
         [[axis]]\nname = \"design.links\"\nvalues = [4, 5]\ncondition = true\n",
    );
    let o = run(&["sweep", arg(&plain), "--dry-run"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("plain.toml:") && e.contains("axis[0].condition"),
        "{e}"
    );
}

/// Issue 39 item 3: beyond 10 000 world values `manifest.json` lists none and names
/// `worlds.csv`, which holds them; `report` reads them back from it and rewrites the same
/// `worlds.csv` (5001 worlds × 2 parameters, 0.5 s runs).
#[test]
fn many_worlds_are_left_to_worlds_csv_not_listed_in_the_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let text = "[study]\nname = \"many\"\nseed = 1\n\n[design]\npreset = \"usm-paper\"\n\n\
        [scenario]\nmode = \"transport\"\nduration = 0.5\n\n[uncertainty]\nworlds = 5001\n\n\
        [[uncertainty.param]]\nname = \"physics.current_speed\"\n\
        distribution = { kind = \"uniform\", low = 0.0, high = 0.1 }\n\n\
        [[uncertainty.param]]\nname = \"hydro.linear_damping_scale\"\n\
        distribution = { kind = \"uniform\", low = 0.8, high = 1.2 }\n";
    let path = write(dir.path(), "many.toml", text);
    let out = dir.path().join("many");
    let o = sweep(&path, &out, &["--jobs", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let bytes = std::fs::read(out.join("manifest.json")).unwrap();
    assert!(bytes.len() < 100_000, "manifest of {} bytes", bytes.len());
    let m: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
    assert_eq!(m["robust"]["world_values_in"], "worlds.csv");
    assert!(m["robust"]
        .get("world_values")
        .is_none_or(|v| v.as_array().is_some_and(|a| a.is_empty())));
    let worlds = std::fs::read(out.join("worlds.csv")).unwrap();
    let text = String::from_utf8(worlds.clone()).unwrap();
    assert_eq!(text.lines().count(), 1 + 5001);
    // Every world's values are in it (no NaN parameter), and `report` gives them back.
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert!(f[2].parse::<f64>().unwrap().is_finite(), "{line}");
        assert!(f[3].parse::<f64>().unwrap().is_finite(), "{line}");
    }
    let o = run(&["report", arg(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(std::fs::read(out.join("worlds.csv")).unwrap(), worlds);
}

//! A run that has failed stops (issue 38 item 1, `[success] stop_on_failure`): a run whose
//! verdict is already certain ends there with the same status and criterion as the whole run,
//! and a successful run is bit-identical with the stop on and off. The runs are the main
//! study's committed leader (ends/4/0.14 of `studies/thrusters.toml` at its tuned gains, as in
//! `tests/capsize.rs`). A small study then shows every consumer (tuning, worlds, validation,
//! faults, the verdict) deciding alike with the stop on and off.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::leader::{metric, missed, run_layers, LEADER};
use common::{stderr, sweep, write};
use usm_study::outcome::RunResult;

/// The leader with `extra` (whole tables or `table.key = value` lines) over it, with
/// `[success] stop_on_failure = stop`.
fn run(extra: &str, stop: bool) -> RunResult {
    let switch = format!("[success]\nstop_on_failure = {stop}\n");
    run_layers(&[LEADER, extra, &switch])
}

/// Run `extra` with the stop off and on: both unsuccessful on `criterion`, the stopped one
/// ended before the end with `stopped_at` set and its metrics up to then; returns it.
fn stops_like_the_whole_run(extra: &str, criterion: &str) -> RunResult {
    let whole = run(extra, false);
    let stopped = run(extra, true);
    for (what, r) in [("whole", &whole), ("stopped", &stopped)] {
        assert_eq!(metric(r, "success"), 0.0, "{what}");
        assert_eq!(metric(r, "completed"), 1.0, "{what}");
        assert!(r.failure.is_none(), "{what}: {:?}", r.failure);
        assert_eq!(missed(r), Some(criterion), "{what}: {:?}", r.missed);
    }
    assert!(metric(&whole, "stopped_at").is_nan());
    assert_eq!(metric(&whole, "simulated_time"), 140.0);
    let at = metric(&stopped, "stopped_at");
    let reached = metric(&stopped, "simulated_time");
    assert!(
        at < 140.0 && reached <= at,
        "stopped at {at} s, logged to {reached} s"
    );
    let detail = &stopped.missed.as_ref().unwrap().detail;
    assert!(detail.contains("run stopped at t = "), "{detail}");
    stopped
}

#[test]
fn a_capsize_stops_on_roll_with_the_whole_runs_verdict() {
    // 1 µm/s upwards: the leader (CB = CG) rolls over (tests/capsize.rs).
    let r = stops_like_the_whole_run(
        "[physics]\ncurrent = [0.0, 0.0, 0.000001]\n",
        "max_roll_deg",
    );
    // Stopped at the first logged sample past the bound: the metric is just above it.
    let roll = metric(&r, "max_abs_roll_deg");
    assert!(roll > 30.0 && roll < 40.0, "max |roll| {roll}°");
}

#[test]
fn a_saturation_bound_of_zero_stops_at_the_first_saturated_period() {
    // Attitude bounds off and a peak bound no thrust can reach (above the 40 N limits, so it
    // does not hide the saturation criterion): saturation is the first criterion judged.
    let extra = "[success]\nmax_saturation_fraction = 0.0\nmax_roll_deg = 0.0\n\
                 max_pitch_deg = 0.0\nmax_vertical_error = 0.0\nmax_peak_thrust = 50.0\n";
    let r = stops_like_the_whole_run(extra, "max_saturation_fraction");
    assert!(metric(&r, "saturation_fraction") > 0.0);
    // With the default attitude bounds in force, roll is judged first and could still be
    // missed later: saturation alone does not stop the run (the verdict could change).
    let guarded = run("[success]\nmax_saturation_fraction = 0.0\n", true);
    assert!(metric(&guarded, "stopped_at").is_nan());
    assert_eq!(missed(&guarded), Some("max_saturation_fraction"));
}

#[test]
fn a_design_that_cannot_reach_stops_at_once() {
    let r = stops_like_the_whole_run("[mission]\nreach = 5.0\n", "mission.reach");
    assert_eq!(
        metric(&r, "stopped_at"),
        metric(&r, "simulated_time") + 0.05
    );
}

#[test]
fn a_successful_run_is_bit_identical_with_the_stop_on_and_off() {
    let (on, off) = (run("", true), run("", false));
    assert_eq!(metric(&on, "success"), 1.0, "{:?}", on.missed);
    let bits = |r: &RunResult| -> Vec<(String, u64)> {
        r.metrics
            .iter()
            .map(|(k, x)| (k.clone(), x.to_bits()))
            .collect()
    };
    assert_eq!(bits(&on), bits(&off));
    let log = |r: &RunResult| -> Vec<Vec<u64>> {
        (r.trajectory.iter())
            .map(|(_, x)| x.iter().map(|v| v.to_bits()).collect())
            .collect()
    };
    assert_eq!(log(&on), log(&off));
    assert_eq!(on.trajectory.channels(), off.trajectory.channels());
}

/// A small study of the leader's body (CB = CG and the generator's 0.02 m metacentric height)
/// whose roll bound of 2° is broken in some worlds (a vertical current) and in the validation
/// variant: tuning, worlds, validation and single faults.
const STUDY: &str = r#"[study]
name = "early_stop"
seed = 7
objective = "mission_cost"

[design.generator]
links = 4
body_profile = "paper"
thrust_limit = 40.0
thruster_rule = "ends"
longitudinal_offset = 0.14

[mission]
tracking_weight = 0.1

[scenario]
mode = "transport"
duration = 60.0

[allocation]
method = "pinv"
lambda = 0.1

[success]
cross_track_bound = 10.0
convergence_window = 1000.0
max_roll_deg = 2.0

[faults]
single = true
at = 10.0

[tune]
starts = 1

[[tune.param]]
name = "control.k_6p"
lower = 0.01
upper = 0.5
scale = "log"

[tune.objective]
[[tune.objective.term]]
metric = "mission_cost"
weight = 1.0

[[tune.constraint]]
metric = "success"
op = "=="
value = 1

[tune.solver]
method = "nelder-mead"
max_evals = 5

[uncertainty]
worlds = 4
sampling = "sobol"

[[uncertainty.param]]
name = "physics.current[2]"
distribution = { kind = "uniform", low = 0.002, high = 0.02 }

[[validate]]
name = "cross_current"
set = { "physics.current[2]" = 0.02 }

[[axis]]
name = "design.metacentric_height"
values = [0.0, 0.02]
"#;

/// `cases.csv` or `worlds.csv` of `out` as rows of named cells.
fn rows(out: &Path, file: &str) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(out.join(file)).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            head.iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

#[test]
fn every_consumer_decides_alike_with_the_stop_on_and_off() {
    let dir = tempfile::tempdir().unwrap();
    let on = write(dir.path(), "on.toml", STUDY);
    let off_text = STUDY.replace(
        "max_roll_deg = 2.0",
        "max_roll_deg = 2.0\nstop_on_failure = false",
    );
    let off = write(dir.path(), "off.toml", &off_text);
    let (out_on, out_off) = (dir.path().join("on"), dir.path().join("off"));
    for (study, out) in [(&on, &out_on), (&off, &out_off)] {
        let o = sweep(study, out, &["--jobs", "2"]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    // What is decided by success alone, and the tuned gains (tuning candidates run whole).
    let decided = |c: &str| {
        c == "status"
            || c.starts_with("tuned.")
            || c.ends_with("success")
            || c.ends_with(".missed")
            || [
                "success_probability",
                "success_probability_lower",
                "fault_tolerance",
            ]
            .contains(&c)
            || c.starts_with("p_best")
            || c.starts_with("rank_")
    };
    let criterion = |r: &str| r.split(':').next().unwrap_or("").to_string();
    let (a, b) = (rows(&out_on, "cases.csv"), rows(&out_off, "cases.csv"));
    assert_eq!(a.len(), 2);
    for (x, y) in a.iter().zip(&b) {
        for (c, v) in x.iter().filter(|(c, _)| decided(c)) {
            assert_eq!(Some(v), y.get(c), "{c}");
        }
        assert_eq!(criterion(&x["reason"]), criterion(&y["reason"]));
    }
    let (a, b) = (rows(&out_on, "worlds.csv"), rows(&out_off, "worlds.csv"));
    let mut stopped = 0;
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((&x["success"], &x["missed"]), (&y["success"], &y["missed"]));
        stopped += usize::from(x["mission_cost"] != y["mission_cost"]);
    }
    // Some world did stop (its metrics went less far); some missed the roll bound.
    assert!(stopped > 0);
    assert!(a.iter().any(|x| x["missed"] == "max_roll_deg"));
    let verdict = |out: &Path| {
        let s = std::fs::read_to_string(out.join("summary.md")).unwrap();
        s.lines()
            .skip(1)
            .find(|l| !l.is_empty())
            .unwrap()
            .to_string()
    };
    assert_eq!(verdict(&out_on), verdict(&out_off));
}

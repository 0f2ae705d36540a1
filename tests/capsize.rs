//! A run that capsizes is unsuccessful, and its verdict names the axis (issue 36 item 3): the
//! main study's committed leader, ends/4/0.14 of `studies/thrusters.toml` (case 47) at its
//! tuned gains (`results/thrusters/cases.csv`), built as the sweep builds it — the transport
//! defaults (`default_table`) with the study's scenario-side sections over them — rolls over
//! under a 1 µm/s vertical current and with thruster T2 dead from 30 s. Before `[success]`
//! bounded the attitude, the first was judged on `max_saturation_fraction` and the second
//! passed (the study's `fault_tolerance` 0.83 counted it as survived).

mod common;

use common::leader::{metric, missed, run_layers, LEADER};
use usm_study::outcome::RunResult;

/// The leader's run with `extra` (TOML: whole tables or `table.key = value` lines) over it,
/// to the end whatever its verdict (`[success] stop_on_failure = false`: these tests look at
/// the whole capsize; tests/early_stop.rs stops the same run at the bound).
fn run(extra: &str) -> RunResult {
    run_with(
        LEADER,
        &format!("{extra}\n[success]\nstop_on_failure = false\n"),
    )
}

/// As [`run`], from the study sections `leader`.
fn run_with(leader: &str, extra: &str) -> RunResult {
    run_layers(&[leader, extra])
}

#[test]
fn the_leader_capsizes_under_a_tiny_vertical_current_and_a_dead_thruster_and_fails_on_roll() {
    // Nominal: level (every body neutral with CB = CG, a horizontal path, no vertical load).
    let nominal = run("");
    assert_eq!(metric(&nominal, "success"), 1.0, "{:?}", nominal.missed);
    assert!(metric(&nominal, "max_abs_roll_deg") < 1.0);
    assert!(metric(&nominal, "max_vertical_error") < 0.1);
    // 1 µm/s upwards: nothing restores roll, the body rolls over.
    let current = run("[physics]\ncurrent = [0.0, 0.0, 0.000001]\n");
    // T2 dead from 30 s (informed allocator, as the study's [faults]).
    let fault = run("[fault]\nthruster = \"T2\"\nat = 30.0\nkind = \"dead\"\ninformed = true\n");
    for (what, r) in [("vertical current", &current), ("T2 dead", &fault)] {
        let roll = metric(r, "max_abs_roll_deg");
        assert!(roll > 90.0, "{what}: max |roll| {roll}°");
        assert_eq!(metric(r, "success"), 0.0, "{what}");
        assert_eq!(missed(r), Some("max_roll_deg"), "{what}: {:?}", r.missed);
        let detail = &r.missed.as_ref().unwrap().detail;
        assert!(
            detail.starts_with("max_abs_roll_deg = "),
            "{what}: {detail}"
        );
        assert!(metric(r, "success_margin") < -1.0, "{what}");
    }
}

/// With the generator's default metacentric height (0.02 m, issue 36 item 1) the same leader,
/// at the same gains and under the same 1 µm/s vertical current, stays level: the hydrostatic
/// restoring moment is what a design without roll authority relies on.
#[test]
fn with_the_default_metacentric_height_the_same_current_does_not_capsize_the_leader() {
    let leader = LEADER.replace("metacentric_height = 0.0", "metacentric_height = 0.02");
    let r = run_with(&leader, "[physics]\ncurrent = [0.0, 0.0, 0.000001]\n");
    let roll = metric(&r, "max_abs_roll_deg");
    assert!(roll < 5.0, "max |roll| {roll}°");
    assert_eq!(metric(&r, "success"), 1.0, "{:?}", r.missed);
}

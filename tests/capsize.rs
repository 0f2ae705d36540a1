//! A run that capsizes is unsuccessful, and its verdict names the axis (issue 36 item 3): the
//! main study's committed leader, ends/4/0.14 of `studies/thrusters.toml` (case 47) at its
//! tuned gains (`results/thrusters/cases.csv`), built as the sweep builds it — the transport
//! defaults (`default_table`) with the study's scenario-side sections over them — rolls over
//! under a 1 µm/s vertical current and with thruster T2 dead from 30 s. Before `[success]`
//! bounded the attitude, the first was judged on `max_saturation_fraction` and the second
//! passed (the study's `fault_tolerance` 0.83 counted it as survived).

use usm_study::outcome::{run_scenario, RunResult};
use usm_study::scenario::{default_table, parse_table, resolve_design, Mode, Source};

/// The study's scenario-side sections for case 47 (design axes, mission, allocation, metrics)
/// and its tuned gains.
const LEADER: &str = r#"
[scenario]
name = "ends-4-0.14"
mode = "transport"
duration = 140.0

[design.generator]
links = 4
body_profile = "paper"
thrust_limit = 40.0
thruster_rule = "ends"
longitudinal_offset = 0.14
# As committed in wave 3: every body neutral with CB = CG (no hydrostatic restoring moment).
# The generator's default since issue 36 item 1 raises the CB 0.02 m above the CG; the second
# test below runs the same leader with that default.
metacentric_height = 0.0

[mission]
payload_mass = 2.0
reach = 2.5
tracking_weight = 0.1

[allocation]
method = "pinv"
lambda = 0.1

[metrics]
propeller_diameter = 0.07
efficiency = 0.5

[control]
k_psi = 0.300961678493135
look_ahead = 1.1990433931350695
k_6p = 0.41125891198668474
k_6d = 0.3018726929028814
"#;

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
    let mut t = default_table(Mode::Transport).unwrap();
    for text in [leader, extra] {
        let over: toml::Table = toml::from_str(text).unwrap();
        for (k, v) in over {
            match (t.get_mut(&k), v) {
                (Some(toml::Value::Table(base)), toml::Value::Table(v)) => base.extend(v),
                (_, v) => {
                    t.insert(k, v);
                }
            }
        }
    }
    let src = Source::unplaced("ends-4-0.14");
    let f = parse_table(&t, &src).unwrap();
    let v = resolve_design(&f, &src).unwrap();
    run_scenario(&v, &f).unwrap()
}

fn metric(r: &RunResult, k: &str) -> f64 {
    r.metric(k).unwrap_or_else(|| panic!("metric {k}"))
}

fn missed(r: &RunResult) -> Option<&'static str> {
    r.missed.as_ref().map(|m| m.criterion.as_str())
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

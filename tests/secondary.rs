//! The paper's secondary objectives (USM section IV-A) in closed loop: the controllability
//! task (climbing the commanded-subspace σ_min of the scaled TCM in the null space of the
//! work-mode tasks, `[secondary] controllability_gain`) raises the smallest commanded σ_min
//! along a work-mode run, and keeps the pose task.

use usm_study::outcome::{run_scenario, RunResult};
use usm_study::paper::secondary::secondary_profile;
use usm_study::scenario::{load_table, parse_table, resolve_design};

/// `work-setpoint` with the paper-like far setpoint pinned (x = 3.7 m, beyond the 3.3 m body,
/// yawed 25° and pitched 10°), and `controllability_gain = k_c`: the run and the smallest
/// commanded σ_min along it.
fn work_run(k_c: f64) -> (RunResult, f64) {
    let (mut t, src) = load_table("work-setpoint").unwrap();
    let text = format!(
        "position = [3.7, 0.5, -0.3]\nrpy_deg = [0.0, 10.0, 25.0]\n\
         [secondary]\ncontrollability_gain = {k_c}\n"
    );
    let extra: toml::Table = toml::from_str(&format!("[setpoint]\n{text}")).unwrap();
    for (k, v) in extra {
        t.insert(k, v);
    }
    let f = parse_table(&t, &src).unwrap();
    let v = resolve_design(&f, &src).unwrap();
    let r = run_scenario(&v, &f).unwrap();
    assert!(r.failure.is_none(), "{:?}", r.failure);
    let (sigma, _) = secondary_profile(&f, &v, &r).unwrap();
    let min = sigma.iter().copied().fold(f64::INFINITY, f64::min);
    (r, min)
}

#[test]
fn controllability_task_raises_the_minimum_commanded_sigma_min_in_work_mode() {
    let (off, s_off) = work_run(0.0);
    let (on, s_on) = work_run(0.5);
    // Measured: 0.4001 without, 0.4047 with (the straight start is 0.4053); every sample is
    // counted, so the raise is of the run's worst configuration.
    assert!(s_on > s_off + 5e-4, "{s_off} → {s_on}");
    // The primary task still converges as closely (final position error 0.0046 → 0.0057 m).
    let e = |r: &RunResult| r.metric("final_position_error").unwrap();
    assert!(e(&on) < 0.02 && e(&off) < 0.02, "{} {}", e(&off), e(&on));
}

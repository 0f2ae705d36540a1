//! Transport mode (USM section V-A, VI-B) in closed loop on the full hydrodynamic model with
//! the QP allocator, both Table III methods, plus the physics sanity checks behind the
//! findings in results/paper/FINDINGS.md. Tests named `reproduced_…` pin the paper's findings
//! the model reproduces; tests named `known_disagreement_…` pin where it does not (Method 2
//! slower, more overshoot, a looser tail; the printed reading not converging), with the
//! numbers and the reason in their comments.

use usm_study::control::transport::TransportMethod;
use usm_study::dynamics::{ActuatorCommand, SimConfig, Simulator};
use usm_study::model::presets::usm_paper;
use usm_study::outcome::{run_scenario, RunResult};
use usm_study::paper::readings::{run_reading, ReadingRun, TransportReading};
use usm_study::scenario::{load_table, parse_table, resolve_design, Channel};

/// Run a preset, extended from the paper's 140 s to 170 s so that convergence within 60 s
/// of the segment commanded at 95 s can be judged.
fn run(preset: &str) -> RunResult {
    let (mut t, src) = load_table(preset).unwrap();
    t["scenario"]
        .as_table_mut()
        .unwrap()
        .insert("duration".into(), toml::Value::Float(170.0));
    let f = parse_table(&t, &src).unwrap();
    let v = resolve_design(&f, &src).unwrap();
    let r = run_scenario(&v, &f).unwrap();
    assert!(r.failure.is_none(), "{preset}: {:?}", r.failure);
    r
}

fn metric(r: &RunResult, k: &str) -> f64 {
    r.metric(k).unwrap_or_else(|| panic!("metric {k}"))
}

/// Peak |thrust| over the samples with `t` in `[a, b)`.
fn peak_thrust(r: &RunResult, a: f64, b: f64) -> f64 {
    let t = r.trajectory.get(Channel::T).unwrap();
    let cols: Vec<&[f64]> = (0..7)
        .map(|j| r.trajectory.get(Channel::U(j)).unwrap())
        .collect();
    (0..t.len())
        .filter(|&i| t[i] >= a && t[i] < b)
        .flat_map(|i| cols.iter().map(move |c| c[i].abs()))
        .fold(0.0, f64::max)
}

/// Both methods under the project's default reading (`TransportReading::DEFAULT`, adopted by
/// `usm-study paper readings` as the reading closest to the printed text under which both
/// Table III methods converge), 170 s.
fn default_runs() -> (ReadingRun, ReadingRun) {
    let r = TransportReading::DEFAULT;
    (
        run_reading(r, TransportMethod::Method1, None).unwrap(),
        run_reading(r, TransportMethod::Method2, None).unwrap(),
    )
}

#[test]
fn reproduced_both_methods_converge_turn_and_cruise_far_below_the_thrust_limit() {
    // The paper's findings this model reproduces (USM section VI-B): both methods converge to
    // the path and complete the 180° turn; thrust stays far below the 40 N limit except in the
    // commanded transients (start and turn); Method 2 uses slightly more thruster effort.
    let r1 = run("transport-method1");
    let r2 = run("transport-method2");
    for (name, r) in [("method1", &r1), ("method2", &r2)] {
        assert_eq!(metric(r, "completed"), 1.0, "{name}");
        assert_eq!(metric(r, "segments_reached"), 2.0, "{name}");
        // Converged (|e_y| < 0.1 m and staying) on both segments, 180° turn completed.
        assert_eq!(metric(r, "converged"), 1.0, "{name}");
        assert!(metric(r, "final_cross_track").abs() < 0.05, "{name}");
        // The QP never exceeds the ±40 N limits, and away from the start transient and the
        // turn the thrust is far below them.
        assert!(metric(r, "peak_thrust") <= 40.0 + 1e-6, "{name}");
        let cruise = peak_thrust(r, 2.0, 95.0).max(peak_thrust(r, 125.0, 170.1));
        assert!(cruise < 10.0, "{name}: cruise peak {cruise}");
        assert!(metric(r, "base_cross_track_rms") < 0.2, "{name}");
    }
    // "Method 2 uses slightly more thruster effort": +1.5 % here (2369 vs 2333 N·s).
    let (e1, e2) = (metric(&r1, "effort_abs"), metric(&r2, "effort_abs"));
    assert!(e2 > e1 && e2 < 1.05 * e1, "{e1} {e2}");
    // The presets run the default reading.
    let (d1, d2) = default_runs();
    assert_eq!(d1.get("effort_abs"), e1);
    assert_eq!(d2.get("effort_abs"), e2);
}

#[test]
fn known_disagreement_method2_converges_slower_with_more_overshoot_and_a_looser_tail() {
    // KNOWN DISAGREEMENT with the paper, pinned so that a change is noticed: the paper finds
    // Method 2 faster, with less overshoot, its tail following the front's track more closely.
    // Under the default reading it is the reverse (results/paper/readings/readings.md: no
    // reading of the 32 makes Method 2 converge faster). Method 1: 24.6 / 26.4 s, overshoot
    // 0.10 m, tail 0.068 m; Method 2: 71.7 / 71.4 s, 1.64 m, 0.21 m.
    let (r1, r2) = default_runs();
    assert!(r1.converged() && r2.converged());
    for k in ["seg0_convergence_time", "seg1_convergence_time"] {
        let (a, b) = (r1.get(k), r2.get(k));
        assert!(a < 40.0 && b > 60.0 && b < 75.0, "{k}: {a} {b}");
    }
    let over = |r: &ReadingRun| r.get("seg0_overshoot").max(r.get("seg1_overshoot"));
    assert!(
        over(&r1) < 0.2 && over(&r2) > 1.0,
        "{} {}",
        over(&r1),
        over(&r2)
    );
    for k in ["tail_deviation_rms", "base_cross_track_rms"] {
        assert!(
            r2.get(k) > 1.5 * r1.get(k),
            "{k}: {} {}",
            r1.get(k),
            r2.get(k)
        );
    }
}

#[test]
fn known_disagreement_comes_from_the_table_iii_yaw_gains_not_the_surge_source() {
    // Why Method 2 is slower here: its Table III yaw gains (k_6p = 0.01, k_6d = 0.2, Δ = 2 m),
    // not its base-surge regulation. With the yaw gains and Δ swapped, the ordering follows
    // the gains: base surge with Method 1's yaw gains converges as fast as Method 1 (24.6 s on
    // segment 0), front surge with Method 2's as slowly as Method 2 (68.8 s).
    let r = TransportReading::DEFAULT;
    let base_fast =
        run_reading(r, TransportMethod::Method2, Some(TransportMethod::Method1)).unwrap();
    let front_slow =
        run_reading(r, TransportMethod::Method1, Some(TransportMethod::Method2)).unwrap();
    assert!(base_fast.converged() && front_slow.converged());
    let (fast, slow) = (
        base_fast.get("seg0_convergence_time"),
        front_slow.get("seg0_convergence_time"),
    );
    assert!(fast < 30.0 && slow > 60.0, "{fast} {slow}");
}

#[test]
fn known_disagreement_printed_reading_does_not_converge() {
    // KNOWN DISAGREEMENT: the printed reading (USM-33 with n, the remaining accelerations
    // literally zero) leaves sway/heave/pitch as pure integrators and cancels the bent body's
    // steering force; neither method converges (bounded: Method 1 limit cycle / offset,
    // Method 2 slow oscillation). See control::transport for the closed-loop analysis.
    for method in [TransportMethod::Method1, TransportMethod::Method2] {
        let r = run_reading(TransportReading::PRINTED, method, None).unwrap();
        assert!(!r.failed, "{method:?}");
        assert!(!r.converged(), "{method:?}");
        assert!(r.get("final_cross_track").abs() < 5.0, "{method:?}");
    }
}

#[test]
fn straight_vehicle_runs_straight_at_the_drag_balance_speed() {
    // 2 × 5.6 N from the longitudinal thrusters, no joint motion: the axial drag
    // Σ ½ρ C_d,x πr² u² + Σ d_x u = 26.8 u² + 9 u balances 11.2 N at u = 0.500 m/s.
    let v = usm_paper();
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    let zero = [0.0; 8];
    let thrust = [0.0, 0.0, 5.6, 5.6, 0.0, 0.0, 0.0];
    let cmd = ActuatorCommand {
        thrust: &thrust,
        joint_ref: &zero,
        joint_rate_ref: &zero,
    };
    for _ in 0..6000 {
        sim.step(0.01, &cmd).unwrap();
    }
    let s = sim.state();
    assert!(
        (s.base_twist[0] - 0.500).abs() < 2e-3,
        "{}",
        s.base_twist[0]
    );
    assert!(s.base_twist.rows(1, 5).norm() < 1e-9);
    assert!(s.pose.position.y.abs() < 1e-9);
    // Whole-body inertia about the tail (base): surge 81.3 + 0.1·81.3, sway 81.3 + πρr²L,
    // yaw about the tail (≈146 kg·m² about the centre + m_sway·1.65²).
    let (m11, _) = sim.base_control_terms().unwrap();
    assert!((m11[(0, 0)] - 89.43).abs() < 0.01);
    assert!((m11[(1, 1)] - 158.15).abs() < 0.01);
    assert!((m11[(5, 5)] - 575.7).abs() < 0.1);

    // Munk instability of the bare body (physical): a small yaw disturbance grows into a
    // steady turn instead of decaying, and the turn is to the side of the disturbance.
    let mut st = sim.state().clone();
    st.base_twist[5] = 0.02;
    st.base_twist[1] = -0.02 * 1.65; // rotation about the centre
    sim.set_state(st).unwrap();
    for _ in 0..3000 {
        sim.step(0.01, &cmd).unwrap();
    }
    let r = sim.state().base_twist[5];
    assert!(r > 0.045 && r < 0.06, "yaw rate {r}");
}

/// The paper design (Method 1) under `[mission]` overrides (extended to 170 s like [`run`]).
fn run_mission(mission: toml::Table) -> RunResult {
    let (mut t, src) = load_table("transport-method1").unwrap();
    t["scenario"]
        .as_table_mut()
        .unwrap()
        .insert("duration".into(), toml::Value::Float(170.0));
    t.insert("mission".into(), toml::Value::Table(mission));
    let f = parse_table(&t, &src).unwrap();
    let v = resolve_design(&f, &src).unwrap();
    run_scenario(&v, &f).unwrap()
}

/// A mission (docs/model.md §6 "Missions"). The paper design reaches 3.3 m at q = 0 (its
/// bodies end to end, base at the tail face, end effector at the head's front face), so a 3.5 m reach requirement fails the run first, with the
/// requirement named, and 3.2 m passes. A neutrally buoyant 2 kg payload at the head adds inertia
/// but no weight: the run still converges. The whole-vehicle energy charges the joints at η_j.
#[test]
fn a_mission_rejects_a_design_that_cannot_reach_and_charges_the_joints() {
    let mission = |reach: f64| {
        let mut m = toml::Table::new();
        m.insert("reach".into(), toml::Value::Float(reach));
        m.insert("payload_mass".into(), toml::Value::Float(2.0));
        m
    };
    let short = run_mission(mission(3.5));
    assert!((metric(&short, "reach") - 3.3).abs() < 1e-9);
    let missed = short
        .missed
        .as_ref()
        .expect("a 3.5 m reach is out of reach");
    assert_eq!(missed.criterion.as_str(), "mission.reach");
    assert!(
        missed.detail.contains("reach = 3.300 m"),
        "{}",
        missed.detail
    );
    let ok = run_mission(mission(3.2));
    assert!(ok.missed.is_none(), "{:?}", ok.missed);
    let total = metric(&ok, "thruster_energy") + metric(&ok, "joint_energy") / 0.7;
    assert!((metric(&ok, "total_energy") - total).abs() <= 1e-9 * total);
    assert!(
        metric(&ok, "total_energy_per_metre") > metric(&ok, "energy_per_metre"),
        "the joints cost something"
    );
    // The tracking term: the run starts 3 m off the path, so at least the initial offset's
    // approach is charged (∫|e_y| dt > 3 m × a few seconds), and it is finite.
    let iae = metric(&ok, "cross_track_iae");
    assert!(iae.is_finite() && iae > 10.0, "{iae}");
}

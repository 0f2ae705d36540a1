//! Transport mode (USM section V-A, VI-B) in closed loop on the full hydrodynamic model with
//! the QP allocator, both Table III methods, plus the physics sanity checks behind the
//! findings in results/paper/FINDINGS.md. The assertions state what the model achieves, not
//! what the paper reports: Method 1 converges within 60 s of each segment change, Method 2
//! converges on both segments but needs ~72 s (the paper's "Method 2 is faster" does not hold
//! here).

use usm_study::dynamics::{ActuatorCommand, SimConfig, Simulator};
use usm_study::model::presets::usm_paper;
use usm_study::scenario::{
    load_table, parse_table, resolve_design, run_scenario, Channel, RunResult,
};

/// Run a preset, extended from the paper's 140 s to 170 s so that convergence within 60 s
/// of the segment commanded at 95 s can be judged, with `overrides` applied.
fn run(preset: &str, overrides: &[(&str, &str, toml::Value)]) -> RunResult {
    let (mut t, src) = load_table(preset).unwrap();
    t["scenario"]
        .as_table_mut()
        .unwrap()
        .insert("duration".into(), toml::Value::Float(170.0));
    for (sec, key, val) in overrides {
        t.entry(sec.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .unwrap()
            .insert(key.to_string(), val.clone());
    }
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

#[test]
fn transport_both_methods_converge_with_qp() {
    let r1 = run("transport-method1", &[]);
    let r2 = run("transport-method2", &[]);
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
    // Method 1: within 60 s of each segment change, small overshoot.
    for k in 0..2 {
        let c = metric(&r1, &format!("seg{k}_convergence_time"));
        assert!(c < 40.0, "method1 seg{k}: {c}");
    }
    assert!(metric(&r1, "overshoot") < 0.2);
    // Method 2: converges, but slower than 60 s and with more overshoot than Method 1 —
    // the opposite of the paper's finding (reported, not tuned away).
    for k in 0..2 {
        let c = metric(&r2, &format!("seg{k}_convergence_time"));
        assert!(c > 60.0 && c < 75.0, "method2 seg{k}: {c}");
    }
    assert!(metric(&r2, "overshoot") > metric(&r1, "overshoot"));
    assert!(metric(&r2, "convergence_time") > metric(&r1, "convergence_time"));
}

#[test]
fn paper_literal_base_control_does_not_converge() {
    // USM-33 with n and the remaining accelerations literally zero: bounded, not converged
    // (Method 2: slow oscillation; Method 1: limit cycle / offset).
    let lit = [
        ("base_control", "nonlinear", toml::Value::Boolean(true)),
        (
            "base_control",
            "kp",
            toml::Value::Array(vec![toml::Value::Float(0.0); 6]),
        ),
    ];
    for preset in ["transport-method1", "transport-method2"] {
        let r = run(preset, &lit);
        assert_eq!(metric(&r, "converged"), 0.0, "{preset}");
        assert!(metric(&r, "final_cross_track").abs() < 5.0, "{preset}");
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

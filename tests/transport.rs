//! Transport mode (USM section V-A, VI-B) in closed loop on the full hydrodynamic model with
//! the QP allocator, both Table III methods, plus the physics sanity checks behind the
//! findings in results/paper/FINDINGS.md. Tests named `reproduced_…` pin the paper's findings
//! the model reproduces under the adopted reading; the others pin behaviour with its reason:
//! the ordering of the methods follows the yaw gains, the printed reading gives the paper's
//! ranking, cross-flow lift (off by default) leaves the model bit-identical when off.

use usm_study::control::transport::TransportMethod;
use usm_study::dynamics::{ActuatorCommand, SimConfig, Simulator};
use usm_study::model::presets::usm_paper;
use usm_study::model::Hydro;
use usm_study::outcome::{run_scenario, RunResult};
use usm_study::paper::readings::{run_reading, run_reading_with, ReadingRun, TransportReading};
use usm_study::paper::transport_claims::{judge_claims, CLAIMS};
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
    // "Method 2 uses slightly more thruster effort" is NOT reproduced under the hull drag
    // (issue 44): Method 2 uses 3.6 % less (1373 vs 1424 N·s). Under the former per-body drag
    // it used 1.5 % more (2369 vs 2333 N·s); the claim rests on a few per cent either way.
    let (e1, e2) = (metric(&r1, "effort_abs"), metric(&r2, "effort_abs"));
    assert!(e2 < e1 && e2 > 0.9 * e1, "{e1} {e2}");
    // The presets run the default reading.
    let (d1, d2) = default_runs();
    assert_eq!(d1.get("effort_abs"), e1);
    assert_eq!(d2.get("effort_abs"), e2);
}

#[test]
fn adopted_reading_ordering_follows_the_yaw_gains_not_the_surge_source() {
    // Under the adopted reading (chosen because both methods converge under it) Method 1 is
    // the faster: 26.2 / 28.9 s, no overshoot, against Method 2's 40.2 / 40.8 s, 0.93 m (hull
    // drag, issue 44; the former per-body drag gave 24.6 / 26.4 against 71.7 / 71.4 s).
    // What makes the difference is the Table III yaw gains (k_6p = 0.13 vs 0.01): with the
    // yaw gains and Δ swapped the ordering follows them (base surge with Method 1's: 26.1 s on
    // segment 0; front surge with Method 2's: 38.3 s), and Method 1's k_6p alone makes
    // Method 2 converge faster than Method 1 on segment 0. With k_6p = 0.01 the base yaw loop
    // is far slower than the LOS loop (Δ/U = 4 s).
    let (r1, r2) = default_runs();
    assert!(r1.converged() && r2.converged());
    let t = |r: &ReadingRun, k: &str| r.get(k);
    assert!((t(&r1, "seg0_convergence_time") - 26.2).abs() < 1e-9);
    assert!((t(&r2, "seg0_convergence_time") - 40.2).abs() < 1e-9);
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
    assert!(fast < 30.0 && slow > 35.0, "{fast} {slow}");
    // k_6p alone carries it.
    let k6p = run_reading_with(
        r,
        TransportMethod::Method2,
        None,
        &[("control", "k_6p", toml::Value::Float(0.13))],
    )
    .unwrap();
    assert!(k6p.converged());
    assert!((t(&k6p, "seg0_convergence_time") - 19.5).abs() < 1e-9);
    assert!((t(&k6p, "seg1_convergence_time") - 15.4).abs() < 1e-9);
    assert!(t(&k6p, "seg0_convergence_time") < t(&r1, "seg0_convergence_time"));
}

#[test]
fn printed_reading_gives_the_papers_ranking_only_method2_converges() {
    // The printed reading (USM-33 with n, the remaining accelerations literally zero):
    // sway/heave/pitch are pure integrators and n cancels the bent body's steering force
    // (control::transport has the closed-loop analysis). Method 1 (k_6p = 0.13) is unstable
    // there: a bounded limit cycle with 40 N saturations (≈ 40 % of the time); Method 2
    // (k_6p = 0.01) oscillates slowly and converges onto segment 1 (72.8 s after the turn).
    // So the printed text supports the paper's ranking — Method 2 converges faster and with
    // less overshoot — but not its "both methods converge".
    let r1 = run_reading(TransportReading::PRINTED, TransportMethod::Method1, None).unwrap();
    let r2 = run_reading(TransportReading::PRINTED, TransportMethod::Method2, None).unwrap();
    assert!(!r1.failed && !r2.failed);
    assert!(!r1.converged() && !r2.converged());
    assert!(r1.get("seg0_convergence_time").is_nan() && r1.get("seg1_convergence_time").is_nan());
    assert!((r2.get("seg1_convergence_time") - 72.8).abs() < 1e-9);
    assert!(r1.get("final_cross_track").abs() > 2.0 && r1.get("final_cross_track").abs() < 5.0);
    assert!(r2.get("final_cross_track").abs() < 0.1);
    assert!(r1.get("saturation_fraction") > 0.3);
    let verdicts = judge_claims(&r1, &r2);
    let supported: Vec<usize> = (0..CLAIMS.len()).filter(|&i| verdicts[i].1).collect();
    assert!(CLAIMS[2].text.contains("faster convergence"));
    assert!(CLAIMS[3].text.contains("less overshoot"));
    assert!(
        supported.contains(&2) && supported.contains(&3),
        "{verdicts:?}"
    );
    assert!(!supported.contains(&0), "not both converge");
}

#[test]
fn without_lift_the_runs_are_bit_identical_to_the_model_before_lift() {
    // `hydro.lift_slope = 0` (the default) must leave the model as it was: these are the
    // adopted reading's and the printed reading's figures from results/paper/readings, to
    // the last bit (re-pinned under the hull drag of issue 44; the lift term is unchanged).
    let lift_off = [("hydro", "lift_slope", toml::Value::Float(0.0))];
    let cases = [
        (
            TransportReading::DEFAULT,
            TransportMethod::Method1,
            "1424.4017359017262",
            "3077.17015495058",
        ),
        (
            TransportReading::DEFAULT,
            TransportMethod::Method2,
            "1372.6289117115582",
            "2711.4764663701694",
        ),
        (
            TransportReading::PRINTED,
            TransportMethod::Method2,
            "2902.051194986988",
            "7744.64216155322",
        ),
    ];
    for (reading, method, effort, energy) in cases {
        let r = run_reading_with(reading, method, None, &lift_off).unwrap();
        assert_eq!(r.lift_slope, 0.0);
        assert_eq!(
            r.get("effort_abs"),
            effort.parse::<f64>().unwrap(),
            "{method:?}"
        );
        assert_eq!(
            r.get("thruster_energy"),
            energy.parse::<f64>().unwrap(),
            "{method:?}"
        );
    }
}

#[test]
fn straight_vehicle_runs_straight_at_the_drag_balance_speed() {
    // 2 × 2.69 N from the longitudinal thrusters, no joint motion: the hull drag
    // (docs/model.md §2 "Hull drag": friction 1.01 N, nose and base 2.62 N, appendages 1.59 N,
    // linear 0.17 N at 0.5 m/s) balances 5.38 N at u = 0.500 m/s (the former per-body drag:
    // 11.2 N).
    let v = usm_paper();
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    cruise(&mut sim, 6000);
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
    disturb_yaw(&mut sim);
    cruise(&mut sim, 3000);
    let r = sim.state().base_twist[5];
    assert!(r > 0.04 && r < 0.06, "yaw rate {r}");
}

/// `steps` × 0.01 s of the straight-running tests' command: 2 × 2.69 N from the longitudinal
/// thrusters, the joints held straight.
fn cruise(sim: &mut Simulator, steps: usize) {
    let zero = [0.0; 8];
    let thrust = [0.0, 0.0, 2.69, 2.69, 0.0, 0.0, 0.0];
    let cmd = ActuatorCommand {
        thrust: &thrust,
        joint_ref: &zero,
        joint_rate_ref: &zero,
    };
    for _ in 0..steps {
        sim.step(0.01, &cmd).unwrap();
    }
}

/// A 0.02 rad/s yaw-rate disturbance about the straight body's centre (1.65 m ahead of the
/// base at the tail).
fn disturb_yaw(sim: &mut Simulator) {
    let mut st = sim.state().clone();
    st.base_twist[5] = 0.02;
    st.base_twist[1] = -0.02 * 1.65;
    sim.set_state(st).unwrap();
}

#[test]
fn lift_at_the_tail_slows_the_turn_onto_the_path_and_lift_at_every_body_narrows_the_gap() {
    // Adopted reading, Table III gains. Lift at the free trailing face (the tail, moving head
    // first) acts like a fin: the body becomes more directionally stable and resists the turns
    // the bending and the yaw law command, so Method 2 converges later (40.2 / 40.8 s →
    // 45.1 / 62.0 s; Method 1 26.2 / 28.7 s, unchanged on segment 0). The upper bound, lift at
    // every body's trailing face, speeds both up (Method 2 36.5 / 36.2 s) but Method 1 stays
    // ahead (22.1 / 18.6 s). (Hull drag, issue 44; the per-body drag gave 71.7 → 83.0 s.)
    let r = TransportReading::DEFAULT;
    let lift = |every: bool| {
        [
            ("hydro", "lift_slope", toml::Value::Float(2.0)),
            ("hydro", "lift_every_body", toml::Value::Boolean(every)),
        ]
    };
    let m2 = run_reading_with(r, TransportMethod::Method2, None, &lift(false)).unwrap();
    let m1 = run_reading_with(r, TransportMethod::Method1, None, &lift(false)).unwrap();
    assert_eq!(m2.lift_slope, 2.0);
    assert!((m2.get("seg0_convergence_time") - 45.1).abs() < 1e-9);
    assert!((m2.get("seg1_convergence_time") - 62.0).abs() < 1e-9);
    assert!(m1.converged() && m1.get("seg0_convergence_time") >= 26.2 - 1e-9);
    let e2 = run_reading_with(r, TransportMethod::Method2, None, &lift(true)).unwrap();
    let e1 = run_reading_with(r, TransportMethod::Method1, None, &lift(true)).unwrap();
    assert!(e1.converged() && e2.converged());
    assert!((e2.get("seg0_convergence_time") - 36.5).abs() < 1e-9);
    assert!((e2.get("seg1_convergence_time") - 36.2).abs() < 1e-9);
    for k in ["seg0_convergence_time", "seg1_convergence_time"] {
        assert!(e1.get(k) < e2.get(k), "{k}");
    }
}

/// The paper design with every cylinder's lift slope set to `lift` (docs/model.md §2 "Lift").
fn paper_with_lift(lift: f64) -> usm_study::model::Vehicle {
    let mut v = usm_paper();
    for b in &mut v.bodies {
        if let Hydro::Cylinder { lift_slope, .. } = &mut b.hydro {
            *lift_slope = lift;
        }
    }
    v
}

/// The straight vehicle of the test above at 0.5 m/s, given the yaw-rate disturbance about
/// its centre, after `steps` × 0.01 s: (surge before the disturbance, yaw rate, sway at the
/// base).
fn disturbed(lift: f64, steps: usize) -> (f64, f64, f64) {
    let v = paper_with_lift(lift);
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    cruise(&mut sim, 6000);
    let u = sim.state().base_twist[0];
    disturb_yaw(&mut sim);
    cruise(&mut sim, steps);
    let s = sim.state();
    (u, s.base_twist[5], s.base_twist[1])
}

#[test]
fn lift_leaves_straight_running_alone_and_weakens_the_munk_instability() {
    // Straight running has no incidence, so lift is exactly zero: the same drag-balance speed
    // to the last bit.
    let (u0, r0, _) = disturbed(0.0, 3000);
    let (u2, r2, _) = disturbed(2.0, 3000);
    assert_eq!(u0, u2);
    // With lift at the free trailing face (the tail, moving head first), the net potential
    // load of slender-body theory sits at the nose instead of the Munk couple: half the
    // destabilising moment, and a side force that opposes the tail's sideslip. The bare body
    // still turns (the nose load is ahead of the centre), but more slowly (under the hull drag
    // 0.0007 rad/s against 0.049 after 30 s).
    assert!(r0 > 0.04 && r0 < 0.06, "without lift {r0}");
    assert!(r2 > 0.0 && r2 < 0.8 * r0, "with lift {r2} (without {r0})");
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

//! Simulation with actuators: joint servos, thruster models, thrust direction and the
//! energy balance.

use super::*;

#[test]
fn second_order_servo_follows_the_filter() {
    // Ideal servos: the joints obey q̈ = ω²(q_r − q) − 2ζωq̇ whatever the base does; critically
    // damped from rest: q(t) = q_r (1 − (1 + ωt) e^{−ωt}). RK4 at dt = 1 ms: error ~1e-12.
    let v = usm_paper();
    let (w, zt) = (4.0, 1.0);
    let mut sim = Simulator::new(
        &v,
        SimConfig {
            servo: ServoModel::SecondOrder {
                omega_n: w,
                zeta: zt,
            },
            ..SimConfig::default()
        },
    )
    .unwrap();
    let qr: Vec<f64> = (0..8).map(|k| 0.1 * (k as f64 - 3.5)).collect();
    let zero = vec![0.0; 8];
    let u = vec![0.0; 7];
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &qr,
        joint_rate_ref: &zero,
    };
    for _ in 0..1500 {
        sim.step(1e-3, &cmd).unwrap();
    }
    let t = sim.time();
    for (k, qr_k) in qr.iter().enumerate() {
        let expect = qr_k * (1.0 - (1.0 + w * t) * (-w * t).exp());
        assert!((sim.state().joint_angles[k] - expect).abs() < 1e-9);
    }
    // The base reacts to the bending (momentum exchange) and the servos work for it.
    assert!(sim.state().base_twist.norm() > 1e-4);
    assert!(sim.last_joint_torque().iter().any(|t| t.abs() > 1e-3));
}

#[test]
fn pd_servo_torques_are_saturated() {
    // Torque-level PD in full forward dynamics, hydrodynamics without restoring forces (the
    // toy's buoyancy offsets would need more than the 2 N·m limit to hold).
    let v = toy(3);
    let lim = 2.0;
    let mut sim = Simulator::new(
        &v,
        SimConfig {
            servo: ServoModel::TorquePd {
                kp: 500.0,
                kd: 20.0,
                torque_limit: lim,
            },
            options: DynOptions {
                restoring: false,
                current: false,
                ..DynOptions::full()
            },
            thruster: ThrusterModel::Ideal,
            ..SimConfig::default()
        },
    )
    .unwrap();
    let qr = vec![1.0, -1.0];
    let zero = vec![0.0; 2];
    let u = vec![0.0; 3];
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &qr,
        joint_rate_ref: &zero,
    };
    let mut saturated = false;
    for _ in 0..3000 {
        sim.step(1e-3, &cmd).unwrap();
        for t in sim.last_joint_torque() {
            assert!(t.abs() <= lim);
            saturated |= t.abs() == lim;
        }
    }
    assert!(saturated);
    // After 3 s the joints have moved well towards the references.
    let qs = &sim.state().joint_angles;
    assert!(qs[0] > 0.3 && qs[1] < -0.3, "{qs:?}");
}

#[test]
fn thruster_models_saturate_lag_and_rate_limit() {
    // Command 100 N on ±30 N thrusters: every model's actual thrust stays within ±30 N.
    // Lag (T = 0.1 s): u(t) = 30(1 − e^{−t/T}); rate limit 100 N/s: u(t) = min(100 t, 30).
    // The thrust states are the exact flows, so 1e-12 is rounding.
    let v = toy(1);
    let dt = 1e-3;
    type Expected = fn(f64) -> f64;
    let cases: [(ThrusterModel, Expected); 3] = [
        (ThrusterModel::Ideal, |_t| 30.0),
        (
            ThrusterModel::FirstOrder {
                time_constant: None,
            },
            |t| 30.0 * (1.0 - (-t / 0.1).exp()),
        ),
        (
            ThrusterModel::RateLimited {
                rate_limit: Some(50.0),
            },
            |t| (50.0 * t).min(30.0),
        ),
    ];
    for (model, f) in cases {
        let mut sim = Simulator::new(
            &v,
            SimConfig {
                options: DynOptions::rigid(),
                servo: ServoModel::Passive,
                thruster: model,
                ..SimConfig::default()
            },
        )
        .unwrap();
        let cmd = ActuatorCommand {
            thrust: &[100.0],
            joint_ref: &[],
            joint_rate_ref: &[],
        };
        for _ in 0..1000 {
            sim.step(dt, &cmd).unwrap();
            let t = sim.time();
            assert!(sim.last_thrust()[0] <= 30.0);
            // last_thrust is at the start of the step: t − dt.
            assert!(
                (sim.last_thrust()[0] - f(t - dt)).abs() < 1e-12,
                "{model:?} at {t}"
            );
            assert!((sim.state().thrust[0] - f(t)).abs() < 1e-12);
        }
    }
}

#[test]
fn lag_and_rate_limit_combined_is_a_flow() {
    // The exact solution has the semigroup property φ(s₁+s₂) = φ(s₂)∘φ(s₁): checks the
    // switch from the ramp to the exponential. Rounding only: 1e-12.
    let v = toy(1);
    let mut sim = Simulator::new(
        &v,
        SimConfig {
            options: DynOptions::rigid(),
            servo: ServoModel::Passive,
            thruster: ThrusterModel::FromModel, // T = 0.1 s, 100 N/s from the model
            ..SimConfig::default()
        },
    )
    .unwrap();
    let cmd = ActuatorCommand {
        thrust: &[25.0],
        joint_ref: &[],
        joint_rate_ref: &[],
    };
    let mut trace = Vec::new();
    for _ in 0..400 {
        sim.step(1e-3, &cmd).unwrap();
        trace.push(sim.state().thrust[0]);
    }
    // Ramp at 100 N/s until |e| = rT = 10 N (t = 0.15 s), then the lag.
    assert!((trace[99] - 10.0).abs() < 1e-12);
    let expect = 25.0 - 10.0 * (-(0.4 - 0.15) / 0.1f64).exp();
    assert!(
        (trace[399] - expect).abs() < 1e-12,
        "{} vs {expect}",
        trace[399]
    );
    let rates: Vec<f64> = trace.windows(2).map(|w| (w[1] - w[0]) / 1e-3).collect();
    assert!(rates.iter().all(|r| *r <= 100.0 + 1e-6));
}

#[test]
fn thrust_moves_the_vehicle_in_its_direction() {
    // A thruster at body 0 pushing along (0.6, 0.8, 0) from rest, rigid, no rotation yet:
    // the initial acceleration is M⁻¹ J_g,0ᵀ F, checked against forward dynamics directly.
    let v = toy(2);
    let mut sim = Simulator::new(
        &v,
        SimConfig {
            options: DynOptions::rigid(),
            servo: ServoModel::Passive,
            thruster: ThrusterModel::Ideal,
            ..SimConfig::default()
        },
    )
    .unwrap();
    let cmd = ActuatorCommand {
        thrust: &[10.0, 0.0],
        joint_ref: &[0.0],
        joint_rate_ref: &[0.0],
    };
    sim.step(1e-3, &cmd).unwrap();
    let mut ws = DynWorkspace::new(&v);
    let mut kin = KinWorkspace::new(&v);
    forward_kinematics(&v, &[0.0], &mut kin);
    let mut map = Mat::<f64>::zeros(v.n_dof(), 2);
    crate::kinematics::generalized_thrust_map(&v, &kin, &mut map);
    let tau: Vec<f64> = (0..v.n_dof()).map(|r| map[(r, 0)] * 10.0).collect();
    let st = SimState::rest(&v);
    forward_dynamics(
        &v,
        &mut ws,
        &st.pose,
        &st.joint_angles,
        &st.zeta(),
        &tau,
        &DynOptions::rigid(),
    )
    .unwrap();
    for r in 0..v.n_dof() {
        // Same arithmetic on the same inputs.
        assert!((sim.last_acceleration()[r] - ws.zeta_dot[r]).abs() < 1e-12);
    }
}

#[test]
fn usm_paper_at_rest_has_zero_bias() {
    // Neutrally buoyant with CG = CB (docs/model.md §2): at rest in still water nothing acts.
    // Weight and buoyancy differ by rounding only (ρ·(m/ρ) vs m): 1e-12 N.
    let v = usm_paper();
    let mut ws = DynWorkspace::new(&v);
    let mut rng = ChaCha8Rng::seed_from_u64(30);
    let s = sample(&v, &mut rng, 0.0);
    bias(&v, &mut ws, &s.pose, &s.q, &s.zeta, &DynOptions::full());
    assert!(ws.bias.iter().all(|h| h.abs() < 1e-12), "{:?}", ws.bias);
}

#[test]
fn simulated_energy_balance() {
    // Whole-system power balance with added mass, drag, restoring forces and constant thrust
    // (passive joints, still water): d/dt (½ζᵀMζ + U) = ζᵀ(Q_thrust + Q_damp), where U is
    // the hydrostatic potential energy. ΔE over 2 s against the trapezoidal integral of the
    // power sampled every 1 ms: the quadrature error O(dt²) ≈ 1e-6 relative dominates RK4's
    // O(dt⁴); tolerance 1e-4 of ∫|P| dt.
    let v = toy(3);
    let opts = DynOptions {
        current: false,
        ..DynOptions::full()
    };
    let mut sim = passive_sim(&v, opts);
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let s = sample(&v, &mut rng, 0.5);
    let mut st = sim.state().clone();
    st.pose = s.pose;
    st.joint_angles = s.q.clone();
    st.set_zeta(&s.zeta);
    sim.set_state(st).unwrap();
    let thrust = [12.0, -8.0, 5.0];
    let z = [0.0; 2];
    let cmd = ActuatorCommand {
        thrust: &thrust,
        joint_ref: &z,
        joint_rate_ref: &z,
    };
    let nv = v.n_dof();
    let mut ws = DynWorkspace::new(&v);
    let mut kin = KinWorkspace::new(&v);
    let mut map = Mat::<f64>::zeros(nv, 3);
    let mut qd = vec![0.0; nv];
    let mut power = |sim: &Simulator| -> f64 {
        let st = sim.state();
        let zeta = st.zeta();
        forward_kinematics(&v, &st.joint_angles, &mut kin);
        crate::kinematics::generalized_thrust_map(&v, &kin, &mut map);
        damping_generalized(
            &v,
            &mut ws,
            &st.pose,
            &st.joint_angles,
            &zeta,
            &opts,
            &mut qd,
        );
        (0..nv)
            .map(|r| zeta[r] * (qd[r] + (0..3).map(|j| map[(r, j)] * thrust[j]).sum::<f64>()))
            .sum()
    };
    let energy = |sim: &mut Simulator| -> f64 {
        let st = sim.state().clone();
        sim.kinetic_energy() + potential_energy(&v, &st.pose, &st.joint_angles)
    };
    let e0 = energy(&mut sim);
    let (mut work, mut abs_work) = (0.0, 0.0);
    let mut p0 = power(&sim);
    let dt = 1e-3;
    for _ in 0..2000 {
        sim.step(dt, &cmd).unwrap();
        let p1 = power(&sim);
        work += 0.5 * dt * (p0 + p1);
        abs_work += 0.5 * dt * (p0.abs() + p1.abs());
        p0 = p1;
    }
    let de = energy(&mut sim) - e0;
    assert!(abs_work > 1.0, "the test exercises real work: {abs_work}");
    assert!(
        (de - work).abs() < 1e-4 * abs_work,
        "ΔE = {de}, ∫P = {work}"
    );
}

//! Simulation: conservation laws and closed-form motions (free motion, drag, uniform
//! current, buoyancy).

use super::*;

fn zero_cmd_buffers(v: &Vehicle) -> (Vec<f64>, Vec<f64>) {
    (vec![0.0; v.n_thrusters()], vec![0.0; v.n_joints()])
}

/// RK4 at 1 ms, the fixed step the conservation bounds below were set for.
const RK4_1MS: Integrator = Integrator::Rk4 { dt: 1e-3 };

/// Run 100 s (in 1 s spans of `integrator`) from a random nonzero ζ, torque-free, and return
/// the largest relative drift of kinetic energy and of the inertial spatial momentum, checked
/// every second. Passive joints do no work: that is asserted too.
pub(super) fn conservation_drift(
    v: &Vehicle,
    options: DynOptions,
    integrator: Integrator,
    seed: u64,
) -> (f64, f64) {
    let mut sim = Simulator::new(
        v,
        SimConfig {
            options,
            servo: ServoModel::Passive,
            thruster: ThrusterModel::Ideal,
            integrator,
        },
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let s = sample(v, &mut rng, 0.3);
    let mut st = sim.state().clone();
    st.pose = s.pose;
    st.joint_angles = s.q.iter().map(|q| 0.5 * q).collect();
    st.set_zeta(&s.zeta);
    sim.set_state(st).unwrap();
    let e0 = sim.kinetic_energy();
    let p0 = sim.spatial_momentum();
    let (u, z) = zero_cmd_buffers(v);
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &z,
        joint_rate_ref: &z,
    };
    let (mut de, mut dp) = (0.0f64, 0.0f64);
    for _ in 0..100 {
        sim.advance(1.0, &cmd).unwrap();
        de = de.max((sim.kinetic_energy() - e0).abs() / e0);
        dp = dp.max((sim.spatial_momentum() - p0).norm() / p0.norm());
    }
    assert!((sim.time() - 100.0).abs() < 1e-9);
    assert_eq!(sim.joint_work(), 0.0);
    (de, dp)
}

#[test]
fn rigid_free_motion_conserves_energy_and_momentum() {
    // docs/model.md §4 invariant, vacuum. RK4 at dt = 1 ms on motions of ~1 rad/s: local error
    // ~(ω dt)⁵ ≈ 1e-15 per step, so 1e5 steps stay far below the required 1e-6.
    for v in [usm_paper(), toy(3)] {
        let (de, dp) = conservation_drift(&v, DynOptions::rigid(), RK4_1MS, 11);
        assert!(
            de < 1e-6 && dp < 1e-6,
            "{}: energy {de:e}, momentum {dp:e}",
            v.name
        );
    }
}

#[test]
fn added_mass_free_motion_conserves_energy_and_momentum() {
    // Added mass, no drag/current/restoring: the Kirchhoff system is still Lagrangian with
    // kinetic energy ½ζᵀMζ and conserved impulse Σ Ad⁻ᵀ(I_RB + M_A)V_i. Same bound.
    let opts = DynOptions {
        added_mass: true,
        ..DynOptions::rigid()
    };
    for v in [usm_paper(), toy(3)] {
        let (de, dp) = conservation_drift(&v, opts, RK4_1MS, 12);
        assert!(
            de < 1e-6 && dp < 1e-6,
            "{}: energy {de:e}, momentum {dp:e}",
            v.name
        );
    }
}

#[test]
fn drag_never_increases_energy() {
    // Drag only: dE/dt = ζᵀQ_damp ≤ 0 with strict dissipation on every axis (linear damping
    // everywhere), and RK4's O(dt⁵) local error is far below the O(dt) decrease per step;
    // 1e-13 relative allows for rounding in evaluating E.
    let opts = DynOptions {
        drag: true,
        ..DynOptions::rigid()
    };
    for v in [usm_paper(), toy(3)] {
        let mut sim = passive_sim(&v, opts);
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let s = sample(&v, &mut rng, 1.0);
        let mut st = sim.state().clone();
        st.joint_angles = s.q.iter().map(|q| 0.5 * q).collect();
        st.set_zeta(&s.zeta);
        sim.set_state(st).unwrap();
        let (u, z) = zero_cmd_buffers(&v);
        let cmd = ActuatorCommand {
            thrust: &u,
            joint_ref: &z,
            joint_rate_ref: &z,
        };
        let mut e = sim.kinetic_energy();
        let e0 = e;
        for _ in 0..10_000 {
            sim.step(1e-3, &cmd).unwrap();
            let e1 = sim.kinetic_energy();
            assert!(e1 <= e * (1.0 + 1e-13), "energy rose at t = {}", sim.time());
            e = e1;
        }
        assert!(e < 0.9 * e0, "drag removed energy over 10 s");
    }
}

#[test]
fn uniform_current_is_a_moving_frame() {
    // Galilean invariance (docs/model.md §4 current model): in a constant irrotational current ν_c,
    // the motion started with V_b + [R_Ibᵀ ν_c; 0] is the current-free motion plus the drift
    // ν_c t (same orientation, joints and relative twist). This holds only if the added-mass
    // force uses V̇_r = V̇ + [ω × v_c; 0]; dropping that term makes this test fail (checked).
    // Both runs use RK4 at dt = 1 ms on different (but equivalent) coordinates: their
    // discretisation errors differ at O(dt⁴) ≈ 1e-12 per unit time; 1e-8 over 3 s.
    let opts = DynOptions::full();
    let base = toy(3);
    let drifting = with_current(base.clone());
    let nu = drifting.fluid.current;
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let s = sample(&base, &mut rng, 0.8);
    let (u, z) = zero_cmd_buffers(&base);
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &z,
        joint_rate_ref: &z,
    };
    let mut a = passive_sim(&base, opts);
    let mut b = passive_sim(&drifting, opts);
    let mut st = a.state().clone();
    st.pose = s.pose;
    st.joint_angles = s.q.clone();
    st.set_zeta(&s.zeta);
    a.set_state(st.clone()).unwrap();
    let vc = s.pose.orientation.inverse() * nu;
    st.base_twist += stack(&vc, &Vec3::zeros());
    b.set_state(st).unwrap();
    for _ in 0..3000 {
        a.step(1e-3, &cmd).unwrap();
        b.step(1e-3, &cmd).unwrap();
    }
    let (sa, sb) = (a.state(), b.state());
    let t = a.time();
    assert!((sb.pose.position - (sa.pose.position + nu * t)).norm() < 1e-8);
    assert!(sa.pose.orientation.angle_to(&sb.pose.orientation) < 1e-8);
    for k in 0..base.n_joints() {
        assert!((sa.joint_angles[k] - sb.joint_angles[k]).abs() < 1e-8);
        assert!((sa.joint_rates[k] - sb.joint_rates[k]).abs() < 1e-8);
    }
    let vc = sb.pose.orientation.inverse() * nu;
    assert!((sb.base_twist - stack(&vc, &Vec3::zeros()) - sa.base_twist).norm() < 1e-8);
    // And the motion is not trivial: the current-free body moved and turned.
    assert!(sa.base_twist.norm() > 1e-3);
}

/// One cylinder body, `volume_factor` × (m/ρ) displaced volume, x axis pointing up.
fn single_body(volume_factor: f64) -> Vehicle {
    let mut v = toy(1);
    let b = &mut v.bodies[0];
    *b = Body::cylinder("float", 10.0, 0.5, 0.1, Hydro::cylinder(0.8, 1.0));
    b.volume = volume_factor * b.mass / v.fluid.rho;
    v.base = Se3::identity();
    v.thrusters.clear();
    v
}

fn upright_state(v: &Vehicle) -> SimState {
    let mut st = SimState::rest(v);
    // R e_x = e_z: rotate by −π/2 about y.
    st.pose.orientation =
        UnitQuaternion::from_axis_angle(&nalgebra::Vector3::y_axis(), -std::f64::consts::FRAC_PI_2);
    st
}

#[test]
fn neutrally_buoyant_body_at_rest_stays_at_rest() {
    // Weight and buoyancy cancel to rounding (ρ·(m/ρ) = m ± 1 ulp); CG = CB. After 10 s the
    // twist stays below 1e-12 (forces of 1e-14 N on 10 kg).
    let v = single_body(1.0);
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    sim.set_state(upright_state(&v)).unwrap();
    let cmd = ActuatorCommand {
        thrust: &[],
        joint_ref: &[],
        joint_rate_ref: &[],
    };
    for _ in 0..10_000 {
        sim.step(1e-3, &cmd).unwrap();
    }
    assert!(sim.state().base_twist.norm() < 1e-12);
    assert!(sim.state().pose.position.norm() < 1e-11);
}

fn rise(v: &Vehicle, options: DynOptions, seconds: f64) -> SimState {
    let mut sim = Simulator::new(
        v,
        SimConfig {
            options,
            ..SimConfig::default()
        },
    )
    .unwrap();
    sim.set_state(upright_state(v)).unwrap();
    let cmd = ActuatorCommand {
        thrust: &[],
        joint_ref: &[],
        joint_rate_ref: &[],
    };
    for _ in 0..(seconds * 1000.0).round() as usize {
        sim.step(1e-3, &cmd).unwrap();
    }
    sim.state().clone()
}

#[test]
fn buoyant_body_rises_at_terminal_speed() {
    // Net buoyancy F = (ρV − m)g along body x (pointing up) is balanced at terminal speed u
    // by axial drag a u² (a = ½ρ C_d,x πr²) plus linear damping d u (d = linear_damping[0]):
    // u = (−d + √(d² + 4aF)) / 2a. The approach is exponential with time constant
    // m/(2au + d) ≈ 0.25 s, so after 20 s it is converged far beyond the 1 % asked.
    //
    // Added mass is off here: with CG = CB the upright body has neutral static stability,
    // and the Munk moment (M_A22 − M_A11) u² sin θ cos θ of a slender body in axial motion
    // turns it broadside from a rounding-level tilt (checked below) — real physics, but not
    // the terminal-speed balance this test is about (which does not involve M_A).
    let v = single_body(1.3);
    let opts = DynOptions {
        added_mass: false,
        ..DynOptions::full()
    };
    let st = rise(&v, opts, 20.0);
    let b = &v.bodies[0];
    let rho = v.fluid.rho;
    let f = (rho * b.volume - b.mass) * v.fluid.g;
    let a = 0.5 * rho * 0.8 * std::f64::consts::PI * b.radius * b.radius;
    let d = 1.0;
    let u = (-d + (d * d + 4.0 * a * f).sqrt()) / (2.0 * a);
    assert!(
        (st.base_twist[0] - u).abs() < 0.01 * u,
        "{} vs {u}",
        st.base_twist[0]
    );
    // Straight up, no sideways motion or rotation (everything is on the axis).
    assert!(st.base_twist.fixed_rows::<5>(1).norm() < 1e-9);
    assert!(st.pose.position.z > 10.0 * u);

    // With added mass the same rise is unstable: the body ends up (nearly) horizontal.
    let st = rise(&v, DynOptions::full(), 20.0);
    let axis = st.pose.orientation * Vec3::x();
    assert!(
        axis.z.abs() < 0.5,
        "Munk moment should tip it over: axis {axis:?}"
    );
}

//! Errors: NaN and overflowing states, a singular mass matrix, bad configurations.

use super::*;

#[test]
fn nan_state_is_reported_not_propagated() {
    let v = usm_paper();
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    let u = vec![0.0; 7];
    let z = vec![0.0; 8];
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &z,
        joint_rate_ref: &z,
    };
    for _ in 0..10 {
        sim.step(1e-3, &cmd).unwrap();
    }
    let mut st = sim.state().clone();
    st.joint_rates[3] = f64::NAN;
    sim.set_state(st.clone()).unwrap();
    let err = sim.step(1e-3, &cmd).unwrap_err();
    assert_eq!(err.quantity, "joint_rates[3]");
    assert_eq!(err.message, "is NaN");
    assert!((err.time - 0.01).abs() < 1e-12);
    assert!(err
        .to_string()
        .contains("joint_rates[3] is NaN at t = 0.010"));
    // The state is untouched.
    assert!(sim.state().joint_rates[3].is_nan());
    // A bad command is named too.
    let bad = vec![0.0, 0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0];
    st.joint_rates[3] = 0.0;
    sim.set_state(st).unwrap();
    let err = sim
        .step(
            1e-3,
            &ActuatorCommand {
                thrust: &bad,
                ..cmd
            },
        )
        .unwrap_err();
    assert_eq!(err.quantity, "command.thrust[2]");
    let err = sim.step(f64::NAN, &cmd).unwrap_err();
    assert_eq!(err.quantity, "dt");
    let err = sim
        .step(
            1e-3,
            &ActuatorCommand {
                thrust: &u[..3],
                ..cmd
            },
        )
        .unwrap_err();
    assert_eq!(err.quantity, "command.thrust");
}

#[test]
fn overflowing_state_is_reported() {
    // Joint rates of 1e160 rad/s make velocity products overflow to inf: an error naming a
    // quantity, never a panic or a silent NaN.
    let v = toy(3);
    let mut sim = passive_sim(&v, DynOptions::full());
    let mut st = sim.state().clone();
    st.joint_rates = vec![1e160, -1e160];
    sim.set_state(st).unwrap();
    let cmd = ActuatorCommand {
        thrust: &[0.0; 3],
        joint_ref: &[0.0; 2],
        joint_rate_ref: &[0.0; 2],
    };
    let err = sim.step(1e-3, &cmd).unwrap_err();
    assert!(!err.quantity.is_empty() && err.time >= 0.0, "{err}");
}

#[test]
fn singular_mass_matrix_is_an_error() {
    // A massless, inertia-free last body without added mass makes its joint column of M
    // zero: M is singular. The validated Simulator refuses the vehicle; the free functions
    // report the singular M.
    let mut v = toy(2);
    v.bodies[1].hydro = Hydro::cylinder(0.5, 1.0);
    v.bodies[1].mass = 0.0;
    v.bodies[1].inertia = Mat3::zeros();
    v.bodies[1].hydro = Hydro::Coefficients {
        added_mass: Mat6::zeros(),
        linear: Mat6::zeros(),
        quadratic: Mat6::zeros(),
    };
    let err = Simulator::new(&v, SimConfig::default()).unwrap_err();
    assert_eq!(err.quantity, "vehicle.body[1].mass");
    let mut ws = DynWorkspace::new(&v);
    let st = SimState::rest(&v);
    let tau = vec![0.0; v.n_dof()];
    let err = forward_dynamics(
        &v,
        &mut ws,
        &st.pose,
        &st.joint_angles,
        &st.zeta(),
        &tau,
        &DynOptions::full(),
    )
    .unwrap_err();
    assert_eq!(err.quantity, "mass_matrix");
    let rep = inspect_dynamics(&v, &st, &tau, &DynOptions::full());
    assert!(rep.is_err());
}

#[test]
fn bad_configuration_is_rejected() {
    let v = toy(2);
    let err = Simulator::new(
        &v,
        SimConfig {
            servo: ServoModel::SecondOrder {
                omega_n: -1.0,
                zeta: 1.0,
            },
            ..SimConfig::default()
        },
    )
    .unwrap_err();
    assert_eq!(err.quantity, "config.servo.omega_n");
    let err = Simulator::new(
        &v,
        SimConfig {
            thruster: ThrusterModel::FirstOrder {
                time_constant: Some(f64::NAN),
            },
            ..SimConfig::default()
        },
    )
    .unwrap_err();
    assert_eq!(err.quantity, "config.thruster.time_constant");
}

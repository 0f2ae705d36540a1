//! Inspect and controller hooks; the unit quaternion.

use super::*;

#[test]
fn inspect_report_is_consistent() {
    let v = usm_paper();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let s = sample(&v, &mut rng, 0.5);
    let mut st = SimState::rest(&v);
    st.pose = s.pose;
    st.joint_angles = s.q.clone();
    st.set_zeta(&s.zeta);
    let tau: Vec<f64> = (0..v.n_dof()).map(|i| i as f64 - 5.0).collect();
    let rep = inspect_dynamics(&v, &st, &tau, &DynOptions::full()).unwrap();
    let json = serde_json::to_value(&rep).unwrap();
    for key in ["mass_matrix", "bias", "acceleration", "kinetic_energy"] {
        assert!(json.get(key).is_some(), "{key}");
    }
    let mut ws = DynWorkspace::new(&v);
    forward_dynamics(
        &v,
        &mut ws,
        &s.pose,
        &s.q,
        &s.zeta,
        &tau,
        &DynOptions::full(),
    )
    .unwrap();
    assert_eq!(rep.acceleration, ws.zeta_dot);
    let ke = kinetic_energy(&v, &mut ws, &s.q, &s.zeta, &DynOptions::full());
    // Two summation orders: 1e-12 relative.
    assert!((rep.kinetic_energy - ke).abs() < 1e-12 * ke);
    assert!(rep.mass_matrix_condition > 1.0 && rep.mass_matrix_condition.is_finite());
    // Rigid inspect: lighter than with added mass.
    let rigid = inspect_dynamics(&v, &st, &tau, &DynOptions::rigid()).unwrap();
    assert!(rigid.mass_matrix[1][1] < rep.mass_matrix[1][1]);
    assert!((rigid.mass_matrix[0][0] - 81.3).abs() < 1e-9);
}

#[test]
fn base_control_terms_are_the_upper_blocks() {
    let v = usm_paper();
    let mut sim = Simulator::new(&v, SimConfig::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let s = sample(&v, &mut rng, 0.5);
    let mut st = sim.state().clone();
    st.pose = s.pose;
    st.joint_angles = s.q.clone();
    st.set_zeta(&s.zeta);
    sim.set_state(st).unwrap();
    let (m11, h1) = sim.base_control_terms().unwrap();
    let mut ws = DynWorkspace::new(&v);
    dynamics_terms(&v, &mut ws, &s.pose, &s.q, &s.zeta, &DynOptions::full());
    for r in 0..6 {
        assert_eq!(h1[r], ws.bias[r]);
        for c in 0..6 {
            assert_eq!(m11[(r, c)], ws.mass[(r, c)]);
        }
    }
}

#[test]
fn quaternion_stays_unit() {
    // Renormalised each step: unit to rounding (1e-15) after 5000 steps of tumbling.
    let v = toy(2);
    let mut sim = passive_sim(&v, DynOptions::rigid());
    let mut st = sim.state().clone();
    st.base_twist = Vec6::new(0.1, 0.0, 0.0, 1.0, -2.0, 3.0);
    sim.set_state(st).unwrap();
    let cmd = ActuatorCommand {
        thrust: &[0.0, 0.0],
        joint_ref: &[0.0],
        joint_rate_ref: &[0.0],
    };
    for _ in 0..5000 {
        sim.step(1e-3, &cmd).unwrap();
    }
    assert!((sim.state().pose.orientation.quaternion().norm() - 1.0).abs() < 1e-15);
}

//! Tests of the substeps (`ocp::substeps`, docs/ocp.md §2 "Substeps") and of the grid
//! fidelity (`ocp::fidelity`, §4 eq. (F1)–(F4)).
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::fidelity::grid_fidelity;
use super::model::{central_jacobians, second_difference_hessian, OcpModel};
use super::tests_derivatives::{random_point, rel_diff};
use crate::dynamics::DynOptions;
use crate::kinematics::BasePose;
use crate::model::design::load_design;
use crate::spatial::Vec3;
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// usm-paper with the full hydrodynamics, a current and thruster actuation, Δt [s].
fn paper(dt: f64) -> ChainModel {
    let mut v = load_design("usm-paper").unwrap();
    v.fluid.current = Vec3::new(0.2, -0.1, 0.05);
    ChainModel::new(v, DynOptions::full(), dt, Vec3::zeros()).with_thrusters()
}

#[test]
fn substeps_compose_plain_steps_and_their_derivatives_follow_the_chain_rule() {
    let s = 4;
    let mut m = paper(0.2).with_substeps(s);
    let mut plain = paper(0.2 / s as f64);
    let mut rng = ChaCha8Rng::seed_from_u64(40);
    let (nx, nu) = (m.nx(), m.nu());
    for trial in 0..2 {
        let (x, u) = random_point(&m, &mut rng);
        // (S0) the composite step is S plain steps of h, bit for bit.
        let mut out = vec![0.0; m.nq()];
        m.step(&x, &u, &mut out).unwrap();
        let mut cur = x.clone();
        let mut next = vec![0.0; m.nq()];
        for _ in 0..s {
            plain.step(&cur, &u, &mut next).unwrap();
            std::mem::swap(&mut cur, &mut next);
        }
        assert_eq!(out, cur, "#{trial}: composite step");
        // (S1) against the central differences of the composite step.
        let (mut a, mut b) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
        let (mut a0, mut b0) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
        m.jacobians(&x, &u, &mut a, &mut b).unwrap();
        central_jacobians(&mut m, &x, &u, &mut a0, &mut b0).unwrap();
        let (ea, eb) = (rel_diff(&a, &a0), rel_diff(&b, &b0));
        assert!(ea <= 1e-6 && eb <= 1e-6, "#{trial}: A {ea:e}, B {eb:e}");
        // (S2) against the second differences of the composite step (both O(ε), ε = 1e-4).
        let w: Vec<f64> = (0..nx).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut h = DMatrix::zeros(nx + nu, nx + nu);
        let mut h0 = DMatrix::zeros(nx + nu, nx + nu);
        m.weighted_hessian(&x, &u, &w, &mut h).unwrap();
        second_difference_hessian(&mut m, &x, &u, &w, &mut h0).unwrap();
        let eh = rel_diff(&h, &h0);
        assert!(eh <= 2e-3, "#{trial}: Hessian {eh:e}");
        assert!(h0.amax() > 1e-3, "#{trial}: a Hessian with curvature");
    }
    // One substep is the plain step.
    let mut one = paper(0.2).with_substeps(1);
    let mut p = paper(0.2);
    let (x, u) = random_point(&one, &mut rng);
    let (mut o1, mut o2) = (vec![0.0; one.nq()], vec![0.0; one.nq()]);
    one.step(&x, &u, &mut o1).unwrap();
    p.step(&x, &u, &mut o2).unwrap();
    assert_eq!(o1, o2);
}

/// An unactuated usm-paper in still water (no current, restoring forces off: nothing but the
/// water's added mass, drag and lift acts), swimming at 0.8 m/s with its joints swinging, for
/// `knots` intervals of 0.1 s with `substeps`: the knots are the model's own rollout.
fn coasting(substeps: usize, knots: usize) -> (ChainModel, Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let mut v = load_design("usm-paper").unwrap();
    v.fluid.current = Vec3::zeros();
    let opts = DynOptions {
        restoring: false,
        ..DynOptions::full()
    };
    let mut m = ChainModel::new(v, opts, 0.1, Vec3::zeros())
        .with_thrusters()
        .with_substeps(substeps);
    let n = m.n_joints();
    let qd: Vec<f64> = (0..n)
        .map(|i| if i % 2 == 0 { 0.6 } else { -0.4 })
        .collect();
    let x0 = ChainModel::pack(
        &BasePose::default(),
        &vec![0.1; n],
        &[0.8, 0.0, 0.0, 0.0, 0.0, 0.1],
        &qd,
    );
    let us = vec![vec![0.0; m.nu()]; knots];
    let mut xs = vec![x0];
    for k in 0..knots {
        let mut next = vec![0.0; m.nq()];
        m.step(&xs[k], &us[k], &mut next).unwrap();
        xs.push(next);
    }
    (m, xs, us)
}

#[test]
fn the_grid_defect_shrinks_with_substeps_and_still_water_only_takes_energy() {
    let (m1, xs1, us1) = coasting(1, 20);
    let f1 = grid_fidelity(&m1, &xs1, &us1, 10).unwrap();
    let (m8, xs8, us8) = coasting(8, 20);
    let f8 = grid_fidelity(&m8, &xs8, &us8, 10).unwrap();
    assert_eq!((f1.substeps, f1.refined_substeps), (1, 10));
    assert_eq!((f8.substeps, f8.refined_substeps), (8, 80));
    // First order: 8 substeps cut the local defect about 8 × (more than 4 × here).
    assert!(
        f8.relative_defect * 4.0 < f1.relative_defect,
        "defect {:e} (1 substep) vs {:e} (8)",
        f1.relative_defect,
        f8.relative_defect
    );
    assert!(f1.max_velocity_defect > 0.0 && f1.max_configuration_defect > 0.0);
    // Nothing pushes: the actuators do no work, the water takes energy (refined).
    for f in [&f1, &f8] {
        assert_eq!(f.actuator_work, 0.0);
        assert_eq!(f.actuator_work_refined, 0.0);
        assert!(f.other_work_refined < 0.0, "{f:?}");
    }
}

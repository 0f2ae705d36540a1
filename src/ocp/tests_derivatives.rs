//! Tests of the structured differences (`ocp::derivatives`): on random states and controls of
//! every preset (full hydrodynamics and a current, thruster actuation, and base-wrench
//! actuation) and of the rigid chain, the chain's Jacobians and weighted Hessian equal the
//! reference central and second differences of `ocp::model` to 1e-12 relative (they are the
//! same numbers, computed with the unchanged dynamics terms reused).
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::model::{central_jacobians, second_difference_hessian, OcpModel};
use crate::dynamics::DynOptions;
use crate::kinematics::BasePose;
use crate::model::design::load_design;
use crate::spatial::Vec3;
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A random state (pose anywhere, joints within ±0.6 rad, moderate velocities) and controls.
pub(super) fn random_point(m: &ChainModel, rng: &mut ChaCha8Rng) -> (Vec<f64>, Vec<f64>) {
    let n = m.n_joints();
    let mut r = |s: f64| rng.random_range(-s..s);
    let pose = BasePose {
        position: Vec3::new(r(2.0), r(2.0), r(2.0)),
        orientation: nalgebra::UnitQuaternion::from_euler_angles(r(3.0), r(1.4), r(3.0)),
    };
    let q: Vec<f64> = (0..n).map(|_| r(0.6)).collect();
    let qd: Vec<f64> = (0..n).map(|_| r(0.3)).collect();
    let twist: Vec<f64> = (0..6).map(|_| r(0.3)).collect();
    let u: Vec<f64> = (0..m.nu()).map(|_| r(2.0)).collect();
    (ChainModel::pack(&pose, &q, &twist, &qd), u)
}

/// `max |a − b| / max(1, max |b|)`.
pub(super) fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax().max(1.0)
}

fn check(name: &str, mut m: ChainModel, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (nx, nu) = (m.nx(), m.nu());
    for trial in 0..3 {
        let (x, u) = random_point(&m, &mut rng);
        let w: Vec<f64> = (0..nx).map(|_| rng.random_range(-1.0..1.0)).collect();
        let (mut a, mut b) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
        let (mut a0, mut b0) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
        m.jacobians(&x, &u, &mut a, &mut b).unwrap();
        central_jacobians(&mut m, &x, &u, &mut a0, &mut b0).unwrap();
        let (ea, eb) = (rel_diff(&a, &a0), rel_diff(&b, &b0));
        assert!(
            ea <= 1e-12 && eb <= 1e-12,
            "{name} #{trial}: A {ea:e}, B {eb:e}"
        );
        let mut h = DMatrix::zeros(nx + nu, nx + nu);
        let mut h0 = DMatrix::zeros(nx + nu, nx + nu);
        m.weighted_hessian(&x, &u, &w, &mut h).unwrap();
        second_difference_hessian(&mut m, &x, &u, &w, &mut h0).unwrap();
        let eh = rel_diff(&h, &h0);
        assert!(eh <= 1e-12, "{name} #{trial}: Hessian {eh:e}");
    }
}

#[test]
fn structured_differences_equal_the_reference_on_every_preset() {
    for (k, name) in crate::model::presets::PRESETS.iter().enumerate() {
        let mut v = load_design(name).unwrap();
        // A current, so that the pose enters h (restoring forces do already).
        v.fluid.current = Vec3::new(0.2, -0.1, 0.05);
        let m = ChainModel::new(v.clone(), DynOptions::full(), 0.05, Vec3::zeros());
        check(&format!("{name} base wrench"), m.clone(), 11 + k as u64);
        check(
            &format!("{name} thrusters"),
            m.with_thrusters(),
            21 + k as u64,
        );
        let rigid = ChainModel::new(v, DynOptions::rigid(), 0.05, Vec3::zeros());
        check(
            &format!("{name} rigid"),
            rigid.with_thrusters(),
            31 + k as u64,
        );
    }
}

#[test]
fn structured_differences_equal_the_reference_on_the_rigid_chain() {
    let v = load_design("studies/designs/rigid_chain5.toml").unwrap();
    let m = ChainModel::new(v, DynOptions::rigid(), 0.1, Vec3::new(2.884, 0.3, -0.2));
    check("rigid chain", m, 5);
}

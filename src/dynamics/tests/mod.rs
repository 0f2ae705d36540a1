//! Physics tests of the dynamics module (docs/model.md §4 invariants), on 1–3 body toy models built
//! here and on `usm-paper`.

use super::passes::inertia_to_parent;
use super::*;
use crate::kinematics::{body_jacobian, forward_kinematics, BasePose, KinWorkspace};
use crate::model::presets::usm_paper;
use crate::model::{Body, Fluid, Hydro, Joint, Thruster, Vehicle};
use crate::spatial::{cross_force, rot_axis_angle, skew, stack, Mat3, Mat6, Se3, Vec3, Vec6};
use faer::Mat;
use nalgebra::{DMatrix, DVector, UnitQuaternion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// ---------------------------------------------------------------------------------------
// Fixtures.

/// A chain of `nb` (1–3) bodies with everything that could hide a bug switched on: off-axis
/// centres of gravity and buoyancy, full rotational inertias, a base frame that is not body
/// 0's frame, joint placements with rotations, non-principal joint axes, and body 1 described
/// by coefficient matrices with a fully coupled added mass.
fn toy(nb: usize) -> Vehicle {
    let fluid = Fluid {
        rho: 1000.0,
        g: 9.81,
        current: Vec3::zeros(),
    };
    let mut bodies = Vec::new();
    for i in 0..nb {
        let l = 0.5 + 0.15 * i as f64;
        let mut b = Body::cylinder(
            &format!("b{i}"),
            6.0 + 2.0 * i as f64,
            l,
            0.08,
            Hydro::cylinder(0.6, 1.1),
        );
        b.cg = Vec3::new(0.45 * l, 0.01, -0.02);
        b.cb = Vec3::new(0.5 * l, -0.005, 0.01);
        b.volume *= 1.05;
        b.inertia += Mat3::new(0.0, 0.01, -0.005, 0.01, 0.0, 0.002, -0.005, 0.002, 0.0);
        if i == 1 {
            let a = Mat6::from_fn(|r, c| ((r * 7 + c * 3) % 5) as f64 * 0.3 - 0.5);
            let ma = a.transpose() * a * 0.8
                + Mat6::from_diagonal(&Vec6::new(2.0, 6.0, 6.0, 0.05, 0.3, 0.3));
            b.hydro = Hydro::Coefficients {
                added_mass: ma,
                linear: Mat6::from_diagonal(&Vec6::new(2.0, 4.0, 4.0, 0.1, 0.3, 0.3)),
                quadratic: Mat6::from_diagonal(&Vec6::new(5.0, 20.0, 20.0, 0.2, 1.0, 1.0)),
            };
        }
        bodies.push(b);
    }
    let axes = [Vec3::z(), Vec3::y(), Vec3::new(0.3, 0.5, 0.8).normalize()];
    let joints = (0..nb - 1)
        .map(|k| Joint {
            name: format!("j{k}"),
            placement: Se3::new(
                rot_axis_angle(&Vec3::new(1.0, 0.2, -0.4).normalize(), 0.3),
                Vec3::new(bodies[k].length, 0.02, -0.01),
            ),
            axis: axes[k],
            min: -1.5,
            max: 1.5,
        })
        .collect();
    let thrusters = (0..nb)
        .map(|i| Thruster {
            name: format!("t{i}"),
            body: i,
            position: Vec3::new(0.2, 0.05, 0.0),
            direction: Vec3::new(0.6, 0.8, 0.0),
            u_min: -30.0,
            u_max: 30.0,
            time_constant: Some(0.1),
            rate_limit: Some(100.0),
        })
        .collect();
    let v = Vehicle {
        name: format!("toy{nb}"),
        bodies,
        joints,
        thrusters,
        base: Se3::new(
            rot_axis_angle(&Vec3::new(0.2, -0.3, 1.0).normalize(), 0.4),
            Vec3::new(0.1, 0.02, -0.03),
        ),
        end_effector: Se3::identity(),
        fluid,
    };
    v.validate().unwrap();
    v
}

fn models() -> Vec<Vehicle> {
    vec![toy(1), toy(2), toy(3), usm_paper()]
}

struct Sample {
    pose: BasePose,
    q: Vec<f64>,
    zeta: Vec<f64>,
}

fn sample(v: &Vehicle, rng: &mut ChaCha8Rng, speed: f64) -> Sample {
    let axis = Vec3::new(rng.random(), rng.random(), rng.random()).normalize();
    let pose = BasePose {
        orientation: UnitQuaternion::from_scaled_axis(axis * rng.random_range(-3.0..3.0)),
        position: Vec3::new(rng.random(), rng.random(), rng.random()),
    };
    let q = v
        .joints
        .iter()
        .map(|j| rng.random_range(j.min..j.max))
        .collect();
    let zeta = (0..v.n_dof())
        .map(|_| speed * rng.random_range(-1.0..1.0))
        .collect();
    Sample { pose, q, zeta }
}

fn all_options() -> [DynOptions; 3] {
    [
        DynOptions::rigid(),
        DynOptions {
            added_mass: true,
            ..DynOptions::rigid()
        },
        DynOptions::full(),
    ]
}

fn with_current(mut v: Vehicle) -> Vehicle {
    v.fluid.current = Vec3::new(0.3, -0.2, 0.1);
    v
}

fn to_dmatrix(m: &Mat<f64>) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |r, c| m[(r, c)])
}

fn body_inertia(ws: &DynWorkspace, i: usize, opts: &DynOptions) -> Mat6 {
    if opts.added_mass {
        ws.i_rb[i] + ws.m_a[i]
    } else {
        ws.i_rb[i]
    }
}

/// All body Jacobians `J_g,i` (6×(6+n)) from the kinematics module.
fn jacobians(v: &Vehicle, q: &[f64]) -> Vec<DMatrix<f64>> {
    let mut kin = KinWorkspace::new(v);
    forward_kinematics(v, q, &mut kin);
    let mut j = Mat::<f64>::zeros(6, v.n_dof());
    (0..v.bodies.len())
        .map(|i| {
            body_jacobian(&kin, i, &mut j);
            to_dmatrix(&j)
        })
        .collect()
}

fn mat6_to_d(m: &Mat6) -> DMatrix<f64> {
    DMatrix::from_fn(6, 6, |r, c| m[(r, c)])
}

fn passive_sim(v: &Vehicle, options: DynOptions) -> Simulator {
    Simulator::new(
        v,
        SimConfig {
            options,
            servo: ServoModel::Passive,
            thruster: ThrusterModel::Ideal,
            ..SimConfig::default()
        },
    )
    .unwrap()
}

/// Hydrostatic potential energy `U = Σ_i (m_i g z_cg,i − ρ V_i g z_cb,i)` [J].
fn potential_energy(v: &Vehicle, pose: &BasePose, q: &[f64]) -> f64 {
    let mut kin = KinWorkspace::new(v);
    forward_kinematics(v, q, &mut kin);
    let g_ib = pose.to_se3();
    let g0 = v.fluid.g;
    v.bodies
        .iter()
        .zip(&kin.g_b)
        .map(|(b, g)| {
            let gi = g_ib.compose(g);
            b.mass * g0 * gi.act_point(&b.cg).z
                - v.fluid.rho * b.volume * g0 * gi.act_point(&b.cb).z
        })
        .sum()
}

mod aba;
mod actuators;
mod conservation;
mod equations;
mod errors;
mod inspect;
mod integrator;
mod kinematics_mass;

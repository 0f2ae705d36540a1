//! Physics tests of the dynamics module (SPEC §4 invariants), on 1–3 body toy models built
//! here and on `usm-paper`.

use super::algorithms::inertia_to_parent;
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

// ---------------------------------------------------------------------------------------
// Kinematics and mass matrix.

#[test]
fn position_pass_matches_kinematics() {
    // Same compositions in a different association order: a few ulps on O(1) numbers.
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for v in models() {
        let mut ws = DynWorkspace::new(&v);
        let mut kin = KinWorkspace::new(&v);
        for _ in 0..5 {
            let s = sample(&v, &mut rng, 1.0);
            mass_matrix(&v, &mut ws, &s.q, &DynOptions::rigid());
            forward_kinematics(&v, &s.q, &mut kin);
            for i in 0..v.bodies.len() {
                assert!((ws.kin.g_b[i].r - kin.g_b[i].r).norm() < 1e-12);
                assert!((ws.kin.g_b[i].p - kin.g_b[i].p).norm() < 1e-12);
            }
            for k in 0..v.n_joints() {
                assert!((ws.kin.joint_twist_b[k] - kin.joint_twist_b[k]).norm() < 1e-12);
            }
            assert!((ws.kin.g_be.p - kin.g_be.p).norm() < 1e-12);
        }
    }
}

#[test]
fn block_inertia_transform_matches_adjoint_form() {
    // Closed-form rearrangement of Ad⁻ᵀ I Ad⁻¹: agreement to rounding (1e-12 relative).
    let v = toy(2);
    let ws = DynWorkspace::new(&v);
    let g = Se3::new(
        rot_axis_angle(&Vec3::new(0.3, -0.4, 0.5).normalize(), 1.1),
        Vec3::new(0.7, -0.3, 1.2),
    );
    for i in [ws.i_rb[0], ws.m_a[1], ws.i_rb[1] + ws.m_a[1]] {
        let a = inertia_to_parent(&g, &i);
        let b = g.inertia_to_parent(&i);
        assert!((a - b).norm() < 1e-12 * b.norm(), "{}", (a - b).norm());
    }
}

#[test]
fn mass_matrix_is_spd_and_equals_jacobian_sum() {
    // M from the CRBA against the defining sum Σ J_g,iᵀ I_i J_g,i (USM-22) built from the
    // kinematics module's body Jacobians, and ½ζᵀMζ against Σ ½V_iᵀI_iV_i with V_i = J_g,i ζ.
    // Different summation orders of O(100) numbers: 1e-10 relative covers the rounding.
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for v in models() {
        let mut ws = DynWorkspace::new(&v);
        for opts in all_options() {
            for _ in 0..5 {
                let s = sample(&v, &mut rng, 1.0);
                mass_matrix(&v, &mut ws, &s.q, &opts);
                let m = to_dmatrix(&ws.mass);
                let scale = m.norm();
                assert_eq!(m, m.transpose(), "symmetric by construction");
                let eig = m.clone().symmetric_eigenvalues();
                assert!(eig.min() > 0.0, "positive definite: {}", eig.min());
                let js = jacobians(&v, &s.q);
                let mut direct = DMatrix::zeros(v.n_dof(), v.n_dof());
                let z = DVector::from_column_slice(&s.zeta);
                let mut ke_direct = 0.0;
                for (i, j) in js.iter().enumerate() {
                    let ii = mat6_to_d(&body_inertia(&ws, i, &opts));
                    direct += j.transpose() * &ii * j;
                    let vi = j * &z;
                    ke_direct += 0.5 * vi.dot(&(&ii * &vi));
                }
                assert!(
                    (&m - &direct).norm() < 1e-10 * scale,
                    "{}",
                    (&m - &direct).norm()
                );
                let ke = kinetic_energy(&v, &mut ws, &s.q, &s.zeta, &opts);
                assert!(
                    (ke - ke_direct).abs() < 1e-10 * ke_direct,
                    "{ke} vs {ke_direct}"
                );
            }
        }
    }
}

#[test]
fn usm_paper_straight_mass_matrix_values() {
    // Straight, rigid: the whole-body inertia M_11 about the tail has total mass 81.3 kg on
    // the translational diagonal (USM Table II) and first moment m x_c (no lateral offsets).
    let v = usm_paper();
    let mut ws = DynWorkspace::new(&v);
    mass_matrix(&v, &mut ws, &[0.0; 8], &DynOptions::rigid());
    for a in 0..3 {
        assert!((ws.mass[(a, a)] - 81.3).abs() < 1e-12);
    }
    // First moment: Σ m_i (x_i + l_i/2) — M_26 = m x_c (v_y from ω_z).
    let mut x0 = 0.0;
    let mut first = 0.0;
    for b in &v.bodies {
        first += b.mass * (x0 + b.length / 2.0);
        x0 += b.length;
    }
    assert!((ws.mass[(1, 5)] - first).abs() < 1e-10);
    assert!((ws.mass[(2, 4)] + first).abs() < 1e-10);
}

// ---------------------------------------------------------------------------------------
// Newton–Euler, inverse/forward/hybrid dynamics.

#[test]
fn inverse_dynamics_is_m_times_acceleration_plus_bias() {
    // RNEA with accelerations minus RNEA without = M ζ̇ (the RNEA and CRBA must agree on
    // the inertia, including added mass and the current's M_A ω × v_c term, which is
    // acceleration-independent). Rounding on O(100) N: 1e-9 absolute.
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for v in models().into_iter().map(with_current) {
        let mut ws = DynWorkspace::new(&v);
        let mut tau = vec![0.0; v.n_dof()];
        for opts in all_options() {
            let s = sample(&v, &mut rng, 1.0);
            let acc: Vec<f64> = (0..v.n_dof())
                .map(|_| rng.random_range(-2.0..2.0))
                .collect();
            inverse_dynamics(&v, &mut ws, &s.pose, &s.q, &s.zeta, &acc, &opts, &mut tau);
            dynamics_terms(&v, &mut ws, &s.pose, &s.q, &s.zeta, &opts);
            let m = to_dmatrix(&ws.mass);
            let expect =
                &m * DVector::from_column_slice(&acc) + DVector::from_column_slice(&ws.bias);
            for r in 0..v.n_dof() {
                assert!((tau[r] - expect[r]).abs() < 1e-9, "{} row {r}", v.name);
            }
        }
    }
}

#[test]
fn forward_of_inverse_dynamics_is_identity() {
    // FD(ID(ζ̇)) = ζ̇. The Cholesky solve of a matrix with condition ~1e3–1e4 on O(1)
    // accelerations loses at most 4 digits of 16: 1e-10 holds with margin.
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for v in models().into_iter().map(with_current) {
        let mut ws = DynWorkspace::new(&v);
        let mut tau = vec![0.0; v.n_dof()];
        for opts in all_options() {
            for _ in 0..5 {
                let s = sample(&v, &mut rng, 1.0);
                let acc: Vec<f64> = (0..v.n_dof())
                    .map(|_| rng.random_range(-2.0..2.0))
                    .collect();
                inverse_dynamics(&v, &mut ws, &s.pose, &s.q, &s.zeta, &acc, &opts, &mut tau);
                forward_dynamics(&v, &mut ws, &s.pose, &s.q, &s.zeta, &tau, &opts).unwrap();
                for (r, a) in acc.iter().enumerate() {
                    assert!((ws.zeta_dot[r] - a).abs() < 1e-10, "{}: {r}", v.name);
                }
            }
        }
    }
}

#[test]
fn hybrid_dynamics_satisfies_the_equations_of_motion() {
    // Hybrid: q̈ prescribed, base from M_11 V̇ = τ_b − M_12 q̈ − h_1, torques recovered. Then
    // ID(ζ̇) must equal Q_ext + [0; τ_q] in every row. Rounding: 1e-9 absolute on O(100).
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for v in models().into_iter().map(with_current) {
        let mut ws = DynWorkspace::new(&v);
        let n = v.n_joints();
        let mut tau = vec![0.0; v.n_dof()];
        let s = sample(&v, &mut rng, 1.0);
        let qdd: Vec<f64> = (0..n).map(|_| rng.random_range(-2.0..2.0)).collect();
        let q_ext: Vec<f64> = (0..v.n_dof())
            .map(|_| rng.random_range(-20.0..20.0))
            .collect();
        let opts = DynOptions::full();
        hybrid_dynamics(&v, &mut ws, &s.pose, &s.q, &s.zeta, &q_ext, &qdd, &opts).unwrap();
        let acc = ws.zeta_dot.clone();
        let torque = ws.joint_torque.clone();
        assert_eq!(&acc[6..], &qdd[..]);
        inverse_dynamics(&v, &mut ws, &s.pose, &s.q, &s.zeta, &acc, &opts, &mut tau);
        for r in 0..6 {
            assert!((tau[r] - q_ext[r]).abs() < 1e-9);
        }
        for k in 0..n {
            assert!((tau[6 + k] - q_ext[6 + k] - torque[k]).abs() < 1e-9);
        }
    }
}

/// `C(q,ζ)` built as a matrix with the skew-symmetric body factorisation
/// `C = Σ_i J_iᵀ (I_i J̇_i + C_i(V_i) J_i)`, `C_i(V) = [[0, −p̂], [−p̂, −ĥ]]`, `[p; h] = I_i V`
/// (Fossen's `C_RB`/`C_A` form: `C_i(V) V = V ×* (I_i V)` and `C_iᵀ = −C_i`), and
/// `J̇_i = Σ_k ∂J_i/∂q_k q̇_k` by central differences of the kinematics Jacobians.
fn c_matrix(v: &Vehicle, ws: &DynWorkspace, s: &Sample, opts: &DynOptions, h: f64) -> DMatrix<f64> {
    let n = v.n_joints();
    let qd = &s.zeta[6..];
    let shift = |sign: f64| -> Vec<f64> { (0..n).map(|k| s.q[k] + sign * h * qd[k]).collect() };
    let (jp, jm, j0) = (
        jacobians(v, &shift(1.0)),
        jacobians(v, &shift(-1.0)),
        jacobians(v, &s.q),
    );
    let z = DVector::from_column_slice(&s.zeta);
    let mut c = DMatrix::zeros(v.n_dof(), v.n_dof());
    for i in 0..v.bodies.len() {
        let ii = body_inertia(ws, i, opts);
        let jdot = (&jp[i] - &jm[i]) / (2.0 * h);
        let vi = &j0[i] * &z;
        let mom = ii * Vec6::from_column_slice(vi.as_slice());
        let (ph, hh) = (
            skew(&Vec3::new(mom[0], mom[1], mom[2])),
            skew(&Vec3::new(mom[3], mom[4], mom[5])),
        );
        let mut ci = Mat6::zeros();
        ci.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-ph));
        ci.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-ph));
        ci.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-hh));
        // Sanity of the factorisation: C_i V = V ×* (I V).
        let vv = Vec6::from_column_slice(vi.as_slice());
        assert!((ci * vv - cross_force(&vv, &mom)).norm() < 1e-12 * (1.0 + mom.norm()));
        let iid = mat6_to_d(&ii);
        c += j0[i].transpose() * (&iid * &jdot + mat6_to_d(&ci) * &j0[i]);
    }
    c
}

#[test]
fn m_dot_minus_two_c_is_skew_symmetric() {
    // SPEC §4: Ṁ − 2C skew-symmetric. The test has two halves:
    // (1) the implemented bias h(q,ζ) (RNEA, gravity/drag/current off, with and without added
    //     mass) equals C(q,ζ)ζ for the matrix C of `c_matrix` — so h *has* this
    //     factorisation;
    // (2) with Ṁ = Σ_k ∂M/∂q_k q̇_k by central differences of the implemented CRBA mass
    //     matrix (M does not depend on the base pose in body coordinates), Ṁ − 2C is skew:
    //     Ṁ − 2C = Σ (J̇ᵀIJ − JᵀIJ̇ − 2JᵀC_iJ), a difference of a matrix and its transpose
    //     plus skew terms, *provided* the CRBA's M is Σ JᵀIJ to first order in q.
    // Together: ζᵀ h = ½ ζᵀ Ṁ ζ (the power balance d/dt ½ζᵀMζ = ζᵀτ for τ = M ζ̇ + h).
    // Central differences with h = 1e-6: truncation O(h²) ≈ 1e-12 relative, rounding
    // ≈ ε/h ≈ 1e-10 relative to ‖M‖ ≈ 1e2: tolerance 1e-6 relative to ‖Ṁ‖ + ‖C‖.
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let fd = 1e-6;
    for v in models() {
        let mut ws = DynWorkspace::new(&v);
        for opts in [
            DynOptions::rigid(),
            DynOptions {
                added_mass: true,
                ..DynOptions::rigid()
            },
        ] {
            for _ in 0..3 {
                let s = sample(&v, &mut rng, 1.0);
                let n = v.n_joints();
                let c = c_matrix(&v, &ws, &s, &opts, fd);
                bias(&v, &mut ws, &s.pose, &s.q, &s.zeta, &opts);
                let z = DVector::from_column_slice(&s.zeta);
                let cz = &c * &z;
                let hb = DVector::from_column_slice(&ws.bias);
                let scale = hb.norm() + 1.0;
                assert!(
                    (&cz - &hb).norm() < 1e-6 * scale,
                    "Cζ = h: {}",
                    (&cz - &hb).norm()
                );
                let qd = &s.zeta[6..];
                let qp: Vec<f64> = (0..n).map(|k| s.q[k] + fd * qd[k]).collect();
                let qm: Vec<f64> = (0..n).map(|k| s.q[k] - fd * qd[k]).collect();
                mass_matrix(&v, &mut ws, &qp, &opts);
                let mp = to_dmatrix(&ws.mass);
                mass_matrix(&v, &mut ws, &qm, &opts);
                let mm = to_dmatrix(&ws.mass);
                let mdot = (mp - mm) / (2.0 * fd);
                let s_mat = &mdot - 2.0 * &c;
                let sym = &s_mat + s_mat.transpose();
                let scale = mdot.norm() + c.norm();
                assert!(
                    sym.norm() < 1e-6 * scale,
                    "{}: {} vs {}",
                    v.name,
                    sym.norm(),
                    scale
                );
                let power = z.dot(&hb) - 0.5 * z.dot(&(&mdot * &z));
                assert!(power.abs() < 1e-6 * scale * z.norm_squared());
            }
        }
    }
}

#[test]
fn damping_and_restoring_generalized_forces_match_bias() {
    // h(full, no added mass) = h(rigid) − Q_damp − Q_restoring: the separate generalised
    // forces are the same wrenches pushed through the same backward pass. 1e-10 absolute.
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for v in models().into_iter().map(with_current) {
        let mut ws = DynWorkspace::new(&v);
        let nv = v.n_dof();
        let s = sample(&v, &mut rng, 1.0);
        let opts = DynOptions {
            added_mass: false,
            ..DynOptions::full()
        };
        let (mut qd, mut qr) = (vec![0.0; nv], vec![0.0; nv]);
        damping_generalized(&v, &mut ws, &s.pose, &s.q, &s.zeta, &opts, &mut qd);
        restoring_generalized(&v, &mut ws, &s.pose, &s.q, &mut qr);
        bias(&v, &mut ws, &s.pose, &s.q, &s.zeta, &DynOptions::rigid());
        let h_rigid = ws.bias.clone();
        bias(&v, &mut ws, &s.pose, &s.q, &s.zeta, &opts);
        for r in 0..nv {
            assert!((ws.bias[r] - (h_rigid[r] - qd[r] - qr[r])).abs() < 1e-10);
        }
        // Without current, damping only dissipates: ζᵀ Q_damp ≤ 0.
        let still = DynOptions {
            current: false,
            ..opts
        };
        damping_generalized(&v, &mut ws, &s.pose, &s.q, &s.zeta, &still, &mut qd);
        let p: f64 = qd.iter().zip(&s.zeta).map(|(a, b)| a * b).sum();
        assert!(p <= 0.0);
    }
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

#[test]
fn restoring_is_gradient_of_potential_energy() {
    // Q_restoring = −∂U/∂(generalised coordinates) with U = Σ (m_i g z_cg,i − ρ V_i g z_cb,i):
    // check its power ζᵀQ against −dU/dt by central differences along ζ (base moved by the
    // exponential of its body twist). h = 1e-6: error ≈ 1e-9 relative to O(100) N·m.
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    for v in models() {
        let mut ws = DynWorkspace::new(&v);
        let nv = v.n_dof();
        let s = sample(&v, &mut rng, 1.0);
        let potential = |pose: &BasePose, q: &[f64]| potential_energy(&v, pose, q);
        let moved = |sgn: f64, h: f64| -> (BasePose, Vec<f64>) {
            let vb = Vec6::from_column_slice(&s.zeta[..6]) * (sgn * h);
            let r = s.pose.orientation;
            let pose = BasePose {
                orientation: r * UnitQuaternion::from_scaled_axis(Vec3::new(vb[3], vb[4], vb[5])),
                position: s.pose.position + r * Vec3::new(vb[0], vb[1], vb[2]),
            };
            let q = (0..v.n_joints())
                .map(|k| s.q[k] + sgn * h * s.zeta[6 + k])
                .collect();
            (pose, q)
        };
        let h = 1e-6;
        let (pp, qp) = moved(1.0, h);
        let (pm, qm) = moved(-1.0, h);
        let du = (potential(&pp, &qp) - potential(&pm, &qm)) / (2.0 * h);
        let mut qr = vec![0.0; nv];
        restoring_generalized(&v, &mut ws, &s.pose, &s.q, &mut qr);
        let p: f64 = qr.iter().zip(&s.zeta).map(|(a, b)| a * b).sum();
        assert!(
            (p + du).abs() < 1e-6 * (1.0 + du.abs()),
            "{}: {p} vs {}",
            v.name,
            -du
        );
    }
}

// ---------------------------------------------------------------------------------------
// Simulation: conservation laws and closed-form motions.

fn passive_sim(v: &Vehicle, options: DynOptions) -> Simulator {
    Simulator::new(
        v,
        SimConfig {
            options,
            servo: ServoModel::Passive,
            thruster: ThrusterModel::Ideal,
        },
    )
    .unwrap()
}

fn zero_cmd_buffers(v: &Vehicle) -> (Vec<f64>, Vec<f64>) {
    (vec![0.0; v.n_thrusters()], vec![0.0; v.n_joints()])
}

/// Run 100 s at dt = 1 ms from a random nonzero ζ, torque-free, and return the largest
/// relative drift of kinetic energy and of the inertial spatial momentum.
fn conservation_drift(v: &Vehicle, options: DynOptions, seed: u64) -> (f64, f64) {
    let mut sim = passive_sim(v, options);
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
    for k in 0..100_000 {
        sim.step(1e-3, &cmd).unwrap();
        if k % 1000 == 999 {
            de = de.max((sim.kinetic_energy() - e0).abs() / e0);
            dp = dp.max((sim.spatial_momentum() - p0).norm() / p0.norm());
        }
    }
    assert!((sim.time() - 100.0).abs() < 1e-9);
    (de, dp)
}

#[test]
fn rigid_free_motion_conserves_energy_and_momentum() {
    // SPEC §4 invariant, vacuum. RK4 at dt = 1 ms on motions of ~1 rad/s: local error
    // ~(ω dt)⁵ ≈ 1e-15 per step, so 1e5 steps stay far below the required 1e-6.
    for v in [usm_paper(), toy(3)] {
        let (de, dp) = conservation_drift(&v, DynOptions::rigid(), 11);
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
        let (de, dp) = conservation_drift(&v, opts, 12);
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
    // Galilean invariance (SPEC §4 current model): in a constant irrotational current ν_c,
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
    // Neutrally buoyant with CG = CB (SPEC §2): at rest in still water nothing acts.
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

// ---------------------------------------------------------------------------------------
// Errors.

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

// ---------------------------------------------------------------------------------------
// Inspect and controller hooks.

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

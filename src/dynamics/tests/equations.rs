//! Newton–Euler, inverse, forward and hybrid dynamics (USM-19/20), the skew-symmetry of
//! Ṁ − 2C, damping and restoring forces.

use super::*;

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
    // docs/model.md §4: Ṁ − 2C skew-symmetric. The test has two halves:
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

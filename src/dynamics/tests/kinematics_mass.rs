//! Kinematics and the mass matrix: the one position pass, the block inertia transform, CRBA
//! against the Jacobian sum (USM-22).

use super::*;

#[test]
fn dynamics_reuses_the_one_position_pass() {
    // The dynamics algorithms run `forward_kinematics` into `ws.kin` (one FK in the crate):
    // their placements are bit for bit those of a standalone kinematics pass, and
    // `g_bi = g_b(i-1) g_(i-1)i` chains the parent-to-child placements.
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    for v in models() {
        let mut ws = DynWorkspace::new(&v);
        let mut kin = KinWorkspace::new(&v);
        for _ in 0..5 {
            let s = sample(&v, &mut rng, 1.0);
            mass_matrix(&v, &mut ws, &s.q, &DynOptions::rigid());
            forward_kinematics(&v, &s.q, &mut kin);
            for i in 0..v.bodies.len() {
                assert_eq!(ws.kin.g_b[i], kin.g_b[i]);
                assert_eq!(ws.kin.g_up[i], kin.g_up[i]);
                let chained = if i == 0 {
                    kin.g_up[0]
                } else {
                    kin.g_b[i - 1].compose(&kin.g_up[i])
                };
                assert_eq!(chained, kin.g_b[i]);
            }
            assert_eq!(ws.kin.joint_twist_b, kin.joint_twist_b);
            assert_eq!(ws.kin.g_be, kin.g_be);
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

//! Structure-exploiting kernels of the dynamics passes (issue 23): the products of the
//! passes written out without their multiplications by exact zeros and ones, for
//!
//! - the transforms `g_up` of axial joints ([`JointShape::Axial`]: `(Rot(e_a, q), (x, 0, 0))`,
//!   the twist and wrench transports of the Newton–Euler and articulated-body passes);
//! - axial spatial inertias ([`is_axial`]: a body symmetric enough about its x axis — a
//!   cylinder, its centre of gravity and added-mass centre on the axis, principal axes along
//!   the body axes — has at most ten nonzero entries of 36), in the body wrenches and in the
//!   composite inertias `Ad⁻ᵀ I Ad⁻¹`.
//! - the 6×6 Cholesky solve of the base block (`M_11` of the hybrid dynamics, the base's
//!   articulated inertia of the ABA): nalgebra's algorithm on the stack, unrolled.
//!
//! Every kernel sums the same nonzero products in the same order as the dense nalgebra
//! product it replaces (`(A B)_ij = ((A_i0 B_0j + A_i1 B_1j) + A_i2 B_2j)`, a product
//! `1 · x = x` exact), so its result is the dense result bit for bit: a skipped `±0` term can
//! change nothing but the sign of a result that is zero (tested against the dense products).
//! Nothing here allocates.

use crate::kinematics::{cyclic, JointShape};
use crate::spatial::{ang, lin, skew, stack, Mat3, Mat6, Se3, Vec3, Vec6};

/// Whether every entry of `m` outside the axial pattern is exactly zero: the diagonal,
/// `(1, 5)`, `(2, 4)`, `(4, 2)`, `(5, 1)` may be nonzero. Rigid-body inertias with the centre
/// of gravity on the x axis and a diagonal rotational inertia, and the cylinder's added mass
/// (diagonal about the centre, moved along x), have this pattern.
pub(crate) fn is_axial(m: &Mat6) -> bool {
    (0..6).all(|r| {
        (0..6).all(|c| {
            r == c || matches!((r, c), (1, 5) | (2, 4) | (4, 2) | (5, 1)) || m[(r, c)] == 0.0
        })
    })
}

/// `m x` for an axial `m` ([`is_axial`]); the dense product otherwise.
#[inline]
pub(crate) fn mul_inertia(m: &Mat6, axial: bool, x: &Vec6) -> Vec6 {
    if !axial {
        return m * x;
    }
    Vec6::new(
        m[(0, 0)] * x[0],
        m[(1, 1)] * x[1] + m[(1, 5)] * x[5],
        m[(2, 2)] * x[2] + m[(2, 4)] * x[4],
        m[(3, 3)] * x[3],
        m[(4, 2)] * x[2] + m[(4, 4)] * x[4],
        m[(5, 1)] * x[1] + m[(5, 5)] * x[5],
    )
}

/// `m[.., 0..3] w` (the first three columns, as the current's `M_A [ω × v_c; 0]`) for an axial
/// `m`; the dense product otherwise. Row 3 of an axial `m` has no entry there: its `±0` is
/// returned as `+0`.
#[inline]
pub(crate) fn mul_inertia_linear(m: &Mat6, axial: bool, w: &Vec3) -> Vec6 {
    if !axial {
        return m.fixed_view::<6, 3>(0, 0) * w;
    }
    Vec6::new(
        m[(0, 0)] * w.x,
        m[(1, 1)] * w.y,
        m[(2, 2)] * w.z,
        0.0,
        m[(4, 2)] * w.z,
        m[(5, 1)] * w.y,
    )
}

/// `Rᵀ x` for the rotation `R = Rot(e_A, q)` of an axial joint.
#[inline(always)]
fn rot_t_axial<const A: usize>(r: &Mat3, x: &Vec3) -> Vec3 {
    let (b, c) = cyclic(A);
    let mut out = [0.0; 3];
    out[A] = x[A];
    out[b] = r[(b, b)] * x[b] + r[(c, b)] * x[c];
    out[c] = r[(b, c)] * x[b] + r[(c, c)] * x[c];
    Vec3::from(out)
}

/// `R x` for the rotation `R = Rot(e_A, q)` of an axial joint.
#[inline(always)]
fn rot_axial<const A: usize>(r: &Mat3, x: &Vec3) -> Vec3 {
    let (b, c) = cyclic(A);
    let mut out = [0.0; 3];
    out[A] = x[A];
    out[b] = r[(b, b)] * x[b] + r[(b, c)] * x[c];
    out[c] = r[(c, b)] * x[b] + r[(c, c)] * x[c];
    Vec3::from(out)
}

/// [`twist_to_child`] for an axial joint about `e_A`.
#[inline(always)]
fn twist_to_child_axial<const A: usize>(g: &Se3, v: &Vec6) -> Vec6 {
    let x = g.p.x;
    let lv = Vec3::new(v[0], v[1] + x * v[5], v[2] - x * v[4]);
    stack(
        &rot_t_axial::<A>(&g.r, &lv),
        &rot_t_axial::<A>(&g.r, &ang(v)),
    )
}

/// `Ad_g⁻¹ V` ([`Se3::twist_to_child`]) for joint `g` of shape `shape`: with `p = (x, 0, 0)`,
/// `v − p × ω = (v_x, v_y + x ω_z, v_z − x ω_y)`, then `Rᵀ` on both parts.
#[inline]
pub(crate) fn twist_to_child(g: &Se3, shape: JointShape, v: &Vec6) -> Vec6 {
    match shape {
        JointShape::Axial(0) => twist_to_child_axial::<0>(g, v),
        JointShape::Axial(1) => twist_to_child_axial::<1>(g, v),
        JointShape::Axial(2) => twist_to_child_axial::<2>(g, v),
        _ => g.twist_to_child(v),
    }
}

/// The joint's rate terms of the forward passes: adds `ω_j = axis q̇` to the angular part of
/// the body twist `v` and returns `v × [0; ω_j] = [v_lin × ω_j; v_ang × ω_j]` of the updated
/// twist. For an axial joint `ω_j = q̇ e_a`: one entry added, and each cross product
/// `u × q̇ e_a` is `(u_c q̇, −u_b q̇)` at `(b, c)` and zero at `a`.
#[inline]
pub(crate) fn add_joint_rate(shape: JointShape, axis: &Vec3, v: &mut Vec6, qd: f64) -> Vec6 {
    match shape {
        JointShape::Axial(0) => add_joint_rate_axial::<0>(v, qd),
        JointShape::Axial(1) => add_joint_rate_axial::<1>(v, qd),
        JointShape::Axial(2) => add_joint_rate_axial::<2>(v, qd),
        _ => {
            let w = axis * qd;
            v[3] += w.x;
            v[4] += w.y;
            v[5] += w.z;
            stack(&lin(v).cross(&w), &ang(v).cross(&w))
        }
    }
}

/// [`add_joint_rate`] for an axial joint about `e_A`.
#[inline(always)]
fn add_joint_rate_axial<const A: usize>(v: &mut Vec6, qd: f64) -> Vec6 {
    let (b, c) = cyclic(A);
    v[3 + A] += qd;
    let mut out = [0.0; 6];
    out[b] = v[c] * qd;
    out[c] = 0.0 - v[b] * qd;
    out[3 + b] = v[3 + c] * qd;
    out[3 + c] = 0.0 - v[3 + b] * qd;
    Vec6::from(out)
}

/// Adds `axis q̈` to the angular part of the body acceleration `a` (one entry for an axial
/// joint).
#[inline]
pub(crate) fn add_joint_accel(shape: JointShape, axis: &Vec3, a: &mut Vec6, qdd: f64) {
    match shape {
        JointShape::Axial(k) => a[3 + k] += qdd,
        JointShape::General => {
            let dw = axis * qdd;
            a[3] += dw.x;
            a[4] += dw.y;
            a[5] += dw.z;
        }
    }
}

/// `axis · ang(f)`, the joint's component of a wrench (or of `I s`): `f[3 + a]` for an axial
/// joint.
#[inline]
pub(crate) fn joint_component(shape: JointShape, axis: &Vec3, f: &Vec6) -> f64 {
    match shape {
        JointShape::Axial(a) => f[3 + a],
        JointShape::General => axis.dot(&ang(f)),
    }
}

/// `I s` for the joint's unit twist `s = [0; axis]`: column `3 + a` of `I` for an axial
/// joint.
#[inline]
pub(crate) fn inertia_times_joint(shape: JointShape, axis: &Vec3, m: &Mat6) -> Vec6 {
    match shape {
        JointShape::Axial(a) => m.column(3 + a).into_owned(),
        JointShape::General => m.fixed_view::<6, 3>(0, 3) * axis,
    }
}

/// [`wrench_to_parent`] for an axial joint about `e_A`.
#[inline(always)]
fn wrench_to_parent_axial<const A: usize>(g: &Se3, f: &Vec6) -> Vec6 {
    let x = g.p.x;
    let force = rot_axial::<A>(&g.r, &lin(f));
    let m = rot_axial::<A>(&g.r, &ang(f));
    Vec6::new(
        force.x,
        force.y,
        force.z,
        m.x,
        m.y - x * force.z,
        m.z + x * force.y,
    )
}

/// `Ad_g⁻ᵀ F` ([`Se3::wrench_to_parent`]) for joint `g` of shape `shape`: `f' = R f`,
/// `m' = R m + p × f'` with `p × f' = (0, −x f'_z, x f'_y)`.
#[inline]
pub(crate) fn wrench_to_parent(g: &Se3, shape: JointShape, f: &Vec6) -> Vec6 {
    match shape {
        JointShape::Axial(0) => wrench_to_parent_axial::<0>(g, f),
        JointShape::Axial(1) => wrench_to_parent_axial::<1>(g, f),
        JointShape::Axial(2) => wrench_to_parent_axial::<2>(g, f),
        _ => g.wrench_to_parent(f),
    }
}

/// `R D Rᵀ` for a diagonal `D = diag(d)`, as the dense `(R D) Rᵀ`: `(R D)_ik = R_ik d_k`.
#[inline]
fn congruence_diag(r: &Mat3, d: [f64; 3]) -> Mat3 {
    let rd = Mat3::from_fn(|i, k| r[(i, k)] * d[k]);
    Mat3::from_fn(|i, j| rd[(i, 0)] * r[(j, 0)] + rd[(i, 1)] * r[(j, 1)] + rd[(i, 2)] * r[(j, 2)])
}

/// `X Y` for `X = p̂` (a skew matrix, zero diagonal): `(p̂ Y)_ij = Σ_{k≠i} p̂_ik Y_kj`.
#[inline]
fn skew_mul(ph: &Mat3, y: &Mat3) -> Mat3 {
    Mat3::from_fn(|i, j| {
        let (k1, k2) = match i {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        ph[(i, k1)] * y[(k1, j)] + ph[(i, k2)] * y[(k2, j)]
    })
}

/// `Ad_g⁻ᵀ I Ad_g⁻¹`: a spatial inertia about the child origin in the child frame, moved to
/// the parent frame, for `g = (R, p)` — by 3×3 blocks (about 60 % of the cost of two 6×6
/// products). With `I = [[A, B], [Bᵀ, C]]` and `A' = RARᵀ`, `B' = RBRᵀ`, `C' = RCRᵀ`:
/// `[[A', B' − A'p̂], [·ᵀ, C' + p̂B' − B'ᵀp̂ − p̂A'p̂]]`.
#[inline]
pub(crate) fn inertia_to_parent(g: &Se3, i: &Mat6) -> Mat6 {
    let r = &g.r;
    let rt = r.transpose();
    let a = r * i.fixed_view::<3, 3>(0, 0) * rt;
    let b = r * i.fixed_view::<3, 3>(0, 3) * rt;
    let c = r * i.fixed_view::<3, 3>(3, 3) * rt;
    let ph = skew(&g.p);
    let aph = a * ph;
    let ur = b - aph;
    let pb = ph * b;
    let lr = c + pb + pb.transpose() - ph * aph;
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&ur);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&ur.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&lr);
    out
}

/// `Ad_g⁻ᵀ I Ad_g⁻¹` (the 3×3 block form of [`inertia_to_parent`]) for an axial `I`
/// ([`is_axial`]) and any `g`: the blocks `A = diag`, `B` with `B_12`, `B_21` only and
/// `C = diag` enter `R A Rᵀ`, `R B Rᵀ`, `R C Rᵀ` without their zero products, and the
/// products with `p̂` skip its zero diagonal.
pub(crate) fn inertia_to_parent_axial(g: &Se3, m: &Mat6) -> Mat6 {
    let r = &g.r;
    let a = congruence_diag(r, [m[(0, 0)], m[(1, 1)], m[(2, 2)]]);
    let c = congruence_diag(r, [m[(3, 3)], m[(4, 4)], m[(5, 5)]]);
    // (R B)_i1 = R_i2 B_21, (R B)_i2 = R_i1 B_12 (column 0 is zero).
    let (b12, b21) = (m[(1, 5)], m[(2, 4)]);
    let rb1 = Vec3::new(r[(0, 2)] * b21, r[(1, 2)] * b21, r[(2, 2)] * b21);
    let rb2 = Vec3::new(r[(0, 1)] * b12, r[(1, 1)] * b12, r[(2, 1)] * b12);
    let b = Mat3::from_fn(|i, j| rb1[i] * r[(j, 1)] + rb2[i] * r[(j, 2)]);
    let ph = skew(&g.p);
    // (A p̂)_ij = Σ_{k≠j} A_ik p̂_kj.
    let aph = Mat3::from_fn(|i, j| {
        let (k1, k2) = match j {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        a[(i, k1)] * ph[(k1, j)] + a[(i, k2)] * ph[(k2, j)]
    });
    let ur = b - aph;
    let pb = skew_mul(&ph, &b);
    let lr = c + pb + pb.transpose() - skew_mul(&ph, &aph);
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&ur);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&ur.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&lr);
    out
}

/// `R X Rᵀ` for the rotation `R = Rot(e_A, q)` of an axial joint and any `X`, as the dense
/// `(R X) Rᵀ`: row and column `A` pass through, the other two mix two entries each.
#[inline(always)]
fn congruence_axial_rotation<const A: usize>(r: &Mat3, x: &Mat3) -> Mat3 {
    let (a, (b, c)) = (A, cyclic(A));
    let mut rx = Mat3::zeros();
    for j in 0..3 {
        rx[(a, j)] = x[(a, j)];
        rx[(b, j)] = r[(b, b)] * x[(b, j)] + r[(b, c)] * x[(c, j)];
        rx[(c, j)] = r[(c, b)] * x[(b, j)] + r[(c, c)] * x[(c, j)];
    }
    let mut out = Mat3::zeros();
    for i in 0..3 {
        out[(i, a)] = rx[(i, a)];
        out[(i, b)] = rx[(i, b)] * r[(b, b)] + rx[(i, c)] * r[(b, c)];
        out[(i, c)] = rx[(i, b)] * r[(c, b)] + rx[(i, c)] * r[(c, c)];
    }
    out
}

/// `Ad_g⁻ᵀ I Ad_g⁻¹` ([`inertia_to_parent`]) for joint `g` of shape `shape` and any
/// `I` (the articulated inertias): for an axial joint `R = Rot(e_a, q)` and `p̂` of
/// `p = (x, 0, 0)` has two entries, `p̂_12 = −x`, `p̂_21 = x`.
pub(crate) fn inertia_to_parent_joint(g: &Se3, shape: JointShape, m: &Mat6) -> Mat6 {
    match shape {
        JointShape::Axial(0) => inertia_to_parent_joint_axial::<0>(g, m),
        JointShape::Axial(1) => inertia_to_parent_joint_axial::<1>(g, m),
        JointShape::Axial(2) => inertia_to_parent_joint_axial::<2>(g, m),
        _ => inertia_to_parent(g, m),
    }
}

/// [`inertia_to_parent_joint`] for an axial joint about `e_A`.
fn inertia_to_parent_joint_axial<const A: usize>(g: &Se3, m: &Mat6) -> Mat6 {
    let r = &g.r;
    let a = congruence_axial_rotation::<A>(r, &m.fixed_view::<3, 3>(0, 0).into_owned());
    let b = congruence_axial_rotation::<A>(r, &m.fixed_view::<3, 3>(0, 3).into_owned());
    let c = congruence_axial_rotation::<A>(r, &m.fixed_view::<3, 3>(3, 3).into_owned());
    let (m12, m21) = (-g.p.x, g.p.x);
    // A p̂: column 0 is zero, (A p̂)_i1 = A_i2 p̂_21, (A p̂)_i2 = A_i1 p̂_12.
    let mut ur = b;
    for i in 0..3 {
        ur[(i, 1)] -= a[(i, 2)] * m21;
        ur[(i, 2)] -= a[(i, 1)] * m12;
    }
    let aph_1 = Vec3::new(a[(0, 2)] * m21, a[(1, 2)] * m21, a[(2, 2)] * m21);
    let aph_2 = Vec3::new(a[(0, 1)] * m12, a[(1, 1)] * m12, a[(2, 1)] * m12);
    // p̂ Y: row 0 is zero, (p̂ Y)_1j = p̂_12 Y_2j, (p̂ Y)_2j = p̂_21 Y_1j.
    let pb = Mat3::from_fn(|i, j| match i {
        0 => 0.0,
        1 => m12 * b[(2, j)],
        _ => m21 * b[(1, j)],
    });
    let aph = Mat3::from_fn(|i, j| match j {
        0 => 0.0,
        1 => aph_1[i],
        _ => aph_2[i],
    });
    let ph_aph = Mat3::from_fn(|i, j| match i {
        0 => 0.0,
        1 => m12 * aph[(2, j)],
        _ => m21 * aph[(1, j)],
    });
    let lr = c + pb + pb.transpose() - ph_aph;
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&ur);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&ur.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&lr);
    out
}

/// `m.cholesky()?.solve(rhs)` of nalgebra for a 6×6 `m` (only its lower triangle read),
/// unrolled on the stack: the same operations in the same order — the left-looking column
/// updates `a_ij ← (−l_jk) l_ik + a_ij`, the pivot `√a_jj` accepted when `a_jj ≠ 0` and
/// `a_jj ≥ 0`, the division of the column below it, forward substitution by columns,
/// back substitution `x_i = (y_i − Σ_{k>i} l_ki x_k) / l_ii` with the sum from `+0` in
/// increasing `k` — so the same bits (tested); `None` where nalgebra's factorisation fails.
pub(crate) fn cholesky6_solve(m: &Mat6, rhs: &Vec6) -> Option<Vec6> {
    let mut a = *m;
    for j in 0..6 {
        for k in 0..j {
            let factor = -a[(j, k)];
            for i in j..6 {
                a[(i, j)] += factor * a[(i, k)];
            }
        }
        let diag = a[(j, j)];
        // nalgebra accepts `diag ≠ 0` with `diag ≥ 0`, i.e. `diag > 0` (NaN fails).
        if diag.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let d = diag.sqrt();
        a[(j, j)] = d;
        for i in j + 1..6 {
            a[(i, j)] /= d;
        }
    }
    let mut b = *rhs;
    for i in 0..6 {
        let coeff = b[i] / a[(i, i)];
        b[i] = coeff;
        for r in i + 1..6 {
            b[r] += -coeff * a[(r, i)];
        }
    }
    for i in (0..6).rev() {
        let mut dot = 0.0;
        for k in i + 1..6 {
            dot += a[(k, i)] * b[k];
        }
        b[i] = (b[i] - dot) / a[(i, i)];
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::{usm_paper, uvms_planar};
    use crate::model::Vehicle;
    use crate::spatial::rot_axis_angle;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Same bits, or both zero.
    fn same(name: &str, a: &[f64], b: &[f64]) {
        for (r, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                x.to_bits() == y.to_bits() || (*x == 0.0 && *y == 0.0),
                "{name}[{r}]: {x:e} vs {y:e}"
            );
        }
    }

    /// A random axial inertia: diagonal, `(1, 5) = (5, 1)`, `(2, 4) = (4, 2)`.
    fn axial(rng: &mut ChaCha8Rng) -> Mat6 {
        let mut m = Mat6::zeros();
        for i in 0..6 {
            m[(i, i)] = rng.random_range(0.5..20.0);
        }
        let (u, w) = (rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
        (m[(1, 5)], m[(5, 1)], m[(2, 4)], m[(4, 2)]) = (u, u, w, w);
        m
    }

    #[test]
    fn the_presets_bodies_and_joints_are_axial() {
        let v: Vehicle = usm_paper();
        let rho = v.fluid.rho;
        for b in &v.bodies {
            assert!(is_axial(&b.rigid_spatial_inertia()), "{}", b.name);
            assert!(is_axial(&b.added_mass(rho)), "{}", b.name);
        }
        for v in [usm_paper(), uvms_planar()] {
            for j in &v.joints {
                assert!(
                    matches!(JointShape::of(j), JointShape::Axial(_)),
                    "{}",
                    j.name
                );
            }
        }
        let mut m = Mat6::identity();
        m[(0, 4)] = 1e-300;
        assert!(!is_axial(&m));
    }

    #[test]
    fn kernels_equal_the_dense_products_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        for t in 0..500 {
            let m = axial(&mut rng);
            let x = Vec6::from_fn(|_, _| rng.random_range(-2.0..2.0));
            same(
                "I x",
                mul_inertia(&m, true, &x).as_slice(),
                (m * x).as_slice(),
            );
            let w = Vec3::new(x[0], x[1], x[2]);
            let dense = m.fixed_view::<6, 3>(0, 0) * w;
            same(
                "I[:, :3] w",
                mul_inertia_linear(&m, true, &w).as_slice(),
                dense.as_slice(),
            );
            // Any transform for the composite inertias (the identity's exact zeros once).
            let axis = Vec3::new(rng.random(), rng.random(), rng.random()).normalize();
            let g = if t == 0 {
                Se3::identity()
            } else {
                Se3::new(
                    rot_axis_angle(&axis, rng.random_range(-3.0..3.0)),
                    Vec3::new(rng.random(), rng.random(), rng.random()),
                )
            };
            let (s, d) = (inertia_to_parent_axial(&g, &m), inertia_to_parent(&g, &m));
            same("Ad⁻ᵀ I Ad⁻¹", s.as_slice(), d.as_slice());
            // An axial joint's transform, about each axis, and a dense articulated inertia.
            let a = t % 3;
            let q = if t < 3 {
                0.0
            } else {
                rng.random_range(-3.0..3.0)
            };
            let g = Se3::new(
                rot_axis_angle(&Vec3::ith(a, 1.0), q),
                Vec3::new(rng.random_range(0.1..1.0), 0.0, 0.0),
            );
            let shape = JointShape::Axial(a);
            same(
                "twist to child",
                twist_to_child(&g, shape, &x).as_slice(),
                g.twist_to_child(&x).as_slice(),
            );
            same(
                "wrench to parent",
                wrench_to_parent(&g, shape, &x).as_slice(),
                g.wrench_to_parent(&x).as_slice(),
            );
            let full = Mat6::from_fn(|_, _| rng.random_range(-5.0..5.0));
            let full = full * full.transpose();
            same(
                "joint Ad⁻ᵀ I Ad⁻¹",
                inertia_to_parent_joint(&g, shape, &full).as_slice(),
                inertia_to_parent(&g, &full).as_slice(),
            );
        }
    }

    #[test]
    fn cholesky6_is_nalgebras_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(43);
        for t in 0..2000 {
            let b = Mat6::from_fn(|_, _| rng.random_range(-2.0..2.0));
            // SPD, ill-conditioned, indefinite and singular matrices.
            let m = match t % 4 {
                0 => b * b.transpose() + Mat6::identity(),
                1 => b * b.transpose() + Mat6::identity() * 1e-9,
                2 => b + b.transpose(),
                _ => {
                    let mut m = b * b.transpose();
                    m.fixed_view_mut::<1, 6>(5, 0).fill(0.0);
                    m.fixed_view_mut::<6, 1>(0, 5).fill(0.0);
                    m
                }
            };
            let rhs = Vec6::from_fn(|_, _| rng.random_range(-10.0..10.0));
            let dense = m.cholesky().map(|c| c.solve(&rhs));
            match (cholesky6_solve(&m, &rhs), dense) {
                (Some(x), Some(y)) => same("cholesky solve", x.as_slice(), y.as_slice()),
                (None, None) => {}
                (x, y) => panic!("case {t}: {x:?} vs {y:?}"),
            }
        }
    }
}

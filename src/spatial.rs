//! Spatial algebra on SE(3) for the `[v; ω]` (linear first) ordering of docs/model.md §1.
//!
//! Conventions (docs/model.md §1):
//! - a transform `g = (R, p)` maps points of the child frame into the parent frame,
//!   `x_parent = R x_child + p`;
//! - twists `V = [v; ω]` and wrenches `F = [f; m]` are expressed in a named frame;
//! - `Ad_g = [[R, p̂R], [0, R]]` maps a twist from the child to the parent frame and
//!   `Ad_g⁻ᵀ` maps a wrench from the child to the parent frame.
//!
//! Angle helpers of rotation geometry live here too: [`wrap_angle`], the heading ψ of a frame
//! ([`heading`], `ψ = atan2(R₁₀, R₀₀)`, the yaw of its x axis about the inertial +z axis), its
//! rate and gradient.
//!
//! Everything here is fixed-size nalgebra and allocation-free.

use nalgebra::{Matrix3, Matrix6, Quaternion, UnitQuaternion, Vector3, Vector6};
use std::f64::consts::PI;

/// A 6-vector: a twist `[v; ω]` (m/s, rad/s) or a wrench `[f; m]` (N, N·m).
pub type Vec6 = Vector6<f64>;
/// A 6×6 matrix: adjoints, spatial inertias.
pub type Mat6 = Matrix6<f64>;
/// A 3-vector in metres (positions) or unitless (directions).
pub type Vec3 = Vector3<f64>;
/// A 3×3 matrix: rotations, rotational inertias.
pub type Mat3 = Matrix3<f64>;

/// The skew-symmetric matrix `p̂` with `p̂ x = p × x`.
#[inline]
pub fn skew(p: &Vec3) -> Mat3 {
    Mat3::new(0.0, -p.z, p.y, p.z, 0.0, -p.x, -p.y, p.x, 0.0)
}

/// Linear part `[v]` of a 6-vector.
#[inline]
pub fn lin(x: &Vec6) -> Vec3 {
    Vec3::new(x[0], x[1], x[2])
}

/// Angular part `[ω]` of a 6-vector.
#[inline]
pub fn ang(x: &Vec6) -> Vec3 {
    Vec3::new(x[3], x[4], x[5])
}

/// Stack `[a; b]` into a 6-vector.
#[inline]
pub fn stack(a: &Vec3, b: &Vec3) -> Vec6 {
    Vec6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}

/// A rigid transform `g = (R, p)` ∈ SE(3) (docs/model.md §1): `R` rotation, `p` translation in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3 {
    /// Rotation of the child frame's axes, expressed in the parent frame.
    pub r: Mat3,
    /// Origin of the child frame in the parent frame [m].
    pub p: Vec3,
}

impl Default for Se3 {
    fn default() -> Self {
        Self::identity()
    }
}

impl Se3 {
    /// The identity transform.
    pub fn identity() -> Self {
        Self {
            r: Mat3::identity(),
            p: Vec3::zeros(),
        }
    }

    /// A transform from rotation and translation.
    pub fn new(r: Mat3, p: Vec3) -> Self {
        Self { r, p }
    }

    /// A pure translation by `p` [m].
    pub fn from_translation(p: Vec3) -> Self {
        Self {
            r: Mat3::identity(),
            p,
        }
    }

    /// A pure rotation by `angle` [rad] about the unit `axis`, Rodrigues' formula.
    pub fn from_axis_angle(axis: &Vec3, angle: f64) -> Self {
        Self {
            r: rot_axis_angle(axis, angle),
            p: Vec3::zeros(),
        }
    }

    /// Composition `self ∘ other` (`g_ac = g_ab g_bc`).
    #[inline]
    pub fn compose(&self, other: &Se3) -> Se3 {
        Se3 {
            r: self.r * other.r,
            p: self.r * other.p + self.p,
        }
    }

    /// The inverse `g⁻¹ = (Rᵀ, −Rᵀp)`.
    #[inline]
    pub fn inverse(&self) -> Se3 {
        let rt = self.r.transpose();
        Se3 {
            r: rt,
            p: -(rt * self.p),
        }
    }

    /// Map a point from the child to the parent frame, `R x + p` [m].
    #[inline]
    pub fn act_point(&self, x: &Vec3) -> Vec3 {
        self.r * x + self.p
    }

    /// Map a free vector from the child to the parent frame, `R x`.
    #[inline]
    pub fn act_vector(&self, x: &Vec3) -> Vec3 {
        self.r * x
    }

    /// The adjoint `Ad_g = [[R, p̂R], [0, R]]` (docs/model.md §1).
    pub fn adjoint(&self) -> Mat6 {
        let mut m = Mat6::zeros();
        let pr = skew(&self.p) * self.r;
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.r);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&pr);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.r);
        m
    }

    /// The inverse adjoint `Ad_g⁻¹ = [[Rᵀ, −Rᵀp̂], [0, Rᵀ]]` (docs/model.md §1).
    pub fn adjoint_inv(&self) -> Mat6 {
        self.inverse().adjoint()
    }

    /// `Ad_g V`: a twist given in the child frame, expressed in the parent frame.
    #[inline]
    pub fn twist_to_parent(&self, v: &Vec6) -> Vec6 {
        let w = self.r * ang(v);
        let lv = self.r * lin(v) + self.p.cross(&w);
        stack(&lv, &w)
    }

    /// `Ad_g⁻¹ V`: a twist given in the parent frame, expressed in the child frame.
    #[inline]
    pub fn twist_to_child(&self, v: &Vec6) -> Vec6 {
        let w = ang(v);
        let lv = lin(v) - self.p.cross(&w);
        let rt = self.r.transpose();
        stack(&(rt * lv), &(rt * w))
    }

    /// `Ad_g⁻ᵀ F`: a wrench `[f; m]` given in the child frame (moment about the child
    /// origin), expressed in the parent frame (moment about the parent origin).
    #[inline]
    pub fn wrench_to_parent(&self, f: &Vec6) -> Vec6 {
        let force = self.r * lin(f);
        let moment = self.r * ang(f) + self.p.cross(&force);
        stack(&force, &moment)
    }

    /// `Ad_gᵀ F`: a wrench given in the parent frame, expressed in the child frame.
    #[inline]
    pub fn wrench_to_child(&self, f: &Vec6) -> Vec6 {
        let force = lin(f);
        let moment = ang(f) - self.p.cross(&force);
        let rt = self.r.transpose();
        stack(&(rt * force), &(rt * moment))
    }

    /// Express a spatial inertia given in the child frame in the parent frame:
    /// `Ad_g⁻ᵀ I Ad_g⁻¹`.
    pub fn inertia_to_parent(&self, i: &Mat6) -> Mat6 {
        let a = self.adjoint_inv();
        a.transpose() * i * a
    }
}

/// Rotation matrix of `angle` [rad] about the unit `axis` (Rodrigues).
#[inline]
pub fn rot_axis_angle(axis: &Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let k = skew(axis);
    Mat3::identity() + k * s + k * k * (1.0 - c)
}

/// The twist cross product matrix `ad_V = [[ω̂, v̂], [0, ω̂]]` for `V = [v; ω]`, so that
/// `ad_V W = V × W` (motion cross product).
pub fn ad(v: &Vec6) -> Mat6 {
    let vh = skew(&lin(v));
    let wh = skew(&ang(v));
    let mut m = Mat6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&wh);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&vh);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&wh);
    m
}

/// Motion cross product `V × W = ad_V W` without forming the matrix.
#[inline]
pub fn cross_motion(v: &Vec6, w: &Vec6) -> Vec6 {
    let (vl, va) = (lin(v), ang(v));
    let (wl, wa) = (lin(w), ang(w));
    stack(&(va.cross(&wl) + vl.cross(&wa)), &va.cross(&wa))
}

/// Force cross product `V ×* F = −ad_Vᵀ F` (the velocity-product term of Newton–Euler,
/// and the Kirchhoff term `V ×* (M_A V)` of docs/model.md §4).
#[inline]
pub fn cross_force(v: &Vec6, f: &Vec6) -> Vec6 {
    let (vl, va) = (lin(v), ang(v));
    let (fl, fa) = (lin(f), ang(f));
    stack(&va.cross(&fl), &(va.cross(&fa) + vl.cross(&fl)))
}

/// Rigid-body spatial inertia about a frame's origin, in that frame, for the `[v; ω]`
/// ordering: `[[m I, −m ĉ], [m ĉ, I_c − m ĉ ĉ]]` with mass `m` [kg], centre of mass `c` [m]
/// and rotational inertia `I_c` about the centre of mass [kg·m²].
pub fn rigid_inertia(m: f64, c: &Vec3, i_c: &Mat3) -> Mat6 {
    let ch = skew(c);
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Mat3::identity() * m));
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-m * ch));
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&(m * ch));
    out.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(i_c - m * ch * ch));
    out
}

/// Unit quaternion from a rotation matrix (assumed orthonormal).
pub fn quat_from_matrix(r: &Mat3) -> UnitQuaternion<f64> {
    UnitQuaternion::from_matrix(r)
}

/// Integrate a body-fixed angular velocity: `q ⊗ exp(ω dt / 2)`, renormalised.
/// `omega` in rad/s in the body frame, `dt` in seconds.
pub fn quat_integrate(q: &UnitQuaternion<f64>, omega: &Vec3, dt: f64) -> UnitQuaternion<f64> {
    let dq = UnitQuaternion::from_scaled_axis(omega * dt);
    UnitQuaternion::new_normalize(*(q * dq).quaternion())
}

/// Vector part of the quaternion error `q_d⁻¹ ⊗ q` with a non-negative scalar part, used as
/// the orientation error of the end-effector task (docs/model.md §5). Both quaternions map body
/// vectors to the inertial frame; the result is expressed in the current body frame's
/// orientation-error sense (`≈ ½ θ axis` for small errors).
pub fn quat_error_vec(q_d: &UnitQuaternion<f64>, q: &UnitQuaternion<f64>) -> Vec3 {
    let e: Quaternion<f64> = *(q.inverse() * q_d).quaternion();
    let s = if e.w < 0.0 { -1.0 } else { 1.0 };
    Vec3::new(e.i, e.j, e.k) * s
}

/// ZYX Euler angles (roll, pitch, yaw) [rad] of a rotation matrix, for plots only.
pub fn euler_zyx(r: &Mat3) -> Vec3 {
    let pitch = (-r[(2, 0)]).clamp(-1.0, 1.0).asin();
    let roll = r[(2, 1)].atan2(r[(2, 2)]);
    let yaw = r[(1, 0)].atan2(r[(0, 0)]);
    Vec3::new(roll, pitch, yaw)
}

/// Largest deviation of `RᵀR` from the identity and of `det R` from one; small for a rotation.
pub fn orthonormality_error(r: &Mat3) -> f64 {
    let e = (r.transpose() * r - Mat3::identity()).abs().max();
    e.max((r.determinant() - 1.0).abs())
}

/// Wrap an angle [rad] into `(−π, π]`.
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    let mut w = a.rem_euclid(2.0 * PI); // [0, 2π)
    if w > PI {
        w -= 2.0 * PI;
    }
    w
}

/// Heading ψ [rad] of a frame whose orientation in `I` is `r`: the yaw of its x axis about
/// the inertial +z axis, `ψ = atan2(R₁₀, R₀₀)` (equal to the ZYX yaw angle), in `(−π, π]`.
#[inline]
pub fn heading(r: &Mat3) -> f64 {
    r[(1, 0)].atan2(r[(0, 0)])
}

/// Time derivative ψ̇ [rad/s] of [`heading`] for a frame with orientation `r` (in `I`) and
/// body-fixed angular velocity `omega` (rad/s, in the same frame): with `Ṙ = R ω̂`,
/// `Ṙ e_x = R (ω × e_x) = R (0, ω_z, −ω_y)`, and `ψ̇ = (R₀₀ Ṙ₁₀ − R₁₀ Ṙ₀₀)/(R₀₀² + R₁₀²)`.
/// Equal to ω_z for a frame level in the horizontal plane; 0 when the x axis is vertical.
#[inline]
pub fn heading_rate(r: &Mat3, omega: &Vec3) -> f64 {
    let (r00, r10) = (r[(0, 0)], r[(1, 0)]);
    let d00 = r[(0, 1)] * omega.z - r[(0, 2)] * omega.y;
    let d10 = r[(1, 1)] * omega.z - r[(1, 2)] * omega.y;
    let den = r00 * r00 + r10 * r10;
    if den < 1e-12 {
        0.0
    } else {
        (r00 * d10 - r10 * d00) / den
    }
}

/// Gradient of [`heading`] with respect to the frame's body-fixed angular velocity: the row
/// `g(R)` with `ψ̇ = g(R)·ω` — [`heading_rate`] is linear in `ω`, so `g` is its value on the
/// unit vectors: `g = (0, R₁₀R₀₂ − R₀₀R₁₂, R₀₀R₁₁ − R₁₀R₀₁)/(R₀₀² + R₁₀²)`. Equal to `e_z`
/// for a frame level in the horizontal plane; zero when the x axis is vertical.
#[inline]
pub fn heading_gradient(r: &Mat3) -> Vec3 {
    Vec3::new(
        heading_rate(r, &Vec3::x()),
        heading_rate(r, &Vec3::y()),
        heading_rate(r, &Vec3::z()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_g() -> Se3 {
        let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
        Se3::new(rot_axis_angle(&axis, 0.7), Vec3::new(0.4, -1.2, 2.0))
    }

    #[test]
    fn adjoint_matches_vector_forms() {
        let g = sample_g();
        let v = Vec6::new(0.1, -0.2, 0.3, 1.1, -0.7, 0.25);
        // Closed-form identities; 1e-12 is a few ulps of O(1) products.
        assert!((g.adjoint() * v - g.twist_to_parent(&v)).norm() < 1e-12);
        assert!((g.adjoint_inv() * v - g.twist_to_child(&v)).norm() < 1e-12);
        assert!((g.adjoint_inv().transpose() * v - g.wrench_to_parent(&v)).norm() < 1e-12);
        assert!((g.adjoint().transpose() * v - g.wrench_to_child(&v)).norm() < 1e-12);
        assert!((g.adjoint() * g.adjoint_inv() - Mat6::identity()).norm() < 1e-12);
    }

    #[test]
    fn power_is_frame_invariant() {
        // Vᵀ F is the same in every frame.
        let g = sample_g();
        let v = Vec6::new(0.1, -0.2, 0.3, 1.1, -0.7, 0.25);
        let f = Vec6::new(3.0, 1.0, -2.0, 0.5, 0.1, -0.4);
        let p_child = v.dot(&f);
        let p_parent = g.twist_to_parent(&v).dot(&g.wrench_to_parent(&f));
        assert!((p_child - p_parent).abs() < 1e-12);
    }

    #[test]
    fn cross_products_match_ad() {
        let v = Vec6::new(0.1, -0.2, 0.3, 1.1, -0.7, 0.25);
        let w = Vec6::new(-0.4, 0.9, 0.2, 0.3, 0.6, -1.0);
        assert!((ad(&v) * w - cross_motion(&v, &w)).norm() < 1e-12);
        assert!((-ad(&v).transpose() * w - cross_force(&v, &w)).norm() < 1e-12);
    }

    #[test]
    fn rigid_inertia_gives_kinetic_energy() {
        // A point-like check: ½VᵀIV = ½m|v_c|² + ½ωᵀI_cω with v_c = v + ω × c.
        let m = 2.5;
        let c = Vec3::new(0.3, 0.1, -0.2);
        let ic = Mat3::from_diagonal(&Vec3::new(0.1, 0.2, 0.3));
        let i = rigid_inertia(m, &c, &ic);
        let v = Vec6::new(0.1, -0.2, 0.3, 1.1, -0.7, 0.25);
        let vc = lin(&v) + ang(&v).cross(&c);
        let direct = 0.5 * m * vc.norm_squared() + 0.5 * ang(&v).dot(&(ic * ang(&v)));
        assert!((0.5 * v.dot(&(i * v)) - direct).abs() < 1e-12);
        assert!((i - i.transpose()).norm() < 1e-14);
    }

    #[test]
    fn quaternion_integration_stays_unit() {
        let mut q = UnitQuaternion::identity();
        let w = Vec3::new(0.3, -1.0, 2.0);
        for _ in 0..10_000 {
            q = quat_integrate(&q, &w, 1e-3);
        }
        assert!((q.quaternion().norm() - 1.0).abs() < 1e-14);
        // Constant body rate: exact rotation by |w| t about w.
        let exact = UnitQuaternion::from_scaled_axis(w * 10.0);
        assert!(q.angle_to(&exact) < 1e-9);
    }

    #[test]
    fn euler_roundtrip() {
        let r = UnitQuaternion::from_euler_angles(0.2, -0.4, 1.3);
        let e = euler_zyx(r.to_rotation_matrix().matrix());
        assert!((e - Vec3::new(0.2, -0.4, 1.3)).norm() < 1e-12);
    }

    #[test]
    fn wrap_angle_range() {
        for (a, w) in [
            (0.0, 0.0),
            (PI, PI),
            (-PI, PI),
            (3.0 * PI, PI),
            (1.5 * PI, -0.5 * PI),
            (-1.5 * PI, 0.5 * PI),
            (7.0, 7.0 - 2.0 * PI),
        ] {
            assert!(
                (wrap_angle(a) - w).abs() < 1e-12,
                "{a} -> {}",
                wrap_angle(a)
            );
        }
    }

    #[test]
    fn heading_rate_matches_difference() {
        let r = rot_axis_angle(&Vec3::new(0.3, 0.5, 0.8).normalize(), 0.9);
        let w = Vec3::new(0.2, -0.4, 0.7);
        let h = 1e-6;
        let rp = r * rot_axis_angle(&w.normalize(), w.norm() * h);
        let rm = r * rot_axis_angle(&w.normalize(), -w.norm() * h);
        let fd = wrap_angle(heading(&rp) - heading(&rm)) / (2.0 * h);
        // Central difference of an O(1) smooth function: error ~h² + 1e-16/h ≈ 1e-10.
        assert!((heading_rate(&r, &w) - fd).abs() < 1e-8);
    }
}

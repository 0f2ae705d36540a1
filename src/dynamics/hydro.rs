//! Hydrodynamic and hydrostatic kernels (docs/model.md §2, §4): pure functions of one body's local
//! quantities, MuJoCo style. Every twist is the body's *relative* twist
//! `V_r = V − [R_Iiᵀ ν_c; 0]` (m/s, rad/s) in the body frame (origin at the rear face, x
//! towards the head), and every returned wrench `[f; m]` (N, N·m) acts on the body, in the
//! body frame, with the moment about the body frame's origin.

use super::manoeuvring::ManoeuvringKernel;
use crate::model::{Body, Hydro};
use crate::spatial::{Mat3, Mat6, Vec3, Vec6};

/// Strip-theory drag of a slender cylinder along its body x axis (docs/model.md §2), with the
/// constants folded in once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylinderDrag {
    /// `½ ρ C_d,x π r²` [kg/m]: axial force `−k_axial |u| u`.
    pub k_axial: f64,
    /// `½ ρ C_d,y (2r) Δs` [kg/m]: cross-flow force of one strip along y.
    pub k_strip_y: f64,
    /// `½ ρ C_d,z (2r) Δs` [kg/m]: cross-flow force of one strip along z.
    pub k_strip_z: f64,
    /// Body length `l` [m]; the cylinder spans `x ∈ [0, l]`.
    pub length: f64,
    /// Number of strips `N` (midpoint rule, strip centres at `(k + ½) l / N`).
    pub strips: usize,
    /// Linear damping `[N·s/m ×3, N·m·s/rad ×3]` on the relative twist at the geometric
    /// centre `(l/2, 0, 0)`.
    pub linear: [f64; 6],
}

impl CylinderDrag {
    /// Constants for a cylinder of radius `radius` and length `length` [m] in fluid of
    /// density `rho` [kg/m³]; `strips` is clamped to at least 1.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        rho: f64,
        radius: f64,
        length: f64,
        cd_x: f64,
        cd_y: f64,
        cd_z: f64,
        linear: [f64; 6],
        strips: usize,
    ) -> Self {
        let strips = strips.max(1);
        let ds = length / strips as f64;
        Self {
            k_axial: 0.5 * rho * cd_x * std::f64::consts::PI * radius * radius,
            k_strip_y: 0.5 * rho * cd_y * 2.0 * radius * ds,
            k_strip_z: 0.5 * rho * cd_z * 2.0 * radius * ds,
            length,
            strips,
            linear,
        }
    }

    /// The damping wrench on the body for relative twist `v_r` (docs/model.md §2):
    /// cross-flow `−½ρ C_d,y|z (2r) |v⊥(s)| v⊥(s)` per unit length with
    /// `v⊥(s) = (0, v_y + ω_z s, v_z − ω_y s)` integrated by the midpoint rule (so rotation
    /// makes moments), axial `−½ρ C_d,x πr² |u| u`, and linear damping at the centre.
    #[inline]
    pub fn wrench(&self, v_r: &Vec6) -> Vec6 {
        let (u, vy, vz) = (v_r[0], v_r[1], v_r[2]);
        let (wx, wy, wz) = (v_r[3], v_r[4], v_r[5]);
        let ds = self.length / self.strips as f64;
        let (mut fy, mut fz, mut my, mut mz) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..self.strips {
            let s = (k as f64 + 0.5) * ds;
            let py = vy + wz * s;
            let pz = vz - wy * s;
            let sp = (py * py + pz * pz).sqrt();
            let dfy = -self.k_strip_y * sp * py;
            let dfz = -self.k_strip_z * sp * pz;
            fy += dfy;
            fz += dfz;
            // (s e_x) × (0, dfy, dfz) = (0, −s dfz, s dfy)
            my -= s * dfz;
            mz += s * dfy;
        }
        let fx = -self.k_axial * u.abs() * u;
        // Linear damping on the twist at the centre c = (l/2, 0, 0): v_c = v + ω × c.
        let cx = 0.5 * self.length;
        let d = &self.linear;
        let (ly, lz) = (-d[1] * (vy + wz * cx), -d[2] * (vz - wy * cx));
        let lx = -d[0] * u;
        // Moment about the origin: m_c + c × f_c, c × (lx, ly, lz) = (0, −cx lz, cx ly).
        Vec6::new(
            fx + lx,
            fy + ly,
            fz + lz,
            -d[3] * wx,
            my - d[4] * wy - cx * lz,
            mz - d[5] * wz + cx * ly,
        )
    }
}

/// Coefficient damping about the body frame origin (docs/model.md §2 `Hydro::Coefficients`):
/// `−(D_l ν_r + D_q (|ν_r| ∘ ν_r))`, `v_r` the relative twist.
#[inline]
pub fn coefficient_damping(d_l: &Mat6, d_q: &Mat6, v_r: &Vec6) -> Vec6 {
    let quad = v_r.component_mul(&v_r.abs());
    -(d_l * v_r + d_q * quad)
}

/// A body's damping model, resolved once from its [`Hydro`] description.
// One per body in a workspace vector: keeping the matrices inline (no Box) is the point.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum DampingKernel {
    /// Strip-theory cylinder drag.
    Cylinder(CylinderDrag),
    /// Linear and quadratic damping matrices.
    Coefficients {
        /// `D_l`.
        linear: Mat6,
        /// `D_q`.
        quadratic: Mat6,
    },
    /// Manoeuvring derivatives of a streamlined hull (NPS AUV II, docs/model.md §8 case 3).
    Manoeuvring(Box<ManoeuvringKernel>),
}

impl DampingKernel {
    /// Resolve the damping model of `body` in fluid of density `rho` [kg/m³].
    pub fn of(body: &Body, rho: f64) -> Self {
        match &body.hydro {
            Hydro::Cylinder {
                cd_x,
                cd_y,
                cd_z,
                linear_damping,
                strips,
                ..
            } => DampingKernel::Cylinder(CylinderDrag::new(
                rho,
                body.radius,
                body.length,
                *cd_x,
                *cd_y,
                *cd_z,
                *linear_damping,
                *strips,
            )),
            Hydro::Coefficients {
                linear, quadratic, ..
            } => DampingKernel::Coefficients {
                linear: *linear,
                quadratic: *quadratic,
            },
            Hydro::Manoeuvring(m) => {
                DampingKernel::Manoeuvring(Box::new(ManoeuvringKernel::new(m)))
            }
        }
    }

    /// Whether the dynamics add the Kirchhoff term `V_r ×* (M_A V_r)` of the added mass for
    /// this body: yes, except for manoeuvring derivatives whose velocity-product table is
    /// the whole measured hull force (MSS `npsauv.m` has no `C_A`), unless their
    /// [`Manoeuvring::kirchhoff`](crate::model::manoeuvring::Manoeuvring::kirchhoff) asks for
    /// it.
    #[inline]
    pub fn kirchhoff(&self) -> bool {
        match self {
            DampingKernel::Manoeuvring(k) => k.model.kirchhoff,
            _ => true,
        }
    }

    /// The damping wrench for relative twist `v_r` (body frame, about its origin).
    #[inline]
    pub fn wrench(&self, v_r: &Vec6) -> Vec6 {
        match self {
            DampingKernel::Cylinder(c) => c.wrench(v_r),
            DampingKernel::Coefficients { linear, quadratic } => {
                coefficient_damping(linear, quadratic, v_r)
            }
            DampingKernel::Manoeuvring(k) => k.wrench(v_r),
        }
    }
}

/// Hydrostatic parameters of one body (docs/model.md §4 restoring forces).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Restoring {
    /// Weight `m g` [N].
    pub weight: f64,
    /// Buoyancy `ρ V g` [N].
    pub buoyancy: f64,
    /// Centre of gravity in the body frame [m].
    pub cg: Vec3,
    /// Centre of buoyancy in the body frame [m].
    pub cb: Vec3,
}

impl Restoring {
    /// Weight and buoyancy of `body` in fluid of density `rho` [kg/m³] under gravity `g`
    /// [m/s²].
    pub fn of(body: &Body, rho: f64, g: f64) -> Self {
        Self {
            weight: body.mass * g,
            buoyancy: rho * body.volume * g,
            cg: body.cg,
            cb: body.cb,
        }
    }

    /// The restoring wrench on the body (docs/model.md §4, USM-19 `N`): weight `−m g e_z` at the CG
    /// and buoyancy `+ρ V g e_z` at the CB, both along the inertial vertical. `r_ii` is the
    /// body's orientation `R_Ii` (body → inertial).
    #[inline]
    pub fn wrench(&self, r_ii: &Mat3) -> Vec6 {
        // Inertial up e_z in body coordinates: the third row of R_Ii.
        let up = Vec3::new(r_ii[(2, 0)], r_ii[(2, 1)], r_ii[(2, 2)]);
        let f_w = up * (-self.weight);
        let f_b = up * self.buoyancy;
        let f = f_w + f_b;
        let m = self.cg.cross(&f_w) + self.cb.cross(&f_b);
        Vec6::new(f.x, f.y, f.z, m.x, m.y, m.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{ang, lin};
    use proptest::prelude::*;

    fn cyl() -> CylinderDrag {
        CylinderDrag::new(
            1026.0,
            0.085,
            0.6,
            0.8,
            1.0,
            1.2,
            [1.0, 2.0, 3.0, 0.05, 0.1, 0.2],
            7,
        )
    }

    /// Reference: the same integral written point by point in a different way (wrench of
    /// each strip moved to the origin with the general formula `m = p × f`).
    fn reference(c: &CylinderDrag, v: &Vec6) -> Vec6 {
        let ds = c.length / c.strips as f64;
        let mut w = Vec6::zeros();
        for k in 0..c.strips {
            let p = Vec3::new((k as f64 + 0.5) * ds, 0.0, 0.0);
            let vp = lin(v) + ang(v).cross(&p);
            let perp = Vec3::new(0.0, vp.y, vp.z);
            let f = Vec3::new(
                0.0,
                -c.k_strip_y * perp.norm() * perp.y,
                -c.k_strip_z * perp.norm() * perp.z,
            );
            let m = p.cross(&f);
            w += Vec6::new(f.x, f.y, f.z, m.x, m.y, m.z);
        }
        w[0] -= c.k_axial * v[0].abs() * v[0];
        let cc = Vec3::new(c.length / 2.0, 0.0, 0.0);
        let vc = lin(v) + ang(v).cross(&cc);
        let fl = -Vec3::new(c.linear[0] * vc.x, c.linear[1] * vc.y, c.linear[2] * vc.z);
        let ml = -Vec3::new(c.linear[3] * v[3], c.linear[4] * v[4], c.linear[5] * v[5]);
        let m = ml + cc.cross(&fl);
        w + Vec6::new(fl.x, fl.y, fl.z, m.x, m.y, m.z)
    }

    #[test]
    fn pure_translation_drag_closed_form() {
        // A cylinder in pure cross-flow v_y: every strip sees the same v, so the total is
        // exactly −½ρ C_d,y (2r) l v|v| − d_y v (docs/model.md §2), acting at the centre.
        let c = cyl();
        let v = 0.7;
        let w = c.wrench(&Vec6::new(0.0, v, 0.0, 0.0, 0.0, 0.0));
        let expect = -0.5 * 1026.0 * 1.0 * 2.0 * 0.085 * 0.6 * v * v - 2.0 * v;
        // Sum of 7 equal terms: a few ulps of relative error.
        assert!((w[1] - expect).abs() < 1e-12 * expect.abs());
        // Moment about the origin = centre × force.
        assert!((w[5] - 0.3 * w[1]).abs() < 1e-12 * expect.abs());
        // Axial.
        let w = c.wrench(&Vec6::new(-0.4, 0.0, 0.0, 0.0, 0.0, 0.0));
        let expect = 0.5 * 1026.0 * 0.8 * std::f64::consts::PI * 0.085f64.powi(2) * 0.16 + 0.4;
        assert!((w[0] - expect).abs() < 1e-12 * expect);
    }

    #[test]
    fn pure_rotation_about_centre_has_no_net_strip_force() {
        // Yaw about the geometric centre: v_y(s) = ω (s − l/2) is odd about the centre, so the
        // strip forces cancel in pairs (midpoint rule is symmetric) and only a moment remains.
        let c = cyl();
        let w = 0.9;
        let v = Vec6::new(0.0, -w * 0.3, 0.0, 0.0, 0.0, w);
        let f = c.wrench(&v);
        // Cancellation of O(10) N terms: 1e-12 absolute.
        assert!(f[1].abs() < 1e-12, "{}", f[1]);
        assert!(f[5] < 0.0, "the moment opposes the rotation");
    }

    proptest! {
        #[test]
        fn cylinder_matches_reference_and_dissipates(
            v in proptest::array::uniform6(-2.0f64..2.0)
        ) {
            let c = cyl();
            let v = Vec6::from_row_slice(&v);
            let w = c.wrench(&v);
            // Two evaluation orders of the same O(100) N sums: 1e-10 absolute.
            prop_assert!((w - reference(&c, &v)).norm() < 1e-10);
            // Drag and linear damping only remove energy: Vᵀ F ≤ 0.
            prop_assert!(v.dot(&w) <= 1e-12);
        }

        #[test]
        fn coefficient_damping_dissipates_for_diagonal_psd(
            v in proptest::array::uniform6(-2.0f64..2.0)
        ) {
            let v = Vec6::from_row_slice(&v);
            let dl = Mat6::from_diagonal(&Vec6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3));
            let dq = Mat6::from_diagonal(&Vec6::new(10.0, 20.0, 30.0, 1.0, 2.0, 3.0));
            let w = coefficient_damping(&dl, &dq, &v);
            prop_assert!(v.dot(&w) <= 0.0);
            for i in 0..6 {
                let e = -(dl[(i, i)] * v[i] + dq[(i, i)] * v[i].abs() * v[i]);
                prop_assert!((w[i] - e).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn restoring_upright_and_tilted() {
        let r = Restoring {
            weight: 100.0,
            buoyancy: 120.0,
            cg: Vec3::new(0.3, 0.0, -0.05),
            cb: Vec3::new(0.3, 0.0, 0.0),
        };
        // Level: net +20 N up; weight at x = 0.3 gives +30 N·m about y, buoyancy −36 N·m.
        let w = r.wrench(&Mat3::identity());
        assert!((w - Vec6::new(0.0, 0.0, 20.0, 0.0, 30.0 - 36.0, 0.0)).norm() < 1e-12);
        // Rolled by 0.3 rad: the metacentric moment −(m g) z_g sin φ about x brings it back.
        let rot = *nalgebra::Rotation3::from_euler_angles(0.3, 0.0, 0.0).matrix();
        let w = r.wrench(&rot);
        let expect_mx = -100.0 * 0.05 * 0.3f64.sin();
        assert!((w[3] - expect_mx).abs() < 1e-12);
    }
}

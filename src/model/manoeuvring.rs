//! Manoeuvring-derivative hydrodynamics of a streamlined hull (SNAME / Healey & Lienard
//! style, the form of the NPS AUV II model in Fossen's MSS; docs/model.md §8 case 3): constant added
//! mass, velocity-product derivatives, a quadratic resistance and a strip-theory cross-flow
//! drag, all about a reference point `CO` in axes of their own.
//!
//! The coefficients are dimensional (the prime values already scaled by `½ρL²…½ρL⁵` for the
//! fluid the vehicle was built for, see [`crate::paper::nps_auv2`]). Unlike
//! [`super::Hydro::Coefficients`], the velocity-product table is by default the *measured*
//! force of the moving hull, which includes what the Kirchhoff term `V_r ×* (M_A V_r)` would
//! add; the dynamics then leave that term out for such a body ([`Manoeuvring::kirchhoff`],
//! [`crate::dynamics::hydro::DampingKernel::kirchhoff`]).

use crate::spatial::{Mat3, Mat6, Vec3, Vec6};

/// Strip-theory cross-flow drag (MSS `npsauv.m`, Fossen's "cross-flow drag"): at stations
/// `x_k` along the derivative frame's x axis, each of width `width`, the local cross-flow
/// `(v + x r, w − x q)` of speed `U` makes the force
/// `−½ρ width (k_y v_x² + k_z w_x²) (v_x, w_x)/U` (y and z), with its moment about `CO`.
#[derive(Clone, Debug, PartialEq)]
pub struct CrossFlow {
    /// Station positions along x of the derivative frame [m] (MSS: 11 stations from −L/2 to
    /// L/2).
    pub stations: Vec<f64>,
    /// Width each station stands for [m] (MSS: L/10, so the stations cover 1.1 L).
    pub width: f64,
    /// `½ρ C_d,y H` [kg/m²]: lateral drag coefficient times the body height, times `½ρ`.
    pub k_y: f64,
    /// `½ρ C_d,z B` [kg/m²]: vertical drag coefficient times the body width, times `½ρ`.
    pub k_z: f64,
}

/// The hydrodynamic description of one hull in its derivative frame (origin `CO`, axes
/// `axes` relative to the body frame). Every quantity acts on the relative twist
/// `ν_r = [u, v, w, p, q, r]` at `CO` in those axes [m/s, rad/s] and gives a wrench
/// `[X, Y, Z, K, M, N]` [N, N·m] about `CO` in those axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Manoeuvring {
    /// Origin `CO` of the derivative frame in the body frame [m].
    pub origin: Vec3,
    /// Orientation of the derivative axes in the body frame (`R_body←derivative`); for
    /// SNAME axes (y starboard, z down) on a body frame with y to port and z up:
    /// `diag(1, −1, −1)`.
    pub axes: Mat3,
    /// Added mass about `CO` in the derivative axes [kg, kg·m, kg·m²], symmetric PSD.
    pub added_mass: Mat6,
    /// Velocity-product derivatives: force component `i` is `ν_rᵀ P_i ν_r` (MSS's
    /// `Yv·u·v`, `Nr·u·r`, `Xvv·v²`, … with their `½ρLᵏ` factors) [N or N·m per (m/s)²].
    pub products: [Mat6; 6],
    /// Quadratic resistance on each component: `−d_i |ν_i| ν_i` (NPS AUV II: surge
    /// `Cd0 ½ρL²`) [N·s²/m², N·m·s²].
    pub quadratic: Vec6,
    /// Cross-flow drag strips.
    pub crossflow: CrossFlow,
    /// Also apply the added mass's Kirchhoff term `V_r ×* (M_A V_r)` (Fossen's
    /// `C_A(ν_r) ν_r`, which carries the Munk moment `(M_A,22 − M_A,11) u v`) on top of the
    /// table. `false` for MSS `npsauv.m`, whose table is the whole measured force; `true`
    /// reads the derivatives as damping `D(ν_r)` beside Fossen's `C_A` (the form of AC-3).
    pub kirchhoff: bool,
}

impl Manoeuvring {
    /// Added mass about the body frame's origin in body axes (`Ad⁻ᵀ M_A Ad⁻¹` of the
    /// derivative frame `(axes, origin)`) [kg, kg·m, kg·m²].
    pub fn added_mass_in_body(&self) -> Mat6 {
        crate::spatial::Se3::new(self.axes, self.origin).inertia_to_parent(&self.added_mass)
    }

    /// The first non-finite coefficient's name, if any (for `Vehicle::validate`).
    pub fn first_non_finite(&self) -> Option<&'static str> {
        let c = &self.crossflow;
        let checks: [(&'static str, bool); 7] = [
            ("origin", self.origin.iter().all(|x| x.is_finite())),
            ("axes", self.axes.iter().all(|x| x.is_finite())),
            ("added_mass", self.added_mass.iter().all(|x| x.is_finite())),
            (
                "products",
                self.products.iter().flatten().all(|x| x.is_finite()),
            ),
            ("quadratic", self.quadratic.iter().all(|x| x.is_finite())),
            (
                "crossflow.stations",
                c.stations.iter().all(|x| x.is_finite()),
            ),
            (
                "crossflow",
                [c.width, c.k_y, c.k_z].iter().all(|x| x.is_finite()),
            ),
        ];
        checks.iter().find(|(_, ok)| !ok).map(|(k, _)| *k)
    }
}

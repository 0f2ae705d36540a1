//! The manoeuvring-derivative kernel (SPEC §8 case 3, [`Manoeuvring`]): a pure function of
//! one body's relative twist `V_r` (body frame, at its origin) returning the hydrodynamic
//! wrench other than inertia (body frame, about its origin), split into its three parts so
//! that reports can say which term carries a force.

use crate::model::manoeuvring::{CrossFlow, Manoeuvring};
use crate::spatial::{Se3, Vec6};

/// The three parts of the manoeuvring wrench, each `[f; m]` in the body frame about its
/// origin [N, N·m].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ManoeuvringParts {
    /// Velocity-product derivatives `ν_rᵀ P_i ν_r` (lift, Munk moment, coupling).
    pub products: Vec6,
    /// Quadratic resistance `−d_i |ν_i| ν_i`.
    pub resistance: Vec6,
    /// Strip-theory cross-flow drag.
    pub crossflow: Vec6,
}

impl ManoeuvringParts {
    /// The total wrench.
    pub fn total(&self) -> Vec6 {
        self.products + self.resistance + self.crossflow
    }
}

/// A resolved [`Manoeuvring`] model: the coefficients and the derivative frame `g` (`CO`
/// and its axes in the body frame).
#[derive(Clone, Debug, PartialEq)]
pub struct ManoeuvringKernel {
    /// The coefficients (derivative frame).
    pub model: Manoeuvring,
    g: Se3,
}

/// Cross-flow wrench about `CO` in the derivative axes for `ν = [u v w p q r]` there: at each
/// station `x`, `(v_x, w_x) = (v + x r, w − x q)`, `U = |(v_x, w_x)|`, force
/// `−width (k_y v_x² + k_z w_x²) (v_x, w_x)/U` on y and z, moments `(0, −x F_z, x F_y)`.
fn crossflow(c: &CrossFlow, nu: &Vec6) -> Vec6 {
    let (v, w, q, r) = (nu[1], nu[2], nu[4], nu[5]);
    let (mut fy, mut fz, mut m, mut n) = (0.0, 0.0, 0.0, 0.0);
    for &x in &c.stations {
        let (vx, wx) = (v + x * r, w - x * q);
        let u = vx.hypot(wx);
        if u == 0.0 {
            continue;
        }
        let d = c.width * (c.k_y * vx * vx + c.k_z * wx * wx) / u;
        let (dy, dz) = (-d * vx, -d * wx);
        fy += dy;
        fz += dz;
        m -= x * dz;
        n += x * dy;
    }
    Vec6::new(0.0, fy, fz, 0.0, m, n)
}

impl ManoeuvringKernel {
    /// Resolve `model` (its coefficients are dimensional already).
    pub fn new(model: &Manoeuvring) -> Self {
        Self {
            g: Se3::new(model.axes, model.origin),
            model: model.clone(),
        }
    }

    /// The three parts of the wrench for the relative twist `v_r` (body frame, at the body
    /// origin).
    pub fn parts(&self, v_r: &Vec6) -> ManoeuvringParts {
        let nu = self.g.twist_to_child(v_r);
        let m = &self.model;
        let products = Vec6::from_fn(|i, _| nu.dot(&(m.products[i] * nu)));
        let resistance = -m.quadratic.component_mul(&nu.abs().component_mul(&nu));
        ManoeuvringParts {
            products: self.g.wrench_to_parent(&products),
            resistance: self.g.wrench_to_parent(&resistance),
            crossflow: self.g.wrench_to_parent(&crossflow(&m.crossflow, &nu)),
        }
    }

    /// The total wrench for `v_r` (see [`Self::parts`]).
    #[inline]
    pub fn wrench(&self, v_r: &Vec6) -> Vec6 {
        self.parts(v_r).total()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::nps_auv2::{nps_auv2_hydro, LENGTH, RHO};
    use proptest::prelude::*;

    fn kernel() -> ManoeuvringKernel {
        ManoeuvringKernel::new(&nps_auv2_hydro(RHO))
    }

    /// `v_r` at the body origin for a twist `nu` at CO in SNAME axes.
    fn at_origin(k: &ManoeuvringKernel, nu: &Vec6) -> Vec6 {
        k.g.twist_to_parent(nu)
    }

    #[test]
    fn pure_sway_matches_the_mss_expressions() {
        // u = 0, v = 0.2 m/s (SNAME): X = r2 Xvv v², Z = r2 Zvv v², M = r3 Mvv v², and the
        // cross-flow −½ρ (L/10)·11·Cdy·Hx·v|v| on Y with no yaw moment (symmetric stations).
        let k = kernel();
        let v = 0.2;
        let nu = Vec6::new(0.0, v, 0.0, 0.0, 0.0, 0.0);
        let p = k.parts(&at_origin(&k, &nu));
        let back = |w: &Vec6| k.g.wrench_to_child(w);
        let (r2, r3) = (0.5 * RHO * LENGTH.powi(2), 0.5 * RHO * LENGTH.powi(3));
        let prod = back(&p.products);
        assert!((prod[0] - r2 * 5.3e-2 * v * v).abs() < 1e-9);
        assert!((prod[2] - r2 * -6.8e-2 * v * v).abs() < 1e-9);
        assert!((prod[4] - r3 * -2.6e-2 * v * v).abs() < 1e-9);
        let cf = back(&p.crossflow);
        let expect = -0.5 * RHO * 0.5 * 0.53 * 1.1 * LENGTH * v * v;
        assert!((cf[1] - expect).abs() < 1e-9 * expect.abs(), "{}", cf[1]);
        assert!(cf[5].abs() < 1e-9, "{}", cf[5]);
    }

    proptest! {
        #[test]
        fn resistance_and_crossflow_dissipate(v in proptest::array::uniform6(-2.0f64..2.0)) {
            // The drag parts never add energy: V_rᵀ F ≤ 0 (the velocity products may: they
            // are lift terms, linear in the surge speed).
            let k = kernel();
            let v = Vec6::from_row_slice(&v);
            let p = k.parts(&v);
            prop_assert!(v.dot(&p.resistance) <= 1e-12);
            prop_assert!(v.dot(&p.crossflow) <= 1e-9);
        }
    }
}

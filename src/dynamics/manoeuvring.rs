//! The manoeuvring-derivative kernel (docs/model.md §8 case 3, [`Manoeuvring`]): a pure function of
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

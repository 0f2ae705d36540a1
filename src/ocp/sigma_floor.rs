//! A lower bound on the commanded-axis σ_min of the scaled thruster matrix along the optimum
//! (issue 40 item 4, docs/ocp.md §1 "σ_min floor"): stay away from singular configurations.
//!
//! ```text
//! (Σ1)  σ(q) = σ_min(S T_L(q)),   T_L = diag(1, 1, 1, 1/L, 1/L, 1/L) T(q)   (docs/model.md §6)
//! (Σ2)  b_σ(x) = −μ Δt ln(σ(q) − σ_lo)           (+∞ where σ(q) ≤ σ_lo), every knot
//! (Σ3)  ∇_q σ by central differences (ε = 1e-6 rad; 2n thruster matrices per knot)
//! (Σ4)  ∇²b_σ ≈ μ Δt ∇σ ∇σᵀ / (σ − σ_lo)²        (Gauss–Newton: the −μΔt ∇²σ/(σ − σ_lo) term is left out)
//! ```
//!
//! `T(q)` is the thruster matrix in the base frame `F_b` (USM-26), so σ depends on the joint
//! angles only (tangent `δq_i` at 6 + i). `S` keeps the commanded axes `dofs` (surge … yaw),
//! `L` [m] is the characteristic length (default half the vehicle's length, as the project's
//! `metrics.char_length`). σ_min is the weakest commanded scaled wrench per newton of thrust
//! norm ([`commanded_sigma`]); it is not differentiable where two singular values cross, where
//! (Σ3) returns a one-sided mix — the barrier's line search still rejects every trial point
//! below the floor, so **every iterate, hence the returned solution, has σ > σ_lo at every
//! knot** (the same argument as the joint-limit barrier of [`super::cost`]). The barrier lives in
//! its own kinematics workspace, so it never disturbs the dynamics' cached terms.

use crate::input::document::Document;
use crate::input::located::InputError;
use crate::kinematics::{forward_kinematics, thruster_matrix, KinWorkspace};
use crate::metrics::singularity::{commanded_sigma, CommandedDofs};
use crate::model::Vehicle;
use nalgebra::{DMatrix, Matrix6xX};

/// Step of the central differences (Σ3) [rad].
const EPS: f64 = 1e-6;

/// The σ_min floor of a chain (module documentation), with its scratch.
#[derive(Clone, Debug)]
pub struct SigmaFloor {
    /// σ_lo, the floor [N/N] (> 0).
    pub lo: f64,
    /// Barrier weight μ [objective units / s].
    pub mu: f64,
    /// The commanded axes `S`.
    pub dofs: CommandedDofs,
    /// Characteristic length `L` [m].
    pub char_length: f64,
    kin: KinWorkspace,
    t: Matrix6xX<f64>,
    q: Vec<f64>,
    grad: Vec<f64>,
}

impl SigmaFloor {
    /// The floor `lo` over the axes `dofs` of `vehicle`'s scaled `T(q)` (length `char_length`
    /// [m]), barrier weight `mu`.
    pub fn new(vehicle: &Vehicle, lo: f64, mu: f64, dofs: CommandedDofs, char_length: f64) -> Self {
        Self {
            lo,
            mu,
            dofs,
            char_length,
            kin: KinWorkspace::new(vehicle),
            t: Matrix6xX::zeros(vehicle.n_thrusters()),
            q: vec![0.0; vehicle.n_joints()],
            grad: vec![0.0; vehicle.n_joints()],
        }
    }

    /// σ(q) of (Σ1) at the joint angles `q` [rad].
    pub fn sigma(&mut self, vehicle: &Vehicle, q: &[f64]) -> f64 {
        forward_kinematics(vehicle, q, &mut self.kin);
        thruster_matrix(vehicle, &self.kin, &mut self.t);
        commanded_sigma(&self.t, self.char_length, self.dofs).sigma_min
    }

    /// b_σ of (Σ2) at the joint angles `q` for a step `dt` [s]: +∞ at or below the floor (or
    /// for a non-finite σ).
    pub fn value(&mut self, vehicle: &Vehicle, dt: f64, q: &[f64]) -> f64 {
        let s = self.sigma(vehicle, q) - self.lo;
        if s > 0.0 {
            -self.mu * dt * s.ln()
        } else {
            f64::INFINITY
        }
    }

    /// ∇_q σ at `q` by (Σ3) into the scratch gradient; returns σ(q) − σ_lo.
    fn gradient(&mut self, vehicle: &Vehicle, q: &[f64]) -> f64 {
        let s = self.sigma(vehicle, q) - self.lo;
        // The scratch point is taken out of `self` while `sigma` borrows it mutably.
        let mut p = std::mem::take(&mut self.q);
        p.copy_from_slice(q);
        for i in 0..q.len() {
            p[i] = q[i] + EPS;
            let hi = self.sigma(vehicle, &p);
            p[i] = q[i] - EPS;
            let lo = self.sigma(vehicle, &p);
            p[i] = q[i];
            self.grad[i] = (hi - lo) / (2.0 * EPS);
        }
        self.q = p;
        s
    }

    /// Add the gradient and the Gauss–Newton Hessian (Σ4) of b_σ at the joint angles `q` to
    /// `g`, `h` (tangent `δq_i` at 6 + i); nothing outside the floor's domain.
    pub fn add_derivatives(
        &mut self,
        vehicle: &Vehicle,
        dt: f64,
        q: &[f64],
        g: &mut [f64],
        h: &mut DMatrix<f64>,
    ) {
        let s = self.gradient(vehicle, q);
        if s.is_nan() || s <= 0.0 {
            return;
        }
        let w = self.mu * dt;
        for i in 0..q.len() {
            g[6 + i] -= w * self.grad[i] / s;
            for j in 0..q.len() {
                h[(6 + i, 6 + j)] += w * self.grad[i] * self.grad[j] / (s * s);
            }
        }
    }

    /// Largest α ≤ 1 (halving) with `σ(q + α dq) − σ_lo` at least 1 % of `σ(q) − σ_lo`
    /// (fraction to the boundary τ = 0.99, evaluated on the nonlinear σ); 1 when `q` is
    /// already outside the domain (the line search then decides).
    pub fn max_step(&mut self, vehicle: &Vehicle, q: &[f64], dq: &[f64]) -> f64 {
        let s0 = self.sigma(vehicle, q) - self.lo;
        if s0.is_nan() || s0 <= 0.0 {
            return 1.0;
        }
        let mut alpha = 1.0;
        let mut trial = std::mem::take(&mut self.q);
        while alpha > 1e-10 {
            for i in 0..q.len() {
                trial[i] = q[i] + alpha * dq[i];
            }
            if self.sigma(vehicle, &trial) - self.lo >= 0.01 * s0 {
                break;
            }
            alpha *= 0.5;
        }
        self.q = trial;
        alpha
    }

    /// The least σ over the knots `xs` (chain states, joint angles at 7 …) [N/N].
    pub fn least_along(&mut self, vehicle: &Vehicle, xs: &[Vec<f64>]) -> f64 {
        let n = vehicle.n_joints();
        xs.iter()
            .map(|x| self.sigma(vehicle, &x[7..7 + n]))
            .fold(f64::INFINITY, f64::min)
    }
}

/// A σ_min floor of a problem file (`[bounds] sigma_min`, `sigma_axes`, `char_length`).
#[derive(Clone, Debug, PartialEq)]
pub struct SigmaFloorSpec {
    /// σ_lo [N/N] (> 0).
    pub lo: f64,
    /// The commanded axes, surge … yaw.
    pub axes: [bool; 6],
    /// Characteristic length L [m] (> 0).
    pub char_length: f64,
}

/// The `[bounds]` keys of the floor, as read.
#[derive(Clone, Copy, Debug)]
pub(super) struct SigmaKeys<'a> {
    pub sigma_min: Option<f64>,
    pub sigma_axes: Option<&'a [String]>,
    pub char_length: Option<f64>,
}

/// Names of the six axes in `bounds.sigma_axes`, in the order of `T(q)`'s rows.
pub const AXES: [&str; 6] = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

/// The σ_min floor keys, validated: σ_lo positive and finite, the design has thrusters, the
/// axes known and distinct, L positive, and σ at the initial joint angles (and at the terminal
/// ones, when the terminal equality fixes them) above the floor — the barrier needs a
/// strictly feasible start.
pub(super) fn check_sigma_floor(
    doc: &Document,
    b: SigmaKeys<'_>,
    vehicle: &Vehicle,
    joint_angles: &[f64],
    terminal_joints: Option<&[f64]>,
) -> Result<Option<SigmaFloorSpec>, InputError> {
    let Some(lo) = b.sigma_min else {
        for (k, given) in [
            ("bounds.sigma_axes", b.sigma_axes.is_some()),
            ("bounds.char_length", b.char_length.is_some()),
        ] {
            if given {
                return Err(doc.err(k, "applies only with bounds.sigma_min"));
            }
        }
        return Ok(None);
    };
    if !(lo.is_finite() && lo > 0.0) {
        return Err(doc.err("bounds.sigma_min", "must be positive and finite [N/N]"));
    }
    if vehicle.n_thrusters() == 0 {
        return Err(doc.err("bounds.sigma_min", "the design has no thrusters"));
    }
    let mut axes = [false; 6];
    match b.sigma_axes {
        None => axes = [true; 6],
        Some(names) => {
            if names.is_empty() {
                return Err(doc.err("bounds.sigma_axes", "must name at least one axis"));
            }
            for name in names {
                let Some(i) = AXES.iter().position(|a| a == name) else {
                    return Err(doc.err(
                        "bounds.sigma_axes",
                        format!("unknown axis {name:?} (one of {})", AXES.join(", ")),
                    ));
                };
                if axes[i] {
                    return Err(doc.err("bounds.sigma_axes", format!("{name:?} given twice")));
                }
                axes[i] = true;
            }
        }
    }
    let char_length = b.char_length.unwrap_or(0.5 * vehicle.total_length());
    if !(char_length.is_finite() && char_length > 0.0) {
        return Err(doc.err("bounds.char_length", "must be positive and finite [m]"));
    }
    let spec = SigmaFloorSpec {
        lo,
        axes,
        char_length,
    };
    let mut floor = SigmaFloor::new(vehicle, lo, 1.0, CommandedDofs::new(axes), char_length);
    for (which, q) in [
        ("initial", Some(joint_angles)),
        ("terminal", terminal_joints),
    ] {
        let Some(q) = q else { continue };
        let s = floor.sigma(vehicle, q);
        if s.is_nan() || s <= lo {
            return Err(doc.err(
                "bounds.sigma_min",
                format!(
                    "the {which} joint angles have σ_min = {s:.4} of the scaled T(q), not above \
                     the floor {lo} (a straight body is often singular: start bent)"
                ),
            ));
        }
    }
    Ok(Some(spec))
}

//! Path costs of the chain beyond the quadratic effort (docs/ocp.md §1): thruster energy,
//! joint energy and the joint-limit barrier, with analytic gradients and Hessians in the
//! tangent coordinates of [`super::chain`] (joint angles `δq_i` at 6 + i, joint rates
//! `δq̇_i` at 12 + n + i, controls after the nx state entries).
//!
//! Per stage k < N (controls held over `[t_k, t_{k+1}]`, rates at `t_k`):
//!
//! ```text
//! l_k = Δt [ w_T Σ_j c φ(u_j) + w_J Σ_i ψ(τ_i q̇_i) ] + b(q_k)
//! φ(u) = (u² + ε_u²)^{3/4} − ε_u^{3/2}        (smoothed |u|^{3/2}: convex, C∞, error ≤ ε_u^{3/2})
//! ψ(s) = √(s² + ε_p²) − ε_p                   (smoothed |s|, error ≤ ε_p)
//! b(q) = −μ Δt Σ_i [ln(q_hi,i − q_i) + ln(q_i − q_lo,i)]   (+∞ outside the limits)
//! ```
//!
//! with `c = 1/(η√(2ρA))` the static actuator-disk coefficient of
//! [`PowerModel::static_power`] (docs/model.md §6): `c |u|^{3/2}` is the shaft power at zero
//! inflow [W], so `Σ_k Δt Σ_j c|u_kj|^{3/2}` is the project's `thruster_energy_static` [J]
//! (the zero-inflow figure; `thruster_energy` adds the useful power `|u| V_a` against the
//! through-flow, which the OCP does not model). `τ_i q̇_i` is joint i's mechanical power
//! [W], its integral of `|·|` the project's `joint_energy`. The barrier is added at every
//! knot 1 … N (x_0 is fixed) and keeps every iterate, hence the returned solution, strictly
//! inside the joint limits.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::model::OcpModel;
use super::riccati::LqStage;
use crate::metrics::trajectory::PowerModel;
use nalgebra::DMatrix;
use serde::Serialize;

/// The path-cost terms and their parameters (module documentation).
#[derive(Clone, Debug)]
pub struct PathCosts {
    /// Step Δt [s].
    pub dt: f64,
    /// Controls before the joint torques (m thrusters, or 6 for a base wrench).
    pub n_body: usize,
    /// Whether those are thrusts (the thruster-energy term needs them).
    pub thrusters: bool,
    /// Weight `w_T` of the thruster energy (0: off).
    pub thruster_energy: f64,
    /// `c = 1/(η√(2ρA))` [W/N^{3/2}].
    pub power_coefficient: f64,
    /// `ε_u` [N].
    pub thrust_smoothing: f64,
    /// Weight `w_J` of the joint energy (0: off).
    pub joint_energy: f64,
    /// `ε_p` [W].
    pub power_smoothing: f64,
    /// Joint limits `(q_lo, q_hi)` [rad] of the barrier (`None`: no barrier).
    pub joint_limits: Option<Vec<(f64, f64)>>,
    /// Barrier weight μ [objective units / s].
    pub barrier: f64,
}

impl PathCosts {
    /// No terms yet, for a chain with step `dt`, `n_body` body controls (thrusts if
    /// `thrusters`), the default power model's coefficient and smoothing ε_u = 0.01 N,
    /// ε_p = 0.01 W, μ = 1e-3.
    pub fn new(dt: f64, n_body: usize, thrusters: bool) -> Self {
        Self {
            dt,
            n_body,
            thrusters,
            thruster_energy: 0.0,
            power_coefficient: PowerModel::default().static_power(1.0),
            thrust_smoothing: 0.01,
            joint_energy: 0.0,
            power_smoothing: 0.01,
            joint_limits: None,
            barrier: 1e-3,
        }
    }

    /// `φ(u)`, `φ'(u)`, `φ''(u)`.
    fn phi(&self, u: f64) -> (f64, f64, f64) {
        let e2 = self.thrust_smoothing * self.thrust_smoothing;
        let r = u * u + e2;
        let v = r.powf(0.75) - self.thrust_smoothing.powf(1.5);
        let d1 = 1.5 * u * r.powf(-0.25);
        let d2 = 1.5 * r.powf(-1.25) * (0.5 * u * u + e2);
        (v, d1, d2)
    }

    /// `ψ(s)`, `ψ'(s)`, `ψ''(s)`.
    fn psi(&self, s: f64) -> (f64, f64, f64) {
        let e = self.power_smoothing;
        let r = (s * s + e * e).sqrt();
        (r - e, s / r, e * e / (r * r * r))
    }

    /// `l_k(x, u)` for a chain of `n` joints (module documentation).
    pub fn stage(&self, n: usize, x: &[f64], u: &[f64]) -> f64 {
        let mut v = 0.0;
        if self.thrusters && self.thruster_energy > 0.0 {
            for j in 0..self.n_body {
                v += self.thruster_energy * self.power_coefficient * self.phi(u[j]).0;
            }
        }
        if self.joint_energy > 0.0 {
            for i in 0..n {
                v += self.joint_energy * self.psi(u[self.n_body + i] * x[13 + n + i]).0;
            }
        }
        v * self.dt + self.barrier(n, x)
    }

    /// Add the gradient and Hessian of [`PathCosts::stage`] to `g`, `h` (order
    /// `[δx, δu]`); `exact` false leaves out the joint energy's indefinite cross term
    /// `ψ'(τq̇)` (keeping `ψ''∇s∇sᵀ ⪰ 0`).
    pub fn stage_derivatives(
        &self,
        n: usize,
        x: &[f64],
        u: &[f64],
        exact: bool,
        g: &mut [f64],
        h: &mut DMatrix<f64>,
    ) {
        let nx = 12 + 2 * n;
        let dt = self.dt;
        if self.thrusters && self.thruster_energy > 0.0 {
            let w = self.thruster_energy * self.power_coefficient * dt;
            for j in 0..self.n_body {
                let (_, d1, d2) = self.phi(u[j]);
                g[nx + j] += w * d1;
                h[(nx + j, nx + j)] += w * d2;
            }
        }
        if self.joint_energy > 0.0 {
            let w = self.joint_energy * dt;
            for i in 0..n {
                let (iq, iu) = (12 + n + i, nx + self.n_body + i);
                let (qd, tau) = (x[13 + n + i], u[self.n_body + i]);
                let (_, d1, d2) = self.psi(tau * qd);
                g[iq] += w * d1 * tau;
                g[iu] += w * d1 * qd;
                h[(iq, iq)] += w * d2 * tau * tau;
                h[(iu, iu)] += w * d2 * qd * qd;
                let cross = w * (d2 * tau * qd + if exact { d1 } else { 0.0 });
                h[(iq, iu)] += cross;
                h[(iu, iq)] += cross;
            }
        }
        self.barrier_derivatives(n, x, g, h);
    }

    /// The joint-limit barrier `b(q)` at a state (0 without limits, +∞ outside them).
    pub fn barrier(&self, n: usize, x: &[f64]) -> f64 {
        let Some(lim) = &self.joint_limits else {
            return 0.0;
        };
        let mut v = 0.0;
        for i in 0..n {
            let (a, b) = (x[7 + i] - lim[i].0, lim[i].1 - x[7 + i]);
            if !(a > 0.0 && b > 0.0) {
                return f64::INFINITY;
            }
            v -= a.ln() + b.ln();
        }
        self.barrier * self.dt * v
    }

    /// Largest α ≤ 1 with every joint angle of `x ⊕ α dx` keeping at least 1 % of its
    /// distance to each limit (fraction to the boundary τ = 0.99); 1 without limits.
    pub fn max_step(&self, n: usize, x: &[f64], dx: &[f64]) -> f64 {
        let Some(lim) = &self.joint_limits else {
            return 1.0;
        };
        let mut a: f64 = 1.0;
        for i in 0..n {
            let d = dx[6 + i];
            let (lo, hi) = (x[7 + i] - lim[i].0, lim[i].1 - x[7 + i]);
            if d < 0.0 {
                a = a.min(0.99 * lo / -d);
            } else if d > 0.0 {
                a = a.min(0.99 * hi / d);
            }
        }
        a
    }

    /// Add the barrier's gradient and (diagonal) Hessian to `g`, `h` (state block; tangent
    /// `δq_i` at 6 + i).
    pub fn barrier_derivatives(&self, n: usize, x: &[f64], g: &mut [f64], h: &mut DMatrix<f64>) {
        let Some(lim) = &self.joint_limits else {
            return;
        };
        let w = self.barrier * self.dt;
        for i in 0..n {
            let (a, b) = (x[7 + i] - lim[i].0, lim[i].1 - x[7 + i]);
            g[6 + i] += w * (1.0 / b - 1.0 / a);
            h[(6 + i, 6 + i)] += w * (1.0 / (a * a) + 1.0 / (b * b));
        }
    }

    /// The terms along a trajectory, smoothed (as optimised) and exact (`|u|^{3/2}`, `|τq̇|`,
    /// [`PowerModel::static_power`]).
    pub fn breakdown(&self, n: usize, xs: &[Vec<f64>], us: &[Vec<f64>]) -> CostBreakdown {
        let pm = PowerModel::default();
        let scale = self.power_coefficient / pm.static_power(1.0);
        let mut b = CostBreakdown::default();
        for (k, u) in us.iter().enumerate() {
            let x = &xs[k];
            if self.thrusters {
                for j in 0..self.n_body {
                    b.thruster_energy_smoothed +=
                        self.dt * self.power_coefficient * self.phi(u[j]).0;
                    b.thruster_energy_static += self.dt * scale * pm.static_power(u[j]);
                }
            }
            for i in 0..n {
                let s = u[self.n_body + i] * x[13 + n + i];
                b.joint_energy_smoothed += self.dt * self.psi(s).0;
                b.joint_energy += self.dt * s.abs();
            }
            b.barrier += self.barrier(n, x);
        }
        if let Some(x) = xs.last() {
            b.barrier += self.barrier(n, x);
        }
        b
    }
}

/// The path-cost terms along a trajectory ([`PathCosts::breakdown`]), unweighted.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct CostBreakdown {
    /// `Σ_k Δt Σ_j c φ(u_kj)` [J] (as optimised).
    pub thruster_energy_smoothed: f64,
    /// `Σ_k Δt Σ_j c |u_kj|^{3/2}` [J]: the project's `thruster_energy_static`.
    pub thruster_energy_static: f64,
    /// `Σ_k Δt Σ_i ψ(τ_ki q̇_ki)` [J] (as optimised).
    pub joint_energy_smoothed: f64,
    /// `Σ_k Δt Σ_i |τ_ki q̇_ki|` [J].
    pub joint_energy: f64,
    /// The joint-limit barrier's total (knots 0 … N).
    pub barrier: f64,
}

/// Add the model's path cost's gradient and Hessian at stage (x, u) to the stage's QP data
/// (`exact`: the full Hessian, else its positive semidefinite part); `buf` is scratch.
pub(crate) fn add_path_cost<M: OcpModel>(
    model: &mut M,
    x: &[f64],
    u: &[f64],
    exact: bool,
    s: &mut LqStage,
    buf: &mut (Vec<f64>, DMatrix<f64>),
) {
    let nx = s.q_vec.len();
    let nu = s.r_vec.len();
    buf.0.fill(0.0);
    buf.1.fill(0.0);
    model.stage_cost_derivatives(x, u, exact, &mut buf.0, &mut buf.1);
    for i in 0..nx {
        s.q_vec[i] += buf.0[i];
    }
    for i in 0..nu {
        s.r_vec[i] += buf.0[nx + i];
    }
    s.q_mat += buf.1.view((0, 0), (nx, nx));
    s.r_mat += buf.1.view((nx, nx), (nu, nu));
    s.s_mat += buf.1.view((nx, 0), (nu, nx));
}

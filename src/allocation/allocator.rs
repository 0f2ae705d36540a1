//! The [`Allocator`] (built once per case, called every control step) and its result types,
//! [`Allocation`] and [`AllocStatus`] (docs/model.md §5, USM-36/37).

use std::fmt;

use nalgebra::{Matrix6xX, Vector6};
use serde::Serialize;

use super::conic::{self, ConicProblem};
use super::error::{check_bounds, check_t, check_tau, check_vec, AllocError};
use super::interior::{inside, InteriorQp};
use super::pinv::{pinv_into, wrench};
use super::settings::{AllocSettings, Method};

/// Outcome of one allocation. Never an error: a closed loop keeps going.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AllocStatus {
    /// Solved and `T u = τ` within the slack tolerance.
    Solved,
    /// Solved, but `‖s‖` exceeds the slack tolerance: `τ` is unattainable under the bounds, or
    /// `T` is singular along a commanded direction.
    SlackActive {
        /// `‖s‖` (mixed N and N·m).
        slack_norm: f64,
    },
    /// `pinv` only: the result violates the thruster bounds (it is returned unclipped).
    BoundsViolated {
        /// Largest violation `max_j max(u_j − u_max,j, u_min,j − u_j)` (N).
        max_violation: f64,
    },
    /// Clarabel did not return a usable solution.
    SolverFailed {
        /// Clarabel's status (e.g. `"NumericalError"`, `"InsufficientProgress"`).
        solver_status: &'static str,
        /// Whether `u` is the clipped pseudoinverse fallback (else `u` is `0` clipped to the
        /// bounds).
        fallback: bool,
    },
}

impl AllocStatus {
    /// Short machine-readable label: `solved`, `slack_active`, `bounds_violated`,
    /// `solver_failed`.
    pub fn label(&self) -> &'static str {
        match self {
            AllocStatus::Solved => "solved",
            AllocStatus::SlackActive { .. } => "slack_active",
            AllocStatus::BoundsViolated { .. } => "bounds_violated",
            AllocStatus::SolverFailed { .. } => "solver_failed",
        }
    }

    /// True unless the solver failed.
    pub fn is_ok(&self) -> bool {
        !matches!(self, AllocStatus::SolverFailed { .. })
    }
}

impl fmt::Display for AllocStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AllocStatus::Solved => f.write_str("solved"),
            AllocStatus::SlackActive { slack_norm } => {
                write!(f, "slack active (|s| = {slack_norm:.3e})")
            }
            AllocStatus::BoundsViolated { max_violation } => {
                write!(f, "bounds violated (by {max_violation:.3e} N)")
            }
            AllocStatus::SolverFailed {
                solver_status,
                fallback,
            } => {
                if *fallback {
                    write!(f, "solver failed ({solver_status}), clipped pinv fallback")
                } else {
                    write!(f, "solver failed ({solver_status})")
                }
            }
        }
    }
}

/// Which computation produced an allocation (counted per run by the scenario recorder).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AllocPath {
    /// `pinv`: the closed-form damped pseudoinverse (USM-37).
    Pinv,
    /// `qp` with no bound or rate limit active: the unconstrained optimum, one SPD solve,
    /// certified as the QP solution (KKT with zero bound multipliers; see `interior.rs`).
    Interior,
    /// Clarabel's interior-point solve (a bound or rate limit would be active, or the method
    /// is `minimax`/`power`, or the shortcut is off).
    Clarabel,
    /// Clarabel failed: `u` is the clipped pseudoinverse (or zero), see
    /// [`AllocStatus::SolverFailed`].
    Fallback,
}

impl AllocPath {
    /// Short machine-readable label: `pinv`, `interior`, `clarabel`, `fallback`.
    pub fn label(self) -> &'static str {
        match self {
            AllocPath::Pinv => "pinv",
            AllocPath::Interior => "interior",
            AllocPath::Clarabel => "clarabel",
            AllocPath::Fallback => "fallback",
        }
    }
}

/// Result of one allocation (docs/model.md §5).
#[derive(Clone, Debug, PartialEq)]
pub struct Allocation {
    /// Thruster forces (N), length `n_thrusters`.
    pub u: Vec<f64>,
    /// Wrench slack `s = T u − τ` (base frame; N, N·m).
    pub s: Vector6<f64>,
    /// Objective of the method at `u` (no ½ factors): `qp` `uᵀWu + q‖s‖²`; `minimax`
    /// `max|u_j| + q‖s‖² + ε‖u‖²`; `power` `Σ w_j|u_j|^{3/2} + q‖s‖²`; each plus
    /// `‖u − u_prev‖²_R` when rate terms are set; `pinv` `uᵀWu + ‖s‖²/λ²` (the function USM-37
    /// minimises; `uᵀWu` when λ = 0).
    pub objective: f64,
    /// Outcome.
    pub status: AllocStatus,
    /// Clarabel's own status text (`"Solved"`, `"AlmostSolved"`, …); `"-"` when Clarabel was
    /// not called (paths [`AllocPath::Pinv`], [`AllocPath::Interior`]).
    pub solver_status: &'static str,
    /// Interior-point iterations (0 when Clarabel was not called).
    pub iterations: u32,
    /// Which computation produced `u`.
    pub path: AllocPath,
}

impl Allocation {
    /// An empty result for `n_thrusters` thrusters, to be filled by [`Allocator::allocate_into`].
    pub fn new(n_thrusters: usize) -> Self {
        Self {
            u: vec![0.0; n_thrusters],
            s: Vector6::zeros(),
            objective: 0.0,
            status: AllocStatus::Solved,
            solver_status: "-",
            iterations: 0,
            path: AllocPath::Pinv,
        }
    }

    /// Largest thruster force magnitude `max_j |u_j|` (N).
    pub fn max_abs_u(&self) -> f64 {
        self.u.iter().fold(0.0, |a, &x| a.max(x.abs()))
    }
}

/// A thrust allocator for one method, thruster count, bounds, weights and settings, built once
/// per case and called every control step (docs/model.md §5). It owns the Clarabel solver and all
/// scratch, so a step allocates nothing outside the solver (use [`Allocator::allocate_into`]).
///
/// The previous output is remembered as `u_prev` for the rate terms; override it with
/// [`Allocator::set_u_prev`]. It starts at zero.
pub struct Allocator {
    method: Method,
    n_thrusters: usize,
    settings: AllocSettings,
    u_min: Vec<f64>,
    u_max: Vec<f64>,
    /// Usage weights `w` (read by the KKT tests).
    pub(super) w: Vec<f64>,
    w_inv: Vec<f64>,
    rate_w: Vec<f64>,
    rate_step: Vec<f64>,
    u_prev: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    conic: Option<ConicProblem>,
    /// Scratch of the `qp` interior shortcut (`qp` with the shortcut on only).
    interior: Option<InteriorQp>,
    failures: u64,
    steps: u64,
}

impl fmt::Debug for Allocator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Allocator")
            .field("method", &self.method)
            .field("n_thrusters", &self.n_thrusters)
            .field("settings", &self.settings)
            .field("failures", &self.failures)
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

impl Allocator {
    /// Build an allocator for `n_thrusters` thrusters.
    ///
    /// `u_min`, `u_max` (N) and `w` (usage weights, > 0) have length `n_thrusters`; the rate weights and
    /// steps in `settings.rate`, if any, too. Returns an [`AllocError`] naming the argument and
    /// index on bad input.
    pub fn new(
        method: Method,
        n_thrusters: usize,
        u_min: &[f64],
        u_max: &[f64],
        w: &[f64],
        settings: AllocSettings,
    ) -> Result<Self, AllocError> {
        if n_thrusters == 0 {
            return Err(AllocError::NoThrusters);
        }
        check_bounds(u_min, u_max, n_thrusters)?;
        check_vec("weights", w, n_thrusters)?;
        for (index, &value) in w.iter().enumerate() {
            if value <= 0.0 {
                return Err(AllocError::BadWeight {
                    arg: "weights",
                    index,
                    value,
                    requirement: "> 0",
                });
            }
        }
        settings.validate()?;
        let (rate_w, rate_step) = match &settings.rate {
            None => (vec![0.0; n_thrusters], vec![f64::INFINITY; n_thrusters]),
            Some(r) => {
                r.validate(n_thrusters)?;
                (r.weights.clone(), r.max_step.clone())
            }
        };
        let conic = match method {
            Method::Pinv => None,
            _ => Some(ConicProblem::new(
                method,
                n_thrusters,
                settings.formulation,
                settings.reuse_solver,
                settings.tol,
            )),
        };
        let interior = (method == Method::Qp && settings.interior_shortcut)
            .then(|| InteriorQp::new(n_thrusters));
        Ok(Self {
            method,
            n_thrusters,
            u_min: u_min.to_vec(),
            u_max: u_max.to_vec(),
            w: w.to_vec(),
            w_inv: w.iter().map(|x| 1.0 / x).collect(),
            rate_w,
            rate_step,
            u_prev: vec![0.0; n_thrusters],
            lo: u_min.to_vec(),
            hi: u_max.to_vec(),
            conic,
            interior,
            failures: 0,
            steps: 0,
            settings,
        })
    }

    /// The allocation method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Number of thrusters `n_thrusters`.
    pub fn thrusters(&self) -> usize {
        self.n_thrusters
    }

    /// The settings.
    pub fn settings(&self) -> &AllocSettings {
        &self.settings
    }

    /// Number of steps whose Clarabel solve failed (each counted once, fallback or not).
    pub fn failures(&self) -> u64 {
        self.failures
    }

    /// Number of allocation steps run.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The previous thrust `u_prev` (N) used by the rate terms.
    pub fn u_prev(&self) -> &[f64] {
        &self.u_prev
    }

    /// Set `u_prev` (N, length `n_thrusters`) for the rate terms of the next step.
    pub fn set_u_prev(&mut self, u_prev: &[f64]) -> Result<(), AllocError> {
        check_vec("u_prev", u_prev, self.n_thrusters)?;
        self.u_prev.copy_from_slice(u_prev);
        Ok(())
    }

    /// Allocate `τ` (base frame; N, N·m) with `T` (6×n_thrusters, base frame) and return a new
    /// [`Allocation`]. See [`Allocator::allocate_into`] for the allocation-free form.
    pub fn allocate(
        &mut self,
        t: &Matrix6xX<f64>,
        tau: &Vector6<f64>,
    ) -> Result<Allocation, AllocError> {
        let mut out = Allocation::new(self.n_thrusters);
        self.allocate_into(t, tau, &mut out)?;
        Ok(out)
    }

    /// Allocate `τ` with `T` into `out` (its `u` is resized to `n_thrusters`, reusing its buffer). On success
    /// the result becomes the next step's `u_prev`. Errors only on bad input (dimensions or
    /// non-finite values); solver outcomes are in `out.status`.
    pub fn allocate_into(
        &mut self,
        t: &Matrix6xX<f64>,
        tau: &Vector6<f64>,
        out: &mut Allocation,
    ) -> Result<(), AllocError> {
        check_t(t, Some(self.n_thrusters))?;
        check_tau(tau)?;
        out.u.resize(self.n_thrusters, 0.0);
        self.steps += 1;
        for j in 0..self.n_thrusters {
            self.lo[j] = (self.u_prev[j] - self.rate_step[j]).clamp(self.u_min[j], self.u_max[j]);
            self.hi[j] = (self.u_prev[j] + self.rate_step[j]).clamp(self.u_min[j], self.u_max[j]);
        }
        match self.method {
            Method::Pinv => self.allocate_pinv(t, tau, out),
            _ => self.allocate_constrained(t, tau, out),
        }
        self.u_prev.copy_from_slice(&out.u);
        Ok(())
    }

    /// `pinv` (USM-37): the damped pseudoinverse, unclipped, with its bound violation.
    fn allocate_pinv(&mut self, t: &Matrix6xX<f64>, tau: &Vector6<f64>, out: &mut Allocation) {
        pinv_into(t, tau, &self.w_inv, self.settings.lambda, &mut out.u);
        out.s = wrench(t, &out.u) - tau;
        out.solver_status = "-";
        out.iterations = 0;
        out.path = AllocPath::Pinv;
        let max_violation = out
            .u
            .iter()
            .zip(self.u_min.iter().zip(&self.u_max))
            .fold(0.0_f64, |a, (&u, (&lo, &hi))| a.max(u - hi).max(lo - u));
        out.objective = self.objective(&out.u, &out.s);
        out.status = if max_violation > 0.0 {
            AllocStatus::BoundsViolated { max_violation }
        } else {
            self.slack_status(&out.s, tau)
        };
    }

    /// The constrained forms: the certified interior shortcut (`qp`), else Clarabel, else the
    /// fallback.
    fn allocate_constrained(
        &mut self,
        t: &Matrix6xX<f64>,
        tau: &Vector6<f64>,
        out: &mut Allocation,
    ) {
        let params = conic::Params {
            t,
            tau,
            lo: &self.lo,
            hi: &self.hi,
            w: &self.w,
            rate_w: &self.rate_w,
            u_prev: &self.u_prev,
            q: self.settings.q,
            eps: self.settings.eps,
        };
        if let Some(interior) = self.interior.as_mut() {
            if interior.solve(&params, &mut out.u) && inside(&out.u, &self.lo, &self.hi) {
                out.solver_status = "-";
                out.iterations = 0;
                out.path = AllocPath::Interior;
                out.s = wrench(t, &out.u) - tau;
                out.objective = self.objective(&out.u, &out.s);
                out.status = self.slack_status(&out.s, tau);
                return;
            }
        }
        let Some(conic) = self.conic.as_mut() else {
            unreachable!("Allocator::new gives every constrained method a conic problem")
        };
        let outcome = conic.solve(&params, &mut out.u);
        out.solver_status = outcome.status_text;
        out.iterations = outcome.iterations;
        if outcome.ok {
            out.path = AllocPath::Clarabel;
            out.s = wrench(t, &out.u) - tau;
            out.objective = self.objective(&out.u, &out.s);
            out.status = self.slack_status(&out.s, tau);
            return;
        }
        self.failures += 1;
        if self.settings.fallback {
            pinv_into(t, tau, &self.w_inv, self.settings.lambda, &mut out.u);
        } else {
            out.u.iter_mut().for_each(|u| *u = 0.0);
        }
        for (u, (&lo, &hi)) in out.u.iter_mut().zip(self.lo.iter().zip(&self.hi)) {
            *u = u.clamp(lo, hi);
        }
        out.path = AllocPath::Fallback;
        out.s = wrench(t, &out.u) - tau;
        out.objective = self.objective(&out.u, &out.s);
        out.status = AllocStatus::SolverFailed {
            solver_status: outcome.status_text,
            fallback: self.settings.fallback,
        };
    }

    fn slack_status(&self, s: &Vector6<f64>, tau: &Vector6<f64>) -> AllocStatus {
        let slack_norm = s.norm();
        if slack_norm > self.settings.slack_tol * tau.norm().max(1.0) {
            AllocStatus::SlackActive { slack_norm }
        } else {
            AllocStatus::Solved
        }
    }

    /// The method's objective at `u` (documented on [`Allocation::objective`]).
    fn objective(&self, u: &[f64], s: &Vector6<f64>) -> f64 {
        let q = self.settings.q;
        let rate: f64 = u
            .iter()
            .zip(self.u_prev.iter().zip(&self.rate_w))
            .map(|(&u, (&p, &r))| r * (u - p) * (u - p))
            .sum();
        match self.method {
            Method::Pinv => {
                let uwu: f64 = u.iter().zip(&self.w).map(|(&u, &w)| w * u * u).sum();
                let l2 = self.settings.lambda * self.settings.lambda;
                if l2 > 0.0 {
                    uwu + s.norm_squared() / l2
                } else {
                    uwu
                }
            }
            Method::Qp => {
                let uwu: f64 = u.iter().zip(&self.w).map(|(&u, &w)| w * u * u).sum();
                uwu + q * s.norm_squared() + rate
            }
            Method::Minimax => {
                let tmax = u.iter().fold(0.0_f64, |a, &x| a.max(x.abs()));
                let uu: f64 = u.iter().map(|x| x * x).sum();
                tmax + q * s.norm_squared() + self.settings.eps * uu + rate
            }
            Method::Power => {
                let p: f64 = u
                    .iter()
                    .zip(&self.w)
                    .map(|(&u, &w)| w * u.abs().powf(1.5))
                    .sum();
                p + q * s.norm_squared() + rate
            }
        }
    }

    #[cfg(test)]
    pub(crate) fn conic(&self) -> Option<&ConicProblem> {
        self.conic.as_ref()
    }

    #[cfg(test)]
    pub(crate) fn conic_mut(&mut self) -> Option<&mut ConicProblem> {
        self.conic.as_mut()
    }

    #[cfg(test)]
    pub(crate) fn effective_bounds(&self) -> (&[f64], &[f64]) {
        (&self.lo, &self.hi)
    }
}

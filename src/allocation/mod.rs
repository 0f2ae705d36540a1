//! Thrust allocation (SPEC §5, USM-36/37): map a commanded base wrench `τ_c` to thruster forces `u`.
//!
//! Conventions used throughout this module:
//! - `T` is the thruster configuration matrix, 6×m, expressed in the base frame `F_b`: column `j` is
//!   the wrench `[f; m]` (force in N, moment in N·m about the base-frame origin) produced by one
//!   newton of thrust of thruster `j`. Rows 0–2 are force x, y, z, rows 3–5 moment x, y, z.
//! - `τ` (`tau`) is the commanded wrench in the same frame and units.
//! - `u` are thruster forces in N, with per-thruster bounds `u_min ≤ u ≤ u_max` (N) and positive
//!   usage weights `w` (`W = diag(w)`).
//! - Every method reports the wrench slack `s = T u − τ` (base frame, N and N·m).
//!
//! Methods ([`Method`]):
//! - `pinv`: damped weighted pseudoinverse `u = W⁻¹Tᵀ(TW⁻¹Tᵀ + λ²I)⁻¹τ` (USM-37), bounds ignored;
//! - `qp`: `min uᵀWu + q‖s‖²` s.t. `Tu = τ + s`, `u_min ≤ u ≤ u_max`;
//! - `minimax`: `min t + q‖s‖² + ε‖u‖²` s.t. `Tu = τ + s`, `−t ≤ u_j ≤ t`, bounds;
//! - `power`: `min Σ w_j|u_j|^{3/2} + q‖s‖²` s.t. `Tu = τ + s`, bounds (exact, power cones);
//! - each constrained form optionally adds the rate/fluctuation terms `‖u − u_prev‖²_R` and
//!   `|u − u_prev| ≤ Δu` ([`RateSettings`]).
//!
//! The objectives carry no ½ factor. Constrained forms are solved with Clarabel; this module is the
//! only user of `clarabel` in the crate. A solver outcome is never an `Err`: it is reported in
//! [`AllocStatus`]. Bad input (dimensions, ordering of bounds, non-finite values, non-positive
//! weights) is an [`AllocError`].

mod attainable;
mod conic;
#[cfg(test)]
pub(crate) mod tests;

use std::fmt;
use std::str::FromStr;

use nalgebra::{Matrix6, Matrix6xX, Vector6};
use serde::{Deserialize, Serialize};

pub use attainable::{attainable_wrench, AttainableWrench};
use conic::ConicProblem;

/// Default damping factor λ of the pseudoinverse (USM-37; the paper uses λ = 0.1).
pub const DEFAULT_LAMBDA: f64 = 0.1;
/// Default slack weight `q` of the constrained forms (SPEC §5, `‖s‖²_Q` with `Q = qI`).
pub const DEFAULT_Q: f64 = 1e4;
/// Default regularisation weight ε of the minimax form (SPEC §5).
pub const DEFAULT_EPS: f64 = 1e-6;
/// Default Clarabel tolerance, see [`AllocSettings::tol`].
pub const DEFAULT_TOL: f64 = 1e-8;
/// Default relative slack tolerance, see [`AllocSettings::slack_tol`].
pub const DEFAULT_SLACK_TOL: f64 = 1e-2;

/// Allocation method (SPEC §5). Parses from and prints as its lowercase name
/// (`pinv`, `qp`, `minimax`, `power`); serde uses the same names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Damped weighted pseudoinverse, USM-37 (bounds ignored).
    Pinv,
    /// Constrained weighted least-norm QP with wrench slack.
    Qp,
    /// Minimise the largest thruster force (minimax).
    Minimax,
    /// Power-optimal: minimise `Σ w_j |u_j|^{3/2}` (momentum theory, SPEC §6).
    Power,
}

impl Method {
    /// All methods in their canonical order.
    pub const ALL: [Method; 4] = [Method::Pinv, Method::Qp, Method::Minimax, Method::Power];

    /// The lowercase name (`"pinv"`, `"qp"`, `"minimax"`, `"power"`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Pinv => "pinv",
            Method::Qp => "qp",
            Method::Minimax => "minimax",
            Method::Power => "power",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Error returned when a string names no [`Method`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown allocation method `{0}` (expected pinv, qp, minimax or power)")]
pub struct ParseMethodError(pub String);

impl FromStr for Method {
    type Err = ParseMethodError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "pinv" => Ok(Method::Pinv),
            "qp" => Ok(Method::Qp),
            "minimax" => Ok(Method::Minimax),
            "power" => Ok(Method::Power),
            _ => Err(ParseMethodError(s.to_string())),
        }
    }
}

/// Rate / fluctuation settings of the constrained forms (SPEC §5): the objective gains
/// `‖u − u_prev‖²_R` with `R = diag(weights)` and each step obeys `|u_j − u_prev,j| ≤ max_step_j`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateSettings {
    /// Diagonal of `R` (1/N², ≥ 0), one per thruster.
    pub weights: Vec<f64>,
    /// Largest change per allocation step `Δu` (N, > 0, `f64::INFINITY` for none), one per
    /// thruster. The step limit is intersected with `[u_min, u_max]`; if `u_prev` lies so far
    /// outside the bounds that the intersection is empty, the nearest bound wins.
    pub max_step: Vec<f64>,
}

/// How the constrained forms are written for Clarabel. Both are exact reformulations.
///
/// Measured on a 6×7 bent-USM T with the solver reused (`benches/allocation.rs`, medians on a
/// loaded 2-core machine): qp 56 µs kept vs 58 µs eliminated, minimax 111 vs 105 µs, power 222
/// vs 238 µs; rebuilding the solver each step costs 25–75 µs more. The eliminated form drops the
/// constant `q‖τ‖²` from Clarabel's objective, so Clarabel's *relative* gap tolerance becomes loose
/// in absolute terms (cancellation): its solutions meet the KKT conditions only to ~1e-4
/// relative, against 1e-6 for the kept form. Hence the kept form is the default.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Slack `s` kept as 6 extra variables with the equality rows `T u − s = τ` (default).
    #[default]
    SlackKept,
    /// Slack substituted (`s = T u − τ`): `P` gains `q TᵀT`, only inequality/cone rows remain.
    /// Smaller problem, but less accurate (see above).
    SlackEliminated,
}

/// Settings of an [`Allocator`] (SPEC §5). Defaults: λ = 0.1, q = 1e4, ε = 1e-6, no rate terms,
/// slack tolerance 1e-2, fallback on, slack kept, solver reused, Clarabel tolerance 1e-8.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AllocSettings {
    /// Damping λ ≥ 0 of the pseudoinverse (USM-37), in the units of `T` (N/N).
    pub lambda: f64,
    /// Slack weight `q > 0` of the constrained forms (`‖s‖²_Q`, `Q = qI`).
    pub q: f64,
    /// Regularisation ε ≥ 0 of the minimax form (`ε‖u‖²`).
    pub eps: f64,
    /// Optional rate / fluctuation terms of the constrained forms.
    pub rate: Option<RateSettings>,
    /// Relative slack tolerance: the status is [`AllocStatus::SlackActive`] when
    /// `‖s‖ > slack_tol · max(1, ‖τ‖)`.
    pub slack_tol: f64,
    /// On a Clarabel failure, fall back to the clipped damped pseudoinverse (default on).
    pub fallback: bool,
    /// How the constrained problem is written for Clarabel.
    pub formulation: Formulation,
    /// Keep one Clarabel solver and update its data in place between steps (default on);
    /// off rebuilds the solver every step.
    pub reuse_solver: bool,
    /// Clarabel's gap and feasibility tolerances (`tol_gap_abs`, `tol_gap_rel`, `tol_feas`),
    /// default 1e-8 (Clarabel's own default).
    pub tol: f64,
}

impl Default for AllocSettings {
    fn default() -> Self {
        Self {
            lambda: DEFAULT_LAMBDA,
            q: DEFAULT_Q,
            eps: DEFAULT_EPS,
            rate: None,
            slack_tol: DEFAULT_SLACK_TOL,
            fallback: true,
            formulation: Formulation::default(),
            reuse_solver: true,
            tol: DEFAULT_TOL,
        }
    }
}

/// Bad input to the allocation functions. Each message names the argument (as the case-file key:
/// `T`, `tau`, `u_min`, `u_max`, `weights`, `u_prev`, `rate_weights`, `rate_limit`, `lambda`, `q`,
/// `eps`, `slack_tol`) and, where relevant, the index.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AllocError {
    /// A vector or matrix has the wrong size.
    #[error("`{arg}` has {found} entries, expected {expected}")]
    Dimension {
        /// Argument name.
        arg: &'static str,
        /// Expected length (number of thrusters m, or 6).
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// No thrusters (T has zero columns).
    #[error("`T` has no columns: at least one thruster is needed")]
    NoThrusters,
    /// A vector entry is NaN or infinite.
    #[error("`{arg}[{index}]` is not finite ({value})")]
    NonFinite {
        /// Argument name.
        arg: &'static str,
        /// Index of the entry.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix entry is NaN or infinite.
    #[error("`{arg}[{row}][{col}]` is not finite ({value})")]
    NonFiniteMatrix {
        /// Argument name.
        arg: &'static str,
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// `u_min[i] > u_max[i]`.
    #[error("`u_min[{index}]` = {min} exceeds `u_max[{index}]` = {max}")]
    BoundsOrder {
        /// Thruster index.
        index: usize,
        /// Lower bound (N).
        min: f64,
        /// Upper bound (N).
        max: f64,
    },
    /// A weight that must be positive (or non-negative) is not.
    #[error("`{arg}[{index}]` = {value} must be {requirement}")]
    BadWeight {
        /// Argument name.
        arg: &'static str,
        /// Index of the entry.
        index: usize,
        /// The offending value.
        value: f64,
        /// What is required, e.g. "> 0".
        requirement: &'static str,
    },
    /// A scalar setting is out of range.
    #[error("setting `{name}` = {value} must be {requirement}")]
    BadSetting {
        /// Setting name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What is required.
        requirement: &'static str,
    },
}

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

/// Result of one allocation (SPEC §5).
#[derive(Clone, Debug, PartialEq)]
pub struct Allocation {
    /// Thruster forces (N), length m.
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
    /// Clarabel's own status text (`"Solved"`, `"AlmostSolved"`, …); `"-"` for `pinv`.
    pub solver_status: &'static str,
    /// Interior-point iterations (0 for `pinv`).
    pub iterations: u32,
}

impl Allocation {
    /// An empty result for `m` thrusters, to be filled by [`Allocator::allocate_into`].
    pub fn new(m: usize) -> Self {
        Self {
            u: vec![0.0; m],
            s: Vector6::zeros(),
            objective: 0.0,
            status: AllocStatus::Solved,
            solver_status: "-",
            iterations: 0,
        }
    }

    /// Largest thruster force magnitude `max_j |u_j|` (N).
    pub fn max_abs_u(&self) -> f64 {
        self.u.iter().fold(0.0, |a, &x| a.max(x.abs()))
    }
}

/// A thrust allocator for one method, thruster count, bounds, weights and settings, built once
/// per case and called every control step (SPEC §5). It owns the Clarabel solver and all
/// scratch, so a step allocates nothing outside the solver (use [`Allocator::allocate_into`]).
///
/// The previous output is remembered as `u_prev` for the rate terms; override it with
/// [`Allocator::set_u_prev`]. It starts at zero.
pub struct Allocator {
    method: Method,
    m: usize,
    settings: AllocSettings,
    u_min: Vec<f64>,
    u_max: Vec<f64>,
    w: Vec<f64>,
    w_inv: Vec<f64>,
    rate_w: Vec<f64>,
    rate_step: Vec<f64>,
    u_prev: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    conic: Option<ConicProblem>,
    failures: u64,
    steps: u64,
}

impl fmt::Debug for Allocator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Allocator")
            .field("method", &self.method)
            .field("m", &self.m)
            .field("settings", &self.settings)
            .field("failures", &self.failures)
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

pub(crate) fn check_vec(arg: &'static str, v: &[f64], m: usize) -> Result<(), AllocError> {
    if v.len() != m {
        return Err(AllocError::Dimension {
            arg,
            expected: m,
            found: v.len(),
        });
    }
    if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(AllocError::NonFinite { arg, index, value });
    }
    Ok(())
}

pub(crate) fn check_bounds(u_min: &[f64], u_max: &[f64], m: usize) -> Result<(), AllocError> {
    check_vec("u_min", u_min, m)?;
    check_vec("u_max", u_max, m)?;
    for (index, (&min, &max)) in u_min.iter().zip(u_max).enumerate() {
        if min > max {
            return Err(AllocError::BoundsOrder { index, min, max });
        }
    }
    Ok(())
}

pub(crate) fn check_t(t: &Matrix6xX<f64>, m: Option<usize>) -> Result<(), AllocError> {
    if t.ncols() == 0 {
        return Err(AllocError::NoThrusters);
    }
    if let Some(m) = m {
        if t.ncols() != m {
            return Err(AllocError::Dimension {
                arg: "T",
                expected: m,
                found: t.ncols(),
            });
        }
    }
    for col in 0..t.ncols() {
        for row in 0..6 {
            let value = t[(row, col)];
            if !value.is_finite() {
                return Err(AllocError::NonFiniteMatrix {
                    arg: "T",
                    row,
                    col,
                    value,
                });
            }
        }
    }
    Ok(())
}

fn check_tau(tau: &Vector6<f64>) -> Result<(), AllocError> {
    check_vec("tau", tau.as_slice(), 6)
}

fn check_setting(
    name: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), AllocError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(AllocError::BadSetting {
            name,
            value,
            requirement,
        })
    }
}

impl Allocator {
    /// Build an allocator for `m` thrusters.
    ///
    /// `u_min`, `u_max` (N) and `w` (usage weights, > 0) have length `m`; the rate weights and
    /// steps in `settings.rate`, if any, too. Returns an [`AllocError`] naming the argument and
    /// index on bad input.
    pub fn new(
        method: Method,
        m: usize,
        u_min: &[f64],
        u_max: &[f64],
        w: &[f64],
        settings: AllocSettings,
    ) -> Result<Self, AllocError> {
        if m == 0 {
            return Err(AllocError::NoThrusters);
        }
        check_bounds(u_min, u_max, m)?;
        check_vec("weights", w, m)?;
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
        check_setting("lambda", settings.lambda, settings.lambda >= 0.0, ">= 0")?;
        check_setting("q", settings.q, settings.q > 0.0, "> 0")?;
        check_setting("eps", settings.eps, settings.eps >= 0.0, ">= 0")?;
        check_setting(
            "slack_tol",
            settings.slack_tol,
            settings.slack_tol >= 0.0,
            ">= 0",
        )?;
        check_setting(
            "tol",
            settings.tol,
            settings.tol > 0.0 && settings.tol < 1.0,
            "in (0, 1)",
        )?;
        let (rate_w, rate_step) = match &settings.rate {
            None => (vec![0.0; m], vec![f64::INFINITY; m]),
            Some(r) => {
                check_vec("rate_weights", &r.weights, m)?;
                for (index, &value) in r.weights.iter().enumerate() {
                    if value < 0.0 {
                        return Err(AllocError::BadWeight {
                            arg: "rate_weights",
                            index,
                            value,
                            requirement: ">= 0",
                        });
                    }
                }
                if r.max_step.len() != m {
                    return Err(AllocError::Dimension {
                        arg: "rate_limit",
                        expected: m,
                        found: r.max_step.len(),
                    });
                }
                for (index, &value) in r.max_step.iter().enumerate() {
                    // NaN and non-positive values are rejected; +inf is allowed (no limit).
                    if value.is_nan() || value <= 0.0 {
                        return Err(AllocError::BadWeight {
                            arg: "rate_limit",
                            index,
                            value,
                            requirement: "> 0 (or +inf)",
                        });
                    }
                }
                (r.weights.clone(), r.max_step.clone())
            }
        };
        let conic = match method {
            Method::Pinv => None,
            _ => Some(ConicProblem::new(
                method,
                m,
                settings.formulation,
                settings.reuse_solver,
                settings.tol,
            )),
        };
        Ok(Self {
            method,
            m,
            u_min: u_min.to_vec(),
            u_max: u_max.to_vec(),
            w: w.to_vec(),
            w_inv: w.iter().map(|x| 1.0 / x).collect(),
            rate_w,
            rate_step,
            u_prev: vec![0.0; m],
            lo: u_min.to_vec(),
            hi: u_max.to_vec(),
            conic,
            failures: 0,
            steps: 0,
            settings,
        })
    }

    /// The allocation method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Number of thrusters m.
    pub fn thrusters(&self) -> usize {
        self.m
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

    /// Set `u_prev` (N, length m) for the rate terms of the next step.
    pub fn set_u_prev(&mut self, u_prev: &[f64]) -> Result<(), AllocError> {
        check_vec("u_prev", u_prev, self.m)?;
        self.u_prev.copy_from_slice(u_prev);
        Ok(())
    }

    /// Allocate `τ` (base frame; N, N·m) with `T` (6×m, base frame) and return a new
    /// [`Allocation`]. See [`Allocator::allocate_into`] for the allocation-free form.
    pub fn allocate(
        &mut self,
        t: &Matrix6xX<f64>,
        tau: &Vector6<f64>,
    ) -> Result<Allocation, AllocError> {
        let mut out = Allocation::new(self.m);
        self.allocate_into(t, tau, &mut out)?;
        Ok(out)
    }

    /// Allocate `τ` with `T` into `out` (its `u` is resized to m, reusing its buffer). On success
    /// the result becomes the next step's `u_prev`. Errors only on bad input (dimensions or
    /// non-finite values); solver outcomes are in `out.status`.
    pub fn allocate_into(
        &mut self,
        t: &Matrix6xX<f64>,
        tau: &Vector6<f64>,
        out: &mut Allocation,
    ) -> Result<(), AllocError> {
        check_t(t, Some(self.m))?;
        check_tau(tau)?;
        out.u.resize(self.m, 0.0);
        self.steps += 1;
        for j in 0..self.m {
            self.lo[j] = (self.u_prev[j] - self.rate_step[j]).clamp(self.u_min[j], self.u_max[j]);
            self.hi[j] = (self.u_prev[j] + self.rate_step[j]).clamp(self.u_min[j], self.u_max[j]);
        }
        match self.method {
            Method::Pinv => {
                pinv_into(t, tau, &self.w_inv, self.settings.lambda, &mut out.u);
                out.s = wrench(t, &out.u) - tau;
                out.solver_status = "-";
                out.iterations = 0;
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
            _ => {
                let Some(conic) = self.conic.as_mut() else {
                    unreachable!("Allocator::new gives every constrained method a conic problem")
                };
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
                let outcome = conic.solve(&params, &mut out.u);
                out.solver_status = outcome.status_text;
                out.iterations = outcome.iterations;
                if outcome.ok {
                    out.s = wrench(t, &out.u) - tau;
                    out.objective = self.objective(&out.u, &out.s);
                    out.status = self.slack_status(&out.s, tau);
                } else {
                    self.failures += 1;
                    if self.settings.fallback {
                        pinv_into(t, tau, &self.w_inv, self.settings.lambda, &mut out.u);
                    } else {
                        out.u.iter_mut().for_each(|u| *u = 0.0);
                    }
                    for (u, (&lo, &hi)) in out.u.iter_mut().zip(self.lo.iter().zip(&self.hi)) {
                        *u = u.clamp(lo, hi);
                    }
                    out.s = wrench(t, &out.u) - tau;
                    out.objective = self.objective(&out.u, &out.s);
                    out.status = AllocStatus::SolverFailed {
                        solver_status: outcome.status_text,
                        fallback: self.settings.fallback,
                    };
                }
            }
        }
        self.u_prev.copy_from_slice(&out.u);
        Ok(())
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

/// `T u` (base frame; N, N·m).
pub fn wrench(t: &Matrix6xX<f64>, u: &[f64]) -> Vector6<f64> {
    let mut f = Vector6::zeros();
    for (j, &uj) in u.iter().enumerate().take(t.ncols()) {
        f += t.column(j) * uj;
    }
    f
}

/// Damped weighted pseudoinverse (USM-37): `u = W⁻¹Tᵀ(TW⁻¹Tᵀ + λ²I)⁻¹τ`, written into `u`
/// (length m). `w_inv` is the diagonal of `W⁻¹`. Uses a fixed 6×6 Cholesky factorisation and
/// allocates nothing; if the 6×6 matrix is not positive definite (λ = 0 and `T` singular) the
/// minimum-norm solution from a 6×6 SVD is used instead.
fn pinv_into(t: &Matrix6xX<f64>, tau: &Vector6<f64>, w_inv: &[f64], lambda: f64, u: &mut [f64]) {
    let mut a = Matrix6::<f64>::identity() * (lambda * lambda);
    for (j, &wi) in w_inv.iter().enumerate() {
        let c = t.fixed_view::<6, 1>(0, j);
        a.ger(wi, &c, &c, 1.0);
    }
    let y = match a.cholesky() {
        Some(ch) => ch.solve(tau),
        None => a
            .svd(true, true)
            .solve(tau, 1e-12 * a.norm().max(f64::MIN_POSITIVE))
            .unwrap_or_else(|_| Vector6::zeros()),
    };
    for (j, (uj, &wi)) in u.iter_mut().zip(w_inv).enumerate() {
        *uj = wi * t.fixed_view::<6, 1>(0, j).dot(&y);
    }
}

/// Damped weighted pseudoinverse allocation (USM-37), a one-shot convenience:
/// `u = W⁻¹Tᵀ(TW⁻¹Tᵀ + λ²I)⁻¹τ` with `W = diag(w)`, `T` 6×m (base frame, N and N·m per N),
/// `τ` (base frame; N, N·m). Returns `u` (N). Bounds are not involved.
pub fn damped_pinv(
    t: &Matrix6xX<f64>,
    tau: &Vector6<f64>,
    w: &[f64],
    lambda: f64,
) -> Result<Vec<f64>, AllocError> {
    check_t(t, None)?;
    check_tau(tau)?;
    let m = t.ncols();
    check_vec("weights", w, m)?;
    if let Some((index, &value)) = w.iter().enumerate().find(|(_, &x)| x <= 0.0) {
        return Err(AllocError::BadWeight {
            arg: "weights",
            index,
            value,
            requirement: "> 0",
        });
    }
    check_setting("lambda", lambda, lambda >= 0.0, ">= 0")?;
    let w_inv: Vec<f64> = w.iter().map(|x| 1.0 / x).collect();
    let mut u = vec![0.0; m];
    pinv_into(t, tau, &w_inv, lambda, &mut u);
    Ok(u)
}

/// One-shot allocation: build an [`Allocator`] for `method` and allocate `τ` once with `T`
/// (6×m, base frame), bounds `u_min`, `u_max` (N) and weights `w` (SPEC §5, USM-36/37).
pub fn allocate(
    method: Method,
    t: &Matrix6xX<f64>,
    tau: &Vector6<f64>,
    u_min: &[f64],
    u_max: &[f64],
    w: &[f64],
    settings: AllocSettings,
) -> Result<Allocation, AllocError> {
    check_t(t, None)?;
    let mut a = Allocator::new(method, t.ncols(), u_min, u_max, w, settings)?;
    a.allocate(t, tau)
}

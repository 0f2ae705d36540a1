//! Allocation settings (docs/model.md §5): the [`Method`], the [`Formulation`] of the constrained forms,
//! the rate terms and the [`AllocSettings`] with every default beside its field and a
//! `validate()` (Clarabel's `settings.rs` habit).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::error::{check_lambda, check_setting, check_vec, AllocError};

/// Default damping factor λ of the pseudoinverse (USM-37; the paper uses λ = 0.1).
pub const DEFAULT_LAMBDA: f64 = 0.1;
/// Default slack weight `q` of the constrained forms (docs/model.md §5, `‖s‖²_Q` with `Q = qI`).
pub const DEFAULT_Q: f64 = 1e4;
/// Default regularisation weight ε of the minimax form (docs/model.md §5).
pub const DEFAULT_EPS: f64 = 1e-6;
/// Default Clarabel tolerance, see [`AllocSettings::tol`].
pub const DEFAULT_TOL: f64 = 1e-8;
/// Default relative slack tolerance, see [`AllocSettings::slack_tol`].
pub const DEFAULT_SLACK_TOL: f64 = 1e-2;

/// Allocation method (docs/model.md §5). Parses from and prints as its lowercase name
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
    /// Power-optimal: minimise `Σ w_j |u_j|^{3/2}` (momentum theory, docs/model.md §6).
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

/// Rate / fluctuation settings of the constrained forms (docs/model.md §5): the objective gains
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

impl RateSettings {
    /// Check both vectors against `n_thrusters`: weights finite and ≥ 0, steps > 0 (`+inf`
    /// allowed, NaN not).
    pub fn validate(&self, n_thrusters: usize) -> Result<(), AllocError> {
        check_vec("rate_weights", &self.weights, n_thrusters)?;
        for (index, &value) in self.weights.iter().enumerate() {
            if value < 0.0 {
                return Err(AllocError::BadWeight {
                    arg: "rate_weights",
                    index,
                    value,
                    requirement: ">= 0",
                });
            }
        }
        if self.max_step.len() != n_thrusters {
            return Err(AllocError::Dimension {
                arg: "rate_limit",
                expected: n_thrusters,
                found: self.max_step.len(),
            });
        }
        for (index, &value) in self.max_step.iter().enumerate() {
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
        Ok(())
    }
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

/// Settings of an [`Allocator`](super::Allocator) (docs/model.md §5). Each field's doc gives its
/// default (the `DEFAULT_*` constants above, or the literal), which [`Default`] uses;
/// [`AllocSettings::validate`] checks the ranges.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AllocSettings {
    /// Damping λ ≥ 0 of the pseudoinverse (USM-37), in the units of `T` (N/N).
    /// Default [`DEFAULT_LAMBDA`] = 0.1.
    pub lambda: f64,
    /// Slack weight `q > 0` of the constrained forms (`‖s‖²_Q`, `Q = qI`).
    /// Default [`DEFAULT_Q`] = 1e4.
    pub q: f64,
    /// Regularisation ε ≥ 0 of the minimax form (`ε‖u‖²`). Default [`DEFAULT_EPS`] = 1e-6.
    pub eps: f64,
    /// Optional rate / fluctuation terms of the constrained forms. Default `None`.
    pub rate: Option<RateSettings>,
    /// Relative slack tolerance ≥ 0: the status is
    /// [`AllocStatus::SlackActive`](super::AllocStatus::SlackActive) when
    /// `‖s‖ > slack_tol · max(1, ‖τ‖)`. Default [`DEFAULT_SLACK_TOL`] = 1e-2.
    pub slack_tol: f64,
    /// On a Clarabel failure, fall back to the clipped damped pseudoinverse. Default `true`.
    pub fallback: bool,
    /// How the constrained problem is written for Clarabel. Default
    /// [`Formulation::SlackKept`].
    pub formulation: Formulation,
    /// Keep one Clarabel solver and update its data in place between steps; off rebuilds the
    /// solver every step. Default `true`.
    pub reuse_solver: bool,
    /// Clarabel's gap and feasibility tolerances (`tol_gap_abs`, `tol_gap_rel`, `tol_feas`),
    /// in (0, 1). Default [`DEFAULT_TOL`] = 1e-8 (Clarabel's own default).
    pub tol: f64,
    /// `qp` only: return the unconstrained optimum (one SPD solve) when it lies within the
    /// effective bounds — it is then the QP solution, certified by the KKT conditions with
    /// zero bound multipliers — and call Clarabel only when a bound or rate limit would be
    /// active. Off sends every step to Clarabel. Default `true`.
    pub interior_shortcut: bool,
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
            interior_shortcut: true,
        }
    }
}

impl AllocSettings {
    /// Check the scalar settings (`0 ≤ lambda ≤` [`crate::allocation::MAX_LAMBDA`], `q > 0`, `eps ≥ 0`, `slack_tol ≥ 0`,
    /// `tol ∈ (0, 1)`, all finite), in that order; the rate terms are checked against the
    /// thruster count by [`RateSettings::validate`].
    pub fn validate(&self) -> Result<(), AllocError> {
        check_lambda(self.lambda)?;
        check_setting("q", self.q, self.q > 0.0, "> 0")?;
        check_setting("eps", self.eps, self.eps >= 0.0, ">= 0")?;
        check_setting("slack_tol", self.slack_tol, self.slack_tol >= 0.0, ">= 0")?;
        check_setting(
            "tol",
            self.tol,
            self.tol > 0.0 && self.tol < 1.0,
            "in (0, 1)",
        )
    }
}

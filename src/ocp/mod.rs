//! Optimal control (issue 40, docs/ocp.md): direct multiple shooting of the multibody chain
//! on the base pose's Lie group, solved by an SQP (exact Lagrangian Hessian by second
//! differences, or Gauss–Newton) whose QP is a Riccati-based interior point.
//!
//! - [`model`]: the [`OcpModel`] trait (discrete dynamics with retraction, terminal equality,
//!   central-difference Jacobians by default) and [`LinearModel`] (closed-form tests);
//! - [`chain`]: [`ChainModel`], the floating chain under base-wrench actuation, symplectic
//!   Euler on SE(3) over the project's multibody dynamics;
//! - [`riccati`]: the equality-constrained LQ subproblem (terminal equality through a
//!   parametric multiplier);
//! - [`qp`]: the box-bounded QP (Mehrotra interior point over the Riccati solve);
//! - [`sqp`]: the SQP with the filter line search, KKT residuals, status and log;
//! - [`derivatives`]: the chain's central and second differences with the dynamics terms
//!   each perturbation leaves unchanged reused (the same numbers, fewer evaluations);
//! - [`fidelity`]: a solution integrated again finer (defects, work balance);
//! - [`cost`]: [`PathCosts`], thruster and joint energy (smoothed) and the joint-limit
//!   barrier, analytic derivatives;
//! - [`cruise`]: the cruise start of a transport leg (a start that already moves);
//! - `substeps`: S symplectic Euler steps per interval, their Jacobians and Hessian by the
//!   chain rule (scratch in `sub_scratch`);
//! - [`start`]: warm start from a trajectory file, the perturbed starts of a multi-start;
//! - [`bound`]: the bound of a design on a transport leg (issue 41), N−1 warm-started;
//!   [`study_bound`]: that bound for every case of a study with `[ocp]` (the sweep's hook);
//! - [`problem`]: problem files with located errors; [`run`]: solve a file, write outputs.

pub mod bound;
pub mod chain;
pub mod cost;
pub mod cruise;
pub mod derivatives;
pub mod fidelity;
pub mod model;
pub mod plots;
pub mod problem;
pub mod qp;
pub mod riccati;
pub mod run;
pub mod sigma_floor;
pub mod sqp;
mod sqp_eval;
pub mod start;
pub mod study_bound;
mod sub_scratch;
mod substeps;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_bound;
#[cfg(test)]
mod tests_costs;
#[cfg(test)]
mod tests_cruise;
#[cfg(test)]
mod tests_derivatives;
#[cfg(test)]
mod tests_fidelity;
#[cfg(test)]
mod tests_sigma;

pub use chain::{ChainModel, TerminalSpec};
pub use cost::{CostBreakdown, PathCosts};
pub use fidelity::{grid_fidelity, GridFidelity};
pub use model::{LinearModel, ModelError, OcpModel};
pub use problem::{load_problem, parse_problem, ProblemSpec};
pub use run::{build_model, solve_spec, write_outputs, OcpRun, StartRecord};
pub use sqp::{solve, Hessian, IterLog, OcpProblem, OcpSolution, SqpSettings, Status, Timing};

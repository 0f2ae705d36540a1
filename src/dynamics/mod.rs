//! Floating-base hydrodynamic multibody dynamics (docs/model.md §4, USM-19 … USM-22, USM-35).
//!
//! The equation of motion, with the base twist `V_b = [v; ω]` in the base frame `F_b` and
//! generalised velocity `ζ = [V_b; q̇]` (size 6+n):
//!
//! ```text
//! M(q) ζ̇ + C(q,ζ) ζ + D(q,ζ) ζ + N(R_Ib, q) = τ,   τ = [T(q) u; τ_q]
//! ```
//!
//! Layout (Pinocchio style: immutable [`Vehicle`](crate::model::Vehicle) + mutable
//! [`DynWorkspace`], free functions `algo(&model, &mut ws, …)`; MuJoCo style fluid forces as
//! pure kernels on local 6-vectors under a thin driver):
//! - [`hydro`]: pure kernels — cylinder strip-theory drag, coefficient damping, restoring
//!   wrench — on one body's relative twist, in that body's frame; [`manoeuvring`]: the
//!   manoeuvring-derivative kernel of a streamlined hull (NPS AUV II);
//! - [`workspace`]: the [`DynWorkspace`] (per-body inertias, kernels and every buffer);
//! - `passes`: the staged passes (CRBA, Newton–Euler forward pass, body wrenches, backward
//!   pass) after the one position pass, [`crate::kinematics::forward_kinematics`];
//! - [`aba`]: the O(n) forward dynamics (articulated-body algorithm with the added mass in
//!   the articulated inertias) and the O(n) hybrid dynamics of the ideal servos — what the
//!   [`Simulator`] evaluates;
//! - [`algorithms`]: composite-rigid-body mass matrix ([`mass_matrix`]), recursive
//!   Newton–Euler bias forces ([`bias`]) and inverse dynamics, forward and hybrid dynamics,
//!   energy and momentum;
//! - `error`: [`DynError`] (a dynamics algorithm's numerical failure), [`SimError`] (with the
//!   simulation time) and the finiteness check;
//! - [`config`]: the servo and thruster models and the [`SimConfig`] (defaults, `validate()`);
//! - [`sim`]: the servo laws, the flat Lie-group state and the [`Simulator`];
//!   `thruster_lag`: the thruster lag and rate limit in closed form;
//! - `integrator`: the fixed-step RK4 step and the adaptive Dormand–Prince 5(4) span
//!   integrator with error control ([`Integrator`] chooses), and the folding of the joint
//!   work's quadrature states at the sign changes of the joint power;
//! - [`inspect`]: the JSON-ready [`DynamicsReport`] of `usm-study inspect`;
//! - [`hydrostatics`]: wet weight, centres, metacentric height, restoring moments per radian
//!   and trim of a design at one configuration (`inspect`, `design draw`).
//!
//! Nothing in a time step allocates: every buffer lives in the workspace or the simulator.

pub mod aba;
pub mod algorithms;
pub mod config;
mod error;
pub mod hydro;
pub mod hydrostatics;
pub mod inspect;
mod integrator;
pub mod manoeuvring;
mod passes;
pub mod sim;
mod structure;
mod thruster_lag;
pub mod workspace;

#[cfg(test)]
mod tests;

pub use aba::{forward_dynamics_aba, hybrid_dynamics_on, hybrid_terms, solve_hybrid_on};
pub use algorithms::{
    bias, damping_generalized, dynamics_terms, forward_dynamics, hybrid_dynamics, inverse_dynamics,
    kinetic_energy, mass_matrix, restoring_generalized, solve_forward, solve_hybrid,
    spatial_momentum,
};
pub use config::{Integrator, ServoModel, SimConfig, ThrusterModel};
pub use error::{DynError, SimError};
pub use inspect::{inspect_dynamics, DynamicsReport};
pub use integrator::StepStats;
pub use sim::{ActuatorCommand, SimState, Simulator};
pub use workspace::DynWorkspace;

/// Which physical effects enter the dynamics (docs/model.md §4).
///
/// `full()` is the paper's model and the default (every field on); `rigid()` is the vehicle
/// in vacuum (no added mass, no drag, no restoring forces, no current) — what
/// `usm-study inspect --rigid` evaluates. Any combination is valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DynOptions {
    /// Add the added-mass inertia `M_A` of every body to `M` and its Kirchhoff velocity
    /// term `V_r ×* (M_A V_r)` to the bias forces. Default on.
    pub added_mass: bool,
    /// Hydrodynamic damping (strip-theory drag, linear damping, or `D_l`/`D_q` matrices).
    /// Default on.
    pub drag: bool,
    /// Weight at the centre of gravity and buoyancy at the centre of buoyancy. Default on.
    pub restoring: bool,
    /// Use the vehicle's constant irrotational current `ν_c`; when off, the fluid is at rest.
    /// Default on.
    pub current: bool,
}

impl DynOptions {
    /// Everything on: added mass, drag, restoring forces and current.
    pub fn full() -> Self {
        Self {
            added_mass: true,
            drag: true,
            restoring: true,
            current: true,
        }
    }

    /// The vehicle in vacuum: rigid-body dynamics only.
    pub fn rigid() -> Self {
        Self {
            added_mass: false,
            drag: false,
            restoring: false,
            current: false,
        }
    }
}

impl Default for DynOptions {
    fn default() -> Self {
        Self::full()
    }
}

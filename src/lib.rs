//! # usm-study
//!
//! A batch workbench for designing and tuning underwater swimming manipulators (USMs) and
//! underwater vehicle-manipulator systems (UVMS): floating-base multibody hydrodynamics,
//! task-priority kinematic control, thrust allocation in Clarabel, thruster-matrix
//! singularity scoring, closed-loop scenarios and parallel parameter sweeps.
//!
//! The physics and control formulation is `docs/model.md` in the repository (equations cited
//! as USM-nn / AC-nn). The modules are rooms in the order `docs/architecture.md` declares,
//! each importing only rooms below it: data flows from [`model`] through [`kinematics`] to the
//! dynamics, the control laws and the scenario loop, a run's [`outcome`] is judged above it, and
//! results flow out to reports ([`report`]) through the static analysis ([`statics`]), the
//! study ([`study`]: what to run), its running ([`batch`]) and what it says ([`review`]), the optimiser ([`optimise`]) and the output pipelines ([`pipeline`]); the
//! paper reproductions ([`paper`]) sit on top. Decisions under uncertainty (quantiles over
//! worlds, Sobol indices, paired rankings and the winner-or-tie verdict) rest on the pure
//! kernels of [`stats`]. The command-line interface is the binary's own
//! (`src/cli/`), not part of this library.

#![warn(missing_docs)]

pub mod allocation;
pub mod batch;
pub mod control;
pub mod dynamics;
pub mod evaluate;
pub mod input;
pub mod kinematics;
pub(crate) mod linalg;
pub mod metrics;
pub mod model;
pub mod ocp;
pub mod optimise;
pub mod outcome;
pub mod paper;
pub mod pipeline;
pub mod report;
pub mod review;
pub mod sampling;
pub mod scenario;
pub mod spatial;
pub mod state;
pub mod statics;
pub mod stats;
pub mod study;

//! Metric kernels (docs/model.md §6), below the control laws: pure functions of a
//! configuration or a trajectory — the scaled singularity metrics of `T(q)` ([`singularity`],
//! on the allocation-free 6×6 kernels of `small_svd`) and the energy, tracking and exposure
//! integrals of a trajectory ([`trajectory`]). A run's summary and success checks, which read
//! scenario types, are in [`crate::outcome`].

pub mod extremes;
pub mod singularity;
mod small_svd;
pub mod trajectory;

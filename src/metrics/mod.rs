//! Metrics (SPEC §6): pure functions of a configuration set or a trajectory.

pub mod run_summary;
pub mod singularity;
mod small_svd;
pub mod success;
pub mod trajectory;

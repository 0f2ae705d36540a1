//! Metrics (SPEC §6): pure functions of a configuration set or a trajectory.

pub mod singularity;
pub mod trajectory;

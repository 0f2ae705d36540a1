//! The sources of a [`Reference`] behind one enum (docs/model.md §5 "References"): the
//! work-mode timed end-effector path ([`super::spline`]) and a trajectory file
//! ([`super::trajectory_file`]). Sampling is allocation-free.

use super::reference::{EeReference, Reference};
use super::spline::{pose_and_twist, PoseReference};
use super::trajectory_file::TrajectoryTable;
use crate::spatial::Mat3;

/// Where a [`Reference`] comes from (module docs).
#[derive(Clone, Debug)]
pub enum ReferenceSource {
    /// A timed end-effector path (work mode's `[reference]` with `duration` and via-points).
    EndEffector(PoseReference),
    /// A trajectory file, interpolated in time.
    Table(TrajectoryTable),
}

impl ReferenceSource {
    /// Fill `out` with the reference at time `t` [s]. `r_ie` is the measured end-effector
    /// orientation in `I`, in whose frame an end-effector twist is expressed (USM-42).
    /// Allocation-free.
    pub fn sample_into(&self, t: f64, r_ie: &Mat3, out: &mut Reference) {
        out.t = t;
        match self {
            ReferenceSource::EndEffector(path) => {
                let (position, orientation, twist) = pose_and_twist(&path.sample(t), r_ie);
                out.ee = Some(EeReference {
                    position,
                    orientation,
                    twist,
                });
            }
            ReferenceSource::Table(table) => table.sample_into(t, out),
        }
    }
}

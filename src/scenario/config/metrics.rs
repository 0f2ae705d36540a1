//! `[metrics]`: thresholds, tolerances and the power models of a scenario file (docs/model.md
//! §6). Re-exported by [`super`].

use crate::metrics::singularity::{RESIDUAL_TOLERANCE, SINGULARITY_THRESHOLD};
use crate::metrics::trajectory::PowerModel;
use serde::{Deserialize, Serialize};

/// `[metrics]`: thresholds and the power model (docs/model.md §6).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MetricsSpec {
    /// σ_min threshold of the scaled T(q) (N per N) below which a configuration counts as
    /// singular, for both `singularity_exposure` (the commanded rows) and
    /// `singularity_exposure_full` (all six). Default
    /// [`SINGULARITY_THRESHOLD`], the one the static analysis uses too.
    pub threshold: f64,
    /// Relative tolerance of `allocation_residual_fraction`: a control step counts when the
    /// commanded slack exceeds this fraction of the commanded wrench
    /// ([`crate::metrics::singularity::residual_exceeds`]). Default [`RESIDUAL_TOLERANCE`].
    pub residual_tolerance: f64,
    /// Characteristic length for scaling moments [m]; 0 = half the vehicle length.
    pub char_length: f64,
    /// Cross-track band for convergence [m] (transport).
    pub band: f64,
    /// Position tolerance for settling [m] (work).
    pub position_tolerance: f64,
    /// Orientation tolerance for settling (roll excluded) [deg] (work).
    pub orientation_tolerance_deg: f64,
    /// Propeller diameter D [m] of the actuator-disk power model (docs/model.md §6). Default 0.07 m
    /// (inferred: the paper gives no propeller data).
    pub propeller_diameter: f64,
    /// Overall efficiency η of the power model, shaft power = ideal power / η. Default 0.5
    /// (inferred).
    pub efficiency: f64,
    /// Efficiency η_j of the joint drives, electrical energy = mechanical joint work / η_j
    /// (metric `total_energy`, docs/model.md §6). Default 0.7 (inferred: a brushless motor with
    /// a harmonic or planetary gear, 0.5–0.9; docs/assumptions.md).
    pub joint_efficiency: f64,
    /// A thruster counts as saturated within this distance of a limit [N].
    pub saturation_tolerance: f64,
    /// Position magnitude [m] beyond which a run counts as diverged.
    pub divergence_distance: f64,
}

impl Default for MetricsSpec {
    fn default() -> Self {
        let p = PowerModel::default();
        Self {
            threshold: SINGULARITY_THRESHOLD,
            residual_tolerance: RESIDUAL_TOLERANCE,
            char_length: 0.0,
            band: 0.1,
            position_tolerance: 0.02,
            orientation_tolerance_deg: 2.0,
            propeller_diameter: p.propeller_diameter,
            efficiency: p.efficiency,
            joint_efficiency: 0.7,
            saturation_tolerance: 1e-3,
            divergence_distance: 1e4,
        }
    }
}

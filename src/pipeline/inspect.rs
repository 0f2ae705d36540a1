//! The `inspect` report: kinematics (end-effector pose and Jacobian, `T(q)` and its singular
//! values) and dynamics of a design at one state, with stable JSON keys in SI units.

use faer::Mat;
use serde::Serialize;

use super::error::PipelineError;
use crate::allocation::AttainableAuthority;
use crate::dynamics::hydrostatics::{hydrostatics, Hydrostatics};
use crate::dynamics::{inspect_dynamics, DynOptions, DynamicsReport, SimState};
use crate::kinematics::{ee_jacobian, forward_kinematics, thruster_matrix_owned, KinWorkspace};
use crate::metrics::singularity::{tcm_metrics, tcm_svd_metrics, LostDirection, TcmMetrics};
use crate::model::Vehicle;
use crate::scenario::Mode;
use crate::state::VehicleState;
use crate::statics::{authority_at, AuthorityReference, N1Summary};

/// The kinematic part of the inspect report (stable JSON keys, SI units).
#[derive(Debug, Serialize)]
pub struct KinematicsReport {
    /// Design name.
    pub design: String,
    /// Total mass [kg].
    pub total_mass: f64,
    /// Total length [m].
    pub total_length: f64,
    /// End-effector position in the inertial frame [m].
    pub ee_position: [f64; 3],
    /// End-effector orientation (maps end-effector vectors to inertial), rows.
    pub ee_rotation: [[f64; 3]; 3],
    /// End-effector geometric Jacobian (USM-18) in the end-effector frame, 6×(6+n) rows.
    pub ee_jacobian: Vec<Vec<f64>>,
    /// Thruster configuration matrix T(q) (USM-26) in the base frame, 6×m rows.
    pub tcm: Vec<Vec<f64>>,
    /// Singular values of T(q), unscaled, six, descending (zeros when m < 6).
    pub tcm_singular_values: Vec<f64>,
    /// Numerical rank of T(q) with the relative tolerance `rank_tol`.
    pub tcm_rank: usize,
    /// Wrench directions T(q) cannot produce, each labelled by its dominant base axis.
    pub tcm_lost_directions: Vec<LostDirection>,
    /// Metrics of the moment-scaled T(q) (docs/model.md §6): σ_min, κ, rank, attainable wrench.
    pub tcm_scaled: TcmMetrics,
    /// Attainable authority along transport's commanded axes in N and N·m about the centre of
    /// mass, and N−1, at this configuration (docs/model.md §6).
    pub authority: AuthorityReport,
}

/// Attainable authority at the report's configuration (docs/model.md §6).
#[derive(Debug, Serialize)]
pub struct AuthorityReport {
    /// The mode whose default controller's commanded axes are scored (`transport`).
    pub mode: String,
    /// Those axes (`surge+sway+heave+pitch+yaw`).
    pub commanded_axes: String,
    /// The reference point (`com`).
    pub reference: String,
    /// The centre of mass in the base frame [m].
    pub reference_point: [f64; 3],
    /// Per axis and sign: the largest force [N] / moment [N·m] along it within the thrust
    /// limits, the other commanded axes at zero (`null` when uncommanded).
    pub attainable: AttainableAuthority,
    /// The smallest commanded force [N].
    pub min_force: f64,
    /// The smallest commanded moment [N·m].
    pub min_moment: f64,
    /// One thruster removed: per thruster and the worst case.
    pub n1: N1Summary,
}

/// The [`AuthorityReport`] of `v` at `q` [rad].
fn authority_report(v: &Vehicle, q: &[f64]) -> Result<AuthorityReport, PipelineError> {
    let mode = Mode::Transport;
    let dofs = mode.default_commanded_dofs();
    let (a, r, n1) = authority_at(v, dofs, &AuthorityReference::Com, q)?;
    Ok(AuthorityReport {
        mode: mode.to_string(),
        commanded_axes: dofs.label(),
        reference: AuthorityReference::Com.to_string(),
        reference_point: r,
        attainable: a,
        min_force: a.min_force(dofs.mask()),
        min_moment: a.min_moment(dofs.mask()),
        n1,
    })
}

/// The whole inspect report: kinematics and dynamics at one state.
#[derive(Debug)]
pub struct InspectReport {
    /// Kinematics and `T(q)`.
    pub kinematics: KinematicsReport,
    /// Mass matrix, bias, acceleration and energy (docs/model.md §4).
    pub dynamics: DynamicsReport,
    /// Wet weight, centres, metacentric height, restoring moments and trim at the state's
    /// joint angles (docs/model.md §4 "Restoring forces"); a property of the design, given
    /// also with `rigid`.
    pub hydrostatics: Hydrostatics,
    /// Whether the bodies were taken in vacuum (no added mass, drag, restoring forces or
    /// current).
    pub rigid: bool,
}

impl InspectReport {
    /// The report as one JSON object: the kinematic keys, then the dynamic keys, then `rigid`
    /// and `hydrostatics` (an object: `wet_weight` N, `roll_restoring_moment` and
    /// `pitch_restoring_moment` N·m/rad, `metacentric_height` m, trim angles, per body).
    pub fn to_json(&self) -> Result<serde_json::Value, PipelineError> {
        let mut obj = serde_json::to_value(&self.kinematics)?;
        let dv = serde_json::to_value(&self.dynamics)?;
        let hv = serde_json::to_value(&self.hydrostatics)?;
        if let (Some(o), serde_json::Value::Object(dm)) = (obj.as_object_mut(), dv) {
            o.extend(dm);
            o.insert("rigid".into(), serde_json::Value::Bool(self.rigid));
            o.insert("hydrostatics".into(), hv);
        }
        Ok(obj)
    }
}

fn rows(m: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|r| (0..m.ncols()).map(|c| m[(r, c)]).collect())
        .collect()
}

/// Evaluates the kinematic report of `v` at `s`; `rank_tol` is relative to σ_max.
pub fn kinematics_report(
    v: &Vehicle,
    s: &VehicleState,
    rank_tol: f64,
) -> Result<KinematicsReport, PipelineError> {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &s.q, &mut ws);
    let g_ie = s.base.to_se3().compose(&ws.g_be);
    let mut j = Mat::<f64>::zeros(6, v.n_dof());
    ee_jacobian(&ws, &mut j);
    let t = thruster_matrix_owned(v, &ws);
    let m = t.ncols();
    let u_min: Vec<f64> = v.thrusters.iter().map(|t| t.u_min).collect();
    let u_max: Vec<f64> = v.thrusters.iter().map(|t| t.u_max).collect();
    let singular = |what| move |source| PipelineError::Singularity { what, source };
    // A characteristic length of 1 m leaves T unscaled.
    let raw = tcm_svd_metrics(&t, 1.0, rank_tol).map_err(singular("analysing T(q)"))?;
    let scaled = tcm_metrics(&t, &u_min, &u_max, v.characteristic_length(), rank_tol)
        .map_err(singular("analysing the scaled T(q)"))?;
    Ok(KinematicsReport {
        design: v.name.clone(),
        total_mass: v.total_mass(),
        total_length: v.total_length(),
        ee_position: [g_ie.p.x, g_ie.p.y, g_ie.p.z],
        ee_rotation: [0, 1, 2].map(|r| [0, 1, 2].map(|c| g_ie.r[(r, c)])),
        ee_jacobian: rows(&j),
        tcm: (0..6)
            .map(|r| (0..m).map(|c| t[(r, c)]).collect())
            .collect(),
        tcm_singular_values: raw.singular_values.to_vec(),
        tcm_rank: raw.rank,
        tcm_lost_directions: raw.lost_directions,
        tcm_scaled: scaled,
        authority: authority_report(v, &s.q)?,
    })
}

/// Evaluates the kinematics (rank tolerance `rank_tol`, relative to σ_max) and the dynamics
/// (in vacuum when `rigid`) of `v` at `s`.
pub fn inspect(
    v: &Vehicle,
    s: &VehicleState,
    rank_tol: f64,
    rigid: bool,
) -> Result<InspectReport, PipelineError> {
    let kinematics = kinematics_report(v, s, rank_tol)?;
    let sim_state = SimState {
        pose: s.base,
        joint_angles: s.q.clone(),
        base_twist: s.twist,
        joint_rates: s.qd.clone(),
        thrust: vec![0.0; v.n_thrusters()],
    };
    let options = if rigid {
        DynOptions::rigid()
    } else {
        DynOptions::full()
    };
    let dynamics = inspect_dynamics(v, &sim_state, &s.generalized_forces, &options)
        .map_err(PipelineError::Dynamics)?;
    Ok(InspectReport {
        kinematics,
        dynamics,
        hydrostatics: hydrostatics(v, &s.q),
        rigid,
    })
}

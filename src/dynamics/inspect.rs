//! The dynamics part of `usm-study inspect`: `M`, `h`, `ζ̇` and kinetic energy at one state,
//! as a serialisable report (not a hot path: it allocates).

use super::algorithms::{dynamics_terms, solve_forward};
use super::error::{check_finite, DynError};
use super::workspace::DynWorkspace;
use super::{DynOptions, SimState};
use crate::model::Vehicle;
use nalgebra::DMatrix;
use serde::Serialize;

/// Dynamics at one state (docs/model.md §4), JSON keys as named.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DynamicsReport {
    /// Mass matrix `M(q)` (USM-22), rows of length 6+n; base block in `F_b`.
    pub mass_matrix: Vec<Vec<f64>>,
    /// Bias forces `h = Cζ + Dζ + N` (6+n) [N, N·m].
    pub bias: Vec<f64>,
    /// Generalised acceleration `ζ̇ = M⁻¹(τ − h)` for the given generalised forces τ, all
    /// joints torque-driven (6+n) [m/s², rad/s²].
    pub acceleration: Vec<f64>,
    /// `½ ζᵀ M ζ` [J].
    pub kinetic_energy: f64,
    /// Spectral condition number `λ_max / λ_min` of `M`.
    pub mass_matrix_condition: f64,
    /// Eigenvalues of `M`, ascending.
    pub mass_matrix_eigenvalues: Vec<f64>,
}

/// Evaluate `M`, `h`, the forward-dynamics acceleration under `generalized_forces`
/// (`τ = [τ_b; τ_q]`, base wrench in `F_b` [N, N·m] then joint torques [N·m]) and the kinetic
/// energy at `state` (its thrust states are ignored), with `options` (`DynOptions::rigid()`
/// for `inspect --rigid`). Errors name the offending input or a singular `M`.
pub fn inspect_dynamics(
    v: &Vehicle,
    state: &SimState,
    generalized_forces: &[f64],
    options: &DynOptions,
) -> Result<DynamicsReport, DynError> {
    let n = v.n_joints();
    let nv = v.n_dof();
    for (name, len, want) in [
        ("joint_angles", state.joint_angles.len(), n),
        ("joint_rates", state.joint_rates.len(), n),
        ("generalized_forces", generalized_forces.len(), nv),
    ] {
        if len != want {
            return Err(DynError::new(
                name,
                format!("has length {len}, expected {want}"),
            ));
        }
    }
    check_finite("base_position", state.pose.position.as_slice())?;
    check_finite("base_orientation", state.pose.orientation.coords.as_slice())?;
    check_finite("joint_angles", &state.joint_angles)?;
    check_finite("base_twist", state.base_twist.as_slice())?;
    check_finite("joint_rates", &state.joint_rates)?;
    let zeta = state.zeta();
    let mut ws = DynWorkspace::new(v);
    dynamics_terms(v, &mut ws, &state.pose, &state.joint_angles, &zeta, options);
    let m = DMatrix::from_fn(nv, nv, |r, c| ws.mass[(r, c)]);
    check_finite("mass_matrix", m.as_slice())?;
    let mut eig: Vec<f64> = m.clone().symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(f64::total_cmp);
    let (lo, hi) = (eig[0], eig[nv - 1]);
    let condition = if lo > 0.0 { hi / lo } else { f64::INFINITY };
    let kinetic_energy = 0.5
        * (m.transpose() * nalgebra::DVector::from_column_slice(&zeta))
            .dot(&nalgebra::DVector::from_column_slice(&zeta));
    solve_forward(&mut ws, generalized_forces)?;
    Ok(DynamicsReport {
        mass_matrix: (0..nv)
            .map(|r| (0..nv).map(|c| ws.mass[(r, c)]).collect())
            .collect(),
        bias: ws.bias.clone(),
        acceleration: ws.zeta_dot.clone(),
        kinetic_energy,
        mass_matrix_condition: condition,
        mass_matrix_eigenvalues: eig,
    })
}

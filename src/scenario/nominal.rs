//! The controller's own model when a world keeps it nominal (`[hydro] controller_nominal =
//! true`, docs/model.md §5 "Dynamic (base) control"): the base control's `M_11` and
//! `n = C_11 ζ + D_11 ζ + N_1` (USM-33/35) are evaluated on the design as the controller
//! knows it — no world scale factors (damping, drag, added mass, buoyancy, lift, thrust), no
//! centre-of-buoyancy shifts, still water, the mission payload's mass at the end effector but
//! neutrally buoyant — at the plant's measured state, while the plant integrates the world's
//! vehicle. Without the key the controller cancels the plant's own terms
//! (`Simulator::base_control_terms`), the identity every earlier study assumed.
//!
//! The allocator keeps the plant's thrust limits (a derated thruster saturates where the
//! allocator expects it to); only the terms the base control cancels are split.

use super::config::ScenarioFile;
use super::error::ScenarioError;
use crate::dynamics::{hybrid_terms, DynOptions, DynWorkspace, SimState};
use crate::input::located::KeyError;
use crate::model::Vehicle;
use crate::spatial::{Vec3, Vec6};
use nalgebra::Matrix6;

/// The nominal model of the controller and the buffers to evaluate it without allocating.
pub(crate) struct NominalModel {
    vehicle: Vehicle,
    ws: DynWorkspace,
    zeta: Vec<f64>,
    options: DynOptions,
}

impl NominalModel {
    /// The controller's model of `design` (the design as loaded, before the world) for the
    /// run `file`, or `None` when the file does not ask for it.
    pub(crate) fn of(design: &Vehicle, file: &ScenarioFile) -> Result<Option<Self>, ScenarioError> {
        if !file.hydro.controller_nominal {
            return Ok(None);
        }
        let mut vehicle = design.clone();
        vehicle.fluid.current = Vec3::zeros();
        let m = file.mission.payload_mass;
        vehicle
            .add_payload(m, m / vehicle.fluid.rho)
            .map_err(|e| ScenarioError::Key(KeyError::new(e.key, e.message)))?;
        let options = file.sim_config().map_err(ScenarioError::Key)?.options;
        Ok(Some(Self {
            ws: DynWorkspace::new(&vehicle),
            zeta: vec![0.0; vehicle.n_dof()],
            vehicle,
            options,
        }))
    }

    /// `M_11(q)` and `n(R_Ib, q, ζ)` of the nominal model at the plant's `state` (base frame,
    /// USM-33/35), as [`crate::dynamics::Simulator::base_control_terms`] gives the plant's.
    pub(crate) fn terms(&mut self, state: &SimState) -> (Matrix6<f64>, Vec6) {
        self.zeta[..6].copy_from_slice(state.base_twist.as_slice());
        self.zeta[6..].copy_from_slice(&state.joint_rates);
        hybrid_terms(
            &self.vehicle,
            &mut self.ws,
            &state.pose,
            &state.joint_angles,
            &self.zeta,
            &self.options,
        );
        (self.ws.mass_base_block(), self.ws.bias_base())
    }
}

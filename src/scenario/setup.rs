//! Setup of a closed-loop run: validate the file, put the vehicle in the file's current,
//! build the simulator at the initial state, the controllers and the allocator, and size
//! every buffer the loop needs once, so that no time step allocates.

use super::channels::check_log_size;
use super::config::ScenarioFile;
use super::controller::{Command, ModeController};
use super::error::ScenarioError;
use super::fault::Fault;
use super::nominal::NominalModel;
use crate::allocation::{Allocation, Allocator};
use crate::control::dynamic::DynamicController;
use crate::dynamics::{SimState, Simulator};
use crate::kinematics::KinWorkspace;
use crate::model::Vehicle;
use crate::spatial::{Vec3, Vec6};
use nalgebra::{Matrix6xX, UnitQuaternion, Vector3};

/// Everything the closed loop owns: the plant, the controllers, the allocator and the
/// per-period buffers. Built by [`ClosedLoop::new`]; stepped by `run::run_loop`.
pub(crate) struct ClosedLoop<'f> {
    /// The scenario.
    pub file: &'f ScenarioFile,
    /// The design with the file's current (docs/model.md §4).
    pub vehicle: Vehicle,
    /// The physics.
    pub sim: Simulator,
    /// Base dynamic control (USM-33).
    pub base_ctl: DynamicController,
    /// The mode's guidance and kinematic control.
    pub mode: ModeController,
    /// Thrust allocation (USM-36/37).
    pub allocator: Allocator,
    /// Forward kinematics of the current joint angles.
    pub ws: KinWorkspace,
    /// Thruster configuration matrix T(q), base frame.
    pub t_mat: Matrix6xX<f64>,
    /// The latest allocation (u held until the next control period).
    pub alloc: Allocation,
    /// The latest command (held until the next control period).
    pub cmd: Command,
    /// Measured joint rates [rad/s].
    pub qd_meas: Vec<f64>,
    /// Control periods in the run (the loop visits 0..=n_control).
    pub n_control: usize,
    /// The file's thruster fault, if any (`scenario::fault`).
    pub fault: Option<Fault>,
    /// The controller's own model when the world keeps it nominal (`hydro.controller_nominal`,
    /// `scenario::nominal`); `None`: the controller cancels the plant's terms.
    pub nominal: Option<NominalModel>,
}

/// The initial state of the file on `v`: position, yaw and (optionally) joint angles.
fn initial_state(v: &Vehicle, file: &ScenarioFile) -> Result<SimState, ScenarioError> {
    let n_joints = v.n_joints();
    let mut st = SimState::rest(v);
    st.pose.position = Vec3::from(file.initial.position);
    st.pose.orientation =
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), file.initial.yaw_deg.to_radians());
    if !file.initial.joint_angles_deg.is_empty() {
        if file.initial.joint_angles_deg.len() != n_joints {
            return Err(ScenarioError::JointCount {
                key: "initial.joint_angles_deg",
                found: file.initial.joint_angles_deg.len(),
                joints: n_joints,
            });
        }
        for (q, d) in st
            .joint_angles
            .iter_mut()
            .zip(&file.initial.joint_angles_deg)
        {
            *q = d.to_radians();
        }
    }
    Ok(st)
}

/// The allocator of the file's `[allocation]` table for the thrusters of `v`.
fn allocator(v: &Vehicle, file: &ScenarioFile) -> Result<Allocator, ScenarioError> {
    let n_thrusters = v.n_thrusters();
    let u_min: Vec<f64> = v.thrusters.iter().map(|t| t.u_min).collect();
    let u_max: Vec<f64> = v.thrusters.iter().map(|t| t.u_max).collect();
    let spec = &file.allocation;
    Allocator::new(
        spec.method,
        n_thrusters,
        &u_min,
        &u_max,
        &spec.weights_for(n_thrusters),
        spec.settings(n_thrusters),
    )
    .map_err(ScenarioError::Allocation)
}

impl<'f> ClosedLoop<'f> {
    /// Set up a run of `file` on `v`; a settings problem is the [`ScenarioError`] of the
    /// check that found it.
    pub fn new(v: &Vehicle, file: &'f ScenarioFile) -> Result<Self, ScenarioError> {
        file.validate()?;
        let s = &file.scenario;
        check_log_size(file, v)?;
        let nominal = NominalModel::of(v, file)?;
        let vehicle = file.world_vehicle(v).map_err(ScenarioError::Key)?;
        let v = &vehicle;
        let n_thrusters = v.n_thrusters();
        if n_thrusters == 0 {
            return Err(ScenarioError::NoThrusters);
        }
        let mut sim = Simulator::new(v, file.sim_config()?)?;
        sim.set_state(initial_state(v, file)?)?;
        let gains = file.mode_gains()?;
        let base_ctl =
            DynamicController::new(file.base_gains()).map_err(|source| ScenarioError::Control {
                prefix: "base_control.",
                source,
            })?;
        let q0 = sim.state().joint_angles.clone();
        let mode = ModeController::new(v, file, gains, &q0, &sim.state().pose)?;
        let allocator = allocator(v, file)?;
        let fault = (file.fault.as_ref())
            .map(|f| Fault::new(f, v))
            .transpose()
            .map_err(ScenarioError::Key)?;
        let cmd = Command {
            qd_ref: vec![0.0; q0.len()],
            q_ref: q0,
            tau_c: Vec6::zeros(),
        };
        Ok(Self {
            ws: KinWorkspace::new(v),
            t_mat: Matrix6xX::<f64>::zeros(n_thrusters),
            alloc: Allocation::new(n_thrusters),
            qd_meas: vec![0.0; v.n_joints()],
            n_control: (s.duration / s.control_dt).round() as usize,
            file,
            sim,
            base_ctl,
            mode,
            allocator,
            cmd,
            fault,
            vehicle,
            nominal,
        })
    }
}

//! The mode controller of the closed loop: guidance and kinematic control for the scenario's
//! mode (transport: LOS path following, USM-38…41; work: end-effector setpoint, USM-42)
//! followed by the base's dynamic control (USM-33). Work mode with a `[reference]` moves the
//! setpoint along the timed path of [`crate::control::spline`] and feeds its twist forward.
//! One enum holds the mode's law; the
//! command it produces (joint references, base wrench τ_c) and the signals it logs are
//! overwritten in place every control period.

use super::config::{ModeGains, ScenarioFile};
use super::error::ScenarioError;
use crate::control::dynamic::DynamicController;
use crate::control::guidance::PathSpec;
use crate::control::kinematic::{ee_pose, SecondaryTasks};
use crate::control::reference::Reference;
use crate::control::reference_source::ReferenceSource;
use crate::control::spline::PoseReference;
use crate::control::tracking::TrackingGains;
use crate::control::trajectory_file::TrajectoryTable;
use crate::control::transport::{measure_transport, TransportController};
use crate::control::work::{WorkController, WorkTarget};
use crate::kinematics::{forward_kinematics, BasePose, KinWorkspace};
use crate::model::Vehicle;
use crate::spatial::{euler_zyx, Vec3, Vec6};
use nalgebra::{Matrix6, UnitQuaternion};

/// What the transport law logs each control period (docs/model.md §5): each field is the
/// [`Channel`](super::channels::Channel) of the same name.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TransportSignals {
    pub psi: f64,
    pub psi_r: f64,
    pub cross_track: f64,
    pub along_track: f64,
    pub segment: f64,
    pub heading_error: f64,
    pub surge_error: f64,
    pub base_cross_track: f64,
    pub path_y: f64,
}

/// What the work law logs each control period: the `Setpoint`, `EePositionError`,
/// `EeOrientationError`, `EeDamping` and `TwistRef` channels.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WorkSignals {
    /// Setpoint position [m] and ZYX angles [rad], inertial frame.
    pub setpoint: [f64; 6],
    pub position_error: f64,
    pub orientation_error: f64,
    /// Damping λ of J_e^# in this period.
    pub damping: f64,
    /// Base velocity reference v_r in the base frame.
    pub twist_ref: Vec6,
}

/// The mode's control law and what it needs beyond the measurement.
pub(crate) enum ModeController {
    /// LOS path following; the path also gives the base's lateral offset (boxed: the
    /// transport law with its secondary-task buffers is large).
    Transport {
        law: Box<TransportController>,
        path: PathSpec,
        signals: TransportSignals,
    },
    /// End-effector setpoint regulation (boxed: the work law's workspace is large); with a
    /// reference, `target` follows it (pose and twist) every control period.
    Work {
        law: Box<WorkController>,
        target: WorkTarget,
        reference: Option<Box<(ReferenceSource, Reference)>>,
        signals: WorkSignals,
    },
    /// Work mode following a whole-state reference from a file (`[reference] file`): the base
    /// by [`TrackingGains::base_reference`] into the dynamic control, the joints by their
    /// servos; `ws` holds the forward kinematics of the reference (its end effector is the
    /// logged setpoint).
    Track {
        law: TrackingGains,
        source: Box<(ReferenceSource, Reference)>,
        ws: Box<KinWorkspace>,
        vehicle: Box<Vehicle>,
        signals: WorkSignals,
    },
}

/// The measurement one control period works from: the base pose and twist, the forward
/// kinematics of the current joint angles, the joint rates, and the base-control terms
/// (M11, n) of USM-33.
pub(crate) struct Measurement<'a> {
    /// Base pose g_Ib.
    pub base: &'a BasePose,
    /// Base twist V_b in F_b [m/s, rad/s].
    pub v_b: &'a Vec6,
    /// Forward kinematics of the current joint angles.
    pub ws: &'a KinWorkspace,
    /// Joint rates [rad/s].
    pub qd: &'a [f64],
    /// Base block M11 of the mass matrix (USM-33).
    pub m11: &'a Matrix6<f64>,
    /// Bias wrench n of USM-33, base frame.
    pub nvec: &'a Vec6,
    /// Whether T(q) can command a roll moment now (transport autopilot only; see
    /// [`ModeController::wants_roll_authority`]).
    pub roll_authority: bool,
}

/// The commands of one control period, held until the next (zero-order hold).
pub(crate) struct Command {
    /// Joint angle references [rad].
    pub q_ref: Vec<f64>,
    /// Joint rate references [rad/s].
    pub qd_ref: Vec<f64>,
    /// Base wrench to allocate, base frame [N, N·m].
    pub tau_c: Vec6,
}

/// Signed lateral offset of `p` from the line of a segment (positive left), for the base's
/// "tail follows the head" measure.
fn lateral_offset(p: &Vec3, from: [f64; 2], to: [f64; 2]) -> f64 {
    let d = [to[0] - from[0], to[1] - from[1]];
    let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if l == 0.0 {
        return 0.0;
    }
    (d[0] * (p.y - from[1]) - d[1] * (p.x - from[0])) / l
}

/// The `[secondary]` objectives of `file` on `v`, for the axes the mode commands
/// ([`ScenarioFile::commanded_dofs`]).
fn secondary_tasks(v: &Vehicle, file: &ScenarioFile) -> Result<SecondaryTasks, ScenarioError> {
    SecondaryTasks::new(
        v,
        file.secondary.clone(),
        file.commanded(),
        file.char_length(v),
    )
    .map_err(ScenarioError::from)
}

impl ModeController {
    /// The mode's controller from the file and its parsed `gains`; `q0` are the initial joint
    /// angles [rad] and `base0` the initial base pose (a work reference starts at the end
    /// effector's pose there).
    pub fn new(
        v: &Vehicle,
        file: &ScenarioFile,
        gains: ModeGains,
        q0: &[f64],
        base0: &BasePose,
    ) -> Result<Self, ScenarioError> {
        let control = |source| ScenarioError::Control {
            prefix: "control.",
            source,
        };
        Ok(match gains {
            ModeGains::Transport(g) => {
                let path = file.path.clone().ok_or(ScenarioError::MissingTable {
                    table: "path",
                    mode: "transport",
                })?;
                let mut law = Box::new(TransportController::new(v, g, &path).map_err(control)?);
                if file.secondary.enabled() {
                    law.set_secondary(secondary_tasks(v, file)?);
                }
                ModeController::Transport {
                    law,
                    path,
                    signals: TransportSignals::default(),
                }
            }
            ModeGains::Work(_) if file.reference_file().is_some() => track(v, file)?,
            ModeGains::Work(g) => {
                let sp = file.setpoint.as_ref().ok_or(ScenarioError::MissingTable {
                    table: "setpoint",
                    mode: "work",
                })?;
                let mut law = WorkController::new(v, &g).map_err(control)?;
                law.reset(q0);
                if file.secondary.enabled() {
                    law.set_secondary(secondary_tasks(v, file)?);
                }
                let r = sp.rpy_deg.map(f64::to_radians);
                let target = WorkTarget {
                    ee_position: Vec3::from(sp.position),
                    ee_orientation: UnitQuaternion::from_euler_angles(r[0], r[1], r[2]),
                    ee_twist: Vec6::zeros(),
                    base_position: Vec3::from(sp.base_position.unwrap_or(file.initial.position)),
                };
                let reference = match &file.reference {
                    Some(spec) => {
                        let mut ws = KinWorkspace::new(v);
                        forward_kinematics(v, q0, &mut ws);
                        let g = ee_pose(base0, &ws.g_be);
                        let a = euler_zyx(&g.r);
                        let start = [g.p.x, g.p.y, g.p.z, a.x, a.y, a.z];
                        let [x, y, z] = sp.position;
                        let end = [x, y, z, r[0], r[1], r[2]];
                        let via = spec.via_points();
                        let path = PoseReference::new(start, end, spec.duration, &via)?;
                        let n = v.n_joints();
                        Some(Box::new((
                            ReferenceSource::EndEffector(path),
                            Reference::new(n),
                        )))
                    }
                    None => None,
                };
                ModeController::Work {
                    law: Box::new(law),
                    target,
                    reference,
                    signals: WorkSignals::default(),
                }
            }
        })
    }

    /// Whether the mode's law uses [`Measurement::roll_authority`]: transport with the
    /// autopilot on (`control.autopilot`), so that the loop computes σ_min of T(q) only then.
    pub fn wants_roll_authority(&self) -> bool {
        matches!(self, ModeController::Transport { law, .. } if law.gains().autopilot)
    }

    /// One control period at time `t` [s] of length `dt` [s]: the mode's law, then the base's
    /// dynamic control; writes `cmd` and the logged signals.
    pub fn step(
        &mut self,
        t: f64,
        dt: f64,
        meas: &Measurement,
        base_ctl: &mut DynamicController,
        cmd: &mut Command,
    ) {
        match self {
            ModeController::Transport { law, path, signals } => {
                let mut tm = measure_transport(meas.base, meas.ws, meas.v_b, meas.qd);
                tm.roll_authority = meas.roll_authority;
                let out = law.step(t, &tm, dt);
                cmd.q_ref.copy_from_slice(law.q_ref());
                cmd.qd_ref.fill(0.0);
                cmd.tau_c = base_ctl
                    .transport_control(meas.m11, meas.nvec, &out.a_b, meas.v_b)
                    .0;
                let seg = out.los.segment;
                let p = &meas.base.position;
                let base_cross_track = if !path.segments.is_empty() {
                    let sg = &path.segments[seg.min(path.segments.len() - 1)];
                    lateral_offset(p, sg.from, sg.to)
                } else if path.waypoints.len() >= 2 {
                    let i = seg.min(path.waypoints.len() - 2);
                    lateral_offset(p, path.waypoints[i], path.waypoints[i + 1])
                } else {
                    f64::NAN
                };
                *signals = TransportSignals {
                    psi: tm.psi,
                    psi_r: out.los.psi_r,
                    cross_track: out.los.cross_track,
                    along_track: out.los.along_track,
                    segment: out.los.segment as f64,
                    heading_error: out.heading_error,
                    surge_error: out.surge_error,
                    base_cross_track,
                    // y of the path point nearest the end-effector: p_ee − e_y n, n the left
                    // normal.
                    path_y: tm.ee_position.y - out.los.cross_track * out.los.alpha.cos(),
                };
            }
            ModeController::Work {
                law,
                target,
                reference,
                signals,
            } => {
                let g_ie = meas.base.to_se3().compose(&meas.ws.g_be);
                if let Some(r) = reference {
                    let (source, sample) = &mut **r;
                    source.sample_into(t, &g_ie.r, sample);
                    if let Some(ee) = sample.ee {
                        (target.ee_position, target.ee_orientation, target.ee_twist) =
                            (ee.position, ee.orientation, ee.twist);
                    }
                }
                let out = law.step(meas.base, meas.ws, target, dt);
                cmd.q_ref.copy_from_slice(law.q_ref());
                cmd.qd_ref.copy_from_slice(law.qd_ref());
                let d = base_ctl.velocity_control(meas.m11, meas.nvec, meas.v_b, &out.v_r, dt);
                cmd.tau_c = d.tau_c;
                // Orientation error with roll excluded: the angle between the desired and the
                // actual end-effector x axes (the pointing direction).
                let x_d = target.ee_orientation * Vec3::x();
                let x_e = g_ie.r * Vec3::x();
                let sp = euler_zyx(target.ee_orientation.to_rotation_matrix().matrix());
                let p = &target.ee_position;
                *signals = WorkSignals {
                    setpoint: [p.x, p.y, p.z, sp.x, sp.y, sp.z],
                    position_error: (g_ie.p - target.ee_position).norm(),
                    orientation_error: x_d.dot(&x_e).clamp(-1.0, 1.0).acos(),
                    damping: out.damping,
                    twist_ref: out.v_r,
                };
            }
            ModeController::Track {
                law,
                source,
                ws,
                vehicle,
                signals,
            } => {
                let g_ie = meas.base.to_se3().compose(&meas.ws.g_be);
                let (src, r) = &mut **source;
                src.sample_into(t, &g_ie.r, r);
                let (v_r, ff) = law.base_reference(meas.base, r);
                cmd.q_ref.copy_from_slice(&r.q);
                cmd.qd_ref.copy_from_slice(&r.qd);
                let d = base_ctl.velocity_control(meas.m11, meas.nvec, meas.v_b, &v_r, dt);
                cmd.tau_c = d.tau_c + ff;
                forward_kinematics(vehicle, &r.q, ws);
                *signals = track_signals(&g_ie, r, ws, v_r);
            }
        }
    }
}

/// The work-mode channels of a tracked run: the reference's end effector (forward kinematics
/// of its base pose and joint angles, already in `ws`) as the setpoint, and the errors of the
/// measured end effector `g_ie` from it.
fn track_signals(
    g_ie: &crate::spatial::Se3,
    r: &Reference,
    ws: &mut KinWorkspace,
    v_r: Vec6,
) -> WorkSignals {
    let base = BasePose {
        orientation: r.base_orientation,
        position: r.base_position,
    };
    let g_d = ee_pose(&base, &ws.g_be);
    let x_d = g_d.r * Vec3::x();
    let x_e = g_ie.r * Vec3::x();
    let sp = euler_zyx(&g_d.r);
    WorkSignals {
        setpoint: [g_d.p.x, g_d.p.y, g_d.p.z, sp.x, sp.y, sp.z],
        position_error: (g_ie.p - g_d.p).norm(),
        orientation_error: x_d.dot(&x_e).clamp(-1.0, 1.0).acos(),
        damping: 0.0,
        twist_ref: v_r,
    }
}

/// The controller of a work-mode run following `[reference] file` (read here, once).
fn track(v: &Vehicle, file: &ScenarioFile) -> Result<ModeController, ScenarioError> {
    let spec = file.reference.as_ref().ok_or(ScenarioError::MissingTable {
        table: "reference",
        mode: "work",
    })?;
    let path = spec.file.as_deref().unwrap_or_default();
    let table = TrajectoryTable::read(std::path::Path::new(path), v.n_joints())?;
    let law = spec.tracking_gains();
    law.validate()
        .map_err(|source| ScenarioError::Control { prefix: "", source })?;
    Ok(ModeController::Track {
        law,
        source: Box::new((ReferenceSource::Table(table), Reference::new(v.n_joints()))),
        ws: Box::new(KinWorkspace::new(v)),
        vehicle: Box::new(v.clone()),
        signals: WorkSignals::default(),
    })
}

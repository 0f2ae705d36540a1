//! The logged channels of a closed-loop run as a type: every column of a trajectory is a
//! [`Channel`], so a consumer (metrics, figures, the table writers) names the channel it reads
//! by id and a renamed channel is a compile error instead of a missing column.
//!
//! [`Channel::name`] gives the column name written to `timeseries.csv` / `.parquet`;
//! [`channel_layout`] gives the column order of a run. Units are SI, angles in rad; poses are
//! in the inertial frame (ZYX Euler angles, docs/model.md §2), twists in the body's own frame.

use super::config::{Mode, ScenarioFile};
use crate::input::located::KeyError;
use crate::model::Vehicle;

/// A pose coordinate: position in the inertial frame [m] or a ZYX Euler angle [rad].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pose {
    /// Inertial x [m].
    X,
    /// Inertial y [m].
    Y,
    /// Inertial z [m].
    Z,
    /// Roll φ [rad].
    Roll,
    /// Pitch θ [rad].
    Pitch,
    /// Yaw ψ [rad].
    Yaw,
}

impl Pose {
    /// All six, in column order.
    pub const ALL: [Pose; 6] = [
        Pose::X,
        Pose::Y,
        Pose::Z,
        Pose::Roll,
        Pose::Pitch,
        Pose::Yaw,
    ];

    /// The column-name suffix (`x`, …, `yaw`).
    pub fn suffix(self) -> &'static str {
        match self {
            Pose::X => "x",
            Pose::Y => "y",
            Pose::Z => "z",
            Pose::Roll => "roll",
            Pose::Pitch => "pitch",
            Pose::Yaw => "yaw",
        }
    }
}

/// A twist component in the body's own frame: linear (u, v, w) [m/s], angular (p, q, r)
/// [rad/s].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Twist {
    /// Surge u [m/s].
    U,
    /// Sway v [m/s].
    V,
    /// Heave w [m/s].
    W,
    /// Roll rate p [rad/s].
    P,
    /// Pitch rate q [rad/s].
    Q,
    /// Yaw rate r [rad/s].
    R,
}

impl Twist {
    /// All six, in column order (linear first).
    pub const ALL: [Twist; 6] = [Twist::U, Twist::V, Twist::W, Twist::P, Twist::Q, Twist::R];

    /// The column-name suffix (`u`, …, `r`).
    pub fn suffix(self) -> &'static str {
        match self {
            Twist::U => "u",
            Twist::V => "v",
            Twist::W => "w",
            Twist::P => "p",
            Twist::Q => "q",
            Twist::R => "r",
        }
    }
}

/// One logged channel of a closed-loop run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Simulation time [s].
    T,
    /// Base pose in the inertial frame.
    BasePose(Pose),
    /// Base twist in the base frame.
    BaseTwist(Twist),
    /// End-effector pose in the inertial frame.
    EePose(Pose),
    /// End-effector twist in the end-effector frame.
    EeTwist(Twist),
    /// Transport: measured path angle ψ (USM-39) [rad].
    Psi,
    /// Transport: LOS reference angle ψ_r (USM-38) [rad].
    PsiR,
    /// Transport: cross-track error e_y of the end-effector (USM-38) [m].
    CrossTrack,
    /// Transport: along-track position on the active segment [m].
    AlongTrack,
    /// Transport: index of the active segment.
    Segment,
    /// Transport: heading error ψ_r − ψ [rad].
    HeadingError,
    /// Transport: surge error u_c − u [m/s].
    SurgeError,
    /// Transport: signed lateral offset of the base from the active segment (left positive) [m].
    BaseCrossTrack,
    /// Transport: inertial y of the path point nearest the end-effector [m].
    PathY,
    /// Work: end-effector setpoint pose in the inertial frame.
    Setpoint(Pose),
    /// Work: end-effector position error ‖p_e − p_d‖ [m].
    EePositionError,
    /// Work: end-effector pointing error (angle between the actual and desired x axes) [rad].
    EeOrientationError,
    /// Work: damping λ of the end-effector task's pseudoinverse J_e^# (USM-42) at this step;
    /// 0 outside the singular region (see `control::work::singularity_robust_damping`).
    EeDamping,
    /// Work: base velocity reference v_r (USM-42) in the base frame.
    TwistRef(Twist),
    /// Joint angle q_k [rad].
    Q(usize),
    /// Joint angle reference [rad].
    QRef(usize),
    /// Joint rate q̇_k [rad/s].
    Qd(usize),
    /// Joint torque τ_k [N·m].
    Tau(usize),
    /// Joint work `∫ Σ_k |τ_k q̇_k| dt` since t = 0 [J], integrated by the simulator with the
    /// motion (the joint-energy metric, docs/model.md §6).
    JointWork,
    /// Commanded (allocated) thrust of thruster j [N]; after a `[fault]` struck, the faulted
    /// thruster's command (`scenario::fault`).
    UCmd(usize),
    /// Actual thrust of thruster j, clamped to its limits [N].
    U(usize),
    /// Shaft power of thruster j by momentum theory with axial inflow [W] (docs/model.md §6): of the
    /// thrust held over the control interval starting at this sample (the allocation
    /// saturated to the limits), the integrand of `thruster_energy`.
    Power(usize),
    /// Axial inflow V_a of thruster j [m/s]: its velocity relative to the water along the
    /// direction it pushes the vehicle (positive when moving the way it pushes).
    Inflow(usize),
    /// Scaled σ_min of the thruster configuration matrix T(q), all six wrench axes (docs/model.md §6).
    SigmaMin,
    /// Scaled σ_min of the rows of T(q) the controller commands, `S·T_L` (docs/model.md §6): the
    /// weakest commanded wrench per newton of thrust norm (N per N), see
    /// [`crate::metrics::singularity::commanded_sigma`].
    SigmaMinCommanded,
    /// Allocation slack norm ‖s‖ [N or N·m].
    SlackNorm,
    /// Allocation status code: 0 solved, 1 slack active, 2 bounds violated, 3 failed.
    AllocStatus,
}

/// The transport-mode channels, in column order.
const TRANSPORT: [Channel; 9] = [
    Channel::Psi,
    Channel::PsiR,
    Channel::CrossTrack,
    Channel::AlongTrack,
    Channel::Segment,
    Channel::HeadingError,
    Channel::SurgeError,
    Channel::BaseCrossTrack,
    Channel::PathY,
];

impl Channel {
    /// The column name in trajectory tables (`t`, `base_x`, `ee_u`, `cross_track`, `u_3`, …).
    /// Indexed families are numbered from 1 like the design's names (joint `q1`, thruster
    /// `T1`): `Channel::Q(0)` is `q_1`, `Channel::U(2)` is `u_3`.
    pub fn name(self) -> String {
        let fixed = match self {
            Channel::T => "t",
            Channel::Psi => "psi",
            Channel::PsiR => "psi_r",
            Channel::CrossTrack => "cross_track",
            Channel::AlongTrack => "along_track",
            Channel::Segment => "segment",
            Channel::HeadingError => "heading_error",
            Channel::SurgeError => "surge_error",
            Channel::BaseCrossTrack => "base_cross_track",
            Channel::PathY => "path_y",
            Channel::EePositionError => "ee_position_error",
            Channel::EeOrientationError => "ee_orientation_error",
            Channel::EeDamping => "ee_damping",
            Channel::SigmaMin => "sigma_min",
            Channel::SigmaMinCommanded => "sigma_min_commanded",
            Channel::SlackNorm => "slack_norm",
            Channel::AllocStatus => "alloc_status",
            Channel::JointWork => "joint_work",
            Channel::BasePose(a) => return format!("base_{}", a.suffix()),
            Channel::BaseTwist(a) => return format!("base_{}", a.suffix()),
            Channel::EePose(a) => return format!("ee_{}", a.suffix()),
            Channel::EeTwist(a) => return format!("ee_{}", a.suffix()),
            Channel::Setpoint(a) => return format!("sp_{}", a.suffix()),
            Channel::TwistRef(a) => return format!("ref_{}", a.suffix()),
            Channel::Q(k) => return format!("q_{}", k + 1),
            Channel::QRef(k) => return format!("qref_{}", k + 1),
            Channel::Qd(k) => return format!("qd_{}", k + 1),
            Channel::Tau(k) => return format!("tau_{}", k + 1),
            Channel::UCmd(j) => return format!("ucmd_{}", j + 1),
            Channel::U(j) => return format!("u_{}", j + 1),
            Channel::Power(j) => return format!("power_{}", j + 1),
            Channel::Inflow(j) => return format!("inflow_{}", j + 1),
        };
        fixed.to_string()
    }
}

/// The channels of a run in column order: time, base and end-effector pose and twist, the
/// mode's channels, the per-joint blocks (q, q_ref, q̇, τ), the joint work, the per-thruster blocks
/// (commanded, actual, power, inflow), then σ_min (all axes, then the commanded ones) and the
/// allocation outcome.
pub fn channel_layout(mode: Mode, n_joints: usize, n_thrusters: usize) -> Vec<Channel> {
    let mut c = vec![Channel::T];
    c.extend(Pose::ALL.map(Channel::BasePose));
    c.extend(Twist::ALL.map(Channel::BaseTwist));
    c.extend(Pose::ALL.map(Channel::EePose));
    c.extend(Twist::ALL.map(Channel::EeTwist));
    match mode {
        Mode::Transport => c.extend(TRANSPORT),
        Mode::Work => {
            c.extend(Pose::ALL.map(Channel::Setpoint));
            c.extend([
                Channel::EePositionError,
                Channel::EeOrientationError,
                Channel::EeDamping,
            ]);
            c.extend(Twist::ALL.map(Channel::TwistRef));
        }
    }
    for family in [Channel::Q, Channel::QRef, Channel::Qd, Channel::Tau] {
        c.extend((0..n_joints).map(family));
    }
    c.push(Channel::JointWork);
    for family in [Channel::UCmd, Channel::U, Channel::Power, Channel::Inflow] {
        c.extend((0..n_thrusters).map(family));
    }
    c.extend([
        Channel::SigmaMin,
        Channel::SigmaMinCommanded,
        Channel::SlackNorm,
        Channel::AllocStatus,
    ]);
    c
}

/// Column-oriented time series of one run: one f64 column per [`Channel`], all of equal
/// length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    channels: Vec<Channel>,
    columns: Vec<Vec<f64>>,
}

impl Trajectory {
    /// An empty trajectory with the given channels, each column reserved for `capacity`
    /// samples (so that appending up to that many rows does not allocate).
    pub fn with_channels(channels: Vec<Channel>, capacity: usize) -> Self {
        let columns = channels
            .iter()
            .map(|_| Vec::with_capacity(capacity))
            .collect();
        Self { channels, columns }
    }

    /// The channels, in column order.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// `(channel, samples)` in column order.
    pub fn iter(&self) -> impl Iterator<Item = (Channel, &[f64])> {
        self.channels
            .iter()
            .zip(&self.columns)
            .map(|(c, x)| (*c, x.as_slice()))
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |c| c.len())
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A channel's samples, if the run logged it.
    pub fn get(&self, channel: Channel) -> Option<&[f64]> {
        self.channels
            .iter()
            .position(|c| *c == channel)
            .map(|i| self.columns[i].as_slice())
    }

    /// An indexed family in index order, e.g. `indexed(Channel::U)` for the actual thrusts
    /// `u_1, u_2, …` (stops at the first index the run did not log).
    pub fn indexed(&self, family: fn(usize) -> Channel) -> Vec<&[f64]> {
        (0..).map_while(|k| self.get(family(k))).collect()
    }

    /// Append one sample of every channel (`row` in column order). Does not allocate while
    /// the reserved capacity lasts.
    pub fn push_row(&mut self, row: &[f64]) {
        for (c, x) in self.columns.iter_mut().zip(row) {
            c.push(*x);
        }
    }
}

/// Largest in-memory log of one run [bytes]: a request above it is refused before the run
/// (the trajectory reserves its columns up front; refusing beats an allocation abort).
pub const MAX_LOG_BYTES: f64 = 1.0e9;

/// The run's log must fit in [`MAX_LOG_BYTES`]: `duration / log_dt` rows of the mode's
/// channels (8 bytes each).
pub fn check_log_size(f: &ScenarioFile, v: &Vehicle) -> Result<(), KeyError> {
    let s = &f.scenario;
    let rows = (s.duration / s.log_dt).floor() + 2.0;
    let cols = channel_layout(s.mode, v.n_joints(), v.n_thrusters()).len() as f64;
    let bytes = rows * cols * 8.0;
    if bytes > MAX_LOG_BYTES {
        return Err(KeyError::new(
            "scenario.log_dt",
            format!(
                "the log would hold {rows:.0} rows × {cols:.0} channels ≈ {:.1} GB, more than \
                 {:.0} GB: raise scenario.log_dt or shorten scenario.duration",
                bytes / 1e9,
                MAX_LOG_BYTES / 1e9
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::scenario::channels::{channel_layout, Channel, Trajectory};
    use crate::scenario::config::Mode;

    #[test]
    fn layout_names_are_the_published_columns() {
        let names: Vec<String> = channel_layout(Mode::Transport, 1, 2)
            .into_iter()
            .map(Channel::name)
            .collect();
        let expected = "t base_x base_y base_z base_roll base_pitch base_yaw base_u base_v \
            base_w base_p base_q base_r ee_x ee_y ee_z ee_roll ee_pitch ee_yaw ee_u ee_v ee_w \
            ee_p ee_q ee_r psi psi_r cross_track along_track segment heading_error surge_error \
            base_cross_track path_y q_1 qref_1 qd_1 tau_1 joint_work ucmd_1 ucmd_2 u_1 u_2 power_1 power_2 \
            inflow_1 inflow_2 sigma_min sigma_min_commanded slack_norm alloc_status";
        assert_eq!(names.join(" "), expected);
        let work: Vec<String> = channel_layout(Mode::Work, 0, 1)
            .into_iter()
            .map(Channel::name)
            .collect();
        let expected = "sp_x sp_y sp_z sp_roll sp_pitch sp_yaw ee_position_error \
            ee_orientation_error ee_damping ref_u ref_v ref_w ref_p ref_q ref_r joint_work ucmd_1 \
            u_1 power_1 inflow_1";
        assert_eq!(work[25..45].join(" "), expected);
    }

    #[test]
    fn channels_are_looked_up_by_id() {
        let mut t = Trajectory::with_channels(channel_layout(Mode::Work, 2, 3), 4);
        let row: Vec<f64> = (0..t.channels().len()).map(|i| i as f64).collect();
        t.push_row(&row);
        assert_eq!(t.len(), 1);
        assert_eq!(t.get(Channel::T), Some(&[0.0][..]));
        assert_eq!(t.get(Channel::CrossTrack), None);
        let u = t.indexed(Channel::U);
        assert_eq!(u.len(), 3);
        let u0 = t
            .channels()
            .iter()
            .position(|c| *c == Channel::U(0))
            .unwrap();
        assert_eq!(u[0], &[u0 as f64][..]);
    }
}

//! The columns of the per-run files in the data dictionary ([`super`]): `timeseries.csv` of
//! `simulate` (and a sweep's `trajectory_best/worst.csv`) and `history.csv` of `optimise`, and
//! the [`ColumnDoc`] record every table of the dictionary is made of.

/// One column (or family of columns: `seg{k}_…`, `tuned.<param>`, `<m>_mean`, …).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColumnDoc {
    /// The name, or its pattern.
    pub name: &'static str,
    /// The unit (`–` for dimensionless, `0/1` for a flag).
    pub unit: &'static str,
    /// The type as stored: `f64`, `i64`, `bool` or `str`.
    pub kind: &'static str,
    /// What it means.
    pub meaning: &'static str,
}

pub(super) const fn c(
    name: &'static str,
    unit: &'static str,
    kind: &'static str,
    meaning: &'static str,
) -> ColumnDoc {
    ColumnDoc {
        name,
        unit,
        kind,
        meaning,
    }
}

/// `timeseries.csv`: one row per logged step.
pub(super) const TIMESERIES_CSV: &[ColumnDoc] = &[
    c("t", "s", "f64", "simulation time"),
    c(
        "base_<pose>",
        "m, rad",
        "f64",
        "base pose in the inertial frame: x, y, z [m], roll, pitch, yaw [rad] (ZYX)",
    ),
    c(
        "base_<twist>",
        "m/s, rad/s",
        "f64",
        "base twist in the base frame: u, v, w [m/s], p, q, r [rad/s]",
    ),
    c(
        "ee_<pose>",
        "m, rad",
        "f64",
        "end-effector pose in the inertial frame (as base_<pose>)",
    ),
    c(
        "ee_<twist>",
        "m/s, rad/s",
        "f64",
        "end-effector twist in the end-effector frame (as base_<twist>)",
    ),
    c(
        "sp_<pose>",
        "m, rad",
        "f64",
        "work: end-effector setpoint in the inertial frame",
    ),
    c(
        "ref_<twist>",
        "m/s, rad/s",
        "f64",
        "work: base velocity reference v_r (USM-42), base frame",
    ),
    c(
        "psi",
        "rad",
        "f64",
        "transport: measured path angle ψ (USM-39)",
    ),
    c(
        "psi_r",
        "rad",
        "f64",
        "transport: LOS reference angle ψ_r (USM-38)",
    ),
    c(
        "cross_track",
        "m",
        "f64",
        "transport: cross-track error e_y of the end effector (USM-38), left positive",
    ),
    c(
        "along_track",
        "m",
        "f64",
        "transport: along-track position on the active segment",
    ),
    c(
        "segment",
        "–",
        "f64",
        "transport: index of the active path segment",
    ),
    c("heading_error", "rad", "f64", "transport: ψ_r − ψ"),
    c("surge_error", "m/s", "f64", "transport: u_c − u"),
    c(
        "base_cross_track",
        "m",
        "f64",
        "transport: signed lateral offset of the base from the active segment",
    ),
    c(
        "path_y",
        "m",
        "f64",
        "transport: inertial y of the path point nearest the end effector",
    ),
    c("ee_position_error", "m", "f64", "work: ‖p_e − p_d‖"),
    c(
        "ee_orientation_error",
        "rad",
        "f64",
        "work: angle between the actual and desired end-effector x axes",
    ),
    c(
        "ee_damping",
        "–",
        "f64",
        "work: damping λ of J_e^# (USM-42), 0 outside the singular region",
    ),
    c("q_<i>", "rad", "f64", "joint i angle (joints and thrusters numbered from 1 like the design's names: `q_1` is joint `q1`, `u_1` thruster `T1`)"),
    c("qref_<i>", "rad", "f64", "joint i angle reference"),
    c("qd_<i>", "rad/s", "f64", "joint i rate"),
    c("tau_<i>", "N·m", "f64", "joint i motor torque"),
    c("joint_work", "J", "f64", "∫Σ|τ_i q̇_i| dt since t = 0"),
    c(
        "ucmd_<i>",
        "N",
        "f64",
        "thruster i commanded (allocated) thrust",
    ),
    c(
        "u_<i>",
        "N",
        "f64",
        "thruster i actual thrust, within its limits (a faulted thruster's real output)",
    ),
    c(
        "power_<i>",
        "W",
        "f64",
        "thruster i shaft power by momentum theory with axial inflow",
    ),
    c("inflow_<i>", "m/s", "f64", "thruster i axial inflow V_a"),
    c(
        "sigma_min",
        "N/N",
        "f64",
        "scaled σ_min of T(q), all six axes",
    ),
    c(
        "sigma_min_commanded",
        "N/N",
        "f64",
        "scaled σ_min of the commanded rows S·T_L",
    ),
    c("slack_norm", "N or N·m", "f64", "allocation slack ‖s‖"),
    c(
        "alloc_status",
        "–",
        "f64",
        "allocation outcome code (0 solved)",
    ),
];

/// `history.csv`: one row per evaluation.
pub(super) const HISTORY_CSV: &[ColumnDoc] = &[
    c(
        "evaluation",
        "–",
        "i64",
        "evaluation number (0: the start point)",
    ),
    c(
        "run",
        "–",
        "i64",
        "solver run (0: the start point; then the first run and restarts)",
    ),
    c("iteration", "–", "i64", "argmin iteration within the run"),
    c(
        "<parameter>",
        "as the key",
        "f64",
        "each parameter's physical value, named by its key (e.g. `control.k_psi`)",
    ),
    c(
        "<metric>",
        "as in cases.csv",
        "f64",
        "each metric the problem reads, as described above",
    ),
    c(
        "objective",
        "–",
        "f64",
        "weighted objective, each term normalised by its value at the start point",
    ),
    c(
        "violation",
        "–",
        "f64",
        "total normalised constraint violation (0 when feasible)",
    ),
    c("feasible", "0/1", "f64", "every constraint holds"),
    c(
        "best_so_far",
        "–",
        "f64",
        "best objective so far (feasibility first)",
    ),
    c(
        "repeat",
        "0/1",
        "f64",
        "served from memory: the point was evaluated before",
    ),
    c(
        "failure",
        "–",
        "str",
        "why the evaluation failed, if it did",
    ),
];

//! The data dictionary of a study's output tables (issue 25 item 5, first part): every column
//! `cases.csv` / `cases.parquet`, `worlds.csv` and `tuning.csv` can carry, with its unit, type
//! and meaning. `docs/columns.md` is [`columns_markdown`] (tests/columns.rs keeps them equal
//! and checks that every name of the metric catalogue — design, static `T(q)`, run metrics of
//! both modes, tuning, worlds — is described here).

#[path = "dictionary_files.rs"]
mod files;
pub use files::ColumnDoc;
use files::{c, HISTORY_CSV, TIMESERIES_CSV};

/// The tables and their columns, in the order they appear.
pub const DICTIONARY: &[(&str, &[ColumnDoc])] = &[
    ("cases.csv: identity and status", IDENTITY),
    ("cases.csv: the design", DESIGN),
    ("cases.csv: the static T(q) analysis (`[static]`)", STATIC),
    (
        "cases.csv: attainable authority and N−1 (`[static]`, docs/model.md §6)",
        AUTHORITY,
    ),
    ("cases.csv: per-case tuning (`[tune]`)", TUNING),
    ("cases.csv: the optimal-control bound (`[ocp]`)", OCP),
    ("cases.csv: the closed-loop run, both modes", RUN_COMMON),
    ("cases.csv: transport runs", RUN_TRANSPORT),
    ("cases.csv: work runs", RUN_WORK),
    (
        "cases.csv: uncertain worlds and ranking (`[uncertainty]`, `[[validate]]`)",
        WORLDS,
    ),
    ("cases.csv: single thruster faults (`[faults]`)", FAULTS),
    ("worlds.csv (one row per case and world)", WORLDS_CSV),
    ("tuning.csv (one row per case and tuning run)", TUNING_CSV),
    (
        "timeseries.csv of `simulate`, trajectory_best/worst.csv of sweeps (one row per logged step)",
        TIMESERIES_CSV,
    ),
    ("history.csv of `optimise` (one row per evaluation)", HISTORY_CSV),
];

const IDENTITY: &[ColumnDoc] = &[
    c("case_id", "–", "i64", "case number, dense from 0 in the order of the design of experiments"),
    c("hash", "–", "str", "hash of the case's resolved tables, seed and tuning: identifies a row across runs, resumes and merges"),
    c("<axis name>", "as the key", "f64 or str", "the case's value of each `[[axis]]` (e.g. `design.links`), named as written"),
    c("status", "–", "str", "`ok` (ran and met every `[success]` criterion), `unsuccessful`, `failed` or `skipped`"),
    c("reason", "–", "str", "why the case is not `ok`: the first criterion missed and by how much, or the error"),
];

const DESIGN: &[ColumnDoc] = &[
    c(
        "design_bodies",
        "–",
        "i64",
        "number of rigid bodies of the built design",
    ),
    c("design_joints", "–", "i64", "number of revolute joints"),
    c("design_thrusters", "–", "i64", "number of thrusters"),
    c(
        "design_length_m",
        "m",
        "f64",
        "length of the straight chain, tail face to head face",
    ),
    c("design_mass_kg", "kg", "f64", "total mass of the bodies"),
];

const STATIC: &[ColumnDoc] = &[
    c("tcm_singular_fraction", "–", "f64", "fraction of sampled joint configurations whose scaled σ_min of T(q) (all six rows) is below the threshold: how often T(q) is singular"),
    c("tcm_rank_deficient_fraction", "–", "f64", "fraction of configurations where T(q) loses rank numerically"),
    c("tcm_sigma_min_min", "–", "f64", "smallest scaled σ_min over the samples (all six rows)"),
    c("tcm_sigma_min_p05", "–", "f64", "5 % quantile of the scaled σ_min"),
    c("tcm_sigma_min_p50", "–", "f64", "median scaled σ_min"),
    c("tcm_sigma_min_mean", "–", "f64", "mean scaled σ_min"),
    c("tcm_kappa_p50", "–", "f64", "median condition number κ of the scaled T(q)"),
    c("tcm_kappa_p95", "–", "f64", "95 % quantile of κ"),
    c("tcm_straight_sigma_min", "–", "f64", "scaled σ_min of the straight configuration q = 0"),
    c("tcm_lost_surge … tcm_lost_yaw", "–", "f64", "fraction of configurations in which each base axis (surge, sway, heave, roll, pitch, yaw) is the lost direction"),
    c("tcm_singular_fraction_commanded", "–", "f64", "as tcm_singular_fraction, for the rows the mode's controller commands"),
    c("tcm_sigma_min_commanded_min", "–", "f64", "smallest scaled σ_min of the commanded rows"),
    c("tcm_sigma_min_commanded_p05", "–", "f64", "5 % quantile of the commanded rows' σ_min"),
    c("tcm_sigma_min_commanded_p50", "–", "f64", "median of the commanded rows' σ_min"),
    c("tcm_kappa_commanded_p50", "–", "f64", "median κ of the commanded rows"),
    c("tcm_straight_sigma_min_commanded", "–", "f64", "σ_min of the commanded rows at q = 0"),
];

const AUTHORITY: &[ColumnDoc] = &[
    c("authority_surge_pos, authority_surge_neg … authority_yaw_pos, authority_yaw_neg", "N (surge, sway, heave), N·m (roll, pitch, yaw)", "f64", "per base axis and sign, the smallest over the sampled configurations (full joint limits) of the largest force or moment the thrusters deliver along that axis within their limits, the other commanded axes held at zero and the uncommanded ones free, moments about `static.authority_reference` (default the centre of mass); NaN for an uncommanded axis"),
    c("authority_min_force", "N", "f64", "smallest of the commanded force columns above (the weakest commanded force anywhere in the joint limits)"),
    c("authority_min_moment", "N·m", "f64", "smallest of the commanded moment columns above"),
    c("authority_straight_min_force", "N", "f64", "smallest commanded force (axes and signs) at the straight configuration q = 0"),
    c("authority_straight_min_moment", "N·m", "f64", "smallest commanded moment at q = 0"),
    c("authority_mission_min_force", "N", "f64", "as authority_min_force over the declared mission range (`static.joint_range` / `joint_ranges`); NaN without one"),
    c("authority_mission_min_moment", "N·m", "f64", "as authority_min_moment over the declared mission range; NaN without one"),
    c("under_actuated", "0/1", "bool", "a flag, not ranked: 1 when a commanded axis is unattainable (≤ 1e-6 × the largest thrust limit, either sign) at every sampled configuration"),
    c("under_actuated_axes", "bitmask", "i64", "an identifier, not ranked: bitmask of those axes: surge 1, sway 2, heave 4, roll 8, pitch 16, yaw 32 (0: none)"),
    c("n1_worst_force", "N", "f64", "N−1: smallest commanded force with one thruster removed (held at zero thrust), over thrusters and the N−1 configurations (q = 0 and the first `static.n1_samples` samples)"),
    c("n1_worst_moment", "N·m", "f64", "N−1: smallest commanded moment with one thruster removed"),
    c("n1_mean_force", "N", "f64", "N−1: mean over the removed thruster of its smallest commanded force"),
    c("n1_mean_moment", "N·m", "f64", "N−1: mean over the removed thruster of its smallest commanded moment"),
    c("n1_worst_thruster", "index", "i64", "number (from 1: thruster `T1` is 1) of the thruster whose removal loses the largest fraction of authority; an identifier, not ranked"),
    c("n1_worst_loss", "–", "f64", "that fraction: the largest n1_loss_t{i}"),
    c("n1_loss_t{i}", "–", "f64", "fraction of authority lost when thruster `T<i>` (i = 1 … 16) is removed, worst commanded axis, sign and N−1 configuration: 1 − (authority without it)/(authority with it), over the axes and signs it had authority on (0: nothing lost, 1: an axis lost entirely); NaN beyond the design's thrusters"),
];

const TUNING: &[ColumnDoc] = &[
    c("tuned.<param>", "as the key", "f64", "the tuned value of each `[[tune.param]]` (e.g. `tuned.control.k_psi`), at which the case is scored"),
    c("tune_evaluations", "–", "i64", "fresh closed-loop runs the tuning used"),
    c("tune_feasible", "0/1", "bool", "1 when the tuned point met every `[[tune.constraint]]`"),
    c("tune_noise", "–", "f64", "relative spread (max − min)/min of the tuned objective: with `[tune] seeds` ≥ 2, of each seed's best point run in the pooled tuning worlds of every seed; else of the best feasible objective across the independent tuning starts (`[tune] starts`); NaN with one start and one seed"),
    c("tune_success_spread", "–", "f64", "with `[tune] seeds` ≥ 2: spread (max − min) over the seeds of the fraction of the pooled tuning worlds in which each seed's best point meets every `[[tune.constraint]]`"),
    c("tune_bound_hits", "–", "i64", "tuned parameters within 0.1 % of a bound of their box"),
];

const OCP: &[ColumnDoc] = &[
    c("ocp_energy", "J", "f64", "with `[ocp]`: the optimal-control bound of the case's design on the section's straight transport leg (from rest to rest, thrusts and joint torques as controls, full hydrodynamics): thruster shaft energy at zero inflow plus joint mechanical energy of the best local optimum found over the starts (never claimed global); the same definitions as the closed loop's `thruster_energy_static` and `joint_energy`"),
    c("ocp_energy_per_metre", "J/m", "f64", "`ocp_energy` per metre of the leg"),
    c("ocp_energy_spread", "–", "f64", "(max − min)/min of the converged starts' objectives; NaN with fewer than two converged starts"),
    c("ocp_status", "code", "i64", "the best start's status: 0 converged (KKT ≤ tolerance), 1 max iterations, 2 stalled (line search found no acceptable step), 3 infeasible, 4 diverged"),
    c("ocp_kkt", "–", "f64", "the best start's largest KKT residual (primal, stationarity, complementarity)"),
    c("ocp_primal", "–", "f64", "the best start's primal residual (dynamics defects and the leg's terminal rows): at most the tolerance means a trajectory the model can fly that ends the leg"),
    c("ocp_work_error", "–", "f64", "the best start's work-balance error on its grid: `\\|W_other − W_other,refined\\| / max(\\|W_act\\|, \\|W_act,refined\\|)` with its controls integrated 10× finer (docs/ocp.md §6); above 0.05 the optimum swims on energy the grid's integration supplies, and the bound does not count"),
    c("ocp_world_energy_per_metre_min", "J/m", "f64", "with `[ocp] worlds = K`: the least bound per metre that counts over the study's first K scoring worlds (each warm-started from the nominal optimum); NaN when none counts"),
    c("ocp_world_energy_per_metre_max", "J/m", "f64", "the greatest of the same"),
    c("ocp_world_feasible", "–", "i64", "how many of those K worlds have a bound that counts (0 when the nominal bound does not count: the worlds are not tried)"),
    c("ocp_world_iterations", "–", "i64", "SQP iterations of every world's solve together (0: not tried)"),
    c("ocp_world_grid_rejected", "–", "i64", "worlds whose leg ended primal feasible but was rejected: the grid supplied its energy (work error above 5 %)"),
    c("ocp_iterations", "–", "i64", "SQP iterations of every start of the design's solve together (one solve per design, shared by its cases)"),
    c("controller_efficiency", "–", "f64", "`ocp_energy_per_metre` / the closed loop's `(thruster_energy_static + joint_energy) / path_progress` in the nominal world (NaN when the bound does not count: `ocp_primal` above the `[ocp]` tolerance or `ocp_work_error` above 0.05): ≤ 1 when both are right, > 1 flags an error of one of them (the two missions differ: the leg is straight from rest to rest, the run follows the study's path)"),
];

const RUN_COMMON: &[ColumnDoc] = &[
    c("completed", "0/1", "bool", "the run did not fail numerically: it reached its duration, or was ended on a certain `[success]` miss (`stopped_at`)"),
    c("simulated_time", "s", "f64", "simulated time reached"),
    c("stopped_at", "s", "f64", "with `[success] stop_on_failure` (the default): the time the run was ended at because the criterion its verdict names could no longer be met (its metrics go that far); NaN for a run that went to its end or failed"),
    c("thruster_energy", "J", "f64", "thruster shaft energy by actuator-disk momentum theory with each thruster's axial inflow"),
    c("thruster_energy_static", "J", "f64", "the same thrusts at zero inflow"),
    c("effort_sq", "N²·s", "f64", "∫‖u‖² dt of the thrust held over each control interval"),
    c("effort_abs", "N·s", "f64", "∫Σ|u_j| dt"),
    c("joint_energy", "J", "f64", "∫Σ|τ_q,i q̇_i| dt of the joint motors"),
    c("joint_torque_peak", "N·m", "f64", "largest joint motor torque"),
    c("peak_thrust", "N", "f64", "largest thrust of any thruster at a control tick"),
    c("saturation_fraction", "–", "f64", "fraction of control intervals with a thruster at a limit"),
    c("singularity_exposure", "–", "f64", "fraction of time σ_min of the commanded rows of T(q) is below `[metrics] threshold`"),
    c("singularity_exposure_full", "–", "f64", "the same for all six rows"),
    c("sigma_min_min", "–", "f64", "smallest scaled σ_min of T(q) (all rows) over the run"),
    c("sigma_min_mean", "–", "f64", "mean scaled σ_min over the run"),
    c("sigma_min_commanded_min", "–", "f64", "smallest σ_min of the commanded rows over the run"),
    c("sigma_min_commanded_mean", "–", "f64", "mean σ_min of the commanded rows"),
    c("slack_fraction", "–", "f64", "fraction of allocations whose slack was active"),
    c("allocation_failures", "–", "f64", "allocations that failed"),
    c("allocation_residual_fraction", "–", "f64", "fraction of control steps leaving the commanded wrench undelivered beyond `[metrics] residual_tolerance`"),
    c("success_margin", "–", "f64", "signed, normalised distance to the `[success]` and `[mission]` bounds: the smallest (bound − value)/bound over the criteria; > 0 met with that room, < 0 missed by that fraction (missed by 1 cm of 0.1 m: −0.1), −1 failed numerically or never converged; a run ended on a certain miss (`stopped_at`) over its metrics up to then"),
    c("total_energy", "J", "f64", "thruster_energy + joint_energy / η_j: thruster shaft energy plus the joint drives' electrical energy (`[metrics] joint_efficiency` η_j, default 0.7)"),
    c("wrench_peak_<axis>", "N or N·m", "f64", "largest |τ_c| the base controller commanded along surge, sway, heave (N), roll, pitch, yaw (N·m) at a control tick, base frame: the required wrench of `authority_margin`"),
    c("authority_margin", "–", "f64", "smallest ratio, over the commanded axes the run asked something of, of the wrench the thrusters can deliver within their limits about the base origin (least over 15 configurations of the nominal run's log) to the peak commanded wrench `wrench_peak_<axis>`; ≥ 1: every peak demand was deliverable (static analysis and a closed loop)"),
    c("reach", "m", "f64", "distance from the base frame's origin to the end effector at q = 0 (a `[mission] reach` requirement is judged on it)"),
    c("success", "0/1", "bool", "1 when the run met every `[success]` criterion (then `status` is `ok`)"),
];

const RUN_TRANSPORT: &[ColumnDoc] = &[
    c("seg{k}_convergence_time", "s", "f64", "time after segment k became active until |e_y| entered `metrics.band` and stayed (NaN: not within the run)"),
    c("seg{k}_overshoot", "m", "f64", "largest cross-track excursion past the path on segment k after the first crossing"),
    c("seg{k}_cross_track_rms", "m", "f64", "RMS cross-track error on segment k after convergence"),
    c("segments_reached", "–", "f64", "segments that became active"),
    c("converged", "0/1", "bool", "every reached segment converged"),
    c("convergence_time", "s", "f64", "convergence time of segment 0"),
    c("overshoot", "m", "f64", "largest overshoot over the segments"),
    c("cross_track_rms", "m", "f64", "RMS cross-track error of the head after convergence"),
    c("base_cross_track_rms", "m", "f64", "the same for the base (tail)"),
    c("final_cross_track", "m", "f64", "signed cross-track error at the end (positive to the left); ranked by magnitude"),
    c("path_progress", "m", "f64", "distance the end effector covered along the path"),
    c("energy_per_metre", "J/m", "f64", "thruster_energy / path_progress: the cruise cost that compares designs of different speeds"),
    c("total_energy_per_metre", "J/m", "f64", "total_energy / path_progress: thrusters and joint drives per metre of path"),
    c("mission_cost", "J/m", "f64", "total_energy_per_metre + `[mission] tracking_weight` × cross_track_iae: the default objective of transport studies"),
    c("cross_track_iae", "m·s", "f64", "∫|cross-track error| dt over the whole run: the tracking term of a transport mission (arriving late on the path is not free)"),
    c("max_abs_roll_deg", "deg", "f64", "largest |roll| of the base frame from level over the whole run (ZYX roll, wrapped; 180 = on its back): judged by `[success] max_roll_deg`"),
    c("max_abs_pitch_deg", "deg", "f64", "largest |pitch| of the base frame from level over the whole run: judged by `[success] max_pitch_deg`"),
    c("max_vertical_error", "m", "f64", "largest depth deviation from the path over the whole run, of the base origin or the end effector, from the depth each started at: judged by `[success] max_vertical_error`"),
    c("roll_commanded_fraction", "–", "f64", "fraction of the logged control periods in which the transport autopilot commanded roll (T(q) could: σ_min of all six rows ≥ `[metrics] threshold`); 0 without the autopilot (`control.autopilot = false`): roll then relies on the hydrostatics"),
];

const RUN_WORK: &[ColumnDoc] = &[
    c(
        "final_position_error",
        "m",
        "f64",
        "end-effector position error at the end",
    ),
    c(
        "final_orientation_error_deg",
        "deg",
        "f64",
        "end-effector pointing error at the end, roll excluded",
    ),
    c(
        "settling_time_position",
        "s",
        "f64",
        "time until the position error stays within `metrics.position_tolerance`",
    ),
    c(
        "settling_time_orientation",
        "s",
        "f64",
        "time until the pointing error stays within `metrics.orientation_tolerance_deg`",
    ),
    c("base_drift", "m", "f64", "base displacement over the run"),
    c(
        "ee_damped_fraction",
        "–",
        "f64",
        "fraction of the logged samples in which the singularity-robust damping λ of the end-effector task was active (λ > 0)",
    ),
    c(
        "ee_damping_max",
        "–",
        "f64",
        "largest damping λ of the end-effector task",
    ),
    c("ee_roll_max_deg", "deg", "f64", "largest |deviation| of the end-effector roll from its setpoint over the run (roll is not controlled in work mode)"),
    c(
        "ee_roll_max_settled_deg",
        "deg",
        "f64",
        "the same after the pose has settled (NaN when it never settles)",
    ),
    c(
        "ee_roll_std_deg",
        "deg",
        "f64",
        "standard deviation of the roll deviation after settling",
    ),
];

const WORLDS: &[ColumnDoc] = &[
    c("<m>_mean, <m>_std, <m>_p05, <m>_p95", "as <m>", "f64", "mean, sample standard deviation and 5 %/95 % quantiles of tracked metric <m> over the sampled worlds (the plain <m> is the nominal world)"),
    c("<m>_worst", "as <m>", "f64", "the worst value of <m> over the worlds, by its direction (largest for costs, smallest for σ_min and outcomes, largest |x| for signed metrics)"),
    c("success_probability", "–", "f64", "fraction of the worlds in which the run met every `[success]` criterion"),
    c("worlds_met", "–", "i64", "a study with adaptive_worlds: the worlds the case met (the first `worlds`, more while in contention; 0 when it did not run in worlds); its summaries over worlds are over these"),
    c("success_probability_lower", "–", "f64", "one-sided Wilson lower confidence bound of success_probability at the study's confidence (docs/statistics.md): a case is ranked when it reaches min_success_probability; NaN when the case did not run in worlds"),
    c("p_best", "–", "f64", "fraction of the paired worlds in which the case is best on the objective among the ranked cases (ties share); NaN when not ranked"),
    c("rank_p05, rank_p50, rank_p95", "–", "f64", "5 %, 50 % and 95 % quantiles of the case's rank (1 = best) over the worlds among the ranked cases"),
    c("validate.<v>.<objective>", "as the objective", "f64", "the objective in held-out variant <v> at the tuned values"),
    c("validate.<v>.success", "0/1", "bool", "the run in variant <v> met every `[success]` criterion"),
    c("validate.<v>.gap", "–", "f64", "relative change of the objective from the nominal run in variant <v>: the generalisation gap"),
];

const FAULTS: &[ColumnDoc] = &[
    c("fault_time", "s", "f64", "a run with a scenario `[fault]`: the simulation time the fault struck (NaN if the run ended before `fault.at`)"),
    c("fault_tolerance", "–", "f64", "fraction of the design's thrusters whose single fault (`[faults]`, re-run at the case's values in the nominal world) still leaves the run successful"),
    c("worst_fault", "index", "i64", "number (from 1: thruster `T1` is 1) of the thruster whose fault hurts most: an unsuccessful faulted run first, then the largest worsening of the objective (NaN objective worst), then the lowest number; an identifier, not ranked"),
    c("fault.t<j>.success", "0/1", "bool", "the run with thruster `T<j>` (j from 1) failed met every `[success]` criterion (NaN: the design has no thruster `T<j>`)"),
    c("fault.t<j>.objective", "as the objective", "f64", "the study's objective (`study.objective`, else the worlds' objective, else `energy_per_metre`) with thruster <j> failed"),
    c("fault.t<j>.change", "–", "f64", "relative change of the objective from the nominal run with thruster <j> failed, `(x − x₀)/|x₀|`"),
    c("fault.t<j>.missed", "–", "f64", "an identifier, not ranked: the first `[success]` criterion the run with thruster <j> failed missed, as its index (from 0) in the criterion list (`no_failure` for a failed run; NaN when it met all)"),
];

const WORLDS_CSV: &[ColumnDoc] = &[
    c(
        "world",
        "–",
        "i64",
        "world index, the same worlds for every case (common random numbers)",
    ),
    c("case_id", "–", "i64", "the case"),
    c(
        "<param>",
        "as the key",
        "f64",
        "each `[[uncertainty.param]]`'s value in the world (a choice of text by its index)",
    ),
    c("<m>", "as <m>", "f64", "each tracked metric in the world"),
    c(
        "success",
        "0/1",
        "f64",
        "the run in the world met every `[success]` criterion",
    ),
    c(
        "missed",
        "–",
        "str",
        "the first `[success]` criterion it missed (empty when none)",
    ),
];

const TUNING_CSV: &[ColumnDoc] = &[
    c("case_id", "–", "i64", "the case"),
    c("evaluation", "–", "i64", "fresh tuning run, from 1, across the starts"),
    c("best", "–", "f64", "best feasible tuning objective so far, relative to the start point's scale (NaN before the first feasible point)"),
];

/// The `timeseries.csv` family a concrete channel name belongs to (`q_3` → `q_<i>`,
/// `base_yaw` → `base_<pose>`, `ee_w` → `ee_<twist>`), if any.
fn channel_family(name: &str) -> Option<String> {
    const POSE: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];
    const TWIST: [&str; 6] = ["u", "v", "w", "p", "q", "r"];
    let (head, tail) = name.rsplit_once('_')?;
    if !tail.is_empty() && tail.bytes().all(|b| b.is_ascii_digit()) {
        return Some(format!("{head}_<i>"));
    }
    let (prefix, rest) = name.split_once('_')?;
    if !["base", "ee", "sp", "ref"].contains(&prefix) {
        return None;
    }
    if POSE.contains(&rest) {
        Some(format!("{prefix}_<pose>"))
    } else if TWIST.contains(&rest) {
        Some(format!("{prefix}_<twist>"))
    } else {
        None
    }
}

/// `seg3_overshoot` → `seg{k}_overshoot`.
fn seg_family(n: &str) -> Option<String> {
    n.strip_prefix("seg")
        .and_then(|r| r.split_once('_'))
        .is_some_and(|(k, rest)| k.parse::<usize>().is_ok() && !rest.is_empty())
        .then(|| format!("seg{{k}}_{}", n.split_once('_').map_or("", |x| x.1)))
}

/// A base axis in the name stands for the `<axis>` family (`wrench_peak_yaw`).
fn axis_family(n: &str) -> Option<String> {
    crate::metrics::singularity::AXIS_NAMES
        .iter()
        .find(|a| n.split('_').any(|w| w == **a))
        .map(|a| {
            n.split('_')
                .map(|w| if w == *a { "<axis>" } else { w })
                .collect::<Vec<_>>()
                .join("_")
        })
}

/// The dictionary entry describing `name` (a concrete column name, not an axis), if any:
/// its own row, or the row of its family (`seg{k}_…`, `q_<i>`, `fault.t<j>.…`, `<m>_mean`, …).
pub fn describe(name: &str) -> Option<&'static ColumnDoc> {
    const AXES: [&str; 6] = crate::metrics::singularity::AXIS_NAMES;
    let docs = || DICTIONARY.iter().flat_map(|(_, cols)| cols.iter());
    let named = |n: &str| docs().find(|c| c.name == n || c.name.split(", ").any(|a| a == n));
    let starting = |p: &str| docs().find(|c| c.name.starts_with(p));
    if let Some(d) = named(name) {
        return Some(d);
    }
    for family in [seg_family(name), axis_family(name), channel_family(name)]
        .into_iter()
        .flatten()
    {
        if let Some(d) = named(&family) {
            return Some(d);
        }
    }
    if name.starts_with("tcm_lost_") {
        return starting("tcm_lost_");
    }
    if name
        .strip_prefix("n1_loss_t")
        .is_some_and(|i| i.parse::<usize>().is_ok())
    {
        return named("n1_loss_t{i}");
    }
    if name.strip_prefix("authority_").is_some_and(|r| {
        AXES.iter()
            .any(|a| r == format!("{a}_pos") || r == format!("{a}_neg"))
    }) {
        return starting("authority_surge_pos");
    }
    if let Some(rest) = name.strip_prefix("fault.t") {
        let what = rest.split_once('.').map_or("", |x| x.1);
        return named(&format!("fault.t<j>.{what}")).or_else(|| starting("fault.t<j>"));
    }
    if name.starts_with("tuned.") {
        return named("tuned.<param>");
    }
    if let Some(rest) = name.strip_prefix("validate.") {
        let what = rest.rsplit_once('.').map_or("", |x| x.1);
        return named(&format!("validate.<v>.{what}"))
            .or_else(|| named("validate.<v>.<objective>"));
    }
    if name.strip_suffix("_worst").is_some_and(is_described) {
        return named("<m>_worst");
    }
    ["_mean", "_std", "_p05", "_p95"]
        .iter()
        .any(|s| name.strip_suffix(s).is_some_and(is_described))
        .then(|| named("<m>_mean"))
        .flatten()
}

/// Whether `name` (a concrete column name) is described by the dictionary.
pub fn is_described(name: &str) -> bool {
    describe(name).is_some()
}

/// The key of the Parquet file-level metadata holding the data dictionary of a table's
/// columns ([`parquet_metadata`]).
pub const PARQUET_COLUMNS_KEY: &str = "usm_study:columns";

/// The Parquet file-level metadata of `table` (a study's case table with the axis columns
/// `axes`): under [`PARQUET_COLUMNS_KEY`], a JSON array with, for each column in order, its
/// `name`, `unit`, `type` (as stored) and `meaning` from the dictionary (`null` unit and
/// meaning for a column it does not describe).
pub fn parquet_metadata(table: &crate::report::Table, axes: &[&str]) -> Vec<(String, String)> {
    let cols: Vec<serde_json::Value> = table
        .columns
        .iter()
        .map(|c| {
            let doc = if axes.contains(&c.name.as_str()) {
                named_doc("<axis name>")
            } else {
                describe(&c.name)
            };
            serde_json::json!({
                "name": c.name,
                "unit": doc.map(|d| d.unit),
                "type": c.data.kind().to_string(),
                "meaning": doc.map(|d| d.meaning),
            })
        })
        .collect();
    vec![(
        PARQUET_COLUMNS_KEY.to_string(),
        serde_json::Value::Array(cols).to_string(),
    )]
}

/// The entry named exactly `name`.
fn named_doc(name: &str) -> Option<&'static ColumnDoc> {
    DICTIONARY
        .iter()
        .flat_map(|(_, cols)| cols.iter())
        .find(|c| c.name == name)
}

/// Whether `column` is a flag the dictionary stores as a boolean (`kind` `bool`: `success`,
/// `completed`, `fault.t<j>.success`, …) — written as `true`/`false` when every case has a 0/1
/// value ([`integers_for_files`]; a NaN keeps the column f64).
pub fn is_bool_column(column: &str) -> bool {
    describe(column).is_some_and(|d| d.kind == "bool")
}

/// Whether `column` holds whole numbers (counts, numbers of things, bitmasks): the dictionary
/// types it `i64`. The case tables are computed in `f64` (NaN where a case has no value); their
/// files store such a column as integers when every value is one ([`integers_for_files`]).
pub fn is_integer_column(column: &str) -> bool {
    describe(column).is_some_and(|d| d.kind == "i64")
        && !matches!(
            column,
            "case_id" | "world" | "evaluation" | "run" | "iteration"
        )
}

/// Store the integer columns of a case table (see [`is_integer_column`]) as `i64` when every
/// value is a whole number, and its flags ([`is_bool_column`]) as `bool` when every value is 0
/// or 1 (`to_files`), or both back as `f64` after reading a file (`!to_files`),
/// so that the report computes on `f64` and the files say "3", not "3.0". A column holding a
/// NaN (a case that did not build or run) stays `f64`. Exact both ways for |x| < 2⁵³.
pub fn integers_for_files(table: &mut crate::report::Table, to_files: bool) {
    use crate::report::ColumnData;
    for c in &mut table.columns {
        if is_bool_column(&c.name) {
            let data = match &c.data {
                ColumnData::F64(v) if to_files && v.iter().all(|x| *x == 0.0 || *x == 1.0) => {
                    ColumnData::Bool(v.iter().map(|x| *x == 1.0).collect())
                }
                ColumnData::Bool(v) if !to_files => {
                    ColumnData::F64(v.iter().map(|&x| f64::from(u8::from(x))).collect())
                }
                _ => continue,
            };
            c.data = data;
            continue;
        }
        if !is_integer_column(&c.name) {
            continue;
        }
        let data = match &c.data {
            ColumnData::F64(v)
                if to_files && v.iter().all(|x| x.fract() == 0.0 && x.abs() < 9.0e15) =>
            {
                ColumnData::I64(v.iter().map(|x| *x as i64).collect())
            }
            ColumnData::I64(v) if !to_files => {
                ColumnData::F64(v.iter().map(|x| *x as f64).collect())
            }
            _ => continue,
        };
        c.data = data;
    }
}

/// The unit of concrete column `name` as the dictionary gives it (`mission_cost` → `J/m`,
/// `q_3` → `rad`, `base_yaw` → `rad`, `wrench_peak_sway` → `N`, `thruster_energy_mean` →
/// `J`; `–` for dimensionless), for axis titles. `None` when the dictionary does not fix one
/// (axis names and `tuned.<param>`, whose unit is the key's).
pub fn unit_of(name: &str) -> Option<&'static str> {
    const AXES: [&str; 6] = crate::metrics::singularity::AXIS_NAMES;
    for suffix in ["_mean", "_std", "_p05", "_p95", "_worst"] {
        if let Some(u) = name.strip_suffix(suffix).and_then(unit_of) {
            return Some(u);
        }
    }
    // Families whose unit depends on the member: poses, twists, base axes.
    let last = name.rsplit('_').next().unwrap_or(name);
    let prefix = name.split('_').next().unwrap_or(name);
    if ["base", "ee", "sp", "ref"].contains(&prefix) && name.matches('_').count() == 1 {
        let unit = match last {
            "x" | "y" | "z" => Some("m"),
            "roll" | "pitch" | "yaw" => Some("rad"),
            "u" | "v" | "w" => Some("m/s"),
            "p" | "q" | "r" => Some("rad/s"),
            _ => None,
        };
        if unit.is_some() {
            return unit;
        }
    }
    let axis = AXES
        .iter()
        .position(|a| name.split('_').any(|w| w == *a) && !name.starts_with("tcm_lost_"));
    if let Some(k) =
        axis.filter(|_| name.starts_with("wrench_peak_") || name.starts_with("authority_"))
    {
        return Some(if k < 3 { "N" } else { "N·m" });
    }
    let seg = name
        .strip_prefix("seg")
        .and_then(|r| r.split_once('_'))
        .filter(|(k, _)| k.parse::<usize>().is_ok())
        .map(|(_, rest)| format!("seg{{k}}_{rest}"));
    let family = channel_family(name);
    DICTIONARY
        .iter()
        .flat_map(|(_, cols)| cols.iter())
        .find(|c| {
            c.name == name || seg.as_deref() == Some(c.name) || family.as_deref() == Some(c.name)
        })
        .map(|c| c.unit)
        .or_else(|| {
            let lost = name.starts_with("tcm_lost_")
                || name
                    .strip_prefix("n1_loss_t")
                    .is_some_and(|i| i.parse::<usize>().is_ok());
            lost.then_some("–")
        })
        .filter(|u| !u.starts_with("as "))
}

/// `docs/columns.md`'s tables.
pub fn columns_markdown() -> String {
    let mut out = String::new();
    for (title, cols) in DICTIONARY {
        out.push_str(&format!(
            "### {title}\n\n| column | unit | type | meaning |\n|---|---|---|---|\n"
        ));
        for c in *cols {
            out.push_str(&format!(
                "| `{}` | {} | {} | {} |\n",
                c.name, c.unit, c.kind, c.meaning
            ));
        }
        out.push('\n');
    }
    out
}

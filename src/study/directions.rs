//! Which way is better for a metric: larger (conditioning, run outcomes, their summaries over
//! worlds), by magnitude (signed metrics), else smaller; and the names the report and the
//! worlds share (`success`, `energy_per_metre`).

use crate::evaluate::metrics::TCM_STRAIGHT_SIGMA_MIN;

/// Signed metrics whose best value is the one nearest zero: ranked, and put on a Pareto
/// front, by |x| (the final cross-track error of transport, positive to the left).
pub const BY_MAGNITUDE: [&str; 1] = ["final_cross_track"];

/// Default objective of a transport study when present: thruster energy per metre of path
/// covered, which compares designs of different speeds.
pub const ENERGY_PER_METRE: &str = "energy_per_metre";

/// Default objective of a transport study: the mission's score, thruster and joint energy per
/// metre plus the price of being off the path (`mission_cost`, docs/model.md §6 "Missions").
pub const TRANSPORT_OBJECTIVE: &str = "mission_cost";

/// The 0/1 success metric of a closed-loop run (1 on every ranked case).
pub const SUCCESS: &str = "success";

/// Whether larger is better for `metric` by default: conditioning (σ_min), attainable authority
/// (`authority_…`, the N−1 forces and moments) and run outcomes
/// (completion, success, convergence, progress, reach, success margin, fault tolerance) and
/// their summaries over worlds
/// (`…_mean`, `…_p05`, …), `success_probability` and `p_best`. Study files add their own with
/// `study.maximise`.
pub fn larger_is_better(metric: &str) -> bool {
    let m = metric;
    m.starts_with("tcm_sigma_min")
        || m.starts_with(TCM_STRAIGHT_SIGMA_MIN)
        || m.starts_with("authority_")
        || [
            "n1_worst_force",
            "n1_worst_moment",
            "n1_mean_force",
            "n1_mean_moment",
        ]
        .contains(&m)
        || m.starts_with("sigma_min")
        || [
            "completed",
            SUCCESS,
            "converged",
            "segments_reached",
            "simulated_time",
            "path_progress",
            "reach",
            "success_margin",
            "fault_tolerance",
        ]
        .iter()
        .any(|b| {
            m == *b
                || m.strip_prefix(b)
                    .is_some_and(|r| r != "_std" && WORLD_SUFFIXES.contains(&r))
        })
        || m == "success_probability"
        || m == "p_best"
}

/// Columns that hold a number but are identifiers or flags, not quantities to rank: a
/// thruster's number (`worst_fault`, `n1_worst_thruster`), the under-actuation flag and axes
/// bitmask, a criterion's index (`fault.t<j>.missed`), the time a failed run was stopped at
/// (`stopped_at`). The report neither ranks them nor
/// lists them among the best cases by metric (docs/columns.md marks them).
pub fn is_identifier(column: &str) -> bool {
    matches!(
        column,
        "worst_fault"
            | "n1_worst_thruster"
            | "under_actuated"
            | "under_actuated_axes"
            | "stopped_at"
    ) || (column.starts_with("fault.t") && column.ends_with(".missed"))
}

/// Suffixes of a metric's summary over worlds (`energy_per_metre_mean`, …).
pub const WORLD_SUFFIXES: [&str; 5] = ["_mean", "_std", "_p05", "_p95", "_worst"];

#[cfg(test)]
mod tests {
    use super::{is_identifier, larger_is_better};

    #[test]
    fn thruster_numbers_and_flags_are_identifiers_not_metrics() {
        for c in [
            "worst_fault",
            "n1_worst_thruster",
            "under_actuated",
            "under_actuated_axes",
            "fault.t3.missed",
        ] {
            assert!(is_identifier(c), "{c}");
        }
        for c in [
            "fault_tolerance",
            "n1_worst_loss",
            "fault.t3.change",
            "n1_loss_t1",
        ] {
            assert!(!is_identifier(c), "{c}");
        }
    }

    #[test]
    fn outcomes_a_design_review_wants_high_rank_larger_first() {
        for m in [
            "fault_tolerance",
            "reach",
            "success_margin",
            "authority_margin",
            "success_probability",
        ] {
            assert!(larger_is_better(m), "{m}");
        }
        for m in [
            "mission_cost",
            "fault_tolerance_typo",
            "saturation_fraction",
        ] {
            assert!(!larger_is_better(m), "{m}");
        }
    }
}

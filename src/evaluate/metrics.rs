//! [`Metrics`]: a case's named metrics, from the evaluator to the CSV/Parquet boundary, and
//! the names of the design and static columns every case may carry. Columns are always found
//! by name; a metric a case did not compute reads as NaN.

use crate::model::Vehicle;
use crate::statics::{AuthoritySummary, Distribution, StaticSummary};

/// Number of thrusters of the built design.
pub const DESIGN_THRUSTERS: &str = "design_thrusters";
/// Fraction of joint configurations with σ_min below the threshold ("how often T is
/// singular").
pub const TCM_SINGULAR_FRACTION: &str = "tcm_singular_fraction";
/// σ_min of the straight configuration `q = 0`.
pub const TCM_STRAIGHT_SIGMA_MIN: &str = "tcm_straight_sigma_min";

/// Columns describing the built design (always present).
pub const DESIGN_COLUMNS: [&str; 5] = [
    "design_bodies",
    "design_joints",
    DESIGN_THRUSTERS,
    "design_length_m",
    "design_mass_kg",
];

/// Static TCM metric columns (present when the static analysis runs): the full 6-DOF figures,
/// then (`…_commanded`) those of the rows the mode's controller commands.
pub const TCM_COLUMNS: [&str; 21] = [
    TCM_SINGULAR_FRACTION,
    "tcm_rank_deficient_fraction",
    "tcm_sigma_min_min",
    "tcm_sigma_min_p05",
    "tcm_sigma_min_p50",
    "tcm_sigma_min_mean",
    "tcm_kappa_p50",
    "tcm_kappa_p95",
    TCM_STRAIGHT_SIGMA_MIN,
    "tcm_lost_surge",
    "tcm_lost_sway",
    "tcm_lost_heave",
    "tcm_lost_roll",
    "tcm_lost_pitch",
    "tcm_lost_yaw",
    "tcm_singular_fraction_commanded",
    "tcm_sigma_min_commanded_min",
    "tcm_sigma_min_commanded_p05",
    "tcm_sigma_min_commanded_p50",
    "tcm_kappa_commanded_p50",
    "tcm_straight_sigma_min_commanded",
];

/// How many thrusters get an `n1_loss_t{i}` column (the main study's designs have at most 16;
/// the N−1 figures of the others are in `summary.json` / `inspect`).
pub const N1_LOSS_COLUMNS: usize = 16;

/// Attainable-authority columns (present when the static analysis runs, docs/model.md §6):
/// per axis and sign the smallest authority over the sampled configurations (N, N·m; NaN when
/// uncommanded), the smallest force and moment (all samples, the straight configuration, the
/// mission range), the under-actuation flag and axes bitmask, N−1 figures and the per-thruster
/// N−1 loss (`n1_loss_t1` … `n1_loss_t16`, numbered like the thrusters `T1` …).
pub const AUTHORITY_COLUMNS: [&str; 42] = [
    "authority_surge_pos",
    "authority_surge_neg",
    "authority_sway_pos",
    "authority_sway_neg",
    "authority_heave_pos",
    "authority_heave_neg",
    "authority_roll_pos",
    "authority_roll_neg",
    "authority_pitch_pos",
    "authority_pitch_neg",
    "authority_yaw_pos",
    "authority_yaw_neg",
    "authority_min_force",
    "authority_min_moment",
    "authority_straight_min_force",
    "authority_straight_min_moment",
    "authority_mission_min_force",
    "authority_mission_min_moment",
    "under_actuated",
    "under_actuated_axes",
    "n1_worst_force",
    "n1_worst_moment",
    "n1_mean_force",
    "n1_mean_moment",
    "n1_worst_thruster",
    "n1_worst_loss",
    "n1_loss_t1",
    "n1_loss_t2",
    "n1_loss_t3",
    "n1_loss_t4",
    "n1_loss_t5",
    "n1_loss_t6",
    "n1_loss_t7",
    "n1_loss_t8",
    "n1_loss_t9",
    "n1_loss_t10",
    "n1_loss_t11",
    "n1_loss_t12",
    "n1_loss_t13",
    "n1_loss_t14",
    "n1_loss_t15",
    "n1_loss_t16",
];

/// Named metrics in the order they were computed. A name is expected once; [`Metrics::set`]
/// replaces, [`Metrics::push`] appends (and [`Metrics::get`] finds the first).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metrics {
    entries: Vec<(String, f64)>,
}

impl Metrics {
    /// No metrics.
    pub fn new() -> Self {
        Self::default()
    }

    /// Append `name = x`.
    pub fn push(&mut self, name: impl Into<String>, x: f64) {
        self.entries.push((name.into(), x));
    }

    /// Set `name` to `x` (replacing its value, or appending it).
    pub fn set(&mut self, name: &str, x: f64) {
        match self.entries.iter_mut().find(|(n, _)| n == name) {
            Some(e) => e.1 = x,
            None => self.push(name, x),
        }
    }

    /// Append `names[i] = values[i]` for each pair.
    pub fn push_all(&mut self, names: &[&str], values: &[f64]) {
        for (n, x) in names.iter().zip(values) {
            self.push(*n, *x);
        }
    }

    /// The value of `name`, if computed.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.entries.iter().find(|(n, _)| n == name).map(|e| e.1)
    }

    /// The value of `name`; NaN when not computed.
    pub fn value(&self, name: &str) -> f64 {
        self.get(name).unwrap_or(f64::NAN)
    }

    /// The values of `names` (NaN where not computed).
    pub fn pick(&self, names: &[String]) -> Vec<f64> {
        names.iter().map(|n| self.value(n)).collect()
    }

    /// `(name, value)` in order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> + '_ {
        self.entries.iter().map(|(n, x)| (n.as_str(), *x))
    }

    /// Number of metrics.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

impl FromIterator<(String, f64)> for Metrics {
    fn from_iter<I: IntoIterator<Item = (String, f64)>>(it: I) -> Self {
        Metrics {
            entries: it.into_iter().collect(),
        }
    }
}

impl Extend<(String, f64)> for Metrics {
    fn extend<I: IntoIterator<Item = (String, f64)>>(&mut self, it: I) {
        self.entries.extend(it);
    }
}

/// The [`DESIGN_COLUMNS`] of a vehicle.
pub fn design_metrics(v: &Vehicle) -> [f64; DESIGN_COLUMNS.len()] {
    [
        v.bodies.len() as f64,
        v.n_joints() as f64,
        v.n_thrusters() as f64,
        v.total_length(),
        v.total_mass(),
    ]
}

/// The [`TCM_COLUMNS`] of a static summary.
pub fn tcm_metrics(s: &StaticSummary) -> [f64; TCM_COLUMNS.len()] {
    let q = |d: &Distribution, p: f64| d.quantile(p).unwrap_or(f64::NAN);
    let lost = |k: usize| s.lost_axes[k].fraction;
    [
        s.singular_fraction,
        s.rank_deficient_fraction,
        s.sigma_min.min,
        q(&s.sigma_min, 0.05),
        q(&s.sigma_min, 0.5),
        s.sigma_min.mean,
        q(&s.kappa, 0.5),
        q(&s.kappa, 0.95),
        s.straight.metrics.sigma_min,
        lost(0),
        lost(1),
        lost(2),
        lost(3),
        lost(4),
        lost(5),
        s.singular_fraction_commanded,
        s.sigma_min_commanded.min,
        q(&s.sigma_min_commanded, 0.05),
        q(&s.sigma_min_commanded, 0.5),
        q(&s.kappa_commanded, 0.5),
        s.straight.metrics.sigma_min_commanded,
    ]
}

/// The [`AUTHORITY_COLUMNS`] of an authority summary.
pub fn authority_metrics(s: &AuthoritySummary) -> [f64; AUTHORITY_COLUMNS.len()] {
    let mut out = [f64::NAN; AUTHORITY_COLUMNS.len()];
    for k in 0..6 {
        out[2 * k] = s.full.min.positive[k];
        out[2 * k + 1] = s.full.min.negative[k];
    }
    let mission =
        |f: fn(&crate::statics::AuthorityStats) -> f64| s.mission.as_ref().map_or(f64::NAN, f);
    let worst_loss =
        s.n1.thrusters
            .get(s.n1.worst_thruster)
            .map_or(f64::NAN, |t| t.loss);
    let rest = [
        s.full.min_force,
        s.full.min_moment,
        s.straight_min_force,
        s.straight_min_moment,
        mission(|m| m.min_force),
        mission(|m| m.min_moment),
        f64::from(u8::from(s.under_actuated)),
        f64::from(s.under_actuated_mask),
        s.n1.worst_force,
        s.n1.worst_moment,
        s.n1.mean_force,
        s.n1.mean_moment,
        // Numbered from 1, like the thrusters (`T1`) and the `n1_loss_t<i>` columns.
        (s.n1.worst_thruster + 1) as f64,
        worst_loss,
    ];
    out[12..12 + rest.len()].copy_from_slice(&rest);
    for (o, t) in out[12 + rest.len()..].iter_mut().zip(&s.n1.thrusters) {
        *o = t.loss;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_are_found_by_name_in_order() {
        let mut m = Metrics::new();
        m.push_all(&["a", "b"], &[1.0, 2.0]);
        m.push("c", 3.0);
        m.set("a", 4.0);
        m.set("d", 5.0);
        assert_eq!(m.get("a"), Some(4.0));
        assert!(m.value("missing").is_nan());
        let names: Vec<&str> = m.iter().map(|e| e.0).collect();
        assert_eq!(names, ["a", "b", "c", "d"]);
        let p = m.pick(&["d".into(), "x".into(), "b".into()]);
        assert_eq!(p[0], 5.0);
        assert!(p[1].is_nan());
        assert_eq!(p[2], 2.0);
        assert_eq!(m.len(), 4);
    }
}

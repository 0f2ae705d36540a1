//! Scoring an evaluation, feasibility first.
//!
//! - Objective of one scenario: `J_v = Σ_i w_i · m_{v,i} / s_i`, with `s_i` the |value| of
//!   metric `i` at the start point (mean over the scenarios; 1 when zero or not finite, or
//!   when normalisation is off). Over the scenarios: the mean of `J_v` or the worst (largest).
//! - Violation: every constraint must hold in every scenario. A constraint's violation in
//!   one scenario is `max(0, m − value)` for `<=`, `max(0, value − m)` for `>=`,
//!   `max(0, |m − value| − tolerance)` for `==`, divided by `max(1, |value|)`; a NaN metric
//!   violates by [`NAN_VIOLATION`]. The total violation is the sum over constraints and
//!   scenarios; a point is feasible when it is zero.
//! - Ranking ([`Score::better_than`]): a feasible point beats every infeasible one; feasible
//!   points rank by objective; infeasible points by total violation. A feasible point whose
//!   objective is NaN counts as infeasible with [`NAN_VIOLATION`].
//! - The scalar the solvers minimise ([`Score::cost`]) keeps that order: the objective for a
//!   feasible point (capped below [`INFEASIBLE_COST`]), `INFEASIBLE_COST + violation`
//!   otherwise.

use super::problem::{Combine, Constraint, Objective, Op};

/// Violation charged for a constraint or objective metric that is NaN.
pub const NAN_VIOLATION: f64 = 1.0e6;

/// The cost of the best infeasible point: every feasible cost is below it.
pub const INFEASIBLE_COST: f64 = 1.0e12;

/// The score of one evaluation.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Score {
    /// Combined objective (NaN when a term is NaN).
    pub objective: f64,
    /// Total normalised constraint violation (0 when feasible).
    pub violation: f64,
    /// Whether every constraint holds in every scenario and the objective is a number.
    pub feasible: bool,
}

impl Score {
    /// Whether `self` ranks strictly before `other` (feasibility first).
    pub fn better_than(&self, other: &Score) -> bool {
        match (self.feasible, other.feasible) {
            (true, false) => true,
            (false, true) => false,
            (true, true) => self.objective < other.objective,
            (false, false) => self.violation < other.violation,
        }
    }

    /// The scalar the solvers minimise, in the order of [`Score::better_than`].
    pub fn cost(&self) -> f64 {
        if self.feasible {
            self.objective.min(0.5 * INFEASIBLE_COST)
        } else {
            INFEASIBLE_COST + self.violation.min(1e300)
        }
    }
}

/// Index of the best of `scores` (the earliest among equals); `None` when empty.
pub fn best_index(scores: impl IntoIterator<Item = Score>) -> Option<usize> {
    let mut best: Option<(usize, Score)> = None;
    for (i, s) in scores.into_iter().enumerate() {
        if best.is_none_or(|(_, b)| s.better_than(&b)) {
            best = Some((i, s));
        }
    }
    best.map(|(i, _)| i)
}

/// The objective and constraints with their normalisation scales.
#[derive(Clone, Debug, PartialEq)]
pub struct Scorer {
    /// The objective.
    pub objective: Objective,
    /// The constraints.
    pub constraints: Vec<Constraint>,
    /// Column of each term's metric in an evaluation's metric vector.
    pub term_columns: Vec<usize>,
    /// Column of each constraint's metric.
    pub constraint_columns: Vec<usize>,
    /// Each term's scale `s_i`.
    pub scales: Vec<f64>,
}

impl Scorer {
    /// A scorer whose metrics are named by `metrics` (the evaluation's columns), scaled by
    /// the start point's metrics `start` (one row per scenario).
    pub fn new(
        objective: &Objective,
        constraints: &[Constraint],
        metrics: &[String],
        start: &[Vec<f64>],
    ) -> Self {
        let col = |m: &str| metrics.iter().position(|n| n == m).unwrap_or(usize::MAX);
        let term_columns: Vec<usize> = objective.terms.iter().map(|t| col(&t.metric)).collect();
        let scales = term_columns
            .iter()
            .map(|&c| {
                let mean = mean_of(start, c).abs();
                if objective.normalise && mean.is_finite() && mean > 0.0 {
                    mean
                } else {
                    1.0
                }
            })
            .collect();
        Scorer {
            objective: objective.clone(),
            constraints: constraints.to_vec(),
            term_columns,
            constraint_columns: constraints.iter().map(|c| col(c.column())).collect(),
            scales,
        }
    }

    /// Objective of one scenario's metrics.
    pub fn scenario_objective(&self, m: &[f64]) -> f64 {
        self.objective
            .terms
            .iter()
            .zip(&self.term_columns)
            .zip(&self.scales)
            .map(|((t, &c), s)| t.weight * m.get(c).copied().unwrap_or(f64::NAN) / s)
            .sum()
    }

    /// Each term's normalised value `w_i · m_i / s_i` over the scenarios (mean), for reports.
    pub fn term_values(&self, per_scenario: &[Vec<f64>]) -> Vec<f64> {
        self.objective
            .terms
            .iter()
            .zip(&self.term_columns)
            .zip(&self.scales)
            .map(|((t, &c), s)| t.weight * mean_of(per_scenario, c) / s)
            .collect()
    }

    /// Violation of constraint `k` by one scenario's metrics (normalised, see module docs).
    pub fn constraint_violation(&self, k: usize, m: &[f64]) -> f64 {
        let c = &self.constraints[k];
        let x = m
            .get(self.constraint_columns[k])
            .copied()
            .unwrap_or(f64::NAN);
        if x.is_nan() {
            return NAN_VIOLATION;
        }
        let v = match c.op {
            Op::Le => (x - c.value).max(0.0),
            Op::Ge => (c.value - x).max(0.0),
            Op::Eq => ((x - c.value).abs() - c.tolerance).max(0.0),
        };
        v / c.value.abs().max(1.0)
    }

    /// The score of an evaluation's metrics (one row per scenario).
    pub fn score(&self, per_scenario: &[Vec<f64>]) -> Score {
        let js = per_scenario.iter().map(|m| self.scenario_objective(m));
        let objective = match self.objective.combine {
            Combine::Mean => js.sum::<f64>() / per_scenario.len().max(1) as f64,
            Combine::Worst => worst_of(js),
            Combine::Cvar(alpha) => cvar(js.collect(), alpha),
        };
        let mut violation = self.hard_violation(per_scenario);
        for (k, c) in self
            .constraints
            .iter()
            .enumerate()
            .filter(|(_, c)| c.chance)
        {
            let col = self.constraint_columns[k];
            let met = per_scenario
                .iter()
                .filter(|m| m.get(col).copied() == Some(1.0))
                .count();
            let p = met as f64 / per_scenario.len().max(1) as f64;
            violation += match c.op {
                Op::Le => (p - c.value).max(0.0),
                Op::Ge => (c.value - p).max(0.0),
                Op::Eq => ((p - c.value).abs() - c.tolerance).max(0.0),
            };
        }
        if objective.is_nan() {
            violation += NAN_VIOLATION;
        }
        Score {
            objective,
            violation,
            feasible: violation == 0.0,
        }
    }
}

impl Scorer {
    /// The violation of the constraints that must hold in every scenario (all but the chance
    /// constraints), summed over `per_scenario`'s rows in order: the first part of
    /// [`Scorer::score`]'s violation, computed by the same sums.
    pub fn hard_violation(&self, per_scenario: &[Vec<f64>]) -> f64 {
        per_scenario
            .iter()
            .map(|m| {
                (0..self.constraints.len())
                    .filter(|&k| !self.constraints[k].chance)
                    .map(|k| self.constraint_violation(k, m))
                    .sum::<f64>()
            })
            .sum()
    }

    /// Racing (`[tune] race`): whether a point whose first scenarios gave `rows` is certainly
    /// infeasible and certainly not ranked before `incumbent` ([`Score::better_than`]) however
    /// its remaining scenarios turn out. The lower bound `L` of its total violation is the
    /// hard violation of `rows`, plus [`NAN_VIOLATION`] when a row's objective is NaN (the
    /// combined objective is then NaN: mean, worst and CVaR alike); the rest of the sum only
    /// adds non-negative terms (more rows, the chance constraints), and rounding is monotone,
    /// so the full violation is `≥ L` bit for bit. The point is out when `L > 0` (infeasible)
    /// and the incumbent is feasible, or `L ≥` the infeasible incumbent's violation (ties go to
    /// the earlier point).
    pub fn cannot_rank_before(&self, rows: &[Vec<f64>], incumbent: &Score) -> bool {
        let mut bound = self.hard_violation(rows);
        if rows.iter().any(|m| self.scenario_objective(m).is_nan()) {
            bound += NAN_VIOLATION;
        }
        bound > 0.0 && (incumbent.feasible || bound >= incumbent.violation)
    }
}

/// The largest value (NaN when any is NaN).
fn worst_of(js: impl Iterator<Item = f64>) -> f64 {
    js.fold(f64::NEG_INFINITY, |a, j| {
        if a.is_nan() || j.is_nan() {
            f64::NAN
        } else {
            a.max(j)
        }
    })
}

/// Conditional value at risk: the mean of the largest `⌈alpha·n⌉` values (NaN when any is
/// NaN).
pub fn cvar(mut js: Vec<f64>, alpha: f64) -> f64 {
    if js.iter().any(|j| j.is_nan()) || js.is_empty() {
        return f64::NAN;
    }
    js.sort_by(|a, b| b.total_cmp(a));
    let k = ((alpha * js.len() as f64).ceil() as usize).clamp(1, js.len());
    js[..k].iter().sum::<f64>() / k as f64
}

/// Mean of column `c` over the rows (NaN when a row lacks it or any value is NaN).
pub fn mean_of(rows: &[Vec<f64>], c: usize) -> f64 {
    let n = rows.len().max(1) as f64;
    rows.iter()
        .map(|r| r.get(c).copied().unwrap_or(f64::NAN))
        .sum::<f64>()
        / n
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn score() -> impl Strategy<Value = Score> {
        (any::<bool>(), -1e3..1e3f64, 0.0..1e3f64).prop_map(|(feasible, objective, v)| Score {
            objective,
            violation: if feasible { 0.0 } else { v + 1e-9 },
            feasible,
        })
    }

    #[test]
    fn cvar_is_the_mean_of_the_worst_fraction() {
        let js = vec![1.0, 5.0, 2.0, 4.0, 3.0];
        assert_eq!(cvar(js.clone(), 1.0), 3.0);
        assert_eq!(cvar(js.clone(), 0.4), 4.5);
        assert_eq!(cvar(js.clone(), 0.01), 5.0);
        assert!(cvar(vec![1.0, f64::NAN], 0.5).is_nan());
    }

    /// A scorer of objective `e` (mean over the scenarios) under `e <= 1` and `c >= 0` in
    /// every scenario and the chance constraint P(success) >= 0.5.
    fn race_scorer() -> Scorer {
        use super::super::problem::Term;
        let con = |metric: &str, op, value, chance| Constraint {
            metric: metric.into(),
            op,
            value,
            tolerance: 0.0,
            chance,
        };
        let objective = Objective {
            terms: vec![Term {
                metric: "e".into(),
                weight: 1.0,
            }],
            combine: Combine::Mean,
            normalise: false,
        };
        let constraints = [
            con("e", Op::Le, 1.0, false),
            con("c", Op::Ge, 0.0, false),
            con("success_probability", Op::Ge, 0.5, true),
        ];
        let names = ["e", "c", "success"].map(String::from);
        Scorer::new(&objective, &constraints, &names, &[vec![1.0, 1.0, 1.0]])
    }

    fn row() -> impl Strategy<Value = Vec<f64>> {
        (
            prop_oneof![4 => 0.0..2.0f64, 1 => Just(f64::NAN)],
            -1.0..1.0f64,
            prop_oneof![Just(0.0), Just(1.0)],
        )
            .prop_map(|(e, c, s)| vec![e, c, s])
    }

    proptest! {
        /// Racing is exact: whenever the first scenarios of a point rule it out against an
        /// incumbent, the point scored on all its scenarios is infeasible and not ranked
        /// before the incumbent, and its partial score (the raced record's) is not either.
        #[test]
        fn a_point_raced_out_could_not_have_ranked_before_the_incumbent(
            rows in proptest::collection::vec(row(), 1..6),
            incumbent in proptest::collection::vec(row(), 1..6),
        ) {
            let s = race_scorer();
            let best = s.score(&incumbent);
            for k in 1..=rows.len() {
                if s.cannot_rank_before(&rows[..k], &best) {
                    let full = s.score(&rows);
                    prop_assert!(!full.feasible);
                    prop_assert!(!full.better_than(&best));
                    prop_assert!(!s.score(&rows[..k]).better_than(&best));
                }
            }
        }

        /// Once a feasible point has been seen, the best so far stays feasible, and the cost
        /// the solvers minimise orders points as the ranking does.
        #[test]
        fn a_feasible_best_is_never_displaced_by_an_infeasible_point(
            scores in proptest::collection::vec(score(), 1..40)
        ) {
            let mut seen_feasible = false;
            for n in 1..=scores.len() {
                let b = best_index(scores[..n].iter().copied()).unwrap();
                seen_feasible |= scores[n - 1].feasible;
                prop_assert_eq!(scores[b].feasible, seen_feasible);
                for s in &scores[..n] {
                    prop_assert!(!s.better_than(&scores[b]));
                }
            }
            for a in &scores {
                for b in &scores {
                    if a.better_than(b) {
                        prop_assert!(a.cost() < b.cost());
                    }
                }
            }
        }
    }
}

//! The optimiser's sections, typed (issue 37 item 1): parameters and their space
//! ([`super::tune_space`]), scenarios, the objective, the constraints and the solver
//! ([`super::tune_solver`]) — of a problem file's top level (`crate::optimise::problem`) or
//! of a sweep's `[tune]` ([`super::schema::TuneSection`]). Read by
//! [`super::tune_spec_parse::parse_spec`]; the format is documented in `docs/optimise.md`.

pub use super::tune_solver::{Method, Polish, SolverSettings, MAX_EVALS, MAX_PARTICLES};
use super::tune_space::Space;

/// The optimiser's top-level sections of a problem file (removed before the study part is
/// parsed).
pub const SPEC_KEYS: [&str; 5] = ["param", "variant", "objective", "constraint", "solver"];

/// How the objectives of several scenarios ([`Variant`]s) are combined.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Combine {
    /// The mean of the scenarios' objectives.
    Mean,
    /// The largest (worst) of the scenarios' objectives.
    Worst,
    /// Conditional value at risk: the mean of the worst `⌈α·n⌉` of the n scenarios'
    /// objectives (`objective.alpha`, 0 < α ≤ 1; α = 1 is the mean, α → 0 the worst).
    Cvar(f64),
}

/// The chance-constraint metric: the fraction of scenarios (worlds) whose run met every
/// `[success]` criterion (`success == 1`), compared once over all scenarios.
pub const SUCCESS_PROBABILITY: &str = "success_probability";

/// One weighted term of the objective: `weight · metric / scale`, the scale being the
/// metric's |value| at the start point (see [`Objective::normalise`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Term {
    /// Metric name (a run-summary, design or static TCM metric).
    pub metric: String,
    /// Weight (negative to maximise the metric).
    pub weight: f64,
}

/// The objective: a weighted sum of named metrics, combined over the scenarios.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Objective {
    /// The terms.
    pub terms: Vec<Term>,
    /// Combination over scenarios.
    pub combine: Combine,
    /// Divide each term by its metric's |value| at the start (mean over the scenarios; 1 when
    /// that is zero or not finite), so that weights are comparable across units.
    pub normalise: bool,
}

/// A comparison of a constraint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Op {
    /// `metric <= value`.
    #[serde(rename = "<=")]
    Le,
    /// `metric >= value`.
    #[serde(rename = ">=")]
    Ge,
    /// `|metric − value| <= tolerance`.
    #[serde(rename = "==")]
    Eq,
}

impl Op {
    /// The operator as written.
    pub fn as_str(self) -> &'static str {
        match self {
            Op::Le => "<=",
            Op::Ge => ">=",
            Op::Eq => "==",
        }
    }
}

/// A constraint `metric op value`, met in every scenario (see [`crate::optimise::score`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Constraint {
    /// Metric name.
    pub metric: String,
    /// Comparison.
    pub op: Op,
    /// Bound.
    pub value: f64,
    /// Slack of `==` (default 1e-9·max(1, |value|)).
    pub tolerance: f64,
    /// A chance constraint ([`SUCCESS_PROBABILITY`]): compared once over the scenarios,
    /// not in each.
    pub chance: bool,
}

impl Constraint {
    /// The metric an evaluation must report for this constraint (`success` for a chance
    /// constraint).
    pub fn column(&self) -> &str {
        if self.chance {
            "success"
        } else {
            &self.metric
        }
    }
}

/// One scenario of a robust objective: key paths set on top of the parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    /// Name (history columns `metric@name`).
    pub name: String,
    /// `(key path, value)` in the order written.
    pub set: Vec<(String, toml::Value)>,
}

/// The optimiser's sections, validated against a study.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// The parameters and their normalised space.
    pub space: Space,
    /// The scenarios (one nameless variant when none is given).
    pub variants: Vec<Variant>,
    /// The objective.
    pub objective: Objective,
    /// The constraints.
    pub constraints: Vec<Constraint>,
    /// The solver.
    pub solver: SolverSettings,
}

impl Spec {
    /// Every metric the objective and the constraints read, each once, in order of first use.
    pub fn metrics(&self) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        let names = self
            .objective
            .terms
            .iter()
            .map(|t| &t.metric)
            .map(String::as_str)
            .chain(self.constraints.iter().map(Constraint::column));
        for n in names {
            if !out.iter().any(|o| o == n) {
                out.push(n.to_string());
            }
        }
        out
    }
}

//! The one case evaluator: a design and a scenario-side table (with optional overrides on
//! top), a seed and a deadline in; one [`CaseResult`] out — named metrics, status, reason
//! (the criterion missed, for an unsuccessful run) and, when asked, the trajectory.
//!
//! Phases: build the vehicle (cached by design), record the design columns, run the static
//! T(q) analysis and the closed-loop scenario as [`Phases`] asks. A panic, an invalid design
//! or a failed run becomes the result's status and reason (the metrics computed until then
//! are kept); it never reaches the caller.

use super::deadline::{Deadline, Phase};
use super::metrics::{
    authority_metrics, design_metrics, tcm_metrics, Metrics, AUTHORITY_COLUMNS, DESIGN_COLUMNS,
    TCM_COLUMNS,
};
use super::overrides::{apply_overrides, OverrideError, Overrides, Side};
use super::static_table::{authority_spec, static_spec, STATIC_TABLE};
use super::status::{CaseEnd, CaseStatus, Disqualification, PANIC, UNDER_ACTUATED};
use crate::model::design::parse_design_table;
use crate::model::Vehicle;
use crate::sampling::derive_seed;
use crate::scenario::channels::Trajectory;
use crate::statics::{analyse, authority_analysis, SinkError, StaticError};

/// Which phases a case runs besides building its design.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Phases {
    /// The static T(q) analysis (the scenario-side `[static]` table).
    pub static_analysis: bool,
    /// The closed-loop scenario (a dynamic mode).
    pub closed_loop: bool,
}

/// What to evaluate.
#[derive(Clone, Copy, Debug)]
pub struct CaseInput<'a> {
    /// The design table.
    pub design: &'a toml::Table,
    /// A hash of the design table (the vehicle cache key).
    pub design_hash: &'a str,
    /// The scenario-side table (with `[static]` when the static analysis runs).
    pub scenario: &'a toml::Table,
    /// Edits on top of both tables, applied in order before anything else
    /// ([`super::overrides`]: the one road for whatever varies a case).
    pub overrides: &'a Overrides,
    /// The case seed (`derive_seed(seed, 1)` seeds the static analysis).
    pub seed: u64,
    /// The case's wall-clock deadline (closed loop and static analysis).
    pub deadline: Deadline,
    /// Which phases run.
    pub phases: Phases,
    /// Keep the closed loop's trajectory.
    pub trajectory: bool,
    /// How the design is named in messages (`case 3 design`).
    pub label: &'a str,
}

/// The result of one case.
#[derive(Clone, Debug)]
pub struct CaseResult {
    /// Named metrics: design columns, static columns, run metrics, in that order.
    pub metrics: Metrics,
    /// How the case ended, with its data ([`CaseEnd::status`] is the `status` column).
    pub end: CaseEnd,
    /// Why it was not `ok`, for people (for `unsuccessful`: `criterion: detail`); empty when
    /// `ok`. Nothing reads meaning back out of it: that is [`CaseResult::end`].
    pub reason: String,
    /// The closed loop's trajectory, typed (when asked for and the run produced one);
    /// [`super::trajectory_table`] makes it a table for the files that hold it.
    pub trajectory: Option<Trajectory>,
}

impl CaseResult {
    fn new() -> Self {
        CaseResult {
            metrics: Metrics::new(),
            end: CaseEnd::Ok,
            reason: String::new(),
            trajectory: None,
        }
    }

    /// End the case with `end` for `reason` (the text for people).
    pub fn finish(&mut self, end: CaseEnd, reason: impl Into<String>) {
        self.end = end;
        self.reason = reason.into();
    }

    /// The `status` column of the case.
    pub fn status(&self) -> CaseStatus {
        self.end.status()
    }

    /// Whether every phase ran and every `[success]` criterion was met.
    pub fn success(&self) -> bool {
        self.end == CaseEnd::Ok
    }

    /// The criterion the case missed (`no_failure` for a failed case), see
    /// [`CaseEnd::criterion`].
    pub fn criterion(&self) -> Option<&'static str> {
        self.end.criterion()
    }

    /// Why the case failed or could not be set up (`None` for `ok` and `unsuccessful`).
    pub fn failure(&self) -> Option<&str> {
        matches!(self.status(), CaseStatus::Failed | CaseStatus::Skipped).then_some(&*self.reason)
    }
}

/// The evaluator: owns the vehicle cache (one entry, so consecutive cases of a design build it
/// once) and the panic guard. One per thread.
#[derive(Default)]
pub struct Evaluator {
    cache: Option<(String, Vehicle)>,
}

impl Evaluator {
    /// An evaluator with an empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Evaluate one case (see the module docs).
    pub fn evaluate(&mut self, input: &CaseInput<'_>) -> CaseResult {
        let mut out = CaseResult::new();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.phases(input, &mut out)
        }));
        if let Err(p) = result {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            out.finish(
                CaseEnd::Panic {
                    message: msg.clone(),
                },
                format!("{PANIC}{msg}"),
            );
            out.trajectory = None;
            self.cache = None;
        }
        out
    }

    fn phases(&mut self, input: &CaseInput<'_>, out: &mut CaseResult) {
        let edited;
        let (design, scenario) = if input.overrides.is_empty() {
            (input.design, input.scenario)
        } else {
            match apply(input) {
                Ok(t) => {
                    edited = t;
                    (&edited.0, &edited.1)
                }
                Err(e) => return out.finish(CaseEnd::NotApplicable, e.to_string()),
            }
        };
        let Some(v) = self.vehicle(input, design, out) else {
            return;
        };
        out.metrics.push_all(&DESIGN_COLUMNS, &design_metrics(v));
        if input.phases.static_analysis && !static_phase(v, scenario, input, out) {
            return;
        }
        if input.phases.closed_loop {
            closed_loop(v, scenario, input, out);
        }
    }

    /// The case's vehicle, built unless cached; `None` (the case skipped) for an invalid design.
    fn vehicle(
        &mut self,
        input: &CaseInput<'_>,
        design: &toml::Table,
        out: &mut CaseResult,
    ) -> Option<&Vehicle> {
        let key = cache_key(input);
        if !matches!(&self.cache, Some((h, _)) if *h == key) {
            match parse_design_table(design, input.label) {
                Ok(v) => self.cache = Some((key, v)),
                Err(e) => {
                    out.finish(CaseEnd::Skipped, format!("invalid design: {e}"));
                    return None;
                }
            }
        }
        self.cache.as_ref().map(|(_, v)| v)
    }
}

/// Whether the design of `design` cannot meet the `[mission] reach` of the scenario-side table
/// `scenario` whatever its gains (docs/model.md §6 "Missions"): its straight reach is shorter.
/// `false` when there is no such requirement or the design does not build (the evaluation
/// reports that). A tuner skips such a case: tuning cannot change a design's reach.
pub fn out_of_reach(design: &toml::Table, scenario: &toml::Table, label: &str) -> bool {
    let required = scenario
        .get("mission")
        .and_then(|m| m.get("reach"))
        .and_then(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
        .unwrap_or(0.0);
    required > 0.0
        && parse_design_table(design, label)
            .is_ok_and(|v| crate::kinematics::straight_reach(&v) < required)
}

/// The cache key: the design hash, and the design overrides when there are any.
fn cache_key(input: &CaseInput<'_>) -> String {
    let mut key = input.design_hash.to_string();
    for o in input.overrides.iter().filter(|o| o.side == Side::Design) {
        key.push_str(&format!(";{}={}", o.shown, o.value));
    }
    key
}

/// The case's tables with its overrides applied ([`apply_overrides`]); `Err` is the reason
/// the case is skipped.
fn apply(input: &CaseInput<'_>) -> Result<(toml::Table, toml::Table), OverrideError> {
    let (mut design, mut scenario) = (input.design.clone(), input.scenario.clone());
    apply_overrides(&mut design, &mut scenario, input.overrides)?;
    Ok((design, scenario))
}

/// The static analysis into the [`TCM_COLUMNS`], then the authority analysis into the
/// [`AUTHORITY_COLUMNS`]; `false` when the case ended (a `timeout` once the deadline passed: it
/// is checked for every sample handed over, so after each chunk, and for every authority
/// configuration).
fn static_phase(
    v: &Vehicle,
    scenario: &toml::Table,
    input: &CaseInput<'_>,
    out: &mut CaseResult,
) -> bool {
    let spec = match static_spec(scenario, derive_seed(input.seed, 1)) {
        Ok(s) => s,
        Err(m) => {
            out.finish(CaseEnd::Skipped, m.to_string());
            return false;
        }
    };
    let auth = match authority_spec(scenario) {
        Ok(s) => s,
        Err(m) => {
            out.finish(CaseEnd::Skipped, m.to_string());
            return false;
        }
    };
    let deadline = input.deadline;
    let mut on_time =
        |_: usize, _: &[f64], _: &_| deadline.check(Phase::Static).map_err(SinkError::from);
    let mut check = || deadline.check(Phase::Static).map_err(SinkError::from);
    let both = analyse(v, &spec, 1, &mut on_time, &|_| {})
        .and_then(|s| Ok((s, authority_analysis(v, &spec, &auth, &mut check)?)));
    match both {
        Ok((s, a)) => {
            out.metrics.push_all(&TCM_COLUMNS, &tcm_metrics(&s));
            out.metrics
                .push_all(&AUTHORITY_COLUMNS, &authority_metrics(&a));
            true
        }
        Err(e) => {
            let (end, reason) = static_failure(e);
            out.finish(end, reason);
            false
        }
    }
}

/// The ending and reason of a failed static phase: a sink's own message (the deadline, its
/// only sink error here: a timeout), else the error.
fn static_failure(e: StaticError) -> (CaseEnd, String) {
    match e {
        StaticError::Sink(m) => (CaseEnd::Timeout, m.to_string()),
        e => (CaseEnd::Error, e.to_string()),
    }
}

/// The closed-loop run: its metrics (kept even when it stopped early), its status and, when
/// asked, its trajectory.
fn closed_loop(v: &Vehicle, scenario: &toml::Table, input: &CaseInput<'_>, out: &mut CaseResult) {
    let mut sc = scenario.clone();
    sc.remove(STATIC_TABLE);
    let stop = input.deadline.stop();
    // The scored evaluation (with the static phase) also measures the run's authority margin,
    // from its logged joint angles; tuning and world runs do not.
    let margin = input.phases.static_analysis;
    let log = input.trajectory || margin;
    let run = match crate::outcome::run_case(v, &sc, input.seed, log, stop) {
        Ok(r) => r,
        Err(e) => return out.finish(CaseEnd::Error, e.to_string()),
    };
    if margin {
        let m = run_authority_margin(v, &sc, &run);
        out.metrics.push(AUTHORITY_MARGIN, m);
    }
    let trajectory = run.trajectory.filter(|_| input.trajectory);
    if let Some(f) = run.failure {
        let end = if f.timeout {
            CaseEnd::Timeout
        } else {
            CaseEnd::Diverged { at: f.at }
        };
        out.finish(end, f.reason);
    } else if let Some((mask, axes)) = under_actuated(out) {
        out.finish(
            CaseEnd::Disqualified(Disqualification::UnderActuated { axes: mask }),
            format!(
                "{UNDER_ACTUATED}: no authority over the commanded {axes} anywhere in the \
                 sampled joint space (static analysis); not ranked whatever its run did"
            ),
        );
    } else if let Some(m) = run.missed {
        out.finish(CaseEnd::missed(m.criterion), m.to_string());
    }
    out.metrics.extend(run.metrics);
    out.trajectory = trajectory;
}

/// The metric of [`run_authority_margin`].
pub const AUTHORITY_MARGIN: &str = "authority_margin";

/// Configurations of a run's log at which its authority margin is measured (evenly spaced).
const MARGIN_CONFIGS: usize = 15;

/// The commanded axes a static analysis found unattainable everywhere: its
/// `under_actuated_axes` bit mask (surge = 1 … yaw = 32) and the axes as words; `None` when
/// it found none or did not run.
fn under_actuated(out: &CaseResult) -> Option<(u32, String)> {
    if out.metrics.get("under_actuated") != Some(1.0) {
        return None;
    }
    let mask = out.metrics.get("under_actuated_axes").unwrap_or(0.0) as u32;
    let names = crate::metrics::singularity::AXIS_NAMES;
    let axes: Vec<&str> = (0..6)
        .filter(|k| mask & (1 << k) != 0)
        .map(|k| names[k])
        .collect();
    Some((
        mask,
        if axes.is_empty() {
            "axes".into()
        } else {
            axes.join(", ")
        },
    ))
}

/// `authority_margin` of a run (docs/model.md §6): the smallest ratio, over the commanded axes
/// the run asked something of, of the wrench the thrusters can deliver about the base frame's
/// origin (the frame of τ_c) within their limits — the least over [`MARGIN_CONFIGS`] joint
/// configurations of its log — to the largest wrench the base controller commanded
/// (`wrench_peak_<axis>`). ≥ 1: the layout could have delivered every peak demand; NaN
/// when nothing was logged or asked.
fn run_authority_margin(v: &Vehicle, scenario: &toml::Table, run: &crate::outcome::CaseRun) -> f64 {
    use crate::scenario::channels::Channel;
    use crate::statics::authority::{authority_over, weakest_ratio, AuthorityReference};
    let (Some(traj), Ok(file)) = (
        run.trajectory.as_ref(),
        crate::scenario::parse_table(scenario, &crate::scenario::Source::unplaced("scenario")),
    ) else {
        return f64::NAN;
    };
    let commanded = file.commanded();
    let names = crate::metrics::singularity::AXIS_NAMES;
    let metric = |n: &str| run.metrics.iter().find(|m| m.0 == n).map_or(0.0, |m| m.1);
    let required: [f64; 6] = std::array::from_fn(|k| metric(&format!("wrench_peak_{}", names[k])));
    let qs: Vec<&[f64]> = (0..v.n_joints())
        .map(|j| traj.get(Channel::Q(j)).unwrap_or(&[]))
        .collect();
    let n = qs.first().map_or(0, |q| q.len());
    if n == 0 {
        return f64::NAN;
    }
    let picks = (0..MARGIN_CONFIGS.min(n)).map(|i| i * (n - 1) / (MARGIN_CONFIGS - 1).max(1));
    let configs: Vec<Vec<f64>> = picks
        .map(|i| {
            qs.iter()
                .map(|q| q.get(i).copied().unwrap_or(0.0))
                .collect()
        })
        .collect();
    match authority_over(v, commanded, &AuthorityReference::Base, configs) {
        Ok(stats) => weakest_ratio(&stats.min, commanded, &required),
        Err(_) => f64::NAN,
    }
}

#[cfg(test)]
#[path = "case_tests.rs"]
mod tests;

//! The validated study: what a study file means once parsed ([`crate::study::parse`] turns
//! the file into a [`Study`]). The format is documented in `docs/study-format.md`.

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use super::runner::{StudyMode, SCENARIO_TABLES};
pub use super::target::Target;
use super::tune_spec::Spec;
use crate::evaluate::static_table::STATIC_TABLE;
use crate::sampling::{derive_seed, Sampler, Sampling};
use crate::stats::normal::inv_cdf;
use crate::stats::sobol::SaltelliDesign;

/// Largest number of cases of a study.
pub const MAX_CASES: usize = 10_000_000;

/// How an axis produces values.
#[derive(Clone, Debug, PartialEq)]
pub enum AxisSpec {
    /// An explicit list (numbers, strings, booleans or arrays).
    Values(Vec<toml::Value>),
    /// `steps` values from `start` to `stop` inclusive (geometric with `log`); continuous in
    /// `[start, stop]` for sampled designs.
    Range {
        /// First value.
        start: f64,
        /// Last value.
        stop: f64,
        /// Number of grid values (grid designs only).
        steps: Option<usize>,
        /// Geometric spacing (start, stop > 0).
        log: bool,
    },
    /// A probability distribution (sampled designs only), by its inverse CDF.
    Distribution(Dist),
}

impl AxisSpec {
    /// Number of grid values (1 for distributions, which grids reject).
    pub fn grid_len(&self) -> usize {
        match self {
            AxisSpec::Values(v) => v.len(),
            AxisSpec::Range { steps, .. } => steps.unwrap_or(1),
            AxisSpec::Distribution(_) => 1,
        }
    }
}

/// A distribution of an axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dist {
    /// Uniform on `[low, high)`.
    Uniform(f64, f64),
    /// Log-uniform on `[low, high)`, 0 < low < high.
    LogUniform(f64, f64),
    /// Normal with mean and standard deviation.
    Normal(f64, f64),
}

/// A validated sweep axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// The name as written (the column name in the results).
    pub name: String,
    /// The resolved target.
    pub target: Target,
    /// The values.
    pub spec: AxisSpec,
    /// Whether the column is numeric (f64) rather than a string.
    pub numeric: bool,
    /// Whether the target key holds an integer (continuous values are rounded).
    pub integer: bool,
    /// Whether the axis is a condition (`condition = true`: a payload, a current, a mission
    /// variant), not a design choice: designs are ranked against each other only under the
    /// same values of every condition axis ([`crate::batch::conditions`]).
    pub condition: bool,
}

/// The kind of design of experiments (`[doe] kind`; written as lower-case text in study files
/// and manifests).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DoeKind {
    /// Cartesian product of the axes' value lists.
    Grid,
    /// Independent uniform draws.
    Random,
    /// Latin hypercube.
    Lhs,
    /// Owen-scrambled Sobol sequence.
    Sobol,
}

impl DoeKind {
    /// Every kind, in the order listed in messages.
    pub const ALL: [DoeKind; 4] = [DoeKind::Grid, DoeKind::Random, DoeKind::Lhs, DoeKind::Sobol];

    /// The name as written in study files and manifests.
    pub fn as_str(self) -> &'static str {
        match self {
            DoeKind::Grid => "grid",
            DoeKind::Random => "random",
            DoeKind::Lhs => "lhs",
            DoeKind::Sobol => "sobol",
        }
    }

    /// The sampler of a sampled design; `None` for the grid.
    pub fn sampling(self) -> Option<Sampling> {
        match self {
            DoeKind::Grid => None,
            DoeKind::Random => Some(Sampling::Random),
            DoeKind::Lhs => Some(Sampling::Lhs),
            DoeKind::Sobol => Some(Sampling::Sobol),
        }
    }
}

impl fmt::Display for DoeKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A `[doe] kind` that is not one of [`DoeKind::ALL`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown kind '{0}'; valid: grid, random, lhs, sobol")]
pub struct UnknownDoeKind(pub String);

impl From<UnknownDoeKind> for String {
    fn from(e: UnknownDoeKind) -> String {
        e.to_string()
    }
}

impl FromStr for DoeKind {
    type Err = UnknownDoeKind;
    fn from_str(s: &str) -> Result<Self, UnknownDoeKind> {
        DoeKind::ALL
            .into_iter()
            .find(|k| k.as_str() == s)
            .ok_or_else(|| UnknownDoeKind(s.to_string()))
    }
}

/// The design of experiments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Doe {
    /// Cartesian product of the axes' value lists (first axis slowest).
    Grid,
    /// `cases` points of a seeded sampler over the axes.
    Sampled {
        /// Sampler.
        kind: Sampling,
        /// Number of cases.
        cases: usize,
    },
}

impl Doe {
    /// The kind of design.
    pub fn kind(&self) -> DoeKind {
        match self {
            Doe::Grid => DoeKind::Grid,
            Doe::Sampled { kind, .. } => match kind {
                Sampling::Random => DoeKind::Random,
                Sampling::Lhs => DoeKind::Lhs,
                Sampling::Sobol => DoeKind::Sobol,
            },
        }
    }
}

/// Settings for summaries and plots.
#[derive(Clone, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ReportSettings {
    /// Metric picking the best and worst case (default: an energy metric, else
    /// `tcm_singular_fraction`).
    pub objective: Option<String>,
    /// The trade-off plotted as a Pareto front `[x, y]` (default: energy vs singular exposure).
    pub pareto: Option<[String; 2]>,
    /// Metrics where larger is better (default: the σ_min metrics).
    pub maximise: Vec<String>,
}

/// A validated study.
#[derive(Clone, Debug)]
pub struct Study {
    /// The study file.
    pub path: PathBuf,
    /// Its text.
    pub text: String,
    /// Name (used in the default output directory).
    pub name: String,
    /// Description.
    pub description: String,
    /// Study seed.
    pub seed: u64,
    /// Output directory.
    pub output: PathBuf,
    /// The base design table (design-file schema).
    pub design: toml::Table,
    /// Whether the base design uses the generator form.
    pub generator: bool,
    /// The scenario-side table as written (`scenario`, `static`, `control`, `allocation`,
    /// `metrics`).
    pub scenario: toml::Table,
    /// The scenario-side table with every default filled in (what cases start from).
    pub scenario_full: toml::Table,
    /// Scenario mode.
    pub mode: StudyMode,
    /// Whether the static TCM analysis runs for every case.
    pub static_enabled: bool,
    /// Axes in file order.
    pub axes: Vec<Axis>,
    /// Design of experiments.
    pub doe: Doe,
    /// Report settings.
    pub report: ReportSettings,
    /// SHA-256 of the study text, the base design and the tool version (hex).
    pub hash: String,
    /// The `[tune]` section as written (per-case tuning, `docs/study-format.md`): part of
    /// every case hash.
    pub tune: Option<toml::Table>,
    /// The `[tune]` section typed and validated at load ([`TuneSection`]); `None` without one.
    pub tuning: Option<TuneSection>,
    /// The `[uncertainty]` section: worlds every case meets (issue 22).
    pub uncertainty: Option<Uncertainty>,
    /// The `[[validate]]` variants, scored at the tuned values.
    pub validate: Vec<Variant>,
    /// `[faults]`: the single thruster fault every case is re-run with, per thruster.
    pub faults: Option<super::fault_spec::FaultStudy>,
    /// `[ocp]`: the optimal-control bound of every case's design on a transport leg (issue 41).
    pub ocp: Option<super::ocp_section::OcpSection>,
    /// `[uncertainty]` and `[[validate]]` as written (part of every case hash: a row
    /// depends on them); empty without them.
    pub robust_table: toml::Table,
}

/// A study's validated `[tune]` section (read at load by [`super::tune_section::parse_tune`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TuneSection {
    /// The optimiser's sections (`[[tune.param]]`, `[tune.objective]`, …), read by
    /// [`super::tune_spec_parse::parse_spec`] under `tune.`.
    pub spec: Spec,
    /// Per parameter: whether `start` is written (otherwise the case's own value).
    pub explicit_start: Vec<bool>,
    /// Independent tuning starts (`[tune] starts`, default 1): the case's own start, then
    /// Sobol points of the box, each with an equal share of the evaluation budget.
    pub starts: usize,
    /// The tuning worlds (`[tune] worlds = N`): the study's `[uncertainty]` with `N` worlds
    /// (Saltelli's design replaced by a plain Sobol sample of the same distributions);
    /// `None` to tune in the nominal world.
    pub worlds: Option<Uncertainty>,
    /// Independent tuning seeds (`[tune] seeds`, default 1), compared in the pooled tuning
    /// worlds of all seeds (issue 36 item 5).
    pub seeds: usize,
    /// Race each candidate's tuning worlds (`[tune] race`, default true).
    pub race: bool,
    /// Screen the candidates with RK4 at the control period (`[tune] screen = "rk4"`,
    /// issue 38 item 3); default false (`"none"`).
    pub screen: bool,
}

/// Column of a study with `[ocp]`: the objective's energy part at the best local optimum found
/// on the leg, `Σ Δt Σ_j c |u_j|^{3/2} + Σ Δt Σ_i |τ_i q̇_i|` [J] (thruster shaft energy at zero
/// inflow plus joint mechanical energy, the closed loop's `thruster_energy_static` +
/// `joint_energy`) over the leg [J]; the best local optimum found, never claimed global.
pub const OCP_ENERGY: &str = "ocp_energy";
/// Column: [`OCP_ENERGY`] per metre of the leg [J/m].
pub const OCP_ENERGY_PER_METRE: &str = "ocp_energy_per_metre";
/// Column: (max − min)/min of the converged starts' objectives (NaN with fewer than two).
pub const OCP_SPREAD: &str = "ocp_energy_spread";
/// Column: the best start's status: 0 converged, 1 max iterations, 2 stalled, 3 infeasible,
/// 4 diverged.
pub const OCP_STATUS: &str = "ocp_status";
/// Column: the best start's largest KKT residual (primal, stationarity, complementarity).
pub const OCP_KKT: &str = "ocp_kkt";
/// Column: the best start's primal residual (defects and terminal rows): ≤ the tolerance
/// means the trajectory is dynamically feasible and meets the leg's end.
pub const OCP_PRIMAL: &str = "ocp_primal";
/// Column: SQP iterations of every start of the design's solve together (the solve's cost in a
/// deterministic unit; wall time is not a table column, so tables stay bit-identical for any
/// thread count — `benches/README.md` gives the time per solve).
pub const OCP_ITERATIONS: &str = "ocp_iterations";
/// Column: the best start's work-balance error on its grid, `|W_other − W_other,refined| /
/// max(|W_act|, |W_act,refined|)` with the controls integrated 10× finer (docs/ocp.md §6): above
/// [`OCP_WORK_TRUSTED`] the optimum swims on energy the grid's integration supplies and is no
/// bound.
pub const OCP_WORK_ERROR: &str = "ocp_work_error";
/// The largest [`OCP_WORK_ERROR`] of a bound that counts (5 %, the `ocp` verb's grid warning).
pub const OCP_WORK_TRUSTED: f64 = 0.05;
/// Column: `ocp_energy_per_metre` / the closed loop's `(thruster_energy_static +
/// joint_energy) / path_progress` (NaN without a feasible bound trusted on its grid,
/// [`OCP_WORK_TRUSTED`]): ≤ 1 when both are right; > 1 flags one of them.
pub const CONTROLLER_EFFICIENCY: &str = "controller_efficiency";
/// Column of a study with `[ocp] worlds`: the least primal-feasible bound per metre over the
/// bound's worlds (the study's first scoring worlds) [J/m]; NaN when none is feasible.
pub const OCP_WORLD_MIN: &str = "ocp_world_energy_per_metre_min";
/// Column: the greatest primal-feasible bound per metre over the bound's worlds [J/m].
pub const OCP_WORLD_MAX: &str = "ocp_world_energy_per_metre_max";
/// Column: how many of the bound's worlds have a primal-feasible bound.
pub const OCP_WORLD_FEASIBLE: &str = "ocp_world_feasible";
/// Column: SQP iterations of every world's solve together.
pub const OCP_WORLD_ITERATIONS: &str = "ocp_world_iterations";
/// Column: how many of the bound's worlds ended primal feasible but were rejected because the
/// grid supplied their energy (work error above [`OCP_WORK_TRUSTED`]).
pub const OCP_WORLD_GRID_REJECTED: &str = "ocp_world_grid_rejected";
/// The columns `[ocp] worlds` adds after [`OCP_COLUMNS`], in order.
pub const OCP_WORLD_COLUMNS: [&str; 5] = [
    OCP_WORLD_MIN,
    OCP_WORLD_MAX,
    OCP_WORLD_FEASIBLE,
    OCP_WORLD_ITERATIONS,
    OCP_WORLD_GRID_REJECTED,
];
/// The columns `[ocp]` adds to every row, in order.
pub const OCP_COLUMNS: [&str; 9] = [
    OCP_ENERGY,
    OCP_ENERGY_PER_METRE,
    OCP_SPREAD,
    OCP_STATUS,
    OCP_KKT,
    OCP_PRIMAL,
    OCP_WORK_ERROR,
    OCP_ITERATIONS,
    CONTROLLER_EFFICIENCY,
];

/// Column of a tuned study's rows: fresh evaluations the case's tuning used.
pub const TUNE_EVALUATIONS: &str = "tune_evaluations";
/// Column of a tuned study's rows: 1 when the tuned point met every `[[tune.constraint]]`.
pub const TUNE_FEASIBLE: &str = "tune_feasible";
/// Column of a tuned study's rows: relative spread of the tuned objective across the
/// independent tuning starts (`[tune] starts`), the tuning noise.
pub const TUNE_NOISE: &str = "tune_noise";
/// Column of a study tuned with `[tune] seeds` ≥ 2: the spread over the seeds of the fraction
/// of pooled tuning worlds in which each seed's best point meets every constraint.
pub const TUNE_SUCCESS_SPREAD: &str = "tune_success_spread";
/// Column of a tuned study's rows: tuned parameters on a bound of their box.
pub const TUNE_BOUND_HITS: &str = "tune_bound_hits";
/// Prefix of a row's best-so-far tuning curve (`tune_curve.<k>`), moved to `tuning.csv`.
pub const TUNE_CURVE_PREFIX: &str = "tune_curve.";
/// Prefix of the tuned-value columns (`tuned.control.k_psi`).
pub const TUNED_PREFIX: &str = "tuned.";

impl Study {
    /// The columns `[ocp]` adds to every row ([`OCP_COLUMNS`], then [`OCP_WORLD_COLUMNS`] with
    /// `[ocp] worlds`; none without `[ocp]`).
    pub fn ocp_columns(&self) -> Vec<String> {
        match &self.ocp {
            Some(s) => OCP_COLUMNS
                .iter()
                .chain(if s.worlds > 0 {
                    &OCP_WORLD_COLUMNS[..]
                } else {
                    &[]
                })
                .map(|c| c.to_string())
                .collect(),
            None => Vec::new(),
        }
    }

    /// The columns per-case tuning adds to every row: `tuned.<param>` for each
    /// `[[tune.param]]` in file order, then [`TUNE_EVALUATIONS`], [`TUNE_FEASIBLE`],
    /// [`TUNE_NOISE`], [`TUNE_SUCCESS_SPREAD`] (only with `[tune] seeds` ≥ 2) and
    /// [`TUNE_BOUND_HITS`] (none without `[tune]`).
    pub fn tune_columns(&self) -> Vec<String> {
        let Some(t) = &self.tune else {
            return Vec::new();
        };
        let params = t.get("param").and_then(|p| p.as_array());
        let mut cols: Vec<String> = params
            .into_iter()
            .flatten()
            .filter_map(|p| p.get("name").and_then(|n| n.as_str()))
            .map(|n| format!("{TUNED_PREFIX}{n}"))
            .collect();
        cols.push(TUNE_EVALUATIONS.into());
        cols.push(TUNE_FEASIBLE.into());
        cols.push(TUNE_NOISE.into());
        if t.get("seeds")
            .and_then(toml::Value::as_integer)
            .unwrap_or(1)
            > 1
        {
            cols.push(TUNE_SUCCESS_SPREAD.into());
        }
        cols.push(TUNE_BOUND_HITS.into());
        cols
    }
}

/// Keys of the design generator table (design-file schema); `design.<key>` is an alias of
/// `design.generator.<key>` when the base design uses the generator.
pub const GENERATOR_KEYS: [&str; 17] = [
    "links",
    "link_length",
    "link_mass",
    "body_profile",
    "radius",
    "module_length",
    "module_mass",
    "joint_limit_deg",
    "thruster_rule",
    "thrust_limit",
    "thrust_per_kg",
    "longitudinal_offset",
    "cd_axial_ends",
    "cd_axial",
    "cd_cross",
    "metacentric_height",
    "wet_weight",
];

/// Whether `key` is a scenario-side top-level table (including `static`).
pub fn is_scenario_table(key: &str) -> bool {
    key == STATIC_TABLE || SCENARIO_TABLES.contains(&key)
}

// ---- uncertain worlds (`[uncertainty]`, `[[validate]]`; parsed by `super::uncertainty`) ----

/// Seed stream of the worlds (shared by every case: common random numbers).
const WORLD_STREAM: u64 = 0x574f_524c_4453; // "WORLDS"

/// Most sampled worlds per case.
pub const MAX_WORLDS: usize = 100_000;

/// A distribution of an uncertain parameter (`distribution = { kind = … }`).
#[derive(Clone, Debug, PartialEq)]
pub enum WorldDist {
    /// Uniform on `[low, high]`.
    Uniform(f64, f64),
    /// Log-uniform on `[low, high]`, 0 < low.
    LogUniform(f64, f64),
    /// Normal with mean and standard deviation.
    Normal(f64, f64),
    /// Log-normal: `exp(N(mu, sigma))` (`mu`, `sigma` of the logarithm).
    LogNormal(f64, f64),
    /// One of the listed values, equally likely.
    Choice(Vec<toml::Value>),
}

impl WorldDist {
    /// The value at probability `u` ∈ (0, 1) (inverse CDF; `Choice` by equal bins).
    pub fn value(&self, u: f64) -> toml::Value {
        let u = u.clamp(1e-12, 1.0 - 1e-12);
        toml::Value::Float(match self {
            WorldDist::Uniform(lo, hi) => lo + u * (hi - lo),
            WorldDist::LogUniform(lo, hi) => (lo.ln() + u * (hi.ln() - lo.ln())).exp(),
            WorldDist::Normal(m, s) => m + s * inv_cdf(u),
            WorldDist::LogNormal(m, s) => (m + s * inv_cdf(u)).exp(),
            WorldDist::Choice(v) => {
                let i = ((u * v.len() as f64) as usize).min(v.len() - 1);
                return v[i].clone();
            }
        })
    }

    /// The 5 % and 95 % quantiles as text (the range a ledger reports), numbers only.
    pub fn range_text(&self) -> String {
        match self {
            WorldDist::Uniform(lo, hi) | WorldDist::LogUniform(lo, hi) => format!("{lo} … {hi}"),
            WorldDist::Choice(v) => v
                .iter()
                .map(crate::report::fmt_value)
                .collect::<Vec<_>>()
                .join(" | "),
            d => {
                let q = |u: f64| match d.value(u) {
                    toml::Value::Float(x) => crate::report::fmt_short(x),
                    _ => String::new(),
                };
                format!("{} … {} (5–95 %)", q(0.05), q(0.95))
            }
        }
    }
}

/// How the worlds are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorldSampling {
    /// A sampled design of `worlds` points.
    Points(Sampling),
    /// Saltelli's design for Sobol indices: `worlds` base samples, `worlds·(d+2)` worlds.
    Saltelli,
}

/// An uncertain parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct UncertainParam {
    /// The key as written (the column name in `worlds.csv`).
    pub name: String,
    /// The table it edits.
    pub target: Target,
    /// Its distribution.
    pub dist: WorldDist,
    /// Whether the key holds an integer (values rounded).
    pub integer: bool,
}

impl UncertainParam {
    /// The value a world at probability `u` ∈ (0, 1) gives the key: the distribution's
    /// inverse CDF ([`WorldDist::value`]), rounded for an integer key.
    pub fn value(&self, u: f64) -> toml::Value {
        match (self.dist.value(u), self.integer) {
            (toml::Value::Float(f), true) => toml::Value::Integer(f.round() as i64),
            (v, _) => v,
        }
    }
}

/// The validated `[uncertainty]` section.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncertainty {
    /// Sampled worlds per case as written (Saltelli: base samples).
    pub worlds: usize,
    /// How they are drawn.
    pub sampling: WorldSampling,
    /// The uncertain parameters, in file order.
    pub params: Vec<UncertainParam>,
    /// Metrics summarised over the worlds (`m_mean`, … columns; the first is the objective).
    pub metrics: Vec<String>,
    /// Least success probability for a case to be ranked (default 0.9).
    pub min_success_probability: f64,
    /// Fraction of paired worlds the leader must win against every other case to be named
    /// the winner (default 0.95).
    pub confidence: f64,
    /// Relative margin below which two designs are called tied (default 0.01).
    pub equivalence: f64,
    /// Adaptive worlds (`adaptive_worlds`, `adaptive_batch`; `None`: the `worlds` only).
    pub adaptive: Option<Adaptive>,
}

/// Adaptive worlds (issue 36 item 6, docs/statistics.md § Adaptive worlds): after the first
/// `worlds`, the designs still in contention meet further points of the same Sobol sequence,
/// `batch` at a time, until the verdict is decided or each has met `budget` worlds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Adaptive {
    /// Most worlds a design meets (`adaptive_worlds`, > `worlds`).
    pub budget: usize,
    /// Worlds added per round (`adaptive_batch`, default `worlds`).
    pub batch: usize,
}

/// A held-out validation variant (`[[validate]]`): overrides not used in tuning, scored at
/// the tuned values in the nominal world.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    /// Name (column part, `validate.<name>.<metric>`).
    pub name: String,
    /// The overrides, in file order.
    pub set: Vec<(String, Target, toml::Value)>,
}

/// One sampled world: a value per uncertain parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// Index (0-based, the `world` column).
    pub index: usize,
    /// The values, in parameter order.
    pub values: Vec<toml::Value>,
}

impl Uncertainty {
    /// Number of worlds each case meets (besides the nominal one).
    pub fn n_worlds(&self) -> usize {
        match self.sampling {
            WorldSampling::Points(_) => self.worlds,
            WorldSampling::Saltelli => self.worlds * (self.params.len() + 2),
        }
    }

    /// The objective summarised over worlds (first of [`Uncertainty::metrics`]).
    pub fn objective(&self) -> &str {
        &self.metrics[0]
    }

    /// The worlds of a study with seed `seed`: the same for every case.
    pub fn sample(&self, seed: u64) -> Vec<World> {
        self.sample_range(seed, 0..self.worlds)
    }

    /// The most worlds a design of the study can meet: the adaptive budget, else
    /// [`Uncertainty::n_worlds`].
    pub fn max_worlds(&self) -> usize {
        self.adaptive.map_or(self.n_worlds(), |a| a.budget)
    }

    /// Worlds `range` of a study with seed `seed` (with points sampling; Saltelli's design is
    /// whole, `range` ignored). A Sobol or random point depends only on the seed and its index
    /// ([`Sampler::point`]), so worlds beyond `worlds` are the next points of the same
    /// sequence and `sample_range(seed, 0..n)` starts with `sample(seed)`.
    pub fn sample_range(&self, seed: u64, range: std::ops::Range<usize>) -> Vec<World> {
        let d = self.params.len();
        let seed = derive_seed(seed, WORLD_STREAM);
        let start = range.start;
        let units: Vec<Vec<f64>> = match self.sampling {
            WorldSampling::Saltelli => SaltelliDesign { n: self.worlds, d }.points(seed),
            WorldSampling::Points(s) => {
                // An LHS point depends on the count: it is always drawn for `worlds` points
                // (parse() allows adaptive worlds with Sobol sampling only).
                let n = if s == Sampling::Lhs {
                    self.worlds
                } else {
                    range.end
                };
                let Ok(sampler) = Sampler::new(s, n, d, seed) else {
                    return Vec::new(); // parse() checked the sizes
                };
                range
                    .map(|i| {
                        let mut u = vec![0.0; d];
                        sampler.point(i, &mut u);
                        u
                    })
                    .collect()
            }
        };
        let start = if self.sampling == WorldSampling::Saltelli {
            0
        } else {
            start
        };
        units
            .into_iter()
            .enumerate()
            .map(|(i, u)| World {
                index: start + i,
                values: self
                    .params
                    .iter()
                    .zip(&u)
                    .map(|(p, &x)| p.value(x))
                    .collect(),
            })
            .collect()
    }
}

//! `[uncertainty]` and `[[validate]]` of study files (issue 22; docs/study-format.md §
//! Uncertain worlds): the uncertain parameters and their distributions, the sampled worlds
//! every case meets, the ranking settings, and the held-out validation variants.
//!
//! **Common random numbers.** World `k`'s parameter values are a pure function of the study
//! seed and `k` (never of the case), so every design meets the same worlds and comparisons
//! between designs are paired — for any `--jobs`, shard split or resume.

use std::collections::BTreeSet;

use serde::Deserialize;

use super::cases::Resolved;
use super::hash::case_hashes;
use super::schema::{Study, Target};
use crate::input::document::Document;
use crate::input::keypath::{set, SetError};
use crate::input::located::InputError;
use crate::sampling::{derive_seed, Sampler, Sampling};
use crate::stats::normal::inv_cdf;
use crate::stats::sobol::SaltelliDesign;

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
        let d = self.params.len();
        let seed = derive_seed(seed, WORLD_STREAM);
        let units: Vec<Vec<f64>> = match self.sampling {
            WorldSampling::Saltelli => SaltelliDesign { n: self.worlds, d }.points(seed),
            WorldSampling::Points(s) => {
                let Ok(sampler) = Sampler::new(s, self.worlds, d, seed) else {
                    return Vec::new(); // parse() checked the sizes
                };
                (0..self.worlds)
                    .map(|i| {
                        let mut u = vec![0.0; d];
                        sampler.point(i, &mut u);
                        u
                    })
                    .collect()
            }
        };
        units
            .into_iter()
            .enumerate()
            .map(|(index, u)| World {
                index,
                values: self
                    .params
                    .iter()
                    .zip(&u)
                    .map(|(p, &x)| match (p.dist.value(x), p.integer) {
                        (toml::Value::Float(f), true) => toml::Value::Integer(f.round() as i64),
                        (v, _) => v,
                    })
                    .collect(),
            })
            .collect()
    }
}

/// Case `r` with overrides applied (a world's values, a validation variant's keys): new
/// tables and a new design hash (the vehicle cache key), the case hash and seed unchanged.
pub fn apply<'a>(
    r: &Resolved,
    overrides: impl IntoIterator<Item = (&'a str, &'a Target, &'a toml::Value)>,
) -> Result<Resolved, SetError> {
    let mut out = r.clone();
    let mut design_changed = false;
    for (name, target, value) in overrides {
        match target {
            Target::Design(p) => {
                set(&mut out.design, &p.0, value.clone(), name)?;
                design_changed = true;
            }
            Target::Scenario(p) => set(&mut out.scenario, &p.0, value.clone(), name)?,
        }
    }
    if design_changed {
        out.design_hash = case_hashes(&out.design, &out.scenario, out.seed).1;
    }
    Ok(out)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UncertaintyFile {
    worlds: Option<usize>,
    sampling: Option<String>,
    metrics: Option<Vec<String>>,
    min_success_probability: Option<f64>,
    confidence: Option<f64>,
    equivalence: Option<f64>,
    param: Option<Vec<ParamFile>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamFile {
    name: String,
    distribution: DistFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DistFile {
    kind: String,
    low: Option<f64>,
    high: Option<f64>,
    mean: Option<f64>,
    std: Option<f64>,
    mu: Option<f64>,
    sigma: Option<f64>,
    values: Option<Vec<toml::Value>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VariantFile {
    name: String,
    set: toml::Table,
}

/// The default tracked metrics of `study`: its objective (`study.objective`, else the
/// energy metric of its mode) and its Pareto metrics that runs report.
fn default_metrics(study: &Study) -> Vec<String> {
    let run_metric = |m: &str| {
        super::parse::known_metric(m, study)
            && !study.tune_columns().iter().any(|c| c == m)
            && !super::records::DESIGN_COLUMNS.contains(&m)
            && !super::records::TCM_COLUMNS.contains(&m)
    };
    let mut v: Vec<String> = Vec::new();
    let energy = match study.mode {
        super::runner::StudyMode::Work => "thruster_energy",
        _ => super::selection::ENERGY_PER_METRE,
    };
    v.push(
        study
            .report
            .objective
            .clone()
            .unwrap_or_else(|| energy.to_string()),
    );
    for m in study.report.pareto.iter().flatten() {
        if run_metric(m) && !v.contains(m) {
            v.push(m.clone());
        }
    }
    v
}

/// Parse `[uncertainty]` of a parsed study (`None` without the section). Every parameter
/// must be a key a sweep axis could edit and not an axis of the study itself.
pub fn parse_uncertainty(
    table: Option<&toml::Table>,
    study: &Study,
    doc: &Document,
) -> Result<Option<Uncertainty>, InputError> {
    let Some(t) = table else { return Ok(None) };
    if !study.mode.is_dynamic() {
        return Err(doc.err(
            "uncertainty",
            "uncertain worlds need a closed-loop mode (scenario.mode = \"transport\" or \"work\"): \
             the static analysis does not depend on them",
        ));
    }
    let f: UncertaintyFile =
        crate::input::document::deserialize_table(t, "uncertainty").map_err(|e| doc.place(e))?;
    let worlds = f.worlds.unwrap_or(16);
    if !(2..=MAX_WORLDS).contains(&worlds) {
        return Err(doc.err(
            "uncertainty.worlds",
            format!("must be between 2 and {MAX_WORLDS}, got {worlds}"),
        ));
    }
    let sampling = match f.sampling.as_deref().unwrap_or("sobol") {
        "saltelli" => WorldSampling::Saltelli,
        s => WorldSampling::Points(s.parse().map_err(|e: crate::sampling::UnknownSampling| {
            doc.err("uncertainty.sampling", format!("{e}, saltelli"))
        })?),
    };
    let probability = |v: Option<f64>, key: &str, default: f64| {
        let x = v.unwrap_or(default);
        if (0.0..=1.0).contains(&x) {
            Ok(x)
        } else {
            Err(doc.err(key, format!("must be within [0, 1], got {x}")))
        }
    };
    let params = parse_params(f.param.as_deref().unwrap_or_default(), study, doc)?;
    if let WorldSampling::Points(s) = sampling {
        Sampler::new(s, worlds, params.len(), 0)
            .map_err(|e| doc.err("uncertainty.param", e.to_string()))?;
    }
    let metrics = match f.metrics {
        Some(m) if m.is_empty() => return Err(doc.err("uncertainty.metrics", "is empty")),
        Some(m) => m,
        None => default_metrics(study),
    };
    for (i, m) in metrics.iter().enumerate() {
        if !super::parse::known_metric(m, study) {
            return Err(super::parse::unknown_metric(
                m,
                &format!("uncertainty.metrics[{i}]"),
                study,
                doc,
            ));
        }
    }
    Ok(Some(Uncertainty {
        worlds,
        sampling,
        params,
        metrics,
        min_success_probability: probability(
            f.min_success_probability,
            "uncertainty.min_success_probability",
            0.9,
        )?,
        confidence: probability(f.confidence, "uncertainty.confidence", 0.95)?,
        equivalence: probability(f.equivalence, "uncertainty.equivalence", 0.01)?,
    }))
}

fn parse_params(
    files: &[ParamFile],
    study: &Study,
    doc: &Document,
) -> Result<Vec<UncertainParam>, InputError> {
    if files.is_empty() {
        return Err(doc.err(
            "uncertainty",
            "needs at least one [[uncertainty.param]] (name = a sweep-axis key, distribution)",
        ));
    }
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for (i, p) in files.iter().enumerate() {
        let key = format!("uncertainty.param[{i}].name");
        let (target, reference) = resolve_key(&p.name, &key, study, doc)?;
        if !seen.insert(p.name.clone()) {
            return Err(doc.err(&key, format!("`{}` is listed twice", p.name)));
        }
        let integer = matches!(reference, Some(toml::Value::Integer(_)));
        let dist = parse_dist(
            &p.distribution,
            &format!("uncertainty.param[{i}].distribution"),
            doc,
        )?;
        out.push(UncertainParam {
            name: p.name.clone(),
            target,
            dist,
            integer,
        });
    }
    Ok(out)
}

/// The target of a world or variant key: a valid sweep-axis key that no axis sweeps.
fn resolve_key(
    name: &str,
    key: &str,
    study: &Study,
    doc: &Document,
) -> Result<(Target, Option<toml::Value>), InputError> {
    let found = super::axes::study_target(study, name).map_err(|e| doc.err(key, e.to_string()))?;
    let Some((target, reference)) = found else {
        return Err(doc.err(
            key,
            format!(
                "`{name}` is not a key a sweep axis could edit (a design key, or a scenario-side \
                 key such as hydro.linear_damping_scale, physics.current_speed, \
                 initial.position[1])"
            ),
        ));
    };
    if let Some(a) = study
        .axes
        .iter()
        .find(|a| super::axes::overlaps(&a.target, &target))
    {
        return Err(doc.err(
            key,
            format!("`{name}` is swept by the axis `{}`: a key is either a design choice or an uncertainty", a.name),
        ));
    }
    Ok((target, reference))
}

fn parse_dist(d: &DistFile, key: &str, doc: &Document) -> Result<WorldDist, InputError> {
    let k = |f: &str| format!("{key}.{f}");
    let allowed: &[&str] = match d.kind.as_str() {
        "uniform" | "loguniform" => &["low", "high"],
        "normal" => &["mean", "std"],
        "lognormal" => &["mu", "sigma"],
        "choice" => &["values"],
        other => {
            return Err(doc.err(
                &k("kind"),
                format!(
                    "unknown distribution '{other}'; valid: uniform, loguniform, normal, \
                     lognormal, choice"
                ),
            ))
        }
    };
    let given = [
        ("low", d.low.is_some()),
        ("high", d.high.is_some()),
        ("mean", d.mean.is_some()),
        ("std", d.std.is_some()),
        ("mu", d.mu.is_some()),
        ("sigma", d.sigma.is_some()),
        ("values", d.values.is_some()),
    ];
    if let Some((f, _)) = given.iter().find(|(f, g)| *g && !allowed.contains(f)) {
        return Err(doc.err(&k(f), format!("not a parameter of kind \"{}\"", d.kind)));
    }
    let need = |v: Option<f64>, f: &str| {
        v.filter(|x| x.is_finite())
            .ok_or_else(|| doc.err(&k(f), format!("`{f}` is required and must be finite")))
    };
    Ok(match d.kind.as_str() {
        "uniform" | "loguniform" => {
            let (lo, hi) = (need(d.low, "low")?, need(d.high, "high")?);
            if lo > hi {
                return Err(doc.err(&k("high"), "needs low <= high"));
            }
            if d.kind == "uniform" {
                WorldDist::Uniform(lo, hi)
            } else if lo <= 0.0 {
                return Err(doc.err(&k("low"), "loguniform needs low > 0"));
            } else {
                WorldDist::LogUniform(lo, hi)
            }
        }
        "normal" | "lognormal" => {
            let (m, s) = if d.kind == "normal" {
                (need(d.mean, "mean")?, need(d.std, "std")?)
            } else {
                (need(d.mu, "mu")?, need(d.sigma, "sigma")?)
            };
            if s < 0.0 {
                return Err(doc.err(
                    &k(if d.kind == "normal" { "std" } else { "sigma" }),
                    "must be >= 0",
                ));
            }
            if d.kind == "normal" {
                WorldDist::Normal(m, s)
            } else {
                WorldDist::LogNormal(m, s)
            }
        }
        _ => match &d.values {
            Some(v) if !v.is_empty() => WorldDist::Choice(v.clone()),
            _ => return Err(doc.err(&k("values"), "needs at least one value")),
        },
    })
}

/// Parse the `[[validate]]` list of a parsed study.
pub fn parse_variants(
    list: Option<&[toml::Table]>,
    study: &Study,
    doc: &Document,
) -> Result<Vec<Variant>, InputError> {
    let mut out: Vec<Variant> = Vec::new();
    for (i, t) in list.unwrap_or_default().iter().enumerate() {
        if !study.mode.is_dynamic() {
            return Err(doc.err("validate", "validation variants need a closed-loop mode"));
        }
        let f: VariantFile =
            crate::input::document::deserialize_table(t, &format!("validate[{i}]"))
                .map_err(|e| doc.place(e))?;
        let key = format!("validate[{i}].name");
        if f.name.is_empty()
            || !f
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            return Err(doc.err(&key, "must be non-empty: letters, digits, `_` and `-`"));
        }
        if out.iter().any(|v| v.name == f.name) {
            return Err(doc.err(&key, format!("`{}` is listed twice", f.name)));
        }
        if f.set.is_empty() {
            return Err(doc.err(
                &format!("validate[{i}].set"),
                "needs at least one key = value",
            ));
        }
        let mut set = Vec::new();
        for (name, value) in &f.set {
            let (target, _) = resolve_key(name, &format!("validate[{i}].set.{name}"), study, doc)?;
            set.push((name.clone(), target, value.clone()));
        }
        out.push(Variant { name: f.name, set });
    }
    Ok(out)
}

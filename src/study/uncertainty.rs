//! `[uncertainty]` and `[[validate]]` of study files (issue 22; docs/study-format.md §
//! Uncertain worlds): the uncertain parameters and their distributions, the sampled worlds
//! every case meets, the ranking settings, and the held-out validation variants.
//!
//! **Common random numbers.** World `k`'s parameter values are a pure function of the study
//! seed and `k` (never of the case), so every design meets the same worlds and comparisons
//! between designs are paired — for any `--jobs`, shard split or resume.

use std::collections::BTreeSet;

use serde::Deserialize;

pub use super::schema::{
    Adaptive, UncertainParam, Uncertainty, Variant, World, WorldDist, WorldSampling, MAX_WORLDS,
};
use super::schema::{Study, Target};
use crate::input::document::Document;
use crate::input::located::InputError;
use crate::sampling::Sampler;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UncertaintyFile {
    worlds: Option<usize>,
    sampling: Option<String>,
    metrics: Option<Vec<String>>,
    min_success_probability: Option<f64>,
    confidence: Option<f64>,
    equivalence: Option<f64>,
    adaptive_worlds: Option<usize>,
    adaptive_batch: Option<usize>,
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
        super::catalogue::known_metric(m, study)
            && !study.tune_columns().iter().any(|c| c == m)
            && !crate::evaluate::metrics::DESIGN_COLUMNS.contains(&m)
            && !crate::evaluate::metrics::TCM_COLUMNS.contains(&m)
            && !crate::evaluate::AUTHORITY_COLUMNS.contains(&m)
    };
    let mut v: Vec<String> = Vec::new();
    let energy = match study.mode {
        super::runner::StudyMode::Work => "thruster_energy",
        _ => super::directions::TRANSPORT_OBJECTIVE,
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
    let adaptive = parse_adaptive(&f, worlds, sampling, doc)?;
    let metrics = match f.metrics {
        Some(m) if m.is_empty() => return Err(doc.err("uncertainty.metrics", "is empty")),
        Some(m) => m,
        None => default_metrics(study),
    };
    for (i, m) in metrics.iter().enumerate() {
        if !super::catalogue::known_metric(m, study) {
            return Err(super::catalogue::unknown_metric(
                m,
                &format!("uncertainty.metrics[{i}]"),
                study,
                doc,
            ));
        }
    }
    Ok(Some(Uncertainty {
        adaptive,
        worlds,
        sampling,
        params,
        metrics,
        min_success_probability: probability(
            f.min_success_probability,
            "uncertainty.min_success_probability",
            0.9,
        )?,
        confidence: match probability(f.confidence, "uncertainty.confidence", 0.95)? {
            // A confidence level 1 − α of the verdict's tests (docs/statistics.md): α = 0 or 1
            // would make every or no comparison significant.
            c if c > 0.0 && c < 1.0 => c,
            c => {
                return Err(doc.err(
                    "uncertainty.confidence",
                    format!("must be within (0, 1) (a confidence level 1 − α), got {c}"),
                ))
            }
        },
        equivalence: probability(f.equivalence, "uncertainty.equivalence", 0.01)?,
    }))
}

/// `adaptive_worlds` (the budget: most worlds a design meets, more than `worlds`) and
/// `adaptive_batch` (worlds added per round, default `worlds`, at most the budget's excess);
/// Sobol sampling only: its further points extend the same low-discrepancy sequence.
fn parse_adaptive(
    f: &UncertaintyFile,
    worlds: usize,
    sampling: WorldSampling,
    doc: &Document,
) -> Result<Option<Adaptive>, InputError> {
    let Some(budget) = f.adaptive_worlds else {
        if f.adaptive_batch.is_some() {
            return Err(doc.err(
                "uncertainty.adaptive_batch",
                "needs `adaptive_worlds` (the most worlds a design may meet)",
            ));
        }
        return Ok(None);
    };
    let key = "uncertainty.adaptive_worlds";
    if sampling != WorldSampling::Points(crate::sampling::Sampling::Sobol) {
        return Err(doc.err(
            key,
            "needs sampling = \"sobol\": adaptive worlds are further points of the same \
             low-discrepancy sequence (an LHS or Saltelli design cannot be extended)",
        ));
    }
    if budget <= worlds || budget > MAX_WORLDS {
        return Err(doc.err(
            key,
            format!(
                "must be more than `worlds` ({worlds}) and at most {MAX_WORLDS} (the most \
                 worlds a design may meet), got {budget}"
            ),
        ));
    }
    let batch = f.adaptive_batch.unwrap_or(worlds).min(budget - worlds);
    if batch == 0 || f.adaptive_batch.is_some_and(|b| b > budget - worlds) {
        return Err(doc.err(
            "uncertainty.adaptive_batch",
            format!(
                "must be between 1 and adaptive_worlds − worlds ({}), got {}",
                budget - worlds,
                f.adaptive_batch.unwrap_or(0)
            ),
        ));
    }
    Ok(Some(Adaptive { budget, batch }))
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

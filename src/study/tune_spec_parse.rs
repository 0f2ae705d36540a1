//! The optimiser's sections of a study-side table → a validated [`Spec`] (issue 37 item 1):
//! `[[param]]`, `[[variant]]`, `[objective]` with `[[objective.term]]`, `[[constraint]]` and
//! `[solver]`, read by [`parse_spec`] under any key prefix — a problem file's top level
//! (`crate::optimise::problem`) or a sweep's `[tune]` ([`super::tune_section`]). The format
//! is documented in `docs/optimise.md`.
//!
//! Every check runs here, before any evaluation; each error names the file, the line and the
//! key (`param[2].upper: needs lower < upper`).

use serde::Deserialize;

use super::axes::{overlaps, study_target};
use super::catalogue::{known_metric, unknown_metric};
use super::schema::{Study, Uncertainty};
use super::tune_solver::{parse_solver, SolverFile};
use super::tune_space::{Param, Scale, Space};
use super::tune_spec::{
    Combine, Constraint, Objective, Op, Spec, Term, Variant, SUCCESS_PROBABILITY,
};
use crate::input::document::{deserialize_table, Document};
use crate::input::keypath::join_key;
use crate::input::located::{InputError, Located, Location};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecFile {
    param: Option<Vec<ParamFile>>,
    variant: Option<Vec<VariantFile>>,
    objective: ObjectiveFile,
    constraint: Option<Vec<ConstraintFile>>,
    solver: SolverFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamFile {
    name: String,
    lower: f64,
    upper: f64,
    scale: Option<String>,
    start: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VariantFile {
    name: String,
    set: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectiveFile {
    term: Vec<TermFile>,
    combine: Option<String>,
    alpha: Option<f64>,
    normalise: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TermFile {
    metric: String,
    weight: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConstraintFile {
    metric: String,
    op: String,
    value: f64,
    tolerance: Option<f64>,
}

/// The optimiser's sections of `table` (found in `doc` under `prefix`, e.g. `tune`),
/// validated against `study`: parameters, scenarios, metric names, solver settings.
pub fn parse_spec(
    doc: &Document,
    table: &toml::Table,
    prefix: &str,
    study: &Study,
) -> Result<Spec, InputError> {
    let key = |k: &str| join_key(prefix, k);
    let file: SpecFile = deserialize_table(table, prefix).map_err(|e| doc.place(e))?;
    let params = file.param.unwrap_or_default();
    if params.is_empty() {
        let near = ["param", "objective", "solver"]
            .into_iter()
            .map(|k| doc.location(&key(k)))
            .find(|l| l.line.is_some())
            .unwrap_or_else(|| Location::origin(doc.origin()));
        return Err(Located {
            at: Location {
                key: key("param"),
                ..near
            },
            error: "the parameter list is empty: give at least one [[param]]".into(),
        });
    }
    let mut list = Vec::new();
    for (i, p) in params.iter().enumerate() {
        let param = parse_param(p, &key(&format!("param[{i}]")), study, doc)?;
        if list.iter().any(|q: &Param| q.name == param.name) {
            return Err(doc.err(&key(&format!("param[{i}].name")), "duplicate parameter"));
        }
        list.push(param);
    }
    check_axis_aliases(&list, &key("param"), study, doc)?;
    let variants = parse_variants(
        file.variant.unwrap_or_default(),
        &key("variant"),
        study,
        doc,
    )?;
    check_variant_params(&variants, &list, &key("variant"), study, doc)?;
    // A problem file's `[uncertainty]`: every scenario in every world (robust optimisation;
    // per-case tuning of sweeps tunes in the nominal world and meets the worlds after).
    let variants = match (&study.uncertainty, prefix.is_empty()) {
        (Some(u), true) => in_worlds(variants, u, study.seed),
        _ => variants,
    };
    let objective = parse_objective(&file.objective, &key("objective"), study, doc)?;
    let mut constraints = Vec::new();
    for (i, c) in file.constraint.unwrap_or_default().iter().enumerate() {
        constraints.push(parse_constraint(
            c,
            &key(&format!("constraint[{i}]")),
            study,
            doc,
        )?);
    }
    let solver = parse_solver(&file.solver, &key("solver"), study.seed, doc)?;
    Ok(Spec {
        space: Space::new(list),
        variants,
        objective,
        constraints,
        solver,
    })
}

/// No parameter may set a key a sweep axis of the study sets (under any alias, e.g.
/// `design.longitudinal_offset` and `design.generator.longitudinal_offset`): the tuned value
/// would silently replace the axis value the case is labelled with.
fn check_axis_aliases(
    params: &[Param],
    at: &str,
    study: &Study,
    doc: &Document,
) -> Result<(), InputError> {
    for (i, p) in params.iter().enumerate() {
        if let Some(a) = study.axes.iter().find(|a| overlaps(&a.target, &p.target)) {
            return Err(doc.err(
                &format!("{at}[{i}].name"),
                format!(
                    "`{}` sets the same key as the sweep axis `{}`: the tuned value would \
                     replace the axis value every case is labelled with; tune another key \
                     or drop the axis",
                    p.name, a.name
                ),
            ));
        }
    }
    Ok(())
}

/// No `[[variant]]` may set a key a `[[param]]` sets: the variant's value would replace the
/// optimiser's in every run while the history reports the parameter's.
fn check_variant_params(
    variants: &[Variant],
    params: &[Param],
    at: &str,
    study: &Study,
    doc: &Document,
) -> Result<(), InputError> {
    for (i, v) in variants.iter().enumerate() {
        for (path, _) in &v.set {
            let Some((target, _)) = study_target(study, path).ok().flatten() else {
                continue; // parse_variants has refused it
            };
            if let Some(p) = params.iter().find(|p| overlaps(&p.target, &target)) {
                return Err(doc.err(
                    &format!("{at}[{i}].set"),
                    format!(
                        "`{path}` is the parameter `{}`: a variant setting it would override \
                         the optimiser's value in every run; drop it from the variant or from \
                         the [[param]] list",
                        p.name
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn parse_param(
    p: &ParamFile,
    at: &str,
    study: &Study,
    doc: &Document,
) -> Result<Param, InputError> {
    let k = |f: &str| format!("{at}.{f}");
    let (target, reference) = study_target(study, &p.name)
        .map_err(|m| doc.err(&k("name"), m))?
        .ok_or_else(|| {
            doc.err(
                &k("name"),
                format!(
                    "unknown parameter `{}`: not a key a sweep axis of this file may edit \
                     (`design.…` or a scenario-side key of mode \"{}\"; see docs/study-format.md)",
                    p.name, study.mode
                ),
            )
        })?;
    let scale = match p.scale.as_deref().unwrap_or("lin") {
        "lin" => Scale::Lin,
        "log" => Scale::Log,
        other => {
            return Err(doc.err(
                &k("scale"),
                format!("unknown scale `{other}`; valid: lin, log"),
            ))
        }
    };
    if !(p.lower.is_finite() && p.upper.is_finite()) {
        return Err(doc.err(&k("lower"), "bounds must be finite"));
    }
    if p.lower >= p.upper {
        return Err(doc.err(
            &k("upper"),
            format!(
                "needs lower < upper (lower = {}, upper = {})",
                p.lower, p.upper
            ),
        ));
    }
    if scale == Scale::Log && p.lower <= 0.0 {
        return Err(doc.err(&k("lower"), "a log scale needs lower > 0"));
    }
    let integer = matches!(reference, Some(toml::Value::Integer(_)));
    let current = match &reference {
        Some(toml::Value::Float(x)) => Some(*x),
        Some(toml::Value::Integer(n)) => Some(*n as f64),
        Some(other) => {
            return Err(doc.err(
                &k("name"),
                format!("`{}` holds a {}, not a number", p.name, other.type_str()),
            ))
        }
        None => None,
    };
    let (start, from) = match (p.start, current) {
        (Some(s), _) => (s, "start"),
        (None, Some(c)) => (c, "name"),
        (None, None) => {
            return Err(doc.err(
                &k("name"),
                format!("`{}` has no value in the file: give `start`", p.name),
            ))
        }
    };
    // A `[tune]` parameter without `start` starts every case from the case's own value clamped
    // to the bounds (`optimise::case_tuner`), so the base file's value is clamped here too; an
    // explicit `start` (or a problem file's current value) must lie in the bounds.
    let start = if at.starts_with("tune.") && from == "name" && start.is_finite() {
        start.clamp(p.lower, p.upper)
    } else {
        start
    };
    if !(start >= p.lower && start <= p.upper) {
        let what = if from == "start" {
            "start".to_string()
        } else {
            format!("the file's current value of `{}`", p.name)
        };
        return Err(doc.err(
            &k(from),
            format!("{what} ({start}) is outside [{}, {}]", p.lower, p.upper),
        ));
    }
    Ok(Param {
        name: p.name.clone(),
        target,
        lower: p.lower,
        upper: p.upper,
        scale,
        start,
        integer,
    })
}

/// Each scenario of `variants` in each world of `u` drawn from `seed` (named `w<k>`, or
/// `<variant>/w<k>`).
pub fn in_worlds(variants: Vec<Variant>, u: &Uncertainty, seed: u64) -> Vec<Variant> {
    let worlds = u.sample(seed);
    let mut out = Vec::with_capacity(variants.len() * worlds.len());
    for v in &variants {
        for w in &worlds {
            let mut set = v.set.clone();
            set.extend(
                u.params
                    .iter()
                    .zip(&w.values)
                    .map(|(p, x)| (p.name.clone(), x.clone())),
            );
            out.push(Variant {
                name: if v.name.is_empty() {
                    format!("w{}", w.index)
                } else {
                    format!("{}/w{}", v.name, w.index)
                },
                set,
            });
        }
    }
    out
}

fn parse_variants(
    files: Vec<VariantFile>,
    at: &str,
    study: &Study,
    doc: &Document,
) -> Result<Vec<Variant>, InputError> {
    if files.is_empty() {
        return Ok(vec![Variant {
            name: String::new(),
            set: Vec::new(),
        }]);
    }
    let mut out: Vec<Variant> = Vec::new();
    for (i, v) in files.into_iter().enumerate() {
        let k = format!("{at}[{i}]");
        if v.name.is_empty() || out.iter().any(|o| o.name == v.name) {
            return Err(doc.err(&format!("{k}.name"), "must be non-empty and unique"));
        }
        let mut set = Vec::new();
        for (path, value) in v.set.unwrap_or_default() {
            let found = study_target(study, &path).map_err(|m| doc.err(&format!("{k}.set"), m))?;
            if found.is_none() {
                return Err(doc.err(
                    &format!("{k}.set"),
                    format!("unknown key `{path}`: not a key a sweep axis of this file may edit"),
                ));
            }
            set.push((path, value));
        }
        out.push(Variant { name: v.name, set });
    }
    // Every key some variant sets needs a base value for the variants that do not set it.
    for v in &out {
        for (path, _) in &v.set {
            let base = study_target(study, path).ok().flatten().and_then(|t| t.1);
            if base.is_none() && out.iter().any(|w| !w.set.iter().any(|(p, _)| p == path)) {
                return Err(doc.err(
                    at,
                    format!("`{path}` has no value in the file; every variant must set it"),
                ));
            }
        }
    }
    Ok(out)
}

fn check_metric(name: &str, at: &str, study: &Study, doc: &Document) -> Result<(), InputError> {
    if known_metric(name, study) {
        return Ok(());
    }
    Err(unknown_metric(name, at, study, doc))
}

fn parse_objective(
    o: &ObjectiveFile,
    at: &str,
    study: &Study,
    doc: &Document,
) -> Result<Objective, InputError> {
    if o.term.is_empty() {
        return Err(doc.err(&format!("{at}.term"), "needs at least one term"));
    }
    let mut terms = Vec::new();
    for (i, t) in o.term.iter().enumerate() {
        check_metric(&t.metric, &format!("{at}.term[{i}].metric"), study, doc)?;
        if !t.weight.is_finite() || t.weight == 0.0 {
            return Err(doc.err(
                &format!("{at}.term[{i}].weight"),
                "must be finite and non-zero",
            ));
        }
        terms.push(Term {
            metric: t.metric.clone(),
            weight: t.weight,
        });
    }
    let combine = match o.combine.as_deref().unwrap_or("mean") {
        "mean" => Combine::Mean,
        "worst" => Combine::Worst,
        "cvar" => match o.alpha {
            Some(a) if a > 0.0 && a <= 1.0 => Combine::Cvar(a),
            Some(a) => {
                return Err(doc.err(
                    &format!("{at}.alpha"),
                    format!("must be in (0, 1], got {a}"),
                ))
            }
            None => {
                return Err(doc.err(
                    &format!("{at}.alpha"),
                    "combine = \"cvar\" needs alpha: the fraction of worst scenarios averaged",
                ))
            }
        },
        other => {
            return Err(doc.err(
                &format!("{at}.combine"),
                format!("unknown combination `{other}`; valid: mean, worst, cvar"),
            ))
        }
    };
    if o.alpha.is_some() && !matches!(combine, Combine::Cvar(_)) {
        return Err(doc.err(&format!("{at}.alpha"), "only with combine = \"cvar\""));
    }
    Ok(Objective {
        terms,
        combine,
        normalise: o.normalise.unwrap_or(true),
    })
}

fn parse_constraint(
    c: &ConstraintFile,
    at: &str,
    study: &Study,
    doc: &Document,
) -> Result<Constraint, InputError> {
    let chance = c.metric == SUCCESS_PROBABILITY;
    if chance {
        if !study.mode.is_dynamic() {
            return Err(doc.err(
                &format!("{at}.metric"),
                "success_probability needs a closed-loop mode",
            ));
        }
    } else {
        check_metric(&c.metric, &format!("{at}.metric"), study, doc)?;
    }
    let op = match c.op.as_str() {
        "<=" => Op::Le,
        ">=" => Op::Ge,
        "==" => Op::Eq,
        other => {
            return Err(doc.err(
                &format!("{at}.op"),
                format!("unknown comparison `{other}`; valid: <=, >=, =="),
            ))
        }
    };
    if !c.value.is_finite() {
        return Err(doc.err(&format!("{at}.value"), "must be finite"));
    }
    let tolerance = c.tolerance.unwrap_or(1e-9 * c.value.abs().max(1.0));
    if !(tolerance >= 0.0 && tolerance.is_finite()) {
        return Err(doc.err(&format!("{at}.tolerance"), "must be finite and >= 0"));
    }
    Ok(Constraint {
        metric: c.metric.clone(),
        op,
        value: c.value,
        tolerance,
        chance,
    })
}

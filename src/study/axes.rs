//! The `[[axis]]` entries of a study file → validated [`Axis`] values: which table and key
//! each edits (checked against the valid parameter names), and its values, range or
//! distribution.

use std::collections::BTreeSet;

use serde::Deserialize;

use super::error::InputError;
use super::schema::{
    is_scenario_table, Axis, AxisSpec, Dist, Doe, Study, Target, GENERATOR_KEYS, MAX_CASES,
};
use crate::input::document::Document;
use crate::input::keypath::{
    did_you_mean, display_pattern, flatten, pattern_allowed, KeyPath, KeyPathError, Seg,
};
use crate::sampling::{Sampling, MAX_SOBOL_DIMS};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct AxisFile {
    name: String,
    values: Option<Vec<toml::Value>>,
    range: Option<RangeFile>,
    distribution: Option<DistFile>,
    condition: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RangeFile {
    start: f64,
    stop: f64,
    steps: Option<usize>,
    log: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DistFile {
    kind: String,
    low: Option<f64>,
    high: Option<f64>,
    mean: Option<f64>,
    std: Option<f64>,
}

const THRUSTER_KEYS: [&str; 10] = [
    "name",
    "body",
    "position",
    "position[]",
    "direction",
    "direction[]",
    "u_min",
    "u_max",
    "time_constant",
    "rate_limit",
];

/// Valid parameter names: patterns, array patterns, and the reference table per side.
pub(crate) struct Names {
    design: BTreeSet<String>,
    design_arrays: BTreeSet<String>,
    scenario: BTreeSet<String>,
    scenario_arrays: BTreeSet<String>,
    /// Scenario defaults merged under the study's own values (reference types).
    pub(crate) scenario_ref: toml::Table,
    generator: bool,
}

impl Names {
    /// Every name an axis may take (generator aliases marked `(alias)`).
    fn all(&self) -> Vec<String> {
        let mut v: Vec<String> = self
            .design
            .iter()
            .map(|p| format!("design.{}", display_pattern(p)))
            .collect();
        if self.generator {
            v.extend(GENERATOR_KEYS.iter().map(|k| format!("design.{k} (alias)")));
        }
        v.extend(self.scenario.iter().map(|p| display_pattern(p)));
        v
    }

    /// What to tell a user who wrote the unknown axis `name`: the closest valid name when one
    /// is close; else the valid names of its table (`design.…`, `control.…`), or all of them.
    fn hint(&self, name: &str) -> String {
        let all = self.all();
        let bare: Vec<&str> = all.iter().map(|n| n.trim_end_matches(" (alias)")).collect();
        let close = did_you_mean(name, bare.iter().copied());
        if !close.is_empty() {
            return close;
        }
        let table = name.split(['.', '[']).next().unwrap_or("");
        let same: Vec<&str> = bare
            .iter()
            .copied()
            .filter(|n| n.split(['.', '[']).next() == Some(table))
            .collect();
        if same.is_empty() {
            format!("; valid names: {}", all.join(", "))
        } else {
            format!("; valid names under `{table}`: {}", same.join(", "))
        }
    }
}

/// The names sweep axes may edit: the design's keys (with the generator aliases and the
/// thruster list) and the scenario side's.
pub(crate) fn valid_names(
    design: &toml::Table,
    generator: bool,
    scenario: BTreeSet<String>,
    scenario_arrays: BTreeSet<String>,
    scenario_ref: toml::Table,
) -> Names {
    let (mut d_names, mut d_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(design, "", &mut d_names, &mut d_arrays);
    let mut extra: Vec<String> = vec![
        "name".into(),
        "fluid".into(),
        "fluid.rho".into(),
        "fluid.g".into(),
        "fluid.current".into(),
        "fluid.current[]".into(),
    ];
    extra.extend(THRUSTER_KEYS.iter().map(|k| format!("thruster[].{k}")));
    if generator {
        extra.extend(GENERATOR_KEYS.iter().map(|k| format!("generator.{k}")));
        extra.push("generator.link_length[]".into());
        extra.push("generator.link_mass[]".into());
        extra.push("thruster".into());
    }
    d_names.extend(extra);
    Names {
        design: d_names,
        design_arrays: d_arrays,
        scenario,
        scenario_arrays,
        scenario_ref,
        generator,
    }
}

/// The axes, with the checks that span them (unique names, Sobol dimensions, grid size).
pub(crate) fn parse_axes(
    files: &[AxisFile],
    names: &Names,
    design: &toml::Table,
    doe: Doe,
    doc: &Document,
) -> Result<Vec<Axis>, InputError> {
    let mut axes = Vec::new();
    for (i, a) in files.iter().enumerate() {
        let axis = validate_axis(a, i, names, design, doe, doc)?;
        if axes.iter().any(|b: &Axis| b.name == axis.name) {
            return Err(doc.err(&format!("axis[{i}].name"), "duplicate axis name"));
        }
        if let Some((j, b)) = axes
            .iter()
            .enumerate()
            .find(|(_, b)| overlaps(&b.target, &axis.target))
        {
            return Err(doc.err(
                &format!("axis[{i}].name"),
                format!(
                    "`{}` sets the same parameter as axis[{j}] `{}` (both resolve to {}); \
                     keep one of them",
                    axis.name,
                    b.name,
                    target_text(&axis.target)
                ),
            ));
        }
        axes.push(axis);
    }
    if let Doe::Sampled { kind, .. } = doe {
        if kind == Sampling::Sobol && axes.len() > MAX_SOBOL_DIMS {
            return Err(doc.err(
                "doe.kind",
                format!("sobol supports at most {MAX_SOBOL_DIMS} axes"),
            ));
        }
    }
    let n = match doe {
        Doe::Grid => {
            let mut n: usize = 1;
            for a in &axes {
                n = n.saturating_mul(a.spec.grid_len());
            }
            if n > MAX_CASES {
                return Err(doc.err(
                    "axis",
                    format!("the grid has {n} cases, more than {MAX_CASES}"),
                ));
            }
            n
        }
        Doe::Sampled { cases, .. } => cases,
    };
    let bytes = n as f64 * (CASE_BYTES + AXIS_VALUE_BYTES * axes.len() as f64);
    if bytes > MAX_PLAN_BYTES {
        let key = if doe == Doe::Grid {
            "axis"
        } else {
            "doe.cases"
        };
        return Err(doc.err(
            key,
            format!(
                "{n} cases × {} axes need about {:.1} GB for the case list and the journal, \
                 more than {:.0} GB: use fewer cases or split the study",
                axes.len(),
                bytes / 1e9,
                MAX_PLAN_BYTES / 1e9
            ),
        ));
    }
    Ok(axes)
}

/// Memory of one case besides its axis values while a sweep runs [bytes]: its id, hash and
/// plan entry, its journal row read back (estimate).
const CASE_BYTES: f64 = 200.0;
/// Memory of one axis value of one case (a TOML value and its text in the tables) [bytes].
const AXIS_VALUE_BYTES: f64 = 64.0;
/// Largest case plan a study may ask for [bytes]: refused before anything runs.
const MAX_PLAN_BYTES: f64 = 4.0e9;

/// Whether two axis targets set the same parameter: equal paths, or one inside the other
/// (`design.thruster[2].position` and `design.thruster[2].position[0]`).
pub(crate) fn overlaps(a: &Target, b: &Target) -> bool {
    let (pa, pb) = match (a, b) {
        (Target::Design(x), Target::Design(y)) | (Target::Scenario(x), Target::Scenario(y)) => {
            (x, y)
        }
        _ => return false,
    };
    let n = pa.0.len().min(pb.0.len());
    pa.0[..n] == pb.0[..n]
}

/// A target as the parameter path of a study file.
fn target_text(t: &Target) -> String {
    match t {
        Target::Design(p) => format!("design.{p}"),
        Target::Scenario(p) => p.to_string(),
    }
}

fn validate_axis(
    a: &AxisFile,
    i: usize,
    names: &Names,
    design: &toml::Table,
    doe: Doe,
    doc: &Document,
) -> Result<Axis, InputError> {
    let unknown = || {
        doc.err(
            &format!("axis[{i}].name"),
            format!("unknown parameter `{}`{}", a.name, names.hint(&a.name)),
        )
    };
    let (target, reference) = axis_target(a, i, names, design, doc)?.ok_or_else(unknown)?;
    let integer = matches!(reference, Some(toml::Value::Integer(_)));
    let spec = match (&a.values, &a.range, &a.distribution) {
        (Some(v), None, None) => values_spec(v, i, doc)?,
        (None, Some(r), None) => range_spec(r, i, doe, doc)?,
        (None, None, Some(d)) => distribution_spec(d, i, doe, doc)?,
        _ => {
            return Err(doc.err(
                &format!("axis[{i}]"),
                "needs exactly one of `values = [...]`, `range = { start, stop, steps }` or `distribution = { kind, ... }`",
            ))
        }
    };
    let numeric = match &spec {
        AxisSpec::Values(v) => v
            .iter()
            .all(|x| matches!(x, toml::Value::Integer(_) | toml::Value::Float(_))),
        _ => true,
    };
    let condition = a.condition.unwrap_or(false);
    if condition && !matches!(spec, AxisSpec::Values(_)) {
        return Err(doc.err(
            &format!("axis[{i}].condition"),
            "a condition axis needs `values = [...]`: each value is a condition the designs \
             are ranked under, apart from the others",
        ));
    }
    Ok(Axis {
        name: a.name.clone(),
        target,
        spec,
        numeric,
        integer,
        condition,
    })
}

/// The table and key an axis edits, with the key's reference value (its type decides
/// integer rounding); `None` when the name is not a valid parameter.
fn axis_target(
    a: &AxisFile,
    i: usize,
    names: &Names,
    design: &toml::Table,
    doc: &Document,
) -> Result<Option<(Target, Option<toml::Value>)>, InputError> {
    target_of(&a.name, names, design).map_err(|m| doc.err(&format!("axis[{i}].name"), m))
}

/// The target and reference value of the key path `name` (as a sweep axis would edit it) in
/// a parsed study: `Err` when the path does not parse, `Ok(None)` when it is not a valid
/// parameter name of the study (the optimiser's `[[param]]` entries use this).
pub fn study_target(
    study: &Study,
    name: &str,
) -> Result<Option<(Target, Option<toml::Value>)>, KeyPathError> {
    let (mut sc, mut sc_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(&study.scenario_full, "", &mut sc, &mut sc_arrays);
    let names = valid_names(
        &study.design,
        study.generator,
        sc,
        sc_arrays,
        study.scenario_full.clone(),
    );
    target_of(name, &names, &study.design)
}

/// [`study_target`] against prepared names.
fn target_of(
    name: &str,
    names: &Names,
    design: &toml::Table,
) -> Result<Option<(Target, Option<toml::Value>)>, KeyPathError> {
    let path = KeyPath::parse(name)?;
    if path.head() == "design" {
        let mut rest = path.tail();
        if names.generator {
            if let Some(Seg::Key(k)) = rest.0.first() {
                if GENERATOR_KEYS.contains(&k.as_str()) {
                    rest.0.insert(0, Seg::Key("generator".into()));
                }
            }
        }
        if rest.0.is_empty()
            || !pattern_allowed(&rest.pattern(), &names.design, &names.design_arrays)
        {
            return Ok(None);
        }
        let reference = crate::input::keypath::get(design, &rest.0)
            .cloned()
            .or_else(|| {
                let links = crate::model::generator::GeneratorSpec::default().links as i64;
                (rest.pattern() == "generator.links").then_some(toml::Value::Integer(links))
            });
        Ok(Some((Target::Design(rest), reference)))
    } else if is_scenario_table(path.head()) {
        if !pattern_allowed(&path.pattern(), &names.scenario, &names.scenario_arrays) {
            return Ok(None);
        }
        let reference = crate::input::keypath::get(&names.scenario_ref, &path.0).cloned();
        Ok(Some((Target::Scenario(path), reference)))
    } else {
        Ok(None)
    }
}

/// `values = [...]`: non-empty, finite, strings without control characters.
fn values_spec(v: &[toml::Value], i: usize, doc: &Document) -> Result<AxisSpec, InputError> {
    if v.is_empty() {
        return Err(doc.err(&format!("axis[{i}].values"), "needs at least one value"));
    }
    if let Some(j) = v
        .iter()
        .position(|x| matches!(x, toml::Value::Float(f) if !f.is_finite()))
    {
        return Err(doc.err(&format!("axis[{i}].values[{j}]"), "must be finite"));
    }
    // A string value is a cell of the results' string columns and of the line-based journal.
    if let Some(j) = v
        .iter()
        .position(|x| matches!(x, toml::Value::String(s) if s.chars().any(char::is_control)))
    {
        return Err(doc.err(
            &format!("axis[{i}].values[{j}]"),
            "a string value may not hold a newline, tab or other control character \
             (it is a cell of cases.csv and of the resumable journal)",
        ));
    }
    Ok(AxisSpec::Values(v.to_vec()))
}

/// `range = { start, stop, steps, log }`: finite ends, positive for `log`, `steps` for grids.
fn range_spec(r: &RangeFile, i: usize, doe: Doe, doc: &Document) -> Result<AxisSpec, InputError> {
    let key = |f: &str| format!("axis[{i}].{f}");
    if !(r.start.is_finite() && r.stop.is_finite()) {
        return Err(doc.err(&key("range"), "start and stop must be finite"));
    }
    let log = r.log.unwrap_or(false);
    if log && !(r.start > 0.0 && r.stop > 0.0) {
        return Err(doc.err(&key("range.log"), "a log range needs start, stop > 0"));
    }
    match (doe, r.steps) {
        (Doe::Grid, None) => return Err(doc.err(&key("range"), "grid designs need `steps` (>= 1)")),
        (_, Some(0)) => return Err(doc.err(&key("range.steps"), "must be >= 1")),
        _ => {}
    }
    Ok(AxisSpec::Range {
        start: r.start,
        stop: r.stop,
        steps: r.steps,
        log,
    })
}

/// `distribution = { kind, ... }` (sampled designs only): the kind's parameters, finite and
/// in range, and no others.
fn distribution_spec(
    d: &DistFile,
    i: usize,
    doe: Doe,
    doc: &Document,
) -> Result<AxisSpec, InputError> {
    if doe == Doe::Grid {
        return Err(doc.err(
            &format!("axis[{i}].distribution"),
            "distributions need a sampled design ([doe] kind = \"random\" | \"lhs\" | \"sobol\")",
        ));
    }
    let dk = |f: &str| format!("axis[{i}].distribution.{f}");
    let need = |v: Option<f64>, f: &str| {
        v.filter(|x| x.is_finite())
            .ok_or_else(|| doc.err(&dk(f), format!("`{f}` is required and must be finite")))
    };
    let forbid = |v: Option<f64>, f: &str| match v {
        Some(_) => Err(doc.err(&dk(f), format!("not a parameter of kind \"{}\"", d.kind))),
        None => Ok(()),
    };
    let dist = match d.kind.as_str() {
        "uniform" | "loguniform" => {
            forbid(d.mean, "mean")?;
            forbid(d.std, "std")?;
            let (lo, hi) = (need(d.low, "low")?, need(d.high, "high")?);
            if lo >= hi {
                return Err(doc.err(&dk("high"), "needs low < high"));
            }
            if d.kind == "uniform" {
                Dist::Uniform(lo, hi)
            } else {
                if lo <= 0.0 {
                    return Err(doc.err(&dk("low"), "loguniform needs low > 0"));
                }
                Dist::LogUniform(lo, hi)
            }
        }
        "normal" => {
            forbid(d.low, "low")?;
            forbid(d.high, "high")?;
            let (m, s) = (need(d.mean, "mean")?, need(d.std, "std")?);
            if s <= 0.0 {
                return Err(doc.err(&dk("std"), "must be > 0"));
            }
            Dist::Normal(m, s)
        }
        other => {
            return Err(doc.err(
                &dk("kind"),
                format!("unknown distribution '{other}'; valid: uniform, loguniform, normal"),
            ))
        }
    };
    Ok(AxisSpec::Distribution(dist))
}

//! Values checked where they enter (issue 39): every value a study hands to a key — a sweep
//! axis's values, the whole support of an uncertain parameter's distribution, a validation
//! variant's `set` — is checked when the study is loaded by the code that would refuse it at
//! run time (the design parser for `design.*` keys; [`super::runner::check_case`] for the
//! scenario side: its schema, settings, the `[hydro]` scales and the mission payload applied to
//! the vehicle), so that `--dry-run` refuses it with file, line and key instead of every
//! affected run counting as a failure of the design.
//!
//! The values are applied to a reference case: the study's tables with every axis at its first
//! value (grids) or its middle (sampled designs). A world or variant value is refused when the
//! reference case with it fails where the reference alone does not (or fails differently); an
//! axis value only when the failure names the axis's own key (the axes combine: a value valid
//! with another axis's value is not refused for the reference's). A distribution's support is
//! checked at its two ends and its middle ([`UncertainParam::value`] at u = 0, ½, 1 — the
//! samples' inverse CDF is monotone and clamped, so this bounds every world), a `choice` at
//! every value. A value that cannot be set on the reference case (an index beyond its design's
//! thrusters) is left to the cases, whose designs differ. A tuning parameter's `lower`,
//! `upper` and `start` (`[[tune.param]]`) are checked the same way once `[tune]` is typed
//! ([`check_tune_values`], after the section's own located errors): every tuning point lies
//! between them. `[faults]` is checked by its own parser (`super::fault_spec`). The values are
//! applied as every case applies them: as typed overrides ([`crate::evaluate::overrides`]).

use super::cases::{override_of, resolve_case, Resolved};
use super::doe::{grid_values, sampled_value, Case};
use super::schema::{Axis, AxisSpec, Doe, Study, Target, UncertainParam, WorldDist};
use crate::evaluate::apply_overrides;
use crate::input::document::Document;
use crate::input::located::{InputError, KeyError};
use crate::model::design::parse_design_table;

/// Most values of one axis checked (first, last and evenly spaced ones between).
const MAX_AXIS_VALUES: usize = 33;

/// Check every value the study's axes, worlds and validation variants hand to a key (see the
/// module docs); the error is placed at the axis, distribution or `set` key that gives it.
pub fn check_values(study: &Study, doc: &Document) -> Result<(), InputError> {
    let Some(reference) = reference_case(study) else {
        return Ok(()); // a reference case that cannot be built is reported per case
    };
    let base = check(study, &reference);
    for (i, a) in study.axes.iter().enumerate() {
        for v in axis_values(a, study.doe) {
            let Err(e) = check_with(study, &reference, &a.name, &a.target, &v) else {
                continue;
            };
            if base.as_ref().err() != Some(&e) && names_target(&e.key, &a.target) {
                return Err(refusal(doc, &axis_key(a, i), &a.name, &v, &e));
            }
        }
    }
    let params = study.uncertainty.iter().flat_map(|u| u.params.iter());
    for (i, p) in params.enumerate() {
        for v in support(p) {
            if let Err(e) = check_with(study, &reference, &p.name, &p.target, &v) {
                if base.as_ref().err() != Some(&e) {
                    let key = format!("uncertainty.param[{i}].distribution");
                    return Err(refusal(doc, &key, &p.name, &v, &e));
                }
            }
        }
    }
    for (i, variant) in study.validate.iter().enumerate() {
        for (name, target, v) in &variant.set {
            if let Err(e) = check_with(study, &reference, name, target, v) {
                if base.as_ref().err() != Some(&e) {
                    let key = format!("validate[{i}].set.{name}");
                    return Err(refusal(doc, &key, name, v, &e));
                }
            }
        }
    }
    Ok(())
}

/// The tuning points' range (`[[tune.param]]` `lower`, `upper` and `start`, as written)
/// checked like an axis's values on the reference case: every tuning candidate lies between
/// them, so a bound that a run would refuse is refused at its line. Runs after
/// [`super::tune_section::parse_tune`], so a section's own errors (unknown key, bad bounds)
/// come first and every parameter's target is resolved.
pub fn check_tune_values(study: &Study, doc: &Document) -> Result<(), InputError> {
    let Some(tuning) = &study.tuning else {
        return Ok(());
    };
    let Some(reference) = reference_case(study) else {
        return Ok(());
    };
    let base = check(study, &reference);
    let raw = study
        .tune
        .as_ref()
        .and_then(|t| t.get("param"))
        .and_then(|p| p.as_array());
    for (i, (p, written)) in tuning
        .spec
        .space
        .params
        .iter()
        .zip(raw.into_iter().flatten())
        .enumerate()
    {
        for bound in ["lower", "upper", "start"] {
            let Some(v) = written.get(bound) else {
                continue;
            };
            if let Err(e) = check_with(study, &reference, &p.name, &p.target, v) {
                if base.as_ref().err() != Some(&e) && names_target(&e.key, &p.target) {
                    let key = format!("tune.param[{i}].{bound}");
                    return Err(refusal(doc, &key, &p.name, v, &e));
                }
            }
        }
    }
    Ok(())
}

/// The error for value `v` of `name` refused at `e.key`, placed at `key`.
fn refusal(doc: &Document, key: &str, name: &str, v: &toml::Value, e: &KeyError) -> InputError {
    let at = if e.key.is_empty() || e.key == name {
        String::new()
    } else {
        format!(" (at `{}`)", e.key)
    };
    doc.err(
        key,
        format!(
            "the value {v} of `{name}` is refused{at}: {}; every run given it would fail, \
             not the design",
            e.message
        ),
    )
}

/// The study's key of axis `a` (number `i`) that holds its values.
fn axis_key(a: &Axis, i: usize) -> String {
    let part = match a.spec {
        AxisSpec::Values(_) => "values",
        AxisSpec::Range { .. } => "range",
        AxisSpec::Distribution(_) => "distribution",
    };
    format!("axis[{i}].{part}")
}

/// Whether a check failure at `key` is at `target` itself (or inside it).
fn names_target(key: &str, target: &Target) -> bool {
    let (p, key) = match target {
        Target::Scenario(p) => (p.to_string(), key),
        Target::Design(p) => (p.to_string(), key.strip_prefix("design.").unwrap_or(key)),
    };
    key == p || key.starts_with(&format!("{p}.")) || key.starts_with(&format!("{p}["))
}

/// The reference case (see the module docs); `None` when the axes' values do not apply.
fn reference_case(study: &Study) -> Option<Resolved> {
    let values = study
        .axes
        .iter()
        .map(|a| match study.doe {
            Doe::Grid => grid_values(a).into_iter().next(),
            Doe::Sampled { .. } => Some(sampled_value(a, 0.5)),
        })
        .collect::<Option<Vec<_>>>()?;
    resolve_case(study, &Case { id: 0, values }).ok()
}

/// The values of axis `a` that are checked: all of a grid's up to [`MAX_AXIS_VALUES`], else
/// evenly spaced ones with the first and the last; a sampled axis's ends and middle.
fn axis_values(a: &Axis, doe: Doe) -> Vec<toml::Value> {
    let all = match (doe, &a.spec) {
        (_, AxisSpec::Values(v)) => v.clone(),
        (Doe::Grid, _) => grid_values(a),
        (Doe::Sampled { .. }, _) => [0.0, 0.5, 1.0 - 1e-12]
            .iter()
            .map(|&u| sampled_value(a, u))
            // A normal axis is unbounded at u = 0: its sampled points never reach it.
            .filter(|v| v.as_float().is_none_or(f64::is_finite))
            .collect(),
    };
    if all.len() <= MAX_AXIS_VALUES {
        return all;
    }
    let last = all.len() - 1;
    (0..MAX_AXIS_VALUES)
        .map(|k| all[k * last / (MAX_AXIS_VALUES - 1)].clone())
        .collect()
}

/// The values of `p`'s distribution that are checked: every `choice`, else the support's ends
/// and middle as the worlds would be given them.
fn support(p: &UncertainParam) -> Vec<toml::Value> {
    match &p.dist {
        WorldDist::Choice(v) => v.clone(),
        _ => [0.0, 0.5, 1.0].iter().map(|&u| p.value(u)).collect(),
    }
}

/// [`check`] of `reference` with `name` (at `target`) set to `v`.
fn check_with(
    study: &Study,
    reference: &Resolved,
    name: &str,
    target: &Target,
    v: &toml::Value,
) -> Result<(), KeyError> {
    if let toml::Value::Float(x) = v {
        if !x.is_finite() {
            return Err(KeyError::new(name, "must be a finite number"));
        }
    }
    // A value that cannot be set (an index beyond the reference design's thrusters, a value of
    // another shape) depends on the case's design: the case records why it is skipped.
    // The override applied as every case applies it (the one road, `crate::evaluate`).
    let mut r = reference.clone();
    let o = [override_of(name, target, v)];
    if apply_overrides(&mut r.design, &mut r.scenario, &o).is_err() {
        return Ok(());
    }
    check(study, &r)
}

/// The run-time checks of case `r` short of running it: its design builds and (closed-loop
/// modes) its scenario side is valid on that design.
fn check(study: &Study, r: &Resolved) -> Result<(), KeyError> {
    let v = parse_design_table(&r.design, "design").map_err(|e| {
        let key = if e.at.key.is_empty() {
            "design".to_string()
        } else {
            format!("design.{}", e.at.key)
        };
        KeyError::new(key, e.error.message)
    })?;
    if !study.mode.is_dynamic() {
        return Ok(());
    }
    let mut sc = r.scenario.clone();
    sc.remove(crate::evaluate::static_table::STATIC_TABLE);
    super::runner::check_case(&v, &sc)
}

/// The least wall time one closed-loop control period takes on one core [s]: a lower bound
/// (a transport period of the shipped designs takes about 25 µs on the reference machine), so
/// [`check_world_budget`] refuses only what cannot fit.
pub const MIN_PERIOD_S: f64 = 1e-6;

/// Refuse, at load, a study whose runs per case — the nominal run, every world of
/// `[uncertainty]` (a Saltelli design's `N × (k + 2)`) and every `[[validate]]` variant —
/// cannot finish within the case's wall-clock budget `budget_s` (`--case-timeout`; 0 = none)
/// on `threads` threads even at [`MIN_PERIOD_S`] per control period: every case would time
/// out. The error names `uncertainty.worlds` at its line.
pub fn check_world_budget(
    study: &Study,
    budget_s: f64,
    threads: usize,
) -> Result<(), crate::input::located::InputError> {
    let Some(u) = &study.uncertainty else {
        return Ok(());
    };
    if budget_s.is_nan() || budget_s <= 0.0 || !study.mode.is_dynamic() {
        return Ok(());
    }
    let sc = study.scenario_full.get("scenario");
    let num = |k: &str| {
        sc.and_then(|s| s.get(k))
            .and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
    };
    let duration = num("duration").unwrap_or(0.0);
    let dt = num("control_dt").unwrap_or(crate::scenario::config::DEFAULT_CONTROL_DT);
    let periods = (duration / dt).ceil().max(1.0);
    let runs = 1 + u.n_worlds() + study.validate.len();
    let need = runs as f64 * periods * MIN_PERIOD_S / threads.max(1) as f64;
    if need <= budget_s {
        return Ok(());
    }
    let doc =
        crate::input::document::Document::parse(&study.text, &study.path.display().to_string())
            .unwrap_or_else(|_| {
                crate::input::document::Document::unplaced(&study.path.display().to_string())
            });
    Err(doc.err(
        "uncertainty.worlds",
        format!(
            "{runs} runs per case ({} worlds{}{}) of {periods} control periods need at least \
             {} s per case on {threads} threads (at {MIN_PERIOD_S} s a period, a lower bound), \
             more than the --case-timeout of {} s: every case would time out; draw fewer \
             worlds or raise --case-timeout",
            u.n_worlds(),
            if matches!(u.sampling, super::schema::WorldSampling::Saltelli) {
                format!(
                    " = {} × ({} parameters + 2), Saltelli",
                    u.worlds,
                    u.params.len()
                )
            } else {
                String::new()
            },
            if study.validate.is_empty() {
                String::new()
            } else {
                format!(", {} validation variants", study.validate.len())
            },
            crate::input::located::fmt_exact(need),
            crate::input::located::fmt_exact(budget_s),
        ),
    ))
}

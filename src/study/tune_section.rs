//! A sweep's `[tune]` section, typed at load (issue 37 item 1; `docs/study-format.md`): the
//! optimiser's sections under `tune.` ([`super::tune_spec::parse_spec`]) and the per-case
//! tuning settings — `starts`, `seeds`, `worlds`, `race`, `screen` — validated once, when the
//! study is read, so that `--dry-run` refuses a bad section at its line. The tuner that runs
//! it (`crate::optimise::case_tuner::Tuner`) reads this type and parses nothing.
//!
//! Checks beyond a problem file's: no `[[tune.variant]]` (a case is scored in its own
//! scenario), no parameter that is also a sweep axis, or an uncertain parameter, or a key a
//! validation variant sets (two roads to one key); `worlds` from 1 to [`MAX_TUNE_WORLDS`] and
//! only with the study's `[uncertainty]`; enough evaluations for every start. Errors name the
//! file, the line and the key (`tune.param[1].upper`).

use super::axes::overlaps;
use super::schema::{Study, TuneSection, WorldSampling};
use super::tune_spec::Spec;
use super::tune_spec_parse::parse_spec;
use crate::input::document::Document;
use crate::input::located::InputError;
use crate::sampling::Sampling;

/// Most independent tuning seeds (`[tune] seeds`).
pub const MAX_SEEDS: usize = 8;

/// Most independent tuning starts (`[tune] starts`).
pub const MAX_STARTS: usize = 16;

/// Most tuning worlds (`[tune] worlds`): each is a full run per evaluation.
pub const MAX_TUNE_WORLDS: usize = 64;

/// The typed `[tune]` of `study` (`None` without one), its errors placed in `doc` (the
/// study file). Reads `study.tune` (the section as written); every other part of the study
/// (axes, `[uncertainty]`, `[[validate]]`) must already be parsed.
pub fn parse_tune(study: &Study, doc: &Document) -> Result<Option<TuneSection>, InputError> {
    let Some(t) = &study.tune else {
        return Ok(None);
    };
    if t.contains_key("variant") {
        return Err(doc.err(
            "tune.variant",
            "not allowed in [tune]: each case is tuned and scored in its own scenario",
        ));
    }
    let params = t.get("param").and_then(|p| p.as_array());
    for (i, p) in params.into_iter().flatten().enumerate() {
        let name = p.get("name").and_then(|n| n.as_str()).unwrap_or_default();
        if study.axes.iter().any(|a| a.name == name) {
            return Err(doc.err(
                &format!("tune.param[{i}].name"),
                format!("`{name}` is also a sweep axis: tune it or sweep it"),
            ));
        }
    }
    let mut t = t.clone();
    let worlds = match t.remove("worlds") {
        None => None,
        Some(toml::Value::Integer(n)) if (1..=MAX_TUNE_WORLDS as i64).contains(&n) => {
            let Some(u) = &study.uncertainty else {
                return Err(doc.err(
                    "tune.worlds",
                    "needs the study's [uncertainty] section to draw the tuning worlds from",
                ));
            };
            let mut u = u.clone();
            u.worlds = n as usize;
            // Saltelli's design serves the sensitivity indices of the scoring worlds; the
            // tuning worlds are a plain Sobol sample of the same distributions.
            if u.sampling == WorldSampling::Saltelli {
                u.sampling = WorldSampling::Points(Sampling::Sobol);
            }
            Some(u)
        }
        Some(v) => {
            return Err(doc.err(
                "tune.worlds",
                format!("must be an integer from 1 to {MAX_TUNE_WORLDS}, got {v}"),
            ))
        }
    };
    let starts = count(&mut t, "starts", MAX_STARTS, doc)?;
    let seeds = count(&mut t, "seeds", MAX_SEEDS, doc)?;
    let race = match t.remove("race") {
        None => true,
        Some(toml::Value::Boolean(b)) => b,
        Some(v) => return Err(doc.err("tune.race", format!("must be true or false, got {v}"))),
    };
    let screen = match t.remove("screen") {
        None => false,
        Some(toml::Value::String(s)) if s == "rk4" => true,
        Some(toml::Value::String(s)) if s == "none" => false,
        Some(v) => {
            return Err(doc.err(
                "tune.screen",
                format!("must be \"rk4\" or \"none\", got {v}"),
            ))
        }
    };
    let spec = parse_spec(doc, &t, "tune", study)?;
    check_two_roads(&spec, study, doc)?;
    if spec.solver.max_evals / starts < 2 {
        return Err(doc.err(
            "tune.starts",
            format!(
                "{starts} starts leave fewer than 2 evaluations each of tune.solver.max_evals = {}",
                spec.solver.max_evals
            ),
        ));
    }
    let explicit_start = params
        .map(|ps| ps.iter().map(|p| p.get("start").is_some()).collect())
        .unwrap_or_default();
    Ok(Some(TuneSection {
        spec,
        explicit_start,
        starts,
        worlds,
        seeds,
        race,
        screen,
    }))
}

/// `[tune] key`, a count from 1 to `max` (default 1), taken out of `t`; located error otherwise.
fn count(t: &mut toml::Table, key: &str, max: usize, doc: &Document) -> Result<usize, InputError> {
    match t.remove(key) {
        None => Ok(1),
        Some(toml::Value::Integer(n)) if (1..=max as i64).contains(&n) => Ok(n as usize),
        Some(v) => Err(doc.err(
            &format!("tune.{key}"),
            format!("must be an integer from 1 to {max}, got {v}"),
        )),
    }
}

/// A tuned key that the study's worlds or validation variants also set (issue 39): the world's
/// or variant's value would replace the tuned one in every run there, so the worlds would score
/// values other than those the table names (and with `[tune] worlds` every candidate would run
/// at the world's value: a flat tuning). Refused, naming both keys.
fn check_two_roads(spec: &Spec, study: &Study, doc: &Document) -> Result<(), InputError> {
    for (i, p) in spec.space.params.iter().enumerate() {
        let at = format!("tune.param[{i}].name");
        if let Some(u) = study
            .uncertainty
            .iter()
            .flat_map(|u| &u.params)
            .find(|u| overlaps(&u.target, &p.target))
        {
            return Err(doc.err(
                &at,
                format!(
                    "`{}` is also the uncertain parameter `{}`: every world would replace the \
                     tuned value, so the worlds would score values the table does not name; \
                     tune it or vary it, not both",
                    p.name, u.name
                ),
            ));
        }
        for v in &study.validate {
            if let Some((key, _, _)) = v.set.iter().find(|(_, t, _)| overlaps(t, &p.target)) {
                return Err(doc.err(
                    &at,
                    format!(
                        "`{}` is also set by the validation variant `{}` (`{key}`): the variant \
                         would replace the tuned value; tune it or validate it, not both",
                        p.name, v.name
                    ),
                ));
            }
        }
    }
    Ok(())
}

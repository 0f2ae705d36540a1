//! Study files (TOML) → validated [`Study`]: the file schema, the valid parameter names, and
//! the checks, one phase per part of the file (name, design, scenario side, design of
//! experiments, axes). The format is documented in `docs/study-format.md`.
//!
//! Every error names the file, the 1-based line and column when known, and the key
//! (`axis[2].name`). `deny_unknown_fields` everywhere; no `serde(flatten)`.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::axes::{parse_axes, valid_names, AxisFile};
pub use super::catalogue::{known_metric, metric_catalogue, unknown_metric};
use super::error::InputError;
use super::fault_spec::{parse_faults, FAULT_KEYS};
use super::hash::study_hash;
use super::runner::{self, StudyMode};
use super::schema::{Axis, Doe, DoeKind, ReportSettings, Study, Target, MAX_CASES};
use super::uncertainty::{parse_uncertainty, parse_variants};
use crate::evaluate::static_table::{
    authority_spec, static_default_table, static_spec, STATIC_OPTIONAL_KEYS, STATIC_TABLE,
};
use crate::input::document::{deserialize_table, Document};
use crate::input::keypath::{flatten, pattern_allowed};
use crate::input::located::{KeyError, Location};
use crate::model::design::{load_design_table, parse_design_table};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    study: StudyMeta,
    design: toml::Table,
    scenario: Option<toml::Table>,
    #[serde(rename = "static")]
    static_: Option<toml::Table>,
    control: Option<toml::Table>,
    base_control: Option<toml::Table>,
    allocation: Option<toml::Table>,
    metrics: Option<toml::Table>,
    physics: Option<toml::Table>,
    initial: Option<toml::Table>,
    path: Option<toml::Table>,
    setpoint: Option<toml::Table>,
    reference: Option<toml::Table>,
    servo: Option<toml::Table>,
    thrusters: Option<toml::Table>,
    success: Option<toml::Table>,
    axis: Option<Vec<AxisFile>>,
    doe: Option<DoeFile>,
    tune: Option<toml::Table>,
    hydro: Option<toml::Table>,
    mission: Option<toml::Table>,
    uncertainty: Option<toml::Table>,
    validate: Option<Vec<toml::Table>>,
    faults: Option<toml::Table>,
    fault: Option<toml::Table>,
    ocp: Option<toml::Table>,
    secondary: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyMeta {
    name: String,
    description: Option<String>,
    seed: Option<u64>,
    output: Option<String>,
    objective: Option<String>,
    pareto: Option<[String; 2]>,
    maximise: Option<Vec<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DoeFile {
    kind: String,
    cases: Option<usize>,
}

fn merge_into(base: &mut toml::Table, over: &toml::Table) {
    for (k, v) in over {
        match (base.get_mut(k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge_into(b, o),
            _ => {
                base.insert(k.clone(), v.clone());
            }
        }
    }
}

/// Read and validate a study file.
pub fn load_study(path: &Path) -> Result<Study, InputError> {
    load_study_at(path, None)
}

/// [`load_study`] at `seed` instead of the file's own `[study] seed` ([`with_seed`]; `None`:
/// the file as written). `sweep --seed`.
pub fn load_study_at(path: &Path, seed: Option<u64>) -> Result<Study, InputError> {
    let origin = path.display().to_string();
    let text = crate::input::document::read_text(path).map_err(|e| InputError {
        at: Location::origin(&origin),
        error: format!("cannot read the study file: {e}"),
    })?;
    match seed {
        None => parse_study(&text, path),
        Some(seed) => parse_study(&with_seed(&text, seed)?, path),
    }
}

fn base_design(
    d: &toml::Table,
    dir: &Path,
    doc: &Document,
) -> Result<(toml::Table, String), InputError> {
    if let Some(f) = d.get("file") {
        if let Some(k) = d.keys().find(|k| *k != "file") {
            return Err(doc.err(
                &format!("design.{k}"),
                "cannot be combined with `design.file`",
            ));
        }
        let f = f.as_str().ok_or_else(|| {
            doc.err(
                "design.file",
                "must be a string (a path relative to the study file)",
            )
        })?;
        let p = dir.join(f);
        let arg = p.display().to_string();
        if !p.is_file() {
            return Err(doc.err("design.file", format!("no design file {arg}")));
        }
        let t = load_design_table(&arg).map_err(InputError::from)?;
        return Ok((t, arg));
    }
    if let Some(p) = d.get("preset") {
        if let Some(k) = d.keys().find(|k| *k != "preset" && *k != "name") {
            return Err(doc.err(
                &format!("design.{k}"),
                "not allowed with `design.preset` (only `name`); sweep axes may still edit the \
                 preset's keys, e.g. design.thruster[2].position",
            ));
        }
        let p = p
            .as_str()
            .ok_or_else(|| doc.err("design.preset", "must be a string"))?;
        let mut t = load_design_table(p).map_err(|e| doc.err("design.preset", e.error.message))?;
        if let Some(n) = d.get("name") {
            t.insert("name".into(), n.clone());
        }
        return Ok((t, format!("preset {p}")));
    }
    let mut t = d.clone();
    if !t.contains_key("name") {
        t.insert("name".into(), toml::Value::String("design".into()));
    }
    Ok((t, format!("{} [design]", doc.origin())))
}

/// `text` with `[study] seed` set to `seed`, everything else as written: the value is replaced
/// on its own line when the key is there (so every error location still points at the file's
/// lines), else the key is added at the end of `[study]`. Errors: the text is not TOML, or
/// `study` is not a table (the same errors [`parse_study`] would give, located).
pub fn with_seed(text: &str, seed: u64) -> Result<String, InputError> {
    let mut doc: toml_edit::DocumentMut =
        text.parse().map_err(|e: toml_edit::TomlError| InputError {
            at: Location::origin("study file"),
            error: format!("not TOML: {e}"),
        })?;
    let study = doc
        .entry("study")
        .or_insert(toml_edit::table())
        .as_table_mut()
        .ok_or_else(|| InputError {
            at: Location::origin("study file"),
            error: "`study` must be a table".into(),
        })?;
    match study.get_mut("seed").and_then(|i| i.as_value_mut()) {
        Some(v) => {
            let decor = v.decor().clone();
            *v = toml_edit::Value::from(seed as i64);
            *v.decor_mut() = decor;
        }
        None => {
            study.insert("seed", toml_edit::value(seed as i64));
        }
    }
    Ok(doc.to_string())
}

/// Parse and validate study text; `path` locates relative design files and names the origin.
pub fn parse_study(text: &str, path: &Path) -> Result<Study, InputError> {
    let origin = path.display().to_string();
    let doc = Document::parse(text, &origin)?;
    let file: StudyFile = toml::from_str(text).map_err(|e| doc.serde_error(&e))?;
    study_from_file(file, &doc, path)
}

/// Parse and validate the study part of a larger file: `table` is `doc`'s table without the
/// sections another reader owns (the optimiser's `[[param]]`, `[objective]`, …). Errors are
/// placed in `doc`, so they name the file's lines; the study hash is of the whole text.
pub fn parse_study_table(
    doc: &Document,
    table: &toml::Table,
    path: &Path,
) -> Result<Study, InputError> {
    let file: StudyFile = deserialize_table(table, "").map_err(|e| doc.place(e))?;
    study_from_file(file, doc, path)
}

fn study_from_file(file: StudyFile, doc: &Document, path: &Path) -> Result<Study, InputError> {
    let text = doc.text();
    let meta = &file.study;
    check_name(&meta.name, doc)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let (design, generator) = check_design(&file, dir, doc)?;
    let side = scenario_side(&file, doc)?;
    let names = valid_names(&design, generator, side.names, side.arrays, side.reference);
    let doe = parse_doe(file.doe.as_ref(), doc)?;
    let axes = parse_axes(
        file.axis.as_deref().unwrap_or_default(),
        &names,
        &design,
        doe,
        doc,
    )?;
    if side.mode.is_dynamic() {
        check_base_scenario(&design, &names.scenario_ref, &axes, doc)?;
    }
    let output = meta
        .output
        .as_ref()
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new("results/sweeps").join(&meta.name));
    let hash = study_hash(text, &design);
    let study = Study {
        path: path.to_path_buf(),
        text: text.to_string(),
        name: meta.name.clone(),
        description: meta.description.clone().unwrap_or_default(),
        seed: meta.seed.unwrap_or(0),
        output,
        design,
        generator,
        scenario: side.own,
        scenario_full: names.scenario_ref,
        mode: side.mode,
        static_enabled: side.static_enabled,
        axes,
        doe,
        report: ReportSettings {
            objective: meta.objective.clone(),
            pareto: meta.pareto.clone(),
            maximise: meta.maximise.clone().unwrap_or_default(),
        },
        hash,
        tune: file.tune.clone(),
        tuning: None,
        uncertainty: None,
        validate: Vec::new(),
        faults: None,
        ocp: super::ocp_section::parse_ocp(
            file.ocp.as_ref(),
            side.mode == StudyMode::Transport,
            doc,
        )?,
        robust_table: toml::Table::new(),
    };
    check_report(&study, doc)?;
    let mut study = study;
    study.uncertainty = parse_uncertainty(file.uncertainty.as_ref(), &study, doc)?;
    super::ocp_section::check_worlds(
        study.ocp.as_ref(),
        study.uncertainty.as_ref().map(|u| u.n_worlds()),
        doc,
    )?;
    study.validate = parse_variants(file.validate.as_deref(), &study, doc)?;
    if let (Some(i), None) = (
        study.axes.iter().position(|a| a.condition),
        &study.uncertainty,
    ) {
        return Err(doc.err(
            &format!("axis[{i}].condition"),
            "a condition axis splits the verdict over uncertain worlds, which this study has \
             not: add `[uncertainty]`, or drop `condition` (without worlds each case is \
             reported on its own)",
        ));
    }
    study.faults = parse_faults(file.faults.as_ref(), study.mode.is_dynamic(), doc)?;
    if let Some(f) = &study.faults {
        // A fault that strikes after the run ends never strikes: every design would read
        // "survives every single fault" (issue 39). Checked against the longest duration any
        // case runs (an axis over `scenario.duration` included).
        let number = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
        let base = study
            .scenario_full
            .get("scenario")
            .and_then(|t| t.get("duration"))
            .and_then(number);
        let longest = study
            .axes
            .iter()
            .filter(|a| a.name == "scenario.duration")
            .flat_map(|a| match &a.spec {
                super::schema::AxisSpec::Values(v) => v.iter().filter_map(number).collect(),
                super::schema::AxisSpec::Range { start, stop, .. } => vec![start.max(*stop)],
                super::schema::AxisSpec::Distribution(_) => vec![f64::INFINITY],
            })
            .chain(base)
            .fold(f64::NAN, f64::max);
        if longest.is_finite() && f.at >= longest {
            return Err(doc.err(
                "faults.at",
                format!(
                    "{} s is not within the run ({} s): the fault would never strike and every \
                     design would read as surviving it",
                    f.at, longest
                ),
            ));
        }
    }
    super::admit::check_values(&study, doc)?;
    study.tuning = super::tune_section::parse_tune(&study, doc)?;
    super::admit::check_tune_values(&study, doc)?;
    study.robust_table = robust_table(&file);
    Ok(study)
}

/// `[faults]`, `[ocp]`, `[uncertainty]` and `[[validate]]` as written: part of every case hash
/// (a row depends on them; the bound's columns depend on the leg, as the worlds' do).
fn robust_table(file: &StudyFile) -> toml::Table {
    let mut t = toml::Table::new();
    if let Some(f) = &file.faults {
        t.insert("faults".into(), toml::Value::Table(f.clone()));
    }
    if let Some(o) = &file.ocp {
        t.insert("ocp".into(), toml::Value::Table(o.clone()));
    }
    if let Some(u) = &file.uncertainty {
        t.insert("uncertainty".into(), toml::Value::Table(u.clone()));
    }
    if let Some(v) = &file.validate {
        let list = v.iter().cloned().map(toml::Value::Table).collect();
        t.insert("validate".into(), toml::Value::Array(list));
    }
    t
}

/// `study.objective`, `study.pareto` and `study.maximise` name metrics the cases report
/// (otherwise the report would silently rank or plot another metric).
fn check_report(study: &Study, doc: &Document) -> Result<(), InputError> {
    let r = &study.report;
    let named = r
        .objective
        .iter()
        .map(|o| (o, "study.objective".to_string()))
        .chain(
            r.pareto
                .iter()
                .flatten()
                .enumerate()
                .map(|(i, m)| (m, format!("study.pareto[{i}]"))),
        )
        .chain(
            r.maximise
                .iter()
                .enumerate()
                .map(|(i, m)| (m, format!("study.maximise[{i}]"))),
        );
    for (name, key) in named {
        if !known_metric(name, study) {
            return Err(unknown_metric(name, &key, study, doc));
        }
    }
    Ok(())
}

/// `study.name` names the output directory: non-empty, letters, digits, `_`, `-` and `.`.
fn check_name(name: &str, doc: &Document) -> Result<(), InputError> {
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
        || name.starts_with('.')
    {
        return Err(doc.err(
            "study.name",
            "must be non-empty and use only letters, digits, `_`, `-` and `.` (it names the output directory)",
        ));
    }
    Ok(())
}

/// The base design table, checked by the design parser; `(table, uses the generator)`.
fn check_design(
    file: &StudyFile,
    dir: &Path,
    doc: &Document,
) -> Result<(toml::Table, bool), InputError> {
    let (design, design_origin) = base_design(&file.design, dir, doc)?;
    let generator = design.contains_key("generator");
    if let Err(e) = parse_design_table(&design, &design_origin) {
        return Err(if file.design.contains_key("file") {
            // Re-parse the file for a positioned error.
            let f = file
                .design
                .get("file")
                .and_then(|v| v.as_str())
                .unwrap_or_default();
            match crate::model::design::load_design(&dir.join(f).display().to_string()) {
                Err(e2) => e2.into(),
                Ok(_) => e.into(),
            }
        } else {
            let key = if e.at.key.is_empty() {
                "design".to_string()
            } else {
                format!("design.{}", e.at.key)
            };
            doc.err(&key, e.error.message)
        });
    }
    Ok((design, generator))
}

/// The base scenario (the study's scenario side over the mode's defaults) run on the base
/// design must be valid, as the base design must be: otherwise every case would fail for the
/// same reason. A problem at a key some axis sets is left to the cases (the axis may fix it).
fn check_base_scenario(
    design: &toml::Table,
    reference: &toml::Table,
    axes: &[Axis],
    doc: &Document,
) -> Result<(), InputError> {
    let Ok(v) = parse_design_table(design, "design") else {
        return Ok(()); // reported by check_design
    };
    let mut sc = reference.clone();
    sc.remove(STATIC_TABLE);
    let Err(KeyError { key, message }) = runner::check_case(&v, &sc) else {
        return Ok(());
    };
    let swept = axes.iter().any(|a| match &a.target {
        Target::Scenario(p) => {
            let p = p.to_string();
            key == p || key.starts_with(&format!("{p}.")) || key.starts_with(&format!("{p}["))
        }
        Target::Design(_) => false,
    });
    if swept {
        return Ok(());
    }
    Err(doc.err(
        &key,
        format!("{message} (in the base scenario: every case would fail)"),
    ))
}

/// The scenario side of a study file, checked against the mode's defaults.
struct ScenarioSide {
    /// The study's own scenario-side tables, as written.
    own: toml::Table,
    /// Scenario mode.
    mode: StudyMode,
    /// Whether the static analysis runs.
    static_enabled: bool,
    /// The mode's defaults (with `[static]` when enabled) merged under `own`.
    reference: toml::Table,
    /// Key patterns of the defaults and of `own`, with their array patterns.
    names: BTreeSet<String>,
    arrays: BTreeSet<String>,
}

fn scenario_side(file: &StudyFile, doc: &Document) -> Result<ScenarioSide, InputError> {
    let mut own = toml::Table::new();
    for (k, t) in [
        ("scenario", &file.scenario),
        (STATIC_TABLE, &file.static_),
        ("control", &file.control),
        ("base_control", &file.base_control),
        ("allocation", &file.allocation),
        ("metrics", &file.metrics),
        ("physics", &file.physics),
        ("initial", &file.initial),
        ("path", &file.path),
        ("setpoint", &file.setpoint),
        ("reference", &file.reference),
        ("servo", &file.servo),
        ("thrusters", &file.thrusters),
        ("hydro", &file.hydro),
        ("success", &file.success),
        ("mission", &file.mission),
        ("fault", &file.fault),
        ("secondary", &file.secondary),
    ] {
        if let Some(t) = t {
            own.insert(k.into(), toml::Value::Table(t.clone()));
        }
    }
    let mode = parse_mode(file, doc)?;
    let static_enabled = mode == StudyMode::Static || file.static_.is_some();
    let mut defaults = runner::default_table(mode).map_err(|m| doc.err("scenario.mode", m))?;
    if static_enabled {
        defaults.insert(
            STATIC_TABLE.into(),
            toml::Value::Table(static_default_table()),
        );
    }
    let (mut sc_names, mut sc_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(&defaults, "", &mut sc_names, &mut sc_arrays);
    if static_enabled {
        for (k, array) in STATIC_OPTIONAL_KEYS {
            let p = format!("{STATIC_TABLE}.{k}");
            if array {
                sc_arrays.insert(p.clone());
            }
            sc_names.insert(p);
        }
    }
    // `[reference]` (work mode) has no default; its keys are checked by parsing it below.
    if mode == StudyMode::Work {
        sc_names.insert("reference".into());
        sc_arrays.insert("reference".into());
    }
    // `[fault]` (one thruster fault, `crate::scenario::fault`) has no default either; its keys
    // may be set by the study, its axes and variants (checked when a case's tables are).
    if mode.is_dynamic() {
        sc_names.insert("fault".into());
        sc_names.extend(FAULT_KEYS.iter().map(|k| format!("fault.{k}")));
    }
    // `mission.payload_volume` is optional (absent = neutral buoyancy), so not in the defaults.
    if mode.is_dynamic() {
        sc_names.insert("mission.payload_volume".into());
    }
    // Reject unknown keys of the study's own scenario-side tables.
    let (mut own_names, mut own_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(&own, "", &mut own_names, &mut own_arrays);
    if let Some(p) = own_names
        .iter()
        .find(|p| !pattern_allowed(p, &sc_names, &sc_arrays))
    {
        return Err(unknown_scenario_key(p, mode, &sc_names, doc));
    }
    let mut reference = defaults;
    merge_into(&mut reference, &own);
    // `control.method` picks its own Table III row: the defaults above are Method 2's.
    if let Some(c) = runner::method_control(mode, own.get("control")) {
        let c = c.map_err(|m| doc.err("control", m))?;
        reference.insert("control".into(), toml::Value::Table(c));
    }
    // The success criteria of the base must parse and hold (dynamic modes).
    if mode.is_dynamic() {
        runner::check_success(&reference).map_err(|e| doc.place(e))?;
        crate::scenario::target::check_reference(&reference).map_err(|e| doc.place(e))?;
    }
    // Static settings of the base must parse.
    if static_enabled {
        if let Err(m) = static_spec(&reference, 0) {
            return Err(doc.err(STATIC_TABLE, m.to_string()));
        }
        if let Err(m) = authority_spec(&reference) {
            let key = m
                .key()
                .map_or(STATIC_TABLE.to_string(), |k| format!("{STATIC_TABLE}.{k}"));
            return Err(doc.err(&key, m.to_string()));
        }
    }
    Ok(ScenarioSide {
        own,
        mode,
        static_enabled,
        reference,
        names: sc_names.union(&own_names).cloned().collect(),
        arrays: sc_arrays.union(&own_arrays).cloned().collect(),
    })
}

/// `scenario.mode` (default `static`).
fn parse_mode(file: &StudyFile, doc: &Document) -> Result<StudyMode, InputError> {
    let Some(v) = file.scenario.as_ref().and_then(|s| s.get("mode")) else {
        return Ok(StudyMode::Static);
    };
    if let Some(m) = v.as_str().and_then(|m| m.parse::<StudyMode>().ok()) {
        return Ok(m);
    }
    Err(doc.err(
        "scenario.mode",
        format!(
            "must be one of {}, got {v}",
            StudyMode::ALL
                .iter()
                .map(|m| format!("\"{m}\""))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ))
}

/// The error for an unknown scenario-side key `p`, listing its valid siblings.
fn unknown_scenario_key(
    p: &str,
    mode: StudyMode,
    valid: &BTreeSet<String>,
    doc: &Document,
) -> InputError {
    let parent = p.rfind('.').map_or("", |i| &p[..i]);
    let siblings: Vec<String> = valid
        .iter()
        .filter(|n| n.rfind('.').map_or("", |i| &n[..i]) == parent && !n.contains("[]"))
        .map(|n| n.rsplit('.').next().unwrap_or(n).to_string())
        .collect();
    doc.err(
        p,
        format!(
            "unknown key for scenario mode \"{mode}\"; valid keys here: {}",
            if siblings.is_empty() {
                "(none)".to_string()
            } else {
                siblings.join(", ")
            }
        ),
    )
}

/// `[doe]` (default: grid).
fn parse_doe(d: Option<&DoeFile>, doc: &Document) -> Result<Doe, InputError> {
    let Some(d) = d else {
        return Ok(Doe::Grid);
    };
    let kind: DoeKind = d.kind.parse().map_err(|m| doc.err("doe.kind", m))?;
    match kind.sampling() {
        None => {
            if d.cases.is_some() {
                return Err(doc.err("doe.cases", "only for sampled designs (random, lhs, sobol)"));
            }
            Ok(Doe::Grid)
        }
        Some(kind) => {
            let cases = d
                .cases
                .ok_or_else(|| doc.err("doe", "sampled designs need `cases = N`"))?;
            if cases == 0 || cases > MAX_CASES {
                return Err(doc.err("doe.cases", format!("must be in 1..={MAX_CASES}")));
            }
            Ok(Doe::Sampled { kind, cases })
        }
    }
}

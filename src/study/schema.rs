//! The study file (TOML): parsing, validation against the valid parameter names, and the
//! validated [`Study`]. The format is documented in `docs/study-format.md`.
//!
//! Every error names the file, the 1-based line and column when known, and the key
//! (`axis[2].name`). `deny_unknown_fields` everywhere; no `serde(flatten)`.

use crate::input::located::{line_col, one_line, Located, Location};
use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::runner;
use crate::input::keypath::{display_pattern, flatten, pattern_allowed, KeyPath, Seg};
use crate::model::design::{load_design_table, parse_design_table, DesignError};
use crate::sampling::{Sampling, MAX_SOBOL_DIMS};

/// A problem with the study file or the command line (exit code 2).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct InputError {
    /// File (or other origin) of the problem.
    pub origin: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// 1-based column, when known.
    pub column: Option<usize>,
    /// Key path, e.g. `axis[2].name`; empty when none.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = Location {
            origin: self.origin.clone(),
            line: self.line,
            column: self.column,
            key: self.key.clone(),
        };
        Located {
            at,
            error: &self.message,
        }
        .fmt(f)
    }
}

impl From<DesignError> for InputError {
    fn from(e: DesignError) -> Self {
        InputError {
            origin: e.at.origin,
            line: e.at.line,
            column: e.at.column,
            key: e.at.key,
            message: e.error.message,
        }
    }
}

// ---------------------------------------------------------------------------------------
// Span index
// ---------------------------------------------------------------------------------------

/// Key paths of a document with their positions: a line scanner over table headers
/// (`[a.b]`, `[[a]]` with array indices) and `key = value` lines. Keys inside inline tables
/// and multi-line values resolve to their parent's line.
pub(crate) struct Spans {
    origin: String,
    text: String,
    /// `(path, byte offset of the key)`.
    entries: Vec<(String, usize)>,
}

fn strip_key(k: &str) -> String {
    k.split('.')
        .map(|p| p.trim().trim_matches('"').trim_matches('\''))
        .collect::<Vec<_>>()
        .join(".")
}

impl Spans {
    pub(crate) fn parse(text: &str, origin: &str) -> Result<Spans, InputError> {
        let mut s = Spans {
            origin: origin.to_string(),
            text: text.to_string(),
            entries: Vec::new(),
        };
        if let Err(e) = toml::from_str::<toml::Table>(text) {
            return Err(s.at_offset(
                e.span().map(|r| r.start),
                "",
                format!("TOML syntax error: {}", one_line(e.message())),
            ));
        }
        s.scan();
        Ok(s)
    }

    fn scan(&mut self) {
        let mut header = String::new();
        let mut arrays: std::collections::HashMap<String, usize> = Default::default();
        let mut depth: i64 = 0;
        let mut offset = 0usize;
        let translate = |name: &str, arrays: &std::collections::HashMap<String, usize>| {
            let mut out = String::new();
            let mut plain = String::new();
            for part in name.split('.') {
                if !plain.is_empty() {
                    plain.push('.');
                    out.push('.');
                }
                plain.push_str(part);
                out.push_str(part);
                if let Some(i) = arrays.get(&plain) {
                    out.push_str(&format!("[{i}]"));
                }
            }
            out
        };
        for line in self.text.split_inclusive('\n') {
            let start = offset;
            offset += line.len();
            let code = line.split('#').next().unwrap_or("");
            if depth > 0 {
                depth += code.matches(['[', '{']).count() as i64
                    - code.matches([']', '}']).count() as i64;
                continue;
            }
            let t = code.trim_start();
            let lead = code.len() - t.len();
            let t = t.trim_end();
            if t.is_empty() {
                continue;
            }
            if let Some(name) = t.strip_prefix("[[").and_then(|r| r.strip_suffix("]]")) {
                let name = strip_key(name);
                let base = translate(&name, &arrays);
                let base = base
                    .strip_suffix(&format!("[{}]", arrays.get(&name).copied().unwrap_or(0)))
                    .map(str::to_string)
                    .unwrap_or(base);
                let idx = arrays
                    .entry(name.clone())
                    .and_modify(|i| *i += 1)
                    .or_insert(0);
                header = format!("{base}[{idx}]");
                self.entries.push((header.clone(), start + lead));
                continue;
            }
            if let Some(name) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
                header = translate(&strip_key(name), &arrays);
                self.entries.push((header.clone(), start + lead));
                continue;
            }
            if let Some((k, v)) = t.split_once('=') {
                let key = strip_key(k);
                let path = if header.is_empty() {
                    key
                } else {
                    format!("{header}.{key}")
                };
                self.entries.push((path, start + lead));
                depth +=
                    v.matches(['[', '{']).count() as i64 - v.matches([']', '}']).count() as i64;
                depth = depth.max(0);
            }
        }
    }

    fn at_offset(&self, offset: Option<usize>, key: &str, message: String) -> InputError {
        let (line, column) = match offset {
            Some(o) => {
                let (l, c) = line_col(&self.text, o);
                (Some(l), Some(c))
            }
            None => (None, None),
        };
        InputError {
            origin: self.origin.clone(),
            line,
            column,
            key: key.to_string(),
            message,
        }
    }

    /// An error at `key` (positioned at the key or its nearest ancestor in the document).
    pub(crate) fn err(&self, key: &str, message: impl Into<String>) -> InputError {
        let mut p = key;
        let offset = loop {
            if let Some(e) = self.entries.iter().find(|e| e.0 == p) {
                break Some(e.1);
            }
            match p.rfind(['.', '[']) {
                Some(i) => p = &p[..i],
                None => break None,
            }
        };
        self.at_offset(offset, key, message.into())
    }

    /// A serde error: positioned by its span, keyed by the last entry starting at or before it.
    fn serde(&self, e: &toml::de::Error) -> InputError {
        let offset = e.span().map(|s| s.start);
        let key = offset
            .and_then(|o| {
                self.entries
                    .iter()
                    .filter(|(_, s)| *s <= o)
                    .max_by_key(|(_, s)| *s)
                    .map(|(p, _)| p.clone())
            })
            .unwrap_or_default();
        self.at_offset(offset, &key, one_line(e.message()))
    }
}

// ---------------------------------------------------------------------------------------
// File schema
// ---------------------------------------------------------------------------------------

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
    servo: Option<toml::Table>,
    thrusters: Option<toml::Table>,
    axis: Option<Vec<AxisFile>>,
    doe: Option<DoeFile>,
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
struct AxisFile {
    name: String,
    values: Option<Vec<toml::Value>>,
    range: Option<RangeFile>,
    distribution: Option<DistFile>,
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

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DoeFile {
    kind: String,
    cases: Option<usize>,
}

// ---------------------------------------------------------------------------------------
// Validated study
// ---------------------------------------------------------------------------------------

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

/// Which table an axis edits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// A key of the design table (path relative to the design table, aliases resolved).
    Design(KeyPath),
    /// A key of the scenario-side table (`scenario`, `static`, `control`, …).
    Scenario(KeyPath),
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
    pub mode: String,
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
}

/// Keys of the design generator table (design-file schema); `design.<key>` is an alias of
/// `design.generator.<key>` when the base design uses the generator.
pub const GENERATOR_KEYS: [&str; 13] = [
    "links",
    "link_length",
    "link_mass",
    "radius",
    "module_length",
    "module_mass",
    "joint_limit_deg",
    "thruster_rule",
    "thrust_limit",
    "longitudinal_offset",
    "cd_axial_ends",
    "cd_axial",
    "cd_cross",
];

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

/// Whether `key` is a scenario-side top-level table (including `static`).
pub fn is_scenario_table(key: &str) -> bool {
    key == "static" || runner::SCENARIO_TABLES.contains(&key)
}

/// Defaults of the `[static]` table (`char_length = 0`: half the vehicle length, or
/// `metrics.char_length` when that is > 0).
pub fn static_default_table() -> toml::Table {
    let mut t = toml::Table::new();
    t.insert("samples".into(), toml::Value::Integer(256));
    t.insert(
        "threshold".into(),
        toml::Value::Float(super::static_tcm::DEFAULT_THRESHOLD),
    );
    t.insert("sampling".into(), toml::Value::String("sobol".into()));
    t.insert("char_length".into(), toml::Value::Float(0.0));
    t.insert(
        "rank_rel_tol".into(),
        toml::Value::Float(crate::metrics::singularity::DEFAULT_RANK_REL_TOL),
    );
    t
}

/// Valid parameter names: patterns, array patterns, and the reference table per side.
pub(crate) struct Names {
    design: BTreeSet<String>,
    design_arrays: BTreeSet<String>,
    scenario: BTreeSet<String>,
    scenario_arrays: BTreeSet<String>,
    /// Scenario defaults merged under the study's own values (reference types).
    scenario_ref: toml::Table,
    generator: bool,
}

impl Names {
    fn list(&self) -> String {
        let mut v: Vec<String> = self
            .design
            .iter()
            .map(|p| format!("design.{}", display_pattern(p)))
            .collect();
        if self.generator {
            v.extend(GENERATOR_KEYS.iter().map(|k| format!("design.{k} (alias)")));
        }
        v.extend(self.scenario.iter().map(|p| display_pattern(p)));
        v.join(", ")
    }
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
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| InputError {
        origin: origin.clone(),
        line: None,
        column: None,
        key: String::new(),
        message: format!("cannot read the study file: {e}"),
    })?;
    parse_study(&text, path)
}

/// Parse and validate study text; `path` locates relative design files and names the origin.
pub fn parse_study(text: &str, path: &Path) -> Result<Study, InputError> {
    let origin = path.display().to_string();
    let spans = Spans::parse(text, &origin)?;
    let file: StudyFile = toml::from_str(text).map_err(|e| spans.serde(&e))?;
    let meta = &file.study;
    if meta.name.is_empty()
        || !meta
            .name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c))
        || meta.name.starts_with('.')
    {
        return Err(spans.err(
            "study.name",
            "must be non-empty and use only letters, digits, `_`, `-` and `.` (it names the output directory)",
        ));
    }

    // ---- design
    let dir = path.parent().unwrap_or(Path::new(""));
    let (design, design_origin) = base_design(&file.design, dir, &spans)?;
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
            spans.err(&key, e.error.message)
        });
    }

    // ---- scenario side
    let mut scenario = toml::Table::new();
    for (k, t) in [
        ("scenario", &file.scenario),
        ("static", &file.static_),
        ("control", &file.control),
        ("base_control", &file.base_control),
        ("allocation", &file.allocation),
        ("metrics", &file.metrics),
        ("physics", &file.physics),
        ("initial", &file.initial),
        ("path", &file.path),
        ("setpoint", &file.setpoint),
        ("servo", &file.servo),
        ("thrusters", &file.thrusters),
    ] {
        if let Some(t) = t {
            scenario.insert(k.into(), toml::Value::Table(t.clone()));
        }
    }
    let mode = match file.scenario.as_ref().and_then(|s| s.get("mode")) {
        None => "static".to_string(),
        Some(toml::Value::String(m)) if runner::MODES.contains(&m.as_str()) => m.clone(),
        Some(other) => {
            return Err(spans.err(
                "scenario.mode",
                format!(
                    "must be one of {}, got {other}",
                    runner::MODES
                        .iter()
                        .map(|m| format!("\"{m}\""))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ))
        }
    };
    let static_enabled = mode == "static" || file.static_.is_some();
    let mut defaults = runner::default_table(&mode).map_err(|m| spans.err("scenario.mode", m))?;
    if static_enabled {
        defaults.insert("static".into(), toml::Value::Table(static_default_table()));
    }
    let (mut sc_names, mut sc_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(&defaults, "", &mut sc_names, &mut sc_arrays);
    // Reject unknown keys of the study's own scenario-side tables.
    let (mut own, mut own_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(&scenario, "", &mut own, &mut own_arrays);
    for p in &own {
        if !pattern_allowed(p, &sc_names, &sc_arrays) {
            let parent = p.rfind('.').map_or("", |i| &p[..i]);
            let siblings: Vec<String> = sc_names
                .iter()
                .filter(|n| n.rfind('.').map_or("", |i| &n[..i]) == parent && !n.contains("[]"))
                .map(|n| n.rsplit('.').next().unwrap_or(n).to_string())
                .collect();
            return Err(spans.err(
                p,
                format!(
                    "unknown key for scenario mode \"{mode}\"; valid keys here: {}",
                    if siblings.is_empty() {
                        "(none)".to_string()
                    } else {
                        siblings.join(", ")
                    }
                ),
            ));
        }
    }
    let mut scenario_ref = defaults;
    merge_into(&mut scenario_ref, &scenario);
    // Static settings of the base must parse.
    if static_enabled {
        if let Err(m) = super::engine::static_spec(&scenario_ref, 0) {
            return Err(spans.err("static", m));
        }
    }

    // ---- valid names
    let (mut d_names, mut d_arrays) = (BTreeSet::new(), BTreeSet::new());
    flatten(&design, "", &mut d_names, &mut d_arrays);
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
    let names = Names {
        design: d_names,
        design_arrays: d_arrays,
        scenario: sc_names.union(&own).cloned().collect(),
        scenario_arrays: sc_arrays.union(&own_arrays).cloned().collect(),
        scenario_ref,
        generator,
    };

    // ---- axes
    let doe = match &file.doe {
        None => Doe::Grid,
        Some(d) => match d.kind.as_str() {
            "grid" => {
                if d.cases.is_some() {
                    return Err(
                        spans.err("doe.cases", "only for sampled designs (random, lhs, sobol)")
                    );
                }
                Doe::Grid
            }
            k => {
                let kind: Sampling = k.parse().map_err(|_| {
                    spans.err(
                        "doe.kind",
                        format!("unknown kind '{k}'; valid: grid, random, lhs, sobol"),
                    )
                })?;
                let cases = d
                    .cases
                    .ok_or_else(|| spans.err("doe", "sampled designs need `cases = N`"))?;
                if cases == 0 || cases > MAX_CASES {
                    return Err(spans.err("doe.cases", format!("must be in 1..={MAX_CASES}")));
                }
                Doe::Sampled { kind, cases }
            }
        },
    };
    let mut axes = Vec::new();
    for (i, a) in file.axis.iter().flatten().enumerate() {
        let axis = validate_axis(a, i, &names, &design, doe, &spans)?;
        if axes.iter().any(|b: &Axis| b.name == axis.name) {
            return Err(spans.err(&format!("axis[{i}].name"), "duplicate axis name"));
        }
        axes.push(axis);
    }
    if let Doe::Sampled { kind, .. } = doe {
        if kind == Sampling::Sobol && axes.len() > MAX_SOBOL_DIMS {
            return Err(spans.err(
                "doe.kind",
                format!("sobol supports at most {MAX_SOBOL_DIMS} axes"),
            ));
        }
    }
    if doe == Doe::Grid {
        let mut n: usize = 1;
        for a in &axes {
            n = n.saturating_mul(super::doe::grid_len(&a.spec));
        }
        if n > MAX_CASES {
            return Err(spans.err(
                "axis",
                format!("the grid has {n} cases, more than {MAX_CASES}"),
            ));
        }
    }

    let output = meta
        .output
        .as_ref()
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new("results/sweeps").join(&meta.name));
    let hash = study_hash(text, &design);
    let scenario_full = names.scenario_ref.clone();
    Ok(Study {
        path: path.to_path_buf(),
        text: text.to_string(),
        name: meta.name.clone(),
        description: meta.description.clone().unwrap_or_default(),
        seed: meta.seed.unwrap_or(0),
        output,
        design,
        generator,
        scenario,
        scenario_full,
        mode,
        static_enabled,
        axes,
        doe,
        report: ReportSettings {
            objective: meta.objective.clone(),
            pareto: meta.pareto.clone(),
            maximise: meta.maximise.clone().unwrap_or_default(),
        },
        hash,
    })
}

/// Largest number of cases of a study.
pub const MAX_CASES: usize = 10_000_000;

fn base_design(
    d: &toml::Table,
    dir: &Path,
    spans: &Spans,
) -> Result<(toml::Table, String), InputError> {
    if let Some(f) = d.get("file") {
        if let Some(k) = d.keys().find(|k| *k != "file") {
            return Err(spans.err(
                &format!("design.{k}"),
                "cannot be combined with `design.file`",
            ));
        }
        let f = f.as_str().ok_or_else(|| {
            spans.err(
                "design.file",
                "must be a string (a path relative to the study file)",
            )
        })?;
        let p = dir.join(f);
        let arg = p.display().to_string();
        if !p.is_file() {
            return Err(spans.err("design.file", format!("no design file {arg}")));
        }
        let t = load_design_table(&arg).map_err(InputError::from)?;
        return Ok((t, arg));
    }
    if let Some(p) = d.get("preset") {
        if let Some(k) = d.keys().find(|k| *k != "preset" && *k != "name") {
            return Err(spans.err(
                &format!("design.{k}"),
                "not allowed with `design.preset` (only `name`); sweep axes may still edit the \
                 preset's keys, e.g. design.thruster[2].position",
            ));
        }
        let p = p
            .as_str()
            .ok_or_else(|| spans.err("design.preset", "must be a string"))?;
        let mut t =
            load_design_table(p).map_err(|e| spans.err("design.preset", e.error.message))?;
        if let Some(n) = d.get("name") {
            t.insert("name".into(), n.clone());
        }
        return Ok((t, format!("preset {p}")));
    }
    let mut t = d.clone();
    if !t.contains_key("name") {
        t.insert("name".into(), toml::Value::String("design".into()));
    }
    Ok((t, format!("{} [design]", spans.origin)))
}

fn validate_axis(
    a: &AxisFile,
    i: usize,
    names: &Names,
    design: &toml::Table,
    doe: Doe,
    spans: &Spans,
) -> Result<Axis, InputError> {
    let key = |f: &str| format!("axis[{i}].{f}");
    let path = KeyPath::parse(&a.name).map_err(|m| spans.err(&key("name"), m))?;
    let unknown = || {
        spans.err(
            &key("name"),
            format!(
                "unknown parameter `{}`; valid names: {}",
                a.name,
                names.list()
            ),
        )
    };
    let (target, reference) = if path.head() == "design" {
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
            return Err(unknown());
        }
        let reference = crate::input::keypath::get(design, &rest.0)
            .cloned()
            .or_else(|| (rest.pattern() == "generator.links").then_some(toml::Value::Integer(5)));
        (Target::Design(rest), reference)
    } else if is_scenario_table(path.head()) {
        if !pattern_allowed(&path.pattern(), &names.scenario, &names.scenario_arrays) {
            return Err(unknown());
        }
        let reference = crate::input::keypath::get(&names.scenario_ref, &path.0).cloned();
        (Target::Scenario(path.clone()), reference)
    } else {
        return Err(unknown());
    };
    let integer = matches!(reference, Some(toml::Value::Integer(_)));
    let given = [
        a.values.is_some(),
        a.range.is_some(),
        a.distribution.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err(spans.err(
            &format!("axis[{i}]"),
            "needs exactly one of `values = [...]`, `range = { start, stop, steps }` or `distribution = { kind, ... }`",
        ));
    }
    let spec = if let Some(v) = &a.values {
        if v.is_empty() {
            return Err(spans.err(&key("values"), "needs at least one value"));
        }
        if let Some(j) = v
            .iter()
            .position(|x| matches!(x, toml::Value::Float(f) if !f.is_finite()))
        {
            return Err(spans.err(&format!("axis[{i}].values[{j}]"), "must be finite"));
        }
        AxisSpec::Values(v.clone())
    } else if let Some(r) = &a.range {
        if !(r.start.is_finite() && r.stop.is_finite()) {
            return Err(spans.err(&key("range"), "start and stop must be finite"));
        }
        let log = r.log.unwrap_or(false);
        if log && !(r.start > 0.0 && r.stop > 0.0) {
            return Err(spans.err(&key("range.log"), "a log range needs start, stop > 0"));
        }
        match (doe, r.steps) {
            (Doe::Grid, None) => {
                return Err(spans.err(&key("range"), "grid designs need `steps` (>= 1)"))
            }
            (_, Some(0)) => return Err(spans.err(&key("range.steps"), "must be >= 1")),
            _ => {}
        }
        AxisSpec::Range {
            start: r.start,
            stop: r.stop,
            steps: r.steps,
            log,
        }
    } else {
        let d = a.distribution.as_ref().ok_or_else(unknown)?;
        if doe == Doe::Grid {
            return Err(spans.err(
                &key("distribution"),
                "distributions need a sampled design ([doe] kind = \"random\" | \"lhs\" | \"sobol\")",
            ));
        }
        let dk = |f: &str| format!("axis[{i}].distribution.{f}");
        let need = |v: Option<f64>, f: &str| {
            v.filter(|x| x.is_finite())
                .ok_or_else(|| spans.err(&dk(f), format!("`{f}` is required and must be finite")))
        };
        let forbid = |v: Option<f64>, f: &str| match v {
            Some(_) => Err(spans.err(&dk(f), format!("not a parameter of kind \"{}\"", d.kind))),
            None => Ok(()),
        };
        let dist = match d.kind.as_str() {
            "uniform" | "loguniform" => {
                forbid(d.mean, "mean")?;
                forbid(d.std, "std")?;
                let (lo, hi) = (need(d.low, "low")?, need(d.high, "high")?);
                if lo >= hi {
                    return Err(spans.err(&dk("high"), "needs low < high"));
                }
                if d.kind == "uniform" {
                    Dist::Uniform(lo, hi)
                } else {
                    if lo <= 0.0 {
                        return Err(spans.err(&dk("low"), "loguniform needs low > 0"));
                    }
                    Dist::LogUniform(lo, hi)
                }
            }
            "normal" => {
                forbid(d.low, "low")?;
                forbid(d.high, "high")?;
                let (m, s) = (need(d.mean, "mean")?, need(d.std, "std")?);
                if s <= 0.0 {
                    return Err(spans.err(&dk("std"), "must be > 0"));
                }
                Dist::Normal(m, s)
            }
            other => {
                return Err(spans.err(
                    &dk("kind"),
                    format!("unknown distribution '{other}'; valid: uniform, loguniform, normal"),
                ))
            }
        };
        AxisSpec::Distribution(dist)
    };
    let numeric = match &spec {
        AxisSpec::Values(v) => v
            .iter()
            .all(|x| matches!(x, toml::Value::Integer(_) | toml::Value::Float(_))),
        _ => true,
    };
    Ok(Axis {
        name: a.name.clone(),
        target,
        spec,
        numeric,
        integer,
    })
}

/// SHA-256 (hex) of the study text, the canonical base design and the tool version.
fn study_hash(text: &str, design: &toml::Table) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    h.update(b"usm-study study v1\0");
    h.update(env!("CARGO_PKG_VERSION").as_bytes());
    h.update([0]);
    h.update(text.as_bytes());
    h.update([0]);
    let mut buf = String::new();
    super::engine::canonical_table(design, &mut buf);
    h.update(buf.as_bytes());
    hex(&h.finalize())
}

/// Lower-case hex of bytes.
pub(crate) fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_locate_keys() {
        let text = "[study]\nname = \"a\"\n\n[[axis]]\nname = \"x\"\nvalues = [1, 2]\n\n[[axis]]\nname = \"y\"\nrange = { start = 0.1, stop = 0.2, steps = 2 }\n\n[[axis]]\nname = \"z\"\n";
        let s = Spans::parse(text, "f.toml").unwrap();
        let e = s.err("axis[2].name", "m");
        assert_eq!((e.line, e.column), (Some(13), Some(1)), "{:?}", s.entries);
        let e = s.err("axis[1].range.steps", "m");
        assert_eq!(e.line, Some(10));
    }
}

//! The `[static]` table of study files ↔ [`StaticSpec`]: the table of defaults the schema
//! offers as axis names, and the settings of a resolved case. Every default comes from
//! [`StaticSpec::default`], so a study file and `usm-study tcm` agree.

use serde::Deserialize;

use crate::sampling::Sampling;
use crate::scenario::config::{Mode, ScenarioFile};
use crate::statics::{AuthorityReference, AuthoritySpec, JointRanges, StaticSpec};

/// The key of the `[static]` table in study files and resolved scenario-side tables.
pub const STATIC_TABLE: &str = "static";

/// The keys of `[static]`, all optional.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StaticFile {
    samples: Option<usize>,
    threshold: Option<f64>,
    sampling: Option<String>,
    char_length: Option<f64>,
    rank_rel_tol: Option<f64>,
    mode: Option<Mode>,
    authority_reference: Option<ReferenceFile>,
    joint_range: Option<f64>,
    joint_ranges: Option<Vec<[f64; 2]>>,
    n1_samples: Option<usize>,
}

/// `static.authority_reference`: a name or a point.
#[derive(Deserialize)]
#[serde(untagged)]
enum ReferenceFile {
    Name(String),
    Point([f64; 3]),
}

/// The keys of `[static]` that have no entry in [`static_default_table`] (so that the case
/// hashes of studies without them stay as they were), with whether each may be an array: the
/// study parser accepts them beside the defaults.
pub const STATIC_OPTIONAL_KEYS: [(&str, bool); 4] = [
    ("authority_reference", true),
    ("joint_range", false),
    ("joint_ranges", true),
    ("n1_samples", false),
];

/// Defaults of the `[static]` table, from [`StaticSpec::default`] (`char_length = 0`: half
/// the vehicle length, or `metrics.char_length` when that is > 0).
pub fn static_default_table() -> toml::Table {
    let d = StaticSpec::default();
    let mut t = toml::Table::new();
    t.insert("samples".into(), toml::Value::Integer(d.samples as i64));
    t.insert("threshold".into(), toml::Value::Float(d.threshold));
    t.insert(
        "sampling".into(),
        toml::Value::String(d.sampling.to_string()),
    );
    t.insert(
        "char_length".into(),
        toml::Value::Float(d.char_length.unwrap_or(0.0)),
    );
    t.insert("rank_rel_tol".into(), toml::Value::Float(d.rank_rel_tol));
    t.insert("mode".into(), toml::Value::String(d.mode.to_string()));
    t
}

/// The closed-loop mode of a resolved scenario-side table (`[scenario] mode`), if it is one.
fn scenario_mode(scenario: &toml::Table) -> Option<Mode> {
    let m = scenario.get("scenario")?.get("mode")?.as_str()?;
    toml::Value::String(m.into()).try_into().ok()
}

/// The axes commanded in `mode`: those of the study's own scenario when it runs that mode
/// (its `[control]` and `[base_control]` gains, [`ScenarioFile::commanded_dofs`]), else the
/// mode's default controller's ([`Mode::default_commanded_dofs`]).
fn commanded_in(scenario: &toml::Table, mode: Mode) -> crate::metrics::singularity::CommandedDofs {
    let own = (scenario_mode(scenario) == Some(mode))
        .then(|| {
            let mut sc = scenario.clone();
            sc.remove(STATIC_TABLE);
            toml::Value::Table(sc).try_into::<ScenarioFile>().ok()
        })
        .flatten()
        .and_then(|f| f.commanded_dofs().ok());
    own.unwrap_or_else(|| mode.default_commanded_dofs())
}

/// The static-analysis settings of a resolved scenario-side table (`[static]`, with
/// `metrics.char_length` as the fallback characteristic length and `metrics.threshold` as the
/// fallback threshold), seeded with `seed`. The commanded axes are those of `static.mode`
/// (default: the study's closed-loop mode, else transport). No configurations are kept
/// (`worst = 0`): sweeps record only the aggregate metrics.
pub fn static_spec(scenario: &toml::Table, seed: u64) -> Result<StaticSpec, StaticTableError> {
    let t = scenario
        .get(STATIC_TABLE)
        .cloned()
        .unwrap_or(toml::Value::Table(toml::Table::new()));
    let f = StaticFile::deserialize(t).map_err(StaticTableError::Table)?;
    let d = StaticSpec::default();
    let sampling: Sampling = match &f.sampling {
        Some(s) => s.parse().map_err(StaticTableError::Sampling)?,
        None => d.sampling,
    };
    let metrics_l = scenario
        .get("metrics")
        .and_then(|m| m.get("char_length"))
        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
        .filter(|l| *l > 0.0);
    let char_length = match f.char_length {
        Some(l) if l != 0.0 => Some(l),
        _ => metrics_l,
    };
    let metrics_threshold = scenario
        .get("metrics")
        .and_then(|m| m.get("threshold"))
        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)));
    let mode = f.mode.or(scenario_mode(scenario)).unwrap_or(d.mode);
    let spec = StaticSpec {
        samples: f.samples.unwrap_or(d.samples),
        seed,
        threshold: f.threshold.or(metrics_threshold).unwrap_or(d.threshold),
        sampling,
        char_length,
        rank_rel_tol: f.rank_rel_tol.unwrap_or(d.rank_rel_tol),
        worst: 0,
        mode,
        commanded: commanded_in(scenario, mode),
    };
    spec.validate().map_err(StaticTableError::Setting)?;
    if spec.samples > MAX_CASE_SAMPLES {
        return Err(StaticTableError::TooManySamples {
            samples: spec.samples,
        });
    }
    Ok(spec)
}

/// The authority settings of a resolved scenario-side table (`[static]` keys
/// `authority_reference` = `"com"` | `"base"` | `[x, y, z]` (m, base frame), `joint_range` (rad,
/// `±r` on every joint) or `joint_ranges` (`[[lo, hi], …]` rad, one per joint), `n1_samples`),
/// defaults from [`AuthoritySpec::default`].
pub fn authority_spec(scenario: &toml::Table) -> Result<AuthoritySpec, StaticTableError> {
    let t = scenario
        .get(STATIC_TABLE)
        .cloned()
        .unwrap_or(toml::Value::Table(toml::Table::new()));
    let f = StaticFile::deserialize(t).map_err(StaticTableError::Table)?;
    let d = AuthoritySpec::default();
    let reference = match f.authority_reference {
        None => d.reference,
        Some(ReferenceFile::Name(n)) if n == "com" => AuthorityReference::Com,
        Some(ReferenceFile::Name(n)) if n == "base" => AuthorityReference::Base,
        Some(ReferenceFile::Name(n)) => {
            return Err(StaticTableError::Authority {
                key: "authority_reference",
                message: format!("`{n}` is none of \"com\", \"base\" or [x, y, z] (m)"),
            })
        }
        Some(ReferenceFile::Point(p)) if p.iter().all(|x| x.is_finite()) => {
            AuthorityReference::Point(p)
        }
        Some(ReferenceFile::Point(p)) => {
            return Err(StaticTableError::Authority {
                key: "authority_reference",
                message: format!("{p:?} is not a finite point"),
            })
        }
    };
    let mission = match (f.joint_range, f.joint_ranges) {
        (Some(_), Some(_)) => {
            return Err(StaticTableError::Authority {
                key: "joint_ranges",
                message: "give `joint_range` or `joint_ranges`, not both".into(),
            })
        }
        (Some(r), None) => Some(JointRanges::Symmetric(r)),
        (None, Some(r)) => Some(JointRanges::PerJoint(r)),
        (None, None) => None,
    };
    if let Some(m) = &mission {
        m.validate().map_err(StaticTableError::Setting)?;
    }
    Ok(AuthoritySpec {
        reference,
        mission,
        n1_samples: f.n1_samples.unwrap_or(d.n1_samples),
    })
}

/// Why a `[static]` table does not give static-analysis settings (the study parser places it
/// at the table's line; a sweep case whose overrides break it is skipped with this reason).
#[derive(Debug, thiserror::Error)]
pub enum StaticTableError {
    /// The table does not deserialise (an unknown key, a wrong type).
    #[error("[static]: {}", .0.message().trim())]
    Table(#[source] toml::de::Error),
    /// `static.sampling` names no sampling method.
    #[error("static.sampling: {0}")]
    Sampling(#[source] crate::sampling::UnknownSampling),
    /// A setting is out of range.
    #[error("{0}")]
    Setting(#[source] crate::statics::StaticError),
    /// An authority setting is not usable.
    #[error("static.{key}: {message}")]
    Authority {
        /// The key in `[static]`.
        key: &'static str,
        /// What is wrong.
        message: String,
    },
    /// More samples per case than a worker may keep.
    #[error(
        "static.samples: {samples} samples per case would keep {:.1} GB of per-sample values \
         (σ_min and κ, for exact quantiles); at most {MAX_CASE_SAMPLES} per case",
        *samples as f64 * 16.0 / 1e9
    )]
    TooManySamples {
        /// The samples asked for.
        samples: usize,
    },
}

impl StaticTableError {
    /// The `[static]` key the error is about, when it is one key.
    pub fn key(&self) -> Option<&'static str> {
        match self {
            Self::Authority { key, .. } => Some(key),
            Self::Setting(crate::statics::StaticError::Setting { key, .. }) => Some(key),
            _ => None,
        }
    }
}

/// Most static samples of one sweep case: 16 bytes each are kept (σ_min and κ), 160 MB at the
/// cap, per worker thread.
pub const MAX_CASE_SAMPLES: usize = 10_000_000;

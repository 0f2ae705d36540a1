//! One thrust-allocation case (docs/model.md §5, USM-36/37) read from a JSON case file, validated and
//! solved with one or more methods; the results serialise as the JSON of `usm-study allocate`.
//!
//! The case file is JSON with these keys (unknown keys are rejected):
//!
//! | key | shape | meaning | default |
//! |---|---|---|---|
//! | `T` | [6][m] | thruster configuration matrix, rows force x, y, z (N/N) then moment x, y, z (N·m/N), base frame | required |
//! | `tau` | [6] | commanded wrench (N, N·m), base frame | required |
//! | `u_min`, `u_max` | [m] | thrust bounds (N) | −40, +40 |
//! | `weights` | [m] | usage weights `W = diag(w)`, > 0 | 1 |
//! | `lambda` | number | pinv damping λ (USM-37) | 0.1 |
//! | `q` | number | slack weight | 1e4 |
//! | `eps` | number | minimax regularisation ε | 1e-6 |
//! | `u_prev` | [m] | previous thrust (N) for the rate terms | 0 |
//! | `rate_weights` | [m] | rate weights `R = diag(r)` (`‖u − u_prev‖²_R`), ≥ 0 | 0 (when `rate_limit` is set) |
//! | `rate_limit` | [m] | step limit `Δu` (N): `|u − u_prev| ≤ Δu`, > 0 | none (when `rate_weights` is set) |
//!
//! The rate terms apply to `qp`, `minimax` and `power` and are active when either `rate_weights`
//! or `rate_limit` is present.
//!
//! JSON output is an object keyed by method name, each with `u`, `s`, `objective`, `status`
//! (`solved`, `slack_active`, `bounds_violated`, `solver_failed`, `non_finite`: NaN or ∞ in
//! the result), `status_detail`,
//! `solver_status`, `iterations`, `path` (`pinv`, `interior`: the certified interior shortcut of
//! `qp`, `clarabel`, `fallback`) and `solve_time_us`.
//!
//! Bad input is a [`CaseFileError`] naming the file and the key.

use std::path::{Path, PathBuf};
use std::time::Instant;

use nalgebra::{Matrix6xX, Vector6};
use serde::{Deserialize, Serialize};

use crate::allocation::{
    check_t, AllocError, AllocSettings, AllocStatus, Allocation, Allocator, Method, RateSettings,
};

/// The status label of a failed solve.
pub const FAILED: &str = "solver_failed";

/// The status label of a result holding NaN or infinite values (e.g. `τ` near `f64::MAX`
/// overflowing the pseudoinverse): never `solved`.
pub const NON_FINITE: &str = "non_finite";

/// A case file that cannot be used; the message names the file, the source the key.
#[derive(Debug, thiserror::Error)]
pub enum CaseFileError {
    /// The file could not be read.
    #[error("cannot read case file {path}", path = .path.display())]
    Read {
        /// The case file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a valid case.
    #[error("invalid case file {path}", path = .path.display())]
    Invalid {
        /// The case file.
        path: PathBuf,
        /// What is wrong, naming the key.
        #[source]
        source: CaseError,
    },
}

/// What is wrong with a case, naming the key (and the index where relevant).
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// Not JSON of the case schema (syntax, unknown key, wrong type); names the line.
    #[error(transparent)]
    Json(serde_json::Error),
    /// A key has the wrong shape or a non-finite value.
    #[error("{0}")]
    Shape(String),
    /// The allocator refused a value (bounds, weights, settings, `T`).
    #[error(transparent)]
    Alloc(#[from] AllocError),
}

/// The case file schema (see the module documentation).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCase {
    #[serde(rename = "T")]
    t: Vec<Vec<f64>>,
    tau: Vec<f64>,
    u_min: Option<Vec<f64>>,
    u_max: Option<Vec<f64>>,
    weights: Option<Vec<f64>>,
    lambda: Option<f64>,
    q: Option<f64>,
    eps: Option<f64>,
    u_prev: Option<Vec<f64>>,
    rate_weights: Option<Vec<f64>>,
    rate_limit: Option<Vec<f64>>,
}

/// A validated case: `T` (6×m, base frame), the commanded wrench, bounds, weights and settings.
#[derive(Debug, Clone)]
pub struct Case {
    /// Thruster configuration matrix (6×m; N/N, N·m/N), base frame.
    pub t: Matrix6xX<f64>,
    /// Commanded wrench (N, N·m), base frame.
    pub tau: Vector6<f64>,
    /// Lower thrust bounds (N).
    pub u_min: Vec<f64>,
    /// Upper thrust bounds (N).
    pub u_max: Vec<f64>,
    /// Usage weights (> 0).
    pub weights: Vec<f64>,
    /// Previous thrust (N) for the rate terms.
    pub u_prev: Option<Vec<f64>>,
    /// Allocator settings (damping, slack weight, rate terms).
    pub settings: AllocSettings,
}

fn key_len(key: &str, v: &[f64], m: usize) -> Result<(), CaseError> {
    if v.len() != m {
        return Err(CaseError::Shape(format!(
            "key `{key}` has {} entries, expected {m} (one per thruster, from the columns of `T`)",
            v.len()
        )));
    }
    Ok(())
}

/// Reads and validates the case file at `path`.
pub fn read_case(path: &Path) -> Result<Case, CaseFileError> {
    let text = crate::input::document::read_text(path).map_err(|source| CaseFileError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_case(&text).map_err(|source| CaseFileError::Invalid {
        path: path.to_path_buf(),
        source,
    })
}

/// Parses and validates case-file text (JSON, the schema of the module documentation).
pub fn parse_case(text: &str) -> Result<Case, CaseError> {
    let raw: RawCase = serde_json::from_str(text).map_err(CaseError::Json)?;
    build_case(raw)
}

fn build_case(raw: RawCase) -> Result<Case, CaseError> {
    if raw.t.len() != 6 {
        return Err(CaseError::Shape(format!(
            "key `T` has {} rows, expected 6 (force x, y, z, moment x, y, z)",
            raw.t.len()
        )));
    }
    let m = raw.t[0].len();
    if m == 0 {
        return Err(CaseError::Shape(
            "key `T` has no columns: at least one thruster is needed".into(),
        ));
    }
    for (i, row) in raw.t.iter().enumerate() {
        if row.len() != m {
            return Err(CaseError::Shape(format!(
                "key `T` row {i} has {} entries, row 0 has {m}: rows must be equally long",
                row.len()
            )));
        }
    }
    let t = Matrix6xX::from_fn(m, |i, j| raw.t[i][j]);
    if raw.tau.len() != 6 {
        return Err(CaseError::Shape(format!(
            "key `tau` has {} entries, expected 6",
            raw.tau.len()
        )));
    }
    let tau = Vector6::from_column_slice(&raw.tau);
    let u_min = raw.u_min.unwrap_or_else(|| vec![-40.0; m]);
    let u_max = raw.u_max.unwrap_or_else(|| vec![40.0; m]);
    let weights = raw.weights.unwrap_or_else(|| vec![1.0; m]);
    key_len("u_min", &u_min, m)?;
    key_len("u_max", &u_max, m)?;
    key_len("weights", &weights, m)?;
    if let Some(p) = &raw.u_prev {
        key_len("u_prev", p, m)?;
    }
    let rate = match (raw.rate_weights, raw.rate_limit) {
        (None, None) => None,
        (w, l) => {
            let weights = w.unwrap_or_else(|| vec![0.0; m]);
            let max_step = l.unwrap_or_else(|| vec![f64::INFINITY; m]);
            key_len("rate_weights", &weights, m)?;
            key_len("rate_limit", &max_step, m)?;
            Some(RateSettings { weights, max_step })
        }
    };
    let d = AllocSettings::default();
    let settings = AllocSettings {
        lambda: raw.lambda.unwrap_or(d.lambda),
        q: raw.q.unwrap_or(d.q),
        eps: raw.eps.unwrap_or(d.eps),
        rate,
        ..d
    };
    // Validate values once (the library names the key and index).
    let mut probe = Allocator::new(Method::Pinv, m, &u_min, &u_max, &weights, settings.clone())?;
    if let Some(p) = &raw.u_prev {
        probe.set_u_prev(p)?;
    }
    check_t(&t, Some(m))?;
    if let Some((i, v)) = raw.tau.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(CaseError::Shape(format!("`tau[{i}]` is not finite ({v})")));
    }
    Ok(Case {
        t,
        tau,
        u_min,
        u_max,
        weights,
        u_prev: raw.u_prev,
        settings,
    })
}

/// One method's result (JSON keys as named).
#[derive(Debug, Clone, Serialize)]
pub struct MethodResult {
    /// Thrusts (N).
    pub u: Vec<f64>,
    /// Wrench slack `s = T u − τ` (N, N·m).
    pub s: [f64; 6],
    /// Objective value of the method.
    pub objective: f64,
    /// Status label: `solved`, `slack_active`, `bounds_violated`, [`FAILED`] or
    /// [`NON_FINITE`].
    pub status: &'static str,
    /// The status in words.
    pub status_detail: String,
    /// Clarabel's status (e.g. `Solved`).
    pub solver_status: &'static str,
    /// Solver iterations.
    pub iterations: u32,
    /// Which computation produced `u` ([`AllocPath::label`](crate::allocation::AllocPath::label)).
    pub path: &'static str,
    /// Wall-clock time of the solve (µs).
    pub solve_time_us: f64,
}

impl MethodResult {
    fn new(a: &Allocation, solve_time_us: f64) -> Self {
        let mut s = [0.0; 6];
        s.copy_from_slice(a.s.as_slice());
        let finite = a.u.iter().chain(&s).all(|v| v.is_finite()) && !a.objective.is_nan();
        let (status, status_detail) = if finite {
            (AllocStatus::label(&a.status), a.status.to_string())
        } else {
            (
                NON_FINITE,
                format!(
                    "the result holds NaN or infinite values (the solver said: {}); τ or T \
                     is too large for double precision",
                    a.status
                ),
            )
        };
        Self {
            u: a.u.clone(),
            s,
            objective: a.objective,
            status,
            status_detail,
            solver_status: a.solver_status,
            iterations: a.iterations,
            path: a.path.label(),
            solve_time_us,
        }
    }
}

/// Results in method order, serialised as a JSON object keyed by method name.
#[derive(Debug, Clone)]
pub struct Results(pub Vec<(Method, MethodResult)>);

impl Serialize for Results {
    fn serialize<S: serde::Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = ser.serialize_map(Some(self.0.len()))?;
        for (m, r) in &self.0 {
            map.serialize_entry(m.name(), r)?;
        }
        map.end()
    }
}

/// Solves `case` with each of `methods` in turn, timing each solve. A failed Clarabel solve is
/// a result with status [`FAILED`] (and the clipped-pinv fallback), not an error.
pub fn solve_case(case: &Case, methods: &[Method]) -> Result<Results, AllocError> {
    let m = case.t.ncols();
    let mut out = Vec::with_capacity(methods.len());
    for &method in methods {
        let mut alloc = Allocator::new(
            method,
            m,
            &case.u_min,
            &case.u_max,
            &case.weights,
            case.settings.clone(),
        )?;
        if let Some(p) = &case.u_prev {
            alloc.set_u_prev(p)?;
        }
        let start = Instant::now();
        let r = alloc.allocate(&case.t, &case.tau)?;
        let us = start.elapsed().as_secs_f64() * 1e6;
        out.push((method, MethodResult::new(&r, us)));
    }
    Ok(Results(out))
}

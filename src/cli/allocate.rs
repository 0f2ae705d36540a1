//! `usm-study allocate`: solve one thrust-allocation case (SPEC §5, USM-36/37) with one or all
//! methods and print the result as a table or JSON.
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
//! (`solved`, `slack_active`, `bounds_violated`, `solver_failed`), `status_detail`,
//! `solver_status`, `iterations` and `solve_time_us`.
//!
//! Exit code: 0 when every requested method produced a result, 1 when a Clarabel solve failed (the
//! clipped-pinv fallback is still printed). Bad input is an `Err` naming the file and the key.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context};
use nalgebra::{Matrix6xX, Vector6};
use serde::{Deserialize, Serialize};

use super::format::Format;
use usm_study::allocation::{
    AllocSettings, AllocStatus, Allocation, Allocator, Method, RateSettings,
};

/// The status label of a failed solve.
const FAILED: &str = "solver_failed";

/// Which method(s) to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Damped pseudoinverse (USM-37).
    Pinv,
    /// Constrained QP.
    Qp,
    /// Minimax (smallest largest thrust).
    Minimax,
    /// Power-optimal (Σ|u|^{3/2}).
    Power,
    /// All four methods.
    All,
}

/// Arguments of `usm-study allocate`.
#[derive(Debug, Clone, clap::Args)]
pub struct AllocateArgs {
    /// Allocation case file (JSON: `T`, `tau`, optional `u_min`, `u_max`, `weights`, `lambda`,
    /// `q`, `eps`, `u_prev`, `rate_weights`, `rate_limit`).
    #[arg(long, value_name = "CASE.json")]
    pub input: PathBuf,
    /// Allocation method, or `all`.
    #[arg(long, value_enum, default_value_t = MethodArg::All)]
    pub method: MethodArg,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
}

/// The case file schema (see the module documentation).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
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

/// A validated case.
struct Case {
    t: Matrix6xX<f64>,
    tau: Vector6<f64>,
    u_min: Vec<f64>,
    u_max: Vec<f64>,
    weights: Vec<f64>,
    u_prev: Option<Vec<f64>>,
    settings: AllocSettings,
}

fn key_len(key: &str, v: &[f64], m: usize) -> anyhow::Result<()> {
    if v.len() != m {
        bail!(
            "key `{key}` has {} entries, expected {m} (one per thruster, from the columns of `T`)",
            v.len()
        );
    }
    Ok(())
}

fn parse_case(path: &Path) -> anyhow::Result<Case> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read case file {}", path.display()))?;
    let raw: CaseFile = serde_json::from_str(&text)
        .with_context(|| format!("invalid case file {}", path.display()))?;
    build_case(raw).with_context(|| format!("invalid case file {}", path.display()))
}

fn build_case(raw: CaseFile) -> anyhow::Result<Case> {
    if raw.t.len() != 6 {
        bail!(
            "key `T` has {} rows, expected 6 (force x, y, z, moment x, y, z)",
            raw.t.len()
        );
    }
    let m = raw.t[0].len();
    if m == 0 {
        bail!("key `T` has no columns: at least one thruster is needed");
    }
    for (i, row) in raw.t.iter().enumerate() {
        if row.len() != m {
            bail!(
                "key `T` row {i} has {} entries, row 0 has {m}: rows must be equally long",
                row.len()
            );
        }
    }
    let t = Matrix6xX::from_fn(m, |i, j| raw.t[i][j]);
    if raw.tau.len() != 6 {
        bail!("key `tau` has {} entries, expected 6", raw.tau.len());
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
    usm_study::allocation::check_t(&t, Some(m))?;
    if let Some((i, v)) = raw.tau.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        bail!("`tau[{i}]` is not finite ({v})");
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

/// One method's result as printed.
#[derive(Debug, Clone, Serialize)]
struct MethodResult {
    u: Vec<f64>,
    s: [f64; 6],
    objective: f64,
    status: &'static str,
    status_detail: String,
    solver_status: &'static str,
    iterations: u32,
    solve_time_us: f64,
}

impl MethodResult {
    fn new(a: &Allocation, solve_time_us: f64) -> Self {
        let mut s = [0.0; 6];
        s.copy_from_slice(a.s.as_slice());
        Self {
            u: a.u.clone(),
            s,
            objective: a.objective,
            status: AllocStatus::label(&a.status),
            status_detail: a.status.to_string(),
            solver_status: a.solver_status,
            iterations: a.iterations,
            solve_time_us,
        }
    }
}

/// Results in method order, serialised as a JSON object keyed by method name.
struct Results(Vec<(Method, MethodResult)>);

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

fn solve_case(case: &Case, methods: &[Method]) -> anyhow::Result<Results> {
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

fn render_text(path: &Path, case: &Case, results: &Results) -> String {
    let m = case.t.ncols();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "thrust allocation: {} ({m} thrusters, |tau| = {:.4})",
        path.display(),
        case.tau.norm()
    );
    let _ = writeln!(
        s,
        "{:<8} {:<16} {:>13} {:>11} {:>10} {:>6} {:>10}",
        "method", "status", "objective", "|s|", "max|u| N", "iter", "time us"
    );
    for (method, r) in &results.0 {
        let snorm = r.s.iter().map(|x| x * x).sum::<f64>().sqrt();
        let umax = r.u.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        let status = if r.status == FAILED {
            format!("failed:{}", r.solver_status)
        } else {
            r.status.to_string()
        };
        let _ = writeln!(
            s,
            "{:<8} {:<16} {:>13.6e} {:>11.3e} {:>10.4} {:>6} {:>10.1}",
            method.name(),
            status,
            r.objective,
            snorm,
            umax,
            r.iterations,
            r.solve_time_us
        );
    }
    let _ = writeln!(s);
    let _ = write!(s, "{:<8}", "u [N]");
    for (method, _) in &results.0 {
        let _ = write!(s, " {:>11}", method.name());
    }
    let _ = writeln!(s);
    for j in 0..m {
        let _ = write!(s, "{:<8}", format!("u{}", j + 1));
        for (_, r) in &results.0 {
            let _ = write!(s, " {:>11.4}", r.u[j]);
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "s = T u - tau [N, N m]");
    for (i, name) in ["fx", "fy", "fz", "mx", "my", "mz"].iter().enumerate() {
        let _ = write!(s, "{:<8}", format!("  {name}"));
        for (_, r) in &results.0 {
            let _ = write!(s, " {:>11.3e}", r.s[i]);
        }
        let _ = writeln!(s);
    }
    s
}

/// Run `usm-study allocate` (SPEC §5): read the case, solve it with the requested method(s),
/// print a table or JSON on stdout. Returns exit code 0, or 1 when a Clarabel solve failed; bad
/// input is an `Err` whose message names the file and the key.
pub fn run(args: &AllocateArgs) -> anyhow::Result<ExitCode> {
    let case = parse_case(&args.input)?;
    let methods: Vec<Method> = match args.method {
        MethodArg::Pinv => vec![Method::Pinv],
        MethodArg::Qp => vec![Method::Qp],
        MethodArg::Minimax => vec![Method::Minimax],
        MethodArg::Power => vec![Method::Power],
        MethodArg::All => Method::ALL.to_vec(),
    };
    let results = solve_case(&case, &methods)
        .with_context(|| format!("invalid case file {}", args.input.display()))?;
    match args.format {
        Format::Json => {
            let text = serde_json::to_string_pretty(&results)?;
            println!("{text}");
        }
        Format::Text => print!("{}", render_text(&args.input, &case, &results)),
    }
    let failed = results.0.iter().any(|(_, r)| r.status == FAILED);
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_case(dir: &tempfile::TempDir, name: &str, body: &str) -> PathBuf {
        let p = dir.path().join(name);
        std::fs::write(&p, body).unwrap();
        p
    }

    const T7: &str = r#"[[1,1,0,0,0,0,0.6],[0,0,1,1,0,0,0],[0,0,0,0,1,1,0.8],
        [0,0,0,0,0,0,0],[0,0,0,0,-0.6,-1.4,-0.8],[0,0,0.4,1.6,0,0,0]]"#;

    #[test]
    fn parses_and_solves_a_case() {
        let dir = tempfile::tempdir().unwrap();
        let p = write_case(
            &dir,
            "c.json",
            &format!(
                r#"{{"T": {T7}, "tau": [10, 2, -3, 0, 1, 0.5], "u_max": [40,40,40,40,40,40,40]}}"#
            ),
        );
        let case = parse_case(&p).unwrap();
        let r = solve_case(&case, &Method::ALL).unwrap();
        assert_eq!(r.0.len(), 4);
        let json = serde_json::to_value(&r).unwrap();
        for k in ["pinv", "qp", "minimax", "power"] {
            assert_eq!(json[k]["u"].as_array().unwrap().len(), 7);
            assert!(json[k]["solve_time_us"].is_number());
        }
        assert_eq!(json["qp"]["status"], "solved");
        let text = render_text(&p, &case, &r);
        assert!(text.contains("minimax") && text.contains("u7"));
    }

    #[test]
    fn bad_cases_name_file_and_key() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            (
                "dim.json",
                format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "u_min": [0, 0]}}"#),
                "u_min",
            ),
            (
                "order.json",
                format!(
                    r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "u_min": [0,0,0,5,0,0,0], "u_max": [1,1,1,1,1,1,1]}}"#
                ),
                "u_min[3]",
            ),
            (
                "unknown.json",
                format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "bogus": 1}}"#),
                "bogus",
            ),
            (
                "tau.json",
                format!(r#"{{"T": {T7}, "tau": [1,2,3]}}"#),
                "tau",
            ),
            (
                "rows.json",
                r#"{"T": [[1],[1],[1]], "tau": [1,2,3,4,5,6]}"#.to_string(),
                "`T`",
            ),
            (
                "nan.json",
                format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,NaN]}}"#),
                "line",
            ),
            (
                "w.json",
                format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "weights": [1,1,1,1,1,0,1]}}"#),
                "weights[5]",
            ),
        ];
        for (name, body, key) in cases {
            let p = write_case(&dir, name, &body);
            let e = parse_case(&p).err().expect("must fail");
            let chain = format!("{e:#}");
            assert!(chain.contains(name), "{chain}");
            assert!(chain.contains(key), "{chain}");
        }
    }
}

//! `usm-study allocate`: solve one thrust-allocation case (docs/model.md §5, USM-36/37) with one or all
//! methods and print the result as a table or JSON. The case file and the JSON output are
//! described in [`usm_study::pipeline::allocate`].
//!
//! Exit code: 0 when every requested method produced a result, 1 when a Clarabel solve failed (the
//! clipped-pinv fallback is still printed). Bad input is an `Err` naming the file and the key.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;

use super::format::Format;
use usm_study::allocation::Method;
use usm_study::pipeline::allocate::{read_case, solve_case, Case, Results, FAILED, NON_FINITE};

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

/// Run `usm-study allocate` (docs/model.md §5): read the case, solve it with the requested method(s),
/// print a table or JSON on stdout. Returns exit code 0, or 1 when a Clarabel solve failed or a
/// result is not finite (`non_finite`); bad input is an `Err` whose message names the file and
/// the key.
pub fn run(args: &AllocateArgs) -> anyhow::Result<ExitCode> {
    let case = read_case(&args.input)?;
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
    let failed = results
        .0
        .iter()
        .any(|(_, r)| r.status == FAILED || r.status == NON_FINITE);
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
        let case = read_case(&p).unwrap();
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
            let e = anyhow::Error::from(read_case(&p).expect_err("must fail"));
            let chain = format!("{e:#}");
            assert!(chain.contains(name), "{chain}");
            assert!(chain.contains(key), "{chain}");
        }
    }
}

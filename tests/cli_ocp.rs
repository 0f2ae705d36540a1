//! End-to-end tests of `usm-study ocp` (docs/ocp.md): a small rigid-chain problem solved and
//! written (trajectory.csv with the time-series column names, summary.json), and exit code 2
//! with a message naming the file, the line and the key for malformed problem files.

mod common;

use common::{arg, run, stderr, write};

/// A short version of the shipped benchmark (2 s, 20 intervals, a 3.6 cm move), bounded.
fn problem(design: &str, extra: &str) -> String {
    format!(
        r#"design = "{design}"
[horizon]
duration = 2.0
knots = 20
[terminal]
ee_displacement = [0.0, 0.03, -0.02]
[bounds]
base_force = 5.0
base_moment = 5.0
joint_torque = 5.0
{extra}"#
    )
}

fn design_path() -> String {
    std::fs::canonicalize("studies/designs/rigid_chain5.toml")
        .unwrap()
        .display()
        .to_string()
}

#[test]
fn small_problem_is_solved_and_written() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "p.toml", &problem(&design_path(), ""));
    let out_dir = dir.path().join("out");
    let out = run(&["ocp", arg(&p), "--out", arg(&out_dir)]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(s["status"], "converged");
    assert!(s["terminal_violation"].as_f64().unwrap() <= 1e-6);
    assert!(s["kkt"]["stationarity"].as_f64().unwrap() <= 1e-6);
    assert!(s["objective"].as_f64().unwrap() > 0.0);
    let csv = std::fs::read_to_string(out_dir.join("trajectory.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for c in [
        "t",
        "base_x",
        "base_yaw",
        "base_u",
        "ee_x",
        "q_1",
        "qd_4",
        "tau_4",
        "wrench_fx",
    ] {
        assert!(header.contains(&c), "column {c} in {header:?}");
    }
    assert_eq!(lines.count(), 21, "N + 1 knots");
    // The plots: states, controls (their bounds: `ocp::plots` tests), convergence, the body
    // at 8 knots.
    let plot = |f: &str| std::fs::read_to_string(out_dir.join("plots").join(f)).unwrap();
    let states = plot("states.svg");
    for t in [
        "Base position",
        "Base attitude",
        "Joint angles",
        "Joint rates",
    ] {
        assert!(states.contains(t), "states.svg: {t}");
    }
    let controls = plot("controls.svg");
    assert!(controls.contains("Base wrench") && controls.contains("Joint torques"));
    let iterations = s["iterations"].as_u64().unwrap();
    assert!(plot("convergence.svg")
        .contains(&format!("Convergence: {iterations} iterations, converged")));
    let shapes = plot("shapes.svg");
    assert_eq!(
        shapes.matches("class=\"snap\"").count(),
        2 * 8,
        "8 knots in 2 views"
    );
}

#[test]
fn malformed_problem_files_exit_2_naming_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = design_path();
    let cases = [
        // (file text, key named, line named)
        (
            problem(&d, "").replace("knots = 20", "knots = 0"),
            "horizon.knots",
            4,
        ),
        (
            problem(&d, "").replace("duration = 2.0", "duration = \"long\""),
            "horizon.duration",
            3,
        ),
        (
            problem(&d, "[solver]\ntolerance = -1.0"),
            "solver.tolerance",
            12,
        ),
        (problem(&d, "[solver]\nmax_iter = 3"), "solver", 12),
        (
            problem(&d, "").replace("base_force = 5.0", "base_force = 0.0"),
            "bounds.base_force",
            8,
        ),
    ];
    for (i, (text, key, line)) in cases.iter().enumerate() {
        let p = write(dir.path(), &format!("bad{i}.toml"), text);
        let out = run(&["ocp", arg(&p), "--out", arg(&dir.path().join("o"))]);
        assert_eq!(out.status.code(), Some(2), "case {i}: {}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains(&format!("bad{i}.toml:{line}")),
            "case {i}: {err}"
        );
        assert!(err.contains(key), "case {i}: {err}");
    }
    // A design that does not exist.
    let p = write(
        dir.path(),
        "nodesign.toml",
        &problem("no/such/design.toml", ""),
    );
    let out = run(&["ocp", arg(&p), "--out", arg(&dir.path().join("o"))]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("nodesign.toml:1"), "{}", stderr(&out));
}

/// `ocp --track SCENARIO` flies the optimum in closed loop through the scenario's plant
/// (`simulate SCENARIO --reference trajectory.csv`) and puts the tracked run beside the
/// optimum in summary.json.
#[test]
fn the_optimum_is_tracked_in_closed_loop_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "p.toml",
        r#"design = "usm-paper"
actuation = "thrusters"
[physics]
hydrodynamics = true
[horizon]
duration = 2.0
knots = 8
[terminal]
ee_displacement = [0.0, 0.03, -0.02]
[objective]
effort = 1.0
[bounds]
joint_torque = 20.0
"#,
    );
    let out_dir = dir.path().join("out");
    let out = run(&[
        "ocp",
        arg(&p),
        "--out",
        arg(&out_dir),
        "--track",
        "work-setpoint",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    let t = &s["tracked"];
    assert_eq!(t["scenario"], "work-setpoint");
    assert_eq!(t["design"], "usm-paper");
    let num = |k: &str| t[k].as_f64().unwrap_or_else(|| panic!("tracked.{k}: {t}"));
    assert!(num("thruster_energy_j") > 0.0);
    assert!(num("optimum_thruster_energy_static_j") >= 0.0);
    let price = num("thruster_energy_static_j") - num("optimum_thruster_energy_static_j");
    assert!((num("price_static_j") - price).abs() <= 1e-12 * price.abs().max(1.0));
    // The tracking law follows the optimum's base path (a 3.6 cm move of the end effector).
    assert!(num("base_error_max_m") < 0.02, "{t}");
    assert!(num("final_position_error_m").is_finite());
    // The run lasts the reference's span, 2 s.
    let ts = std::fs::read_to_string(out_dir.join("tracked/timeseries.csv")).unwrap();
    let last = ts.lines().last().unwrap().split(',').next().unwrap();
    assert!((last.parse::<f64>().unwrap() - 2.0).abs() < 1e-9, "{last}");
    assert!(out_dir.join("tracked/tracking.json").exists());
    assert!(String::from_utf8_lossy(&out.stdout).contains("tracked in closed loop"));
}

//! End-to-end tests of `usm-study allocate` (docs/model.md §5): JSON and text output, method selection,
//! and exit code 2 with a message naming the file and the key on bad input.

mod common;

use common::{run, write};
use std::process::Output;

/// A straight-USM-like T (7 thrusters, roll row zero) as JSON rows.
const T7: &str = r#"[[1,1,0,0,0,0,0.6],[0,0,1,1,0,0,0],[0,0,0,0,1,1,0.8],
    [0,0,0,0,0,0,0],[0,0,0,0,-0.6,-1.4,-0.8],[0,0,0.4,1.6,0,0,0]]"#;

fn allocate(args: &[&str]) -> Output {
    let mut a = vec!["allocate"];
    a.extend_from_slice(args);
    run(&a)
}

#[test]
fn json_output_has_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "case.json",
        &format!(r#"{{"T": {T7}, "tau": [10, 2, -3, 0, 1, 0.5]}}"#),
    );
    let out = allocate(&["--input", p.to_str().unwrap(), "--format", "json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout is JSON");
    for k in ["pinv", "qp", "minimax", "power"] {
        let r = &v[k];
        assert_eq!(r["u"].as_array().unwrap().len(), 7, "{k}");
        assert_eq!(r["s"].as_array().unwrap().len(), 6, "{k}");
        assert!(r["objective"].is_number(), "{k}");
        assert!(r["solve_time_us"].is_number(), "{k}");
        assert!(r["status"].is_string(), "{k}");
    }
    assert_eq!(v["qp"]["status"], "solved");
}

#[test]
fn single_method_and_unattainable_roll() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "roll.json",
        &format!(
            r#"{{"T": {T7}, "tau": [10, 2, -3, 5, 1, 0.5], "u_min": [-40,-40,-40,-40,-40,-40,-40]}}"#
        ),
    );
    let out = allocate(&[
        "--input",
        p.to_str().unwrap(),
        "--method",
        "qp",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let obj = v.as_object().unwrap();
    assert_eq!(obj.len(), 1);
    assert_eq!(v["qp"]["status"], "slack_active");
    let s_roll = v["qp"]["s"][3].as_f64().unwrap();
    assert!((s_roll + 5.0).abs() < 1e-6, "{s_roll}");
}

#[test]
fn text_output_is_a_table() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "case.json",
        &format!(r#"{{"T": {T7}, "tau": [10, 2, -3, 0, 1, 0.5], "rate_limit": [5,5,5,5,5,5,5]}}"#),
    );
    let out = allocate(&["--input", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    for k in ["pinv", "qp", "minimax", "power", "u7", "status"] {
        assert!(text.contains(k), "{k} missing in\n{text}");
    }
}

#[test]
fn bad_input_exits_2_naming_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "dims.json",
            format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "u_max": [1,2]}}"#),
            "u_max",
        ),
        (
            "order.json",
            format!(
                r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "u_min": [0,0,9,0,0,0,0], "u_max": [1,1,1,1,1,1,1]}}"#
            ),
            "u_min[2]",
        ),
        (
            "nan.json",
            format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,NaN]}}"#),
            "nan.json",
        ),
        (
            "unknown.json",
            format!(r#"{{"T": {T7}, "tau": [1,2,3,4,5,6], "speed": 3}}"#),
            "speed",
        ),
    ];
    for (name, body, key) in cases {
        let p = write(dir.path(), name, &body);
        let out = allocate(&["--input", p.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(name), "{name}: {err}");
        assert!(err.contains(key), "{name}: {err}");
    }
    let out = allocate(&["--input", dir.path().join("missing.json").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
}

/// A damping whose square overflows used to send the pseudoinverse's SVD fallback into an
/// endless loop on infinite data: it is now refused up front, naming the key (exit 2).
#[test]
fn overflowing_damping_is_refused_not_a_hang() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "huge_lambda.json",
        &format!(r#"{{"T": {T7}, "tau": [1, 0, 0, 0, 0, 0], "lambda": 1e300}}"#),
    );
    let out = allocate(&["--input", p.to_str().unwrap(), "--method", "pinv"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("lambda") && err.contains("1e300"), "{err}");
}

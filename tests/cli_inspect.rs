//! End-to-end tests of `usm-study inspect` and `usm-study design show`: the reference values
//! of the foundation issue and every bad-input case (exit code 2, a message naming the file,
//! the key and, for TOML, the line).

mod common;

use common::{json, run};
use std::path::Path;

/// [`common::write`], as the `&str` argument the commands take.
fn write(dir: &Path, name: &str, text: &str) -> String {
    common::write(dir, name, text).display().to_string()
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn usm_paper_straight_reference_values() {
    // USM Table II: 81.3 kg, 3.300 m; the end-effector is the head's front face.
    let d = json(&["inspect", "usm-paper", "--format", "json"]);
    assert!((f(&d["total_mass"]) - 81.3).abs() < 1e-9);
    assert!((f(&d["total_length"]) - 3.3).abs() < 1e-9);
    assert!((f(&d["ee_position"][0]) - 3.3).abs() < 1e-9);
    assert_eq!(d["tcm_rank"], 5);
    assert_eq!(d["tcm_lost_directions"][0]["dominant_axis"], "roll");
    assert_eq!(d["tcm"].as_array().unwrap().len(), 6);
    assert_eq!(d["tcm"][0].as_array().unwrap().len(), 7);
    assert_eq!(d["ee_jacobian"].as_array().unwrap().len(), 6);
    assert_eq!(d["ee_jacobian"][0].as_array().unwrap().len(), 14);
    assert_eq!(d["mass_matrix"].as_array().unwrap().len(), 14);
    assert_eq!(d["bias"].as_array().unwrap().len(), 14);
    assert_eq!(d["acceleration"].as_array().unwrap().len(), 14);
    // Neutrally buoyant at rest: no bias, no motion.
    assert!(d["bias"]
        .as_array()
        .unwrap()
        .iter()
        .all(|x| f(x).abs() < 1e-9));
    assert_eq!(f(&d["kinetic_energy"]), 0.0);
}

#[test]
fn usm_paper_straight_authority_in_newtons_about_the_centre_of_mass() {
    // Issue 24 "Must show": the attainable force along each commanded axis of transport, in N
    // about the centre of mass, and the N−1 worst case.
    let d = json(&["inspect", "usm-paper", "--format", "json"]);
    let a = &d["authority"];
    assert_eq!(a["reference"], "com");
    assert_eq!(a["commanded_axes"], "surge+sway+heave+pitch+yaw");
    // Straight, the CoM lies on the body axis, inside the 3.3 m body.
    let r = f(&a["reference_point"][0]);
    assert!(
        r > 0.5 && r < 2.8 && f(&a["reference_point"][1]).abs() < 1e-12,
        "{r}"
    );
    // Surge: only the longitudinal pair (2 × 40 N) pushes along x and its moments cancel.
    for sign in ["positive", "negative"] {
        assert!((f(&a["attainable"][sign][0]) - 80.0).abs() < 1e-6, "{a}");
        assert!(a["attainable"][sign][3].is_null(), "roll is not commanded");
        for k in [1, 2, 4, 5] {
            assert!(f(&a["attainable"][sign][k]) > 1.0, "{k}: {a}");
        }
    }
    // N−1: removing either longitudinal thruster (T3, T4: mirrored) halves surge.
    let t = &a["n1"]["thrusters"];
    for i in [2, 3] {
        assert!((f(&t[i]["loss"]) - 0.5).abs() < 1e-6, "{}", t[i]);
        assert_eq!(t[i]["loss_axis"], "surge");
        assert!((f(&t[i]["straight"]["positive"][0]) - 40.0).abs() < 1e-6);
    }
    let worst = a["n1"]["worst_thruster"].as_u64().unwrap() as usize;
    let loss = f(&t[worst]["loss"]);
    assert!(t.as_array().unwrap().iter().all(|x| f(&x["loss"]) <= loss));
    assert!(loss > 0.5 && loss <= 1.0);
    assert!(f(&a["n1"]["worst_force"]) < f(&a["min_force"]));
    // The text report says the same.
    let out = run(&["inspect", "usm-paper"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("about the centre of mass") && text.contains("N−1"),
        "{text}"
    );
}

#[test]
fn bent_usm_paper_has_full_rank_and_state_is_used() {
    let dir = tempfile::tempdir().unwrap();
    let state = write(
        dir.path(),
        "bent.json",
        r#"{"base_position": [1, 2, 3],
            "base_rotation": [[1,0,0],[0,1,0],[0,0,1]],
            "joint_angles": [0, 0, 0.5, 0, 0, 0, 0, 0],
            "base_twist": [0.5, 0, 0, 0, 0, 0.1],
            "generalized_forces": [10, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]}"#,
    );
    let d = json(&[
        "inspect",
        "usm-paper",
        "--state",
        &state,
        "--format",
        "json",
    ]);
    assert_eq!(d["tcm_rank"], 6);
    assert!(d["tcm_lost_directions"].as_array().unwrap().is_empty());
    assert!((f(&d["ee_position"][0]) - 1.0) > 2.0);
    assert!(f(&d["kinetic_energy"]) > 0.0);
    // A surge force accelerates the vehicle forward.
    assert!(f(&d["acceleration"][0]) > 0.0);
    // --rigid removes the added mass: the surge entry of M drops to the dry mass.
    let r = json(&[
        "inspect",
        "usm-paper",
        "--state",
        &state,
        "--format",
        "json",
        "--rigid",
    ]);
    assert!((f(&r["mass_matrix"][0][0]) - 81.3).abs() < 1e-9);
    assert!(f(&d["mass_matrix"][0][0]) > 81.3);
}

#[test]
fn text_output_and_design_show() {
    let out = run(&["inspect", "usm-paper"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("total mass 81.300 kg"));
    assert!(text.contains("rank: 5 of 6"));
    assert!(text.contains("lost direction: roll"));
    assert!(text.contains("mass matrix 14x14"));
    // design show prints a file that inspect accepts and that describes the same vehicle.
    let dir = tempfile::tempdir().unwrap();
    for preset in ["usm-paper", "uvms-planar"] {
        let out = run(&["design", "show", preset]);
        assert!(out.status.success());
        let p = write(
            dir.path(),
            &format!("{preset}.toml"),
            &String::from_utf8(out.stdout).unwrap(),
        );
        let a = json(&["inspect", preset, "--format", "json"]);
        let b = json(&["inspect", &p, "--format", "json"]);
        assert_eq!(a["tcm"], b["tcm"]);
        assert_eq!(a["mass_matrix"], b["mass_matrix"]);
        assert_eq!(a["total_mass"], b["total_mass"]);
    }
}

/// Run inspect on a design text, expect exit code 2 and an error naming file, key and line.
fn expect_design_error(text: &str, key: &str, line: usize) {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bad.toml", text);
    let out = run(&["inspect", &p]);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(
        out.stdout.is_empty(),
        "nothing half-written: {:?}",
        out.stdout
    );
    assert!(err.contains(&p), "names the file: {err}");
    assert!(err.contains(key), "names the key {key}: {err}");
    assert!(
        err.contains(&format!("{p}:{line}:")),
        "names line {line}: {err}"
    );
    assert_eq!(err.lines().count(), 1, "one-line cause chain: {err}");
}

const BODY: &str = "[[body]]\nname = \"a\"\nmass = 10.0\nlength = 0.5\nradius = 0.08\n";

fn two_bodies(extra_b: &str, joint: &str, thruster: &str) -> String {
    format!(
        "{BODY}\n[[body]]\nname = \"b\"\nmass = 5.0\nlength = 0.4\nradius = 0.08\n{extra_b}\n[[joint]]\naxis = [0, 0, 1]\n{joint}\n[[thruster]]\nbody = 1\nposition = [0.2, 0, 0]\ndirection = [0, 1, 0]\n{thruster}\n"
    )
}

#[test]
fn design_errors_name_file_key_and_line() {
    // Lines: body a 1-5, blank 6, body b 7-11, extra 12, joint 13-15, thruster 16-20.
    expect_design_error(&two_bodies("colour = \"red\"", "", ""), "colour", 12);
    expect_design_error(
        &two_bodies("", "", "").replace("mass = 5.0", "mass = \"five\""),
        "mass",
        9,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("mass = 5.0", "mass = -5.0"),
        "mass",
        9,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("length = 0.4", "length = 0.0"),
        "length",
        10,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("radius = 0.08\n\n[[joint]]", "radius = -1.0\n\n[[joint]]"),
        "radius",
        11,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("body = 1", "body = 7"),
        "body",
        17,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("direction = [0, 1, 0]", "direction = [0, 0, 0]"),
        "direction",
        19,
    );
    expect_design_error(
        &two_bodies("", "", "u_min = 10.0\nu_max = -10.0"),
        "u_m",
        20,
    );
    expect_design_error(
        &two_bodies("", "limits_deg = [45.0, -45.0]", ""),
        "limits",
        15,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("mass = 5.0", "mass = nan"),
        "mass",
        9,
    );
    expect_design_error(
        &two_bodies("", "", "").replace("position = [0.2, 0, 0]", "position = [inf, 0, 0]"),
        "position",
        18,
    );
    expect_design_error("[[body]]\nname = \"a\"\nmass = = 3\n", "", 3);
}

#[test]
fn state_errors_are_clear() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (r#"{"joint_angles": [0, 0, 0]}"#, "joint_angles"),
        (
            r#"{"base_rotation": [[1,0,0],[0,1,0],[0,0,2]]}"#,
            "base_rotation",
        ),
        (r#"{"joint_rates": [0,0,0,0,0,0,0,0,0]}"#, "joint_rates"),
        (r#"{"base_positon": [0,0,0]}"#, "base_positon"),
    ];
    for (i, (text, key)) in cases.iter().enumerate() {
        let p = write(dir.path(), &format!("s{i}.json"), text);
        let out = run(&["inspect", "usm-paper", "--state", &p]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(&p) && err.contains(key), "{text}: {err}");
    }
    let out = run(&["inspect", "no-such-design"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("usm-paper"));
}

//! Two public vehicle descriptions nobody here wrote (tests/fixtures/urdf/README.md): the UUV
//! Simulator RexROV 2 (UUV plugin blocks) and a BlueROV2 (gz-sim Hydrodynamics and Thruster
//! systems). `design import` succeeds; `inspect`'s totals (mass, volume, T(q) singular values
//! and rank, and the attainable wrench and authority under the thrust box) equal a reading of
//! the file written here independently of the importer (`urdf_reading/mod.rs`: its own XML
//! walk and a vertex enumeration of the LPs, no usm-study code); each runs a short `simulate`
//! and a small `tcm`.

mod common;
#[path = "urdf_reading/mod.rs"]
mod reading;

use common::{json, run, stderr};
use nalgebra::DMatrix;
use std::path::Path;

const DIR: &str = "tests/fixtures/urdf";

fn sorted_singular_values(m: &DMatrix<f64>) -> Vec<f64> {
    let mut s: Vec<f64> = m
        .clone()
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    s.sort_by(|a, b| b.partial_cmp(a).unwrap());
    s
}

/// How a fixture is imported and read.
struct Fixture<'a> {
    name: &'a str,
    /// T(q) rank the independent reading must find.
    rank: usize,
    /// `--thrust-limit` given to the import (neither file has finite limits): the box of the
    /// independent LPs. `None`: the project's default, 40 N.
    thrust_limit: Option<f64>,
    /// `--fix-joint` joints.
    fixed: &'a [&'a str],
    /// Links of bodies the file gives no volume (neutral at import, m/ρ).
    neutral: &'a [&'a str],
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// `inspect`'s attainable values (`positive`/`negative` arrays of `node`) against the
/// independent LPs, to 1e-6 of the thrust limit.
fn compare_attainable(what: &str, node: &serde_json::Value, ours: &[(usize, f64, f64)], lim: f64) {
    for &(axis, pos, neg) in ours {
        let p = node["positive"][axis].as_f64().unwrap();
        let n = node["negative"][axis].as_f64().unwrap();
        assert!(
            close(p, pos, 1e-6 * lim) && close(n, neg, 1e-6 * lim),
            "{what} axis {axis}: inspect +{p} / -{n}, independent +{pos} / -{neg}"
        );
    }
}

fn check(f: &Fixture) -> tempfile::TempDir {
    let name = f.name;
    let d = tempfile::tempdir().unwrap();
    let design = d.path().join("design.toml");
    let urdf = format!("{DIR}/{name}");
    let mut args = vec!["design".to_string(), "import".into(), urdf.clone()];
    args.extend(["--out".into(), design.display().to_string()]);
    if let Some(l) = f.thrust_limit {
        args.extend(["--thrust-limit".into(), l.to_string()]);
    }
    for j in f.fixed {
        args.extend(["--fix-joint".into(), j.to_string()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = run(&args);
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let text = std::fs::read_to_string(&urdf).unwrap();
    let r = reading::read(&text, f.neutral);
    let j = json(&["inspect", design.to_str().unwrap(), "--format", "json"]);
    let mass = j["total_mass"].as_f64().unwrap();
    assert!(
        (mass - r.mass).abs() <= 1e-9 * r.mass,
        "{name}: mass {mass} vs {}",
        r.mass
    );
    let g = 9.81;
    let volume = j["hydrostatics"]["buoyancy"].as_f64().unwrap() / (r.rho * g);
    assert!(
        (volume - r.volume).abs() <= 1e-9 * r.volume,
        "{name}: volume {volume} vs {}",
        r.volume
    );
    let rows: Vec<Vec<f64>> = serde_json::from_value(j["tcm"].clone()).unwrap();
    let ours = DMatrix::from_fn(6, rows[0].len(), |i, k| rows[i][k]);
    let (a, b) = (sorted_singular_values(&ours), sorted_singular_values(&r.t));
    for (x, y) in a.iter().zip(&b) {
        assert!(
            (x - y).abs() < 1e-9,
            "{name}: singular values {a:?} vs {b:?}"
        );
    }
    let rank = b.iter().filter(|s| **s > 1e-6 * b[0]).count();
    assert_eq!(rank, f.rank, "{name}: independent rank");
    assert_eq!(
        j["tcm_rank"].as_u64().unwrap() as usize,
        rank,
        "{name}: inspect rank"
    );
    // Attainable authority under the thrust box: the pure base wrench along each axis
    // (`T u = ±α e_k`), and transport's commanded axes about the centre of mass (roll free).
    let lim = f.thrust_limit.unwrap_or(40.0);
    let c = &j["authority"]["reference_point"];
    for k in 0..3 {
        let x = c[k].as_f64().unwrap();
        assert!(
            close(x, r.com[k], 1e-9),
            "{name}: CoM[{k}] {x} vs {}",
            r.com[k]
        );
    }
    let pure = reading::attainable(&r.t, &[0, 1, 2, 3, 4, 5], lim);
    compare_attainable(name, &j["tcm_scaled"]["attainable"], &pure, lim);
    let about_com = reading::attainable(&reading::about(&r.t, &r.com), &[0, 1, 2, 4, 5], lim);
    compare_attainable(name, &j["authority"]["attainable"], &about_com, lim);
    assert!(
        j["authority"]["attainable"]["positive"][3].is_null(),
        "{name}: roll is free"
    );
    eprintln!("{name}: pure wrench (axis, +, -) {pure:?}; about the CoM {about_com:?}");
    // A short closed loop and a small tcm on the imported design.
    let sim = d.path().join("sim");
    let set = format!("scenario.design=\"{}\"", design.display());
    let o = run(&[
        "simulate",
        "transport-method1",
        "--set",
        &set,
        "--set",
        "scenario.duration=2",
        "--no-plots",
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{name} simulate: {}", stderr(&o));
    let s = common::summary(&sim);
    assert_eq!(s["metrics"]["completed"].as_f64(), Some(1.0), "{name}: {s}");
    let tcm = d.path().join("tcm");
    let o = run(&[
        "tcm",
        design.to_str().unwrap(),
        "--samples",
        "16",
        "--out",
        tcm.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{name} tcm: {}", stderr(&o));
    d
}

#[test]
fn rexrov2_imports_and_matches_an_independent_reading() {
    // 1862.87 kg hull + 39 sensor and propeller links; 1.83826 m³; six thrusters, full rank.
    check(&Fixture {
        name: "rexrov2.urdf",
        rank: 6,
        // The RexROV 2 repository's thruster_manager.yaml: max_thrust 1540 N.
        thrust_limit: Some(1540.0),
        fixed: &[],
        neutral: &[],
    });
}

#[test]
fn bluerov2_imports_and_matches_an_independent_reading() {
    // Six thrusters: four vectored horizontal, two vertical on the lateral axis, so pitch
    // has no authority: rank 5.
    check(&Fixture {
        name: "bluerov2.urdf",
        rank: 5,
        thrust_limit: None,
        fixed: &[],
        neutral: &["bluerov2/camera"],
    });
}

/// The gripper's two finger joints, held fixed so the chain does not branch.
const FINGERS: [&str; 2] = ["oberon7/finger_left_joint", "oberon7/finger_right_joint"];

#[test]
fn rexrov_oberon7_imports_and_matches_an_independent_reading() {
    // UUV Simulator's vehicle-manipulator: the RexROV (8 thrusters, full rank) with the
    // Oberon 7 arm (six revolute joints, UUV cylinder hydrodynamic model per arm link).
    let d = check(&Fixture {
        name: "rexrov_oberon7.urdf",
        rank: 6,
        // uuv_thruster_manager's config/rexrov/thruster_manager.yaml: max_thrust 2000 N.
        thrust_limit: Some(2000.0),
        fixed: &FINGERS,
        // The gripper (end effector, fingers, tips) has no UUV block: neutral at import.
        neutral: &[
            "oberon7/end_effector",
            "oberon7/finger_left",
            "oberon7/finger_tip_left",
            "oberon7/finger_right",
            "oberon7/finger_tip_right",
        ],
    });
    let j = json(&[
        "inspect",
        d.path().join("design.toml").to_str().unwrap(),
        "--format",
        "json",
    ]);
    // Root body + the six arm bodies (azimuth … wrist); the chain's 12 DOF.
    assert_eq!(j["ee_jacobian"][0].as_array().unwrap().len(), 12, "{j}");
}

#[test]
fn a_branching_gripper_is_refused_unless_its_fingers_are_fixed() {
    let o = run(&["design", "import", &format!("{DIR}/rexrov_oberon7.urdf")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("branching tree"), "{}", stderr(&o));
    let o = run(&[
        "design",
        "import",
        &format!("{DIR}/rexrov_oberon7.urdf"),
        "--fix-joint",
        "oberon7/no_such_joint",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no_such_joint"), "{}", stderr(&o));
}

#[test]
fn a_urdf_is_accepted_wherever_a_design_is() {
    let j = json(&[
        "inspect",
        &format!("{DIR}/bluerov2.urdf"),
        "--format",
        "json",
    ]);
    assert_eq!(j["design"], "bluerov2");
}

#[test]
fn a_malformed_urdf_exits_2_naming_the_element_and_its_line() {
    let d = tempfile::tempdir().unwrap();
    let good = std::fs::read_to_string(format!("{DIR}/bluerov2.urdf")).unwrap();
    // Unknown joint type on the tilt joint; a zero axis (the unit tests cover the rest).
    let line_of = |pat: &str| good.lines().position(|l| l.contains(pat)).unwrap() + 1;
    let cases = [
        (
            good.replace(
                "name=\"tilt\" type=\"revolute\"",
                "name=\"tilt\" type=\"hinge\"",
            ),
            format!(
                "{}: <joint name=\"tilt\">: unknown joint type",
                line_of("name=\"tilt\"")
            ),
        ),
        (
            good.replace("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 0 0\"/>"),
            format!(
                "{}: <axis>: axis must be a nonzero vector",
                line_of("<axis xyz=\"0 1 0\"/>")
            ),
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let p = d.path().join(format!("bad{k}.urdf"));
        std::fs::write(&p, text).unwrap();
        let o = run(&["design", "import", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(want.as_str()),
            "want `{want}` in {}",
            stderr(&o)
        );
    }
}

#[test]
fn a_design_file_can_point_at_a_urdf_relative_to_itself() {
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("robots")).unwrap();
    let good = std::fs::read_to_string(format!("{DIR}/bluerov2.urdf")).unwrap();
    std::fs::write(d.path().join("robots/robot.urdf"), &good).unwrap();
    let bad = good.replace(
        "name=\"tilt\" type=\"revolute\"",
        "name=\"tilt\" type=\"hinge\"",
    );
    std::fs::write(d.path().join("robots/bad.urdf"), &bad).unwrap();
    let design = common::write(
        d.path(),
        "design.toml",
        "name = \"mine\"\nurdf = \"robots/robot.urdf\"\nthrust_limit = 55.0\n",
    );
    // The same design as the import with the same options (only the name differs).
    let shown = run(&["design", "show", design.to_str().unwrap()]);
    assert!(shown.status.success(), "{}", stderr(&shown));
    let shown = String::from_utf8(shown.stdout).unwrap();
    let imported = run(&[
        "design",
        "import",
        &format!("{DIR}/bluerov2.urdf"),
        "--thrust-limit",
        "55",
    ]);
    let imported = String::from_utf8(imported.stdout).unwrap();
    let body = |s: &str| -> String {
        s.lines()
            .filter(|l| {
                !l.starts_with('#')
                    && !l.starts_with("name = \"mine\"")
                    && !l.starts_with("name = \"bluerov2\"")
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(body(&shown), body(&imported));
    assert!(
        shown.contains("name = \"mine\"") && shown.contains("u_max = 55.0"),
        "{shown}"
    );
    let j = json(&["inspect", design.to_str().unwrap(), "--format", "json"]);
    assert_eq!(j["design"], "mine");
    // Located errors: the design file's key and line, or the URDF's element and line.
    let cases = [
        (
            "urdf = \"robots/missing.urdf\"\n",
            "e0.toml:1:1: urdf: no URDF file".to_string(),
        ),
        (
            "# a comment\nurdf = \"robots/bad.urdf\"\n",
            format!(
                "robots/bad.urdf:{}: <joint name=\"tilt\">: unknown joint type `hinge` (the URDF named by `urdf` at ",
                bad.lines().position(|l| l.contains("name=\"tilt\"")).unwrap() + 1
            ),
        ),
        (
            "preset = \"usm-paper\"\nthrust_limit = 5.0\n",
            "e2.toml:2:1: thrust_limit: only with `urdf`".to_string(),
        ),
        (
            "urdf = \"robots/robot.urdf\"\n[fluid]\nrho = 1000.0\n",
            "fluid: not allowed with `urdf`".to_string(),
        ),
        (
            "urdf = \"robots/robot.urdf\"\nfixed_joints = [\"nope\"]\n",
            "no joint of that name".to_string(),
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let p = common::write(d.path(), &format!("e{k}.toml"), text);
        let o = run(&["inspect", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(want.as_str()),
            "want `{want}` in {}",
            stderr(&o)
        );
    }
}

#[test]
fn the_uvms_study_sweeps_the_arm_mount_of_a_urdf_design() {
    // studies/uvms_urdf.toml: a pointer-form design, its arm's first joint moved by a sweep
    // axis; the file's own mount (x = 1.3 m) holds station and reaches the work point, the
    // aftmost (x = 0.7 m) cannot reach it within the tolerance.
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("uvms");
    let o = common::sweep(Path::new("studies/uvms_urdf.toml"), &out, &[]);
    assert!(o.status.code().is_some(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    let mut rows = text.lines();
    let head: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (x, y, st) = (
        col("design.joint[0].position[0]"),
        col("design.joint[0].position[1]"),
        col("status"),
    );
    let status = |xv: &str, yv: &str| -> String {
        text.lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .find(|r| {
                r[x].parse::<f64>().unwrap() == xv.parse::<f64>().unwrap()
                    && r[y].parse::<f64>().unwrap() == yv.parse::<f64>().unwrap()
            })
            .map(|r| r[st].to_string())
            .unwrap()
    };
    assert_eq!(text.lines().count(), 16, "15 cases");
    assert_eq!(status("1.3", "-0.5"), "ok");
    assert_eq!(status("0.7", "-0.5"), "unsuccessful");
}

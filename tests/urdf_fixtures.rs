//! Two public vehicle descriptions nobody here wrote (tests/fixtures/urdf/README.md): the UUV
//! Simulator RexROV 2 (UUV plugin blocks) and a BlueROV2 (gz-sim Hydrodynamics and Thruster
//! systems). `design import` succeeds; `inspect`'s totals (mass, volume, T(q) singular values
//! and rank) equal a reading of the file written here independently of the importer (its own
//! XML walk, no usm-study code); each runs a short `simulate` and a small `tcm`.

mod common;

use common::{json, run, stderr};
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::path::Path;

const DIR: &str = "tests/fixtures/urdf";

fn floats(s: &str) -> Vec<f64> {
    s.split_whitespace().map(|t| t.parse().unwrap()).collect()
}

fn rpy(v: &[f64]) -> Matrix3<f64> {
    let (r, p, y) = (v[0], v[1], v[2]);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, r.cos(), -r.sin(), 0.0, r.sin(), r.cos());
    let ry = Matrix3::new(p.cos(), 0.0, p.sin(), 0.0, 1.0, 0.0, -p.sin(), 0.0, p.cos());
    let rz = Matrix3::new(y.cos(), -y.sin(), 0.0, y.sin(), y.cos(), 0.0, 0.0, 0.0, 1.0);
    rz * ry * rx
}

/// What the file says, read directly: total mass, displaced volume, fluid density and the
/// thruster matrix at rest (thrusters on the root link: column `[d; p × d]`).
struct Reading {
    mass: f64,
    volume: f64,
    rho: f64,
    t: DMatrix<f64>,
}

fn read(name: &str) -> Reading {
    let text = std::fs::read_to_string(Path::new(DIR).join(name)).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let txt = |n: roxmltree::Node| n.text().unwrap().trim().to_string();
    let robot = doc.root_element();
    let links: Vec<_> = robot
        .children()
        .filter(|c| c.has_tag_name("link"))
        .collect();
    let mass: f64 = links
        .iter()
        .filter_map(|l| el(l, "inertial"))
        .map(|i| {
            el(&i, "mass")
                .unwrap()
                .attribute("value")
                .unwrap()
                .parse::<f64>()
                .unwrap()
        })
        .sum();
    let plugins: Vec<_> = robot
        .descendants()
        .filter(|c| c.has_tag_name("plugin"))
        .collect();
    let uuv = plugins.iter().find(|p| {
        p.attribute("filename")
            .unwrap()
            .contains("underwater_object")
    });
    let (rho, volume) = match uuv {
        // UUV Simulator: the plugin's fluid density and the volume of its link blocks.
        Some(p) => {
            let rho: f64 = txt(el(p, "fluid_density").unwrap()).parse().unwrap();
            let v: f64 = p
                .children()
                .filter(|c| c.has_tag_name("link"))
                .map(|l| txt(el(&l, "volume").unwrap()).parse::<f64>().unwrap())
                .sum();
            (rho, v)
        }
        // gz-sim: the Buoyancy system's collision volumes; a body without any (the camera on
        // its tilt joint) is neutral, m/ρ; ρ from the thrusters' fluid_density.
        None => {
            let rho: f64 = plugins
                .iter()
                .find_map(|p| el(p, "fluid_density"))
                .map(|n| txt(n).parse().unwrap())
                .unwrap();
            let mut v = 0.0;
            for l in &links {
                for c in l.children().filter(|c| c.has_tag_name("collision")) {
                    let g = el(&el(&c, "geometry").unwrap(), "box")
                        .map(|b| floats(b.attribute("size").unwrap()).iter().product::<f64>())
                        .or_else(|| {
                            el(&el(&c, "geometry").unwrap(), "cylinder").map(|y| {
                                let r: f64 = y.attribute("radius").unwrap().parse().unwrap();
                                let h: f64 = y.attribute("length").unwrap().parse().unwrap();
                                std::f64::consts::PI * r * r * h
                            })
                        });
                    v += g.unwrap_or(0.0);
                }
            }
            let camera = links
                .iter()
                .find(|l| l.attribute("name") == Some("bluerov2/camera"));
            let m: f64 = el(&el(camera.unwrap(), "inertial").unwrap(), "mass")
                .unwrap()
                .attribute("value")
                .unwrap()
                .parse()
                .unwrap();
            (rho, v + m / rho)
        }
    };
    // Thruster joints in the order of their plugins.
    let joint_names: Vec<String> = plugins
        .iter()
        .filter(|p| p.attribute("filename").unwrap().contains("thruster"))
        .filter_map(|p| el(p, "jointName").or_else(|| el(p, "joint_name")).map(txt))
        .collect();
    let mut cols = Vec::new();
    for jn in &joint_names {
        let j = robot
            .children()
            .find(|c| c.has_tag_name("joint") && c.attribute("name") == Some(jn.as_str()))
            .unwrap();
        let o = el(&j, "origin").unwrap();
        let p = Vector3::from_vec(floats(o.attribute("xyz").unwrap()));
        let a = Vector3::from_vec(floats(el(&j, "axis").unwrap().attribute("xyz").unwrap()));
        let d = rpy(&floats(o.attribute("rpy").unwrap())) * a.normalize();
        let m = p.cross(&d);
        cols.extend([d.x, d.y, d.z, m.x, m.y, m.z]);
    }
    let t = DMatrix::from_column_slice(6, joint_names.len(), &cols);
    Reading {
        mass,
        volume,
        rho,
        t,
    }
}

fn el<'a, 'i>(n: &roxmltree::Node<'a, 'i>, tag: &str) -> Option<roxmltree::Node<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(tag))
}

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

fn check(name: &str, expect_rank: usize) {
    let d = tempfile::tempdir().unwrap();
    let design = d.path().join("design.toml");
    let urdf = format!("{DIR}/{name}");
    let o = run(&["design", "import", &urdf, "--out", design.to_str().unwrap()]);
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let r = read(name);
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
    assert_eq!(rank, expect_rank, "{name}: independent rank");
    assert_eq!(
        j["tcm_rank"].as_u64().unwrap() as usize,
        rank,
        "{name}: inspect rank"
    );
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
}

#[test]
fn rexrov2_imports_and_matches_an_independent_reading() {
    // 1862.87 kg hull + 39 sensor and propeller links; 1.83826 m³; six thrusters, full rank.
    check("rexrov2.urdf", 6);
}

#[test]
fn bluerov2_imports_and_matches_an_independent_reading() {
    // Six thrusters: four vectored horizontal, two vertical on the lateral axis, so pitch
    // has no authority: rank 5.
    check("bluerov2.urdf", 5);
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

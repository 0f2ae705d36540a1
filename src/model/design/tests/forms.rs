//! The three forms of a design file, the explicit form's round trip and the examples.

use super::*;

#[test]
fn presets_round_trip() {
    for p in PRESETS {
        let v = presets::preset(p).unwrap();
        let back = round_trip(&v).unwrap();
        close(&v, &back, 1e-12).unwrap();
        // Floats other than angles come back bit-exact.
        assert_eq!(v.bodies, back.bodies, "{p}");
        assert_eq!(v.thrusters, back.thrusters, "{p}");
        assert_eq!(v.fluid, back.fluid, "{p}");
        assert_eq!(v.joints, back.joints, "{p}");
    }
}

#[test]
fn preset_form_and_load_design() {
    let v = parse_design("preset = \"usm-paper\"\nname = \"mine\"\n", "p.toml").unwrap();
    assert_eq!(v.name, "mine");
    assert_eq!(v.bodies, usm_paper().bodies);
    let v = load_design("uvms-planar").unwrap();
    assert_eq!(v.n_joints(), 3);
    let e = load_design("no/such/file.toml").unwrap_err();
    assert_eq!(e.error.kind, DesignErrorKind::NotFound);
    assert!(e.to_string().contains("usm-paper"), "{e}");
    assert!(e.to_string().contains("no design file"), "{e}");
    let e = parse_design("preset = \"nope\"\n", "p.toml").unwrap_err();
    assert_eq!((e.at.key.as_str(), e.at.line), ("preset", Some(1)));
    // A file on disk.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.toml");
    std::fs::write(&path, design_to_toml(&usm_paper())).unwrap();
    let v = load_design(path.to_str().unwrap()).unwrap();
    close(&v, &usm_paper(), 1e-12).unwrap();
}

const SMALL: &str = r#"
name = "small"

[fluid]
rho = 1000
current = [0.1, 0, 0]

[[body]]
name = "tail"
mass = 10
length = 0.5
radius = 0.1
neutral = true

[[body]]
name = "mid"
mass = 5.0
length = 0.2
radius = 0.1
cg = [0.1, 0.0, -0.01]
[body.hydro]
kind = "coefficients"
added_mass = [
  [1, 0, 0, 0, 0, 0],
  [0, 2, 0, 0, 0, 0],
  [0, 0, 2, 0, 0, 0],
  [0, 0, 0, 0, 0, 0],
  [0, 0, 0, 0, 0.1, 0],
  [0, 0, 0, 0, 0, 0.1],
]

[[body]]
name = "head"
mass = 3
length = 0.3
radius = 0.05
volume = 0.002
inertia = [[0.01, 0, 0], [0, 0.03, 0], [0, 0, 0.03]]
[body.hydro]
cd_x = 0.5
strips = 3

[[joint]]
name = "yaw"
axis = [0, 0, 2]

[[joint]]
axis = [0, 1, 0]
position = [0.25, 0, 0]
rpy_deg = [0, 0, 90]
limits_deg = [-45, 30]

[[thruster]]
body = "mid"
position = [0.1, 0, 0.05]
direction = [0, 3, 4]

[[thruster]]
name = "aft"
body = 2
position = [0.1, 0, 0]
direction = [1, 0, 0]
u_min = -10
u_max = 20
time_constant = 0.1
rate_limit = 100

[end_effector]
position = [0.3, 0, 0]
rpy_deg = [0, -90, 0]
"#;

#[test]
fn explicit_small_file() {
    let v = parse_design(SMALL, "small.toml").unwrap();
    assert_eq!((v.bodies.len(), v.n_joints(), v.n_thrusters()), (3, 2, 2));
    assert_eq!(v.fluid.rho, 1000.0);
    assert_eq!(v.fluid.g, GRAVITY_DEFAULT);
    assert_eq!(v.bodies[0].volume, 10.0 / 1000.0);
    assert_eq!(v.bodies[1].cg, Vec3::new(0.1, 0.0, -0.01));
    assert_eq!(v.bodies[1].cb, Vec3::new(0.1, 0.0, 0.0));
    assert!(matches!(v.bodies[1].hydro, Hydro::Coefficients { .. }));
    assert_eq!(v.bodies[2].volume, 0.002);
    assert_eq!(v.bodies[2].inertia[(1, 1)], 0.03);
    match &v.bodies[2].hydro {
        Hydro::Cylinder {
            cd_x, cd_y, strips, ..
        } => {
            assert_eq!((*cd_x, *cd_y, *strips), (0.5, 1.0, 3));
        }
        _ => panic!("cylinder expected"),
    }
    assert_eq!(v.joints[0].axis, Vec3::z());
    assert_eq!(v.joints[0].name, "yaw");
    assert_eq!(v.joints[0].placement.p, Vec3::new(0.5, 0.0, 0.0));
    assert!((v.joints[0].max - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(v.joints[1].name, "q2");
    assert!((v.joints[1].placement.r * Vec3::x() - Vec3::y()).norm() < 1e-15);
    assert!((v.joints[1].min + 45f64.to_radians()).abs() < 1e-15);
    assert_eq!(v.thrusters[0].name, "T1");
    assert_eq!(v.thrusters[0].body, 1);
    assert!((v.thrusters[0].direction - Vec3::new(0.0, 0.6, 0.8)).norm() < 1e-15);
    assert_eq!((v.thrusters[0].u_min, v.thrusters[0].u_max), (-40.0, 40.0));
    assert_eq!(v.thrusters[1].body, 2);
    assert_eq!(v.thrusters[1].time_constant, Some(0.1));
    assert!((v.end_effector.r * Vec3::x() - Vec3::z()).norm() < 1e-15);
    // And it round-trips (gimbal-lock rpy included).
    close(&v, &round_trip(&v).unwrap(), 1e-12).unwrap();
}

const GRAVITY_DEFAULT: f64 = crate::model::GRAVITY;

#[test]
fn generator_files() {
    let text = "name = \"g4\"\n[generator]\nlinks = 4\nlink_length = [0.5, 0.6, 0.7, 0.4]\n\
                thruster_rule = \"distributed\"\njoint_limit_deg = 60\n";
    let v = parse_design(text, "g.toml").unwrap();
    let spec = GeneratorSpec {
        links: 4,
        link_length: vec![0.5, 0.6, 0.7, 0.4],
        thruster_rule: ThrusterRule::Distributed,
        joint_limit: 60f64.to_radians(),
        ..Default::default()
    };
    assert_eq!(v, spec.build("g4").unwrap());
    assert_eq!((v.bodies.len(), v.n_joints(), v.n_thrusters()), (7, 6, 6));
    // USM Table II from the generator; lengths cannot be given beside the profile.
    let v = parse_design("[generator]\nbody_profile = \"paper\"\n", "p.toml").unwrap();
    assert!((v.total_mass() - 81.3).abs() < 1e-9 && (v.total_length() - 3.3).abs() < 1e-9);
    let e = parse_design(
        "[generator]\nbody_profile = \"paper\"\nlink_length = 0.5\n",
        "p.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("generator.link_length") && e.contains("Table II"),
        "{e}"
    );
    let e = parse_design("[generator]\nbody_profile = \"tabel\"\n", "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("uniform, paper"), "{e}");
    // Defaults only; name from the file stem.
    let v = parse_design("[generator]\n", "designs/usm5.toml").unwrap();
    assert_eq!(v, GeneratorSpec::default().build("usm5").unwrap());
    // Generator + explicit thrusters: the list replaces the rule's thrusters.
    let text = "[generator]\nlinks = 3\nlink_length = 0.5\nthruster_rule = \"paper\"\n\
                [fluid]\ncurrent = [0.2, 0, 0]\n\
                [[thruster]]\nbody = \"L1\"\nposition = [0.25, 0, 0]\ndirection = [0, 1, 0]\n\
                [[thruster]]\nbody = 0\nposition = [0.25, 0, 0]\ndirection = [0, 0, -1]\n";
    let v = parse_design(text, "gt.toml").unwrap();
    assert_eq!(v.n_thrusters(), 2);
    assert_eq!(v.thrusters[0].body, 2);
    assert_eq!(v.thrusters[1].direction, -Vec3::z());
    assert_eq!(v.bodies.len(), 5);
    assert_eq!(v.fluid.current, Vec3::new(0.2, 0.0, 0.0));
}

/// Parse `text` expecting an error at `key` on `line`; returns the error.
#[track_caller]
#[test]
fn example_designs_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/designs");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) == Some("toml") {
            let v = load_design(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
            v.validate().unwrap();
            close(&v, &round_trip(&v).unwrap(), 1e-12).unwrap();
            n += 1;
        }
    }
    assert!(n >= 2, "expected example designs in {}", dir.display());
}

#[test]
fn rpy_inverse_and_degrees() {
    for rpy in [
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(-3.0, 1.5, 2.9),
        Vec3::new(0.0, std::f64::consts::FRAC_PI_2, 0.7),
        Vec3::new(0.0, -std::f64::consts::FRAC_PI_2, -0.7),
    ] {
        let r = rot_rpy(&rpy);
        assert!((rot_rpy(&rpy_of(&r)) - r).abs().max() < 1e-14, "{rpy:?}");
    }
    for x in [
        std::f64::consts::FRAC_PI_2,
        1.0,
        -0.3,
        1e-5,
        std::f64::consts::PI,
    ] {
        assert_eq!(deg(x).to_radians(), x);
    }
    assert_eq!(fnum(1.0), "1.0");
    assert_eq!(fnum(1e300), "1e300");
    let t: toml::Table = toml::from_str("a = 1e300\nb = 1e-7").unwrap();
    assert_eq!(t["a"].as_float(), Some(1e300));
}

//! The hull drag of docs/model.md §2 (issue 44): the paper's body against a hand estimate
//! written out here, and the drag of a body that does not depend on how many links it is cut
//! into.

use std::f64::consts::PI;
use usm_study::model::generator::{BodyProfile, GeneratorSpec, ThrusterRule};
use usm_study::model::{presets, Hydro};
use usm_study::paper::published_drag::cruise_drag;

const RHO: f64 = 1026.0;
const NU: f64 = 1.19e-6;

/// ITTC-57: C_F = 0.075 / (log10 Re − 2)².
fn ittc57(re: f64) -> f64 {
    0.075 / (re.log10() - 2.0).powi(2)
}

#[test]
fn usm_paper_cruise_drag_matches_the_hull_estimate() {
    // usm-paper: 3.300 m, r = 0.085 m, 7 thrusters (2 longitudinal pods, 5 tunnels), 8 joints.
    let (u, l, r) = (0.5, 3.3, 0.085);
    let q = 0.5 * RHO * u * u;
    let d = 2.0 * r;
    // Skin friction on the side area at the whole body's Reynolds number, with Hoerner's
    // form factor for d/L = 0.0515 (1.019).
    let re = u * l / NU;
    let k = 1.0 + 1.5 * (d / l).powf(1.5) + 7.0 * (d / l).powi(3);
    let friction = q * ittc57(re) * k * 2.0 * PI * r * l;
    // Form drag at the free ends only: a flat nose C_d 0.8 and a blunt base 0.1 on πr².
    let form = q * (0.8 + 0.1) * PI * r * r;
    // Appendages: C_D·A 3.2e-3 m² per pod, 7.7e-4 per tunnel thruster, 2.7e-4 per joint gap.
    let appendages = q * (2.0 * 3.2e-3 + 5.0 * 7.7e-4 + 8.0 * 2.7e-4);
    // Linear damping 0.1 N·s/m per metre of body in surge.
    let linear = 0.1 * l * u;
    let hand = friction + form + appendages + linear;
    // The values the issue's clean blunt cylinder (friction + nose 0.8) stated: 3.32 N.
    assert!(
        (friction / k + q * 0.8 * PI * r * r - 3.32).abs() < 0.01,
        "{friction}"
    );
    let model = cruise_drag(&presets::usm_paper(), u);
    assert!(
        (model / hand - 1.0).abs() < 0.3,
        "model {model} N, hand {hand} N"
    );
    // And the model is that formula, not merely near it (sums of a few terms: 1e-9).
    assert!(
        (model - hand).abs() < 1e-9 * hand,
        "model {model} N, hand {hand} N"
    );
    // The per-body model charged 11.20 N here (issue 44); the hull drag about half.
    assert!(model < 0.6 * 11.20, "{model}");
}

/// A uniform body of `links` links and total length `total` [m] (modules 0.104 m), radius
/// 0.085 m, the `ends` thruster rule (6 thrusters whatever the link count).
fn uniform(links: usize, total: f64) -> usm_study::model::Vehicle {
    let module = 0.104;
    let link = (total - (links - 1) as f64 * module) / links as f64;
    GeneratorSpec {
        links,
        link_length: vec![link],
        body_profile: BodyProfile::Uniform,
        thruster_rule: ThrusterRule::Ends,
        ..GeneratorSpec::default()
    }
    .build("uniform")
    .unwrap()
}

#[test]
fn four_and_nine_links_of_one_length_have_nearly_the_same_drag() {
    let total = 6.05;
    let (four, nine) = (uniform(4, total), uniform(9, total));
    assert!((four.total_length() - total).abs() < 1e-12);
    assert!((nine.total_length() - total).abs() < 1e-12);
    assert_eq!(four.n_thrusters(), nine.n_thrusters());
    let u = 0.5;
    let (d4, d9) = (cruise_drag(&four, u), cruise_drag(&nine, u));
    // The only difference is the joint-gap allowance: 16 − 6 = 10 more gaps of C_D·A
    // 2.7e-4 m², i.e. ½ρu² · 10 · 2.7e-4 = 0.346 N.
    let gaps = 0.5 * RHO * u * u * 10.0 * 2.7e-4;
    assert!((d9 - d4 - gaps).abs() < 1e-9, "{d4} {d9} {gaps}");
    assert!(d9 / d4 < 1.1, "{d4} {d9}");
    // Under the per-body model the same pair differed by 2.4 times the 4-link drag's
    // quadratic axial part of the inner bodies and 10 more linear dampers.
    let per_body = |v: &usm_study::model::Vehicle| {
        let mut v = v.clone();
        let n = v.bodies.len();
        for (i, b) in v.bodies.iter_mut().enumerate() {
            b.hydro = Hydro::cylinder(if i == 0 || i + 1 == n { 0.8 } else { 0.1 }, 1.0);
        }
        cruise_drag(&v, u)
    };
    let (o4, o9) = (per_body(&four), per_body(&nine));
    assert!(o9 / o4 > 1.4, "{o4} {o9}");
}

#[test]
fn an_explicit_per_body_cd_x_in_a_design_file_means_what_it_says() {
    // A body with `cd_x` keeps the per-body form −½ρ C_d,x πr² |u| u + 1 N·s/m; one without
    // takes the hull drag.
    let text = r#"
name = "two"
[[body]]
name = "a"
mass = 10.0
length = 0.5
radius = 0.085
neutral = true
[body.hydro]
cd_x = 0.8
[[body]]
name = "b"
mass = 10.0
length = 0.5
radius = 0.085
neutral = true
[[joint]]
axis = [0.0, 0.0, 1.0]
"#;
    let dir = std::env::temp_dir().join(format!("hull_drag_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("two.toml");
    std::fs::write(&path, text).unwrap();
    let v = usm_study::model::design::load_design(path.to_str().unwrap()).unwrap();
    let axial = |h: &Hydro| match h {
        Hydro::Cylinder {
            cd_x,
            hull,
            linear_damping,
            ..
        } => (*cd_x, hull.is_some(), linear_damping[0]),
        other => panic!("{other:?}"),
    };
    assert_eq!(axial(&v.bodies[0].hydro), (0.8, false, 1.0));
    assert_eq!(axial(&v.bodies[1].hydro), (0.0, true, 0.1 * 0.5));
    // A hull key next to `cd_x` without `hull = true` is refused, naming the key.
    let bad = text.replace("cd_x = 0.8", "cd_x = 0.8\nnose_cd = 0.3");
    std::fs::write(&path, bad).unwrap();
    let err = usm_study::model::design::load_design(path.to_str().unwrap()).unwrap_err();
    assert!(err.to_string().contains("body[0].hydro.nose_cd"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

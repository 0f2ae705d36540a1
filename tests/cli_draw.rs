//! End-to-end tests of `usm-study design draw`: the drawn thrust arrows start at the design's
//! thruster positions projected into each view (straight and bent), point along the docs/model.md §2
//! directions, the SVG is deterministic, every preset and example design draws, and bad
//! inputs exit with code 2 naming the file.
//!
//! The SVG is read through its documented structure (`src/report/drawing/mod.rs`): each
//! `<g class="view" id="view-V">` carries its transform `x = x0 + scale·u`, `y = y0 − scale·v`,
//! each `<g class="thruster" id="V-NAME">` its projected start `data-x1 data-y1` and tip
//! `data-x2 data-y2` in px.

mod common;

use common::{arg, read, run, stderr, write};
use std::collections::BTreeMap;
use usm_study::kinematics::{forward_kinematics, KinWorkspace};
use usm_study::model::design::load_design;
use usm_study::state::{load_state, VehicleState};

/// The value of attribute `name` in the element text `tag`.
fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(tag[start..end].to_string())
}

fn num(tag: &str, name: &str) -> f64 {
    attr(tag, name)
        .unwrap_or_else(|| panic!("{name} in {tag}"))
        .parse()
        .unwrap()
}

/// A view's transform and its thruster groups (name → the opening tag and the next line).
struct View {
    scale: f64,
    x0: f64,
    y0: f64,
    thrusters: BTreeMap<String, (String, String)>,
}

impl View {
    /// View coordinates [m] → SVG px.
    fn to_svg(&self, u: f64, v: f64) -> (f64, f64) {
        (self.x0 + self.scale * u, self.y0 - self.scale * v)
    }
}

/// The three views of a drawing, by id (`top`, `side`, `front`).
fn views(svg: &str) -> BTreeMap<String, View> {
    let mut out = BTreeMap::new();
    let lines: Vec<&str> = svg.lines().map(str::trim).collect();
    let mut current = String::new();
    for (i, l) in lines.iter().enumerate() {
        if l.starts_with("<g class=\"view\"") {
            current = attr(l, "id")
                .unwrap()
                .trim_start_matches("view-")
                .to_string();
            let v = View {
                scale: num(l, "data-scale"),
                x0: num(l, "data-x0"),
                y0: num(l, "data-y0"),
                thrusters: BTreeMap::new(),
            };
            out.insert(current.clone(), v);
        } else if let Some(name) = attr(l, "data-thruster") {
            let id = attr(l, "id").unwrap();
            assert_eq!(id, format!("{current}-{name}"));
            let next = lines[i + 1].to_string();
            let view = out.get_mut(&current).unwrap();
            view.thrusters.insert(name, (l.to_string(), next));
        }
    }
    out
}

/// Every thruster of the design at `state` is drawn in every view starting at its position
/// (forward kinematics, then the view's projection), the `<line>`, if any, from that point.
fn check_arrow_starts(design: &str, svg: &str, state: &VehicleState) {
    let v = load_design(design).unwrap();
    let mut ws = KinWorkspace::new(&v);
    forward_kinematics(&v, &state.q, &mut ws);
    let g_ib = state.base.to_se3();
    let views = views(svg);
    assert_eq!(views.len(), 3);
    for (id, (iu, iv)) in [("top", (0, 1)), ("side", (0, 2)), ("front", (1, 2))] {
        let view = &views[id];
        assert_eq!(view.thrusters.len(), v.n_thrusters(), "{id}");
        for t in &v.thrusters {
            let p = g_ib.compose(&ws.g_b[t.body]).act_point(&t.position);
            let (x, y) = view.to_svg(p[iu], p[iv]);
            let (group, next) = &view.thrusters[&t.name];
            let (x1, y1) = (num(group, "data-x1"), num(group, "data-y1"));
            assert!(
                (x1 - x).abs() < 0.006 && (y1 - y).abs() < 0.006,
                "{id} {}: {group}",
                t.name
            );
            if next.starts_with("<line") {
                assert_eq!((num(next, "x1"), num(next, "y1")), (x1, y1), "{next}");
            }
        }
    }
}

fn draw(args: &[&str]) -> String {
    let out = run(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    let i = args.iter().position(|a| *a == "--out").unwrap();
    String::from_utf8(read(std::path::Path::new(args[i + 1]))).unwrap()
}

#[test]
fn usm_paper_arrows_start_at_the_thrusters_and_point_along_spec_directions() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("usm-paper.svg");
    let svg = draw(&["design", "draw", "usm-paper", "--out", arg(&out)]);
    let v = load_design("usm-paper").unwrap();
    check_arrow_starts("usm-paper", &svg, &VehicleState::rest(&v));
    let views = views(&svg);
    // docs/model.md §2: T3 sits on L2 (body 4, starting at 0.62 + 0.104 + 0.584 + 0.104 = 1.412 m),
    // 0.278 m along it and 0.10 m to starboard (−y).
    let top = &views["top"];
    let (x, y) = top.to_svg(1.412 + 0.278, -0.10);
    let t3 = &top.thrusters["T3"].0;
    assert!((num(t3, "data-x1") - x).abs() < 0.006 && (num(t3, "data-y1") - y).abs() < 0.006);
    // Directions: T2, T6 lateral (+y), T1, T5, T7 vertical (+z), T3, T4 longitudinal (+x).
    let delta = |view: &str, name: &str| {
        let g = &views[view].thrusters[name].0;
        (
            num(g, "data-x2") - num(g, "data-x1"),
            num(g, "data-y2") - num(g, "data-y1"),
        )
    };
    let (along_x, along_up, end_on) = (
        |d: (f64, f64)| d.0 > 10.0 && d.1.abs() < 0.01,
        |d: (f64, f64)| d.1 < -10.0 && d.0.abs() < 0.01,
        |d: (f64, f64)| d.0.abs() < 0.01 && d.1.abs() < 0.01,
    );
    for name in ["T2", "T6"] {
        assert!(
            along_up(delta("top", name)),
            "{name} along +y in the top view"
        );
        assert!(
            end_on(delta("side", name)),
            "{name} end-on in the side view"
        );
    }
    for name in ["T1", "T5", "T7"] {
        assert!(end_on(delta("top", name)), "{name} end-on in the top view");
        assert!(
            along_up(delta("side", name)),
            "{name} along +z in the side view"
        );
        assert!(
            along_up(delta("front", name)),
            "{name} along +z in the front view"
        );
    }
    for name in ["T3", "T4"] {
        assert!(
            along_x(delta("top", name)) && along_x(delta("side", name)),
            "{name}"
        );
        assert!(
            end_on(delta("front", name)),
            "{name} end-on in the front view"
        );
    }
    // The caption: the scaled singular values and the lost roll of the straight USM.
    assert!(svg.contains("rank 5 of 6; lost"), "caption");
    assert!(svg.contains("): roll</text>"), "lost roll");
}

#[test]
fn a_bent_state_moves_the_arrows_as_forward_kinematics_says_and_bytes_are_stable() {
    let dir = tempfile::tempdir().unwrap();
    let state = write(
        dir.path(),
        "bent.json",
        r#"{"base_position": [0.5, -0.2, 1.0],
            "base_rotation": [[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]],
            "joint_angles": [0.6, 0.3, -0.5, -0.4, 0.7, 0.2, 0.4, -0.3]}"#,
    );
    let a = dir.path().join("a.svg");
    let b = dir.path().join("b.svg");
    let args = |o| {
        [
            "design",
            "draw",
            "usm-paper",
            "--state",
            arg(&state),
            "--out",
            o,
        ]
    };
    let svg = draw(&args(arg(&a)));
    let again = draw(&args(arg(&b)));
    assert_eq!(svg, again, "same input, same bytes");
    let v = load_design("usm-paper").unwrap();
    let s = load_state(&state, &v).unwrap();
    check_arrow_starts("usm-paper", &svg, &s);
    let straight = draw(&[
        "design",
        "draw",
        "usm-paper",
        "--out",
        arg(&dir.path().join("s.svg")),
    ]);
    assert_ne!(
        views(&svg)["top"].thrusters["T6"].0,
        views(&straight)["top"].thrusters["T6"].0
    );
}

#[test]
fn every_preset_and_example_design_draws() {
    let dir = tempfile::tempdir().unwrap();
    let mut designs: Vec<String> = vec!["usm-paper".into(), "uvms-planar".into()];
    for e in std::fs::read_dir("studies/designs").unwrap() {
        designs.push(e.unwrap().path().display().to_string());
    }
    designs.sort();
    for (k, d) in designs.iter().enumerate() {
        let out = dir.path().join(format!("{k}.svg"));
        let svg = draw(&["design", "draw", d, "--out", arg(&out)]);
        assert!(svg.contains("id=\"scale-bar\""), "{d}");
        check_arrow_starts(d, &svg, &VehicleState::rest(&load_design(d).unwrap()));
    }
}

#[test]
fn twenty_links_fit_and_no_thrusters_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let long = write(
        dir.path(),
        "long.toml",
        "name = \"usm20\"\n[generator]\nlinks = 20\nthruster_rule = \"distributed\"\n",
    );
    let svg = draw(&[
        "design",
        "draw",
        arg(&long),
        "--out",
        arg(&dir.path().join("l.svg")),
    ]);
    let width: f64 = attr(svg.lines().nth(1).unwrap(), "width")
        .unwrap()
        .parse()
        .unwrap();
    let top = &views(&svg)["top"];
    for (group, _) in top.thrusters.values() {
        let x = num(group, "data-x2");
        assert!(x > 0.0 && x < width, "{group}");
    }
    let bare = write(
        dir.path(),
        "bare.toml",
        "name = \"bare\"\n[generator]\nlinks = 3\nthruster_rule = \"none\"\n",
    );
    let svg = draw(&[
        "design",
        "draw",
        arg(&bare),
        "--out",
        arg(&dir.path().join("b.svg")),
    ]);
    assert!(svg.contains("no thrusters: T(q) has no columns"), "caption");
    assert!(views(&svg)["top"].thrusters.is_empty());
}

#[test]
fn bad_inputs_exit_2_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let state = write(dir.path(), "s.json", r#"{"joint_angles": [0, 0]}"#);
    let out = run(&["design", "draw", "usm-paper", "--state", arg(&state)]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(e.contains("s.json") && e.contains("joint_angles"), "{e}");
    let design = write(
        dir.path(),
        "d.toml",
        "name = \"x\"\n[generator]\nlinks = 1\n",
    );
    let out = run(&[
        "design",
        "draw",
        arg(&design),
        "--out",
        arg(&dir.path().join("x.svg")),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let e = stderr(&out);
    assert!(e.contains("d.toml:3") && e.contains("links"), "{e}");
    // A directory that cannot exist (its parent is a file): exit 2 naming the path.
    let target = state.join("u.svg");
    let out = run(&["design", "draw", "usm-paper", "--out", arg(&target)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains(arg(&state)), "{}", stderr(&out));
    assert!(!target.exists());
    // A directory that does not exist yet is created, as other verbs' `--out` are.
    let target = dir.path().join("missing").join("u.svg");
    let out = run(&["design", "draw", "usm-paper", "--out", arg(&target)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(target.is_file());
}

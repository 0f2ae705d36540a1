//! Hydrostatics as part of the design, and worlds that break the symmetry (issue 36 items 1–2):
//! `inspect` reports the wet weight, the restoring moments per radian, the metacentric height
//! and the trim; `design show` and `design draw` write and draw them; the world keys
//! (`physics.current_vertical`, `hydro.cb_offset_z`/`_x`, `mission.payload_wet_weight`) are
//! refused out of range with the file and the key.

mod common;

use common::{arg, json, run, stderr, write};

#[test]
fn inspect_reports_the_hydrostatics_of_usm_paper_and_of_a_generated_design() {
    // usm-paper: neutral with CB = CG in every body (the paper's "wet mass 0", inferred): zero
    // wet weight and zero restoring moments, no trim attitude.
    let j = json(&["inspect", "usm-paper", "--format", "json"]);
    let h = &j["hydrostatics"];
    for key in [
        "wet_weight",
        "roll_restoring_moment",
        "pitch_restoring_moment",
        "metacentric_height",
        "weight",
        "buoyancy",
    ] {
        assert!(h[key].as_f64().is_some(), "{key}: {h}");
    }
    assert!(h["wet_weight"].as_f64().unwrap().abs() < 1e-9);
    assert!(h["roll_restoring_moment"].as_f64().unwrap().abs() < 1e-9);
    assert!(h["trim_roll_deg"].is_null());
    assert_eq!(h["bodies"].as_array().unwrap().len(), 9);

    // A generated design: the default metacentric height 0.02 m in every body, so the vehicle's
    // restoring moment per radian is B · 0.02 in roll and pitch, level trim.
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "g.toml",
        "name = \"g\"\n[generator]\nlinks = 4\nbody_profile = \"paper\"\nthruster_rule = \"ends\"\n\
         wet_weight = 3.0\n",
    );
    let j = json(&["inspect", arg(&p), "--format", "json"]);
    let h = &j["hydrostatics"];
    let b = h["buoyancy"].as_f64().unwrap();
    assert!((h["metacentric_height"].as_f64().unwrap() - 0.02).abs() < 1e-12);
    assert!((h["roll_restoring_moment"].as_f64().unwrap() - 0.02 * b).abs() < 1e-9 * b);
    assert!((h["pitch_restoring_moment"].as_f64().unwrap() - 0.02 * b).abs() < 1e-9 * b);
    assert!((h["wet_weight"].as_f64().unwrap() - 3.0).abs() < 1e-9);
    assert!(h["trim_roll_deg"].as_f64().unwrap().abs() < 1e-9);
    assert!(h["trim_pitch_deg"].as_f64().unwrap().abs() < 1e-9);
    // The text form says it too.
    let o = run(&["inspect", arg(&p)]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("wet weight") && text.contains("restoring moment per radian"));

    // design show writes the centres (explicit cg/cb, so the file is the design) with the
    // hydrostatics as a comment; design draw marks CG and CB and captions the figures.
    let o = run(&["design", "show", arg(&p)]);
    let shown = String::from_utf8_lossy(&o.stdout);
    assert!(shown.contains("metacentric height 0.020000 m"), "{shown}");
    let svg = dir.path().join("g.svg");
    let o = run(&["design", "draw", arg(&p), "--out", arg(&svg)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(svg).unwrap();
    assert!(svg.contains("data-marker=\"CG\"") && svg.contains("data-marker=\"CB\""));
    assert!(svg.contains("wet weight 3 N"), "caption");
}

#[test]
fn world_keys_out_of_range_are_refused_with_the_file_and_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let base = "[scenario]\nname = \"w\"\nmode = \"transport\"\ndesign = \"usm-paper\"\n\
                duration = 5.0\n[path]\nsegments = [ { from = [0.0, 0.0], to = [200.0, 0.0] } ]\n";
    for (extra, key) in [
        (
            "[physics]\ncurrent_vertical = 2.0\n",
            "physics.current_vertical",
        ),
        ("[hydro]\ncb_offset_z = 0.2\n", "hydro.cb_offset_z"),
        ("[hydro]\ncb_offset_x = 5.0\n", "hydro.cb_offset_x"),
        (
            "[mission]\npayload_mass = 1.0\npayload_wet_weight = 20.0\n",
            "mission.payload_wet_weight",
        ),
        (
            "[mission]\npayload_mass = 1.0\npayload_wet_weight = 1.0\npayload_volume = 0.001\n",
            "mission.payload_wet_weight",
        ),
    ] {
        let p = write(dir.path(), "s.toml", &format!("{base}{extra}"));
        let out = dir.path().join("out");
        let o = run(&["simulate", arg(&p), "--no-plots", "--out", arg(&out)]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra}: {e}");
        assert!(e.contains("s.toml") && e.contains(key), "{extra}: {e}");
    }
    // In range they run.
    let p = write(
        dir.path(),
        "s.toml",
        &format!(
            "{base}[physics]\ncurrent_vertical = 0.01\n[hydro]\ncb_offset_z = 0.01\n\
             cb_offset_x = 0.001\ncontroller_nominal = true\n[mission]\npayload_mass = 1.0\n\
             payload_wet_weight = 0.5\n"
        ),
    );
    let out = dir.path().join("ok");
    let o = run(&["simulate", arg(&p), "--no-plots", "--out", arg(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
}

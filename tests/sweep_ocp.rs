//! `[ocp]` in studies (issue 41): every case's design gets the optimal-control bound of the
//! study's straight transport leg and `controller_efficiency` against its closed loop; the
//! summary shows the bound beside the closed loop with the agreement sentence and the plot.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::{arg, run, stderr, sweep, write};

const STUDY: &str = r#"[study]
name = "tiny_ocp"
seed = 3
objective = "energy_per_metre"

[design.generator]
links = 3
link_length = 0.6
thrust_limit = 40.0

[scenario]
mode = "transport"
duration = 30.0

[allocation]
method = "pinv"
lambda = 0.1

[[axis]]
name = "design.links"
values = [3, 4]

[[axis]]
name = "control.k_psi"
values = [0.5, 0.8]

[ocp]
distance = 1.0
duration = 4.0
knots = 8
substeps = 2
"#;

/// `cases.csv` of `out` as rows of (column → cell).
fn rows(out: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            head.iter()
                .zip(l.split(','))
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect()
        })
        .collect()
}

fn num(r: &BTreeMap<String, String>, k: &str) -> f64 {
    r.get(k)
        .unwrap_or_else(|| panic!("no column {k}"))
        .parse()
        .unwrap_or(f64::NAN)
}

#[test]
fn every_case_gets_its_designs_bound_and_the_tables_do_not_depend_on_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let study = write(dir.path(), "s.toml", STUDY);
    let (one, two) = (dir.path().join("j1"), dir.path().join("j2"));
    sweep(&study, &one, &["--jobs", "1"]);
    sweep(&study, &two, &["--jobs", "2"]);
    let a = std::fs::read(one.join("cases.csv")).unwrap();
    assert_eq!(
        a,
        std::fs::read(two.join("cases.csv")).unwrap(),
        "--jobs 1 vs 2"
    );
    let rs = rows(&one);
    assert_eq!(rs.len(), 4);
    for r in &rs {
        // Same design (links), same bound, whatever the gain.
        let twin = rs
            .iter()
            .find(|q| q["design.links"] == r["design.links"] && q["case_id"] != r["case_id"])
            .unwrap();
        for c in [
            "ocp_energy",
            "ocp_energy_per_metre",
            "ocp_status",
            "ocp_iterations",
        ] {
            assert_eq!(r[c], twin[c], "{c} of one design");
        }
        let e = num(r, "ocp_energy");
        assert!(e > 0.0 && e.is_finite(), "ocp_energy {e}");
        assert_eq!(num(r, "ocp_energy_per_metre"), e / 1.0);
        assert!(num(r, "ocp_iterations") >= 1.0);
        // The efficiency is the bound per metre over the closed loop's, from the row itself.
        let closed =
            (num(r, "thruster_energy_static") + num(r, "joint_energy")) / num(r, "path_progress");
        let eff = num(r, "controller_efficiency");
        assert!(
            ((eff - e / closed) / eff).abs() < 1e-12,
            "{eff} vs {}",
            e / closed
        );
    }
    // The 3-link bound is a trajectory the model can fly (defects and end rows within 1e-6).
    let three = rs.iter().find(|r| num(r, "design.links") == 3.0).unwrap();
    assert!(num(three, "ocp_primal") <= 1e-6, "{}", three["ocp_primal"]);
    let md = std::fs::read_to_string(one.join("summary.md")).unwrap();
    assert!(
        md.contains("## Physical limit: the optimal-control bound"),
        "{md}"
    );
    assert!(md.contains("What the bound does not carry"));
    assert!(md.contains("Spearman rank correlation"));
    // A 1 m leg from rest to rest in 4 s costs more per metre than cruising: flagged, not hidden.
    assert!(md.contains("Flagged: closed loop below its bound"));
    assert!(one.join("plots/bound.svg").exists() && one.join("plots/bound.pdf").exists());
}

/// [`STUDY`] with two uncertain worlds of more drag (×1.1 … ×1.5) and a current, and the
/// bound solved in both.
fn study_in_worlds() -> String {
    format!(
        "{}worlds = 2\n\n[uncertainty]\nworlds = 2\nsampling = \"sobol\"\n\n\
         [[uncertainty.param]]\nname = \"hydro.drag_scale\"\n\
         distribution = {{ kind = \"uniform\", low = 1.1, high = 1.5 }}\n\n\
         [[uncertainty.param]]\nname = \"physics.current_speed\"\n\
         distribution = {{ kind = \"uniform\", low = 0.0, high = 0.02 }}\n",
        STUDY
    )
}

#[test]
fn the_bound_in_worlds_costs_more_where_the_water_drags_more() {
    let dir = tempfile::tempdir().unwrap();
    let study = write(dir.path(), "w.toml", &study_in_worlds());
    let out = dir.path().join("w");
    sweep(&study, &out, &["--jobs", "2"]);
    let rs = rows(&out);
    assert_eq!(rs.len(), 4);
    let three = rs.iter().find(|r| num(r, "design.links") == 3.0).unwrap();
    // The nominal bound is trusted on its grid: the water's work agrees 10× finer.
    assert!(
        num(three, "ocp_work_error") <= 0.05,
        "{}",
        three["ocp_work_error"]
    );
    assert_eq!(num(three, "ocp_world_feasible"), 2.0, "{three:?}");
    let (lo, hi, nominal) = (
        num(three, "ocp_world_energy_per_metre_min"),
        num(three, "ocp_world_energy_per_metre_max"),
        num(three, "ocp_energy_per_metre"),
    );
    assert!(lo <= hi, "{lo} > {hi}");
    // Every world drags at least 10 % more than the nominal one: its bound is higher.
    assert!(lo > nominal, "world bound {lo} vs nominal {nominal}");
    assert!(num(three, "ocp_world_iterations") >= 2.0);
    // Both worlds count, so neither was rejected for grid energy.
    assert_eq!(num(three, "ocp_world_grid_rejected"), 0.0, "{three:?}");
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("bound in worlds J/m"), "{md}");
    assert!(md.contains("also solved in the study's first scoring worlds"));
}

#[test]
fn bad_ocp_sections_exit_2_naming_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    for (edit, key) in [
        (STUDY.replace("knots = 8", "knots = 0"), "ocp.knots"),
        (
            STUDY.replace("substeps = 2", "substeps = 2\nsubstep = 3"),
            "ocp",
        ),
        (
            STUDY.replace("distance = 1.0", "distance = -1.0"),
            "ocp.distance",
        ),
        // Worlds without [uncertainty], and more worlds than it has.
        (format!("{STUDY}worlds = 2\n"), "ocp.worlds"),
        (
            study_in_worlds().replace("worlds = 2\n\n[uncertainty]", "worlds = 3\n\n[uncertainty]"),
            "ocp.worlds",
        ),
        (
            STUDY.replace("substeps = 2", "substeps = 2\ncurrent = [0.0, 9.0, 0.0]"),
            "ocp.current",
        ),
        (
            STUDY
                .replace("mode = \"transport\"", "mode = \"static\"")
                .replace(
                    "[[axis]]\nname = \"control.k_psi\"\nvalues = [0.5, 0.8]\n",
                    "",
                )
                .replace("objective = \"energy_per_metre\"\n", "")
                .replace("[allocation]\nmethod = \"pinv\"\nlambda = 0.1\n", "")
                .replace("duration = 30.0\n", ""),
            "ocp",
        ),
    ] {
        let study = write(dir.path(), "bad.toml", &edit);
        let o = run(&["sweep", arg(&study), "--dry-run"]);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{key}: {e}");
        assert!(e.contains("bad.toml:") && e.contains(key), "{key}: {e}");
    }
}

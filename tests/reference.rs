//! A `Reference` the closed loop follows (issue 37 item 4, issue 40 item 5;
//! docs/model.md §5 "References"): a recorded `timeseries.csv` of `transport-method1` fed back
//! through `simulate --reference` reproduces its own base path within the original run's
//! tracking error; an `ocp` optimum (`studies/ocp_usm_paper.toml`) is tracked in closed loop and
//! priced beside the open-loop optimum; the Parquet time series is the same reference as the
//! CSV one; a bad reference file or scenario key is a located
//! error with exit code 2.

mod common;

use common::{arg, run, stderr, summary, write};
use std::path::Path;

/// The columns `names` of a CSV file, parsed as numbers (NaN where empty).
fn columns(path: &Path, names: &[&str]) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let idx: Vec<usize> = (names.iter())
        .map(|n| {
            head.iter()
                .position(|h| h == n)
                .unwrap_or_else(|| panic!("{n}"))
        })
        .collect();
    let mut out = vec![Vec::new(); names.len()];
    for l in lines {
        let cells: Vec<&str> = l.split(',').collect();
        for (o, i) in out.iter_mut().zip(&idx) {
            o.push(cells[*i].parse().unwrap_or(f64::NAN));
        }
    }
    out
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn simulate(args: &[&str]) {
    let o = run(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
}

#[test]
fn a_recorded_transport_run_fed_back_reproduces_its_base_path() {
    let d = tempfile::tempdir().unwrap();
    let (rec, tr) = (d.path().join("rec"), d.path().join("tracked"));
    simulate(&[
        "simulate",
        "transport-method1",
        "--out",
        arg(&rec),
        "--no-plots",
    ]);
    let ts = rec.join("timeseries.csv");
    simulate(&[
        "simulate",
        "transport-method1",
        "--reference",
        arg(&ts),
        "--out",
        arg(&tr),
        "--no-plots",
    ]);
    let original = summary(&rec);
    let tracked = summary(&tr);
    assert_eq!(tracked["mode"], "work");
    let names = ["t", "base_x", "base_y", "base_z"];
    let (a, b) = (
        columns(&ts, &names),
        columns(&tr.join("timeseries.csv"), &names),
    );
    assert_eq!(a[0], b[0], "same logged times");
    let dev: Vec<f64> = (0..a[0].len())
        .map(|k| {
            (1..4)
                .map(|i| (a[i][k] - b[i][k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let rms = (dev.iter().map(|d| d * d).sum::<f64>() / dev.len() as f64).sqrt();
    let m = |k: &str| original["metrics"][k].as_f64().unwrap();
    // The original run's own tracking error: its base's RMS offset from the path, its final
    // cross-track error, and its largest cross-track error over the settled cruise.
    assert!(
        rms < m("base_cross_track_rms"),
        "{rms} vs {}",
        m("base_cross_track_rms")
    );
    let last = *dev.last().unwrap();
    assert!(last < m("final_cross_track").abs(), "{last}");
    let ct = columns(&ts, &["t", "cross_track"]);
    let cruise = |k: &usize| (30.0..95.0).contains(&ct[0][*k]);
    let ct_max = (0..ct[0].len()).filter(cruise).map(|k| ct[1][k].abs());
    let dev_max = (0..dev.len()).filter(cruise).map(|k| dev[k]);
    let (ct_max, dev_max) = (ct_max.fold(0.0, f64::max), dev_max.fold(0.0, f64::max));
    assert!(dev_max < ct_max, "cruise: {dev_max} vs {ct_max}");
    // tracking.json says the same.
    let t = json(&tr.join("tracking.json"));
    assert!((t["base_error_rms"].as_f64().unwrap() - rms).abs() < 1e-9);
    assert!(t["reference_effort"].as_f64().unwrap() > 0.0);
    // The Parquet time series is the same reference: the tracked run is bit-identical.
    let pq = d.path().join("from_parquet");
    let parquet = rec.join("timeseries.parquet");
    let args = [
        "simulate",
        "transport-method1",
        "--reference",
        arg(&parquet),
    ];
    simulate(&[&args[..], &["--out", arg(&pq), "--no-plots"]].concat());
    let csv = |dir: &Path| std::fs::read(dir.join("timeseries.csv")).unwrap();
    assert!(csv(&pq) == csv(&tr), "Parquet and CSV references differ");
    assert!(pq.join("reference.csv").is_file());
}

#[test]
fn an_ocp_optimum_is_tracked_in_closed_loop_and_priced() {
    let d = tempfile::tempdir().unwrap();
    let (ocp, tr) = (d.path().join("ocp"), d.path().join("tracked"));
    let o = run(&["ocp", "studies/ocp_usm_paper.toml", "--out", arg(&ocp)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let optimum = json(&ocp.join("summary.json"));
    assert_eq!(optimum["status"], "converged");
    simulate(&[
        "simulate",
        "work-setpoint",
        "--reference",
        arg(&ocp.join("trajectory.csv")),
        "--set",
        "scenario.log_dt=0.05",
        "--out",
        arg(&tr),
        "--no-plots",
    ]);
    let t = json(&tr.join("tracking.json"));
    let f = |k: &str| t[k].as_f64().unwrap_or_else(|| panic!("{k} in {t}"));
    // The reference's effort read back from trajectory.csv is the optimum's objective.
    let j = optimum["objective"].as_f64().unwrap();
    assert!(
        (f("reference_effort") - j).abs() <= 1e-12 * j,
        "{} vs {j}",
        f("reference_effort")
    );
    // Closing the loop costs effort and energy above the open-loop optimum (its price).
    assert!(f("price") > 0.0 && (f("price") - (f("tracked_effort") - j)).abs() < 1e-12);
    assert!(f("tracked_thruster_energy_static") > f("reference_thruster_energy_static"));
    // The base follows the optimum within millimetres; the end effector ends within the
    // work mode's 2 cm of the optimum's (joint-servo lag) and the run succeeds.
    assert!(f("base_error_max") < 0.01, "{t}");
    let s = summary(&tr);
    let final_ee = s["metrics"]["final_position_error"].as_f64().unwrap();
    assert!(final_ee < 0.02, "{final_ee}");
    assert_eq!(s["status"], "ok", "{s}");
    eprintln!(
        "ocp_usm_paper: optimum J = {j:.6}, tracked effort {:.6}, price {:.6}, static thruster \
         energy {:.4} J vs {:.4} J, final EE error {final_ee:.4} m, base error max {:.4} m",
        f("tracked_effort"),
        f("price"),
        f("tracked_thruster_energy_static"),
        f("reference_thruster_energy_static"),
        f("base_error_max")
    );
}

#[test]
fn a_scenario_key_names_a_file_relative_to_the_scenario_and_bad_files_exit_2() {
    let d = tempfile::tempdir().unwrap();
    let header =
        "t,base_x,base_y,base_z,base_roll,base_pitch,base_yaw,q_1,q_2,q_3,q_4,q_5,q_6,q_7,q_8";
    let good =
        format!("{header}\n0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n2,0.1,0,0,0,0,0,0,0,0,0,0,0,0,0\n");
    write(d.path(), "good.csv", &good);
    // Held at its last row after t = 2 s: the base settles there (K_p = 0.5 1/s).
    let scenario =
        "[scenario]\nmode = \"work\"\nduration = 12.0\n[reference]\nfile = \"good.csv\"\n";
    let sc = write(d.path(), "follow.toml", scenario);
    let out = d.path().join("out");
    simulate(&["simulate", arg(&sc), "--out", arg(&out), "--no-plots"]);
    let x = columns(&out.join("timeseries.csv"), &["base_x"]);
    assert!(
        (x[0].last().unwrap() - 0.1).abs() < 0.005,
        "{:?}",
        x[0].last()
    );
    // A bad cell: exit 2, the file, its line and the column.
    let bad =
        format!("{header}\n0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n2,0.1,zero,0,0,0,0,0,0,0,0,0,0,0,0\n");
    let p = write(d.path(), "bad.csv", &bad);
    let o = run(&[
        "simulate",
        "work-setpoint",
        "--reference",
        arg(&p),
        "--out",
        arg(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("bad.csv:3: column `base_y`: `zero` is not a finite number"),
        "{e}"
    );
    // A missing joint column.
    let p = write(
        d.path(),
        "short.csv",
        "t,base_x,base_y,base_z,base_roll,base_pitch,base_yaw\n",
    );
    let o = run(&[
        "simulate",
        "work-setpoint",
        "--reference",
        arg(&p),
        "--out",
        arg(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("short.csv:1: no column `q_1`"),
        "{}",
        stderr(&o)
    );
    // A reference key outside its place: via-points with a file, gains without one.
    let both = format!("{scenario}[[reference.via]]\ntime = 1.0\nposition = [0.0, 0.0, 0.0]\n");
    let sc = write(d.path(), "both.toml", &both);
    let o = run(&["simulate", arg(&sc), "--out", arg(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("reference.via"), "{}", stderr(&o));
    let o = run(&[
        "simulate",
        "work-setpoint",
        "--set",
        "reference.k_position=[1.0, 1.0, 1.0]",
        "--set",
        "reference.duration=20.0",
        "--out",
        arg(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("reference.k_position: applies only with reference.file"));
}

//! `simulate SCENARIO --reference FILE`: the scenario's plant (design, physics, current,
//! allocation, servos) follows a trajectory file with the tracking law of
//! `usm_study::control::tracking` (work mode, `[reference] file`), and the run is compared with
//! the reference (`tracking.json`: base path error, effort, the controller's price).

use std::path::{Path, PathBuf};
use usm_study::control::{Reference, TrajectoryTable};
use usm_study::model::Vehicle;
use usm_study::report::{atomic_write, read_parquet, write_csv};
use usm_study::scenario::{compare_with_reference, ScenarioFile, TrackingComparison, Trajectory};
use usm_study::spatial::euler_zyx;

/// Make the scenario table follow `file`: work mode with `[reference] file` (absolute, as the
/// user named it from the current directory); the scenario's own `[control]` and
/// `[base_control]` (gains of another law) are dropped, so the tracking defaults apply
/// (`control::tracking`, `DynamicGains::tracking`), and so are a transport scenario's `[path]`
/// and `[success]` (transport criteria). Runs before the `--set` overrides, so that they can
/// set any of these again (`reference.k_position`, `base_control.kp`).
pub fn follow(table: &mut toml::Table, file: &Path) -> anyhow::Result<()> {
    let abs = std::path::absolute(file)
        .map_err(|e| anyhow::anyhow!("--reference {}: {e}", file.display()))?;
    let section = table
        .entry("scenario")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    let Some(section) = section.as_table_mut() else {
        anyhow::bail!("scenario: must be a table");
    };
    let was_work = section.get("mode").and_then(|m| m.as_str()) == Some("work");
    section.insert("mode".into(), toml::Value::String("work".into()));
    for key in ["control", "base_control"] {
        table.remove(key);
    }
    if !was_work {
        for key in ["path", "success"] {
            table.remove(key);
        }
    }
    let mut r = toml::Table::new();
    r.insert(
        "file".into(),
        toml::Value::String(abs.display().to_string()),
    );
    table.insert("reference".into(), toml::Value::Table(r));
    Ok(())
}

/// Start the run where the reference starts (its first row's base position, yaw and joint
/// angles) and end it at the reference's last time, unless `--set` gave `initial.*` or
/// `scenario.duration`; returns the reference read (for [`write_comparison`]). A `.parquet`
/// reference (e.g. `timeseries.parquet`) is first written as `out/reference.csv` (the same
/// columns, every number round-tripped exactly) and that file is followed.
pub fn start_at_reference(
    file: &mut ScenarioFile,
    vehicle: &Vehicle,
    sets: &[String],
    out: &Path,
) -> anyhow::Result<TrajectoryTable> {
    let mut path = PathBuf::from(file.reference_file().unwrap_or_default());
    if path.extension().is_some_and(|e| e == "parquet") {
        let csv = out.join("reference.csv");
        write_csv(&read_parquet(&path)?, &csv)?;
        path = std::path::absolute(&csv)?;
        if let Some(r) = file.reference.as_mut() {
            r.file = Some(path.display().to_string());
        }
    }
    let table = TrajectoryTable::read(&path, vehicle.n_joints())?;
    let given = |key: &str| sets.iter().any(|s| s.trim_start().starts_with(key));
    let (t0, t1) = table.span();
    let mut r = Reference::new(vehicle.n_joints());
    table.sample_into(t0, &mut r);
    if !given("initial") {
        file.initial.position = r.base_position.into();
        let rot = r.base_orientation.to_rotation_matrix();
        file.initial.yaw_deg = euler_zyx(rot.matrix()).z.to_degrees();
        file.initial.joint_angles_deg = r.q.iter().map(|q| q.to_degrees()).collect();
    }
    if !given("scenario.duration") {
        file.scenario.duration = t1;
    }
    file.validate()
        .map_err(|e| anyhow::anyhow!("--reference {}: {e}", path.display()))?;
    Ok(table)
}

/// Compare the run with its reference, print it and write `tracking.json` into `out`.
pub fn write_comparison(
    table: &TrajectoryTable,
    file: &ScenarioFile,
    vehicle: &Vehicle,
    trajectory: &Trajectory,
    out: &Path,
) -> anyhow::Result<TrackingComparison> {
    let power = file.power_model(vehicle.fluid.rho);
    let c = compare_with_reference(table, trajectory, &power);
    println!(
        "  tracking: base error max {:.4} m, rms {:.4} m, final {:.4} m; effort {:.6} (reference {}{})",
        c.base_error_max,
        c.base_error_rms,
        c.base_error_final,
        c.tracked_effort,
        c.reference_effort
            .map_or("has no controls".to_string(), |j| format!("{j:.6}")),
        c.price
            .map_or(String::new(), |p| format!(", price {p:.6}")),
    );
    if let Some(e) = c.reference_thruster_energy_static {
        println!(
            "  thruster energy (static actuator disk): tracked {:.6} J, reference {e:.6} J",
            c.tracked_thruster_energy_static
        );
    }
    let mut text = serde_json::to_string_pretty(&c)?;
    text.push('\n');
    atomic_write(&out.join("tracking.json"), text.as_bytes())?;
    Ok(c)
}

/// The closed-loop run of a trajectory file through a scenario's plant ([`follow`],
/// [`start_at_reference`]), as `simulate SCENARIO --reference FILE --out DIR` runs it.
pub struct Tracked {
    /// The scenario as given (file or preset).
    pub scenario: String,
    /// The plant's design name.
    pub design: String,
    /// The run (its metrics: `thruster_energy` with the axial inflow, `final_position_error`
    /// of the end effector against the reference's last pose, …).
    pub run: usm_study::outcome::RunResult,
    /// The run against its reference (`tracking.json`).
    pub comparison: TrackingComparison,
}

/// Run `scenario` following `reference` and write the run's outputs (time series, figure,
/// `summary.json`, `tracking.json`) into `out` (created).
pub fn track(scenario: &str, reference: &Path, out: &Path) -> anyhow::Result<Tracked> {
    let (mut table, src) = usm_study::scenario::load_table(scenario)?;
    follow(&mut table, reference)?;
    table.remove("uncertainty");
    let mut file = usm_study::scenario::parse_table(&table, &src)?;
    let vehicle = usm_study::scenario::resolve_design(&file, &src)?;
    usm_study::pipeline::create_dir(out)?;
    let table = start_at_reference(&mut file, &vehicle, &[], out)?;
    let run =
        usm_study::outcome::run_scenario_until(&vehicle, &file, usm_study::scenario::Stop::NEVER)?;
    let files = usm_study::pipeline::simulate::RunFiles {
        timeseries: true,
        figure: true,
        shapes: false,
    };
    usm_study::pipeline::simulate::write_run_outputs(&run, out, &vehicle, files)?;
    let comparison = write_comparison(&table, &file, &vehicle, &run.trajectory, out)?;
    Ok(Tracked {
        scenario: scenario.to_string(),
        design: vehicle.name.clone(),
        run,
        comparison,
    })
}

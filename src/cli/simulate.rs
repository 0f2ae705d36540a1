//! `usm-study simulate SCENARIO [--out DIR] [--allocation METHOD] [--reference FILE]
//! [--set key=value ...]`.
//!
//! Ctrl-C (SIGINT) or SIGTERM stops the run at its next control period: the outputs of the
//! run up to then are written, what was written is printed, and the exit code is 130.

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use usm_study::allocation::Method;
use usm_study::evaluate::{apply_overrides, Override};
use usm_study::input::keypath::parse_override;
use usm_study::outcome::{run_scenario_until, RunResult};
use usm_study::paper::antonelli_outputs::{run_antonelli_preset as run_preset, AntonelliPreset};
use usm_study::pipeline::create_dir;
use usm_study::pipeline::simulate::{set_allocation_method, write_run_outputs, RunFiles};
use usm_study::report::fmt_num;
use usm_study::scenario::{load_table, parse_table, resolve_design, Stop, INTERRUPTED};

/// Arguments of `simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML) or preset: transport-method1, transport-method2, work-setpoint,
    /// transport-method1-torque-limited, work-setpoint-far; or one of Antonelli & Chiaverini's
    /// cases antonelli-case1, -case1b, -case2, -case3a, -case3b (fixed set-ups: no overrides).
    pub scenario: String,
    /// Output directory (default: out/<scenario name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override the allocation method: pinv, qp, minimax or power.
    #[arg(long)]
    pub allocation: Option<Method>,
    /// Override any scenario key, e.g. `--set control.k_psi=0.3 --set scenario.duration=60`
    /// (values are TOML: numbers, strings, arrays).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Do not write the SVG figure, shapes.svg and animation.svg.
    #[arg(long)]
    pub no_plots: bool,
    /// Follow a trajectory file (CSV with the time-series column names: `simulate`'s
    /// timeseries.csv or .parquet, `ocp`'s trajectory.csv) with the scenario's plant: work mode with
    /// `[reference] file`, starting at its first row and lasting to its last; writes
    /// tracking.json (base error, effort beside the reference's, the controller's price).
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
}

/// Run `simulate`.
pub fn run(a: &SimulateArgs) -> anyhow::Result<ExitCode> {
    if let Some(p) = AntonelliPreset::parse(&a.scenario) {
        return run_antonelli_preset(p, a);
    }
    let (mut table, src) = load_table(&a.scenario)?;
    if let Some(m) = a.allocation {
        set_allocation_method(&mut table, m);
    }
    if let Some(f) = &a.reference {
        super::simulate_reference::follow(&mut table, f)?;
    }
    // `--set` takes the one road for variation (typed overrides, as sweeps and optimisers
    // vary a case); the scenario file holds its design, so each edits the file's table.
    for s in &a.set {
        let (path, value) = parse_override(s)?;
        let o = [Override::scenario(path.0, value, s.as_str())];
        apply_overrides(&mut toml::Table::new(), &mut table, &o)
            .map_err(|e| anyhow::anyhow!("--set {s}: {e}"))?;
    }
    // `[uncertainty]` is the study layer's: the nominal run below, then the worlds.
    let uncertainty = match table.remove("uncertainty") {
        Some(toml::Value::Table(t)) => Some(t),
        Some(_) => anyhow::bail!("{}: uncertainty: must be a table", src.origin),
        None => None,
    };
    let mut file = parse_table(&table, &src)?;
    let vehicle = resolve_design(&file, &src)?;
    let worlds = match uncertainty {
        Some(u) => Some(super::simulate_worlds::prepare(
            &table,
            u,
            &src,
            &file.scenario.name,
        )?),
        None => None,
    };
    let out = a.out.clone().unwrap_or_else(|| {
        PathBuf::from("out").join(usm_study::report::file_stem_safe(&file.scenario.name))
    });
    create_dir(&out)?;
    let reference = match &a.reference {
        Some(_) => Some(super::simulate_reference::start_at_reference(
            &mut file, &vehicle, &a.set, &out,
        )?),
        None => None,
    };
    eprintln!(
        "[simulate] {} ({} mode, design {}, {} s, allocation {})",
        file.scenario.name,
        file.scenario.mode,
        vehicle.name,
        file.scenario.duration,
        file.allocation.method.name()
    );
    catch_interrupt();
    let r = run_scenario_until(&vehicle, &file, Stop::NEVER.on_flag(&INTERRUPT))?;
    let files = RunFiles {
        timeseries: true,
        figure: !a.no_plots,
        shapes: !a.no_plots,
    };
    write_run_outputs(&r, &out, &vehicle, files)?;
    print_summary(&r);
    if let Some(table) = &reference {
        super::simulate_reference::write_comparison(table, &file, &vehicle, &r.trajectory, &out)?;
    }
    if let Some((t, INTERRUPTED)) = r.failure.as_ref().map(|(t, c)| (t, c.as_str())) {
        eprintln!(
            "[simulate] interrupted at t = {t:.3} s of {} s: wrote the run up to then to {} \
             (timeseries.csv/.parquet, summary.json{}){}",
            file.scenario.duration,
            out.display(),
            if a.no_plots {
                ""
            } else {
                ", figure.svg, shapes.svg, animation.svg"
            },
            if worlds.is_some() {
                "; the [uncertainty] worlds were not run"
            } else {
                ""
            }
        );
        return Ok(ExitCode::from(130));
    }
    if let Some(w) = &worlds {
        super::simulate_worlds::run_worlds(w, &out)?;
    }
    eprintln!("[simulate] wrote {}", out.display());
    match &r.failure {
        Some((t, cause)) => {
            eprintln!(
                "error: run stopped at t = {t:.3} s: {cause} (outputs hold the run up to then)"
            );
            Ok(ExitCode::from(1))
        }
        None => Ok(ExitCode::SUCCESS),
    }
}

/// Set by the first SIGINT/SIGTERM of `simulate`: the run stops at its next control period
/// and its outputs up to then are written. A second signal exits at once.
static INTERRUPT: AtomicBool = AtomicBool::new(false);

extern "C" fn on_interrupt(sig: libc::c_int) {
    if INTERRUPT.swap(true, Ordering::SeqCst) {
        const MSG: &[u8] = b"\nusm-study simulate: interrupted again; stopping without writing\n";
        // SAFETY: write and _exit are async-signal-safe.
        unsafe {
            libc::write(2, MSG.as_ptr().cast(), MSG.len());
            libc::_exit(128 + sig);
        }
    }
}

/// Route SIGINT (Ctrl-C) and SIGTERM to [`INTERRUPT`] (a signal the parent ignores stays
/// ignored).
fn catch_interrupt() {
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `on_interrupt` only performs async-signal-safe operations (an atomic swap,
        // write, _exit).
        unsafe {
            let handler = on_interrupt as extern "C" fn(libc::c_int) as libc::sighandler_t;
            if libc::signal(sig, handler) == libc::SIG_IGN {
                libc::signal(sig, libc::SIG_IGN);
            }
        }
    }
}

fn print_summary(r: &RunResult) {
    println!("{} ({} mode)", r.name, r.mode);
    for (k, v) in &r.metrics {
        println!("  {k:<30} {}", fmt_num(*v));
    }
    match &r.missed {
        None => println!("  success: every [success] criterion met"),
        Some(m) => println!("  success: missed {m}"),
    }
    let t = &r.timing;
    println!(
        "  wall time {:.3} s ({:.0}x real time): dynamics {:.3} s, allocation {:.3} s, control {:.3} s, logging {:.3} s",
        t.total_s, t.realtime_factor, t.dynamics_s, t.allocation_s, t.control_s, t.logging_s
    );
}

/// `simulate antonelli-…`: one of the paper's cases with its fixed set-up, written to `--out`
/// (default `out/<preset>`); the closed-loop overrides do not apply to it.
pub fn run_antonelli_preset(p: AntonelliPreset, a: &SimulateArgs) -> anyhow::Result<ExitCode> {
    if a.allocation.is_some() || !a.set.is_empty() {
        anyhow::bail!(
            "{}: a fixed case of Antonelli & Chiaverini; --allocation and --set do not apply",
            a.scenario
        );
    }
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&a.scenario));
    let summary = run_preset(p, &out)?;
    println!("{}", serde_json::to_string_pretty(&summary)?);
    eprintln!("[simulate] wrote {}", out.display());
    Ok(ExitCode::SUCCESS)
}

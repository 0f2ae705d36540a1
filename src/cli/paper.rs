//! `usm-study paper [usm|antonelli|readings|secondary|drag] [--out DIR]`: regenerate a seed paper's
//! simulations — the USM paper (see [`usm_study::paper::usm`], the default), Antonelli &
//! Chiaverini's case studies and Table I (see [`usm_study::paper::antonelli_outputs`]), the USM
//! transport readings comparison (see [`usm_study::paper::readings`]), or the secondary
//! objectives comparison (see [`usm_study::paper::secondary`]), or the hull drag against
//! published vehicles (see [`usm_study::paper::published_drag`]).

use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use usm_study::paper::antonelli_outputs::run_antonelli;
use usm_study::paper::published_drag::run_drag_comparison;
use usm_study::paper::secondary::run_secondary_comparison;
use usm_study::paper::transport_claims::run_readings_and_claims;
use usm_study::paper::usm::run_paper;

/// Which paper to regenerate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PaperName {
    /// The USM paper (its scenario presets, allocator comparison).
    Usm,
    /// Antonelli & Chiaverini (1998): kinematic case studies 1, 1b and 2 on `uvms-planar`,
    /// case 3 (NPS AUV II under current, Table I) and the paper-like figures.
    Antonelli,
    /// The USM paper's transport mode under every reading of its open choices (USM-33/34,
    /// USM-40/41): `readings.csv`, `readings.md` and `claims.md`.
    Readings,
    /// The USM paper's secondary objectives (manipulability, controllability) on and off, in
    /// work mode and transport: `secondary.csv` and `secondary.md`.
    Secondary,
    /// The hull drag (docs/model.md §2) against published vehicles (NPS AUV II, REMUS 100):
    /// `comparison.csv` and `comparison.md`.
    Drag,
}

/// Arguments of `paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// The paper.
    #[arg(value_enum, default_value = "usm")]
    pub paper: PaperName,
    /// Output directory (default `results/paper` for `usm`, `results/antonelli` for
    /// `antonelli`, `results/paper/readings` for `readings`, `results/paper/secondary` for
    /// `secondary`, `results/drag` for `drag`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write each run's time series (CSV and Parquet; about 2 MB per run; `usm` only).
    #[arg(long)]
    pub timeseries: bool,
}

/// Run `paper`: exit code 1 when a run stopped early.
pub fn run(a: &PaperArgs) -> anyhow::Result<ExitCode> {
    if a.paper == PaperName::Antonelli {
        let out = a.out.clone().unwrap_or_else(|| "results/antonelli".into());
        let outcome = run_antonelli(&out, &mut |s| {
            eprintln!(
                "[paper antonelli] {}: {} → {:.4} (target {:.4}), max end-effector error {:.2e} m",
                s.name,
                s.fourth_task,
                s.fourth_task_final,
                s.fourth_task_target,
                s.max_ee_position_error
            );
        })?;
        let t = &outcome.table1;
        eprintln!(
            "[paper antonelli] Table I (ours / paper): ∫‖f‖ a {:.0} / {:.0}, b {:.0} / {:.0}; \
             ∫‖m‖ a {:.0} / {:.0}, b {:.0} / {:.0}",
            t.ours.force_integral_a,
            t.paper.force_integral_a,
            t.ours.force_integral_b,
            t.paper.force_integral_b,
            t.ours.moment_integral_a,
            t.paper.moment_integral_a,
            t.ours.moment_integral_b,
            t.paper.moment_integral_b
        );
        eprintln!(
            "[paper antonelli] Table I differs (the 1998 code behind it had other cross-flow \
             terms): every reading of case 3 and why, in results/antonelli/FINDINGS.md \
             §\"Case 3 and Table I\""
        );
        eprintln!("[paper antonelli] wrote {}", out.display());
        return Ok(ExitCode::SUCCESS);
    }
    if a.paper == PaperName::Readings {
        let out = a
            .out
            .clone()
            .unwrap_or_else(|| "results/paper/readings".into());
        let outcome = run_readings_and_claims(&out, &mut |r| {
            eprintln!(
                "[paper readings] {} {:?}: {}",
                r.reading.key(),
                r.method,
                if r.converged() {
                    "converged"
                } else {
                    "not converged"
                }
            );
        })?;
        match outcome.adopted {
            Some(r) => eprintln!("[paper readings] adopted: {}", r.key()),
            None => eprintln!("[paper readings] no reading makes both methods converge"),
        }
        eprintln!("[paper readings] wrote {}", out.display());
        return Ok(ExitCode::SUCCESS);
    }
    if a.paper == PaperName::Drag {
        let out = a.out.clone().unwrap_or_else(|| "results/drag".into());
        let rows = run_drag_comparison(&out)?;
        for r in &rows {
            eprintln!(
                "[paper drag] {} {} at {}: published {:.2}, ours {:.2} ({:.2}x)",
                r.vehicle,
                r.coefficient,
                r.at,
                r.published,
                r.ours,
                r.ratio()
            );
        }
        eprintln!("[paper drag] wrote {}", out.display());
        return Ok(ExitCode::SUCCESS);
    }
    if a.paper == PaperName::Secondary {
        let out = a
            .out
            .clone()
            .unwrap_or_else(|| "results/paper/secondary".into());
        run_secondary_comparison(&out, &mut |r| {
            eprintln!(
                "[paper secondary] {} {}: min commanded σ_min {:.4}",
                r.scenario,
                r.case,
                r.get("sigma_c_min")
            );
        })?;
        eprintln!("[paper secondary] wrote {}", out.display());
        return Ok(ExitCode::SUCCESS);
    }
    let out = a.out.clone().unwrap_or_else(|| "results/paper".into());
    let outcome = run_paper(&out, a.timeseries, &mut |r| {
        eprintln!(
            "[paper] {}: {} in {:.2} s",
            r.dir,
            if r.failed { "FAILED" } else { "ok" },
            r.seconds
        );
    })?;
    eprintln!("[paper] wrote {}", out.display());
    Ok(if outcome.failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

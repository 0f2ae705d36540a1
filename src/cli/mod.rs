//! The command-line interface of the binary: clap commands, progress display, printing and
//! exit codes. Each command turns its raw arguments into the library's validated settings,
//! calls the library (the pipelines of `usm_study::pipeline` and `usm_study::study`), and
//! prints the result. This is the only module that prints, and the only user of clap, anyhow
//! and indicatif.

mod allocate;
mod design;
mod format;
mod inspect;
mod ocp;
mod optimise;
mod paper;
mod progress;
mod simulate;
mod simulate_reference;
mod simulate_worlds;
mod sweep;
mod tcm;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// usm-study: design, simulate and sweep underwater swimming manipulators.
#[derive(Debug, Parser)]
#[command(name = "usm-study", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Summarise a design and evaluate kinematics (and dynamics) at a state.
    Inspect(inspect::InspectArgs),
    /// Work with design files and presets.
    #[command(subcommand)]
    Design(design::DesignCommand),
    /// Solve one thrust-allocation problem with one or all methods.
    Allocate(allocate::AllocateArgs),
    /// Run one closed-loop scenario (transport or work mode) and write its time series,
    /// summary and figure.
    Simulate(simulate::SimulateArgs),
    /// Regenerate a seed paper's simulations: the USM paper (its scenario presets, allocator
    /// comparison, figures and tables) or Antonelli & Chiaverini's case studies.
    Paper(paper::PaperArgs),
    /// Static configuration-space analysis of the thruster matrix: how often is T(q) singular.
    Tcm(tcm::TcmArgs),
    /// Run a batch study (parameter sweep) from a study file.
    Sweep(sweep::SweepArgs),
    /// Merge the outputs of sweep shards into one result.
    Merge(sweep::MergeArgs),
    /// Rebuild the review of a finished study (sweep, merge or optimise output): summary.md,
    /// plots and report.html, from its files alone; `--objective` / `--pareto` re-rank it
    /// without re-running any case.
    Report(sweep::ReportArgs),
    /// Optimise gains, layouts or references of a problem file with argmin (Nelder–Mead,
    /// particle swarm, L-BFGS), feasibility first.
    Optimise(optimise::OptimiseArgs),
    /// Solve an optimal-control problem file (multiple shooting, Gauss–Newton SQP with a
    /// Riccati interior-point QP) and write the trajectory and its summary.
    Ocp(ocp::OcpArgs),
}

/// Threads per core `--jobs` may ask for: more only adds thread start-up and memory (results
/// do not depend on the thread count).
const JOBS_PER_CORE: usize = 4;

/// `--jobs` capped at [`JOBS_PER_CORE`] × the cores of this machine (at least 8), with a note
/// on stderr when capped; 0 (all cores) is kept.
fn cap_jobs(jobs: &mut usize, verb: &str) {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cap = (JOBS_PER_CORE * cores).max(8);
    if *jobs > cap {
        eprintln!(
            "[{verb}] note: --jobs {} capped to {cap} ({JOBS_PER_CORE} × {cores} cores); \
             results do not depend on it",
            *jobs
        );
        *jobs = cap;
    }
}

/// Parse `std::env::args` and run the chosen command.
pub fn run() -> anyhow::Result<ExitCode> {
    let mut cli = Cli::parse();
    match &mut cli.command {
        // A Slurm script's --jobs is for the compute nodes, not this machine.
        Command::Sweep(a) if a.emit_slurm.is_none() => cap_jobs(&mut a.jobs, "sweep"),
        Command::Optimise(a) => cap_jobs(&mut a.jobs, "optimise"),
        Command::Tcm(a) => cap_jobs(&mut a.jobs, "tcm"),
        _ => {}
    }
    match &cli.command {
        Command::Inspect(a) => inspect::run(a),
        Command::Design(c) => design::run(c),
        Command::Allocate(a) => allocate::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Paper(a) => paper::run(a),
        Command::Tcm(a) => tcm::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Merge(a) => sweep::run_merge(a),
        Command::Report(a) => sweep::run_report(a),
        Command::Optimise(a) => optimise::run_optimise(a),
        Command::Ocp(a) => ocp::run(a),
    }
}

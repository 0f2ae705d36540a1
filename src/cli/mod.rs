//! The command-line interface: clap commands, output formatting and exit codes. This is the
//! only module that prints.

pub mod allocate;
pub mod design;
pub mod inspect;
pub mod paper;
pub mod simulate;
pub mod sweep;
pub mod tcm;

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
    /// Regenerate the USM paper's simulations (three presets, allocator comparison) with
    /// figures and comparison tables.
    Paper(paper::PaperArgs),
    /// Static configuration-space analysis of the thruster matrix: how often is T(q) singular.
    Tcm(tcm::TcmArgs),
    /// Run a batch study (parameter sweep) from a study file.
    Sweep(sweep::SweepArgs),
    /// Merge the outputs of sweep shards into one result.
    Merge(sweep::MergeArgs),
    /// Regenerate summary.md and plots of a sweep output directory.
    Report(sweep::ReportArgs),
}

/// Parse `std::env::args` and run the chosen command.
pub fn run() -> anyhow::Result<ExitCode> {
    let cli = Cli::parse();
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
    }
}

/// Output format shared by the commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Human-readable text.
    Text,
    /// Machine-readable JSON with stable keys.
    Json,
}

/// Format a number for tables: fixed width, sensible precision.
pub(crate) fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.abs() >= 1e4 || x.abs() < 1e-3 {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

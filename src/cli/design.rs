//! `usm-study design …`: presets and design files.

use clap::Subcommand;
use std::process::ExitCode;
use usm_study::model::design::{design_to_toml, load_design};
use usm_study::model::presets::PRESETS;

/// Design subcommands.
#[derive(Debug, Subcommand)]
pub enum DesignCommand {
    /// Print a preset (or a design file, fully expanded) as an explicit design file you can
    /// copy and edit.
    Show {
        /// Preset name (usm-paper, uvms-planar) or path to a design file.
        design: String,
    },
    /// List the built-in presets.
    List,
}

/// Run a design subcommand.
pub fn run(cmd: &DesignCommand) -> anyhow::Result<ExitCode> {
    match cmd {
        DesignCommand::Show { design } => {
            let v = load_design(design)?;
            print!("{}", design_to_toml(&v));
        }
        DesignCommand::List => {
            for p in PRESETS {
                println!("{p}");
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

//! `usm-study design …`: presets, design files and their drawings.

use anyhow::Context;
use clap::Subcommand;
use std::path::PathBuf;
use std::process::ExitCode;
use usm_study::model::design::{design_to_toml, load_design};
use usm_study::model::presets::PRESETS;
use usm_study::pipeline::draw::write_drawing;
use usm_study::report::file_stem_safe;
use usm_study::state::{load_state, VehicleState};

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
    /// Draw a design at a state: top, side and front views to scale, thrusters as arrows,
    /// joint axes, base and end-effector frames, and the singular values of T(q), as SVG.
    Draw {
        /// Preset name (usm-paper, uvms-planar) or path to a design file.
        design: String,
        /// State file (JSON, as for `inspect --state`). Default: straight, base at the origin.
        #[arg(long)]
        state: Option<PathBuf>,
        /// Output SVG file. Default: DESIGN_NAME.svg in the current directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
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
        DesignCommand::Draw { design, state, out } => {
            let v = load_design(design)?;
            let (s, label) = match state {
                Some(p) => (load_state(p, &v)?, p.display().to_string()),
                None => (
                    VehicleState::rest(&v),
                    "straight, base at the origin".into(),
                ),
            };
            let out = out
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}.svg", file_stem_safe(&v.name))));
            write_drawing(&v, &s, &label, &out)
                .with_context(|| format!("writing the drawing {}", out.display()))?;
            println!("wrote {}", out.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}

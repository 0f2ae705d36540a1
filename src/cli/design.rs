//! `usm-study design …`: presets, design files and their drawings.

use anyhow::Context;
use clap::Subcommand;
use std::path::PathBuf;
use std::process::ExitCode;
use usm_study::model::design::{design_to_toml, load_design};
use usm_study::model::presets::PRESETS;
use usm_study::model::urdf::{
    imported_to_toml, load_urdf, vehicle_to_mjcf, vehicle_to_urdf, ImportOptions,
};
use usm_study::pipeline::draw::write_drawing;
use usm_study::report::atomic::atomic_write;
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
    /// Import a URDF (with UUV Simulator / Plankton or gz-sim hydrodynamic plugin blocks) as a
    /// design file (docs/urdf.md); values the file does not give are listed as inferred.
    Import {
        /// The URDF file (expand xacro first).
        urdf: PathBuf,
        /// Output design file. Default: print to stdout.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Symmetric thrust limit [N] for thrusters whose plugin gives no finite limit
        /// (default 40, marked inferred).
        #[arg(long)]
        thrust_limit: Option<f64>,
        /// Hold this revolute joint at zero and merge its child into the parent's body (e.g.
        /// a gripper's fingers, which would make the tree branch); repeat for more.
        #[arg(long = "fix-joint", value_name = "JOINT")]
        fix_joint: Vec<String>,
    },
    /// Export a design (preset or file) as URDF with UUV Simulator plugin blocks, or as MuJoCo
    /// MJCF (docs/urdf.md).
    Export {
        /// Preset name or path to a design file.
        design: String,
        /// `urdf` or `mjcf`.
        #[arg(long, value_parser = ["urdf", "mjcf"])]
        format: String,
        /// Output file. Default: print to stdout.
        #[arg(long)]
        out: Option<PathBuf>,
    },
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
        DesignCommand::Import {
            urdf,
            out,
            thrust_limit,
            fix_joint,
        } => {
            if let Some(l) = thrust_limit {
                anyhow::ensure!(
                    l.is_finite() && *l > 0.0,
                    "--thrust-limit must be finite and > 0, got {l}"
                );
            }
            let opts = ImportOptions {
                thrust_limit: *thrust_limit,
                fixed_joints: fix_joint.clone(),
            };
            let imp = load_urdf(urdf, &opts)?;
            let text = imported_to_toml(&imp, &urdf.display().to_string());
            for i in &imp.inferred {
                eprintln!("[design import] inferred: {}: {}", i.key, i.note);
            }
            emit(&text, out.as_ref())?;
        }
        DesignCommand::Export {
            design,
            format,
            out,
        } => {
            let v = load_design(design)?;
            let text = if format == "mjcf" {
                vehicle_to_mjcf(&v)?
            } else {
                vehicle_to_urdf(&v)?
            };
            emit(&text, out.as_ref())?;
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

/// Print `text`, or write it to `out` through the atomic writer.
fn emit(text: &str, out: Option<&PathBuf>) -> anyhow::Result<()> {
    match out {
        None => print!("{text}"),
        Some(p) => {
            // Its folder is made as `design draw --out` makes its own (the file, not the
            // folder, is the tool's output; an existing folder is left as it is).
            if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("creating the folder {}", dir.display()))?;
            }
            atomic_write(p, text.as_bytes()).with_context(|| format!("writing {}", p.display()))?;
            println!("wrote {}", p.display());
        }
    }
    Ok(())
}

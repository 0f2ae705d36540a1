//! Output pipelines of the single-run commands: each runs the library's computation and writes
//! the command's files (CSV, Parquet, SVG, JSON, Markdown), so that the binary only parses
//! arguments, calls one of these, and prints.
//!
//! - [`tcm`]: the static analysis of `T(q)` over joint space (docs/model.md §6) and its files;
//! - [`simulate`]: the files of one closed-loop scenario run;
//! - [`shapes`]: the body along a run (`shapes.svg`, `animation.svg`);
//! - [`draw`]: the drawing of a design at one state (`design draw`);
//! - [`review`]: `report.html`, the design-review page of a study output directory;
//! - [`inspect`]: the kinematic report of a design at one state (printed by the binary);
//! - [`allocate`]: one thrust-allocation case file, validated and solved with each method;
//! - [`optimise`]: the files of an optimisation (history, best point, summary, plots).
//!
//! The batch sweep's pipeline lives in [`crate::study`]; the paper reproductions (`paper`,
//! `paper readings`, `paper antonelli`) in [`crate::paper`]. No pipeline prints: progress and
//! per-run outcomes reach the caller through callbacks.

pub mod allocate;
pub mod draw;
pub mod error;
pub mod inspect;
pub mod ocp_shapes;
pub mod optimise;
mod optimise_plots;
pub mod review;
mod review_designs;
mod review_page;
mod review_top;
pub mod run_figure;
pub mod shapes;
pub mod simulate;
pub mod tcm;

pub use error::{create_dir, PipelineError};

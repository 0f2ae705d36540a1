//! What a finished study says (issue 37 item 1): `summary.md` as named sections, its verdict
//! over uncertain worlds and the verdict box, "how firm", families of designs, best/worst and
//! Pareto selection, the sweep's SVG plots, the report step (best/worst reruns) and
//! `usm-study report`, re-ranking without re-running. `report.html` is written from these by
//! [`crate::pipeline::review`].
//!
//! - [`selection`], [`families`]: best/worst, Pareto front, families of ranked designs.
//! - [`plots_ranked`], [`plots`]: the sweep's plots, ranked designs told apart.
//! - [`summary_robust`], [`verdict_box`], [`verdict_firm`], [`summary_bound`], [`summary`]:
//!   `summary.md` (with `[ocp]`, the physical-limit section and `plots/bound.svg`).
//! - [`rerank`]: `usm-study report --objective/--pareto`.
//! - [`finish`]: the report step (handed to a sweep as its [`HOOK`]) and `usm-study report`.

pub mod families;
pub mod finish;
pub mod plots;
pub mod plots_ranked;
pub mod rerank;
pub mod selection;
pub mod summary;
pub mod summary_bound;
pub mod summary_robust;
pub mod verdict_box;
pub mod verdict_firm;

pub use finish::{report, report_ranked, Reported, HOOK};
pub use rerank::Rerank;

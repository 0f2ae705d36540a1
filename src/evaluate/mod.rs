//! The one case evaluator (issue 20): every path that scores a case — the sweep worker,
//! per-case tuning, the optimiser and the report's best/worst reruns — goes through
//! [`Evaluator::evaluate`], which takes a design, a scenario-side table, overrides, a seed and
//! a [`Deadline`] and returns one [`CaseResult`]: [`Metrics`] by name, a [`CaseEnd`] with
//! its reason (the `[success]` criterion an unsuccessful run missed) and, when asked, the
//! trajectory.
//!
//! Files (this one only declares and re-exports):
//! - [`deadline`]: [`Deadline`], the one wall-clock budget type, and its timeout message.
//! - [`metrics`]: [`Metrics`] (named metrics) and the design and static column names.
//! - [`status`]: [`CaseEnd`] (how a case ended, with its data) and its [`CaseStatus`] column.
//! - [`overrides`]: [`Override`] and [`apply_overrides`], the one road for whatever varies a
//!   case (axis values, worlds, validation variants, faults, tuning and optimiser points).
//! - [`case`]: [`CaseInput`], [`Evaluator`] (design cache, panic guard, phases), [`CaseResult`].
//! - [`static_table`]: a case's `[static]` table ↔ [`crate::statics::StaticSpec`] (the study
//!   file's section; the evaluator reads it for every case).

pub mod case;
pub mod deadline;
pub mod metrics;
pub mod overrides;
pub mod static_table;
pub mod status;
pub mod trajectory;

pub use case::{out_of_reach, CaseInput, CaseResult, Evaluator, Phases, AUTHORITY_MARGIN};
pub use deadline::{Deadline, Phase, TimedOut, TIMEOUT};
pub use metrics::{Metrics, AUTHORITY_COLUMNS, DESIGN_COLUMNS, N1_LOSS_COLUMNS, TCM_COLUMNS};
pub use overrides::{apply_overrides, Override, OverrideError, Overrides, Side};
pub use status::{
    reason_detail, CaseEnd, CaseStatus, Disqualification, UnknownStatus, PANIC, UNDER_ACTUATED,
};
pub use trajectory::trajectory_table;

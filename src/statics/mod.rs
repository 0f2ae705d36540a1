//! The static analysis of the thruster configuration matrix over joint space (docs/model.md
//! §6): "how often is `T(q)` singular" for one design, without a closed loop. Used by the
//! `tcm` command ([`crate::pipeline::tcm`]) and by studies (a sweep case's static metrics).
//!
//! - [`analysis`]: [`StaticSpec`] (defaults, validation), [`analyse`] / [`analyse_text`] and
//!   the [`StaticSummary`];
//! - [`authority`]: attainable authority in N and N·m over joint space (full limits and a
//!   mission range), under-actuated axes, N−1;
//! - [`dist`]: [`Distribution`], exact quantiles of a per-sample quantity;
//! - [`slice`]: σ_min over 2-D slices of joint space, the most influential joints;
//! - `eval`: the per-sample evaluator (forward kinematics, `T(q)`, scaled σ) and its pools.

pub mod analysis;
pub mod authority;
pub mod dist;
mod eval;
pub mod slice;

pub use analysis::{
    analyse, analyse_text, SinkError, StaticError, StaticSpec, StaticSummary, DEFAULT_MODE,
    DEFAULT_SAMPLES, DEFAULT_SAMPLING, DEFAULT_THRESHOLD, DEFAULT_WORST,
};
pub use authority::{
    authority_analysis, authority_at, authority_over, weakest_ratio, AuthorityReference,
    AuthoritySpec, AuthorityStats, AuthoritySummary, JointRanges, N1Summary, N1Thruster,
};
pub use dist::{distribution, quantile_sorted, Distribution, QUANTILES};
pub use eval::SampleMetrics;

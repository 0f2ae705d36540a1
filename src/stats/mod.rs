//! Statistics kernels for decisions under uncertainty (issue 22): pure functions of their
//! inputs, deterministic (sorted copies, seeded generators, no hashing), independent of thread
//! count.
//!
//! - [`describe`](mod@describe): quantiles (numpy's default, R type 7) and a NaN-ignoring
//!   summary ([`Describe`]) of one metric over worlds;
//! - [`normal`]: the standard normal distribution ([`normal::cdf`], [`normal::inv_cdf`]);
//! - [`sobol`]: Saltelli designs ([`SaltelliDesign`]) and first-order / total Sobol indices
//!   with percentile-bootstrap intervals ([`sobol_indices`]);
//! - [`srrc`](mod@srrc): standardised (rank) regression coefficients ([`srrc()`], [`src()`]);
//! - [`confidence`]: Wilson lower bounds, the exact sign test and Holm's correction;
//! - [`ranking`]: paired ranking of cases over common worlds ([`rank_stats`]) and the
//!   winner-or-tie verdict ([`verdict`]).
//!
//! The formulas and their sources are `docs/statistics.md`.

pub mod confidence;
pub mod describe;
pub mod normal;
pub mod ranking;
pub mod sobol;
pub mod srrc;

pub use describe::{describe, quantile_sorted, Describe};
pub use ranking::{
    rank_stats, verdict, Contender, RankStats, Verdict, VerdictSettings, VerdictSettingsError,
};
pub use sobol::{sobol_indices, SaltelliDesign, SobolIndex};
pub use srrc::{average_ranks, src, srrc, Srrc};

#[cfg(test)]
mod ranking_tests;
#[cfg(test)]
mod tests;

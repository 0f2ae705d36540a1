//! The paper reproductions, above the core: nothing below this room imports it.
//!
//! - [`usm`]: the USM paper's simulations (`usm-study paper`), their files and comparison
//!   tables; [`readings`]: transport mode under every reading of the paper's open choices;
//!   [`transport_claims`]: the paper's transport claims under the printed and the adopted
//!   reading, with and without cross-flow lift, from the trajectory figures of
//!   [`transport_metrics`];
//!   [`secondary`]: the paper's secondary objectives on and off;
//! - [`antonelli`]: Antonelli & Chiaverini's kinematic case studies 1, 1b, 2 and
//!   ([`antonelli::dynamic`]) case 3 on the NPS AUV II ([`nps_auv2`]) under the sliding-mode
//!   base control ([`sliding`]); [`antonelli_outputs`]: `paper antonelli` and the
//!   `simulate antonelli-*` presets, their CSVs and summary; [`antonelli_figures`]: their
//!   figures;
//! - [`published_drag`]: the hull drag of docs/model.md §2 against the NPS AUV II and REMUS
//!   100 (`paper drag`, `results/drag/`).
//!
//! The formulation these reproduce is `docs/model.md` (AC-nn, USM-nn).

pub mod antonelli;
pub mod antonelli_figures;
pub mod antonelli_outputs;
pub mod nps_auv2;
pub mod published_drag;
pub mod readings;
pub mod secondary;
pub mod sliding;
pub mod transport_claims;
pub mod transport_metrics;
pub mod usm;

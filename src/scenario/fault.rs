//! `[fault]`: one thruster fault in a run (docs/model.md §5, thruster faults).
//!
//! A fault strikes thruster `thruster` (0-based index, or its name) at the first control period
//! with `t ≥ at` and lasts to the end of the run. Its `kind`:
//! - `dead`: the thruster produces no thrust;
//! - `stuck`: it produces `value` [N] (default: the thrust it was producing at the fault time),
//!   clamped to its limits;
//! - `derated`: its limits are multiplied by `value` ∈ (0, 1].
//!
//! `informed = true` (the default) reconfigures the allocator at the fault time: it is given
//! T(q) with the faulted column removed (dead), removed with the stuck thrust moved to the
//! right-hand side (`τ − T_j u_stuck`, stuck), or scaled by the factor (derated: the allocator
//! decides `v_j` in the original limits and the thruster produces `value · v_j`, so the limits
//! are exact and its usage weight grows by `1/value²`). `informed = false` leaves the allocator
//! as it was: it keeps allocating to the thruster, and the vehicle gets the faulted thrust.
//!
//! Either way the thrust the vehicle gets — logged, integrated into the energy and the effort,
//! and used for the allocation residual — is the faulted one. The fault changes the thrust
//! command of the thruster: with a lag or rate model (`[thrusters] model`), a dead thruster
//! spins down with its own dynamics. The σ metrics of T(q) stay those of the healthy layout.
//! Nothing here allocates after [`Fault::new`].

use crate::input::located::KeyError;
use crate::model::Vehicle;
use crate::spatial::Vec6;
use nalgebra::Matrix6xX;
use serde::{Deserialize, Serialize};

/// Which thruster a fault strikes: its 0-based index or its name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ThrusterRef {
    /// 0-based index in the design's thruster list.
    Index(i64),
    /// The thruster's name in the design.
    Name(String),
}

/// What a fault does to its thruster.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// No thrust.
    Dead,
    /// A fixed thrust `value` [N] (default: the thrust at the fault time).
    Stuck,
    /// Limits multiplied by `value` ∈ (0, 1].
    Derated,
}

impl FaultKind {
    /// The kind as written in files: `dead`, `stuck`, `derated`.
    pub fn label(self) -> &'static str {
        match self {
            FaultKind::Dead => "dead",
            FaultKind::Stuck => "stuck",
            FaultKind::Derated => "derated",
        }
    }
}

fn yes() -> bool {
    true
}

fn dead() -> FaultKind {
    FaultKind::Dead
}

/// `[fault]`: one thruster fault (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// The faulted thruster: 0-based index or name.
    pub thruster: ThrusterRef,
    /// Fault time [s] (≥ 0; default 0).
    #[serde(default)]
    pub at: f64,
    /// `dead` (default), `stuck` or `derated`.
    #[serde(default = "dead")]
    pub kind: FaultKind,
    /// `stuck`: the thrust [N] (default: the thrust at the fault time); `derated`: the factor
    /// on the limits, in (0, 1] (required); `dead`: not allowed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// Whether the allocator is reconfigured at the fault time (default true).
    #[serde(default = "yes")]
    pub informed: bool,
}

impl FaultSpec {
    /// Check the values that do not need the vehicle.
    pub fn validate(&self) -> Result<(), KeyError> {
        if !self.at.is_finite() || self.at < 0.0 {
            return Err(KeyError::new(
                "fault.at",
                format!("must be a finite time ≥ 0 s, got {}", self.at),
            ));
        }
        match (self.kind, self.value) {
            (FaultKind::Dead, Some(_)) => Err(KeyError::new(
                "fault.value",
                "a dead thruster takes no value (use kind = \"stuck\" for a fixed thrust)",
            )),
            (FaultKind::Stuck, Some(v)) if !v.is_finite() => Err(KeyError::new(
                "fault.value",
                format!("the stuck thrust must be finite, got {v}"),
            )),
            (FaultKind::Derated, None) => Err(KeyError::new(
                "fault.value",
                "kind = \"derated\" needs value = the factor on the limits, in (0, 1]",
            )),
            (FaultKind::Derated, Some(v)) if !(v > 0.0 && v <= 1.0) => Err(KeyError::new(
                "fault.value",
                format!("the derating factor must be in (0, 1], got {v}"),
            )),
            _ => Ok(()),
        }
    }

    /// The 0-based index of the faulted thruster on `v`.
    pub fn thruster_index(&self, v: &Vehicle) -> Result<usize, KeyError> {
        let n = v.n_thrusters();
        match &self.thruster {
            ThrusterRef::Index(i) if *i >= 0 && (*i as u64) < n as u64 => Ok(*i as usize),
            ThrusterRef::Index(i) => Err(KeyError::new(
                "fault.thruster",
                format!(
                    "no thruster {i}: the design has {n} thrusters (indices 0 to {})",
                    n.saturating_sub(1)
                ),
            )),
            ThrusterRef::Name(name) => {
                v.thrusters
                    .iter()
                    .position(|t| &t.name == name)
                    .ok_or_else(|| {
                        let names: Vec<&str> =
                            v.thrusters.iter().map(|t| t.name.as_str()).collect();
                        KeyError::new(
                            "fault.thruster",
                            format!(
                                "no thruster named {name:?}; the design's thrusters are {}",
                                names.join(", ")
                            ),
                        )
                    })
            }
        }
    }
}

/// A fault during a run: the resolved spec, its state and the reconfigured allocator inputs
/// (sized once).
#[derive(Clone, Debug)]
pub(crate) struct Fault {
    kind: FaultKind,
    j: usize,
    at: f64,
    value: Option<f64>,
    informed: bool,
    u_min: f64,
    u_max: f64,
    /// The thrust the faulted thruster produces once stuck [N].
    stuck: f64,
    /// The simulation time the fault struck [s]; `None` before.
    pub struck_at: Option<f64>,
    /// T(q) as the informed allocator sees it.
    t_alloc: Matrix6xX<f64>,
}

impl Fault {
    /// The fault of `spec` on `v` (the vehicle of the run, limits scaled).
    pub fn new(spec: &FaultSpec, v: &Vehicle) -> Result<Self, KeyError> {
        spec.validate()?;
        let j = spec.thruster_index(v)?;
        let th = &v.thrusters[j];
        Ok(Self {
            kind: spec.kind,
            j,
            at: spec.at,
            value: spec.value,
            informed: spec.informed,
            u_min: th.u_min,
            u_max: th.u_max,
            stuck: 0.0,
            struck_at: None,
            t_alloc: Matrix6xX::zeros(v.n_thrusters()),
        })
    }

    /// Strike at the first period with `t ≥ at` (1e-9 s tolerance for the control grid);
    /// `u_now` is the thrust the faulted thruster produces then [N]. Whether it is active.
    pub fn update(&mut self, t: f64, u_now: f64) -> bool {
        if self.struck_at.is_none() && t >= self.at - 1e-9 {
            self.struck_at = Some(t);
            self.stuck = self.value.unwrap_or(u_now).clamp(self.u_min, self.u_max);
        }
        self.struck_at.is_some()
    }

    /// Whether the allocator must see reconfigured inputs now.
    pub fn reconfigures(&self) -> bool {
        self.informed && self.struck_at.is_some()
    }

    /// The informed allocator's T(q) and τ (see the module documentation).
    pub fn reconfigured(&mut self, t_mat: &Matrix6xX<f64>, tau: &Vec6) -> (&Matrix6xX<f64>, Vec6) {
        self.t_alloc.copy_from(t_mat);
        let mut tau = *tau;
        let factor = self.factor();
        let mut col = self.t_alloc.column_mut(self.j);
        match self.kind {
            FaultKind::Dead => col.fill(0.0),
            FaultKind::Stuck => {
                tau -= t_mat.column(self.j) * self.stuck;
                col.fill(0.0);
            }
            FaultKind::Derated => col *= factor,
        }
        (&self.t_alloc, tau)
    }

    fn factor(&self) -> f64 {
        self.value.unwrap_or(1.0)
    }

    /// Overwrite the allocator's thrusts `u` with what the thrusters produce (after the fault
    /// struck): dead 0, stuck the stuck thrust, derated the derated limits (informed: `value · v_j`).
    pub fn produce(&self, u: &mut [f64]) {
        if self.struck_at.is_none() {
            return;
        }
        let u = &mut u[self.j];
        match self.kind {
            FaultKind::Dead => *u = 0.0,
            FaultKind::Stuck => *u = self.stuck,
            FaultKind::Derated => {
                let f = self.factor();
                if self.informed {
                    *u *= f;
                }
                *u = u.clamp(f * self.u_min, f * self.u_max);
            }
        }
    }

    /// The faulted thruster's index.
    pub fn thruster(&self) -> usize {
        self.j
    }
}

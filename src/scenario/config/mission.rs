//! `[mission]`: what a design must do beyond following the path or holding the setpoint —
//! carry a payload at the end effector, reach a distance, converge by a deadline (docs/model.md
//! §6 "Missions"). A design that cannot meet a requirement is unsuccessful with the
//! requirement named (`mission.reach`, `mission.deadline`; `outcome::judge::judge`).
//!
//! ```toml
//! [mission]
//! payload_mass = 2.0     # kg, a point mass at the end-effector frame (0 = none)
//! payload_volume = 0.002 # m³ displaced by the payload; omitted = neutrally buoyant (m/ρ)
//! # payload_wet_weight = 2.0 # N, instead of payload_volume: m g − ρ V g (positive sinks)
//! reach = 2.6            # m, |base origin → end effector| at the straight configuration (0 = none)
//! deadline = 30.0        # s, transport: every reached segment converges this soon (0 = none)
//! tracking_weight = 0.1  # J/m per m·s: mission_cost = total_energy_per_metre + w·cross_track_iae
//! ```
//!
//! Every default leaves a run bit for bit as it was without the table.

use crate::input::located::{fmt_exact, KeyError};
use serde::{Deserialize, Serialize};

/// `[mission]`: payload, reach and deadline requirements. Defaults: none of them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MissionSpec {
    /// Payload mass [kg] carried as a point mass at the origin of the end-effector frame
    /// `F_e` (`model::Vehicle::add_payload`); 0 = no payload.
    pub payload_mass: f64,
    /// Volume [m³] the payload displaces (its buoyancy acts at `F_e`); `None` = neutrally
    /// buoyant, `payload_mass / ρ` (transport has no depth hold, so a heavy payload sinks).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub payload_volume: Option<f64>,
    /// Wet weight [N] of the payload, `m_p g − ρ V_p g` (positive sinks): its volume
    /// instead of `payload_volume` (a scalar key an uncertain world can vary; not with
    /// `payload_volume`). 0 (the default) = neutrally buoyant.
    pub payload_wet_weight: f64,
    /// Required reach [m]: the distance from the base frame's origin to the end effector at
    /// the straight configuration `q = 0` (metric `reach`) must be at least this; 0 = none.
    pub reach: f64,
    /// Transport: every segment the run reaches must converge (metric
    /// `seg<k>_convergence_time`) within this many seconds of becoming active; 0 = none.
    /// Stricter than `success.convergence_window` when smaller.
    pub deadline: f64,
    /// Transport: the price of being off the path, in J/m per m·s of `cross_track_iae`: the
    /// metric `mission_cost = total_energy_per_metre + tracking_weight · cross_track_iae`
    /// [J/m], the default objective of transport studies. 0 (the default) = energy alone.
    pub tracking_weight: f64,
}

impl MissionSpec {
    /// Check the values; errors name `mission.<key>`.
    pub fn validate(&self) -> Result<(), KeyError> {
        for (k, v) in [
            ("payload_mass", self.payload_mass),
            ("reach", self.reach),
            ("deadline", self.deadline),
            ("tracking_weight", self.tracking_weight),
            ("payload_volume", self.payload_volume.unwrap_or(0.0)),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(KeyError::new(
                    format!("mission.{k}"),
                    format!("must be a finite number >= 0, got {}", fmt_exact(v)),
                ));
            }
        }
        if !self.payload_wet_weight.is_finite() {
            return Err(KeyError::new(
                "mission.payload_wet_weight",
                format!("must be finite, got {}", fmt_exact(self.payload_wet_weight)),
            ));
        }
        if self.payload_wet_weight != 0.0 && self.payload_volume.is_some() {
            return Err(KeyError::new(
                "mission.payload_wet_weight",
                "give the payload's buoyancy once: payload_volume or payload_wet_weight",
            ));
        }
        Ok(())
    }

    /// The payload's displaced volume [m³] in fluid of density `rho` [kg/m³] under gravity
    /// `g` [m/s²]: `payload_volume`, else `(m_p g − payload_wet_weight)/(ρ g)` (neutral, `m_p/ρ`,
    /// when the wet weight is 0). A wet weight above the payload's weight (a negative volume)
    /// is an error at `mission.payload_wet_weight`.
    pub fn payload_volume_in(&self, rho: f64, g: f64) -> Result<f64, KeyError> {
        if let Some(v) = self.payload_volume {
            return Ok(v);
        }
        if self.payload_wet_weight == 0.0 {
            return Ok(self.payload_mass / rho);
        }
        let weight = self.payload_mass * g;
        if self.payload_wet_weight > weight || g <= 0.0 {
            return Err(KeyError::new(
                "mission.payload_wet_weight",
                format!(
                    "cannot exceed the payload's weight m_p g = {} N (its volume would be \
                     negative), got {}",
                    fmt_exact(weight),
                    fmt_exact(self.payload_wet_weight)
                ),
            ));
        }
        Ok((weight - self.payload_wet_weight) / (rho * g))
    }

    /// Whether the table asks for anything (a default table changes nothing).
    pub fn is_active(&self) -> bool {
        self.payload_mass > 0.0
            || self.payload_volume.is_some_and(|v| v > 0.0)
            || self.payload_wet_weight != 0.0
            || self.reach > 0.0
            || self.deadline > 0.0
            || self.tracking_weight > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::MissionSpec;

    #[test]
    fn validation_names_the_key_and_defaults_ask_nothing() {
        assert!(!MissionSpec::default().is_active());
        assert!(MissionSpec::default().validate().is_ok());
        let bad = MissionSpec {
            reach: -1.0,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "mission.reach");
        let bad = MissionSpec {
            payload_volume: Some(f64::NAN),
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "mission.payload_volume");
    }

    #[test]
    fn a_payload_wet_weight_sets_its_volume() {
        let m = MissionSpec {
            payload_mass: 2.0,
            payload_wet_weight: 4.0,
            ..Default::default()
        };
        assert!(m.validate().is_ok() && m.is_active());
        let v = m.payload_volume_in(1000.0, 10.0).unwrap();
        assert!((v - (20.0 - 4.0) / 1e4).abs() < 1e-18);
        let neutral = MissionSpec {
            payload_mass: 2.0,
            ..Default::default()
        };
        assert_eq!(
            neutral.payload_volume_in(1026.0, 9.81).unwrap(),
            2.0 / 1026.0
        );
        let heavy = MissionSpec {
            payload_wet_weight: 25.0,
            ..m.clone()
        };
        let e = heavy.payload_volume_in(1000.0, 10.0).unwrap_err();
        assert_eq!(e.key, "mission.payload_wet_weight");
        let both = MissionSpec {
            payload_volume: Some(0.001),
            ..m
        };
        assert_eq!(
            both.validate().unwrap_err().key,
            "mission.payload_wet_weight"
        );
    }
}

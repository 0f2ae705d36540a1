//! The physical sections of a scenario file: `[servo]` (joint servos, docs/model.md §4), `[thrusters]`
//! (thruster dynamics) and `[physics]` (which effects act, the current, the time integrator).
//! Re-exported by [`super`]; their translation into a [`crate::dynamics::SimConfig`] stays
//! there.

use crate::dynamics::{Integrator, ServoModel};
use serde::{Deserialize, Serialize};

/// `[servo]`: joint servo model (docs/model.md §4).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ServoSpec {
    /// `second_order` (ideal reference filter, hybrid dynamics) or `torque_pd`.
    pub kind: String,
    /// Natural frequency ω_n [rad/s] of the reference filter.
    pub omega_n: f64,
    /// Damping ratio of the reference filter.
    pub zeta: f64,
    /// PD proportional gain [N·m/rad].
    pub kp: f64,
    /// PD derivative gain [N·m·s/rad].
    pub kd: f64,
    /// PD torque limit [N·m].
    pub torque_limit: f64,
}

impl Default for ServoSpec {
    fn default() -> Self {
        Self {
            kind: "second_order".into(),
            omega_n: ServoModel::DEFAULT_OMEGA_N,
            zeta: ServoModel::DEFAULT_ZETA,
            kp: 200.0,
            kd: 40.0,
            torque_limit: 100.0,
        }
    }
}

/// `[thrusters]`: thruster dynamics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThrusterSpec {
    /// `ideal`, `lag`, `rate` or `model` (each thruster's own lag/rate from the design).
    pub model: String,
    /// Lag time constant [s] for `lag` (0 = each thruster's own).
    pub time_constant: f64,
    /// Rate limit [N/s] for `rate` (0 = each thruster's own).
    pub rate_limit: f64,
    /// Factor on every thruster's thrust limits (derating; > 0, nominal 1): an uncertain
    /// world's key (docs/assumptions.md).
    pub limit_scale: f64,
}

impl Default for ThrusterSpec {
    fn default() -> Self {
        Self {
            model: "ideal".into(),
            time_constant: 0.0,
            rate_limit: 0.0,
            limit_scale: 1.0,
        }
    }
}

impl PhysicsSpec {
    /// The current's world keys within their ranges: `current_vertical` finite with
    /// |w| ≤ 1 m/s (ocean vertical currents are of mm/s to cm/s; the bound refuses a unit
    /// slip, e.g. cm/s written as m/s).
    pub fn validate_current(&self) -> Result<(), crate::input::located::KeyError> {
        let w = self.current_vertical;
        if !w.is_finite() || w.abs() > 1.0 {
            return Err(crate::input::located::KeyError::new(
                "physics.current_vertical",
                format!("must be finite with |w| <= 1 m/s, got {w}"),
            ));
        }
        Ok(())
    }

    /// The current in the inertial frame [m/s]: `current` plus the horizontal current of
    /// `current_speed` towards `current_direction`, plus `current_vertical` along inertial +z
    /// (up).
    pub fn total_current(&self) -> [f64; 3] {
        let mut c = self.current;
        if self.current_speed != 0.0 {
            let a = self.current_direction.to_radians();
            c[0] += self.current_speed * a.cos();
            c[1] += self.current_speed * a.sin();
        }
        if self.current_vertical != 0.0 {
            c[2] += self.current_vertical;
        }
        c
    }
}

/// `[hydro]`: whole-design scale factors of the hydrodynamics and buoyancy (an uncertain
/// world's keys; docs/assumptions.md). Nominal values change nothing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HydroScaleSpec {
    /// Factor on every body's linear damping (≥ 0).
    pub linear_damping_scale: f64,
    /// Factor on the roll entry of the linear damping, on top (≥ 0).
    pub roll_damping_scale: f64,
    /// Factor on the quadratic drag coefficients (≥ 0).
    pub drag_scale: f64,
    /// Factor on the added mass (≥ 0).
    pub added_mass_scale: f64,
    /// Relative buoyancy offset: displaced volumes × (1 + offset) (> −1).
    pub buoyancy_offset: f64,
    /// Slender-body lift slope `C_Lα` [1/rad] on `π r²` of every cylinder body, acting at the
    /// chain's free trailing face (docs/model.md §2 "Lift"; ≥ 0). Default 0: no lift; 2 is
    /// slender-body theory's value for a blunt-based body.
    pub lift_slope: f64,
    /// Apply that lift at every body's trailing face (each body its own blunt base), not only
    /// at the chain's free faces: an upper bound on the lift (default false).
    pub lift_every_body: bool,
    /// Shift [m] of every body's centre of buoyancy along its own z axis (up when level):
    /// a metacentric-height error (`ModelScales::cb_offset_z`; |shift| ≤ the body's radius).
    pub cb_offset_z: f64,
    /// Shift [m] of every body's centre of buoyancy along its own x axis (towards the head):
    /// a longitudinal trim error, a pitch moment `B·shift` at level (|shift| ≤ half the
    /// body's length).
    pub cb_offset_x: f64,
    /// Keep the controller's model at the nominal design while the plant takes this world:
    /// the base control's `M_11` and `n` (USM-33/35) come from the design without the scale
    /// factors and centre-of-buoyancy shifts above, in still water, the mission payload
    /// neutrally buoyant (`scenario::nominal`). Default false: the controller cancels the
    /// plant's own terms.
    pub controller_nominal: bool,
    /// Factor on the hull's skin friction (ITTC-57 line; docs/model.md §2 "Hull drag"), on
    /// top of `drag_scale` (≥ 0).
    pub skin_friction_scale: f64,
    /// Factor on the hull's nose and base (form) drag, on top of `drag_scale` (≥ 0).
    pub form_drag_scale: f64,
    /// Factor on the hull's appendage allowance (thrusters, joint gaps), on top of
    /// `drag_scale` (≥ 0).
    pub appendage_scale: f64,
}

impl Default for HydroScaleSpec {
    fn default() -> Self {
        Self {
            linear_damping_scale: 1.0,
            roll_damping_scale: 1.0,
            drag_scale: 1.0,
            added_mass_scale: 1.0,
            buoyancy_offset: 0.0,
            lift_slope: 0.0,
            lift_every_body: false,
            cb_offset_z: 0.0,
            cb_offset_x: 0.0,
            controller_nominal: false,
            skin_friction_scale: 1.0,
            form_drag_scale: 1.0,
            appendage_scale: 1.0,
        }
    }
}

/// The study keys of the scale factors, for error messages.
pub const SCALE_KEYS: crate::model::world::ScaleKeys = crate::model::world::ScaleKeys {
    linear_damping: "hydro.linear_damping_scale",
    roll_damping: "hydro.roll_damping_scale",
    drag: "hydro.drag_scale",
    added_mass: "hydro.added_mass_scale",
    buoyancy_offset: "hydro.buoyancy_offset",
    thrust_limit: "thrusters.limit_scale",
    lift_slope: "hydro.lift_slope",
    cb_offset_z: "hydro.cb_offset_z",
    cb_offset_x: "hydro.cb_offset_x",
    skin_friction: "hydro.skin_friction_scale",
    form_drag: "hydro.form_drag_scale",
    appendage: "hydro.appendage_scale",
};

impl HydroScaleSpec {
    /// The model scales of this section with the thrust-limit factor of `[thrusters]`.
    pub fn scales(&self, limit_scale: f64) -> crate::model::world::ModelScales {
        crate::model::world::ModelScales {
            linear_damping: self.linear_damping_scale,
            roll_damping: self.roll_damping_scale,
            drag: self.drag_scale,
            added_mass: self.added_mass_scale,
            buoyancy_offset: self.buoyancy_offset,
            thrust_limit: limit_scale,
            lift_slope: self.lift_slope,
            lift_every_body: self.lift_every_body,
            cb_offset_z: self.cb_offset_z,
            cb_offset_x: self.cb_offset_x,
            skin_friction: self.skin_friction_scale,
            form_drag: self.form_drag_scale,
            appendage: self.appendage_scale,
        }
    }
}

/// `(rtol, atol)` of [`Integrator::dopri5_default`].
const DOPRI5_DEFAULT: (f64, f64) = match Integrator::dopri5_default() {
    Integrator::Dopri5 { rtol, atol, .. } => (rtol, atol),
    Integrator::Rk4 { .. } => (0.0, 0.0),
};

/// `[physics]`: which effects act, the current, and the time integrator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsSpec {
    /// Added mass (and its Kirchhoff term).
    pub added_mass: bool,
    /// Hydrodynamic damping.
    pub drag: bool,
    /// Weight and buoyancy.
    pub restoring: bool,
    /// Constant irrotational current, inertial frame [m/s].
    pub current: [f64; 3],
    /// Speed [m/s] of a horizontal current added to `current` (an uncertain world's key).
    pub current_speed: f64,
    /// Direction [deg] of that current: the angle from inertial +x towards +y.
    pub current_direction: f64,
    /// Vertical current [m/s] added to `current` along inertial +z (up; an uncertain world's
    /// key: upwelling > 0, downwelling < 0; |w| ≤ 1 m/s).
    pub current_vertical: f64,
    /// Time integrator: `"dopri5"` (adaptive Dormand–Prince 5(4), the default) or `"rk4"`
    /// (fixed steps of `scenario.dt`); see [`Integrator`].
    pub integrator: String,
    /// Relative tolerance of `dopri5` (> 0). Default from [`Integrator::dopri5_default`].
    pub rtol: f64,
    /// Absolute tolerance of `dopri5` (> 0). Default from [`Integrator::dopri5_default`].
    pub atol: f64,
}

impl Default for PhysicsSpec {
    fn default() -> Self {
        Self {
            added_mass: true,
            drag: true,
            restoring: true,
            current: [0.0; 3],
            current_speed: 0.0,
            current_direction: 0.0,
            current_vertical: 0.0,
            integrator: "dopri5".into(),
            rtol: DOPRI5_DEFAULT.0,
            atol: DOPRI5_DEFAULT.1,
        }
    }
}

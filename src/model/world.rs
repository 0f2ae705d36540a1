//! Whole-design scale factors of an uncertain world (issue 22; docs/assumptions.md): the
//! inferred and measured-with-error quantities of a design scaled together, so that an
//! uncertainty study can ask "what if the linear damping we inferred is twice too large?"
//! without editing every body.
//!
//! The nominal scales ([`ModelScales::default`]) change nothing, bit for bit.

use super::error::ModelError;
use super::{Hydro, Vehicle};
use crate::spatial::{Mat3, Vec3};

/// Scale factors applied to every body and thruster of a design (dimensionless).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelScales {
    /// Factor on all six linear-damping entries of every body (cylinder `linear_damping`,
    /// coefficient `D_l`). Nominal 1.
    pub linear_damping: f64,
    /// Factor on the roll entry of the linear damping, on top of `linear_damping`. Nominal 1.
    pub roll_damping: f64,
    /// Factor on the quadratic drag (cylinder `cd_x`, `cd_y`, `cd_z`; coefficient `D_q`).
    /// Nominal 1.
    pub drag: f64,
    /// Factor on the added-mass matrix `M_A` of every body. Nominal 1.
    pub added_mass: f64,
    /// Relative buoyancy offset δ: every displaced volume × (1 + δ). Nominal 0.
    pub buoyancy_offset: f64,
    /// Factor on every thrust limit `u_min`, `u_max` (derating). Nominal 1.
    pub thrust_limit: f64,
    /// Slender-body lift slope `C_Lα` [1/rad] set on every cylinder body (`Hydro::Cylinder`
    /// `lift_slope`; docs/model.md §2 "Lift"). Not a factor: nominal 0, no lift. Bodies given
    /// by coefficient matrices take no lift.
    pub lift_slope: f64,
    /// Lift at every body's trailing face, not only at the chain's free faces
    /// (`Hydro::Cylinder` `lift_every_body`). Nominal false.
    pub lift_every_body: bool,
    /// Shift [m] of every body's centre of buoyancy along its own z axis: a metacentric-height
    /// error (positive raises the CB, more righting moment). Not a factor: nominal 0;
    /// |shift| ≤ the body's radius (the CB of the displaced volume stays inside the body).
    pub cb_offset_z: f64,
    /// Shift [m] of every body's centre of buoyancy along its own x axis (towards the head):
    /// a longitudinal trim error, the pitch moment `ρ V g · shift` per body at level. Nominal
    /// 0; |shift| ≤ half the body's length.
    pub cb_offset_x: f64,
    /// Factor on the hull's skin friction (`HullDrag::friction_scale`; docs/model.md §2 "Hull
    /// drag"), on top of `drag`. Nominal 1.
    pub skin_friction: f64,
    /// Factor on the hull's nose and base drag (`HullDrag::form_scale`), on top of `drag`.
    /// Nominal 1.
    pub form_drag: f64,
    /// Factor on the hull's appendage allowance (`HullDrag::appendage_scale`: thrusters and
    /// joint gaps), on top of `drag`. Nominal 1.
    pub appendage: f64,
}

impl Default for ModelScales {
    fn default() -> Self {
        Self {
            linear_damping: 1.0,
            roll_damping: 1.0,
            drag: 1.0,
            added_mass: 1.0,
            buoyancy_offset: 0.0,
            thrust_limit: 1.0,
            lift_slope: 0.0,
            lift_every_body: false,
            cb_offset_z: 0.0,
            cb_offset_x: 0.0,
            skin_friction: 1.0,
            form_drag: 1.0,
            appendage: 1.0,
        }
    }
}

impl ModelScales {
    /// Whether the scales leave the hydrodynamics untouched.
    fn hydro_nominal(&self) -> bool {
        self.linear_damping == 1.0
            && self.roll_damping == 1.0
            && self.drag == 1.0
            && self.added_mass == 1.0
            && self.lift_slope == 0.0
            && !self.lift_every_body
            && self.skin_friction == 1.0
            && self.form_drag == 1.0
            && self.appendage == 1.0
    }

    /// Check the factors: finite, the damping, drag and added-mass factors ≥ 0, the thrust
    /// factor > 0 and the buoyancy offset > −1. `key` names the offending factor as given.
    pub fn validate(&self, keys: &ScaleKeys) -> Result<(), ModelError> {
        for (k, v) in [
            (keys.linear_damping, self.linear_damping),
            (keys.roll_damping, self.roll_damping),
            (keys.drag, self.drag),
            (keys.added_mass, self.added_mass),
            (keys.lift_slope, self.lift_slope),
            (keys.skin_friction, self.skin_friction),
            (keys.form_drag, self.form_drag),
            (keys.appendage, self.appendage),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(ModelError::new(
                    k,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        if !self.thrust_limit.is_finite() || self.thrust_limit <= 0.0 {
            return Err(ModelError::new(
                keys.thrust_limit,
                format!("must be finite and > 0, got {}", self.thrust_limit),
            ));
        }
        for (k, v) in [
            (keys.cb_offset_z, self.cb_offset_z),
            (keys.cb_offset_x, self.cb_offset_x),
        ] {
            if !v.is_finite() {
                return Err(ModelError::new(k, format!("must be finite, got {v}")));
            }
        }
        if !self.buoyancy_offset.is_finite() || self.buoyancy_offset <= -1.0 {
            return Err(ModelError::new(
                keys.buoyancy_offset,
                format!("must be finite and > -1, got {}", self.buoyancy_offset),
            ));
        }
        Ok(())
    }
}

/// The names under which the scale factors are given (for error messages).
#[derive(Clone, Copy, Debug)]
pub struct ScaleKeys {
    /// Name of [`ModelScales::linear_damping`].
    pub linear_damping: &'static str,
    /// Name of [`ModelScales::roll_damping`].
    pub roll_damping: &'static str,
    /// Name of [`ModelScales::drag`].
    pub drag: &'static str,
    /// Name of [`ModelScales::added_mass`].
    pub added_mass: &'static str,
    /// Name of [`ModelScales::buoyancy_offset`].
    pub buoyancy_offset: &'static str,
    /// Name of [`ModelScales::thrust_limit`].
    pub thrust_limit: &'static str,
    /// Name of [`ModelScales::lift_slope`].
    pub lift_slope: &'static str,
    /// Name of [`ModelScales::cb_offset_z`].
    pub cb_offset_z: &'static str,
    /// Name of [`ModelScales::cb_offset_x`].
    pub cb_offset_x: &'static str,
    /// Name of [`ModelScales::skin_friction`].
    pub skin_friction: &'static str,
    /// Name of [`ModelScales::form_drag`].
    pub form_drag: &'static str,
    /// Name of [`ModelScales::appendage`].
    pub appendage: &'static str,
}

impl Vehicle {
    /// Apply whole-design scale factors in place (see [`ModelScales`]). Nominal factors leave
    /// the vehicle bit-identical. Bodies described by manoeuvring derivatives take no
    /// hydrodynamic factor (their tables are measured as a whole): a non-nominal one is an
    /// error at `body[i].hydro`.
    pub fn apply_scales(&mut self, s: &ModelScales, keys: &ScaleKeys) -> Result<(), ModelError> {
        s.validate(keys)?;
        for (i, b) in self.bodies.iter_mut().enumerate() {
            if s.buoyancy_offset != 0.0 {
                b.volume *= 1.0 + s.buoyancy_offset;
            }
            shift_cb(b, s, keys)?;
            if s.hydro_nominal() {
                continue;
            }
            match &mut b.hydro {
                Hydro::Cylinder {
                    cd_x,
                    cd_y,
                    cd_z,
                    linear_damping,
                    added_mass_scale,
                    lift_slope,
                    lift_every_body,
                    hull,
                    ..
                } => {
                    if let Some(h) = hull {
                        h.friction_scale *= s.drag * s.skin_friction;
                        h.form_scale *= s.drag * s.form_drag;
                        h.appendage_scale *= s.drag * s.appendage;
                    }
                    for d in linear_damping.iter_mut() {
                        *d *= s.linear_damping;
                    }
                    linear_damping[3] *= s.roll_damping;
                    for c in [cd_x, cd_y, cd_z] {
                        *c *= s.drag;
                    }
                    *added_mass_scale *= s.added_mass;
                    *lift_slope = s.lift_slope;
                    *lift_every_body = s.lift_every_body;
                }
                Hydro::Coefficients {
                    added_mass,
                    linear,
                    quadratic,
                } => {
                    *linear *= s.linear_damping;
                    linear[(3, 3)] *= s.roll_damping;
                    *quadratic *= s.drag;
                    *added_mass *= s.added_mass;
                }
                Hydro::Manoeuvring(_) => {
                    return Err(ModelError::new(
                        format!("body[{i}].hydro"),
                        "the hydrodynamic scale factors (damping, drag, added mass) and the \
                         lift slope do not apply to a hull given by manoeuvring derivatives",
                    ))
                }
            }
        }
        if s.thrust_limit != 1.0 {
            for t in &mut self.thrusters {
                t.u_min *= s.thrust_limit;
                t.u_max *= s.thrust_limit;
            }
        }
        Ok(())
    }
}

/// Shift `b`'s centre of buoyancy by the world's offsets, each within the body (the error
/// names the key and the body).
fn shift_cb(b: &mut super::Body, s: &ModelScales, keys: &ScaleKeys) -> Result<(), ModelError> {
    for (key, shift, bound, axis) in [
        (keys.cb_offset_z, s.cb_offset_z, b.radius, 2),
        (keys.cb_offset_x, s.cb_offset_x, 0.5 * b.length, 0),
    ] {
        if shift == 0.0 {
            continue;
        }
        if shift.abs() > bound {
            return Err(ModelError::new(
                key,
                format!(
                    "moves body {}'s centre of buoyancy out of the body: |{shift}| m > {bound} m",
                    b.name
                ),
            ));
        }
        b.cb[axis] += shift;
    }
    Ok(())
}

impl Vehicle {
    /// Carry a point-mass payload of `mass` [kg] displacing `volume` [m³] at the origin of the
    /// end-effector frame `F_e` (a mission's payload, docs/model.md §6 "Missions"). The last
    /// body's mass, centre of gravity (mass-weighted), rotational inertia about the new centre
    /// of gravity (parallel-axis theorem; the point mass has none about itself), displaced
    /// volume and centre of buoyancy (volume-weighted) change; its added mass and drag do not.
    /// `mass = volume = 0` changes nothing, bit for bit.
    pub fn add_payload(&mut self, mass: f64, volume: f64) -> Result<(), ModelError> {
        for (k, v) in [
            ("mission.payload_mass", mass),
            ("mission.payload_volume", volume),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(ModelError::new(
                    k,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        if mass == 0.0 && volume == 0.0 {
            return Ok(());
        }
        let at = self.end_effector.p;
        let Some(body) = self.bodies.last_mut() else {
            return Err(ModelError::new(
                "design",
                "a payload needs at least one body",
            ));
        };
        let m = body.mass + mass;
        let cg = (body.cg * body.mass + at * mass) / m;
        let shift =
            |mass: f64, d: Vec3| (Mat3::identity() * d.norm_squared() - d * d.transpose()) * mass;
        body.inertia += shift(body.mass, body.cg - cg) + shift(mass, at - cg);
        if volume > 0.0 {
            let v = body.volume + volume;
            body.cb = (body.cb * body.volume + at * volume) / v;
            body.volume = v;
        }
        body.mass = m;
        body.cg = cg;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    const KEYS: ScaleKeys = ScaleKeys {
        linear_damping: "ld",
        roll_damping: "rd",
        drag: "drag",
        added_mass: "am",
        buoyancy_offset: "bo",
        thrust_limit: "tl",
        lift_slope: "ls",
        cb_offset_z: "cbz",
        cb_offset_x: "cbx",
        skin_friction: "sf",
        form_drag: "fd",
        appendage: "ap",
    };

    #[test]
    fn nominal_scales_change_nothing() {
        let v0 = presets::usm_paper();
        let mut v = v0.clone();
        v.apply_scales(&ModelScales::default(), &KEYS).unwrap();
        assert_eq!(v, v0);
    }

    #[test]
    fn scales_reach_every_body_and_thruster() {
        let v0 = presets::usm_paper();
        let mut v = v0.clone();
        let s = ModelScales {
            linear_damping: 2.0,
            roll_damping: 3.0,
            drag: 0.5,
            added_mass: 1.5,
            buoyancy_offset: 0.01,
            thrust_limit: 0.8,
            lift_slope: 2.0,
            lift_every_body: true,
            cb_offset_z: 0.01,
            cb_offset_x: -0.02,
            skin_friction: 1.5,
            form_drag: 0.5,
            appendage: 2.0,
        };
        v.apply_scales(&s, &KEYS).unwrap();
        for (b, b0) in v.bodies.iter().zip(&v0.bodies) {
            let (
                Hydro::Cylinder {
                    cd_x,
                    linear_damping,
                    lift_slope,
                    lift_every_body,
                    hull,
                    ..
                },
                Hydro::Cylinder {
                    cd_x: cd_x0,
                    linear_damping: ld0,
                    ..
                },
            ) = (&b.hydro, &b0.hydro)
            else {
                panic!("usm-paper bodies are cylinders");
            };
            assert_eq!(linear_damping[0], 2.0 * ld0[0]);
            assert_eq!(linear_damping[3], 6.0 * ld0[3]);
            assert_eq!(linear_damping[4], 2.0 * ld0[4]);
            assert_eq!(*cd_x, 0.5 * cd_x0);
            // The hull's factors: drag × their own.
            let h = hull.expect("usm-paper bodies carry hull drag");
            assert_eq!(
                (h.friction_scale, h.form_scale, h.appendage_scale),
                (0.75, 0.25, 1.0)
            );
            assert_eq!(*lift_slope, 2.0, "set, not scaled");
            assert!(*lift_every_body);
            let (ma, ma0) = (b.added_mass(1026.0), b0.added_mass(1026.0));
            assert!((ma - 1.5 * ma0).abs().max() <= 1e-12 * ma0.abs().max());
            assert_eq!(b.volume, b0.volume * 1.01);
            assert_eq!(b.cb, b0.cb + Vec3::new(-0.02, 0.0, 0.01));
            assert_eq!(b.cg, b0.cg);
        }
        for (t, t0) in v.thrusters.iter().zip(&v0.thrusters) {
            assert_eq!(t.u_max, 0.8 * t0.u_max);
            assert_eq!(t.u_min, 0.8 * t0.u_min);
        }
        assert!(v.validate().is_ok());
    }

    #[test]
    fn bad_factors_are_named() {
        let mut v = presets::usm_paper();
        let s = ModelScales {
            thrust_limit: 0.0,
            ..ModelScales::default()
        };
        assert_eq!(v.apply_scales(&s, &KEYS).unwrap_err().key, "tl");
        let s = ModelScales {
            drag: f64::NAN,
            ..ModelScales::default()
        };
        assert_eq!(v.apply_scales(&s, &KEYS).unwrap_err().key, "drag");
        let s = ModelScales {
            lift_slope: -1.0,
            ..ModelScales::default()
        };
        assert_eq!(v.apply_scales(&s, &KEYS).unwrap_err().key, "ls");
        // A centre of buoyancy moved out of the body (radius 0.085 m) is refused by its key.
        let s = ModelScales {
            cb_offset_z: 0.1,
            ..ModelScales::default()
        };
        let e = v.apply_scales(&s, &KEYS).unwrap_err();
        assert_eq!(e.key, "cbz");
        assert!(e.message.contains("out of the body"), "{}", e.message);
        let s = ModelScales {
            cb_offset_x: f64::INFINITY,
            ..ModelScales::default()
        };
        assert_eq!(v.apply_scales(&s, &KEYS).unwrap_err().key, "cbx");
    }
    #[test]
    fn a_payload_adds_its_mass_moment_and_volume_at_the_end_effector() {
        let v0 = presets::usm_paper();
        let mut v = v0.clone();
        v.add_payload(0.0, 0.0).unwrap();
        assert_eq!(v, v0);
        let (m, vol) = (2.0, 0.001);
        v.add_payload(m, vol).unwrap();
        let (b, b0) = (v.bodies.last().unwrap(), v0.bodies.last().unwrap());
        let at = v.end_effector.p;
        assert_eq!(b.mass, b0.mass + m);
        // First moment about the body origin: old + m·p_e.
        assert!((b.cg * b.mass - (b0.cg * b0.mass + at * m)).norm() < 1e-12);
        // Second moment about the body origin: old + point mass at p_e.
        let about_origin = |i: &Mat3, mass: f64, c: &Vec3| {
            i + (Mat3::identity() * c.norm_squared() - c * c.transpose()) * mass
        };
        let point = (Mat3::identity() * at.norm_squared() - at * at.transpose()) * m;
        let lhs = about_origin(&b.inertia, b.mass, &b.cg);
        let rhs = about_origin(&b0.inertia, b0.mass, &b0.cg) + point;
        assert!((lhs - rhs).abs().max() < 1e-12 * rhs.abs().max());
        assert!((b.volume - (b0.volume + vol)).abs() < 1e-15);
        assert!((b.cb * b.volume - (b0.cb * b0.volume + at * vol)).norm() < 1e-12);
        assert!(v.validate().is_ok());
        assert_eq!(
            v.add_payload(-1.0, 0.0).unwrap_err().key,
            "mission.payload_mass"
        );
    }
}

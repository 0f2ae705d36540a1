//! The transport autopilot (docs/model.md §5 "Autopilot"): depth hold with a bounded integral
//! and roll/pitch stabilisation towards level, added to USM-40/41 when
//! [`TransportGains::autopilot`](super::TransportGains::autopilot) is set.

use super::{TransportController, TransportMeasurement};
use crate::spatial::{Vec3, Vec6};

impl TransportController {
    /// The autopilot's depth reference `z_r` [m] (the base depth at its first step; `None`
    /// before it, or without the autopilot).
    pub fn depth_reference(&self) -> Option<f64> {
        self.depth_ref
    }

    /// The autopilot's depth integral `∫(z_b − z_r) dt` [m·s].
    pub fn depth_integral(&self) -> f64 {
        self.depth_integral
    }

    /// The autopilot's base acceleration (docs/model.md §5 "Autopilot"), added to USM-40/41's
    /// `a^b` when [`TransportGains::autopilot`](super::TransportGains::autopilot) is set; advances the depth integral over `dt`
    /// [s]. In `F_b` [m/s², rad/s²]:
    ///
    /// - **depth hold**: the inertial vertical acceleration
    ///   `a_z = −k_zp (z_b − z_r) − k_zi ∫(z_b − z_r) dt`, with `z_r` the base depth at the first
    ///   step (transport paths are horizontal, at the depth the vehicle starts) and the integral
    ///   clamped to `±depth_integral_limit` (anti-windup), expressed in the base frame,
    ///   `R_Ibᵀ (0, 0, a_z)`; USM-34's heave velocity feedback `−K_p,heave v_b,z` stays the
    ///   damping;
    /// - **attitude**: the tilt error `e = ∠(g, e_z) · (g × e_z)/|g × e_z|` (`g = R_Ibᵀ e_z`, the
    ///   inertial up seen from the base: the rotation, in `F_b`, from level to the base's
    ///   attitude; `(φ, θ, 0)` to first order, exact angle up to 180°), and
    ///   `a_4 = −k_φp e_x − k_φd p` (roll, only when `meas.roll_authority`),
    ///   `a_5 = −k_θp e_y − k_θd q` (pitch, always: transport commands pitch).
    ///
    /// Returns the acceleration and whether roll was commanded. Allocation-free.
    pub fn autopilot(&mut self, meas: &TransportMeasurement, dt: f64) -> (Vec6, bool) {
        let g = &self.gains;
        let z_r = *self.depth_ref.get_or_insert(meas.base_z);
        let e_z = meas.base_z - z_r;
        if dt.is_finite() && dt > 0.0 && e_z.is_finite() {
            let l = g.depth_integral_limit;
            self.depth_integral = (self.depth_integral + e_z * dt).clamp(-l, l);
        }
        let a_z = -g.k_depth_p * e_z - g.k_depth_i * self.depth_integral;
        let lin_b = meas.base_up * a_z;
        let axis = meas.base_up.cross(&Vec3::z());
        let s = axis.norm();
        let angle = s.atan2(meas.base_up.dot(&Vec3::z()));
        let tilt = if s > 0.0 {
            axis * (angle / s)
        } else {
            Vec3::zeros()
        };
        let roll = meas.roll_authority;
        let a_roll = if roll {
            -g.k_roll_p * tilt.x - g.k_roll_d * meas.base_rates.x
        } else {
            0.0
        };
        let a_pitch = -g.k_pitch_p * tilt.y - g.k_pitch_d * meas.base_rates.y;
        (
            Vec6::new(lin_b.x, lin_b.y, lin_b.z, a_roll, a_pitch, 0.0),
            roll,
        )
    }
}

//! The thruster model of the [`Simulator`](super::Simulator) (docs/model.md §4): a first-order lag
//! with time constant `T` and rate limit `r`, either of which may be absent, solved in closed
//! form (`u̇ = clamp((u_c − u)/T, −r, r)`), and the saturation to the thrust limits.

/// Lag and rate limit of one thruster, resolved from the model and the config.
#[derive(Clone, Copy, Debug)]
pub(super) struct ThrusterDyn {
    /// First-order lag time constant [s], if any.
    pub time_constant: Option<f64>,
    /// Rate limit [N/s], if any.
    pub rate_limit: Option<f64>,
    /// Lower thrust limit [N].
    pub u_min: f64,
    /// Upper thrust limit [N].
    pub u_max: f64,
}

impl ThrusterDyn {
    /// Exact solution after `s` seconds of `u̇ = clamp((u_c − u)/T, −r, r)` from `u0`
    /// towards the (saturated) command `u_c`.
    pub fn evolve(&self, u0: f64, u_c: f64, s: f64) -> f64 {
        let e0 = u_c - u0;
        match (self.time_constant, self.rate_limit) {
            (None, None) => u_c,
            (Some(t), None) => u_c - e0 * (-s / t).exp(),
            (None, Some(r)) => {
                if e0.abs() <= r * s {
                    u_c
                } else {
                    u0 + r * s * e0.signum()
                }
            }
            (Some(t), Some(r)) => {
                // Rate-limited while |e| > r T, then the exponential lag.
                let e_lin = r * t;
                if e0.abs() <= e_lin {
                    u_c - e0 * (-s / t).exp()
                } else {
                    let t1 = (e0.abs() - e_lin) / r;
                    if s <= t1 {
                        u0 + r * s * e0.signum()
                    } else {
                        u_c - e_lin * e0.signum() * (-(s - t1) / t).exp()
                    }
                }
            }
        }
    }

    /// `u` [N] clamped to `[u_min, u_max]`.
    pub fn saturate(&self, u: f64) -> f64 {
        u.clamp(self.u_min, self.u_max)
    }
}

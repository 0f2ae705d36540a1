//! The search space: each parameter's bounds and scale, and the map between its physical
//! value `x` and the normalised coordinate `u ∈ [0, 1]` the solvers work in
//! (lin: `x = lower + u·(upper − lower)`; log: `x = lower·(upper/lower)^u`). Points outside
//! the unit box (Nelder–Mead and L-BFGS are unbounded) are projected onto it before they are
//! evaluated; [`Space::project`] returns the squared distance so the solver's cost can add
//! a penalty that leads back inside.

use super::target::Target;

/// Linear or logarithmic parameter scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Scale {
    /// Uniform in `[lower, upper]`.
    Lin,
    /// Uniform in `[ln lower, ln upper]` (lower > 0).
    Log,
}

/// One optimised parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// The key path as written (`control.k_psi`, `design.thruster[2].position[0]`).
    pub name: String,
    /// The table and key it edits.
    pub target: Target,
    /// Lower bound (physical units of the key).
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// Scale of the normalised coordinate.
    pub scale: Scale,
    /// Start value (the file's value unless `start` is given).
    pub start: f64,
    /// Whether the key holds an integer (values are rounded).
    pub integer: bool,
}

impl Param {
    /// Physical value of the normalised coordinate `u` (clamped to [0, 1]; rounded for
    /// integer keys). The start's coordinate maps back to the start value exactly (the
    /// round trip through a log scale would lose the last bits).
    pub fn value(&self, u: f64) -> f64 {
        if u == self.coordinate(self.start) {
            return self.start;
        }
        let u = u.clamp(0.0, 1.0);
        let x = match self.scale {
            Scale::Lin => self.lower + u * (self.upper - self.lower),
            Scale::Log => self.lower * (self.upper / self.lower).powf(u),
        };
        let x = x.clamp(self.lower, self.upper);
        if self.integer {
            x.round()
        } else {
            x
        }
    }

    /// Normalised coordinate of the physical value `x`.
    pub fn coordinate(&self, x: f64) -> f64 {
        let u = match self.scale {
            Scale::Lin => (x - self.lower) / (self.upper - self.lower),
            Scale::Log => (x / self.lower).ln() / (self.upper / self.lower).ln(),
        };
        u.clamp(0.0, 1.0)
    }
}

/// The parameters of a problem.
#[derive(Clone, Debug, PartialEq)]
pub struct Space {
    /// The parameters, in file order.
    pub params: Vec<Param>,
}

impl Space {
    /// A space of `params`.
    pub fn new(params: Vec<Param>) -> Self {
        Space { params }
    }

    /// Number of parameters.
    pub fn dim(&self) -> usize {
        self.params.len()
    }

    /// The start point in normalised coordinates.
    pub fn start(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.coordinate(p.start)).collect()
    }

    /// `u` projected onto the unit box, and the squared distance it moved.
    pub fn project(&self, u: &[f64]) -> (Vec<f64>, f64) {
        let mut d2 = 0.0;
        let v = u
            .iter()
            .map(|&x| {
                let c = if x.is_nan() { 0.5 } else { x.clamp(0.0, 1.0) };
                d2 += (x - c).powi(2);
                c
            })
            .collect();
        (v, if d2.is_finite() { d2 } else { f64::MAX })
    }

    /// Physical values of normalised coordinates (inside the box).
    pub fn values(&self, u: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(u)
            .map(|(p, &x)| p.value(x))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::input::keypath::KeyPath;

    fn param(scale: Scale, lower: f64, upper: f64) -> Param {
        Param {
            name: "control.k".into(),
            target: Target::Scenario(KeyPath::parse("control.k").unwrap()),
            lower,
            upper,
            scale,
            start: lower,
            integer: false,
        }
    }

    #[test]
    fn coordinates_round_trip_on_both_scales() {
        for p in [param(Scale::Lin, -2.0, 3.0), param(Scale::Log, 0.01, 10.0)] {
            for u in [0.0, 0.25, 0.5, 1.0] {
                let x = p.value(u);
                assert!((p.coordinate(x) - u).abs() < 1e-12, "{p:?} {u}");
            }
            assert_eq!(p.value(-1.0), p.lower);
            assert_eq!(p.value(2.0), p.upper);
        }
        let p = param(Scale::Log, 0.01, 10.0);
        assert!((p.value(0.5) - 0.1_f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn projection_reports_the_distance() {
        let s = Space::new(vec![param(Scale::Lin, 0.0, 1.0); 2]);
        let (v, d2) = s.project(&[1.5, -0.5]);
        assert_eq!(v, vec![1.0, 0.0]);
        assert!((d2 - 0.5).abs() < 1e-15);
    }
}

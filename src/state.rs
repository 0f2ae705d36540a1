//! The vehicle state file (`STATE.json`) read by `usm-study inspect --state`.
//!
//! Keys (SI units): `base_position` [3] (m, inertial), `base_rotation` [3][3] (maps base-frame
//! vectors to the inertial frame), `joint_angles` [n] (rad), and optionally `base_twist` [6]
//! (`[v; ω]` in the base frame, m/s and rad/s), `joint_rates` [n] (rad/s),
//! `generalized_forces` [6+n] (base wrench in F_b then joint torques; N, N·m).

use crate::input::located::{InputError, KeyError, Located, Location};
use crate::kinematics::BasePose;
use crate::model::Vehicle;
use crate::spatial::{orthonormality_error, Mat3, Vec3, Vec6};
use nalgebra::{Rotation3, UnitQuaternion};
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawState {
    base_position: Option<[f64; 3]>,
    base_rotation: Option<[[f64; 3]; 3]>,
    joint_angles: Option<Vec<f64>>,
    base_twist: Option<[f64; 6]>,
    joint_rates: Option<Vec<f64>>,
    generalized_forces: Option<Vec<f64>>,
}

/// A full mechanical state of a design plus optional generalised forces.
#[derive(Clone, Debug, PartialEq)]
pub struct VehicleState {
    /// Base pose in the inertial frame.
    pub base: BasePose,
    /// Joint angles [rad].
    pub q: Vec<f64>,
    /// Base twist `[v; ω]` in F_b [m/s, rad/s].
    pub twist: Vec6,
    /// Joint rates [rad/s].
    pub qd: Vec<f64>,
    /// Generalised forces `[τ_b; τ_q]` (zero when absent).
    pub generalized_forces: Vec<f64>,
}

impl VehicleState {
    /// The straight configuration at rest at the origin.
    pub fn rest(v: &Vehicle) -> Self {
        let n = v.n_joints();
        Self {
            base: BasePose::default(),
            q: vec![0.0; n],
            twist: Vec6::zeros(),
            qd: vec![0.0; n],
            generalized_forces: vec![0.0; n + 6],
        }
    }
}

/// Read and check a state file against a design; errors name the file, the key and, for
/// JSON syntax and schema errors, the line and column.
pub fn load_state(path: &Path, v: &Vehicle) -> Result<VehicleState, InputError> {
    let file = path.display().to_string();
    let text = crate::input::document::read_text(path).map_err(|e| Located {
        at: Location::origin(&file),
        error: e.to_string(),
    })?;
    parse_state(&text, v, &file)
}

/// Parse a state from JSON text; `origin` names it in errors.
pub fn parse_state(text: &str, v: &Vehicle, origin: &str) -> Result<VehicleState, InputError> {
    let raw: RawState = serde_json::from_str(text).map_err(|e| Located {
        at: Location {
            line: Some(e.line()),
            column: Some(e.column()),
            ..Location::origin(origin)
        },
        error: e.to_string(),
    })?;
    check_state(raw, v).map_err(|e| Located {
        at: Location {
            key: e.key,
            ..Location::origin(origin)
        },
        error: e.message,
    })
}

/// Check the fields of a state file against the design `v`.
fn check_state(raw: RawState, v: &Vehicle) -> Result<VehicleState, KeyError> {
    let n = v.n_joints();
    let mut s = VehicleState::rest(v);
    let finite = |key: &str, xs: &[f64]| -> Result<(), KeyError> {
        match xs.iter().position(|x| !x.is_finite()) {
            Some(i) => Err(KeyError::new(key, format!("entry {i} is not finite"))),
            None => Ok(()),
        }
    };
    let sized = |key: &str, xs: &[f64], len: usize| -> Result<(), KeyError> {
        if xs.len() != len {
            return Err(KeyError::new(
                key,
                format!(
                    "has {} entries but the design '{}' needs {len}",
                    xs.len(),
                    v.name
                ),
            ));
        }
        finite(key, xs)
    };
    if let Some(p) = raw.base_position {
        finite("base_position", &p)?;
        s.base.position = Vec3::from(p);
    }
    if let Some(r) = raw.base_rotation {
        let flat: Vec<f64> = r.iter().flatten().copied().collect();
        finite("base_rotation", &flat)?;
        let m = Mat3::from_fn(|i, j| r[i][j]);
        let e = orthonormality_error(&m);
        if e > 1e-6 {
            return Err(KeyError::new(
                "base_rotation",
                format!("is not a rotation matrix (|RᵀR − I|, |det R − 1| up to {e:.3e})"),
            ));
        }
        s.base.orientation =
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
    }
    if let Some(q) = raw.joint_angles {
        sized("joint_angles", &q, n)?;
        s.q = q;
    }
    if let Some(t) = raw.base_twist {
        finite("base_twist", &t)?;
        s.twist = Vec6::from_row_slice(&t);
    }
    if let Some(qd) = raw.joint_rates {
        sized("joint_rates", &qd, n)?;
        s.qd = qd;
    }
    if let Some(f) = raw.generalized_forces {
        sized("generalized_forces", &f, n + 6)?;
        s.generalized_forces = f;
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::usm_paper;

    #[test]
    fn state_errors_name_the_key() {
        let v = usm_paper();
        let bad = [
            (r#"{"joint_angles": [0,0]}"#, "joint_angles"),
            (
                r#"{"base_rotation": [[1,0,0],[0,2,0],[0,0,1]]}"#,
                "base_rotation",
            ),
            (r#"{"joint_rates": [0,0,0,0,0,0,0,0,0]}"#, "joint_rates"),
            (r#"{"generalized_forces": [0]}"#, "generalized_forces"),
        ];
        for (text, key) in bad {
            let e = parse_state(text, &v, "s.json").unwrap_err();
            assert_eq!(e.at.key, key, "{text}: {e}");
        }
        // JSON syntax and schema errors carry the line instead of a key.
        for text in [r#"{"bogus": 1}"#, "{\n\"base_position\": [0,0]}"] {
            let e = parse_state(text, &v, "s.json").unwrap_err();
            let line = text.lines().count();
            assert_eq!(
                (e.at.key.as_str(), e.at.line),
                ("", Some(line)),
                "{text}: {e}"
            );
            assert!(e.to_string().starts_with(&format!("s.json:{line}:")), "{e}");
        }
        let ok = parse_state(
            r#"{"base_position":[1,2,3],"base_rotation":[[0,-1,0],[1,0,0],[0,0,1]],"joint_angles":[0,0.1,0,0,0,0,0,0]}"#,
            &v,
            "s.json",
        )
        .unwrap();
        assert!((ok.base.orientation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}

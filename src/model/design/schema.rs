//! The serde schema of a design file: one struct per table, `deny_unknown_fields`
//! everywhere, every optional key an `Option` so that [`super::build`] applies the
//! documented defaults (and can tell a key given from a key left out).

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DesignFile {
    pub(super) name: Option<String>,
    pub(super) preset: Option<String>,
    /// The pointer form: a URDF path relative to the design file, with two import options.
    pub(super) urdf: Option<String>,
    pub(super) thrust_limit: Option<f64>,
    pub(super) fixed_joints: Option<Vec<String>>,
    pub(super) fluid: Option<FluidSpec>,
    pub(super) body: Option<Vec<BodySpec>>,
    pub(super) joint: Option<Vec<JointSpec>>,
    pub(super) thruster: Option<Vec<ThrusterSpec>>,
    pub(super) base: Option<FrameSpec>,
    pub(super) end_effector: Option<FrameSpec>,
    pub(super) generator: Option<GeneratorFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FluidSpec {
    pub(super) rho: Option<f64>,
    pub(super) g: Option<f64>,
    pub(super) current: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BodySpec {
    pub(super) name: String,
    pub(super) mass: f64,
    pub(super) length: f64,
    pub(super) radius: f64,
    pub(super) cg: Option<[f64; 3]>,
    pub(super) cb: Option<[f64; 3]>,
    pub(super) volume: Option<f64>,
    pub(super) neutral: Option<bool>,
    pub(super) inertia: Option<[[f64; 3]; 3]>,
    pub(super) hydro: Option<HydroSpec>,
}

/// Both hydro kinds in one struct so that each misplaced key gets its own error.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct HydroSpec {
    pub(super) kind: Option<String>,
    pub(super) cd_x: Option<f64>,
    pub(super) cd_y: Option<f64>,
    pub(super) cd_z: Option<f64>,
    pub(super) linear_damping: Option<[f64; 6]>,
    pub(super) strips: Option<usize>,
    pub(super) axial_added_mass_ratio: Option<f64>,
    pub(super) added_mass_scale: Option<f64>,
    pub(super) hull: Option<bool>,
    pub(super) friction_scale: Option<f64>,
    pub(super) nose_cd: Option<f64>,
    pub(super) base_cd: Option<f64>,
    pub(super) pod_drag_area: Option<f64>,
    pub(super) tunnel_drag_area: Option<f64>,
    pub(super) gap_drag_area: Option<f64>,
    pub(super) appendage_scale: Option<f64>,
    pub(super) form_scale: Option<f64>,
    pub(super) viscosity: Option<f64>,
    pub(super) added_mass: Option<[[f64; 6]; 6]>,
    pub(super) linear: Option<[[f64; 6]; 6]>,
    pub(super) quadratic: Option<[[f64; 6]; 6]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct JointSpec {
    pub(super) name: Option<String>,
    pub(super) axis: [f64; 3],
    pub(super) position: Option<[f64; 3]>,
    pub(super) rpy_deg: Option<[f64; 3]>,
    pub(super) limits_deg: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ThrusterSpec {
    pub(super) name: Option<String>,
    pub(super) body: BodyRef,
    pub(super) position: [f64; 3],
    pub(super) direction: [f64; 3],
    pub(super) u_min: Option<f64>,
    pub(super) u_max: Option<f64>,
    pub(super) time_constant: Option<f64>,
    pub(super) rate_limit: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FrameSpec {
    pub(super) position: Option<[f64; 3]>,
    pub(super) rpy_deg: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct GeneratorFile {
    pub(super) links: Option<usize>,
    pub(super) link_length: Option<OneOrMany>,
    pub(super) link_mass: Option<OneOrMany>,
    pub(super) body_profile: Option<String>,
    pub(super) radius: Option<f64>,
    pub(super) module_length: Option<f64>,
    pub(super) module_mass: Option<f64>,
    pub(super) joint_limit_deg: Option<f64>,
    pub(super) thruster_rule: Option<String>,
    pub(super) thrust_limit: Option<f64>,
    pub(super) thrust_per_kg: Option<f64>,
    pub(super) longitudinal_offset: Option<f64>,
    pub(super) cd_axial_ends: Option<f64>,
    pub(super) cd_axial: Option<f64>,
    pub(super) cd_cross: Option<f64>,
    pub(super) metacentric_height: Option<f64>,
    pub(super) wet_weight: Option<f64>,
}

/// A thruster's body: by name or by 0-based index.
pub(super) enum BodyRef {
    Index(i64),
    Name(String),
}

impl<'de> Deserialize<'de> for BodyRef {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = BodyRef;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a body name (string) or a 0-based body index (integer)")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<BodyRef, E> {
                Ok(BodyRef::Index(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<BodyRef, E> {
                Ok(BodyRef::Index(i64::try_from(v).unwrap_or(i64::MAX)))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<BodyRef, E> {
                Ok(BodyRef::Name(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

/// One number for every link, or one per link.
pub(super) struct OneOrMany(pub(super) Vec<f64>);

impl<'de> Deserialize<'de> for OneOrMany {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = OneOrMany;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a number or an array of numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<OneOrMany, E> {
                Ok(OneOrMany(vec![v]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<OneOrMany, E> {
                Ok(OneOrMany(vec![v as f64]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<OneOrMany, E> {
                Ok(OneOrMany(vec![v as f64]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<OneOrMany, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(OneOrMany(v))
            }
        }
        d.deserialize_any(V)
    }
}

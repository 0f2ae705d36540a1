//! The explicit form of a design (`usm-study design show`), written so that it parses back
//! to the same vehicle bit for bit.

use crate::model::{Hydro, Thruster, Vehicle};
use crate::spatial::{Mat3, Vec3};
use std::fmt::Write as _;

/// `[roll, pitch, yaw]` [rad] of a rotation matrix, inverse of `build::rot_rpy`; at the
/// gimbal lock (pitch = ±90°) roll is set to zero.
pub(super) fn rpy_of(r: &Mat3) -> Vec3 {
    let s = (-r[(2, 0)]).clamp(-1.0, 1.0);
    let pitch = s.asin();
    if s.abs() < 1.0 - 1e-12 {
        Vec3::new(
            r[(2, 1)].atan2(r[(2, 2)]),
            pitch,
            r[(1, 0)].atan2(r[(0, 0)]),
        )
    } else {
        Vec3::new(0.0, pitch, (-r[(0, 1)]).atan2(r[(1, 1)]))
    }
}

/// A float written so that it parses back to the same bits (shortest round-trip form,
/// always with a `.` or an exponent so that TOML reads it as a float).
pub(super) fn fnum(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:?}")
    }
}

pub(super) fn farr(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| fnum(*x)).collect();
    format!("[{}]", items.join(", "))
}

fn fmat<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f64, R, C>, indent: &str) -> String {
    let rows: Vec<String> = (0..R)
        .map(|r| {
            let row: Vec<f64> = (0..C).map(|c| m[(r, c)]).collect();
            format!("{indent}  {},", farr(&row))
        })
        .collect();
    format!("[\n{}\n{indent}]", rows.join("\n"))
}

fn tstr(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// Degrees of `x` [rad] chosen so that converting back with `to_radians` gives `x` exactly
/// when a neighbouring float allows it.
pub(super) fn deg(x: f64) -> f64 {
    let d = x.to_degrees();
    if !d.is_finite() || d.to_radians() == x {
        return d;
    }
    for k in 1..=4u64 {
        for cand in [
            f64::from_bits(d.to_bits().wrapping_add(k)),
            f64::from_bits(d.to_bits().wrapping_sub(k)),
        ] {
            if cand.is_finite() && cand.to_radians() == x {
                return cand;
            }
        }
    }
    d
}

fn write_rpy(out: &mut String, r: &Mat3) {
    if *r != Mat3::identity() {
        let rpy = rpy_of(r).map(deg);
        let _ = writeln!(out, "rpy_deg = {}", farr(rpy.as_slice()));
    }
}

/// The explicit form of a design (what `usm-study design show` prints): every body, joint
/// and thruster with all values written out, plus `[fluid]`, `[base]` and
/// `[end_effector]`. Floats are written in their shortest round-trip form, so
/// `parse_design(&design_to_toml(&v), ..)` gives back `v` (angles in `_deg` keys within
/// about 1e-15 relative, exact for the presets' joint limits).
pub fn design_to_toml(v: &Vehicle) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# usm-study design file, explicit form, of the design {}.\n\
         # Written by `usm-study design show`; save it, edit it and pass the file wherever a\n\
         # design or preset name is accepted (e.g. `usm-study inspect my_design.toml`,\n\
         # `design = \"my_design.toml\"` in a scenario, `[design] file = \"my_design.toml\"` in a study).\n\
         # Units: SI (m, kg, s, N); angles in degrees only in keys ending in `_deg`.\n\
         # Frames: each body frame has its origin at the body's tail face, x towards the head;\n\
         # joint k joins body k (parent) to body k+1; positions are in the owning body's frame.",
        tstr(&v.name)
    );
    let _ = writeln!(o, "name = {}\n", tstr(&v.name));
    let _ = writeln!(o, "[fluid]");
    let _ = writeln!(o, "rho = {}  # density [kg/m³]", fnum(v.fluid.rho));
    let _ = writeln!(o, "g = {}  # gravity [m/s²]", fnum(v.fluid.g));
    let _ = writeln!(
        o,
        "current = {}  # inertial frame [m/s]\n",
        farr(v.fluid.current.as_slice())
    );
    let _ = writeln!(o, "# Base frame on body 0 (tail face by default).\n[base]");
    let _ = writeln!(o, "position = {}", farr(v.base.p.as_slice()));
    write_rpy(&mut o, &v.base.r);
    let _ = writeln!(
        o,
        "\n# End-effector frame on the last body (front face by default).\n[end_effector]"
    );
    let _ = writeln!(o, "position = {}", farr(v.end_effector.p.as_slice()));
    write_rpy(&mut o, &v.end_effector.r);
    for (i, b) in v.bodies.iter().enumerate() {
        let _ = writeln!(o, "\n# body {i}\n[[body]]");
        let _ = writeln!(o, "name = {}", tstr(&b.name));
        let _ = writeln!(o, "mass = {}  # [kg]", fnum(b.mass));
        let _ = writeln!(o, "length = {}  # [m]", fnum(b.length));
        let _ = writeln!(o, "radius = {}  # [m]", fnum(b.radius));
        let _ = writeln!(o, "cg = {}", farr(b.cg.as_slice()));
        let _ = writeln!(o, "cb = {}", farr(b.cb.as_slice()));
        let _ = writeln!(o, "volume = {}  # displaced [m³]", fnum(b.volume));
        hydrostatics_comment(&mut o, v, b);
        let _ = writeln!(
            o,
            "inertia = {}  # about the CG [kg·m²]",
            fmat(&b.inertia, "")
        );
        let _ = writeln!(o, "[body.hydro]");
        write_hydro(&mut o, &b.hydro);
    }
    for (k, j) in v.joints.iter().enumerate() {
        let _ = writeln!(o, "\n# joint {k}: body {k} -> body {}\n[[joint]]", k + 1);
        let _ = writeln!(o, "name = {}", tstr(&j.name));
        let _ = writeln!(o, "axis = {}", farr(j.axis.as_slice()));
        let _ = writeln!(o, "position = {}", farr(j.placement.p.as_slice()));
        write_rpy(&mut o, &j.placement.r);
        let _ = writeln!(o, "limits_deg = {}", farr(&[deg(j.min), deg(j.max)]));
    }
    let unique_names = unique_body_names(v);
    for t in &v.thrusters {
        let _ = writeln!(o, "\n[[thruster]]");
        let _ = writeln!(o, "name = {}", tstr(&t.name));
        let _ = writeln!(o, "body = {}", body_ref(v, t, unique_names));
        let _ = writeln!(o, "position = {}", farr(t.position.as_slice()));
        let _ = writeln!(o, "direction = {}", farr(t.direction.as_slice()));
        let _ = writeln!(o, "u_min = {}", fnum(t.u_min));
        let _ = writeln!(o, "u_max = {}", fnum(t.u_max));
        if let Some(tc) = t.time_constant {
            let _ = writeln!(o, "time_constant = {}", fnum(tc));
        }
        if let Some(r) = t.rate_limit {
            let _ = writeln!(o, "rate_limit = {}", fnum(r));
        }
    }
    o
}

/// The `[body.hydro]` keys of one body's [`Hydro`] (the table header written by the caller).
fn write_hydro(o: &mut String, hydro: &Hydro) {
    match hydro {
        Hydro::Cylinder {
            cd_x,
            cd_y,
            cd_z,
            linear_damping,
            strips,
            axial_added_mass_ratio,
            added_mass_scale,
            // A world property (scenario key `hydro.lift_slope`), not a design one.
            lift_slope: _,
            lift_every_body: _,
            hull,
        } => {
            let _ = writeln!(o, "kind = \"cylinder\"");
            let _ = writeln!(o, "cd_x = {}", fnum(*cd_x));
            let _ = writeln!(o, "cd_y = {}", fnum(*cd_y));
            let _ = writeln!(o, "cd_z = {}", fnum(*cd_z));
            let _ = writeln!(o, "linear_damping = {}", farr(linear_damping));
            let _ = writeln!(o, "strips = {strips}");
            let _ = writeln!(
                o,
                "axial_added_mass_ratio = {}",
                fnum(*axial_added_mass_ratio)
            );
            if *added_mass_scale != 1.0 {
                let _ = writeln!(o, "added_mass_scale = {}", fnum(*added_mass_scale));
            }
            match hull {
                Some(h) => {
                    let _ = writeln!(o, "hull = true  # hull drag, docs/model.md §2");
                    for (k, v) in h.fields() {
                        let _ = writeln!(o, "{k} = {}", fnum(v));
                    }
                }
                None => {
                    let _ = writeln!(o, "hull = false");
                }
            }
        }
        Hydro::Coefficients {
            added_mass,
            linear,
            quadratic,
        } => {
            let _ = writeln!(o, "kind = \"coefficients\"");
            let _ = writeln!(o, "added_mass = {}", fmat(added_mass, ""));
            let _ = writeln!(o, "linear = {}", fmat(linear, ""));
            let _ = writeln!(o, "quadratic = {}", fmat(quadratic, ""));
        }
        Hydro::Manoeuvring(_) => {
            // Built-in derivative tables (paper::nps_auv2) have no design-file form:
            // reading this back fails with "unknown hydro kind".
            let _ = writeln!(o, "kind = \"manoeuvring\"  # built in, not readable");
        }
    }
}

/// The comment line of body `b`'s hydrostatics (docs/model.md §4 "Restoring forces"): `CB −
/// CG`, the metacentric height and the wet weight in `v`'s fluid; the file's keys `cg`, `cb`
/// and `volume` carry the values.
fn hydrostatics_comment(o: &mut String, v: &Vehicle, b: &crate::model::Body) {
    let d = b.cb - b.cg;
    let _ = writeln!(
        o,
        "# hydrostatics: CB − CG = [{:.6}, {:.6}, {:.6}] m (metacentric height {:.6} m), \
         wet weight {:.6} N (positive sinks)",
        d.x,
        d.y,
        d.z,
        d.z,
        (b.mass - v.fluid.rho * b.volume) * v.fluid.g
    );
}

/// Whether every body of `v` has its own name (thrusters then name their body).
fn unique_body_names(v: &Vehicle) -> bool {
    v.bodies
        .iter()
        .enumerate()
        .all(|(i, b)| v.bodies[..i].iter().all(|o| o.name != b.name))
}

/// The `body` of thruster `t`: its body's name when `unique_names`, else its index.
fn body_ref(v: &Vehicle, t: &Thruster, unique_names: bool) -> toml::Value {
    match v.bodies.get(t.body) {
        Some(b) if unique_names => toml::Value::String(b.name.clone()),
        _ => toml::Value::Integer(t.body as i64),
    }
}

/// The `[[thruster]]` array of [`design_to_toml`]`(v)` as a TOML value, equal to what parsing
/// that text gives (same keys, the same floats bit for bit), without writing and parsing the
/// whole design: a sweep that edits one generated thruster per case writes the generated ones
/// out with it.
pub fn thrusters_to_toml(v: &Vehicle) -> toml::Value {
    use toml::Value;
    let unique_names = unique_body_names(v);
    let floats = |x: &[f64]| Value::Array(x.iter().map(|&c| Value::Float(c)).collect());
    let tables = v
        .thrusters
        .iter()
        .map(|t| {
            let mut m = toml::Table::new();
            m.insert("name".into(), Value::String(t.name.clone()));
            m.insert("body".into(), body_ref(v, t, unique_names));
            m.insert("position".into(), floats(t.position.as_slice()));
            m.insert("direction".into(), floats(t.direction.as_slice()));
            m.insert("u_min".into(), Value::Float(t.u_min));
            m.insert("u_max".into(), Value::Float(t.u_max));
            if let Some(tc) = t.time_constant {
                m.insert("time_constant".into(), Value::Float(tc));
            }
            if let Some(r) = t.rate_limit {
                m.insert("rate_limit".into(), Value::Float(r));
            }
            Value::Table(m)
        })
        .collect();
    Value::Array(tables)
}

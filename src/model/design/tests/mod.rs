//! Tests of design files: round trips of the explicit form, the three forms, located
//! errors and property tests (generated designs, mutated files). Helpers live here.

mod errors;
mod forms;
mod props;

use super::build::{rot_rpy, vec3};
use super::write::{deg, farr, fnum, rpy_of};
use super::*;
use crate::model::generator::{GeneratorSpec, ThrusterRule};
use crate::model::presets::usm_paper;
use crate::model::{Hydro, Thruster};
use crate::spatial::{Se3, Vec3};
use std::ops::Range;

/// Compare two vehicles field by field with an absolute tolerance (relative for big
/// values); `Err` names the first difference.
fn close(a: &Vehicle, b: &Vehicle, tol: f64) -> Result<(), String> {
    if a.name != b.name {
        return Err(format!("name: {} vs {}", a.name, b.name));
    }
    if (a.bodies.len(), a.joints.len(), a.thrusters.len())
        != (b.bodies.len(), b.joints.len(), b.thrusters.len())
    {
        return Err("counts differ".into());
    }
    num("fluid.rho", a.fluid.rho, b.fluid.rho, tol)?;
    num("fluid.g", a.fluid.g, b.fluid.g, tol)?;
    nums(
        "fluid.current",
        a.fluid.current.as_slice(),
        b.fluid.current.as_slice(),
        tol,
    )?;
    se3("base", &a.base, &b.base, tol)?;
    se3("end_effector", &a.end_effector, &b.end_effector, tol)?;
    for (i, (x, y)) in a.bodies.iter().zip(&b.bodies).enumerate() {
        let k = |f: &str| format!("body[{i}].{f}");
        if x.name != y.name {
            return Err(k("name"));
        }
        num(&k("mass"), x.mass, y.mass, tol)?;
        num(&k("length"), x.length, y.length, tol)?;
        num(&k("radius"), x.radius, y.radius, tol)?;
        num(&k("volume"), x.volume, y.volume, tol)?;
        nums(&k("cg"), x.cg.as_slice(), y.cg.as_slice(), tol)?;
        nums(&k("cb"), x.cb.as_slice(), y.cb.as_slice(), tol)?;
        nums(
            &k("inertia"),
            x.inertia.as_slice(),
            y.inertia.as_slice(),
            tol,
        )?;
        close_hydro(&k("hydro"), &x.hydro, &y.hydro, tol)?;
    }
    for (i, (x, y)) in a.joints.iter().zip(&b.joints).enumerate() {
        let k = |f: &str| format!("joint[{i}].{f}");
        if x.name != y.name {
            return Err(k("name"));
        }
        se3(&k("placement"), &x.placement, &y.placement, tol)?;
        nums(&k("axis"), x.axis.as_slice(), y.axis.as_slice(), tol)?;
        nums(&k("limits"), &[x.min, x.max], &[y.min, y.max], tol)?;
    }
    for (i, (x, y)) in a.thrusters.iter().zip(&b.thrusters).enumerate() {
        close_thruster(&format!("thruster[{i}]"), x, y, tol)?;
    }
    Ok(())
}

fn round_trip(v: &Vehicle) -> Result<Vehicle, String> {
    let text = design_to_toml(v);
    parse_design(&text, "rt.toml").map_err(|e| format!("{e}\n{text}"))
}

fn num(key: &str, x: f64, y: f64, tol: f64) -> Result<(), String> {
    if (x - y).abs() <= tol * (1.0 + x.abs().max(y.abs())) {
        Ok(())
    } else {
        Err(format!("{key}: {x} vs {y}"))
    }
}

fn nums(key: &str, x: &[f64], y: &[f64], tol: f64) -> Result<(), String> {
    if x.len() != y.len() {
        return Err(format!("{key}: lengths {} vs {}", x.len(), y.len()));
    }
    for (i, (p, q)) in x.iter().zip(y).enumerate() {
        num(&format!("{key}[{i}]"), *p, *q, tol)?;
    }
    Ok(())
}

fn se3(key: &str, x: &Se3, y: &Se3, tol: f64) -> Result<(), String> {
    nums(&format!("{key}.p"), x.p.as_slice(), y.p.as_slice(), tol)?;
    nums(&format!("{key}.r"), x.r.as_slice(), y.r.as_slice(), tol)
}

/// [`close`] for the hydrodynamic models of one body (`key` = `body[i].hydro`).
fn close_hydro(key: &str, x: &Hydro, y: &Hydro, tol: f64) -> Result<(), String> {
    let k = |f: &str| format!("{key}.{f}");
    match (x, y) {
        (
            Hydro::Cylinder {
                cd_x,
                cd_y,
                cd_z,
                linear_damping,
                strips,
                axial_added_mass_ratio,
                added_mass_scale,
                lift_slope,
                lift_every_body,
                hull,
            },
            Hydro::Cylinder {
                cd_x: cx,
                cd_y: cy,
                cd_z: cz,
                linear_damping: ld,
                strips: s,
                axial_added_mass_ratio: ar,
                added_mass_scale: ams,
                lift_slope: ls,
                lift_every_body: le,
                hull: hl,
            },
        ) => {
            match (hull, hl) {
                (Some(a), Some(b)) => {
                    let (fa, fb) = (a.fields(), b.fields());
                    for ((name, x), (_, y)) in fa.iter().zip(&fb) {
                        num(&k(name), *x, *y, tol)?;
                    }
                }
                (None, None) => {}
                _ => return Err(k("hull")),
            }
            nums(&k("cd"), &[*cd_x, *cd_y, *cd_z], &[*cx, *cy, *cz], tol)?;
            nums(&k("linear_damping"), linear_damping, ld, tol)?;
            num(&k("axial"), *axial_added_mass_ratio, *ar, tol)?;
            num(&k("added_mass_scale"), *added_mass_scale, *ams, tol)?;
            num(&k("lift_slope"), *lift_slope, *ls, tol)?;
            if strips != s || lift_every_body != le {
                return Err(k("strips"));
            }
        }
        (
            Hydro::Coefficients {
                added_mass,
                linear,
                quadratic,
            },
            Hydro::Coefficients {
                added_mass: am,
                linear: l,
                quadratic: q,
            },
        ) => {
            nums(&k("added_mass"), added_mass.as_slice(), am.as_slice(), tol)?;
            nums(&k("linear"), linear.as_slice(), l.as_slice(), tol)?;
            nums(&k("quadratic"), quadratic.as_slice(), q.as_slice(), tol)?;
        }
        _ => return Err(k("kind")),
    }
    Ok(())
}

/// [`close`] for one thruster (`key` = `thruster[i]`).
fn close_thruster(key: &str, x: &Thruster, y: &Thruster, tol: f64) -> Result<(), String> {
    let k = |f: &str| format!("{key}.{f}");
    if x.name != y.name || x.body != y.body {
        return Err(k("name/body"));
    }
    nums(
        &k("position"),
        x.position.as_slice(),
        y.position.as_slice(),
        tol,
    )?;
    nums(
        &k("direction"),
        x.direction.as_slice(),
        y.direction.as_slice(),
        tol,
    )?;
    nums(&k("limits"), &[x.u_min, x.u_max], &[y.u_min, y.u_max], tol)?;
    if x.time_constant.is_some() != y.time_constant.is_some()
        || x.rate_limit.is_some() != y.rate_limit.is_some()
    {
        return Err(k("options"));
    }
    num(
        &k("tc"),
        x.time_constant.unwrap_or(0.0),
        y.time_constant.unwrap_or(0.0),
        tol,
    )?;
    num(
        &k("rate"),
        x.rate_limit.unwrap_or(0.0),
        y.rate_limit.unwrap_or(0.0),
        tol,
    )?;
    Ok(())
}

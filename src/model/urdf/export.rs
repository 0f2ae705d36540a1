//! A [`Vehicle`] → URDF with UUV Simulator plugin blocks (docs/urdf.md "Export"): one link per
//! body, revolute joints with limits, one continuous propeller joint and link per thruster
//! with a `uuv_thruster_ros_plugin` block, one `uuv_underwater_object_ros_plugin` block with
//! every body's volume, centre of buoyancy and Fossen matrices (UUV's frame, docs/urdf.md),
//! and a `usm_study` block with what URDF cannot say (body length and radius, the cylinder
//! model's coefficients, base and end-effector frames, gravity and current). Floats are
//! written in Rust's shortest round-trip form, so [`super::import_urdf`] gives the design back
//! (rotations through roll-pitch-yaw, to about 1e-15).

use crate::model::{Body, Hydro, Vehicle};
use crate::spatial::{Mat3, Mat6, Se3, Vec3};
use std::fmt::Write as _;
use thiserror::Error;

/// A design URDF cannot carry.
#[derive(Debug, Error, Clone, PartialEq)]
#[error("cannot export {what}: {why}")]
pub struct ExportError {
    /// The item (e.g. `body[3] (hull)`).
    pub what: String,
    /// Why.
    pub why: String,
}

pub(super) fn num(x: f64) -> String {
    format!("{x:?}")
}

pub(super) fn nums(x: &[f64]) -> String {
    x.iter().map(|v| num(*v)).collect::<Vec<_>>().join(" ")
}

/// Roll-pitch-yaw of `r = Rz(y) Ry(p) Rx(r)` (URDF's convention), well conditioned near
/// pitch ±90° (pitch from `atan2`, not `asin`).
pub(super) fn rpy_of(r: &Mat3) -> Vec3 {
    let pitch = (-r[(2, 0)]).atan2((r[(0, 0)] * r[(0, 0)] + r[(1, 0)] * r[(1, 0)]).sqrt());
    if pitch.cos() > 1e-12 {
        Vec3::new(
            r[(2, 1)].atan2(r[(2, 2)]),
            pitch,
            r[(1, 0)].atan2(r[(0, 0)]),
        )
    } else {
        // Gimbal lock: yaw 0, roll from the second column.
        let s = pitch.sin().signum();
        Vec3::new((s * r[(0, 1)]).atan2(r[(1, 1)]), pitch, 0.0)
    }
}

pub(super) fn origin_xml(g: &Se3) -> String {
    format!(
        "<origin xyz=\"{}\" rpy=\"{}\"/>",
        nums(g.p.as_slice()),
        nums(rpy_of(&g.r).as_slice())
    )
}

/// Unique link names: the body names when they are unique, else `NAME_i`.
pub(super) fn link_names(v: &Vehicle) -> Vec<String> {
    let unique = v
        .bodies
        .iter()
        .enumerate()
        .all(|(i, b)| v.bodies[..i].iter().all(|o| o.name != b.name));
    v.bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            if unique {
                b.name.clone()
            } else {
                format!("{}_{i}", b.name)
            }
        })
        .collect()
}

/// `S M S` with `S = diag(1, −1, −1, 1, −1, −1)` (UUV's hydrodynamic frame, docs/urdf.md).
fn ned(m: &Mat6, sign: f64) -> Vec<f64> {
    let s = [1.0, -1.0, -1.0, 1.0, -1.0, -1.0];
    let mut out = Vec::with_capacity(36);
    for i in 0..6 {
        for j in 0..6 {
            out.push(sign * s[i] * s[j] * m[(i, j)]);
        }
    }
    out
}

/// The Fossen matrices of a body about its frame origin: exact for `Coefficients`; for the
/// cylinder model the added mass is exact and the damping an equivalent (docs/urdf.md).
fn fossen(b: &Body, rho: f64) -> Result<(Mat6, Mat6, Mat6), String> {
    match &b.hydro {
        Hydro::Coefficients {
            added_mass,
            linear,
            quadratic,
        } => Ok((*added_mass, *linear, *quadratic)),
        Hydro::Cylinder {
            cd_x,
            cd_y,
            cd_z,
            linear_damping,
            ..
        } => {
            let (r, l) = (b.radius, b.length);
            let centre = Se3::from_translation(b.centre());
            let lin = centre.inertia_to_parent(&Mat6::from_diagonal(
                &nalgebra::Vector6::from_column_slice(linear_damping),
            ));
            let half = 0.5 * rho;
            let area = std::f64::consts::PI * r * r;
            let rot = 2.0 * r * l.powi(4) / 32.0;
            let q = nalgebra::Vector6::new(
                half * cd_x * area,
                half * cd_y * 2.0 * r * l,
                half * cd_z * 2.0 * r * l,
                0.0,
                half * cd_z * rot,
                half * cd_y * rot,
            );
            Ok((b.added_mass(rho), lin, Mat6::from_diagonal(&q)))
        }
        Hydro::Manoeuvring(_) => {
            Err("built-in manoeuvring derivative tables have no URDF form".into())
        }
    }
}

fn link_xml(o: &mut String, name: &str, b: &Body) {
    let i = &b.inertia;
    let _ = writeln!(o, "  <link name=\"{name}\">");
    let _ = writeln!(o, "    <inertial>");
    let _ = writeln!(
        o,
        "      <origin xyz=\"{}\" rpy=\"0 0 0\"/>",
        nums(b.cg.as_slice())
    );
    let _ = writeln!(o, "      <mass value=\"{}\"/>", num(b.mass));
    let _ = writeln!(
        o,
        "      <inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>",
        num(i[(0, 0)]),
        num(i[(0, 1)]),
        num(i[(0, 2)]),
        num(i[(1, 1)]),
        num(i[(1, 2)]),
        num(i[(2, 2)])
    );
    let _ = writeln!(o, "    </inertial>");
    let _ = writeln!(
        o,
        "    <collision>\n      <origin xyz=\"{} 0 0\" rpy=\"0 1.5707963267948966 0\"/>\n      \
         <geometry><cylinder radius=\"{}\" length=\"{}\"/></geometry>\n    </collision>",
        num(b.length / 2.0),
        num(b.radius),
        num(b.length)
    );
    let _ = writeln!(o, "  </link>");
}

fn uuv_block(o: &mut String, v: &Vehicle, names: &[String]) -> Result<(), ExportError> {
    let _ = writeln!(
        o,
        "  <gazebo>\n    <plugin name=\"uuv_plugin\" filename=\"libuuv_underwater_object_ros_plugin.so\">"
    );
    let _ = writeln!(
        o,
        "      <fluid_density>{}</fluid_density>",
        num(v.fluid.rho)
    );
    let _ = writeln!(
        o,
        "      <flow_velocity_topic>hydrodynamics/current_velocity</flow_velocity_topic>"
    );
    for (i, b) in v.bodies.iter().enumerate() {
        let (ma, dl, dq) = fossen(b, v.fluid.rho).map_err(|why| ExportError {
            what: format!("body[{i}] ({})", b.name),
            why,
        })?;
        let _ = writeln!(o, "      <link name=\"{}\">", names[i]);
        let _ = writeln!(o, "        <neutrally_buoyant>0</neutrally_buoyant>");
        let _ = writeln!(o, "        <volume>{}</volume>", num(b.volume));
        let _ = writeln!(
            o,
            "        <center_of_buoyancy>{}</center_of_buoyancy>",
            nums(b.cb.as_slice())
        );
        let _ = writeln!(
            o,
            "        <hydrodynamic_model>\n          <type>fossen</type>"
        );
        let _ = writeln!(
            o,
            "          <added_mass>{}</added_mass>",
            nums(&ned(&ma, 1.0))
        );
        let _ = writeln!(
            o,
            "          <linear_damping>{}</linear_damping>",
            nums(&ned(&dl, -1.0))
        );
        let _ = writeln!(
            o,
            "          <quadratic_damping>{}</quadratic_damping>",
            nums(&ned(&dq, -1.0))
        );
        let _ = writeln!(o, "        </hydrodynamic_model>\n      </link>");
    }
    let _ = writeln!(o, "    </plugin>\n  </gazebo>");
    Ok(())
}

fn frame_attrs(g: &Se3) -> String {
    let r: Vec<f64> = (0..3)
        .flat_map(|i| (0..3).map(move |j| g.r[(i, j)]))
        .collect();
    format!(
        "position=\"{}\" rotation=\"{}\"",
        nums(g.p.as_slice()),
        nums(&r)
    )
}

fn usm_block(o: &mut String, v: &Vehicle, names: &[String]) {
    let _ = writeln!(
        o,
        "  <gazebo>\n    <plugin name=\"usm_study\" filename=\"usm_study\">"
    );
    let _ = writeln!(o, "      <base {}/>", frame_attrs(&v.base));
    let _ = writeln!(o, "      <end_effector {}/>", frame_attrs(&v.end_effector));
    let _ = writeln!(
        o,
        "      <fluid g=\"{}\" current=\"{}\"/>",
        num(v.fluid.g),
        nums(v.fluid.current.as_slice())
    );
    for (i, b) in v.bodies.iter().enumerate() {
        let head = format!(
            "      <body link=\"{}\" length=\"{}\" radius=\"{}\"",
            names[i],
            num(b.length),
            num(b.radius)
        );
        match &b.hydro {
            Hydro::Cylinder {
                cd_x,
                cd_y,
                cd_z,
                linear_damping,
                strips,
                axial_added_mass_ratio,
                added_mass_scale,
                hull,
                ..
            } => {
                let hull = hull.map_or(String::new(), |h| {
                    let f: Vec<f64> = h.fields().iter().map(|x| x.1).collect();
                    format!(" hull=\"{}\"", nums(&f))
                });
                let _ = writeln!(
                    o,
                    "{head}>\n        <cylinder cd_x=\"{}\" cd_y=\"{}\" cd_z=\"{}\" linear_damping=\"{}\" \
                     strips=\"{strips}\" axial_added_mass_ratio=\"{}\" added_mass_scale=\"{}\"{hull}/>\n      </body>",
                    num(*cd_x),
                    num(*cd_y),
                    num(*cd_z),
                    nums(linear_damping),
                    num(*axial_added_mass_ratio),
                    num(*added_mass_scale)
                );
            }
            _ => {
                let _ = writeln!(o, "{head}/>");
            }
        }
    }
    let _ = writeln!(o, "    </plugin>\n  </gazebo>");
}

/// The URDF text of `v` (docs/urdf.md "Export").
pub fn vehicle_to_urdf(v: &Vehicle) -> Result<String, ExportError> {
    let names = link_names(v);
    let mut o = String::new();
    let _ = writeln!(o, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        o,
        "<!-- Written by `usm-study design export` (format urdf) from the design {}.\n     \
         Conventions (docs/urdf.md): SI units; hydrodynamic matrices in UUV Simulator's frame\n     \
         (the link frame turned 180 deg about x) about the link origin. Cylinder-model bodies: the\n     \
         added mass is exact, the Fossen damping an equivalent (usm-study reads the usm_study block).\n     \
         Propeller links carry no inertial: Gazebo needs a small one added. -->",
        v.name.replace("--", "- -")
    );
    let _ = writeln!(o, "<robot name=\"{}\">", xml_escape(&v.name));
    for (i, b) in v.bodies.iter().enumerate() {
        link_xml(&mut o, &names[i], b);
    }
    for (k, j) in v.joints.iter().enumerate() {
        let _ = writeln!(
            o,
            "  <joint name=\"{}\" type=\"revolute\">\n    {}\n    <parent link=\"{}\"/>\n    \
             <child link=\"{}\"/>\n    <axis xyz=\"{}\"/>\n    \
             <limit lower=\"{}\" upper=\"{}\" effort=\"0\" velocity=\"0\"/>\n  </joint>",
            xml_escape(&j.name),
            origin_xml(&j.placement),
            names[k],
            names[k + 1],
            nums(j.axis.as_slice()),
            num(j.min),
            num(j.max)
        );
    }
    for (i, t) in v.thrusters.iter().enumerate() {
        let (jn, ln) = (
            xml_escape(&t.name),
            format!("{}_propeller", xml_escape(&t.name)),
        );
        let _ = writeln!(
            o,
            "  <link name=\"{ln}\"/>\n  <joint name=\"{jn}\" type=\"continuous\">\n    \
             <origin xyz=\"{}\" rpy=\"0 0 0\"/>\n    <parent link=\"{}\"/>\n    <child link=\"{ln}\"/>\n    \
             <axis xyz=\"{}\"/>\n  </joint>",
            nums(t.position.as_slice()),
            names[t.body],
            nums(t.direction.as_slice())
        );
        let dynamics = match t.time_constant {
            Some(tc) => format!(
                "<type>FirstOrder</type><timeConstant>{}</timeConstant>",
                num(tc)
            ),
            None => "<type>ZeroOrder</type>".into(),
        };
        let rate = t.rate_limit.map_or(String::new(), |r| {
            format!("\n      <rateLimit>{}</rateLimit>", num(r))
        });
        let _ = writeln!(
            o,
            "  <gazebo>\n    <plugin name=\"{jn}_thruster_model\" filename=\"libuuv_thruster_ros_plugin.so\">\n      \
             <linkName>{ln}</linkName>\n      <jointName>{jn}</jointName>\n      <thrusterID>{i}</thrusterID>\n      \
             <dynamics>{dynamics}</dynamics>\n      \
             <conversion><type>Basic</type><rotorConstant>1.0</rotorConstant></conversion>\n      \
             <thrustMin>{}</thrustMin>\n      <thrustMax>{}</thrustMax>{rate}\n    </plugin>\n  </gazebo>",
            num(t.u_min),
            num(t.u_max)
        );
    }
    uuv_block(&mut o, v, &names)?;
    usm_block(&mut o, v, &names);
    let _ = writeln!(o, "</robot>");
    Ok(o)
}

/// Escape `& < > "` for attribute and text content.
pub(super) fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

//! A [`Vehicle`] → MuJoCo MJCF (docs/urdf.md "MJCF"): nested bodies with explicit inertials
//! (the root body's frame is the base frame `F_b`, under a free joint), hinge joints with their
//! limits, one site and one `motor` per thruster (force along the site's z axis), a cylinder
//! geom per body with MuJoCo's ellipsoid fluid model, and buoyancy as `gravcomp = ρV/m`. The
//! file's leading comment lists what MuJoCo cannot represent.

use super::export::{link_names, num, nums, xml_escape, ExportError};
use crate::model::{Body, Vehicle};
use crate::spatial::{quat_from_matrix, Mat3, Se3, Vec3};
use std::fmt::Write as _;

const CAVEATS: &str = "What MuJoCo cannot represent from this design (docs/urdf.md):\n\
  - buoyancy is gravcomp = rho V / m, a force at the centre of mass: the restoring moment of\n\
    CB != CG is lost;\n\
  - drag and added mass come from MuJoCo's own ellipsoid fluid model of each geom (fluidshape),\n\
    not from the design's coefficients, cylinder strips, hull drag or Fossen matrices;\n\
  - no current (MuJoCo's wind option moves the medium but is not set here), no thruster time\n\
    constant or rate limit (motors act instantly within ctrlrange);\n\
  - the mass matrix (rigid bodies, joints, free base) is exact; a test compares it with\n\
    usm-study's at random configurations (benches/mujoco_check.py).";

fn quat(r: &Mat3) -> String {
    let q = quat_from_matrix(r);
    nums(&[q.w, q.i, q.j, q.k])
}

fn pose(g: &Se3) -> String {
    format!("pos=\"{}\" quat=\"{}\"", nums(g.p.as_slice()), quat(&g.r))
}

/// The inertial, geom and thruster sites of body `i`, in a frame `t` of the MuJoCo body
/// (identity except for the root, whose MuJoCo frame is `F_b`).
fn body_contents(o: &mut String, v: &Vehicle, i: usize, b: &Body, t: &Se3, ind: &str) {
    let c = t.act_point(&b.cg);
    let inertia = t.r * b.inertia * t.r.transpose();
    let _ = writeln!(
        o,
        "{ind}<inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{}\"/>",
        nums(c.as_slice()),
        num(b.mass),
        nums(&[
            inertia[(0, 0)],
            inertia[(1, 1)],
            inertia[(2, 2)],
            inertia[(0, 1)],
            inertia[(0, 2)],
            inertia[(1, 2)]
        ])
    );
    let a = t.act_point(&Vec3::zeros());
    let e = t.act_point(&Vec3::new(b.length, 0.0, 0.0));
    let _ = writeln!(
        o,
        "{ind}<geom type=\"cylinder\" fromto=\"{} {}\" size=\"{}\" fluidshape=\"ellipsoid\" contype=\"0\" conaffinity=\"0\"/>",
        nums(a.as_slice()),
        nums(e.as_slice()),
        num(b.radius)
    );
    for th in v.thrusters.iter().filter(|th| th.body == i) {
        let p = t.act_point(&th.position);
        let d = t.act_vector(&th.direction);
        let _ = writeln!(
            o,
            "{ind}<site name=\"{}\" pos=\"{}\" zaxis=\"{}\" size=\"0.01\"/>",
            xml_escape(&th.name),
            nums(p.as_slice()),
            nums(d.as_slice())
        );
    }
}

/// The MJCF text of `v`.
pub fn vehicle_to_mjcf(v: &Vehicle) -> Result<String, ExportError> {
    let names = link_names(v);
    let mut o = String::new();
    let _ = writeln!(
        o,
        "<!-- Written by `usm-study design export` (format mjcf) from the design {}.\n{}\n-->",
        v.name.replace("--", "- -"),
        CAVEATS
    );
    let _ = writeln!(o, "<mujoco model=\"{}\">", xml_escape(&v.name));
    let _ = writeln!(
        o,
        "  <compiler angle=\"radian\" inertiafromgeom=\"false\" autolimits=\"true\"/>"
    );
    let _ = writeln!(
        o,
        "  <option density=\"{}\" viscosity=\"0\" gravity=\"0 0 {}\" integrator=\"implicitfast\"/>",
        num(v.fluid.rho),
        num(-v.fluid.g)
    );
    let _ = writeln!(o, "  <worldbody>");
    let base_inv = v.base.inverse();
    let mut ind = String::from("    ");
    for (i, b) in v.bodies.iter().enumerate() {
        let gravcomp = v.fluid.rho * b.volume / b.mass;
        let (frame, t) = if i == 0 {
            ("pos=\"0 0 0\"".to_string(), base_inv)
        } else {
            let p = if i == 1 {
                base_inv.compose(&v.joints[0].placement)
            } else {
                v.joints[i - 1].placement
            };
            (pose(&p), Se3::identity())
        };
        let _ = writeln!(
            o,
            "{ind}<body name=\"{}\" {frame} gravcomp=\"{}\">",
            xml_escape(&names[i]),
            num(gravcomp)
        );
        let inner = format!("{ind}  ");
        if i == 0 {
            let _ = writeln!(o, "{inner}<freejoint name=\"base\"/>");
        } else {
            let j = &v.joints[i - 1];
            let _ = writeln!(
                o,
                "{inner}<joint name=\"{}\" type=\"hinge\" axis=\"{}\" range=\"{} {}\"/>",
                xml_escape(&j.name),
                nums(j.axis.as_slice()),
                num(j.min),
                num(j.max)
            );
        }
        body_contents(&mut o, v, i, b, &t, &inner);
        ind = inner;
    }
    for _ in &v.bodies {
        ind.truncate(ind.len() - 2);
        let _ = writeln!(o, "{ind}</body>");
    }
    let _ = writeln!(o, "  </worldbody>\n  <actuator>");
    for th in &v.thrusters {
        let _ = writeln!(
            o,
            "    <motor name=\"{0}\" site=\"{0}\" gear=\"0 0 1 0 0 0\" ctrlrange=\"{1} {2}\"/>",
            xml_escape(&th.name),
            num(th.u_min),
            num(th.u_max)
        );
    }
    let _ = writeln!(o, "  </actuator>\n</mujoco>");
    Ok(o)
}

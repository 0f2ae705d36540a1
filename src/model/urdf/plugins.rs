//! The hydrodynamic plugin blocks of a URDF (docs/urdf.md): UUV Simulator / Plankton
//! (`uuv_underwater_object_ros_plugin`, `uuv_thruster_ros_plugin`), gz-sim `Hydrodynamics` and
//! `Thruster` systems, and usm-study's own `usm_study` block (what a URDF cannot say: body
//! sizes, the cylinder model, base and end-effector frames). Every matrix is converted here to
//! the model's convention (docs/model.md §2): body frame x forward, y left, z up; added mass
//! `M_A` positive; damping wrench `−(D_l ν + D_q (|ν| ∘ ν))` about the link frame's origin.

use super::error::UrdfError;
use super::parse::{child, children, err_at, floats, line_of};
use crate::model::{HullDrag, Hydro};
use crate::spatial::{Mat3, Mat6, Se3, Vec3};
use roxmltree::Node;
use std::collections::BTreeMap;

/// Hydrodynamics and hydrostatics one plugin gives for one link.
#[derive(Clone, Debug, Default)]
pub(super) struct LinkHydro {
    /// Displaced volume [m³] (UUV `<volume>`).
    pub volume: Option<f64>,
    /// Centre of buoyancy in the link frame [m] (UUV `<center_of_buoyancy>`).
    pub cob: Option<Vec3>,
    /// UUV `<neutrally_buoyant>`: buoyancy equal to the link's weight.
    pub neutral: bool,
    /// `M_A`, `D_l`, `D_q` in the model's convention, when given.
    pub added_mass: Option<Mat6>,
    pub linear: Option<Mat6>,
    pub quadratic: Option<Mat6>,
    /// Notes for the ledger (terms dropped, conventions applied).
    pub notes: Vec<String>,
}

/// One thruster plugin.
#[derive(Clone, Debug)]
pub(super) struct ThrusterSpec {
    pub line: usize,
    /// The propeller joint (UUV `<jointName>`, gz `<joint_name>`).
    pub joint: Option<String>,
    /// The propeller link (UUV `<linkName>`).
    pub link: Option<String>,
    /// Thrust limits [N] the block implies, when finite.
    pub limits: Option<(f64, f64)>,
    /// First-order time constant [s] (UUV `<dynamics><type>FirstOrder`).
    pub time_constant: Option<f64>,
    /// usm-study extension `<rateLimit>` [N/s].
    pub rate_limit: Option<f64>,
}

/// usm-study's own per-link values (`<plugin name="usm_study">`'s `<body>`).
#[derive(Clone, Debug)]
pub(super) struct UsmBody {
    pub length: f64,
    pub radius: f64,
    pub cylinder: Option<Hydro>,
}

/// Everything the plugin blocks say.
#[derive(Clone, Debug, Default)]
pub(super) struct Plugins {
    /// Fluid density [kg/m³] (UUV `<fluid_density>`, gz `<water_density>`).
    pub rho: Option<f64>,
    /// gz-sim Thruster `<fluid_density>`, the fallback for `rho`.
    pub thruster_rho: Option<f64>,
    /// Gravity and current (usm_study block only).
    pub g: Option<f64>,
    pub current: Option<Vec3>,
    pub hydro: BTreeMap<String, LinkHydro>,
    pub thrusters: Vec<ThrusterSpec>,
    pub usm: BTreeMap<String, UsmBody>,
    pub base: Option<Se3>,
    pub end_effector: Option<Se3>,
    /// Whether any UUV underwater-object block is present (then collision shapes give no
    /// volume: docs/urdf.md "Hydrostatics").
    pub any_uuv: bool,
}

/// `S = diag(1, −1, −1, 1, −1, −1)`: UUV Simulator's hydrodynamic frame is the link frame
/// turned 180° about x (its `ToNED`); `M_ours = S M_uuv S`.
fn flip_ned(m: &Mat6) -> Mat6 {
    let s = [1.0, -1.0, -1.0, 1.0, -1.0, -1.0];
    Mat6::from_fn(|i, j| s[i] * s[j] * m[(i, j)])
}

fn text<'a>(n: Node<'a, '_>) -> &'a str {
    n.text().unwrap_or("").trim()
}

fn f64_of(origin: &str, n: Node) -> Result<f64, UrdfError> {
    let v = floats(origin, n, text(n), n.tag_name().name())?;
    match v.as_slice() {
        [x] => Ok(*x),
        _ => Err(err_at(
            origin,
            n,
            format!("needs one number, got {}", v.len()),
        )),
    }
}

fn vec3_of(origin: &str, n: Node, s: &str) -> Result<Vec3, UrdfError> {
    let v = floats(origin, n, s, n.tag_name().name())?;
    match v.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(err_at(
            origin,
            n,
            format!("needs 3 numbers, got {}", v.len()),
        )),
    }
}

/// A 6×6 from 6 numbers (the diagonal) or 36 (row-major), as UUV Simulator reads them.
fn mat6_of(origin: &str, n: Node) -> Result<Mat6, UrdfError> {
    let v = floats(origin, n, text(n), n.tag_name().name())?;
    match v.len() {
        6 => Ok(Mat6::from_diagonal(&nalgebra::Vector6::from_column_slice(
            &v,
        ))),
        36 => Ok(Mat6::from_row_slice(&v)),
        k => Err(err_at(origin, n, format!("needs 6 or 36 numbers, got {k}"))),
    }
}

fn uuv_link(origin: &str, l: Node, p: &mut Plugins) -> Result<(), UrdfError> {
    let name = l
        .attribute("name")
        .ok_or_else(|| err_at(origin, l, "<link> in a plugin without a name"))?;
    let mut h = LinkHydro::default();
    if let Some(v) = child(l, "volume") {
        h.volume = Some(f64_of(origin, v)?);
    }
    if let Some(c) = child(l, "center_of_buoyancy") {
        h.cob = Some(vec3_of(origin, c, text(c))?);
    }
    if let Some(nb) = child(l, "neutrally_buoyant") {
        h.neutral = matches!(text(nb), "1" | "true");
    }
    if let Some(m) = child(l, "hydrodynamic_model") {
        let kind = child(m, "type").map(text).unwrap_or("fossen");
        if kind != "fossen" && kind != "cylinder" {
            return Err(err_at(
                origin,
                m,
                format!(
                    "hydrodynamic model type `{kind}` is not supported (only `fossen` and \
                     `cylinder`)"
                ),
            ));
        }
        // UUV's file convention first (HMCylinder starts from HMFossen's matrices).
        let given = |tag: &'static str| child(m, tag).map(|n| mat6_of(origin, n)).transpose();
        let (mut a, d, mut q) = (
            given("added_mass")?,
            given("linear_damping")?,
            given("quadratic_damping")?,
        );
        if kind == "cylinder" {
            let rho = match p.rho {
                Some(r) => r,
                None => {
                    h.notes.push(format!(
                        "{name}: cylinder model without <fluid_density>: UUV Simulator's \
                         default 1028 kg/m³"
                    ));
                    1028.0
                }
            };
            let (ma, dq) = uuv_cylinder(origin, l, m, rho, &mut h.notes)?;
            let (a0, q0) = (
                a.get_or_insert_with(Mat6::zeros),
                q.get_or_insert_with(Mat6::zeros),
            );
            for i in 0..6 {
                if ma[i] != 0.0 {
                    a0[(i, i)] = ma[i];
                }
                if dq[i] != 0.0 {
                    q0[(i, i)] = dq[i];
                }
            }
        }
        if let Some(a) = a {
            h.added_mass = Some(flip_ned(&a));
        }
        if let Some(d) = d {
            h.linear = Some(-flip_ned(&d));
        }
        if let Some(q) = q {
            let q = -flip_ned(&q);
            if (0..6).any(|i| (0..6).any(|j| i != j && q[(i, j)] != 0.0)) {
                h.notes.push(format!(
                    "{name}: off-diagonal quadratic damping kept (UUV Simulator itself uses \
                     only the diagonal)"
                ));
            }
            h.quadratic = Some(q);
        }
        if child(m, "linear_damping_forward_speed").is_some() {
            h.notes.push(format!(
                "{name}: linear_damping_forward_speed ignored (no speed-dependent linear term)"
            ));
        }
    }
    p.hydro.insert(name.to_string(), h);
    Ok(())
}

/// UUV Simulator's `cylinder` hydrodynamic model (`HMCylinder`, uuv_gazebo_plugins
/// HydrodynamicModel.cc), in UUV's file convention: the diagonal added mass (positive) and
/// quadratic damping (negative) it sets. Radius and length are `<radius>`/`<length>` of the
/// model, else — as UUV does — the smallest and the largest extent of the link block's `<box>`
/// (`width` x, `length` y, `height` z; the smallest extent itself, not half of it, is UUV's
/// radius); the axis is `<axis>` `i`/`j`/`k`, else the direction of the largest extent. With
/// `L/(2r)` the dimension ratio, `C_d` of the circular face 0.91/0.85/0.87/0.99 for ratios
/// ≤ 1, 2, 4, 7 (0 beyond 7, as UUV leaves it) and of the side 0.63/0.68/0.74/0.82/0.98 for
/// ≤ 1, 2, 5, 10, above: along the axis `A = ρπr²` (UUV's expression, kg/m), across it
/// `ρπr²L`, about the two transverse axes `ρπr²L³/12`, about the axis 0; quadratic damping
/// `−½ρ C_d πr²` along the axis and `−½ρ C_d r L` across it.
fn uuv_cylinder(
    origin: &str,
    l: Node,
    m: Node,
    rho: f64,
    notes: &mut Vec<String>,
) -> Result<([f64; 6], [f64; 6]), UrdfError> {
    let name = l.attribute("name").unwrap_or("");
    let num = |n: Node, tag: &'static str| child(n, tag).map(|c| f64_of(origin, c)).transpose();
    let extents = match child(l, "box") {
        Some(b) => match (num(b, "width")?, num(b, "length")?, num(b, "height")?) {
            (Some(x), Some(y), Some(z)) => Some([x, y, z]),
            _ => None,
        },
        None => None,
    };
    let (r, len) = match (num(m, "radius")?, num(m, "length")?, extents) {
        (Some(r), Some(len), _) => (r, len),
        (r, len, Some(e)) => (
            r.unwrap_or(e[0].min(e[1]).min(e[2])),
            len.unwrap_or(e[0].max(e[1]).max(e[2])),
        ),
        _ => {
            return Err(err_at(
                origin,
                m,
                "cylinder model needs <radius> and <length>, or a <box> in its <link> block \
                 (UUV Simulator would fall back to Gazebo's bounding box, which a URDF does \
                 not carry)",
            ))
        }
    };
    if !(r > 0.0 && len > 0.0 && r.is_finite() && len.is_finite()) {
        return Err(err_at(origin, m, "cylinder radius and length must be > 0"));
    }
    let axis = match child(m, "axis").map(text) {
        Some("i") => 0,
        Some("j") => 1,
        Some("k") => 2,
        Some(other) => {
            return Err(err_at(
                origin,
                m,
                format!("cylinder <axis> must be i, j or k, got `{other}`"),
            ))
        }
        None => match extents {
            Some(e) if e[0] >= e[1].max(e[2]) => 0,
            Some(e) if e[1] >= e[2] => 1,
            Some(_) => 2,
            None => 0,
        },
    };
    let ratio = len / (2.0 * r);
    let cd_circ = match ratio {
        x if x <= 1.0 => 0.91,
        x if x <= 2.0 => 0.85,
        x if x <= 4.0 => 0.87,
        x if x <= 7.0 => 0.99,
        _ => 0.0,
    };
    let cd_len = match ratio {
        x if x <= 1.0 => 0.63,
        x if x <= 2.0 => 0.68,
        x if x <= 5.0 => 0.74,
        x if x <= 10.0 => 0.82,
        _ => 0.98,
    };
    let pi = std::f64::consts::PI;
    let ma_len = rho * pi * r * r * len;
    let ma_circ = rho * pi * r * r;
    let ma_torque = rho * pi * r * r * len.powi(3) / 12.0;
    let d_circ = -0.5 * cd_circ * pi * r * r * rho;
    let d_len = -0.5 * cd_len * r * len * rho;
    let (mut ma, mut dq) = ([0.0; 6], [0.0; 6]);
    for k in 0..3 {
        ma[k] = if k == axis { ma_circ } else { ma_len };
        dq[k] = if k == axis { d_circ } else { d_len };
        ma[3 + k] = if k == axis { 0.0 } else { ma_torque };
    }
    notes.push(format!(
        "{name}: UUV Simulator cylinder model (HMCylinder) evaluated as UUV does: r = {r} m, \
         L = {len} m, axis {}, added mass along the axis ρπr² (UUV's expression), none about it",
        ["i", "j", "k"][axis]
    ));
    Ok((ma, dq))
}

const FORCES: [char; 6] = ['x', 'y', 'z', 'k', 'm', 'n'];
const VELS: [char; 6] = ['U', 'V', 'W', 'P', 'Q', 'R'];

/// `(kind, i, j)` of a gz-sim Hydrodynamics coefficient name: kind 0 `xDotU` (added mass),
/// 1 `xU` (linear), 2 `xUabsU` or `xUU` (quadratic on `|ν_j| ν_j`), 3 a quadratic cross term
/// `xUabsV` (`|ν_k| ν_j`, k ≠ j) the model cannot hold.
fn gz_name(tag: &str) -> Option<(u8, usize, usize)> {
    let mut c = tag.chars();
    let i = FORCES.iter().position(|f| Some(*f) == c.next())?;
    let rest: String = c.collect();
    let vel = |s: &str| -> Option<usize> {
        let mut it = s.chars();
        let v = VELS.iter().position(|v| Some(*v) == it.next())?;
        it.next().is_none().then_some(v)
    };
    if let Some(r) = rest.strip_prefix("Dot") {
        return vel(r).map(|j| (0, i, j));
    }
    if let Some(j) = vel(&rest) {
        return Some((1, i, j));
    }
    if rest.len() == 2 {
        let (a, b) = rest.split_at(1);
        return match (vel(a), vel(b)) {
            (Some(j), Some(k)) if j == k => Some((2, i, j)),
            _ => None,
        };
    }
    let (a, b) = rest.split_once("abs")?;
    let (j, k) = (vel(a)?, vel(b)?);
    Some(if j == k { (2, i, j) } else { (3, i, j) })
}

fn gz_hydro(origin: &str, pl: Node, p: &mut Plugins) -> Result<(), UrdfError> {
    let link = child(pl, "link_name")
        .map(text)
        .ok_or_else(|| err_at(origin, pl, "Hydrodynamics system without <link_name>"))?;
    let mut h = LinkHydro::default();
    let (mut ma, mut dl, mut dq) = (Mat6::zeros(), Mat6::zeros(), Mat6::zeros());
    let (mut any_a, mut any_l, mut any_q) = (false, false, false);
    for c in pl.children().filter(|c| c.is_element()) {
        let tag = c.tag_name().name();
        if tag == "water_density" {
            p.rho = Some(f64_of(origin, c)?);
            continue;
        }
        let Some((kind, i, j)) = gz_name(tag) else {
            continue;
        };
        let v = f64_of(origin, c)?;
        match kind {
            0 => (ma[(i, j)], any_a) = (-v, true),
            1 => (dl[(i, j)], any_l) = (-v, true),
            2 => (dq[(i, j)], any_q) = (-v, true),
            _ => {
                if v != 0.0 {
                    h.notes.push(format!(
                        "{link}: quadratic cross term <{tag}> = {v} ignored"
                    ));
                }
            }
        }
    }
    h.added_mass = any_a.then_some(ma);
    h.linear = any_l.then_some(dl);
    h.quadratic = any_q.then_some(dq);
    p.hydro.insert(link.to_string(), h);
    Ok(())
}

/// Thrust limits of UUV Simulator's conversion functions: `Basic` `f(x) = c |x| x` on the
/// clamped command, `LinearInterp` the range of `outputValues`, cut by `thrustMin/Max`.
fn uuv_thruster(origin: &str, pl: Node) -> Result<ThrusterSpec, UrdfError> {
    let opt = |tag: &'static str| -> Result<Option<f64>, UrdfError> {
        child(pl, tag).map(|n| f64_of(origin, n)).transpose()
    };
    let (cmin, cmax) = (opt("clampMin")?, opt("clampMax")?);
    let (tmin, tmax) = (opt("thrustMin")?, opt("thrustMax")?);
    let mut lo = tmin.unwrap_or(f64::NEG_INFINITY);
    let mut hi = tmax.unwrap_or(f64::INFINITY);
    if let Some(conv) = child(pl, "conversion") {
        match child(conv, "type").map(text) {
            Some("Basic") => {
                let c = child(conv, "rotorConstant")
                    .map(|n| f64_of(origin, n))
                    .transpose()?
                    .unwrap_or(0.0);
                if let (Some(a), Some(b)) = (cmin, cmax) {
                    lo = lo.max(c * a.abs() * a);
                    hi = hi.min(c * b.abs() * b);
                }
            }
            Some("LinearInterp") => {
                if let Some(o) = child(conv, "outputValues") {
                    let v = floats(origin, o, text(o), "outputValues")?;
                    lo = lo.max(v.iter().copied().fold(f64::INFINITY, f64::min));
                    hi = hi.min(v.iter().copied().fold(f64::NEG_INFINITY, f64::max));
                }
            }
            _ => {}
        }
    }
    let time_constant = match child(pl, "dynamics") {
        Some(d) if child(d, "type").map(text) == Some("FirstOrder") => child(d, "timeConstant")
            .map(|n| f64_of(origin, n))
            .transpose()?,
        _ => None,
    };
    let huge = 1e15;
    Ok(ThrusterSpec {
        line: line_of(pl),
        joint: child(pl, "jointName").map(|n| text(n).to_string()),
        link: child(pl, "linkName").map(|n| text(n).to_string()),
        limits: (lo.abs() < huge && hi.abs() < huge && lo <= hi).then_some((lo, hi)),
        time_constant,
        rate_limit: opt("rateLimit")?,
    })
}

/// gz-sim Thruster: `<max_thrust_cmd>` / `<min_thrust_cmd>` in newtons, or with
/// `<use_angvel_cmd>` in rad/s through `T = C_t ρ D⁴ ω|ω|`.
fn gz_thruster(origin: &str, pl: Node, p: &mut Plugins) -> Result<ThrusterSpec, UrdfError> {
    let opt = |tag: &'static str| -> Result<Option<f64>, UrdfError> {
        child(pl, tag).map(|n| f64_of(origin, n)).transpose()
    };
    let angvel = child(pl, "use_angvel_cmd").map(text) == Some("true");
    if let Some(d) = opt("fluid_density")? {
        p.thruster_rho.get_or_insert(d);
    }
    let k = opt("thrust_coefficient")?.unwrap_or(1.0)
        * opt("fluid_density")?.unwrap_or(1000.0)
        * opt("propeller_diameter")?.unwrap_or(0.02).powi(4);
    let conv = |x: f64| if angvel { k * x.abs() * x } else { x };
    let limits = match (opt("min_thrust_cmd")?, opt("max_thrust_cmd")?) {
        (Some(a), Some(b)) => Some((conv(a), conv(b))),
        _ => None,
    };
    Ok(ThrusterSpec {
        line: line_of(pl),
        joint: child(pl, "joint_name").map(|n| text(n).to_string()),
        link: None,
        limits,
        time_constant: None,
        rate_limit: None,
    })
}

fn frame_attr(origin: &str, n: Node) -> Result<Se3, UrdfError> {
    let p = vec3_of(origin, n, n.attribute("position").unwrap_or("0 0 0"))?;
    let r = match n.attribute("rotation") {
        Some(s) => {
            let v = floats(origin, n, s, "rotation")?;
            if v.len() != 9 {
                return Err(err_at(origin, n, "rotation needs 9 numbers (row-major)"));
            }
            Mat3::from_row_slice(&v)
        }
        None => Mat3::identity(),
    };
    Ok(Se3::new(r, p))
}

fn attr_num(origin: &str, n: Node, a: &str) -> Result<f64, UrdfError> {
    let s = n
        .attribute(a)
        .ok_or_else(|| err_at(origin, n, format!("missing attribute {a}")))?;
    let v = floats(origin, n, s, a)?;
    v.first()
        .copied()
        .ok_or_else(|| err_at(origin, n, format!("attribute {a} is empty")))
}

fn usm_cylinder(origin: &str, c: Node) -> Result<Hydro, UrdfError> {
    let num = |a: &str| attr_num(origin, c, a);
    let ld = floats(
        origin,
        c,
        c.attribute("linear_damping").unwrap_or(""),
        "linear_damping",
    )?;
    let linear_damping: [f64; 6] = ld
        .try_into()
        .map_err(|_| err_at(origin, c, "linear_damping needs 6 numbers"))?;
    let hull = match c.attribute("hull") {
        None => None,
        Some(s) => {
            let v = floats(origin, c, s, "hull")?;
            let [friction_scale, nose_cd, base_cd, pod_drag_area, tunnel_drag_area, gap_drag_area, appendage_scale, form_scale, viscosity]: [f64; 9] =
                v.try_into().map_err(|_| err_at(origin, c, "hull needs 9 numbers"))?;
            Some(HullDrag {
                friction_scale,
                nose_cd,
                base_cd,
                pod_drag_area,
                tunnel_drag_area,
                gap_drag_area,
                appendage_scale,
                form_scale,
                viscosity,
            })
        }
    };
    Ok(Hydro::Cylinder {
        cd_x: num("cd_x")?,
        cd_y: num("cd_y")?,
        cd_z: num("cd_z")?,
        linear_damping,
        strips: num("strips")? as usize,
        axial_added_mass_ratio: num("axial_added_mass_ratio")?,
        added_mass_scale: num("added_mass_scale")?,
        lift_slope: 0.0,
        lift_every_body: false,
        hull,
    })
}

fn usm_block(origin: &str, pl: Node, p: &mut Plugins) -> Result<(), UrdfError> {
    for c in pl.children().filter(|c| c.is_element()) {
        match c.tag_name().name() {
            "base" => p.base = Some(frame_attr(origin, c)?),
            "end_effector" => p.end_effector = Some(frame_attr(origin, c)?),
            "fluid" => {
                p.g = Some(attr_num(origin, c, "g")?);
                p.current = Some(vec3_of(
                    origin,
                    c,
                    c.attribute("current").unwrap_or("0 0 0"),
                )?);
            }
            "body" => {
                let link = c
                    .attribute("link")
                    .ok_or_else(|| err_at(origin, c, "<body> without a link attribute"))?;
                let cylinder = child(c, "cylinder")
                    .map(|n| usm_cylinder(origin, n))
                    .transpose()?;
                p.usm.insert(
                    link.to_string(),
                    UsmBody {
                        length: attr_num(origin, c, "length")?,
                        radius: attr_num(origin, c, "radius")?,
                        cylinder,
                    },
                );
            }
            _ => {}
        }
    }
    Ok(())
}

/// Read every `<gazebo><plugin>` block of the robot.
pub(super) fn read_plugins(origin: &str, robot: Node) -> Result<Plugins, UrdfError> {
    let mut p = Plugins::default();
    for g in children(robot, "gazebo") {
        for pl in children(g, "plugin") {
            let file = pl.attribute("filename").unwrap_or("");
            let name = pl.attribute("name").unwrap_or("");
            if file.contains("underwater_object") {
                p.any_uuv = true;
                if let Some(d) = child(pl, "fluid_density") {
                    p.rho = Some(f64_of(origin, d)?);
                }
                for l in children(pl, "link") {
                    uuv_link(origin, l, &mut p)?;
                }
            } else if file.contains("hydrodynamics") || name.ends_with("Hydrodynamics") {
                gz_hydro(origin, pl, &mut p)?;
            } else if file.contains("uuv") && file.contains("thruster") {
                p.thrusters.push(uuv_thruster(origin, pl)?);
            } else if file.contains("thruster-system") || name.ends_with("systems::Thruster") {
                let t = gz_thruster(origin, pl, &mut p)?;
                p.thrusters.push(t);
            } else if name == "usm_study" {
                usm_block(origin, pl, &mut p)?;
            }
        }
    }
    Ok(p)
}

//! Building a [`Vehicle`] from the parsed schema: the three forms (preset, explicit
//! lists, generator), their defaults and the consistency checks, each error placed at its
//! key in the document.

use super::error::{DesignError, DesignErrorKind, DesignFault};
use super::schema::{BodyRef, BodySpec, DesignFile, FrameSpec, HydroSpec, JointSpec, ThrusterSpec};
use crate::input::document::Document;
use crate::model::error::ModelError;
use crate::model::generator::{BodyProfile, GeneratorSpec, ThrusterRule};
use crate::model::presets;
use crate::model::{Body, Fluid, HullDrag, Hydro, Joint, Thruster, Vehicle};
use crate::spatial::{rot_axis_angle, Mat3, Mat6, Se3, Vec3};
use std::path::Path;

/// Error-reporting context of one design: the located document its errors point into.
pub(super) struct Ctx<'a> {
    doc: &'a Document,
}

impl<'a> Ctx<'a> {
    /// A context placing errors in `doc`.
    pub(super) fn new(doc: &'a Document) -> Self {
        Ctx { doc }
    }

    /// An error at key `key` (positioned at the key or its nearest ancestor).
    fn err(&self, kind: DesignErrorKind, key: &str, message: impl Into<String>) -> DesignError {
        self.doc.error_at(
            key,
            DesignFault {
                kind,
                message: message.into(),
            },
        )
    }

    /// A schema error with the given message.
    pub(super) fn schema(&self, key: &str, message: impl Into<String>) -> DesignError {
        self.err(DesignErrorKind::Schema, key, message)
    }

    /// A physics/consistency error with the given message.
    fn invalid(&self, key: &str, message: impl Into<String>) -> DesignError {
        self.err(DesignErrorKind::Invalid, key, message)
    }

    /// A serde error from deserialising the typed schema.
    pub(super) fn serde_error(&self, e: &toml::de::Error) -> DesignError {
        self.doc.serde_error(e).map(|message| DesignFault {
            kind: DesignErrorKind::Schema,
            message,
        })
    }

    /// Map a [`ModelError`] from [`Vehicle::validate`] or [`GeneratorSpec::build`] to a
    /// positioned error, translating model keys to file keys; a key absent from the file
    /// is placed at `fallback` (e.g. `generator`) when given.
    fn model_error(&self, e: ModelError, fallback: Option<&str>) -> DesignError {
        let key = file_key(&e.key);
        let mut err = self.invalid(&key, e.message);
        if err.at.line.is_none() && self.doc.locate(&key).is_none() {
            if let Some(fb) = fallback {
                let at = self.doc.location(fb);
                err.at.line = at.line;
                err.at.column = at.column;
            }
        }
        err
    }
}

/// Translate a model key (`joint[1].limits`) into the design-file key (`joint[1].limits_deg`).
fn file_key(key: &str) -> String {
    let (parent, last) = match key.rfind('.') {
        Some(i) => (&key[..i + 1], &key[i + 1..]),
        None => ("", key),
    };
    let last = match last {
        "limits" => "limits_deg",
        "rotation" => "rpy_deg",
        "joint_limit" => "joint_limit_deg",
        other => other,
    };
    format!("{parent}{last}")
}

pub(super) fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Rotation `Rz(yaw) Ry(pitch) Rx(roll)` from `[roll, pitch, yaw]` [rad].
pub(super) fn rot_rpy(rpy: &Vec3) -> Mat3 {
    rot_axis_angle(&Vec3::z(), rpy[2])
        * rot_axis_angle(&Vec3::y(), rpy[1])
        * rot_axis_angle(&Vec3::x(), rpy[0])
}

/// A frame from optional `position` and `rpy_deg`.
fn frame(spec: Option<&FrameSpec>, default_position: Vec3) -> Se3 {
    let p = spec.and_then(|s| s.position).map_or(default_position, vec3);
    match spec.and_then(|s| s.rpy_deg) {
        Some(rpy) => Se3::new(rot_rpy(&vec3(rpy).map(f64::to_radians)), p),
        None => Se3::from_translation(p),
    }
}

/// Normalise a nonzero vector; vectors already unit to rounding are kept bit-exact.
fn unit(ctx: &Ctx, key: &str, v: [f64; 3]) -> Result<Vec3, DesignError> {
    let v = vec3(v);
    let n = v.norm();
    if n.is_nan() || n <= 0.0 || n.is_infinite() {
        return Err(ctx.invalid(key, "must be a nonzero vector"));
    }
    if (n - 1.0).abs() <= 4.0 * f64::EPSILON {
        Ok(v)
    } else {
        Ok(v / n)
    }
}

fn mat6(a: &[[f64; 6]; 6]) -> Mat6 {
    Mat6::from_fn(|r, c| a[r][c])
}

pub(super) fn build(file: &DesignFile, ctx: &Ctx) -> Result<Vehicle, DesignError> {
    let explicit = file.body.is_some() || file.joint.is_some();
    let explicit_key = if file.body.is_some() { "body" } else { "joint" };
    let forms: Vec<&str> = [
        ("preset", file.preset.is_some()),
        ("urdf", file.urdf.is_some()),
        (explicit_key, explicit),
        ("generator", file.generator.is_some()),
    ]
    .iter()
    .filter(|(_, present)| *present)
    .map(|(k, _)| *k)
    .collect();
    let usage = "a design uses exactly one of `preset = \"NAME\"`, `urdf = \"ROBOT.urdf\"`, \
                 explicit [[body]]/[[joint]] lists or a [generator] table";
    if forms.len() > 1 {
        return Err(ctx.schema(
            forms[1],
            format!("cannot be combined with `{}`: {usage}", forms[0]),
        ));
    }
    let default_name = || {
        Path::new(ctx.doc.origin())
            .file_stem()
            .and_then(|s| s.to_str())
            .filter(|s| !s.is_empty())
            .unwrap_or("design")
            .to_string()
    };
    for (key, present) in [
        ("thrust_limit", file.thrust_limit.is_some()),
        ("fixed_joints", file.fixed_joints.is_some()),
    ] {
        if present && file.urdf.is_none() {
            return Err(ctx.schema(key, "only with `urdf` (an import option)"));
        }
    }
    let name = file.name.clone().unwrap_or_else(default_name);
    let v = match forms.first() {
        None => return Err(ctx.schema("", format!("no design found: {usage}"))),
        Some(&"preset") => build_preset(file, ctx)?,
        Some(&"urdf") => build_urdf(file, ctx)?,
        Some(&"generator") => build_generator(file, ctx, &name)?,
        Some(_) => build_explicit(file, ctx, &name)?,
    };
    let fallback = if file.generator.is_some() {
        Some("generator")
    } else {
        None
    };
    v.validate().map_err(|e| ctx.model_error(e, fallback))?;
    Ok(v)
}

/// The pointer form `urdf = "robot.urdf"` (docs/urdf.md "A design file that points at a
/// URDF"): the path is relative to the design file; `thrust_limit` [N] and `fixed_joints` are
/// the import's options (`design import --thrust-limit`, `--fix-joint`). An error in the URDF
/// keeps the URDF's file, line and element and names the design file's `urdf` line.
fn build_urdf(file: &DesignFile, ctx: &Ctx) -> Result<Vehicle, DesignError> {
    for (key, present) in [
        ("fluid", file.fluid.is_some()),
        ("thruster", file.thruster.is_some()),
        ("base", file.base.is_some()),
        ("end_effector", file.end_effector.is_some()),
    ] {
        if present {
            return Err(ctx.schema(
                key,
                "not allowed with `urdf`: a URDF design takes only `name`, `thrust_limit` and \
                 `fixed_joints`; import it with `usm-study design import` to edit it",
            ));
        }
    }
    let rel = file.urdf.as_deref().unwrap_or_default();
    let dir = Path::new(ctx.doc.origin())
        .parent()
        .unwrap_or_else(|| Path::new(""));
    let path = dir.join(rel);
    if !path.is_file() {
        return Err(ctx.invalid(
            "urdf",
            format!(
                "no URDF file {} (the path is relative to the design file)",
                path.display()
            ),
        ));
    }
    if let Some(l) = file.thrust_limit {
        if !(l.is_finite() && l > 0.0) {
            return Err(ctx.invalid("thrust_limit", format!("must be finite and > 0, got {l}")));
        }
    }
    let opts = crate::model::urdf::ImportOptions {
        thrust_limit: file.thrust_limit,
        fixed_joints: file.fixed_joints.clone().unwrap_or_default(),
    };
    let at = ctx.doc.location("urdf");
    let mut v = crate::model::urdf::load_urdf(&path, &opts)
        .map(|i| i.vehicle)
        .map_err(|e| DesignError {
            at: crate::input::located::Location {
                origin: e.file.clone(),
                line: (e.line > 0).then_some(e.line),
                column: None,
                key: e.element.clone(),
            },
            error: DesignFault {
                kind: DesignErrorKind::Invalid,
                message: format!(
                    "{} (the URDF named by `urdf` at {}{})",
                    e.message,
                    at.origin,
                    at.line.map_or(String::new(), |l| format!(":{l}"))
                ),
            },
        })?;
    if let Some(n) = &file.name {
        v.name = n.clone();
    }
    Ok(v)
}

fn build_preset(file: &DesignFile, ctx: &Ctx) -> Result<Vehicle, DesignError> {
    for (key, present) in [
        ("fluid", file.fluid.is_some()),
        ("thruster", file.thruster.is_some()),
        ("base", file.base.is_some()),
        ("end_effector", file.end_effector.is_some()),
    ] {
        if present {
            return Err(ctx.schema(
                key,
                "not allowed with `preset`: a preset design takes only `name`; write the \
                 preset out with `usm-study design show` to change it",
            ));
        }
    }
    let p = file.preset.as_deref().unwrap_or_default();
    let mut v = presets::preset(p).map_err(|e| ctx.invalid("preset", e.message))?;
    if let Some(n) = &file.name {
        v.name = n.clone();
    }
    Ok(v)
}

fn fluid(file: &DesignFile) -> Fluid {
    let d = Fluid::default();
    match &file.fluid {
        None => d,
        Some(f) => Fluid {
            rho: f.rho.unwrap_or(d.rho),
            g: f.g.unwrap_or(d.g),
            current: f.current.map_or(d.current, vec3),
        },
    }
}

fn build_generator(file: &DesignFile, ctx: &Ctx, name: &str) -> Result<Vehicle, DesignError> {
    let Some(g) = &file.generator else {
        return Err(ctx.schema("generator", "missing"));
    };
    let d = GeneratorSpec::default();
    let rule = match &g.thruster_rule {
        None => d.thruster_rule,
        Some(s) => s
            .parse::<ThrusterRule>()
            .map_err(|e| ctx.schema("generator.thruster_rule", e.to_string()))?,
    };
    let body_profile = match &g.body_profile {
        None => d.body_profile,
        Some(s) => BodyProfile::parse(s).ok_or_else(|| {
            ctx.schema(
                "generator.body_profile",
                format!("unknown body profile '{s}'; valid: uniform, paper"),
            )
        })?,
    };
    if body_profile == BodyProfile::Paper {
        for key in ["link_length", "link_mass"] {
            if ctx.doc.contains(&format!("generator.{key}")) {
                return Err(ctx.invalid(
                    &format!("generator.{key}"),
                    "cannot be given with body_profile = \"paper\" (USM Table II sets every \
                     link's length and mass)",
                ));
            }
        }
    }
    let spec = GeneratorSpec {
        links: g.links.unwrap_or(d.links),
        body_profile,
        link_length: g
            .link_length
            .as_ref()
            .map_or(d.link_length, |v| v.0.clone()),
        link_mass: g.link_mass.as_ref().map_or(d.link_mass, |v| v.0.clone()),
        radius: g.radius.unwrap_or(d.radius),
        module_length: g.module_length.unwrap_or(d.module_length),
        module_mass: g.module_mass.unwrap_or(d.module_mass),
        joint_limit: g.joint_limit_deg.map_or(d.joint_limit, f64::to_radians),
        thruster_rule: rule,
        thrust_limit: g.thrust_limit.unwrap_or(d.thrust_limit),
        thrust_per_kg: g.thrust_per_kg.unwrap_or(d.thrust_per_kg),
        longitudinal_offset: g.longitudinal_offset.unwrap_or(d.longitudinal_offset),
        cd_axial_ends: g.cd_axial_ends.or(d.cd_axial_ends),
        cd_axial: g.cd_axial.or(d.cd_axial),
        cd_cross: g.cd_cross.unwrap_or(d.cd_cross),
        metacentric_height: g.metacentric_height.unwrap_or(d.metacentric_height),
        wet_weight: g.wet_weight.unwrap_or(d.wet_weight),
    };
    for (key, values) in [
        ("link_length", &spec.link_length),
        ("link_mass", &spec.link_mass),
    ] {
        if let Some(x) = values.iter().find(|x| x.is_nan() || **x <= 0.0) {
            return Err(ctx.invalid(
                &format!("generator.{key}"),
                format!("values must be > 0, got {x}"),
            ));
        }
    }
    if ctx.doc.contains("generator.link_length") && spec.link_length.is_empty() {
        return Err(ctx.invalid("generator.link_length", "needs at least one value"));
    }
    for (key, v) in [
        ("cd_axial_ends", spec.cd_axial_ends),
        ("cd_axial", spec.cd_axial),
        ("cd_cross", Some(spec.cd_cross)),
    ] {
        let Some(v) = v else { continue };
        if v.is_nan() || v < 0.0 {
            return Err(ctx.invalid(
                &format!("generator.{key}"),
                format!("must be >= 0, got {v}"),
            ));
        }
    }
    let mut v = spec
        .build(name)
        .map_err(|e| ctx.model_error(e, Some("generator")))?;
    if file.fluid.is_some() {
        v.fluid = fluid(file);
        if v.fluid.rho > 0.0 {
            let factor = spec.volume_factor(v.total_mass(), v.fluid.g);
            for b in &mut v.bodies {
                b.volume = b.mass / v.fluid.rho;
                if factor != 1.0 {
                    b.volume *= factor;
                }
            }
        }
    }
    if let Some(list) = &file.thruster {
        v.thrusters = thrusters(list, &v.bodies, ctx)?;
    }
    if let Some(b) = &file.base {
        v.base = frame(Some(b), Vec3::zeros());
    }
    if let Some(e) = &file.end_effector {
        let last = v.bodies.last().map_or(0.0, |b| b.length);
        v.end_effector = frame(Some(e), Vec3::new(last, 0.0, 0.0));
    }
    Ok(v)
}

fn build_explicit(file: &DesignFile, ctx: &Ctx, name: &str) -> Result<Vehicle, DesignError> {
    let Some(body_specs) = &file.body else {
        return Err(ctx.schema("body", "explicit [[joint]] lists need [[body]] lists"));
    };
    let fluid = fluid(file);
    let mut bodies = Vec::with_capacity(body_specs.len());
    for (i, b) in body_specs.iter().enumerate() {
        if let Some(j) = body_specs[..i].iter().position(|o| o.name == b.name) {
            return Err(ctx.invalid(
                &format!("body[{i}].name"),
                format!("duplicate body name '{}' (also body[{j}])", b.name),
            ));
        }
        bodies.push(body(b, i, &fluid, ctx)?);
    }
    let joint_specs: &[JointSpec] = file.joint.as_deref().unwrap_or_default();
    let mut joints = Vec::with_capacity(joint_specs.len());
    for (k, j) in joint_specs.iter().enumerate() {
        let key = |f: &str| format!("joint[{k}].{f}");
        let axis = unit(ctx, &key("axis"), j.axis)?;
        let parent_len = bodies.get(k).map_or(0.0, |b: &Body| b.length);
        let pos = j.position.map_or(Vec3::new(parent_len, 0.0, 0.0), vec3);
        let placement = match j.rpy_deg {
            Some(rpy) => Se3::new(rot_rpy(&vec3(rpy).map(f64::to_radians)), pos),
            None => Se3::from_translation(pos),
        };
        let [lo, hi] = j.limits_deg.unwrap_or([-90.0, 90.0]);
        if lo > hi {
            return Err(ctx.invalid(
                &key("limits_deg"),
                format!("need min <= max, got [{lo}, {hi}]"),
            ));
        }
        joints.push(Joint {
            name: j.name.clone().unwrap_or_else(|| format!("q{}", k + 1)),
            placement,
            axis,
            min: lo.to_radians(),
            max: hi.to_radians(),
        });
    }
    let thrusters = match &file.thruster {
        Some(list) => thrusters(list, &bodies, ctx)?,
        None => Vec::new(),
    };
    let base = frame(file.base.as_ref(), Vec3::zeros());
    let last = bodies.last().map_or(0.0, |b| b.length);
    let end_effector = frame(file.end_effector.as_ref(), Vec3::new(last, 0.0, 0.0));
    Ok(Vehicle {
        name: name.to_string(),
        bodies,
        joints,
        thrusters,
        base,
        end_effector,
        fluid,
    })
}

fn body(b: &BodySpec, i: usize, fluid: &Fluid, ctx: &Ctx) -> Result<Body, DesignError> {
    let key = |f: &str| format!("body[{i}].{f}");
    // Check the scalars the defaults are computed from before using them.
    for (f, v) in [("mass", b.mass), ("length", b.length), ("radius", b.radius)] {
        if v.is_nan() || v <= 0.0 {
            return Err(ctx.invalid(&key(f), format!("must be > 0, got {v}")));
        }
    }
    let hydro = hydro(b.hydro.as_ref(), b.length, i, ctx)?;
    let mut body = Body::cylinder(&b.name, b.mass, b.length, b.radius, hydro);
    if let Some(cg) = b.cg {
        body.cg = vec3(cg);
    }
    if let Some(cb) = b.cb {
        body.cb = vec3(cb);
    }
    match (b.volume, b.neutral) {
        (Some(_), Some(true)) => {
            return Err(ctx.schema(
                &key("neutral"),
                "give either `volume` or `neutral = true`, not both",
            ))
        }
        (Some(v), _) => body.volume = v,
        (None, Some(true)) => body.volume = b.mass / fluid.rho,
        _ => {}
    }
    if let Some(m) = b.inertia {
        body.inertia = Mat3::from_fn(|r, c| m[r][c]);
    }
    Ok(body)
}

/// A body's `[body.hydro]` (module doc). The cylinder kind's axial drag: the hull drag
/// (docs/model.md §2 "Hull drag") unless the file gives a per-body `cd_x`, which then means
/// what it says (USM Table II's form, with the former per-body linear damping), and `hull =
/// true` adds the hull drag on top; `linear_damping` given is per body, left out it is
/// [`crate::model::LINEAR_DAMPING_PER_METRE`] × `length` with the hull and the former per-body default
/// without.
fn hydro(h: Option<&HydroSpec>, length: f64, i: usize, ctx: &Ctx) -> Result<Hydro, DesignError> {
    let Some(h) = h else {
        return Ok(Hydro::hull(length, 1.0));
    };
    let key = |f: &str| format!("body[{i}].hydro.{f}");
    let cylinder_keys = [
        ("cd_x", h.cd_x.is_some()),
        ("cd_y", h.cd_y.is_some()),
        ("cd_z", h.cd_z.is_some()),
        ("linear_damping", h.linear_damping.is_some()),
        ("strips", h.strips.is_some()),
        ("axial_added_mass_ratio", h.axial_added_mass_ratio.is_some()),
        ("added_mass_scale", h.added_mass_scale.is_some()),
        ("hull", h.hull.is_some()),
        ("friction_scale", h.friction_scale.is_some()),
        ("nose_cd", h.nose_cd.is_some()),
        ("base_cd", h.base_cd.is_some()),
        ("pod_drag_area", h.pod_drag_area.is_some()),
        ("tunnel_drag_area", h.tunnel_drag_area.is_some()),
        ("gap_drag_area", h.gap_drag_area.is_some()),
        ("appendage_scale", h.appendage_scale.is_some()),
        ("form_scale", h.form_scale.is_some()),
        ("viscosity", h.viscosity.is_some()),
    ];
    let coefficient_keys = [
        ("added_mass", h.added_mass.is_some()),
        ("linear", h.linear.is_some()),
        ("quadratic", h.quadratic.is_some()),
    ];
    let misplaced = |keys: &[(&str, bool)], kind: &str| -> Result<(), DesignError> {
        match keys.iter().find(|(_, present)| *present) {
            Some((f, _)) => Err(ctx.schema(&key(f), format!("not a key of hydro kind \"{kind}\""))),
            None => Ok(()),
        }
    };
    match h.kind.as_deref().unwrap_or("cylinder") {
        "cylinder" => {
            misplaced(&coefficient_keys, "cylinder")?;
            cylinder(h, length, i, ctx)
        }
        "coefficients" => {
            misplaced(&cylinder_keys, "coefficients")?;
            let Some(added_mass) = &h.added_mass else {
                return Err(ctx.schema(
                    &key("added_mass"),
                    "required with kind = \"coefficients\" (a 6×6 matrix)",
                ));
            };
            Ok(Hydro::Coefficients {
                added_mass: mat6(added_mass),
                linear: h.linear.as_ref().map_or(Mat6::zeros(), mat6),
                quadratic: h.quadratic.as_ref().map_or(Mat6::zeros(), mat6),
            })
        }
        other => Err(ctx.schema(
            &key("kind"),
            format!("unknown hydro kind '{other}'; valid: cylinder, coefficients"),
        )),
    }
}

/// The cylinder kind of a body's `[body.hydro]` ([`hydro`]): defaults from [`Hydro::hull`] or
/// [`Hydro::cylinder`], overridden key by key.
fn cylinder(h: &HydroSpec, length: f64, i: usize, ctx: &Ctx) -> Result<Hydro, DesignError> {
    let key = |f: &str| format!("body[{i}].hydro.{f}");
    let hull_fields = [
        ("friction_scale", h.friction_scale),
        ("nose_cd", h.nose_cd),
        ("base_cd", h.base_cd),
        ("pod_drag_area", h.pod_drag_area),
        ("tunnel_drag_area", h.tunnel_drag_area),
        ("gap_drag_area", h.gap_drag_area),
        ("appendage_scale", h.appendage_scale),
        ("form_scale", h.form_scale),
        ("viscosity", h.viscosity),
    ];
    let with_hull = h.hull.unwrap_or(h.cd_x.is_none());
    if !with_hull {
        if let Some((f, _)) = hull_fields.iter().find(|(_, v)| v.is_some()) {
            return Err(ctx.schema(
                &key(f),
                "a hull-drag key, but this body has no hull drag (it gives `cd_x` or \
                 `hull = false`; add `hull = true` for both)",
            ));
        }
    }
    let Hydro::Cylinder {
        cd_y,
        cd_z,
        linear_damping,
        strips,
        axial_added_mass_ratio,
        added_mass_scale,
        lift_slope,
        lift_every_body,
        hull,
        ..
    } = (if with_hull {
        Hydro::hull(length, 1.0)
    } else {
        Hydro::cylinder(0.1, 1.0)
    })
    else {
        return Err(ctx.schema(&key("kind"), "internal: cylinder defaults"));
    };
    let hull = hull.map(|d| HullDrag {
        friction_scale: h.friction_scale.unwrap_or(d.friction_scale),
        nose_cd: h.nose_cd.unwrap_or(d.nose_cd),
        base_cd: h.base_cd.unwrap_or(d.base_cd),
        pod_drag_area: h.pod_drag_area.unwrap_or(d.pod_drag_area),
        tunnel_drag_area: h.tunnel_drag_area.unwrap_or(d.tunnel_drag_area),
        gap_drag_area: h.gap_drag_area.unwrap_or(d.gap_drag_area),
        appendage_scale: h.appendage_scale.unwrap_or(d.appendage_scale),
        form_scale: h.form_scale.unwrap_or(d.form_scale),
        viscosity: h.viscosity.unwrap_or(d.viscosity),
    });
    let strips = h.strips.unwrap_or(strips);
    if !(1..=MAX_STRIPS).contains(&strips) {
        return Err(ctx.invalid(
            &key("strips"),
            format!("must be between 1 and {MAX_STRIPS}, got {strips}"),
        ));
    }
    Ok(Hydro::Cylinder {
        cd_x: h.cd_x.unwrap_or(if with_hull { 0.0 } else { 0.1 }),
        cd_y: h.cd_y.unwrap_or(cd_y),
        cd_z: h.cd_z.unwrap_or(cd_z),
        linear_damping: h.linear_damping.unwrap_or(linear_damping),
        strips,
        axial_added_mass_ratio: h.axial_added_mass_ratio.unwrap_or(axial_added_mass_ratio),
        added_mass_scale: h.added_mass_scale.unwrap_or(added_mass_scale),
        lift_slope,
        lift_every_body,
        hull,
    })
}

/// Upper bound on strip-theory integration points per body (guards against absurd input).
const MAX_STRIPS: usize = 1000;

fn thrusters(
    list: &[ThrusterSpec],
    bodies: &[Body],
    ctx: &Ctx,
) -> Result<Vec<Thruster>, DesignError> {
    let mut out = Vec::with_capacity(list.len());
    for (i, t) in list.iter().enumerate() {
        let key = |f: &str| format!("thruster[{i}].{f}");
        let body = match &t.body {
            BodyRef::Index(k) => usize::try_from(*k)
                .ok()
                .filter(|k| *k < bodies.len())
                .ok_or_else(|| {
                    ctx.invalid(
                        &key("body"),
                        format!(
                            "body index {k} does not exist (the design has {} bodies, 0..{})",
                            bodies.len(),
                            bodies.len()
                        ),
                    )
                })?,
            BodyRef::Name(n) => bodies.iter().position(|b| &b.name == n).ok_or_else(|| {
                let names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
                ctx.invalid(
                    &key("body"),
                    format!("no body named '{n}'; bodies: {}", names.join(", ")),
                )
            })?,
        };
        let direction = unit(ctx, &key("direction"), t.direction)?;
        let u_min = t.u_min.unwrap_or(-40.0);
        let u_max = t.u_max.unwrap_or(40.0);
        if u_min > u_max {
            let k = if t.u_min.is_some() { "u_min" } else { "u_max" };
            return Err(ctx.invalid(
                &key(k),
                format!("need u_min <= u_max, got [{u_min}, {u_max}]"),
            ));
        }
        out.push(Thruster {
            name: t.name.clone().unwrap_or_else(|| format!("T{}", i + 1)),
            body,
            position: vec3(t.position),
            direction,
            u_min,
            u_max,
            time_constant: t.time_constant,
            rate_limit: t.rate_limit,
        });
    }
    Ok(out)
}

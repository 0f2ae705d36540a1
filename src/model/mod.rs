//! The vehicle model (docs/model.md §2): a floating-base serial chain of rigid bodies joined by 1-DOF
//! revolute joints, with thrusters fixed to bodies and per-body hydrodynamic parameters.
//!
//! Frames: every body frame has its origin at the body's rear (tail) face and its x axis
//! along the body towards the head. Joint `i` (1-based in docs/model.md, index `i-1` here) joins
//! body `i-1` (parent) to body `i` (child). Nothing here assumes a USM: a UVMS is one large
//! vehicle body with thrusters followed by thruster-less links (docs/model.md §8).

pub mod design;
mod error;
pub mod generator;
pub mod ledger;
pub mod manoeuvring;
pub mod presets;
pub mod urdf;
pub mod world;

pub use error::ModelError;

use crate::spatial::{rigid_inertia, Mat3, Mat6, Se3, Vec3};
use nalgebra::Vector6;
use std::f64::consts::PI;

/// Default water density [kg/m³] (docs/model.md §2, ρ = 1026).
pub const RHO_SEAWATER: f64 = 1026.0;
/// Gravitational acceleration [m/s²] (docs/model.md §1).
pub const GRAVITY: f64 = 9.81;

/// The fluid the vehicle moves in. Each field's doc gives its default ([`Default`]); the
/// ranges are checked by [`Vehicle::validate`] (`fluid.*` keys).
#[derive(Clone, Debug, PartialEq)]
pub struct Fluid {
    /// Density ρ [kg/m³], finite and > 0. Default [`RHO_SEAWATER`] = 1026.
    pub rho: f64,
    /// Gravitational acceleration g [m/s²], acting along −z of the inertial frame; finite and
    /// ≥ 0. Default [`GRAVITY`] = 9.81.
    pub g: f64,
    /// Constant irrotational current ν_c, linear velocity in the inertial frame [m/s], finite.
    /// Default zero (still water).
    pub current: Vec3,
}

impl Default for Fluid {
    fn default() -> Self {
        Self {
            rho: RHO_SEAWATER,
            g: GRAVITY,
            current: Vec3::zeros(),
        }
    }
}

/// Per-body hydrodynamics (docs/model.md §2): a sum type over the two ways a body is described.
///
/// The `Coefficients` variant is large (three 6×6 matrices); bodies are few and built once,
/// so it is kept inline rather than boxed.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Hydro {
    /// A slender cylinder along the body's x axis: the USM paper's added-mass formulas
    /// (`M_A11 = 0.1 m`, `M_A22 = M_A33 = πρr²l`, `M_A44 = 0`, `M_A55 = M_A66 = πρr²l³/12`,
    /// about the geometric centre) and strip-theory drag coefficients.
    Cylinder {
        /// Axial drag coefficient `C_d,x` (on the cross-section area πr²).
        cd_x: f64,
        /// Cross-flow drag coefficient along body y (on the projected area 2r per unit length).
        cd_y: f64,
        /// Cross-flow drag coefficient along body z.
        cd_z: f64,
        /// Small linear damping on every axis, `[N·s/m ×3, N·m·s/rad ×3]`, applied to the
        /// relative twist at the body's geometric centre (inferred, docs/model.md §2).
        linear_damping: [f64; 6],
        /// Number of integration points along the body for the cross-flow strip integral.
        strips: usize,
        /// Ratio of axial added mass to body mass (paper: 0.1).
        axial_added_mass_ratio: f64,
        /// Factor on the whole added-mass matrix of the formulas above (1 = the paper's
        /// formulas; an uncertain world's `hydro.added_mass_scale`, docs/assumptions.md).
        added_mass_scale: f64,
        /// Slender-body lift slope `C_Lα` [1/rad] on the cross-section `π r²` (docs/model.md
        /// §2 "Lift"; `crate::dynamics::hydro::slender_lift`), acting at a free trailing face
        /// only. 0 = no lift (the default); set for every cylinder by the scenario key
        /// `hydro.lift_slope` (a world property, not written to design files).
        lift_slope: f64,
        /// Lift at the trailing face of *every* body, each its own blunt base, not only at
        /// the chain's free faces: an upper bound (`hydro.lift_every_body`; default false).
        lift_every_body: bool,
        /// The body's share of the whole hull's axial drag (docs/model.md §2 "Hull drag"):
        /// skin friction on its wetted side at the chain's Reynolds number, form drag at its
        /// faces where they are free ends of the chain or steps in diameter, and an appendage
        /// allowance for its thrusters and the joint gap at its rear face. Added to the
        /// per-body `cd_x` term (0 for hull bodies). `None`: no hull drag (the per-body
        /// coefficient model of USM Table II, and any design file that gives `cd_x`).
        hull: Option<HullDrag>,
    },
    /// Hydrodynamic derivatives in matrix form about the body frame's origin:
    /// added mass `M_A` (6×6, symmetric PSD), linear damping `D_l` and quadratic damping
    /// `D_q` so that the damping wrench is `−(D_l ν_r + D_q (|ν_r| ∘ ν_r))`.
    Coefficients {
        /// Added-mass matrix [kg, kg·m, kg·m²] about the body frame origin.
        added_mass: Mat6,
        /// Linear damping matrix.
        linear: Mat6,
        /// Quadratic damping matrix, multiplying the element-wise `|ν_r| ∘ ν_r`.
        quadratic: Mat6,
    },
    /// Manoeuvring derivatives of a streamlined hull (added mass, velocity products,
    /// resistance, cross-flow drag) about a reference point in axes of their own: the NPS
    /// AUV II of Antonelli & Chiaverini's case 3 ([`nps_auv2`]). The velocity-product table
    /// replaces the Kirchhoff term of the added mass (docs/model.md §4).
    Manoeuvring(Box<manoeuvring::Manoeuvring>),
}

/// Linear damping per metre of body length (docs/model.md §2 "Hull drag"), `[N·s/m per m ×3,
/// N·m·s/rad per m ×3]`, applied as `length ×` these on the body's relative twist at its
/// centre. **Inferred.** Surge 0.1: the order of laminar (Blasius) skin friction
/// `0.664 ρ (νU/L)^½ · 2πr` linearised at U = 0.1 m/s on the 3.3 m, r = 0.085 m paper hull
/// (0.07 N·s/m per m). Sway and heave 2.7, rotations 0.136: the paper design's former
/// 1 N·s/m and 0.05 N·m·s/rad per body (9 bodies) spread over its 3.3 m, so that only the
/// dependence on the body count changes; no source gives these (a regulariser of slow motion).
pub const LINEAR_DAMPING_PER_METRE: [f64; 6] = [0.1, 2.7, 2.7, 0.136, 0.136, 0.136];

/// The hull-drag constants a cylinder body carries (docs/model.md §2 "Hull drag"); the chain
/// they act in (its length, free ends, diameter steps, thrusters, joints) is read once when
/// the dynamics are built (`dynamics::hydro::HullSite`). Each field's doc gives its default
/// ([`Default`]) and source; the ranges are checked by [`Vehicle::validate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HullDrag {
    /// Factor on the ITTC-57 friction line `C_F = 0.075/(log₁₀ Re − 2)²` (ITTC 1957), applied
    /// on the body's side area `2πr l` with the chain's Reynolds number `Re = |u| L/ν`.
    /// Default 1.
    pub friction_scale: f64,
    /// Form drag coefficient of a free *leading* face (the nose; on `πr²`, or on the exposed
    /// annulus of a diameter step). Default 0.8: a flat-faced cylinder's forebody (Hoerner,
    /// *Fluid-Dynamic Drag*, 1965, ch. 3; USM Table II's C_d,x of the end links). 0 for a
    /// streamlined nose.
    pub nose_cd: f64,
    /// Base drag coefficient of a free *trailing* face (on `πr²` or the exposed annulus).
    /// Default 0.1 (inferred: Hoerner ch. 3 gives 0.1–0.2 behind a blunt base on a long
    /// cylinder). 0 for a tapered tail.
    pub base_cd: f64,
    /// Drag area `C_D A` [m²] of each thruster on the body whose direction is along the body
    /// axis (an external pod). Default 3.2e-3 (inferred: a 90 mm pod at C_D 0.5).
    pub pod_drag_area: f64,
    /// Drag area `C_D A` [m²] of each other thruster (a tunnel through the hull). Default
    /// 7.7e-4 (inferred: C_D 0.2 on a 70 mm tunnel's section for its two openings).
    pub tunnel_drag_area: f64,
    /// Drag area `C_D A` [m²] of the joint gap at the body's rear face (one per joint).
    /// Default 2.7e-4 (inferred: a 5 mm annular gap round a 0.085 m radius at C_D 0.1 on
    /// its area `w · 2πr`, a transverse groove in a turbulent boundary layer).
    pub gap_drag_area: f64,
    /// Factor on the three appendage drag areas. Default 1.
    pub appendage_scale: f64,
    /// Factor on the nose and base coefficients. Default 1.
    pub form_scale: f64,
    /// Kinematic viscosity ν [m²/s] of the Reynolds number. Default 1.19e-6 (seawater at
    /// 15 °C, 35 g/kg: ITTC 7.5-02-01-03, 2011).
    pub viscosity: f64,
}

impl Default for HullDrag {
    fn default() -> Self {
        Self {
            friction_scale: 1.0,
            nose_cd: 0.8,
            base_cd: 0.1,
            pod_drag_area: 3.2e-3,
            tunnel_drag_area: 7.7e-4,
            gap_drag_area: 2.7e-4,
            appendage_scale: 1.0,
            form_scale: 1.0,
            viscosity: 1.19e-6,
        }
    }
}

impl HullDrag {
    /// The fields by name, for validation and design files.
    pub fn fields(&self) -> [(&'static str, f64); 9] {
        [
            ("friction_scale", self.friction_scale),
            ("nose_cd", self.nose_cd),
            ("base_cd", self.base_cd),
            ("pod_drag_area", self.pod_drag_area),
            ("tunnel_drag_area", self.tunnel_drag_area),
            ("gap_drag_area", self.gap_drag_area),
            ("appendage_scale", self.appendage_scale),
            ("form_scale", self.form_scale),
            ("viscosity", self.viscosity),
        ]
    }
}

impl Hydro {
    /// The USM paper's cylinder model with per-body drag coefficients (USM Table II's form:
    /// axial `C_d,x` on `πr²` per body, no hull drag) and the former per-body linear damping
    /// (1 N·s/m on translations, 0.05 N·m·s/rad on rotations, inferred): what a design file's
    /// explicit `cd_x` means.
    pub fn cylinder(cd_x: f64, cd_yz: f64) -> Self {
        Hydro::Cylinder {
            cd_x,
            cd_y: cd_yz,
            cd_z: cd_yz,
            linear_damping: [1.0, 1.0, 1.0, 0.05, 0.05, 0.05],
            strips: 5,
            axial_added_mass_ratio: 0.1,
            added_mass_scale: 1.0,
            lift_slope: 0.0,
            lift_every_body: false,
            hull: None,
        }
    }

    /// A body of `length` [m] in the hull-drag model (docs/model.md §2 "Hull drag"): no
    /// per-body axial coefficient, the default [`HullDrag`], cross-flow coefficient `cd_yz`
    /// and linear damping [`LINEAR_DAMPING_PER_METRE`] × `length`.
    pub fn hull(length: f64, cd_yz: f64) -> Self {
        Hydro::Cylinder {
            cd_x: 0.0,
            cd_y: cd_yz,
            cd_z: cd_yz,
            linear_damping: LINEAR_DAMPING_PER_METRE.map(|d| d * length),
            strips: 5,
            axial_added_mass_ratio: 0.1,
            added_mass_scale: 1.0,
            lift_slope: 0.0,
            lift_every_body: false,
            hull: Some(HullDrag::default()),
        }
    }
}

/// A rigid body of the chain (docs/model.md §2).
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name used in reports and design files.
    pub name: String,
    /// Mass [kg].
    pub mass: f64,
    /// Length along the body x axis [m]; the next joint sits at the front face by default.
    pub length: f64,
    /// Radius [m] (cylinder model).
    pub radius: f64,
    /// Centre of gravity in the body frame [m].
    pub cg: Vec3,
    /// Centre of buoyancy in the body frame [m].
    pub cb: Vec3,
    /// Displaced volume [m³].
    pub volume: f64,
    /// Rotational inertia about the centre of gravity, body axes [kg·m²].
    pub inertia: Mat3,
    /// Hydrodynamic description.
    pub hydro: Hydro,
}

impl Body {
    /// A solid cylinder body with CG = CB at the geometric centre, inertia
    /// `Ixx = m r²/2, Iyy = Izz = m(3r²+l²)/12` and volume `πr²l` (docs/model.md §2 defaults).
    pub fn cylinder(name: &str, mass: f64, length: f64, radius: f64, hydro: Hydro) -> Self {
        let c = Vec3::new(length / 2.0, 0.0, 0.0);
        let ixx = mass * radius * radius / 2.0;
        let iyy = mass * (3.0 * radius * radius + length * length) / 12.0;
        Body {
            name: name.to_string(),
            mass,
            length,
            radius,
            cg: c,
            cb: c,
            volume: PI * radius * radius * length,
            inertia: Mat3::from_diagonal(&Vec3::new(ixx, iyy, iyy)),
            hydro,
        }
    }

    /// Geometric centre `(l/2, 0, 0)` in the body frame [m].
    pub fn centre(&self) -> Vec3 {
        Vec3::new(self.length / 2.0, 0.0, 0.0)
    }

    /// Rigid-body spatial inertia `I_RB` about the body frame origin (USM-22 summand).
    pub fn rigid_spatial_inertia(&self) -> Mat6 {
        rigid_inertia(self.mass, &self.cg, &self.inertia)
    }

    /// Added-mass spatial inertia `M_A` about the body frame origin (docs/model.md §2), in fluid
    /// of density `rho` [kg/m³].
    pub fn added_mass(&self, rho: f64) -> Mat6 {
        match &self.hydro {
            Hydro::Cylinder {
                axial_added_mass_ratio,
                added_mass_scale,
                ..
            } => {
                let (r, l) = (self.radius, self.length);
                let lat = PI * rho * r * r * l;
                let rot = PI * rho * r * r * l * l * l / 12.0;
                let mut d =
                    Vector6::new(axial_added_mass_ratio * self.mass, lat, lat, 0.0, rot, rot);
                if *added_mass_scale != 1.0 {
                    d *= *added_mass_scale;
                }
                // Paper formulas hold about the geometric centre; move to the frame origin.
                Se3::from_translation(self.centre()).inertia_to_parent(&Mat6::from_diagonal(&d))
            }
            Hydro::Coefficients { added_mass, .. } => *added_mass,
            Hydro::Manoeuvring(m) => m.added_mass_in_body(),
        }
    }
}

/// A revolute joint (docs/model.md §2). The child body's frame at zero angle is `placement` in the
/// parent body's frame; the joint rotates the child about `axis` (a unit vector in the
/// child frame, through its origin).
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name used in reports and design files.
    pub name: String,
    /// Child frame in the parent frame at zero joint angle.
    pub placement: Se3,
    /// Unit rotation axis in the child frame.
    pub axis: Vec3,
    /// Lower limit [rad].
    pub min: f64,
    /// Upper limit [rad].
    pub max: f64,
}

/// A thruster fixed to a body (docs/model.md §2).
#[derive(Clone, Debug, PartialEq)]
pub struct Thruster {
    /// Name used in reports and design files.
    pub name: String,
    /// Index of the body it is fixed to.
    pub body: usize,
    /// Point of application in the body frame [m].
    pub position: Vec3,
    /// Unit thrust direction in the body frame.
    pub direction: Vec3,
    /// Lower thrust limit [N].
    pub u_min: f64,
    /// Upper thrust limit [N].
    pub u_max: f64,
    /// Optional first-order lag time constant [s].
    pub time_constant: Option<f64>,
    /// Optional rate limit [N/s].
    pub rate_limit: Option<f64>,
}

/// A complete design: the floating-base chain (docs/model.md §2).
#[derive(Clone, Debug, PartialEq)]
pub struct Vehicle {
    /// Design name.
    pub name: String,
    /// Bodies, tail to head; body 0 carries the base frame.
    pub bodies: Vec<Body>,
    /// Joints; joint `k` joins body `k` to body `k+1`.
    pub joints: Vec<Joint>,
    /// Thrusters.
    pub thrusters: Vec<Thruster>,
    /// Pose of the base frame `F_b` in body 0's frame (default identity: the tail face).
    pub base: Se3,
    /// Pose of the end-effector frame `F_e` in the last body's frame (default: front face).
    pub end_effector: Se3,
    /// The surrounding fluid.
    pub fluid: Fluid,
}

fn finite_pos(key: String, v: f64) -> Result<(), ModelError> {
    if !v.is_finite() {
        return Err(ModelError::new(
            key,
            format!("must be a finite number, got {v}"),
        ));
    }
    if v <= 0.0 {
        return Err(ModelError::new(key, format!("must be > 0, got {v}")));
    }
    Ok(())
}

fn finite_vec(key: String, v: &[f64]) -> Result<(), ModelError> {
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(ModelError::new(key, format!("must be finite, got {x}")));
    }
    Ok(())
}

impl Vehicle {
    /// Number of joints `n`.
    pub fn n_joints(&self) -> usize {
        self.joints.len()
    }

    /// Number of generalised velocities `6 + n`.
    pub fn n_dof(&self) -> usize {
        6 + self.joints.len()
    }

    /// Number of thrusters `m`.
    pub fn n_thrusters(&self) -> usize {
        self.thrusters.len()
    }

    /// Total mass [kg].
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// Total length [m]: the sum of the body lengths (the straight chain's extent).
    pub fn total_length(&self) -> f64 {
        self.bodies.iter().map(|b| b.length).sum()
    }

    /// Characteristic length for scaling moments (docs/model.md §6 default: half the vehicle length) [m].
    pub fn characteristic_length(&self) -> f64 {
        0.5 * self.total_length()
    }

    /// Joint limits as `(min, max)` pairs [rad].
    pub fn joint_limits(&self) -> Vec<(f64, f64)> {
        self.joints.iter().map(|j| (j.min, j.max)).collect()
    }

    /// Check every physical requirement; the error names the key path of the first problem.
    /// A flat checklist in the order of the fields (chain shape, fluid, then each body, joint
    /// and thruster), kept in one function on purpose so that it reads as the list of rules.
    pub fn validate(&self) -> Result<(), ModelError> {
        if self.bodies.is_empty() {
            return Err(ModelError::new("body", "a design needs at least one body"));
        }
        if self.joints.len() + 1 != self.bodies.len() {
            return Err(ModelError::new(
                "joint",
                format!(
                    "a chain of {} bodies needs {} joints, got {}",
                    self.bodies.len(),
                    self.bodies.len() - 1,
                    self.joints.len()
                ),
            ));
        }
        finite_pos("fluid.rho".into(), self.fluid.rho)?;
        if !self.fluid.g.is_finite() || self.fluid.g < 0.0 {
            return Err(ModelError::new("fluid.g", "must be finite and >= 0"));
        }
        finite_vec("fluid.current".into(), self.fluid.current.as_slice())?;
        for (i, b) in self.bodies.iter().enumerate() {
            let k = |f: &str| format!("body[{i}].{f}");
            finite_pos(k("mass"), b.mass)?;
            finite_pos(k("length"), b.length)?;
            finite_pos(k("radius"), b.radius)?;
            finite_pos(k("volume"), b.volume)?;
            finite_vec(k("cg"), b.cg.as_slice())?;
            finite_vec(k("cb"), b.cb.as_slice())?;
            finite_vec(k("inertia"), b.inertia.as_slice())?;
            if (b.inertia - b.inertia.transpose()).abs().max() > 1e-9 * b.inertia.abs().max() {
                return Err(ModelError::new(k("inertia"), "must be symmetric"));
            }
            if b.inertia.cholesky().is_none() {
                return Err(ModelError::new(k("inertia"), "must be positive definite"));
            }
            match &b.hydro {
                Hydro::Cylinder {
                    cd_x,
                    cd_y,
                    cd_z,
                    linear_damping,
                    strips,
                    axial_added_mass_ratio,
                    added_mass_scale,
                    lift_slope,
                    lift_every_body: _,
                    hull,
                } => {
                    if let Some(h) = hull {
                        for (name, v) in h.fields() {
                            if !v.is_finite() || v < 0.0 {
                                return Err(ModelError::new(
                                    k(&format!("hydro.{name}")),
                                    format!("must be finite and >= 0, got {v}"),
                                ));
                            }
                        }
                        if h.viscosity <= 0.0 {
                            return Err(ModelError::new(k("hydro.viscosity"), "must be > 0"));
                        }
                    }
                    for (name, v) in [
                        ("cd_x", cd_x),
                        ("cd_y", cd_y),
                        ("cd_z", cd_z),
                        ("added_mass_scale", added_mass_scale),
                        ("lift_slope", lift_slope),
                    ] {
                        if !v.is_finite() || *v < 0.0 {
                            return Err(ModelError::new(
                                k(&format!("hydro.{name}")),
                                format!("must be finite and >= 0, got {v}"),
                            ));
                        }
                    }
                    if linear_damping.iter().any(|d| !d.is_finite() || *d < 0.0) {
                        return Err(ModelError::new(
                            k("hydro.linear_damping"),
                            "entries must be finite and >= 0",
                        ));
                    }
                    if *strips == 0 {
                        return Err(ModelError::new(k("hydro.strips"), "must be >= 1"));
                    }
                    if !axial_added_mass_ratio.is_finite() || *axial_added_mass_ratio < 0.0 {
                        return Err(ModelError::new(
                            k("hydro.axial_added_mass_ratio"),
                            "must be finite and >= 0",
                        ));
                    }
                }
                Hydro::Manoeuvring(m) => {
                    if let Some(key) = m.first_non_finite() {
                        return Err(ModelError::new(
                            k(&format!("hydro.{key}")),
                            "must be finite",
                        ));
                    }
                }
                Hydro::Coefficients {
                    added_mass,
                    linear,
                    quadratic,
                } => {
                    for (name, m) in [
                        ("added_mass", added_mass),
                        ("linear", linear),
                        ("quadratic", quadratic),
                    ] {
                        finite_vec(k(&format!("hydro.{name}")), m.as_slice())?;
                    }
                    if (added_mass - added_mass.transpose()).abs().max()
                        > 1e-9 * added_mass.abs().max().max(1.0)
                    {
                        return Err(ModelError::new(k("hydro.added_mass"), "must be symmetric"));
                    }
                    let ev = added_mass.symmetric_eigenvalues();
                    if ev
                        .iter()
                        .any(|e| !e.is_finite() || *e < -1e-9 * ev.amax().max(1.0))
                    {
                        return Err(ModelError::new(
                            k("hydro.added_mass"),
                            "must be positive semi-definite",
                        ));
                    }
                }
            }
        }
        for (i, j) in self.joints.iter().enumerate() {
            let k = |f: &str| format!("joint[{i}].{f}");
            finite_vec(k("position"), j.placement.p.as_slice())?;
            finite_vec(k("rotation"), j.placement.r.as_slice())?;
            if crate::spatial::orthonormality_error(&j.placement.r) > 1e-9 {
                return Err(ModelError::new(k("rotation"), "is not a rotation matrix"));
            }
            finite_vec(k("axis"), j.axis.as_slice())?;
            if (j.axis.norm() - 1.0).abs() > 1e-9 {
                return Err(ModelError::new(
                    k("axis"),
                    format!("must be a unit vector, has norm {}", j.axis.norm()),
                ));
            }
            if !j.min.is_finite() || !j.max.is_finite() || j.min > j.max {
                return Err(ModelError::new(
                    k("limits"),
                    format!("need finite min <= max, got [{}, {}]", j.min, j.max),
                ));
            }
        }
        for (i, t) in self.thrusters.iter().enumerate() {
            let k = |f: &str| format!("thruster[{i}].{f}");
            if t.body >= self.bodies.len() {
                return Err(ModelError::new(
                    k("body"),
                    format!(
                        "body {} does not exist (the design has {} bodies)",
                        t.body,
                        self.bodies.len()
                    ),
                ));
            }
            finite_vec(k("position"), t.position.as_slice())?;
            finite_vec(k("direction"), t.direction.as_slice())?;
            if (t.direction.norm() - 1.0).abs() > 1e-9 {
                return Err(ModelError::new(
                    k("direction"),
                    format!("must be a unit vector, has norm {}", t.direction.norm()),
                ));
            }
            if !t.u_min.is_finite() || !t.u_max.is_finite() || t.u_min > t.u_max {
                return Err(ModelError::new(
                    k("u_min"),
                    format!("need finite u_min <= u_max, got [{}, {}]", t.u_min, t.u_max),
                ));
            }
            if let Some(tc) = t.time_constant {
                finite_pos(k("time_constant"), tc)?;
            }
            if let Some(r) = t.rate_limit {
                finite_pos(k("rate_limit"), r)?;
            }
        }
        for (key, g) in [("base", &self.base), ("end_effector", &self.end_effector)] {
            finite_vec(format!("{key}.position"), g.p.as_slice())?;
            if crate::spatial::orthonormality_error(&g.r) > 1e-9 {
                return Err(ModelError::new(
                    format!("{key}.rotation"),
                    "is not a rotation matrix",
                ));
            }
        }
        Ok(())
    }
}

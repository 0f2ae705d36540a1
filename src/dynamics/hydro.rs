//! Hydrodynamic and hydrostatic kernels (docs/model.md §2, §4): pure functions of one body's local
//! quantities, MuJoCo style. Every twist is the body's *relative* twist
//! `V_r = V − [R_Iiᵀ ν_c; 0]` (m/s, rad/s) in the body frame (origin at the rear face, x
//! towards the head), and every returned wrench `[f; m]` (N, N·m) acts on the body, in the
//! body frame, with the moment about the body frame's origin.

use super::manoeuvring::ManoeuvringKernel;
use crate::model::{Body, HullDrag, Hydro, Vehicle};
use crate::spatial::{Mat3, Mat6, Vec3, Vec6};

/// Strip-theory drag of a slender cylinder along its body x axis (docs/model.md §2), with the
/// constants folded in once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylinderDrag {
    /// `½ ρ C_d,x π r²` [kg/m]: axial force `−k_axial |u| u`.
    pub k_axial: f64,
    /// `½ ρ C_d,y (2r) Δs` [kg/m]: cross-flow force of one strip along y.
    pub k_strip_y: f64,
    /// `½ ρ C_d,z (2r) Δs` [kg/m]: cross-flow force of one strip along z.
    pub k_strip_z: f64,
    /// Body length `l` [m]; the cylinder spans `x ∈ [0, l]`.
    pub length: f64,
    /// Number of strips `N` (midpoint rule, strip centres at `(k + ½) l / N`).
    pub strips: usize,
    /// The strip width `l / N` [m], derived from `length` and `strips` by [`Self::new`] (so
    /// change those two only through a new kernel).
    ds: f64,
    /// Linear damping `[N·s/m ×3, N·m·s/rad ×3]` on the relative twist at the geometric
    /// centre `(l/2, 0, 0)`.
    pub linear: [f64; 6],
    /// Slender-body lift constant `½ ρ C_Lα π r²` [kg/m] of [`slender_lift`]; 0 = no lift
    /// (the default: then [`Self::wrench`] is bit-identical to the model without lift).
    pub k_lift: f64,
    /// The rear face (`x = 0`) is free: no body is joined behind it (the chain's tail).
    pub free_rear: bool,
    /// The front face (`x = l`) is free: no body is joined in front of it (the chain's head).
    pub free_front: bool,
    /// Hull skin friction `½ρ (1 + k) s_f 2πr l` [kg/m] (docs/model.md §2 "Hull drag"): the
    /// axial force is `−k_friction C_F(Re) |u| u` with the ITTC-57 line [`ittc57`]; 0 = none.
    pub k_friction: f64,
    /// `L/ν` [s/m] of the whole chain: the Reynolds number is `Re = |u| L/ν`.
    pub re_per_speed: f64,
    /// Form drag `½ρ (C_nose A_front + C_base A_rear)` [kg/m] when moving head first
    /// (`u > 0`: the front face leads), `A` the exposed areas of [`HullSite`].
    pub k_form_ahead: f64,
    /// Form drag `½ρ (C_nose A_rear + C_base A_front)` [kg/m] when moving tail first.
    pub k_form_astern: f64,
    /// Appendage drag `½ρ Σ C_D A` [kg/m] of the body's thrusters and rear joint gap.
    pub k_appendage: f64,
}

/// Lowest Reynolds number at which [`ittc57`] is evaluated: below it the line's value at
/// 10⁵ is kept (the line is a turbulent-flow fit, stated for Re ≳ 10⁵; `log₁₀ Re − 2` would
/// vanish at Re = 100). At 10⁵ `C_F` = 0.0083.
pub const ITTC57_RE_MIN: f64 = 1.0e5;

/// The ITTC-57 model-ship correlation line `C_F = 0.075 / (log₁₀ Re − 2)²` (ITTC 1957;
/// ITTC Recommended Procedure 7.5-02-02-02), with `Re` raised to [`ITTC57_RE_MIN`].
#[inline]
pub fn ittc57(re: f64) -> f64 {
    let d = re.max(ITTC57_RE_MIN).log10() - 2.0;
    0.075 / (d * d)
}

/// Hoerner's form factor of a streamlined body of revolution on its skin friction,
/// `1 + 1.5 (d/L)^{3/2} + 7 (d/L)³` (S. F. Hoerner, *Fluid-Dynamic Drag*, 1965, ch. 6),
/// for diameter `d` and length `l` [m].
pub fn hoerner_form_factor(d: f64, l: f64) -> f64 {
    let t = d / l;
    1.0 + 1.5 * t.powf(1.5) + 7.0 * t.powi(3)
}

/// Where one body sits in the hull, read once from the chain when the dynamics are built
/// (docs/model.md §2 "Hull drag"; nothing of it is recomputed per time step).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct HullSite {
    /// No body is joined at the rear face (`x = 0`): the chain's tail.
    pub free_rear: bool,
    /// No body is joined at the front face (`x = l`): the chain's head.
    pub free_front: bool,
    /// Exposed area of the rear face [m²]: `πr²` when free, else the annulus
    /// `π max(0, r² − r_prev²)` a larger body shows behind a smaller one (a diameter step).
    pub rear_area: f64,
    /// Exposed area of the front face [m²], likewise with the next body.
    pub front_area: f64,
    /// The hull's wetted length `L` [m]: the straight chain's length, all bodies.
    pub hull_length: f64,
    /// [`hoerner_form_factor`] of the chain (largest diameter over `L`).
    pub form_factor: f64,
    /// Thrusters on the body pushing along its axis (`|e_x · d| ≥ ½`): external pods.
    pub pods: usize,
    /// The body's other thrusters: tunnels through the hull.
    pub tunnels: usize,
    /// Joint gaps at the body's faces: one per joint at its rear face.
    pub gaps: usize,
}

impl HullSite {
    /// The site of every body of `v`, tail to head.
    pub fn of_chain(v: &Vehicle) -> Vec<HullSite> {
        let nb = v.bodies.len();
        let hull_length = v.total_length();
        let d_max = v.bodies.iter().map(|b| 2.0 * b.radius).fold(0.0, f64::max);
        let form_factor = if hull_length > 0.0 {
            hoerner_form_factor(d_max, hull_length)
        } else {
            1.0
        };
        let pi = std::f64::consts::PI;
        (0..nb)
            .map(|i| {
                let r2 = v.bodies[i].radius.powi(2);
                let exposed = |other: Option<usize>| match other {
                    None => pi * r2,
                    Some(j) => pi * (r2 - v.bodies[j].radius.powi(2)).max(0.0),
                };
                let (pods, tunnels) =
                    v.thrusters
                        .iter()
                        .filter(|t| t.body == i)
                        .fold((0, 0), |(p, t), th| {
                            if th.direction.x.abs() >= 0.5 {
                                (p + 1, t)
                            } else {
                                (p, t + 1)
                            }
                        });
                HullSite {
                    free_rear: i == 0,
                    free_front: i + 1 == nb,
                    rear_area: exposed(i.checked_sub(1)),
                    front_area: exposed((i + 1 < nb).then_some(i + 1)),
                    hull_length,
                    form_factor,
                    pods,
                    tunnels,
                    gaps: usize::from(i > 0),
                }
            })
            .collect()
    }
}

/// Cross-flow lift of a slender blunt-based cylinder (docs/model.md §2 "Lift"), `[N]`, for the
/// relative velocity `v` [m/s] (body frame, x along the axis) of the point it acts at, with
/// `k = ½ ρ C_Lα π r²` [kg/m]:
///
/// `f_L = −k (U v⊥ − (|v⊥|² / U) v)`, `U = |v|`, `v⊥ = (0, v_y, v_z)`,
///
/// i.e. magnitude `½ ρ π r² U² C_L(α)` with `C_L(α) = C_Lα sin α |cos α|` (α the angle between
/// the axis and `v`), direction perpendicular to `v` in the plane of the axis and `v`, on the
/// side that opposes `v⊥` (a fin's lift). At small α this is slender-body theory's
/// `ρ U² π r² α` for `C_Lα = 2` (Munk 1924; the potential term `(S_b/S) sin 2α cos(α/2)` of
/// Jorgensen, NASA TR R-474, 1977). `f_L · v = 0` exactly in real arithmetic: lift does no
/// work. Zero for `v⊥ = 0` (α = 0) and for `U = 0`.
#[inline]
pub fn slender_lift(k: f64, v: &Vec3) -> Vec3 {
    let u2 = v.norm_squared();
    if u2 == 0.0 {
        return Vec3::zeros();
    }
    let big_u = u2.sqrt();
    // U v⊥ − (|v⊥|²/U) v = ((U² − |v⊥|²)/U) v⊥ − (|v⊥|²/U) u e_x = (u²/U) v⊥ − (|v⊥|²/U) u e_x:
    // written so, it is exactly zero at α = 0 (v⊥ = 0) and at α = 90° (u = 0).
    let axial = v.x * v.x / big_u;
    let perp = (v.y * v.y + v.z * v.z) / big_u;
    Vec3::new(k * perp * v.x, -k * axial * v.y, -k * axial * v.z)
}

impl CylinderDrag {
    /// Constants for a cylinder of radius `radius` and length `length` [m] in fluid of
    /// density `rho` [kg/m³]; `strips` is clamped to at least 1.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        rho: f64,
        radius: f64,
        length: f64,
        cd_x: f64,
        cd_y: f64,
        cd_z: f64,
        linear: [f64; 6],
        strips: usize,
    ) -> Self {
        let strips = strips.max(1);
        let ds = length / strips as f64;
        Self {
            k_axial: 0.5 * rho * cd_x * std::f64::consts::PI * radius * radius,
            k_strip_y: 0.5 * rho * cd_y * 2.0 * radius * ds,
            k_strip_z: 0.5 * rho * cd_z * 2.0 * radius * ds,
            length,
            strips,
            ds,
            linear,
            k_lift: 0.0,
            free_rear: false,
            free_front: false,
            k_friction: 0.0,
            re_per_speed: 0.0,
            k_form_ahead: 0.0,
            k_form_astern: 0.0,
            k_appendage: 0.0,
        }
    }

    /// The same cylinder with its share of the hull's axial drag (docs/model.md §2 "Hull
    /// drag") for constants `h` at `site`, in fluid of density `rho`: skin friction on its
    /// side `2πr l` times the chain's form factor, nose and base drag on the exposed areas
    /// of its faces, and the drag areas of its thrusters and joint gap.
    pub fn with_hull(mut self, rho: f64, radius: f64, h: &HullDrag, site: &HullSite) -> Self {
        let q = 0.5 * rho;
        let side = 2.0 * std::f64::consts::PI * radius * self.length;
        self.k_friction = q * h.friction_scale * site.form_factor * side;
        self.re_per_speed = site.hull_length / h.viscosity;
        let (nose, base) = (h.nose_cd * h.form_scale, h.base_cd * h.form_scale);
        self.k_form_ahead = q * (nose * site.front_area + base * site.rear_area);
        self.k_form_astern = q * (nose * site.rear_area + base * site.front_area);
        self.k_appendage = q
            * h.appendage_scale
            * (site.pods as f64 * h.pod_drag_area
                + site.tunnels as f64 * h.tunnel_drag_area
                + site.gaps as f64 * h.gap_drag_area);
        self
    }

    /// The quadratic axial coefficient `k(u)` [kg/m] of the axial force `−k(u) |u| u`: the
    /// per-body `C_d,x` term, the appendages, the form drag of the leading and trailing faces
    /// for the sign of `u`, and the skin friction at `Re = |u| L/ν` (docs/model.md §2).
    #[inline]
    pub fn axial_coefficient(&self, u: f64) -> f64 {
        let form = if u > 0.0 {
            self.k_form_ahead
        } else {
            self.k_form_astern
        };
        let friction = if self.k_friction == 0.0 {
            0.0
        } else {
            self.k_friction * ittc57(u.abs() * self.re_per_speed)
        };
        self.k_axial + self.k_appendage + form + friction
    }

    /// The same cylinder with slender-body lift of slope `lift_slope` = `C_Lα` [1/rad] on
    /// `π r²` (≥ 0; 0 = none), acting at a *free* trailing face only (`free_rear`,
    /// `free_front`: whether no body is joined at `x = 0`, `x = l`); see [`Self::lift`].
    pub fn with_lift(
        mut self,
        rho: f64,
        radius: f64,
        lift_slope: f64,
        free_rear: bool,
        free_front: bool,
    ) -> Self {
        self.k_lift = 0.5 * rho * lift_slope * std::f64::consts::PI * radius * radius;
        self.free_rear = free_rear;
        self.free_front = free_front;
        self
    }

    /// The lift wrench (body frame, moment about the origin) for relative twist `v_r`:
    /// [`slender_lift`] evaluated with the relative velocity of the **trailing face's centre**
    /// `p` (`x = 0` when the axial relative velocity `u > 0`, `x = l` when `u < 0`; none at
    /// `u = 0`, α = 90°, where `C_L = 0`) and applied there, moment `p × f_L`; zero when that
    /// face is not free. Why there: the Kirchhoff term of the added mass already carries the
    /// potential-flow loads of slender-body theory, equal and opposite at the two faces (the
    /// Munk couple); flow separation at a blunt base removes the base's load, and adding
    /// `f_L` at the trailing face is exactly that removal, leaving the net lift at the
    /// leading face as slender-body theory has it (docs/model.md §2 "Lift"). Inner faces of the
    /// chain are joined to the next body, so the flow does not separate there: a straight
    /// chain behaves as one slender body whose only base is its tail.
    #[inline]
    pub fn lift(&self, v_r: &Vec6) -> Vec6 {
        let u = v_r[0];
        let s = if u > 0.0 && self.free_rear {
            0.0
        } else if u < 0.0 && self.free_front {
            self.length
        } else {
            return Vec6::zeros();
        };
        // Velocity of p = (s, 0, 0): v + ω × p = (u, v_y + ω_z s, v_z − ω_y s).
        let vp = Vec3::new(u, v_r[1] + v_r[5] * s, v_r[2] - v_r[4] * s);
        let f = slender_lift(self.k_lift, &vp);
        // p × f = (0, −s f_z, s f_y)
        Vec6::new(f.x, f.y, f.z, 0.0, -s * f.z, s * f.y)
    }

    /// The damping wrench on the body for relative twist `v_r` (docs/model.md §2):
    /// cross-flow `−½ρ C_d,y|z (2r) |v⊥(s)| v⊥(s)` per unit length with
    /// `v⊥(s) = (0, v_y + ω_z s, v_z − ω_y s)` integrated by the midpoint rule (so rotation
    /// makes moments), axial `−½ρ C_d,x πr² |u| u`, linear damping at the centre, and the
    /// [`Self::lift`] wrench when `k_lift ≠ 0`.
    #[inline]
    pub fn wrench(&self, v_r: &Vec6) -> Vec6 {
        let (u, vy, vz) = (v_r[0], v_r[1], v_r[2]);
        let (wx, wy, wz) = (v_r[3], v_r[4], v_r[5]);
        let ds = self.ds;
        let (mut fy, mut fz, mut my, mut mz) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..self.strips {
            let s = (k as f64 + 0.5) * ds;
            let py = vy + wz * s;
            let pz = vz - wy * s;
            let sp = (py * py + pz * pz).sqrt();
            let dfy = -self.k_strip_y * sp * py;
            let dfz = -self.k_strip_z * sp * pz;
            fy += dfy;
            fz += dfz;
            // (s e_x) × (0, dfy, dfz) = (0, −s dfz, s dfy)
            my -= s * dfz;
            mz += s * dfy;
        }
        let fx = -self.axial_coefficient(u) * u.abs() * u;
        // Linear damping on the twist at the centre c = (l/2, 0, 0): v_c = v + ω × c.
        let cx = 0.5 * self.length;
        let d = &self.linear;
        let (ly, lz) = (-d[1] * (vy + wz * cx), -d[2] * (vz - wy * cx));
        let lx = -d[0] * u;
        // Moment about the origin: m_c + c × f_c, c × (lx, ly, lz) = (0, −cx lz, cx ly).
        let w = Vec6::new(
            fx + lx,
            fy + ly,
            fz + lz,
            -d[3] * wx,
            my - d[4] * wy - cx * lz,
            mz - d[5] * wz + cx * ly,
        );
        if self.k_lift == 0.0 {
            w
        } else {
            w + self.lift(v_r)
        }
    }
}

/// Coefficient damping about the body frame origin (docs/model.md §2 `Hydro::Coefficients`):
/// `−(D_l ν_r + D_q (|ν_r| ∘ ν_r))`, `v_r` the relative twist.
#[inline]
pub fn coefficient_damping(d_l: &Mat6, d_q: &Mat6, v_r: &Vec6) -> Vec6 {
    let quad = v_r.component_mul(&v_r.abs());
    -(d_l * v_r + d_q * quad)
}

/// A body's damping model, resolved once from its [`Hydro`] description.
// One per body in a workspace vector: keeping the matrices inline (no Box) is the point.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum DampingKernel {
    /// Strip-theory cylinder drag.
    Cylinder(CylinderDrag),
    /// Linear and quadratic damping matrices.
    Coefficients {
        /// `D_l`.
        linear: Mat6,
        /// `D_q`.
        quadratic: Mat6,
    },
    /// Manoeuvring derivatives of a streamlined hull (NPS AUV II, docs/model.md §8 case 3).
    Manoeuvring(Box<ManoeuvringKernel>),
}

impl DampingKernel {
    /// Resolve the damping model of `body` in fluid of density `rho` [kg/m³] at `site` in
    /// the chain ([`HullSite::of_chain`]): its free faces, where a cylinder's lift
    /// ([`CylinderDrag::lift`]) may act, and what its hull drag
    /// ([`CylinderDrag::with_hull`]) needs.
    pub fn of(body: &Body, rho: f64, site: &HullSite) -> Self {
        let (free_rear, free_front) = (site.free_rear, site.free_front);
        match &body.hydro {
            Hydro::Cylinder {
                cd_x,
                cd_y,
                cd_z,
                linear_damping,
                strips,
                lift_slope,
                lift_every_body,
                hull,
                ..
            } => {
                let c = CylinderDrag::new(
                    rho,
                    body.radius,
                    body.length,
                    *cd_x,
                    *cd_y,
                    *cd_z,
                    *linear_damping,
                    *strips,
                );
                let c = match hull {
                    Some(h) => c.with_hull(rho, body.radius, h, site),
                    None => c,
                };
                DampingKernel::Cylinder(if *lift_slope == 0.0 {
                    c
                } else {
                    let every = *lift_every_body;
                    c.with_lift(
                        rho,
                        body.radius,
                        *lift_slope,
                        free_rear || every,
                        free_front || every,
                    )
                })
            }
            Hydro::Coefficients {
                linear, quadratic, ..
            } => DampingKernel::Coefficients {
                linear: *linear,
                quadratic: *quadratic,
            },
            Hydro::Manoeuvring(m) => {
                DampingKernel::Manoeuvring(Box::new(ManoeuvringKernel::new(m)))
            }
        }
    }

    /// Whether the dynamics add the Kirchhoff term `V_r ×* (M_A V_r)` of the added mass for
    /// this body: yes, except for manoeuvring derivatives whose velocity-product table is
    /// the whole measured hull force (MSS `npsauv.m` has no `C_A`), unless their
    /// [`Manoeuvring::kirchhoff`](crate::model::manoeuvring::Manoeuvring::kirchhoff) asks for
    /// it.
    #[inline]
    pub fn kirchhoff(&self) -> bool {
        match self {
            DampingKernel::Manoeuvring(k) => k.model.kirchhoff,
            _ => true,
        }
    }

    /// The damping wrench for relative twist `v_r` (body frame, about its origin).
    #[inline]
    pub fn wrench(&self, v_r: &Vec6) -> Vec6 {
        match self {
            DampingKernel::Cylinder(c) => c.wrench(v_r),
            DampingKernel::Coefficients { linear, quadratic } => {
                coefficient_damping(linear, quadratic, v_r)
            }
            DampingKernel::Manoeuvring(k) => k.wrench(v_r),
        }
    }
}

/// The damping of a whole vehicle held rigid at its zero joint angles (the straight chain),
/// for checks and reports (`results/drag/`, tests of docs/model.md §2 "Hull drag"): built
/// once, like the dynamics' kernels; not used in the time step.
#[derive(Clone, Debug)]
pub struct RigidDamping {
    kernels: Vec<DampingKernel>,
    /// `g_bi` at `q = 0`: body `i`'s frame in the base frame `F_b`.
    poses: Vec<crate::spatial::Se3>,
}

impl RigidDamping {
    /// The kernels of `v` ([`HullSite::of_chain`], [`DampingKernel::of`]) and its straight
    /// body poses.
    pub fn new(v: &Vehicle) -> Self {
        let ws = crate::kinematics::KinWorkspace::new(v);
        Self {
            kernels: v
                .bodies
                .iter()
                .zip(HullSite::of_chain(v))
                .map(|(b, site)| DampingKernel::of(b, v.fluid.rho, &site))
                .collect(),
            poses: ws.g_b,
        }
    }

    /// The damping wrench on the vehicle [N, N·m], in `F_b` with the moment about its
    /// origin, for the base twist `v_b` relative to the water (in `F_b`) of the rigid
    /// straight vehicle: `Σ_i Ad_{g_bi}⁻ᵀ D_i(Ad_{g_bi}⁻¹ V_b)`.
    pub fn wrench(&self, v_b: &Vec6) -> Vec6 {
        self.kernels
            .iter()
            .zip(&self.poses)
            .map(|(k, g)| g.wrench_to_parent(&k.wrench(&g.twist_to_child(v_b))))
            .sum()
    }
}

/// Hydrostatic parameters of one body (docs/model.md §4 restoring forces).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Restoring {
    /// Weight `m g` [N].
    pub weight: f64,
    /// Buoyancy `ρ V g` [N].
    pub buoyancy: f64,
    /// Centre of gravity in the body frame [m].
    pub cg: Vec3,
    /// Centre of buoyancy in the body frame [m].
    pub cb: Vec3,
}

impl Restoring {
    /// Weight and buoyancy of `body` in fluid of density `rho` [kg/m³] under gravity `g`
    /// [m/s²].
    pub fn of(body: &Body, rho: f64, g: f64) -> Self {
        Self {
            weight: body.mass * g,
            buoyancy: rho * body.volume * g,
            cg: body.cg,
            cb: body.cb,
        }
    }

    /// The restoring wrench on the body (docs/model.md §4, USM-19 `N`): weight `−m g e_z` at the CG
    /// and buoyancy `+ρ V g e_z` at the CB, both along the inertial vertical. `r_ii` is the
    /// body's orientation `R_Ii` (body → inertial).
    #[inline]
    pub fn wrench(&self, r_ii: &Mat3) -> Vec6 {
        // Inertial up e_z in body coordinates: the third row of R_Ii.
        self.wrench_up(&Vec3::new(r_ii[(2, 0)], r_ii[(2, 1)], r_ii[(2, 2)]))
    }

    /// [`Self::wrench`] from the inertial vertical `up = R_Iiᵀ e_z` in body coordinates (the
    /// third row of `R_Ii`) alone.
    #[inline]
    pub fn wrench_up(&self, up: &Vec3) -> Vec6 {
        let up = *up;
        let f_w = up * (-self.weight);
        let f_b = up * self.buoyancy;
        let f = f_w + f_b;
        let m = self.cg.cross(&f_w) + self.cb.cross(&f_b);
        Vec6::new(f.x, f.y, f.z, m.x, m.y, m.z)
    }
}

#[cfg(test)]
#[path = "hydro_tests.rs"]
mod tests;

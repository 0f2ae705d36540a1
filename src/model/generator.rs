//! The parametric USM generator (foundation issue, item 4): `N` links with 2-DOF joint
//! modules between them and a named thruster-placement rule, so that a sweep can vary the
//! link count and move thrusters without hand-writing every body.
//!
//! Body layout for `N` links: `L0 J1 L1 J2 … J(N-1) L(N-1)`, i.e. link `k` is body `2k` and
//! module `k` (between link `k-1` and link `k`) is body `2k-1`. Each module carries a yaw
//! joint (z) at its rear face and a pitch joint (y) at its front face, like `usm-paper`.

use super::error::ModelError;
use super::presets::{face_joint, neutral_body, thruster};
use super::{Fluid, Hydro, Thruster, Vehicle};
use crate::spatial::{Se3, Vec3};
use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// Named thruster-placement rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ThrusterRule {
    /// The paper's 7-thruster pattern generalised: vertical + lateral on link 1, a
    /// longitudinal pair and a vertical on the middle link `⌊N/2⌋`, lateral + vertical on
    /// link `N-2`; at 3 and 4 links the groups that would share the middle link move to the
    /// end links ([`paper_rule_links`]), so no link carries more than the paper's 3. With
    /// [`BodyProfile::Paper`] at `N = 5` this is `usm-paper` (USM Table II).
    Paper,
    /// A lateral and a vertical thruster on every inner link, plus the longitudinal pair on
    /// the middle link.
    Distributed,
    /// Lateral + vertical on the tail and head links, the longitudinal pair on the middle link.
    Ends,
    /// No thrusters from the rule (thrusters may be listed explicitly instead).
    None,
}

impl ThrusterRule {
    /// All rules, for error messages and sweeps.
    pub const ALL: [ThrusterRule; 4] = [
        ThrusterRule::Paper,
        ThrusterRule::Distributed,
        ThrusterRule::Ends,
        ThrusterRule::None,
    ];

    /// The rule's name as written in design and study files.
    pub fn name(&self) -> &'static str {
        match self {
            ThrusterRule::Paper => "paper",
            ThrusterRule::Distributed => "distributed",
            ThrusterRule::Ends => "ends",
            ThrusterRule::None => "none",
        }
    }
}

impl fmt::Display for ThrusterRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A thruster rule name that is none of [`ThrusterRule::ALL`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("unknown thruster rule '{name}'; valid: {}", ThrusterRule::names().join(", "))]
pub struct UnknownThrusterRule {
    /// The name given.
    pub name: String,
}

impl ThrusterRule {
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|r| r.name()).collect()
    }
}

impl FromStr for ThrusterRule {
    type Err = UnknownThrusterRule;
    fn from_str(s: &str) -> Result<Self, UnknownThrusterRule> {
        Self::ALL
            .iter()
            .copied()
            .find(|r| r.name() == s)
            .ok_or_else(|| UnknownThrusterRule { name: s.into() })
    }
}

/// Where the generator takes link lengths and masses from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum BodyProfile {
    /// `link_length` and `link_mass` as given (one value or one per link; masses default to
    /// neutrally buoyant solid cylinders).
    #[default]
    Uniform,
    /// USM Table II (../shared/seeds, docs/model.md §2) generalised to `N` links: the tail link
    /// 0.62 m / 14.3 kg, the head link 0.37 m / 7.8 kg, the middle link `⌊N/2⌋` (the one
    /// carrying the longitudinal pair) 0.726 m / 9.8 kg and every other inner link
    /// 0.584 m / 12.7 kg. At `N = 5` this is Table II exactly (81.3 kg with the four 6 kg
    /// modules, 3.300 m); `link_length` and `link_mass` are ignored.
    Paper,
}

impl BodyProfile {
    /// All profiles, in the order of their names in error messages.
    pub const ALL: [BodyProfile; 2] = [BodyProfile::Uniform, BodyProfile::Paper];

    /// The profile's name as written in design and study files.
    pub fn name(&self) -> &'static str {
        match self {
            BodyProfile::Uniform => "uniform",
            BodyProfile::Paper => "paper",
        }
    }

    /// The profile called `s`, if any.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|p| p.name() == s)
    }
}

/// USM Table II's (length [m], mass [kg]) of link `k` of `n` under [`BodyProfile::Paper`].
fn paper_link(k: usize, n: usize) -> (f64, f64) {
    if k == 0 {
        (0.62, 14.3)
    } else if k == n - 1 {
        (0.37, 7.8)
    } else if k == n / 2 {
        (0.726, 9.8)
    } else {
        (0.584, 12.7)
    }
}

/// The three links the [`ThrusterRule::Paper`] groups go on, `a < b < c`: group A (vertical +
/// lateral) on `a`, group B (longitudinal pair + vertical) on `b = ⌊N/2⌋`, group C (lateral +
/// vertical) on `c`. The paper's links 1 and `N-2` when they differ from `b`, otherwise the tail
/// link 0 and the head link `N-1`: so no link carries more than the paper's per-link count
/// (2, 3, 2). `None` below 3 links (7 thrusters do not fit under that cap on 2 links).
pub fn paper_rule_links(n: usize) -> Option<(usize, usize, usize)> {
    if n < 3 {
        return None;
    }
    let b = n / 2;
    let a = if b > 1 { 1 } else { 0 };
    let c = if n - 2 > b { n - 2 } else { n - 1 };
    Some((a, b, c))
}

/// Parameters of the generator. Defaults follow `usm-paper` (radius 0.085 m, 0.104 m / 6 kg
/// joint modules, ±90° joints, ±40 N thrusters, drag coefficients of USM Table II).
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratorSpec {
    /// Number of links `N` (2 ≤ N ≤ 20; studies use 3–9).
    pub links: usize,
    /// Link lengths [m]: one value for every link, or exactly `N` values.
    pub link_length: Vec<f64>,
    /// Link masses [kg]: empty = neutrally buoyant solid cylinders `ρπr²l`; one value for
    /// every link; or exactly `N` values.
    pub link_mass: Vec<f64>,
    /// Where lengths and masses come from ([`BodyProfile`]); `Paper` overrides the two above.
    pub body_profile: BodyProfile,
    /// Radius of every body [m].
    pub radius: f64,
    /// Joint module length [m].
    pub module_length: f64,
    /// Joint module mass [kg].
    pub module_mass: f64,
    /// Symmetric joint limit [rad].
    pub joint_limit: f64,
    /// Thruster placement rule.
    pub thruster_rule: ThrusterRule,
    /// Symmetric thrust limit [N] of every thruster (the `fixed` propulsion rule).
    pub thrust_limit: f64,
    /// Propulsion sizing rule: when > 0, every thruster's symmetric limit is this many
    /// newtons per kilogram of the design's dry mass (links and joint modules), replacing
    /// `thrust_limit`, so that designs of different length keep one thrust-to-mass ratio
    /// [N/kg]. 0 (the default) = the fixed `thrust_limit`.
    pub thrust_per_kg: f64,
    /// Lateral offset of the longitudinal thruster pair from the body axis [m].
    pub longitudinal_offset: f64,
    /// Per-body axial drag coefficient of the tail and head links (USM Table II: 0.8).
    /// `None` with `cd_axial` `None` (the default): the hull drag of docs/model.md §2. Either
    /// given: every body takes the per-body coefficient form of `Hydro::cylinder` (the other
    /// one defaulting to Table II's value), with its per-body linear damping.
    pub cd_axial_ends: Option<f64>,
    /// Per-body axial drag coefficient of inner links and modules (USM Table II: 0.1); see
    /// `cd_axial_ends`.
    pub cd_axial: Option<f64>,
    /// Cross-flow drag coefficient of every body.
    pub cd_cross: f64,
    /// Metacentric height `GM` [m] of every body: its centre of buoyancy this far above its
    /// centre of gravity (body z). The centre of gravity stays on the body's axis at its
    /// geometric centre (as in `usm-paper`); the centre of buoyancy is raised by `GM`
    /// (buoyancy foam fitted above the axis). Not the other way round: a CG below the axis
    /// couples sway and roll in `M_11`, which transport's base control (USM-33) then commands
    /// as a roll moment that a straight body without roll authority cannot produce (measured
    /// on ends/4: a capsize within 1 s in still water). `|GM|` < the radius; negative is
    /// top-heavy. Default [`DEFAULT_METACENTRIC_HEIGHT`].
    pub metacentric_height: f64,
    /// Trim rule: the design's wet weight `W − B` [N] (positive sinks), spread over the
    /// bodies in proportion to their masses, `V_i = (m_i/ρ)(1 − wet_weight/(g Σ m))`, so
    /// that every body is trimmed alike and the vehicle stays level (no trim moment). Default
    /// 0: neutral, the paper's "wet mass 0" (USM Table II).
    pub wet_weight: f64,
}

/// Default [`GeneratorSpec::metacentric_height`] [m]: the REMUS 100's centre of gravity 2 cm
/// below its centre of buoyancy (Fossen's MSS toolbox `remus100.m`, `r_bg = [0 0 0.02]`, after
/// Prestero 2001, z_G = 1.96 cm), a torpedo AUV of 0.19 m diameter against the USM's 0.17 m.
/// The USM paper states no value (inferred for the USM, docs/assumptions.md).
pub const DEFAULT_METACENTRIC_HEIGHT: f64 = 0.02;

impl Default for GeneratorSpec {
    fn default() -> Self {
        Self {
            links: 5,
            link_length: vec![0.6],
            link_mass: Vec::new(),
            body_profile: BodyProfile::Uniform,
            radius: 0.085,
            module_length: 0.104,
            module_mass: 6.0,
            joint_limit: PI / 2.0,
            thruster_rule: ThrusterRule::Paper,
            thrust_limit: 40.0,
            thrust_per_kg: 0.0,
            longitudinal_offset: 0.10,
            cd_axial_ends: None,
            cd_axial: None,
            cd_cross: 1.0,
            metacentric_height: DEFAULT_METACENTRIC_HEIGHT,
            wet_weight: 0.0,
        }
    }
}

fn per_link(key: &str, v: &[f64], n: usize) -> Result<Vec<f64>, ModelError> {
    match v.len() {
        1 => Ok(vec![v[0]; n]),
        len if len == n => Ok(v.to_vec()),
        len => Err(ModelError::new(
            format!("generator.{key}"),
            format!("needs 1 or {n} values (one per link), got {len}"),
        )),
    }
}

/// Body index of link `k`.
pub fn link_body(k: usize) -> usize {
    2 * k
}

impl GeneratorSpec {
    /// The factor on every body's neutral volume `m_i/ρ` of the trim rule
    /// ([`Self::wet_weight`]) for a design of `dry_mass` [kg] under gravity `g` [m/s²]:
    /// `1 − wet_weight/(g · dry_mass)`; exactly 1 for a neutral design.
    pub fn volume_factor(&self, dry_mass: f64, g: f64) -> f64 {
        if self.wet_weight == 0.0 {
            1.0
        } else {
            1.0 - self.wet_weight / (g * dry_mass)
        }
    }

    /// Apply the hydrostatic rules to freshly built neutral bodies: CB raised by `GM` above
    /// the CG (the geometric centre), volumes scaled by [`Self::volume_factor`].
    fn apply_hydrostatics(&self, bodies: &mut [super::Body], g: f64) -> Result<(), ModelError> {
        let r_min = bodies
            .iter()
            .map(|b| b.radius)
            .fold(f64::INFINITY, f64::min);
        let gm = self.metacentric_height;
        if !gm.is_finite() || gm.abs() >= r_min {
            return Err(ModelError::new(
                "generator.metacentric_height",
                format!(
                    "must be finite with |GM| < the radius {r_min} m (the CB inside the body), got {gm}"
                ),
            ));
        }
        let dry_mass: f64 = bodies.iter().map(|b| b.mass).sum();
        let w = self.wet_weight;
        if !w.is_finite() || w >= g * dry_mass || (w != 0.0 && g <= 0.0) {
            return Err(ModelError::new(
                "generator.wet_weight",
                format!(
                    "must be finite and below the dry weight {} N (a positive displaced \
                     volume), got {w}",
                    g * dry_mass
                ),
            ));
        }
        let factor = self.volume_factor(dry_mass, g);
        for b in bodies.iter_mut() {
            b.cb.z += gm;
            if factor != 1.0 {
                b.volume *= factor;
            }
        }
        Ok(())
    }

    /// The generator's numbers that must be finite and positive (or non-negative), with the
    /// key that is wrong.
    fn check_numbers(&self) -> Result<(), ModelError> {
        for (key, v) in [
            ("radius", self.radius),
            ("module_length", self.module_length),
            ("module_mass", self.module_mass),
            ("joint_limit", self.joint_limit),
        ] {
            if !v.is_finite() || v <= 0.0 {
                return Err(ModelError::new(
                    format!("generator.{key}"),
                    format!("must be a finite number > 0, got {v}"),
                ));
            }
        }
        for (key, v) in [
            ("thrust_limit", self.thrust_limit),
            ("thrust_per_kg", self.thrust_per_kg),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(ModelError::new(
                    format!("generator.{key}"),
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        Ok(())
    }

    /// Build the vehicle (validated).
    pub fn build(&self, name: &str) -> Result<Vehicle, ModelError> {
        let n = self.links;
        if !(2..=20).contains(&n) {
            return Err(ModelError::new(
                "generator.links",
                format!("must be between 2 and 20, got {n}"),
            ));
        }
        if self.thruster_rule == ThrusterRule::Paper && paper_rule_links(n).is_none() {
            return Err(ModelError::new(
                "generator.links",
                format!(
                    "the paper thruster rule needs at least 3 links (7 thrusters, at most 3 on \
                     one link), got {n}"
                ),
            ));
        }
        let (lengths, masses) = match self.body_profile {
            BodyProfile::Paper => (0..n).map(|k| paper_link(k, n)).unzip(),
            BodyProfile::Uniform => {
                let lengths = per_link("link_length", &self.link_length, n)?;
                let masses = if self.link_mass.is_empty() {
                    let r = self.radius;
                    lengths
                        .iter()
                        .map(|l| Fluid::default().rho * PI * r * r * l)
                        .collect()
                } else {
                    per_link("link_mass", &self.link_mass, n)?
                };
                (lengths, masses)
            }
        };
        let fluid = Fluid::default();
        let rho = fluid.rho;
        let r = self.radius;
        self.check_numbers()?;
        // Per-body coefficients when either is given (USM Table II's values by default),
        // else the hull drag (docs/model.md §2 "Hull drag").
        let per_body = (self.cd_axial_ends.is_some() || self.cd_axial.is_some()).then(|| {
            (
                self.cd_axial_ends.unwrap_or(0.8),
                self.cd_axial.unwrap_or(0.1),
            )
        });
        let hydro = |length: f64, end: bool| match per_body {
            Some((ends, inner)) => Hydro::cylinder(if end { ends } else { inner }, self.cd_cross),
            None => Hydro::hull(length, self.cd_cross),
        };
        let mut bodies = Vec::with_capacity(2 * n - 1);
        for k in 0..n {
            if k > 0 {
                bodies.push(neutral_body(
                    &format!("J{k}"),
                    self.module_mass,
                    self.module_length,
                    r,
                    hydro(self.module_length, false),
                    rho,
                ));
            }
            bodies.push(neutral_body(
                &format!("L{k}"),
                masses[k],
                lengths[k],
                r,
                hydro(lengths[k], k == 0 || k == n - 1),
                rho,
            ));
        }
        let mut joints = Vec::with_capacity(2 * (n - 1));
        for (b, parent) in bodies.iter().enumerate().take(bodies.len() - 1) {
            let (axis, kind) = if b % 2 == 0 {
                (Vec3::z(), "yaw")
            } else {
                (Vec3::y(), "pitch")
            };
            joints.push(face_joint(
                &format!("{kind}{}", b / 2 + 1),
                parent.length,
                axis,
                self.joint_limit,
            ));
        }
        self.apply_hydrostatics(&mut bodies, fluid.g)?;
        let dry_mass: f64 = bodies.iter().map(|b| b.mass).sum();
        let limit = if self.thrust_per_kg > 0.0 {
            self.thrust_per_kg * dry_mass
        } else {
            self.thrust_limit
        };
        let v = Vehicle {
            name: name.to_string(),
            bodies,
            joints,
            thrusters: self.rule_thrusters(&lengths, limit),
            base: Se3::identity(),
            end_effector: Se3::from_translation(Vec3::new(lengths[n - 1], 0.0, 0.0)),
            fluid,
        };
        v.validate()?;
        Ok(v)
    }

    fn rule_thrusters(&self, lengths: &[f64], lim: f64) -> Vec<Thruster> {
        let n = lengths.len();
        let (ex, ey, ez) = (Vec3::x(), Vec3::y(), Vec3::z());
        let mid = n / 2;
        let inner_first = 1.min(n - 1);
        let inner_last = n.saturating_sub(2).max(inner_first);
        // Checked in `build`: the paper rule has three distinct links.
        let (ga, gb, gc) = paper_rule_links(n).unwrap_or((0, mid, n - 1));
        let mut out: Vec<Thruster> = Vec::new();
        let mut add = |link: usize, frac: f64, y: f64, dir: Vec3| {
            let name = format!("T{}", out.len() + 1);
            out.push(thruster(
                &name,
                link_body(link),
                frac * lengths[link],
                y,
                dir,
                lim,
            ));
        };
        let pair = |add: &mut dyn FnMut(usize, f64, f64, Vec3), link: usize, frac: f64| {
            add(link, frac, -self.longitudinal_offset, ex);
            add(link, frac, self.longitudinal_offset, ex);
        };
        match self.thruster_rule {
            ThrusterRule::Paper => {
                // Fractions of the link length from the docs/model.md §2 layout on usm-paper:
                // 0.237/0.584, 0.347/0.584, 0.278/0.726, 0.488/0.726.
                let (f1, f2) = (0.237 / 0.584, 0.347 / 0.584);
                add(ga, f1, 0.0, ez);
                add(ga, f2, 0.0, ey);
                pair(&mut add, gb, 0.278 / 0.726);
                add(gb, 0.488 / 0.726, 0.0, ez);
                add(gc, f1, 0.0, ey);
                add(gc, f2, 0.0, ez);
            }
            ThrusterRule::Distributed => {
                for link in inner_first..=inner_last {
                    add(link, 0.35, 0.0, ey);
                    add(link, 0.65, 0.0, ez);
                }
                pair(&mut add, mid, 0.5);
            }
            ThrusterRule::Ends => {
                for link in [0, n - 1] {
                    add(link, 0.4, 0.0, ey);
                    add(link, 0.6, 0.0, ez);
                }
                pair(&mut add, mid, 0.5);
            }
            ThrusterRule::None => {}
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generator_counts() {
        for n in 3..=9 {
            for rule in ThrusterRule::ALL {
                let spec = GeneratorSpec {
                    links: n,
                    thruster_rule: rule,
                    ..Default::default()
                };
                let v = spec.build("g").unwrap();
                assert_eq!(v.bodies.len(), 2 * n - 1);
                assert_eq!(v.n_joints(), 2 * (n - 1));
                match rule {
                    ThrusterRule::Paper => assert_eq!(v.n_thrusters(), 7),
                    ThrusterRule::Ends => assert_eq!(v.n_thrusters(), 6),
                    ThrusterRule::Distributed => assert_eq!(v.n_thrusters(), 2 * (n - 2) + 2),
                    ThrusterRule::None => assert_eq!(v.n_thrusters(), 0),
                }
            }
        }
    }

    #[test]
    fn paper_profile_and_rule_at_five_links_is_usm_paper() {
        // USM Table II: the generated 5-link paper design has the preset's bodies (masses,
        // lengths, inertias) and thrusters (bodies, positions, directions, limits).
        // The preset keeps CB = CG (its inference from "wet mass 0"); with the metacentric
        // height set to 0 the generator gives the same centres, bit for bit.
        let spec = GeneratorSpec {
            body_profile: BodyProfile::Paper,
            metacentric_height: 0.0,
            ..Default::default()
        };
        let g = spec.build("g").unwrap();
        let p = super::super::presets::usm_paper();
        assert_eq!(g.bodies.len(), p.bodies.len());
        for (a, b) in g.bodies.iter().zip(&p.bodies) {
            assert_eq!((a.mass, a.length, a.volume), (b.mass, b.length, b.volume));
            assert_eq!(a.inertia, b.inertia);
            assert_eq!((a.cg, a.cb), (b.cg, b.cb));
        }
        assert!((g.total_mass() - 81.3).abs() < 1e-9);
        assert_eq!(g.thrusters.len(), p.thrusters.len());
        for (a, b) in g.thrusters.iter().zip(&p.thrusters) {
            assert_eq!(a.body, b.body);
            assert!((a.position - b.position).norm() < 1e-12, "{}", a.name);
            assert_eq!(a.direction, b.direction);
            assert_eq!((a.u_min, a.u_max), (b.u_min, b.u_max));
        }
        assert_eq!(g.joints.len(), p.joints.len());
    }

    #[test]
    fn paper_rule_never_stacks_more_than_the_papers_per_link_count() {
        // The paper carries 2, 3, 2 thrusters on links 1, 2, 3; at 3 and 4 links the groups
        // that would share the middle link go to the end links instead.
        for n in 3..=12 {
            let spec = GeneratorSpec {
                links: n,
                ..Default::default()
            };
            let v = spec.build("g").unwrap();
            assert_eq!(v.n_thrusters(), 7);
            let mut per_body = std::collections::BTreeMap::new();
            for t in &v.thrusters {
                *per_body.entry(t.body).or_insert(0) += 1;
            }
            assert_eq!(per_body.len(), 3, "n = {n}: {per_body:?}");
            assert!(per_body.values().all(|&c| c <= 3), "n = {n}: {per_body:?}");
        }
        let three = GeneratorSpec {
            links: 3,
            ..Default::default()
        }
        .build("g")
        .unwrap();
        let bodies: Vec<usize> = three.thrusters.iter().map(|t| t.body).collect();
        assert_eq!(bodies, [0, 0, 2, 2, 2, 4, 4]);
        let two = GeneratorSpec {
            links: 2,
            ..Default::default()
        };
        assert!(two
            .build("g")
            .unwrap_err()
            .to_string()
            .contains("at least 3 links"));
    }

    #[test]
    fn paper_profile_at_other_link_counts() {
        // Tail 0.62, head 0.37, middle 0.726, other inner links 0.584 m.
        let v = GeneratorSpec {
            links: 7,
            body_profile: BodyProfile::Paper,
            ..Default::default()
        }
        .build("g")
        .unwrap();
        let lengths: Vec<f64> = (0..7).map(|k| v.bodies[link_body(k)].length).collect();
        assert_eq!(lengths, [0.62, 0.584, 0.584, 0.726, 0.584, 0.584, 0.37]);
        let masses: f64 = (0..7).map(|k| v.bodies[link_body(k)].mass).sum();
        assert!((masses - (14.3 + 7.8 + 9.8 + 4.0 * 12.7)).abs() < 1e-9);
    }

    #[test]
    fn bad_generator_input() {
        let spec = GeneratorSpec {
            links: 4,
            link_length: vec![0.5, 0.5],
            ..Default::default()
        };
        assert_eq!(spec.build("g").unwrap_err().key, "generator.link_length");
        let spec = GeneratorSpec {
            links: 1,
            ..Default::default()
        };
        assert_eq!(spec.build("g").unwrap_err().key, "generator.links");
        assert!("diagonal".parse::<ThrusterRule>().is_err());
    }

    #[test]
    fn per_mass_propulsion_sizes_every_thruster_by_the_dry_mass() {
        for links in [3, 9] {
            let spec = GeneratorSpec {
                links,
                thrust_per_kg: 0.5,
                ..Default::default()
            };
            let v = spec.build("g").unwrap();
            let lim = 0.5 * v.total_mass();
            for t in &v.thrusters {
                assert_eq!((t.u_min, t.u_max), (-lim, lim));
            }
        }
        let fixed = GeneratorSpec::default().build("g").unwrap();
        assert!(fixed.thrusters.iter().all(|t| t.u_max == 40.0));
        let bad = GeneratorSpec {
            thrust_per_kg: -1.0,
            ..Default::default()
        };
        assert_eq!(bad.build("g").unwrap_err().key, "generator.thrust_per_kg");
    }

    #[test]
    fn hydrostatic_rules_raise_the_cb_and_trim_by_mass() {
        // Default: every body's CB 2 cm above its CG (the geometric centre, on the axis).
        let v = GeneratorSpec::default().build("g").unwrap();
        for b in &v.bodies {
            assert_eq!(b.cg, b.centre());
            assert!((b.cb.z - b.cg.z - DEFAULT_METACENTRIC_HEIGHT).abs() < 1e-15);
            assert!((b.volume * 1026.0 - b.mass).abs() < 1e-12 * b.mass);
        }
        // A wet weight of 5 N spread by mass: each body sinks by its share, no trim moment.
        let spec = GeneratorSpec {
            wet_weight: 5.0,
            ..Default::default()
        };
        let v = spec.build("g").unwrap();
        let total = v.total_mass();
        for b in &v.bodies {
            let wet = b.mass * 9.81 - 1026.0 * b.volume * 9.81;
            assert!((wet - 5.0 * b.mass / total).abs() < 1e-9, "{}", b.name);
        }
        for (gm, key) in [
            (0.1, "generator.metacentric_height"),
            (f64::NAN, "generator.metacentric_height"),
        ] {
            let bad = GeneratorSpec {
                metacentric_height: gm,
                ..Default::default()
            };
            assert_eq!(bad.build("g").unwrap_err().key, key);
        }
        let bad = GeneratorSpec {
            wet_weight: 1e6,
            ..Default::default()
        };
        assert_eq!(bad.build("g").unwrap_err().key, "generator.wet_weight");
    }
}

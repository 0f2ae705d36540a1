//! Attainable authority over joint space (docs/model.md §6, issue 24 items 2 and 3): per joint
//! configuration, the largest force [N] and moment [N·m] the thrusters can deliver along each
//! commanded axis and sign within their limits, about the vehicle's centre of mass (or a declared
//! point), with the other commanded axes held at zero
//! ([`crate::allocation::attainable_authority`]); its distribution over the full joint limits
//! and over a declared mission range; the under-actuated axes; and N−1 (one thruster removed).
//!
//! Forces and moments are never mixed: every "smallest" figure comes in a force (N) and a moment
//! (N·m) version; a single dimensionless figure needs a required wrench ([`weakest_ratio`]).
//!
//! Determinism: configurations are those of the σ analysis (the same sampler, seed and
//! indices), evaluated serially with one solver built from the straight configuration, so every
//! number is a function of the design and the settings only.

use nalgebra::Matrix6xX;
use serde::Serialize;

use super::analysis::{SinkError, StaticError, StaticSpec};
use super::eval::map_joint;
use crate::allocation::{AttainableAuthority, AuthoritySolver};
use crate::kinematics::{centre_of_mass, forward_kinematics, thruster_matrix, KinWorkspace};
use crate::metrics::singularity::{CommandedDofs, AXIS_NAMES};
use crate::model::Vehicle;
use crate::sampling::Sampler;
use crate::spatial::Vec3;

/// Default number of sampled configurations (besides the straight one) at which N−1 is
/// evaluated (`[static] n1_samples`): the first ones of the σ analysis's sequence.
pub const DEFAULT_N1_SAMPLES: usize = 32;

/// An axis counts as unattainable at a configuration when its authority (the smaller sign) is at
/// most this fraction of the largest thrust limit (N, or N·m with the same number).
pub const UNDER_ACTUATED_REL: f64 = 1e-6;

/// The point about which moments are taken (`[static] authority_reference`).
#[derive(Clone, Debug, PartialEq)]
pub enum AuthorityReference {
    /// The vehicle's centre of mass at each configuration (`"com"`, the default).
    Com,
    /// The base frame's origin (`"base"`).
    Base,
    /// A fixed point in the base frame [m] (`[x, y, z]`).
    Point([f64; 3]),
}

impl AuthorityReference {
    /// The point in the base frame [m] at the configuration of `ws`.
    fn point(&self, v: &Vehicle, ws: &KinWorkspace) -> Vec3 {
        match self {
            Self::Com => centre_of_mass(v, ws),
            Self::Base => Vec3::zeros(),
            Self::Point(p) => Vec3::from(*p),
        }
    }
}

impl std::fmt::Display for AuthorityReference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Com => f.write_str("com"),
            Self::Base => f.write_str("base"),
            Self::Point([x, y, z]) => write!(f, "[{x}, {y}, {z}]"),
        }
    }
}

/// A declared mission distribution in joint space: uniform within these ranges, each
/// intersected with the joint's limits.
#[derive(Clone, Debug, PartialEq)]
pub enum JointRanges {
    /// `±r` [rad] on every joint (`[static] joint_range = r`).
    Symmetric(f64),
    /// `[lo, hi]` [rad] per joint, in joint order (`[static] joint_ranges`).
    PerJoint(Vec<[f64; 2]>),
}

impl JointRanges {
    /// The ranges of `v`'s joints, intersected with their limits.
    fn resolve(&self, v: &Vehicle) -> Result<Vec<(f64, f64)>, StaticError> {
        let bad = |key, message| Err(StaticError::Setting { key, message });
        let raw: Vec<[f64; 2]> = match self {
            Self::Symmetric(r) => vec![[-r, *r]; v.n_joints()],
            Self::PerJoint(r) if r.len() != v.n_joints() => {
                return bad(
                    "joint_ranges",
                    format!("has {} ranges, the design {} joints", r.len(), v.n_joints()),
                )
            }
            Self::PerJoint(r) => r.clone(),
        };
        let mut out = Vec::with_capacity(raw.len());
        for (k, ([lo, hi], j)) in raw.iter().zip(&v.joints).enumerate() {
            let (a, b) = (lo.max(j.min), hi.min(j.max));
            if a > b || a.is_nan() || b.is_nan() {
                return bad(
                    "joint_ranges",
                    format!(
                        "joint {k}: [{lo}, {hi}] rad does not meet its limits [{}, {}]",
                        j.min, j.max
                    ),
                );
            }
            out.push((a, b));
        }
        Ok(out)
    }

    /// Check the values (finite, `r ≥ 0`, `lo ≤ hi`); the error names the key.
    pub fn validate(&self) -> Result<(), StaticError> {
        let bad = |key, message| Err(StaticError::Setting { key, message });
        match self {
            Self::Symmetric(r) if !(r.is_finite() && *r >= 0.0) => bad(
                "joint_range",
                format!("must be finite and >= 0 (rad), got {r}"),
            ),
            Self::PerJoint(r) => match r
                .iter()
                .position(|[a, b]| !(a.is_finite() && b.is_finite() && a <= b))
            {
                Some(k) => bad(
                    "joint_ranges",
                    format!("range {k} must be finite [lo, hi] with lo <= hi (rad)"),
                ),
                None => Ok(()),
            },
            _ => Ok(()),
        }
    }
}

/// Settings of the authority analysis beside the [`StaticSpec`] (`[static]` keys
/// `authority_reference`, `joint_range` / `joint_ranges`, `n1_samples`).
#[derive(Clone, Debug, PartialEq)]
pub struct AuthoritySpec {
    /// The point about which moments are taken (default [`AuthorityReference::Com`]).
    pub reference: AuthorityReference,
    /// A declared mission range; `None` (the default): only the full joint limits.
    pub mission: Option<JointRanges>,
    /// Sampled configurations at which N−1 is evaluated besides the straight one (at most the
    /// static analysis's samples; default [`DEFAULT_N1_SAMPLES`]).
    pub n1_samples: usize,
}

impl Default for AuthoritySpec {
    fn default() -> Self {
        Self {
            reference: AuthorityReference::Com,
            mission: None,
            n1_samples: DEFAULT_N1_SAMPLES,
        }
    }
}

/// The authority over a set of joint configurations.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AuthorityStats {
    /// Number of configurations.
    pub samples: usize,
    /// Per axis and sign, the smallest authority over the configurations (N, N·m; NaN for an
    /// uncommanded axis).
    pub min: AttainableAuthority,
    /// Per axis and sign, the median authority.
    pub median: AttainableAuthority,
    /// The smallest commanded force over axes, signs and configurations [N] (NaN: none
    /// commanded).
    pub min_force: f64,
    /// The smallest commanded moment over axes, signs and configurations [N·m].
    pub min_moment: f64,
    /// The commanded axes unattainable (authority ≤ [`UNDER_ACTUATED_REL`] × the largest thrust
    /// limit, either sign, NaN counting as none) at every configuration.
    pub under_actuated_axes: Vec<&'static str>,
}

/// One thruster removed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct N1Thruster {
    /// Thruster index (0-based).
    pub index: usize,
    /// Thruster name.
    pub name: String,
    /// The authority with it removed at the straight configuration.
    pub straight: AttainableAuthority,
    /// The smallest commanded force with it removed over the N−1 configurations [N].
    pub min_force: f64,
    /// The smallest commanded moment with it removed over the N−1 configurations [N·m].
    pub min_moment: f64,
    /// The largest fraction of authority lost over the N−1 configurations, commanded axes and
    /// signs: `1 − a_without / a_with` where `a_with` is above the under-actuation tolerance
    /// (0 when nothing can be lost).
    pub loss: f64,
    /// The axis of that largest loss (`surge` … `yaw`; `none` when nothing is lost).
    pub loss_axis: &'static str,
}

/// N−1 over the straight configuration and the first [`AuthoritySpec::n1_samples`] samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct N1Summary {
    /// Configurations evaluated (the straight one included).
    pub samples: usize,
    /// Per thruster.
    pub thrusters: Vec<N1Thruster>,
    /// The thruster whose removal loses the largest fraction (ties: the lowest index).
    pub worst_thruster: usize,
    /// The axis of that loss.
    pub worst_axis: &'static str,
    /// The smallest force over thrusters removed [N].
    pub worst_force: f64,
    /// The smallest moment over thrusters removed [N·m].
    pub worst_moment: f64,
    /// The mean over thrusters removed of their smallest force [N].
    pub mean_force: f64,
    /// The mean over thrusters removed of their smallest moment [N·m].
    pub mean_moment: f64,
}

/// Result of [`authority_analysis`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AuthoritySummary {
    /// The reference point (`com`, `base`, `[x, y, z]`).
    pub reference: String,
    /// The commanded axes (`surge+sway+heave+pitch+yaw`).
    pub commanded_axes: String,
    /// The under-actuation tolerance used [N or N·m].
    pub tolerance: f64,
    /// The reference point at the straight configuration, base frame [m].
    pub straight_reference: [f64; 3],
    /// The authority at the straight configuration.
    pub straight: AttainableAuthority,
    /// Its smallest commanded force [N].
    pub straight_min_force: f64,
    /// Its smallest commanded moment [N·m].
    pub straight_min_moment: f64,
    /// Over the full joint limits (the σ analysis's samples).
    pub full: AuthorityStats,
    /// Over the declared mission range, when one is declared (the same unit-cube points).
    pub mission: Option<AuthorityStats>,
    /// Whether a commanded axis is unattainable everywhere in the full limits.
    pub under_actuated: bool,
    /// Bit `k` set when axis `k` (surge = 0 … yaw = 5) is unattainable everywhere.
    pub under_actuated_mask: u32,
    /// One thruster removed.
    pub n1: N1Summary,
}

/// One reusable evaluator: kinematics, `T`, the reference point, the solver.
struct Evaluator<'a> {
    v: &'a Vehicle,
    reference: &'a AuthorityReference,
    ws: KinWorkspace,
    t: Matrix6xX<f64>,
    solver: AuthoritySolver,
}

impl<'a> Evaluator<'a> {
    /// Built from the straight configuration (which fixes the solver's equilibration).
    fn new(
        v: &'a Vehicle,
        commanded: CommandedDofs,
        reference: &'a AuthorityReference,
    ) -> Result<Self, StaticError> {
        let ws = KinWorkspace::new(v);
        let mut t = Matrix6xX::zeros(v.n_thrusters());
        thruster_matrix(v, &ws, &mut t);
        let (lo, hi) = bounds(v);
        let r = reference.point(v, &ws);
        let solver = AuthoritySolver::new(&t, &lo, &hi, commanded.mask(), &r).map_err(|e| {
            StaticError::Setting {
                key: "authority",
                message: format!("design `{}`: {e}", v.name),
            }
        })?;
        Ok(Self {
            v,
            reference,
            ws,
            t,
            solver,
        })
    }

    /// The authority at `q` [rad] and the reference point used.
    fn at(&mut self, q: &[f64]) -> (AttainableAuthority, Vec3) {
        forward_kinematics(self.v, q, &mut self.ws);
        thruster_matrix(self.v, &self.ws, &mut self.t);
        let r = self.reference.point(self.v, &self.ws);
        let a = self
            .solver
            .solve(&self.t, &r)
            .unwrap_or(AttainableAuthority::NAN);
        (a, r)
    }
}

/// The thrust bounds of `v` [N].
fn bounds(v: &Vehicle) -> (Vec<f64>, Vec<f64>) {
    v.thrusters.iter().map(|t| (t.u_min, t.u_max)).unzip()
}

/// The under-actuation tolerance of `v`: [`UNDER_ACTUATED_REL`] × its largest thrust limit.
pub fn tolerance(v: &Vehicle) -> f64 {
    let scale = v
        .thrusters
        .iter()
        .map(|t| t.u_min.abs().max(t.u_max.abs()))
        .fold(0.0, f64::max);
    UNDER_ACTUATED_REL * scale
}

/// Per-configuration authorities folded into [`AuthorityStats`].
struct StatsTally {
    commanded: CommandedDofs,
    tol: f64,
    values: Vec<[f64; 12]>,
    attained: [bool; 6],
}

impl StatsTally {
    fn new(commanded: CommandedDofs, tol: f64, n: usize) -> Self {
        Self {
            commanded,
            tol,
            values: Vec::with_capacity(n),
            attained: [false; 6],
        }
    }

    fn add(&mut self, a: &AttainableAuthority) {
        let mut row = [f64::NAN; 12];
        row[..6].copy_from_slice(&a.positive);
        row[6..].copy_from_slice(&a.negative);
        self.values.push(row);
        for (k, hit) in self.attained.iter_mut().enumerate() {
            *hit |= a.along(k) > self.tol;
        }
    }

    fn finish(self) -> AuthorityStats {
        let mut min = AttainableAuthority::NAN;
        let mut median = AttainableAuthority::NAN;
        let mask = self.commanded.mask();
        for c in (0..12).filter(|c| mask[c % 6]) {
            let mut col: Vec<f64> = self.values.iter().map(|r| r[c]).collect();
            col.sort_unstable_by(f64::total_cmp);
            let lo = if col.iter().any(|x| x.is_nan()) {
                f64::NAN
            } else {
                col.first().copied().unwrap_or(f64::NAN)
            };
            let mid = super::dist::quantile_sorted(&col, 0.5);
            let (m, d) = if c < 6 {
                (&mut min.positive[c], &mut median.positive[c])
            } else {
                (&mut min.negative[c - 6], &mut median.negative[c - 6])
            };
            (*m, *d) = (lo, mid);
        }
        let under = (0..6)
            .filter(|&k| mask[k] && !self.attained[k])
            .map(|k| AXIS_NAMES[k])
            .collect();
        AuthorityStats {
            samples: self.values.len(),
            min,
            median,
            min_force: min.min_force(mask),
            min_moment: min.min_moment(mask),
            under_actuated_axes: under,
        }
    }
}

/// The authority of `vehicle` over explicit joint configurations (each `n_joints` angles [rad],
/// e.g. a run's logged joint angles), about `reference`, for the `commanded` axes.
pub fn authority_over<Q: AsRef<[f64]>>(
    vehicle: &Vehicle,
    commanded: CommandedDofs,
    reference: &AuthorityReference,
    configs: impl IntoIterator<Item = Q>,
) -> Result<AuthorityStats, StaticError> {
    let mut ev = Evaluator::new(vehicle, commanded, reference)?;
    let mut tally = StatsTally::new(commanded, tolerance(vehicle), 0);
    for (i, q) in configs.into_iter().enumerate() {
        let q = q.as_ref();
        if q.len() != vehicle.n_joints() || q.iter().any(|x| !x.is_finite()) {
            return Err(StaticError::Setting {
                key: "joint configuration",
                message: format!(
                    "{i}: needs {} finite angles (rad), got {:?}",
                    vehicle.n_joints(),
                    q
                ),
            });
        }
        tally.add(&ev.at(q).0);
    }
    Ok(tally.finish())
}

/// The authority at one configuration `q` [rad] about `reference`, with N−1 there: the
/// authority, the reference point (base frame [m]) and N−1 over this one configuration (the
/// `inspect` report).
pub fn authority_at(
    vehicle: &Vehicle,
    commanded: CommandedDofs,
    reference: &AuthorityReference,
    q: &[f64],
) -> Result<(AttainableAuthority, [f64; 3], N1Summary), StaticError> {
    if q.len() != vehicle.n_joints() || q.iter().any(|x| !x.is_finite()) {
        return Err(StaticError::Setting {
            key: "joint configuration",
            message: format!("needs {} finite angles (rad)", vehicle.n_joints()),
        });
    }
    let mut ev = Evaluator::new(vehicle, commanded, reference)?;
    let (a, r) = ev.at(q);
    let mut n1 = N1Tally::new(vehicle.n_thrusters(), commanded, tolerance(vehicle));
    n1.add(&a, &mut ev.solver);
    Ok((a, [r.x, r.y, r.z], n1.finish(vehicle)))
}

/// The smallest ratio of attainable to required authority over the
/// commanded axes with a positive requirement `required` (surge … yaw, N and N·m, a magnitude
/// asked in both signs): `≥ 1` when every requirement is met. NaN when nothing is required.
pub fn weakest_ratio(
    a: &AttainableAuthority,
    commanded: CommandedDofs,
    required: &[f64; 6],
) -> f64 {
    let mut out = f64::NAN;
    for k in (0..6).filter(|&k| commanded.contains(k) && required[k] > 0.0) {
        let r = a.along(k) / required[k];
        out = if out.is_nan() { r } else { out.min(r) };
    }
    out
}

/// The authority analysis of `vehicle` (docs/model.md §6): the configurations of `spec` (its
/// sampler, seed and sample count within the joint limits, and the same unit-cube points in
/// `auth.mission` when declared), the straight configuration, and N−1. `check` is called once
/// per configuration (a deadline); its error stops the analysis as [`StaticError::Sink`].
pub fn authority_analysis(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    auth: &AuthoritySpec,
    check: &mut dyn FnMut() -> Result<(), SinkError>,
) -> Result<AuthoritySummary, StaticError> {
    spec.validate()?;
    let mission = match &auth.mission {
        Some(m) => {
            m.validate()?;
            Some(m.resolve(vehicle)?)
        }
        None => None,
    };
    let commanded = spec.commanded;
    let mask = commanded.mask();
    let tol = tolerance(vehicle);
    let mut ev = Evaluator::new(vehicle, commanded, &auth.reference)?;
    let n = vehicle.n_joints();
    let sampler =
        Sampler::new(spec.sampling, spec.samples, n, spec.seed).map_err(StaticError::Sampler)?;
    let mut n1 = N1Tally::new(vehicle.n_thrusters(), commanded, tol);
    let q0 = vec![0.0; n];
    let (straight, r0) = ev.at(&q0);
    n1.add(&straight, &mut ev.solver);
    let mut full = StatsTally::new(commanded, tol, spec.samples);
    let mut miss = mission
        .as_ref()
        .map(|_| StatsTally::new(commanded, tol, spec.samples));
    let (mut u, mut q) = (vec![0.0; n], vec![0.0; n]);
    for i in 0..spec.samples {
        check().map_err(StaticError::Sink)?;
        sampler.point(i, &mut u);
        map_joint(vehicle, &u, &mut q);
        let (a, _) = ev.at(&q);
        full.add(&a);
        if i < auth.n1_samples {
            n1.add(&a, &mut ev.solver);
        }
        if let (Some(ranges), Some(t)) = (&mission, miss.as_mut()) {
            for ((qk, uk), (lo, hi)) in q.iter_mut().zip(&u).zip(ranges) {
                *qk = lo + uk * (hi - lo);
            }
            t.add(&ev.at(&q).0);
        }
    }
    let full = full.finish();
    let under_mask = (0..6)
        .filter(|&k| full.under_actuated_axes.contains(&AXIS_NAMES[k]))
        .fold(0u32, |m, k| m | (1 << k));
    Ok(AuthoritySummary {
        reference: auth.reference.to_string(),
        commanded_axes: commanded.label(),
        tolerance: tol,
        straight_reference: [r0.x, r0.y, r0.z],
        straight,
        straight_min_force: straight.min_force(mask),
        straight_min_moment: straight.min_moment(mask),
        under_actuated: under_mask != 0,
        under_actuated_mask: under_mask,
        full,
        mission: miss.map(StatsTally::finish),
        n1: n1.finish(vehicle),
    })
}

/// N−1 over the configurations handed to it (after the solver solved each with every thruster).
struct N1Tally {
    commanded: CommandedDofs,
    tol: f64,
    samples: usize,
    straight: Vec<AttainableAuthority>,
    force: Vec<f64>,
    moment: Vec<f64>,
    loss: Vec<(f64, &'static str)>,
}

impl N1Tally {
    fn new(n_thrusters: usize, commanded: CommandedDofs, tol: f64) -> Self {
        Self {
            commanded,
            tol,
            samples: 0,
            straight: Vec::with_capacity(n_thrusters),
            force: vec![f64::INFINITY; n_thrusters],
            moment: vec![f64::INFINITY; n_thrusters],
            loss: vec![(0.0, "none"); n_thrusters],
        }
    }

    /// Thruster by thruster removed at the configuration `solver` last solved (`full`).
    fn add(&mut self, full: &AttainableAuthority, solver: &mut AuthoritySolver) {
        let mask = self.commanded.mask();
        for i in 0..self.force.len() {
            let a = solver.solve_without(i);
            if self.samples == 0 {
                self.straight.push(a);
            }
            self.force[i] = nan_min(self.force[i], a.min_force(mask));
            self.moment[i] = nan_min(self.moment[i], a.min_moment(mask));
            for k in (0..6).filter(|&k| mask[k]) {
                for (with, without) in [
                    (full.positive[k], a.positive[k]),
                    (full.negative[k], a.negative[k]),
                ] {
                    if with > self.tol {
                        // NaN (a failed programme) counts as nothing left: `max` drops it.
                        let lost = (1.0 - without.max(0.0) / with).clamp(0.0, 1.0);
                        if lost > self.loss[i].0 {
                            self.loss[i] = (lost, AXIS_NAMES[k]);
                        }
                    }
                }
            }
        }
        self.samples += 1;
    }

    fn finish(self, v: &Vehicle) -> N1Summary {
        let n = self.force.len();
        let worst = (0..n).fold(0, |w, i| {
            if self.loss[i].0 > self.loss[w].0 {
                i
            } else {
                w
            }
        });
        let fold_min = |x: &[f64]| x.iter().copied().fold(f64::INFINITY, nan_min);
        let mean = |x: &[f64]| x.iter().sum::<f64>() / n as f64;
        let finite = |x: f64| if x == f64::INFINITY { f64::NAN } else { x };
        N1Summary {
            samples: self.samples,
            worst_thruster: worst,
            worst_axis: self.loss.get(worst).map_or("none", |l| l.1),
            worst_force: finite(fold_min(&self.force)),
            worst_moment: finite(fold_min(&self.moment)),
            mean_force: finite(mean(&self.force)),
            mean_moment: finite(mean(&self.moment)),
            thrusters: (0..n)
                .map(|i| N1Thruster {
                    index: i,
                    name: v.thrusters[i].name.clone(),
                    straight: self.straight[i],
                    min_force: finite(self.force[i]),
                    min_moment: finite(self.moment[i]),
                    loss: self.loss[i].0,
                    loss_axis: self.loss[i].1,
                })
                .collect(),
        }
    }
}

/// `min(a, b)` with NaN winning.
fn nan_min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

#[cfg(test)]
#[path = "authority_tests.rs"]
mod tests;

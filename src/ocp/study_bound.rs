//! The optimal-control bound of every case of a study with `[ocp]` (issue 41, docs/ocp.md §6),
//! wired into the sweep through [`HOOK`] (`crate::batch::bound_hook`): the case's design on
//! the section's straight transport leg ([`super::bound::leg_problem`]: thrusts and joint
//! torques as controls, full hydrodynamics, from rest to rest), solved from `starts` starts
//! ([`super::bound::solve_bound`]), the best local optimum's energy written into the row.
//!
//! The bound depends on the design and the leg only, never on the controller's gains: the
//! cases of one design (its `design_hash`) share one solve, cached for the sweep. Two workers
//! that meet one design at once wait for one solve; the numbers are the same whichever
//! computes them (each solve is sequential and seeded), so the tables do not depend on the
//! thread count.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use super::bound::{leg_problem, solve_bound, LegSpec};
use super::sqp::Status;
use crate::batch::bound_hook::{BoundHook, CaseBound};
use crate::evaluate::Metrics;
use crate::model::design::parse_design_table;
use crate::study::cases::Resolved;
use crate::study::ocp_section::OcpSection;
use crate::study::schema::{
    Study, OCP_ENERGY, OCP_ENERGY_PER_METRE, OCP_ITERATIONS, OCP_KKT, OCP_PRIMAL, OCP_SPREAD,
    OCP_STATUS,
};

/// The hook wiring this solver into sweeps.
pub const HOOK: BoundHook = BoundHook(boxed);

fn boxed(study: &Study) -> Option<Box<dyn CaseBound>> {
    study
        .ocp
        .as_ref()
        .map(|s| Box::new(StudyBound::new(s, study.seed)) as Box<dyn CaseBound>)
}

/// The columns of one design's bound, in [`crate::study::schema::OCP_COLUMNS`] order (without
/// `controller_efficiency`, which needs the case's closed loop).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundColumns {
    /// `thruster_energy_static + joint_energy` of the best start [J].
    pub energy: f64,
    /// The same per metre of the leg [J/m].
    pub energy_per_metre: f64,
    /// Spread of the converged starts' objectives.
    pub spread: f64,
    /// Status code (0 converged, 1 max iterations, 2 stalled, 3 infeasible, 4 diverged).
    pub status: f64,
    /// Largest KKT residual of the best start.
    pub kkt: f64,
    /// Primal residual of the best start.
    pub primal: f64,
    /// SQP iterations of every start.
    pub iterations: f64,
}

impl BoundColumns {
    /// Every column NaN (a design the leg cannot be posed on).
    const NAN: BoundColumns = BoundColumns {
        energy: f64::NAN,
        energy_per_metre: f64::NAN,
        spread: f64::NAN,
        status: f64::NAN,
        kkt: f64::NAN,
        primal: f64::NAN,
        iterations: f64::NAN,
    };
}

/// The status code of `s` in the `ocp_status` column.
pub fn status_code(s: Status) -> f64 {
    match s {
        Status::Converged => 0.0,
        Status::MaxIterations => 1.0,
        Status::Stalled => 2.0,
        Status::Infeasible => 3.0,
        Status::Diverged => 4.0,
    }
}

/// The leg of `section` as the bound's [`LegSpec`], the starts seeded by the study seed.
pub fn leg_of(section: &OcpSection, seed: u64) -> LegSpec {
    LegSpec {
        distance: section.distance,
        duration: section.duration,
        knots: section.knots,
        substeps: section.substeps,
        current: section.current,
        joint_torque: section.joint_torque,
        effort: section.effort,
        starts: section.starts,
        seed,
        tolerance: section.tolerance,
        max_iterations: section.max_iterations,
        ..LegSpec::default()
    }
}

/// The bound of the design table `design` on `leg` (NaN columns when it does not build or has
/// no thrusters).
pub fn design_bound(design: &toml::Table, leg: &LegSpec) -> BoundColumns {
    let Ok(vehicle) = parse_design_table(design, "case design") else {
        return BoundColumns::NAN;
    };
    if vehicle.n_thrusters() == 0 {
        return BoundColumns::NAN;
    }
    let b = solve_bound(&leg_problem(&vehicle, leg), None);
    let energy = b.thruster_energy_static + b.joint_energy;
    BoundColumns {
        energy,
        energy_per_metre: energy / leg.distance,
        spread: b.spread,
        status: status_code(b.status),
        kkt: b.kkt.iter().copied().fold(0.0, f64::max),
        primal: b.kkt[0],
        iterations: b.iterations as f64,
    }
}

/// A study's bound solver: the leg, and one solve per design for the whole sweep.
pub struct StudyBound {
    leg: LegSpec,
    cache: Mutex<HashMap<String, Arc<OnceLock<BoundColumns>>>>,
}

impl StudyBound {
    /// The solver of `section`, its perturbed starts seeded by `seed`.
    pub fn new(section: &OcpSection, seed: u64) -> Self {
        Self {
            leg: leg_of(section, seed),
            cache: Mutex::new(HashMap::new()),
        }
    }

    /// The bound of `r`'s design, solved once per design hash.
    pub fn columns(&self, r: &Resolved) -> BoundColumns {
        let cell = {
            let mut c = self.cache.lock().unwrap_or_else(|p| p.into_inner());
            c.entry(r.design_hash.clone()).or_default().clone()
        };
        *cell.get_or_init(|| design_bound(&r.design, &self.leg))
    }
}

impl CaseBound for StudyBound {
    fn bound(&self, _study: &Study, r: &Resolved, metrics: &mut Metrics) {
        let b = self.columns(r);
        metrics.set(OCP_ENERGY, b.energy);
        metrics.set(OCP_ENERGY_PER_METRE, b.energy_per_metre);
        metrics.set(OCP_SPREAD, b.spread);
        metrics.set(OCP_STATUS, b.status);
        metrics.set(OCP_KKT, b.kkt);
        metrics.set(OCP_PRIMAL, b.primal);
        metrics.set(OCP_ITERATIONS, b.iterations);
    }
}

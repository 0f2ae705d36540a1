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
//!
//! The bound's vehicle is the case's plant in the nominal world
//! ([`crate::scenario::ScenarioFile::world_vehicle`]: payload, `[hydro]` scales, derating). With
//! `[ocp] worlds = K` the design's bound is also solved in the study's first K scoring worlds
//! (the `[uncertainty]` sample every case meets): the world's overrides applied to the case's
//! tables as the closed loop's worlds apply them, the plant that world makes, and the world's
//! current change added to the leg's; each warm-started from the nominal optimum (one start:
//! cold, a world's leg did not converge in 300 iterations where warm it converged in 39).
//! Columns [`OCP_WORLD_COLUMNS`]: the least and greatest feasible bound per metre over those
//! worlds, how many were feasible, and their iterations. A design without a nominal bound that
//! counts (feasible, trusted on its grid) has none to start the worlds from: they are not
//! tried (0 feasible, 0 iterations).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use super::bound::{leg_problem, solve_bound, LegSpec};
use super::sqp::Status;
use crate::batch::bound_hook::{BoundHook, CaseBound};
use crate::evaluate::{apply_overrides, Metrics, Override};
use crate::model::design::parse_design_table;
use crate::model::Vehicle;
use crate::study::cases::{overrides_of, Resolved};
use crate::study::ocp_section::OcpSection;
use crate::study::schema::{
    Study, OCP_ENERGY, OCP_ENERGY_PER_METRE, OCP_ITERATIONS, OCP_KKT, OCP_PRIMAL, OCP_SPREAD,
    OCP_STATUS, OCP_WORK_ERROR, OCP_WORLD_FEASIBLE, OCP_WORLD_GRID_REJECTED, OCP_WORLD_ITERATIONS,
    OCP_WORLD_MAX, OCP_WORLD_MIN,
};

/// The hook wiring this solver into sweeps.
pub const HOOK: BoundHook = BoundHook(boxed);

fn boxed(study: &Study) -> Option<Box<dyn CaseBound>> {
    study
        .ocp
        .as_ref()
        .map(|s| Box::new(StudyBound::new(s, study)) as Box<dyn CaseBound>)
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
    /// Work-balance error of the best start on its grid.
    pub work_error: f64,
    /// SQP iterations of every start.
    pub iterations: f64,
    /// Least feasible bound per metre over the bound's worlds [J/m] (NaN: none feasible).
    pub world_min: f64,
    /// Greatest feasible bound per metre over the bound's worlds [J/m].
    pub world_max: f64,
    /// Worlds whose bound is primal feasible.
    pub world_feasible: f64,
    /// SQP iterations of every world together.
    pub world_iterations: f64,
    /// Worlds ending primal feasible whose energy the grid supplied (work error above
    /// [`crate::study::schema::OCP_WORK_TRUSTED`]): rejected.
    pub world_grid_rejected: f64,
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
        work_error: f64::NAN,
        iterations: f64::NAN,
        world_min: f64::NAN,
        world_max: f64::NAN,
        world_feasible: f64::NAN,
        world_iterations: f64::NAN,
        world_grid_rejected: f64::NAN,
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

/// The plant of a case's tables `design` and `scenario` with `overrides` applied (a world's;
/// none for the nominal one), as the closed loop builds it: `None` when they do not apply or
/// the design does not build.
fn plant(design: &toml::Table, scenario: &toml::Table, overrides: &[Override]) -> Option<Vehicle> {
    let (mut d, mut s) = (design.clone(), scenario.clone());
    apply_overrides(&mut d, &mut s, overrides).ok()?;
    let vehicle = parse_design_table(&d, "case design").ok()?;
    let file =
        crate::scenario::parse_table(&s, &crate::scenario::Source::unplaced("scenario")).ok()?;
    file.world_vehicle(&vehicle).ok()
}

/// The bound of the case tables `design`, `scenario` on `leg` in the nominal world and in the
/// worlds `worlds` (their overrides; NaN columns when the design does not build or has no
/// thrusters).
pub fn design_bound(
    design: &toml::Table,
    scenario: &toml::Table,
    leg: &LegSpec,
    worlds: &[Vec<Override>],
    world_substeps: usize,
) -> BoundColumns {
    let Some(vehicle) = plant(design, scenario, &[]) else {
        return BoundColumns::NAN;
    };
    if vehicle.n_thrusters() == 0 {
        return BoundColumns::NAN;
    }
    let b = solve_bound(&leg_problem(&vehicle, leg), None);
    let energy = b.thruster_energy_static + b.joint_energy;
    let mut out = BoundColumns {
        energy,
        energy_per_metre: energy / leg.distance,
        spread: b.spread,
        status: status_code(b.status),
        kkt: b.kkt.iter().copied().fold(0.0, f64::max),
        primal: b.kkt[0],
        work_error: b.work_error,
        iterations: b.iterations as f64,
        ..BoundColumns::NAN
    };
    if worlds.is_empty() {
        return out;
    }
    if !b.counts(leg.tolerance) {
        // No nominal bound to start the worlds from (cold, a world's leg did not converge in
        // 300 iterations): the worlds are not tried, and say so (0 feasible, 0 iterations).
        out.world_feasible = 0.0;
        out.world_iterations = 0.0;
        out.world_grid_rejected = 0.0;
        return out;
    }
    let warm = (b.solution.xs.clone(), b.solution.us.clone());
    let (mut lo, mut hi, mut ok, mut its) = (f64::INFINITY, f64::NEG_INFINITY, 0usize, 0usize);
    let mut rejected = 0usize;
    for w in worlds {
        let Some(world) = plant(design, scenario, w) else {
            continue;
        };
        let mut wleg = leg.clone();
        wleg.starts = 1;
        wleg.substeps = world_substeps;
        for i in 0..3 {
            wleg.current[i] += world.fluid.current[i] - vehicle.fluid.current[i];
        }
        let wb = solve_bound(&leg_problem(&world, &wleg), Some(&warm));
        its += wb.iterations;
        if wb.counts(leg.tolerance) {
            let e = (wb.thruster_energy_static + wb.joint_energy) / leg.distance;
            lo = lo.min(e);
            hi = hi.max(e);
            ok += 1;
        } else if wb.flies(leg.tolerance) {
            rejected += 1;
        }
    }
    if ok > 0 {
        out.world_min = lo;
        out.world_max = hi;
    }
    out.world_feasible = ok as f64;
    out.world_iterations = its as f64;
    out.world_grid_rejected = rejected as f64;
    out
}

/// A study's bound solver: the leg, and one solve per design for the whole sweep.
pub struct StudyBound {
    leg: LegSpec,
    /// Substeps of the worlds' legs (`[ocp] world_substeps`).
    world_substeps: usize,
    /// The overrides of the bound's worlds (the study's first `[ocp] worlds` scoring worlds).
    worlds: Vec<Vec<Override>>,
    cache: Mutex<HashMap<String, Arc<OnceLock<BoundColumns>>>>,
}

impl StudyBound {
    /// The solver of `study`'s `section`, its starts seeded by the study seed.
    pub fn new(section: &OcpSection, study: &Study) -> Self {
        let worlds = match (&study.uncertainty, section.worlds) {
            (Some(u), k) if k > 0 => u
                .sample(study.seed)
                .iter()
                .take(k)
                .map(|w| {
                    overrides_of(
                        u.params
                            .iter()
                            .zip(&w.values)
                            .map(|(p, v)| (p.name.as_str(), &p.target, v)),
                    )
                })
                .collect(),
            _ => Vec::new(),
        };
        Self {
            leg: leg_of(section, study.seed),
            world_substeps: section.world_substeps,
            worlds,
            cache: Mutex::new(HashMap::new()),
        }
    }

    /// The bound of `r`'s design, solved once per design hash.
    pub fn columns(&self, r: &Resolved) -> BoundColumns {
        let cell = {
            let mut c = self.cache.lock().unwrap_or_else(|p| p.into_inner());
            c.entry(r.design_hash.clone()).or_default().clone()
        };
        *cell.get_or_init(|| {
            design_bound(
                &r.design,
                &r.scenario,
                &self.leg,
                &self.worlds,
                self.world_substeps,
            )
        })
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
        metrics.set(OCP_WORK_ERROR, b.work_error);
        metrics.set(OCP_ITERATIONS, b.iterations);
        if !self.worlds.is_empty() {
            metrics.set(OCP_WORLD_MIN, b.world_min);
            metrics.set(OCP_WORLD_MAX, b.world_max);
            metrics.set(OCP_WORLD_FEASIBLE, b.world_feasible);
            metrics.set(OCP_WORLD_ITERATIONS, b.world_iterations);
            metrics.set(OCP_WORLD_GRID_REJECTED, b.world_grid_rejected);
        }
    }
}

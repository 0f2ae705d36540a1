//! The `[ocp]` section of a study file (issue 41, docs/ocp.md §6): the optimal-control bound
//! every case's design gets beside its closed-loop run — the least energy the best local
//! optimum found spends on a straight leg of the study's transport mission (from rest to
//! rest, `distance` metres ahead along +x in `duration` seconds), with the thrusts and joint
//! torques as controls on the full hydrodynamic model. The bound depends on the design and the
//! leg only, not on the controller's gains: cases of one design share one solve.
//!
//! ```toml
//! [ocp]
//! distance = 10.0        # leg length [m] (default 10)
//! duration = 20.0        # horizon T [s] (default 20: 0.5 m/s, the transport cruise)
//! knots = 20             # N (Δt = T/N)
//! substeps = 10          # symplectic Euler steps per interval (h = Δt/substeps)
//! starts = 1             # multi-start: the best local optimum, and the spread
//! current = [0, 0, 0]    # the leg's current, inertial [m/s] (the nominal world's)
//! joint_torque = 20.0    # |τ_i| bound [N·m]
//! effort = 1e-3          # weight of Σ Δt ‖u‖²
//! tolerance = 1e-6       # KKT tolerance
//! max_iterations = 150   # SQP iterations per start
//! worlds = 0             # also in the first K scoring worlds of [uncertainty] (warm-started)
//! world_substeps = 20     # substeps of the worlds' legs (default 2 × substeps, at most 1000)
//! ```
//!
//! The bound's vehicle is the case's plant in the nominal world (`ScenarioFile::world_vehicle`:
//! the payload, the `[hydro]` scales, the thrust derating); with `worlds = K` the bound is also
//! solved in each of the study's first K `[uncertainty]` worlds — the plant that world makes
//! (damping, drag, added mass, derating, buoyancy and centre-of-buoyancy errors, payload wet
//! weight) and the world's current on top of `current` — warm-started from the nominal
//! optimum (cold, a world's leg did not converge in 300 iterations where warm it took 39),
//! on a grid of `world_substeps` steps per interval: with the 10 steps of the nominal leg, a
//! world whose body is 1.1 % heavier than its buoyancy found legs at a fifth of the nominal
//! energy that the refined integration showed to be the grid's (work error 2.7); at 20 steps
//! the same world converged, trusted (work error 0.006), at +51 % (docs/ocp.md §6).

use crate::input::document::{deserialize_table, Document};
use crate::input::located::InputError;
use serde::Deserialize;

/// Most knots of a study's leg (each case's design solves N·substeps steps per iteration).
pub const MAX_KNOTS: usize = 200;
/// Most substeps per interval.
pub const MAX_SUBSTEPS: usize = 100;
/// Most starts of the multi-start.
pub const MAX_STARTS: usize = 16;
/// Most worlds the bound is solved in.
pub const MAX_WORLDS: usize = 64;

/// Check `[ocp] worlds` against the study's `[uncertainty]` (`n_worlds`: its worlds per case,
/// `None` without one): the bound's worlds are the first of the scoring worlds.
pub fn check_worlds(
    section: Option<&OcpSection>,
    n_worlds: Option<usize>,
    doc: &Document,
) -> Result<(), InputError> {
    let Some(k) = section.map(|s| s.worlds).filter(|&k| k > 0) else {
        return Ok(());
    };
    match n_worlds {
        None => Err(doc.err(
            "ocp.worlds",
            format!(
                "the bound's {k} worlds are the first of the study's scoring worlds, and this \
                 study has no `[uncertainty]`: add one, or drop `ocp.worlds`"
            ),
        )),
        Some(n) if n < k => Err(doc.err(
            "ocp.worlds",
            format!("{k} worlds asked, the study's `[uncertainty]` has {n}"),
        )),
        Some(_) => Ok(()),
    }
}

/// The validated `[ocp]` section: the leg every design's bound is solved on.
#[derive(Clone, Debug, PartialEq)]
pub struct OcpSection {
    /// Leg length along inertial +x [m].
    pub distance: f64,
    /// Horizon T [s].
    pub duration: f64,
    /// Knots N.
    pub knots: usize,
    /// Symplectic Euler steps per interval.
    pub substeps: usize,
    /// Starts of the multi-start (start 0 from rest, the others perturbed).
    pub starts: usize,
    /// The leg's current, inertial [m/s].
    pub current: [f64; 3],
    /// Joint torque bound [N·m].
    pub joint_torque: f64,
    /// Weight of `Σ Δt ‖u‖²`.
    pub effort: f64,
    /// KKT tolerance.
    pub tolerance: f64,
    /// SQP iterations per start.
    pub max_iterations: usize,
    /// The study's first `worlds` scoring worlds in which the bound is solved too (0: none).
    pub worlds: usize,
    /// Symplectic Euler steps per interval of the worlds' legs.
    pub world_substeps: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OcpFile {
    distance: Option<f64>,
    duration: Option<f64>,
    knots: Option<i64>,
    substeps: Option<i64>,
    starts: Option<i64>,
    current: Option<[f64; 3]>,
    joint_torque: Option<f64>,
    effort: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<i64>,
    worlds: Option<i64>,
    world_substeps: Option<i64>,
}

/// Parse `[ocp]` of a study file (`None` without one) of a closed-loop `transport` mode
/// (`transport`); errors are placed in `doc` at `ocp.<key>`.
pub fn parse_ocp(
    table: Option<&toml::Table>,
    transport: bool,
    doc: &Document,
) -> Result<Option<OcpSection>, InputError> {
    let Some(t) = table else {
        return Ok(None);
    };
    if !transport {
        return Err(doc.err(
            "ocp",
            "the optimal-control bound is a transport leg: it needs `scenario.mode = \"transport\"`",
        ));
    }
    let f: OcpFile = deserialize_table(t, "ocp").map_err(|e| doc.place(e))?;
    let positive = |key: &str, v: Option<f64>, default: f64| -> Result<f64, InputError> {
        let x = v.unwrap_or(default);
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(doc.err(
                &format!("ocp.{key}"),
                format!("must be a positive number, got {x}"),
            ))
        }
    };
    let count = |key: &str, v: Option<i64>, default: usize, max: usize| {
        let n = v.unwrap_or(default as i64);
        if (1..=max as i64).contains(&n) {
            Ok(n as usize)
        } else {
            Err(doc.err(
                &format!("ocp.{key}"),
                format!("must be an integer from 1 to {max}, got {n}"),
            ))
        }
    };
    let current = f.current.unwrap_or([0.0; 3]);
    if current.iter().any(|c| !c.is_finite() || c.abs() > 5.0) {
        return Err(doc.err(
            "ocp.current",
            format!("each component must be a finite speed within ±5 m/s, got {current:?}"),
        ));
    }
    let effort = f.effort.unwrap_or(1e-3);
    if !(effort.is_finite() && effort > 0.0) {
        return Err(doc.err(
            "ocp.effort",
            format!("must be positive (it keeps the torques' Hessian positive), got {effort}"),
        ));
    }
    let tolerance = positive("tolerance", f.tolerance, 1e-6)?;
    if tolerance >= 1.0 {
        return Err(doc.err("ocp.tolerance", format!("must be below 1, got {tolerance}")));
    }
    let substeps = count("substeps", f.substeps, 10, MAX_SUBSTEPS)?;
    Ok(Some(OcpSection {
        distance: positive("distance", f.distance, 10.0)?,
        duration: positive("duration", f.duration, 20.0)?,
        knots: count("knots", f.knots, 20, MAX_KNOTS)?,
        substeps,
        starts: count("starts", f.starts, 1, MAX_STARTS)?,
        current,
        joint_torque: positive("joint_torque", f.joint_torque, 20.0)?,
        effort,
        tolerance,
        max_iterations: count("max_iterations", f.max_iterations, 150, 10_000)?,
        worlds: match f.worlds {
            None | Some(0) => 0,
            Some(_) => count("worlds", f.worlds, 0, MAX_WORLDS)?,
        },
        world_substeps: count(
            "world_substeps",
            f.world_substeps,
            (2 * substeps).min(MAX_SUBSTEPS),
            MAX_SUBSTEPS,
        )?,
    }))
}

//! `[solver]` of a problem file (or of a sweep's `[tune]`): the method, its budgets and
//! tolerances, with the limits checked before anything runs (an evaluation budget, restarts
//! that fit in it, a swarm argmin can allocate). Read by [`super::tune_spec::parse_spec`].

use serde::Deserialize;

use crate::input::document::Document;
use crate::input::located::InputError;

/// The solver of `[solver] method`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Method {
    /// Nelder–Mead simplex from the start point (local; argmin `NelderMead`).
    #[serde(rename = "nelder-mead")]
    NelderMead,
    /// Particle swarm within the bounds (global; argmin `ParticleSwarm`, seeded).
    #[serde(rename = "particle-swarm")]
    ParticleSwarm,
    /// L-BFGS with central finite-difference gradients (argmin `LBFGS`, Moré–Thuente line
    /// search), for smooth static objectives.
    #[serde(rename = "lbfgs")]
    Lbfgs,
    /// CMA-ES within the bounds (global-local, seeded; IPOP restarts double the population;
    /// [`crate::optimise::cmaes`]).
    #[serde(rename = "cmaes")]
    Cmaes,
    /// Bayesian optimisation: Gaussian-process surrogates of the objective and of
    /// feasibility, constrained expected improvement (global, seeded; [`crate::optimise::bayes`]).
    #[serde(rename = "bayes")]
    Bayes,
}

impl Method {
    /// Every method, as written in problem files.
    pub const ALL: [(&'static str, Method); 5] = [
        ("nelder-mead", Method::NelderMead),
        ("particle-swarm", Method::ParticleSwarm),
        ("lbfgs", Method::Lbfgs),
        ("cmaes", Method::Cmaes),
        ("bayes", Method::Bayes),
    ];

    /// The name as written.
    pub fn as_str(self) -> &'static str {
        Method::ALL
            .iter()
            .find(|(_, m)| *m == self)
            .map_or("", |(n, _)| n)
    }
}

/// `[solver]`: the method, its budgets and tolerances.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SolverSettings {
    /// The method.
    pub method: Method,
    /// Iterations per run of the method (argmin `max_iters`; default 100).
    pub max_iters: u64,
    /// Evaluations in all, the start point included (default 200, at most [`MAX_EVALS`]);
    /// repeated points are served from memory but counted.
    pub max_evals: usize,
    /// Nelder–Mead: standard deviation of the simplex's costs; L-BFGS: gradient norm and
    /// cost change; CMA-ES: step size and flat best cost (default 1e-6).
    pub tolerance: f64,
    /// Further runs after the first (Nelder–Mead and L-BFGS from the best point so far,
    /// particle swarm with a new seed, CMA-ES from the best point so far with a new seed and
    /// twice the population (IPOP); default 0).
    pub restarts: usize,
    /// Seed of the particle swarm, of CMA-ES and of Bayesian optimisation (default:
    /// `study.seed`).
    pub seed: u64,
    /// Particles of the swarm (default 12, at most [`MAX_PARTICLES`] and `max_evals`).
    pub particles: usize,
    /// Nelder–Mead initial simplex edge, CMA-ES initial step size σ0, in the unit box of the
    /// normalised parameters (default 0.1; 0.3 for CMA-ES).
    pub step: f64,
    /// `polish` > 0: a final Nelder–Mead from the best point of the method's runs (none by
    /// default; the manifest then omits the key).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polish: Option<Polish>,
}

/// `[solver] polish` and `polish_step`: the last `evals` evaluations of `max_evals` go to a
/// Nelder–Mead from the best point so far, initial simplex `u + step·e_i` in the unit box.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Polish {
    /// Evaluations of the polish, kept back from `max_evals`.
    pub evals: usize,
    /// Initial simplex edge (default 0.05).
    pub step: f64,
}

/// Largest `[solver] max_evals` (every evaluation is kept in memory and in the history).
pub const MAX_EVALS: usize = 1_000_000;

/// Largest `[solver] particles` (argmin allocates the whole swarm before the first
/// evaluation).
pub const MAX_PARTICLES: usize = 10_000;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SolverFile {
    method: String,
    max_iters: Option<u64>,
    max_evals: Option<usize>,
    tolerance: Option<f64>,
    restarts: Option<usize>,
    seed: Option<u64>,
    particles: Option<usize>,
    step: Option<f64>,
    polish: Option<usize>,
    polish_step: Option<f64>,
}

pub(super) fn parse_solver(
    s: &SolverFile,
    at: &str,
    seed: u64,
    doc: &Document,
) -> Result<SolverSettings, InputError> {
    let k = |f: &str| format!("{at}.{f}");
    let method = Method::ALL
        .iter()
        .find(|(n, _)| *n == s.method)
        .map(|(_, m)| *m)
        .ok_or_else(|| {
            doc.err(
                &k("method"),
                format!(
                    "unknown method `{}`; valid: nelder-mead, particle-swarm, lbfgs, cmaes, bayes",
                    s.method
                ),
            )
        })?;
    let out = SolverSettings {
        method,
        max_iters: s.max_iters.unwrap_or(100),
        max_evals: s.max_evals.unwrap_or(200),
        tolerance: s.tolerance.unwrap_or(1e-6),
        restarts: s.restarts.unwrap_or(0),
        seed: s.seed.unwrap_or(seed),
        particles: s.particles.unwrap_or(12),
        step: s
            .step
            .unwrap_or(if method == Method::Cmaes { 0.3 } else { 0.1 }),
        polish: s.polish.filter(|&n| n > 0).map(|evals| Polish {
            evals,
            step: s.polish_step.unwrap_or(0.05),
        }),
    };
    if out.max_iters == 0 {
        return Err(doc.err(&k("max_iters"), "must be >= 1"));
    }
    if out.max_evals < 2 || out.max_evals > MAX_EVALS {
        return Err(doc.err(
            &k("max_evals"),
            format!("must be in 2..={MAX_EVALS} (the start point and one more, at least)"),
        ));
    }
    if out.restarts >= out.max_evals {
        return Err(doc.err(
            &k("restarts"),
            format!(
                "{} restarts cannot run within max_evals = {}: every run evaluates at least \
                 one point; use restarts < max_evals",
                out.restarts, out.max_evals
            ),
        ));
    }
    if !(out.tolerance > 0.0 && out.tolerance.is_finite()) {
        return Err(doc.err(&k("tolerance"), "must be finite and > 0"));
    }
    if out.particles < 2 || out.particles > MAX_PARTICLES {
        return Err(doc.err(&k("particles"), format!("must be in 2..={MAX_PARTICLES}")));
    }
    if method == Method::ParticleSwarm && out.particles > out.max_evals {
        return Err(doc.err(
            &k("particles"),
            format!(
                "a swarm of {} particles cannot be evaluated once within max_evals = {}",
                out.particles, out.max_evals
            ),
        ));
    }
    if !(out.step > 0.0 && out.step <= 0.5) {
        return Err(doc.err(&k("step"), "must be in (0, 0.5]"));
    }
    let polish_step = s.polish_step.unwrap_or(0.05);
    if !(polish_step > 0.0 && polish_step <= 0.5) {
        return Err(doc.err(&k("polish_step"), "must be in (0, 0.5]"));
    }
    if let Some(p) = out.polish {
        if p.evals + out.restarts >= out.max_evals {
            return Err(doc.err(
                &k("polish"),
                format!(
                    "a polish of {} evaluations leaves the method's {} run(s) nothing of \
                     max_evals = {}; use polish + restarts < max_evals",
                    p.evals,
                    out.restarts + 1,
                    out.max_evals
                ),
            ));
        }
    }
    Ok(out)
}

//! How far a solution can be trusted off its grid (docs/ocp.md §4, "Grid fidelity"): each
//! interval of a solution integrated again from its knot with `refine` times as many
//! symplectic Euler steps, under the same constant control.
//!
//! - (F1) the local defect of interval k: `d_k = f_fine(x_k, u_k) ⊖ f(x_k, u_k)` (tangent,
//!   [m, rad, rad | m/s, rad/s, rad/s]), split into its configuration part (the first 6 + n
//!   components) and its velocity part (the last 6 + n);
//! - (F2) the relative defect `max_k ‖d_k‖ / max_k ‖f(x_k, u_k) ⊖ x_k‖` (2-norms of the whole
//!   tangent vector): how much of the largest change per interval the grid gets wrong;
//! - (F3) the work balance of every interval, `ΔE_k = W_act,k + W_other,k` with
//!   `E = ½ ζᵀ M(q) ζ` ([`ChainModel::kinetic_energy`]) and the actuators' work summed over the
//!   steps, `W_act = Σ_i h τ_iᵀ (ζ_i + ζ_{i+1}) / 2` (exact for a constant mass matrix: what
//!   is left, `W_other`, is the work of the water, the restoring forces and the integrator);
//! - (F4) `W_other` on the grid and refined: in still water without restoring moments the
//!   water only takes energy, so an `other_work` above `other_work_refined` is energy the
//!   grid's integration supplies.

use super::chain::ChainModel;
use super::model::{ModelError, OcpModel};

/// The grid fidelity of a solution ((F1)–(F4) of the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct GridFidelity {
    /// Symplectic Euler steps per interval of the solution's grid.
    pub substeps: usize,
    /// Steps per interval of the refined integration.
    pub refined_substeps: usize,
    /// Largest configuration defect `max_k ‖d_k[..6+n]‖` (F1) [m, rad].
    pub max_configuration_defect: f64,
    /// Largest velocity defect `max_k ‖d_k[6+n..]‖` (F1) [m/s, rad/s].
    pub max_velocity_defect: f64,
    /// The interval of the largest defect `‖d_k‖`.
    pub worst_interval: usize,
    /// (F2): the largest defect over the largest change per interval.
    pub relative_defect: f64,
    /// Actuator work on the grid, `Σ_k W_act,k` [J] (F3).
    pub actuator_work: f64,
    /// Actuator work of the refined integration [J].
    pub actuator_work_refined: f64,
    /// Work of everything but the actuators on the grid, `Σ_k W_other,k` [J] (F3).
    pub other_work: f64,
    /// The same, refined [J] (F4).
    pub other_work_refined: f64,
}

/// (F3) for one interval from `x` under `u`, integrated by `steps` plain steps of the model
/// `fine` (one substep per interval of length h): the end state into `end`, and
/// `(W_act, W_other)` [J].
fn interval_work(
    fine: &mut ChainModel,
    x: &[f64],
    u: &[f64],
    steps: usize,
    end: &mut Vec<f64>,
) -> Result<(f64, f64), ModelError> {
    let n = fine.n_joints();
    let nv = 6 + n;
    let h = fine.dt();
    let mut cur = x.to_vec();
    let mut next = vec![0.0; x.len()];
    let e0 = fine.kinetic_energy(x);
    let mut work = 0.0;
    for _ in 0..steps {
        fine.step(&cur, u, &mut next)?;
        let tau = fine.last_actuation();
        let (z0, z1) = (&cur[7 + n..7 + n + nv], &next[7 + n..7 + n + nv]);
        work += h * (0..nv).map(|r| tau[r] * 0.5 * (z0[r] + z1[r])).sum::<f64>();
        std::mem::swap(&mut cur, &mut next);
    }
    let e1 = fine.kinetic_energy(&cur);
    *end = cur;
    Ok((work, e1 - e0 - work))
}

/// Check the solution `(xs, us)` (N + 1 states, N controls) of `model` against its
/// integration `refine` (≥ 2) times finer ((F1)–(F4)). Allocates (once per call, after a
/// solve).
pub fn grid_fidelity(
    model: &ChainModel,
    xs: &[Vec<f64>],
    us: &[Vec<f64>],
    refine: usize,
) -> Result<GridFidelity, ModelError> {
    let s = model.substeps();
    let refine = refine.max(2);
    let dt = model.dt();
    let n = model.n_joints();
    let nc = 6 + n;
    // Plain steps of h (the grid's) and of h / refine.
    let mut grid = model.clone().with_substeps(1).with_interval(dt / s as f64);
    let mut fine = model
        .clone()
        .with_substeps(1)
        .with_interval(dt / (s * refine) as f64);
    let nx = model.nx();
    let (mut end_g, mut end_f) = (Vec::new(), Vec::new());
    let mut d = vec![0.0; nx];
    let mut out = GridFidelity {
        substeps: s,
        refined_substeps: s * refine,
        max_configuration_defect: 0.0,
        max_velocity_defect: 0.0,
        worst_interval: 0,
        relative_defect: 0.0,
        actuator_work: 0.0,
        actuator_work_refined: 0.0,
        other_work: 0.0,
        other_work_refined: 0.0,
    };
    let (mut worst, mut largest_change) = (0.0f64, 0.0f64);
    for (k, u) in us.iter().enumerate() {
        let x = &xs[k];
        let (wa, wo) = interval_work(&mut grid, x, u, s, &mut end_g)?;
        let (fa, fo) = interval_work(&mut fine, x, u, s * refine, &mut end_f)?;
        out.actuator_work += wa;
        out.other_work += wo;
        out.actuator_work_refined += fa;
        out.other_work_refined += fo;
        model.difference(&end_g, &end_f, &mut d);
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        out.max_configuration_defect = out.max_configuration_defect.max(norm(&d[..nc]));
        out.max_velocity_defect = out.max_velocity_defect.max(norm(&d[nc..]));
        let dk = norm(&d);
        if dk > worst {
            worst = dk;
            out.worst_interval = k;
        }
        model.difference(x, &end_g, &mut d);
        largest_change = largest_change.max(norm(&d));
    }
    out.relative_defect = if largest_change > 0.0 {
        worst / largest_change
    } else {
        0.0
    };
    Ok(out)
}

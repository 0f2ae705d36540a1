//! The extreme singular values of the commanded rows of `T_L` (docs/model.md §6): σ_min, σ_max,
//! κ and the rank without the middle of the spectrum, the static analysis' per-configuration
//! route ([`commanded_extremes_with`]), two selections at once
//! ([`commanded_extremes_pair_with`], one Householder reduction when one of them is all six
//! rows) and the QR + Jacobi fallback for ill-conditioned blocks.

use nalgebra::Matrix6xX;

use super::singularity::{
    commanded_sigma_with, condition, from_squares, selected_rows, triangle_sigma_sq, CommandedDofs,
    ScaledGram, SigmaExtremes,
};
use crate::metrics::small_svd::{
    extreme_eigenvalues, extreme_eigenvalues_nested, extreme_eigenvalues_pair,
};

/// Below this ratio `λ_min/λ_max` (κ > 1000) [`commanded_extremes_with`] leaves the Gram
/// route: its σ_min then carries a relative error up to about `ε κ²/2` ≤ 5.6e-11, within
/// the static analysis' 1e-10 (a hundredfold looser than [`GRAM_MIN_RATIO`](super::singularity::GRAM_MIN_RATIO)'s, for a third
/// fewer trips through the QR + Jacobi route on the paper's design).
pub const EXTREMES_MIN_RATIO: f64 = 1e-6;

/// [`commanded_sigma_with`] reduced to σ_min, σ_max, κ and the rank under `rank_rel_tol`,
/// equal to it to rounding: on the well-conditioned (Gram) route only the two extreme
/// eigenvalues of the Gram matrix are sought (Laguerre's iteration on its tridiagonal form,
/// no QL sweeps) while `λ_min ≥ EXTREMES_MIN_RATIO·λ_max`, and every singular value then
/// exceeds `rank_rel_tol · σ_max` (rank `k`) as long as `rank_rel_tol² < EXTREMES_MIN_RATIO`;
/// otherwise, and on the ill-conditioned route,
/// all singular values as [`commanded_sigma_with`] computes them. Allocation-free.
pub fn commanded_extremes_with(
    g: &ScaledGram,
    t: &Matrix6xX<f64>,
    dofs: CommandedDofs,
    rank_rel_tol: f64,
) -> SigmaExtremes {
    let k = dofs.len();
    if !extremes_route_applies(g, k, rank_rel_tol) {
        return commanded_sigma_with(g, t, dofs).extremes(rank_rel_tol);
    }
    let rows = selected_rows(dofs);
    let mut gram = g.select(&rows, k);
    let ev = extreme_eigenvalues(&mut gram, k);
    extremes_from(g, t, &rows, k, ev, rank_rel_tol)
}

/// [`commanded_extremes_with`] for two axis selections of one configuration (the static
/// analysis' all six rows and its commanded ones), each equal to its own call to rounding: when
/// one selection is all six rows, one Householder reduction serves both
/// ([`extreme_eigenvalues_nested`]); the two Gram blocks' Laguerre iterations share one loop.
pub fn commanded_extremes_pair_with(
    g: &ScaledGram,
    t: &Matrix6xX<f64>,
    dofs: [CommandedDofs; 2],
    rank_rel_tol: f64,
) -> [SigmaExtremes; 2] {
    commanded_extremes_pair_planned(g, t, &PairPlan::new(dofs), rank_rel_tol)
}

/// Two axis selections of [`commanded_extremes_pair_with`] resolved once, for many
/// configurations (the static analysis scores the same pair at every sample): their rows and,
/// when one is all six rows and the other five or six, the row order of the one Householder
/// reduction that serves both (the selected rows first, [`extreme_eigenvalues_nested`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairPlan {
    dofs: [CommandedDofs; 2],
    ks: [usize; 2],
    rows: [[usize; 6]; 2],
    /// The index of the selection that is not all six rows (or 1 when both are) and the row
    /// order that puts it first.
    nested: Option<(usize, [usize; 6])>,
}

impl PairPlan {
    /// The plan of the selections `dofs`.
    pub fn new(dofs: [CommandedDofs; 2]) -> Self {
        let ks = dofs.map(CommandedDofs::len);
        let rows = dofs.map(selected_rows);
        let nested = match (0..2).position(|i| ks[i] == 6) {
            Some(full) if ks[1 - full] >= 5 => {
                let sel = 1 - full;
                Some((sel, rows_first(&rows[sel], ks[sel])))
            }
            _ => None,
        };
        Self {
            dofs,
            ks,
            rows,
            nested,
        }
    }
}

/// [`commanded_extremes_pair_with`] of the selections resolved in `plan`.
pub fn commanded_extremes_pair_planned(
    g: &ScaledGram,
    t: &Matrix6xX<f64>,
    plan: &PairPlan,
    rank_rel_tol: f64,
) -> [SigmaExtremes; 2] {
    let PairPlan {
        dofs,
        ks,
        rows,
        nested,
    } = plan;
    if !ks
        .iter()
        .all(|&k| extremes_route_applies(g, k, rank_rel_tol))
    {
        return dofs.map(|d| commanded_extremes_with(g, t, d, rank_rel_tol));
    }
    let ev = match nested {
        // All six rows and five (or six) of them: one Householder reduction of the Gram
        // matrix with the selected rows first serves both (its leading block is the
        // selection's, [`extreme_eigenvalues_nested`]).
        Some((sel, order)) => {
            let mut gram = g.permuted(order);
            let [of_full, of_sel] = extreme_eigenvalues_nested(&mut gram, ks[*sel]);
            let mut ev = [of_full; 2];
            ev[*sel] = of_sel;
            ev
        }
        None => {
            let (mut ga, mut gb) = (g.select(&rows[0], ks[0]), g.select(&rows[1], ks[1]));
            extreme_eigenvalues_pair(&mut ga, ks[0], &mut gb, ks[1])
        }
    };
    std::array::from_fn(|i| extremes_from(g, t, &rows[i], ks[i], ev[i], rank_rel_tol))
}

/// All six row indices: `rows[..k]` first, then the others in increasing order.
fn rows_first(rows: &[usize; 6], k: usize) -> [usize; 6] {
    let mut order = *rows;
    let mut n = k;
    for r in 0..6 {
        if !rows[..k].contains(&r) {
            order[n] = r;
            n += 1;
        }
    }
    order
}

/// Whether [`commanded_extremes_with`]'s Gram route may score `k` commanded rows of `g`: not
/// for invalid input, nothing commanded, or a rank tolerance the route cannot certify.
fn extremes_route_applies(g: &ScaledGram, k: usize, rank_rel_tol: f64) -> bool {
    g.valid && k > 0 && rank_rel_tol * rank_rel_tol < EXTREMES_MIN_RATIO
}

/// The [`SigmaExtremes`] of the rows `rows[..k]` whose Gram block has the extreme eigenvalues
/// `(lo, hi)`: the QR + Jacobi route below [`EXTREMES_MIN_RATIO`].
fn extremes_from(
    g: &ScaledGram,
    t: &Matrix6xX<f64>,
    rows: &[usize; 6],
    k: usize,
    (lo, hi): (f64, f64),
    rank_rel_tol: f64,
) -> SigmaExtremes {
    if lo < EXTREMES_MIN_RATIO * hi {
        return from_squares(&triangle_sigma_sq(g, t, rows, k), k).extremes(rank_rel_tol);
    }
    let (sigma_min, sigma_max) = (lo.max(0.0).sqrt(), hi.max(0.0).sqrt());
    SigmaExtremes {
        k,
        sigma_min,
        sigma_max,
        condition_number: condition(sigma_max, sigma_min),
        rank: k,
    }
}

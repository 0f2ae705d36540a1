//! The interior shortcut of the `qp` form (docs/model.md §5): when the unconstrained optimum lies inside
//! the bounds, it is the QP solution, found by one small SPD solve instead of Clarabel.
//!
//! The `qp` problem is `min uᵀWu + q‖s‖² + ‖u − u_prev‖²_R` s.t. `T u = τ + s`,
//! `lo ≤ u ≤ hi` (`lo`, `hi` the effective bounds: thruster bounds ∩ rate limits; `R = 0`
//! without rate terms). Eliminating `s = T u − τ` gives the objective Clarabel minimises in
//! both formulations (`conic.rs`, up to the constant `q‖τ‖² + Σ r_j u_prev,j²`):
//!
//! `f(u) = Σ_j w_j u_j² + q‖T u − τ‖² + Σ_j r_j (u_j − u_prev,j)²`,
//! `∇f(u) = 2(W + R) u + 2q Tᵀ(T u − τ) − 2R u_prev`.
//!
//! Its unconstrained minimiser solves the n_thrusters×n_thrusters SPD system
//! `H u = b`, `H = W + R + q TᵀT`, `b = q Tᵀτ + R u_prev` (SPD since `W ≻ 0`), factorised by
//! the crate's one Cholesky (`dynamics::cholesky`).
//!
//! **Certificate.** If that `u` satisfies `lo ≤ u ≤ hi`, it solves the QP: with the slack
//! `s = T u − τ`, the equality multiplier `ν = 2q s` and zero bound multipliers
//! `μ_lo = μ_hi = 0`, the KKT conditions of the slack-kept problem hold —
//! stationarity `∇f(u) = 0` (by construction, and *checked*: every component of the
//! gradient, evaluated from the objective itself, is below [`CERT_TOL`] relative to the
//! magnitudes it sums), primal feasibility (`T u − s = τ` by definition of `s`; the bounds
//! checked), dual feasibility (`μ = 0 ≥ 0`) and complementary slackness (`μ·(bound gap) = 0`
//! trivially). The problem is strictly convex, so the KKT point is the unique optimum. If a
//! bound is violated, or the gradient check or the factorisation fails, the caller calls
//! Clarabel.
//!
//! `minimax` and `power` have no such shortcut, so they keep Clarabel. Minimax: its term
//! `max_j |u_j|` is the epigraph variable `t` with the rows `−t ≤ u_j ≤ t`, and at every optimum
//! with `u ≠ 0` at least one of them is active (`t = max_j |u_j|`): the optimum is never
//! interior, zero multipliers never certify it, and which `|u_j|` tie at the maximum is a
//! combinatorial (active-set) choice — Clarabel's job. Power: `Σ w_j |u_j|^{3/2}` is not
//! quadratic (and its curvature is unbounded at `u_j = 0`), so even its unconstrained optimum
//! needs an iterative (Newton) solve whose stationarity holds only to a tolerance, as
//! Clarabel's does — no exact one-solve certificate.

use super::conic::Params;
use crate::linalg;

/// Relative tolerance of the stationarity check: `|∇f(u)_j| ≤ CERT_TOL · a_j`, with `a_j` the
/// sum of the magnitudes of the terms of `∇f(u)_j` (the componentwise backward-error scale).
/// Cholesky's round-off is ~1e-15 of it; Clarabel's default gap tolerance is 1e-8.
pub(crate) const CERT_TOL: f64 = 1e-10;

/// Scratch of the interior shortcut for `n_thrusters` thrusters, sized once (a step allocates
/// nothing).
pub(crate) struct InteriorQp {
    n_thrusters: usize,
    /// `H`, column-major n×n, overwritten by its Cholesky factor.
    h: Vec<f64>,
}

impl InteriorQp {
    /// Scratch for `n_thrusters` thrusters.
    pub(crate) fn new(n_thrusters: usize) -> Self {
        Self {
            n_thrusters,
            h: vec![0.0; n_thrusters * n_thrusters],
        }
    }

    /// The unconstrained minimiser of the `qp` objective of `p` (module doc) into `u` (N).
    /// Returns `true` if it was computed and its stationarity check passed; `u` is then the
    /// QP solution iff it lies within `[p.lo, p.hi]` ([`inside`]).
    pub(crate) fn solve(&mut self, p: &Params<'_>, u: &mut [f64]) -> bool {
        let n = self.n_thrusters;
        let h = &mut self.h;
        for j in 0..n {
            let cj = p.t.fixed_view::<6, 1>(0, j);
            // Lower triangle only: rows j..n of column j.
            for i in j..n {
                h[j * n + i] = p.q * p.t.fixed_view::<6, 1>(0, i).dot(&cj);
            }
            h[j * n + j] += p.w[j] + p.rate_w[j];
            u[j] = p.q * cj.dot(p.tau) + p.rate_w[j] * p.u_prev[j];
        }
        let tol = linalg::relative_tolerance(h, n);
        if linalg::factor(h, n, tol).is_err() {
            return false;
        }
        linalg::solve(h, n, u);
        stationary(p, u)
    }
}

/// The stationarity check of the certificate: every component of `∇f(u)` (module doc),
/// evaluated from the objective, is at most [`CERT_TOL`] times the sum of the magnitudes of its
/// terms. False for non-finite `u`.
fn stationary(p: &Params<'_>, u: &[f64]) -> bool {
    let mut s = -p.tau;
    let mut mag = p.tau.abs();
    for (j, &uj) in u.iter().enumerate() {
        let cj = p.t.fixed_view::<6, 1>(0, j);
        s += cj * uj;
        mag += cj.abs() * uj.abs();
    }
    u.iter().enumerate().all(|(j, &uj)| {
        let cj = p.t.fixed_view::<6, 1>(0, j);
        let (w, r, up) = (p.w[j], p.rate_w[j], p.u_prev[j]);
        let grad = 2.0 * (w * uj + r * (uj - up) + p.q * cj.dot(&s));
        let scale = 2.0 * (w * uj.abs() + r * (uj.abs() + up.abs()) + p.q * cj.abs().dot(&mag));
        grad.abs() <= CERT_TOL * scale
    })
}

/// Whether `lo ≤ u ≤ hi` componentwise (closed bounds: an optimum exactly on a bound still
/// has zero multipliers).
pub(crate) fn inside(u: &[f64], lo: &[f64], hi: &[f64]) -> bool {
    u.iter()
        .zip(lo.iter().zip(hi))
        .all(|(&x, (&l, &h))| l <= x && x <= h)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::needless_range_loop)]

    use super::super::tests::bent_t;
    use super::super::{AllocPath, AllocSettings, Allocation, Allocator, Method, RateSettings};
    use nalgebra::{DMatrix, DVector, Matrix6xX, Vector6};
    use proptest::prelude::*;

    /// A random 6×7 T: a bent-USM-like one (seeded) or one with uniform entries in [-1, 1]
    /// (full rank with probability 1).
    fn random_t(bent: bool, seed: u64, entries: &[f64]) -> Matrix6xX<f64> {
        if bent {
            bent_t(seed)
        } else {
            Matrix6xX::from_iterator(7, entries.iter().copied())
        }
    }

    /// The unconstrained optimum of the qp objective by an independent dense LU solve of
    /// `(W + R + q TᵀT) u = q Tᵀτ + R u_prev`.
    fn reference_optimum(
        t: &Matrix6xX<f64>,
        tau: &Vector6<f64>,
        w: &[f64],
        rate_w: &[f64],
        u_prev: &[f64],
        q: f64,
    ) -> Vec<f64> {
        let td = DMatrix::from_column_slice(6, 7, t.as_slice());
        let d = DVector::from_iterator(7, w.iter().zip(rate_w).map(|(a, b)| a + b));
        let h = DMatrix::from_diagonal(&d) + td.transpose() * &td * q;
        let rp = DVector::from_iterator(7, rate_w.iter().zip(u_prev).map(|(r, p)| r * p));
        let tau = DVector::from_column_slice(tau.as_slice());
        let b = td.transpose() * tau * q + rp;
        h.lu()
            .solve(&b)
            .expect("H is SPD")
            .iter()
            .copied()
            .collect()
    }

    fn allocator(lo: &[f64], hi: &[f64], w: &[f64], s: AllocSettings) -> Allocator {
        Allocator::new(Method::Qp, 7, lo, hi, w, s).expect("valid case")
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        /// On interior problems (bounds set 50 % beyond the unconstrained optimum, rate terms
        /// or not) the shortcut is taken and returns Clarabel's u to 1e-8 (Clarabel forced by
        /// `interior_shortcut = false`, with its tolerance tightened to 1e-12).
        #[test]
        fn prop_interior_shortcut_equals_clarabel(
            bent in any::<bool>(),
            seed in 0u64..10_000,
            entries in proptest::collection::vec(-1.0f64..1.0, 42),
            tauv in proptest::collection::vec(-1.0f64..1.0, 6),
            tau_scale in 0.01f64..50.0,
            w in proptest::collection::vec(0.2f64..5.0, 7),
            rate in proptest::option::of(proptest::collection::vec(0.0f64..3.0, 7)),
            u_prev in proptest::collection::vec(-5.0f64..5.0, 7),
            q in prop_oneof![Just(1e4), 1.0f64..1e5],
        ) {
            let t = random_t(bent, seed, &entries);
            let tau = Vector6::from_iterator(tauv.iter().map(|x| x * tau_scale));
            let rate_w = rate.clone().unwrap_or(vec![0.0; 7]);
            let u_ref = reference_optimum(&t, &tau, &w, &rate_w, &u_prev, q);
            let big = u_ref.iter().chain(&u_prev).fold(1.0_f64, |m, x| m.max(x.abs()));
            let (lo, hi) = (vec![-1.5 * big; 7], vec![1.5 * big; 7]);
            let settings = AllocSettings {
                q,
                rate: rate.map(|weights| RateSettings { weights, max_step: vec![f64::INFINITY; 7] }),
                ..AllocSettings::default()
            };
            let mut fast = allocator(&lo, &hi, &w, settings.clone());
            let mut clar = allocator(&lo, &hi, &w, AllocSettings {
                interior_shortcut: false,
                tol: 1e-12,
                ..settings
            });
            fast.set_u_prev(&u_prev).unwrap();
            clar.set_u_prev(&u_prev).unwrap();
            let (mut a, mut b) = (Allocation::new(7), Allocation::new(7));
            fast.allocate_into(&t, &tau, &mut a).unwrap();
            clar.allocate_into(&t, &tau, &mut b).unwrap();
            prop_assert_eq!(a.path, AllocPath::Interior);
            prop_assert_eq!(b.path, AllocPath::Clarabel);
            for j in 0..7 {
                prop_assert!((a.u[j] - b.u[j]).abs() <= 1e-8 * big,
                    "u[{}]: shortcut {} vs Clarabel {} (scale {})", j, a.u[j], b.u[j], big);
                prop_assert!((a.u[j] - u_ref[j]).abs() <= 1e-10 * big);
            }
            prop_assert!((a.objective - b.objective).abs() <= 1e-8 * a.objective.abs().max(1.0));
        }

        /// The shortcut is never taken when the unconstrained optimum (independent reference)
        /// violates an effective bound (thruster bounds ∩ rate limits), and always taken when it
        /// lies strictly inside them (margins of 1e-9 relative either side).
        #[test]
        fn prop_shortcut_never_taken_with_an_active_bound(
            bent in any::<bool>(),
            seed in 0u64..10_000,
            entries in proptest::collection::vec(-1.0f64..1.0, 42),
            tauv in proptest::collection::vec(-60.0f64..60.0, 6),
            lov in proptest::collection::vec(-40.0f64..0.0, 7),
            width in proptest::collection::vec(0.0f64..60.0, 7),
            rate in proptest::option::of((
                proptest::collection::vec(0.0f64..3.0, 7),
                proptest::collection::vec(0.5f64..20.0, 7),
            )),
            u_prev in proptest::collection::vec(-10.0f64..10.0, 7),
        ) {
            let t = random_t(bent, seed, &entries);
            let tau = Vector6::from_iterator(tauv.iter().copied());
            let hiv: Vec<f64> = lov.iter().zip(&width).map(|(l, w)| l + w).collect();
            let (rate_w, step) = rate.clone().unwrap_or((vec![0.0; 7], vec![f64::INFINITY; 7]));
            let w = [1.0; 7];
            let settings = AllocSettings {
                rate: rate.map(|(weights, max_step)| RateSettings { weights, max_step }),
                ..AllocSettings::default()
            };
            let mut a = allocator(&lov, &hiv, &w, settings);
            a.set_u_prev(&u_prev).unwrap();
            let r = a.allocate(&t, &tau).unwrap();
            let u_ref = reference_optimum(&t, &tau, &w, &rate_w, &u_prev, AllocSettings::default().q);
            let mut violation = f64::NEG_INFINITY;
            let mut scale = 1.0_f64;
            for j in 0..7 {
                let lo = (u_prev[j] - step[j]).clamp(lov[j], hiv[j]);
                let hi = (u_prev[j] + step[j]).clamp(lov[j], hiv[j]);
                violation = violation.max(u_ref[j] - hi).max(lo - u_ref[j]);
                scale = scale.max(u_ref[j].abs());
            }
            if violation > 1e-9 * scale {
                prop_assert_ne!(r.path, AllocPath::Interior, "violation {}", violation);
            } else if violation < -1e-9 * scale {
                prop_assert_eq!(r.path, AllocPath::Interior, "violation {}", violation);
            }
        }
    }
}

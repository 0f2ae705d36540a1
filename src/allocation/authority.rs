//! Attainable authority along the commanded axes, about a reference point, under thrust limits
//! (docs/model.md §6, AC/USM issue 24 item 2), and its thruster-removed (N−1) variant.
//!
//! For each commanded axis `k` and sign `±` the linear programme
//!
//! ```text
//! max α   s.t.   S T_r u = ±α S e_k,   u_min ≤ u ≤ u_max
//! ```
//!
//! where `T_r` is `T` with its moment rows transported to the reference point `r` (base frame:
//! `m_r = m_b − r × f`, `r` the point's position in the base frame [m]) and `S` selects the
//! commanded rows. The uncommanded rows are free (the thrusters may produce any wrench there),
//! the other commanded axes are held at zero. `α` is a force [N] for surge/sway/heave and a
//! moment [N·m] for roll/pitch/yaw: the support of the thrust box mapped through `S T_r` along
//! `±e_k`.
//!
//! One Clarabel solver is built per [`AuthoritySolver`] and reused for every axis, sign,
//! configuration and removed thruster: only the values of `A` (the configuration's `T_r` and
//! the `α` column) and of `b` (the bounds of a removed thruster) change, updated in place.
//! Clarabel keeps no state between solves except the equilibration computed when the solver is
//! built, so the result of a programme is a function of (the data the solver was built with,
//! the programme's data): build every solver of an analysis from the same data for
//! bit-identical results across workers.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{Matrix6xX, Vector3};
use serde::Serialize;

use super::conic::clarabel_settings;
use super::error::{check_bounds, check_t, check_vec, AllocError};

/// The attainable authority along each base axis (docs/model.md §6), surge, sway, heave (N),
/// roll, pitch, yaw (N·m) about the reference point, base axes. `NaN` (JSON `null`) for an
/// uncommanded axis, and where the programme failed or is infeasible (possible only when
/// `u = 0` violates the bounds).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AttainableAuthority {
    /// `max α ≥ 0` with the commanded rows of `T_r u` equal to `+α e_k`.
    pub positive: [f64; 6],
    /// `max α ≥ 0` with the commanded rows of `T_r u` equal to `−α e_k` (a magnitude).
    pub negative: [f64; 6],
}

impl AttainableAuthority {
    /// All `NaN` (nothing solved).
    pub const NAN: Self = Self {
        positive: [f64::NAN; 6],
        negative: [f64::NAN; 6],
    };

    /// The smaller of the two signs along axis `k` (NaN when either is NaN).
    pub fn along(&self, k: usize) -> f64 {
        nan_min(self.positive[k], self.negative[k])
    }

    /// The smallest commanded force [N] over surge, sway, heave and both signs, among the
    /// axes of `commanded` (NaN when none is commanded or a programme failed).
    pub fn min_force(&self, commanded: [bool; 6]) -> f64 {
        self.min_over(commanded, 0..3)
    }

    /// The smallest commanded moment [N·m] over roll, pitch, yaw and both signs, among the
    /// axes of `commanded` (NaN when none is commanded or a programme failed).
    pub fn min_moment(&self, commanded: [bool; 6]) -> f64 {
        self.min_over(commanded, 3..6)
    }

    fn min_over(&self, commanded: [bool; 6], axes: std::ops::Range<usize>) -> f64 {
        let mut out = f64::INFINITY;
        let mut any = false;
        for k in axes.filter(|&k| commanded[k]) {
            any = true;
            out = nan_min(out, self.along(k));
        }
        if any {
            out
        } else {
            f64::NAN
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

/// `T` (6×n_thrusters, base frame, moments about the base origin) with its moment rows about
/// `reference` (base frame [m]): `m_r = m_b − r × f` per column, written into `out`.
pub fn transport_moments(t: &Matrix6xX<f64>, reference: &Vector3<f64>, out: &mut Matrix6xX<f64>) {
    for j in 0..t.ncols() {
        let f = Vector3::new(t[(0, j)], t[(1, j)], t[(2, j)]);
        let m = Vector3::new(t[(3, j)], t[(4, j)], t[(5, j)]) - reference.cross(&f);
        for i in 0..3 {
            out[(i, j)] = f[i];
            out[(3 + i, j)] = m[i];
        }
    }
}

/// One Clarabel solver for the authority programmes of a vehicle's thrusters (see the module
/// documentation): built once, then [`AuthoritySolver::solve`] per configuration and
/// [`AuthoritySolver::solve_without`] per removed thruster.
pub struct AuthoritySolver {
    n_thrusters: usize,
    /// The commanded axes, in order (the rows of the equality block).
    rows: Vec<usize>,
    u_min: Vec<f64>,
    u_max: Vec<f64>,
    /// The solver (`None` when Clarabel refused the data: every result is NaN).
    solver: Option<DefaultSolver<f64>>,
    /// The values of `A`, column-major: per thruster `k` rows of `S T_r` then its two box rows;
    /// then the `α` column.
    nz: Vec<f64>,
    b: Vec<f64>,
    /// Scratch for `T_r`.
    t_ref: Matrix6xX<f64>,
}

impl AuthoritySolver {
    /// A solver for `t` (6×n_thrusters, base frame, N and N·m per N), bounds `u_min ≤ u ≤
    /// u_max` (N) and the `commanded` axes (surge … yaw), with `t`'s moments about
    /// `reference` (base frame [m]); `t` also fixes the solver's equilibration. Errors only on
    /// bad input.
    pub fn new(
        t: &Matrix6xX<f64>,
        u_min: &[f64],
        u_max: &[f64],
        commanded: [bool; 6],
        reference: &Vector3<f64>,
    ) -> Result<Self, AllocError> {
        check_t(t, None)?;
        let n_thrusters = t.ncols();
        check_bounds(u_min, u_max, n_thrusters)?;
        check_vec("reference", reference.as_slice(), 3)?;
        let rows: Vec<usize> = (0..6).filter(|&k| commanded[k]).collect();
        let k = rows.len();
        let mut t_ref = Matrix6xX::zeros(n_thrusters);
        transport_moments(t, reference, &mut t_ref);
        // x = [u (n_thrusters); α]; rows: k equalities [S T_r, −s e_k] x = 0, then the box.
        let n = n_thrusters + 1;
        let m = k + 2 * n_thrusters;
        let mut colptr = Vec::with_capacity(n + 1);
        let mut rowval = Vec::new();
        let mut nz = Vec::new();
        for j in 0..n_thrusters {
            colptr.push(rowval.len());
            for (r, &axis) in rows.iter().enumerate() {
                rowval.push(r);
                nz.push(t_ref[(axis, j)]);
            }
            rowval.push(k + j);
            nz.push(1.0);
            rowval.push(k + n_thrusters + j);
            nz.push(-1.0);
        }
        colptr.push(rowval.len());
        for r in 0..k {
            rowval.push(r);
            nz.push(if r == 0 { -1.0 } else { 0.0 });
        }
        colptr.push(rowval.len());
        let a = CscMatrix::new(m, n, colptr, rowval, nz.clone());
        let p = CscMatrix::zeros((n, n));
        let mut q = vec![0.0; n];
        q[n_thrusters] = -1.0;
        let mut b = vec![0.0; m];
        b[k..k + n_thrusters].copy_from_slice(u_max);
        for (bj, &lo) in b[k + n_thrusters..].iter_mut().zip(u_min) {
            *bj = -lo;
        }
        let cones = [
            SupportedConeT::ZeroConeT(k),
            SupportedConeT::NonnegativeConeT(2 * n_thrusters),
        ];
        let solver = if k == 0 {
            None
        } else {
            DefaultSolver::new(&p, &q, &a, &b, &cones, clarabel_settings()).ok()
        };
        Ok(Self {
            n_thrusters,
            rows,
            u_min: u_min.to_vec(),
            u_max: u_max.to_vec(),
            solver,
            nz,
            b,
            t_ref,
        })
    }

    /// The authority of `t` (6×n_thrusters, base frame, moments about the base origin) about
    /// `reference` (base frame [m]) with every thruster available. Errors only on bad input
    /// (dimensions, non-finite values).
    pub fn solve(
        &mut self,
        t: &Matrix6xX<f64>,
        reference: &Vector3<f64>,
    ) -> Result<AttainableAuthority, AllocError> {
        check_t(t, Some(self.n_thrusters))?;
        check_vec("reference", reference.as_slice(), 3)?;
        transport_moments(t, reference, &mut self.t_ref);
        let k = self.rows.len();
        let stride = k + 2;
        for j in 0..self.n_thrusters {
            for (r, &axis) in self.rows.iter().enumerate() {
                self.nz[j * stride + r] = self.t_ref[(axis, j)];
            }
        }
        self.set_bounds(None);
        Ok(self.programmes())
    }

    /// The authority of the `T` of the last [`AuthoritySolver::solve`] with thruster `removed`
    /// held at zero thrust (its bounds set to `[0, 0]`): the N−1 authority. All NaN for an
    /// index out of range.
    pub fn solve_without(&mut self, removed: usize) -> AttainableAuthority {
        if removed >= self.n_thrusters {
            return AttainableAuthority::NAN;
        }
        self.set_bounds(Some(removed));
        let out = self.programmes();
        self.set_bounds(None);
        out
    }

    /// `b`'s box rows: the bounds, with thruster `removed` (if any) at `[0, 0]`.
    fn set_bounds(&mut self, removed: Option<usize>) {
        let (k, n) = (self.rows.len(), self.n_thrusters);
        for j in 0..n {
            let off = removed == Some(j);
            self.b[k + j] = if off { 0.0 } else { self.u_max[j] };
            self.b[k + n + j] = if off { 0.0 } else { -self.u_min[j] };
        }
    }

    /// The 2·k programmes on the current data.
    fn programmes(&mut self) -> AttainableAuthority {
        let mut out = AttainableAuthority::NAN;
        let Some(solver) = self.solver.as_mut() else {
            return out;
        };
        if solver.update_b(&self.b).is_err() {
            return out;
        }
        let k = self.rows.len();
        let alpha_start = self.n_thrusters * (k + 2);
        for (r, &axis) in self.rows.iter().enumerate() {
            for sign in [1.0, -1.0] {
                for i in 0..k {
                    self.nz[alpha_start + i] = if i == r { -sign } else { 0.0 };
                }
                if solver.update_A(&self.nz).is_err() {
                    return AttainableAuthority::NAN;
                }
                solver.solve();
                let sol = &solver.solution;
                let alpha = if matches!(
                    sol.status,
                    SolverStatus::Solved | SolverStatus::AlmostSolved
                ) {
                    sol.x[self.n_thrusters].max(0.0)
                } else {
                    f64::NAN
                };
                if sign > 0.0 {
                    out.positive[axis] = alpha;
                } else {
                    out.negative[axis] = alpha;
                }
            }
        }
        out
    }
}

/// Attainable authority along each commanded axis (`commanded`, surge … yaw) of `t`
/// (6×n_thrusters, base frame, moments about the base origin) about `reference` (base frame
/// [m]) within `u_min ≤ u ≤ u_max` (N): the other commanded axes held at zero, the uncommanded
/// ones free (docs/model.md §6). Errors only on bad input.
pub fn attainable_authority(
    t: &Matrix6xX<f64>,
    u_min: &[f64],
    u_max: &[f64],
    commanded: [bool; 6],
    reference: &Vector3<f64>,
) -> Result<AttainableAuthority, AllocError> {
    AuthoritySolver::new(t, u_min, u_max, commanded, reference)?.solve(t, reference)
}

/// The N−1 authority of [`attainable_authority`]: element `i` is the authority with thruster
/// `i` removed (held at zero thrust). Errors only on bad input.
pub fn attainable_authority_n1(
    t: &Matrix6xX<f64>,
    u_min: &[f64],
    u_max: &[f64],
    commanded: [bool; 6],
    reference: &Vector3<f64>,
) -> Result<Vec<AttainableAuthority>, AllocError> {
    let mut s = AuthoritySolver::new(t, u_min, u_max, commanded, reference)?;
    s.solve(t, reference)?;
    Ok((0..t.ncols()).map(|i| s.solve_without(i)).collect())
}

#[cfg(test)]
#[path = "authority_tests.rs"]
mod tests;

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
//! **Solvers.** Each programme — `max α` s.t. `S T_r u − s α e_k = 0`, the box, `α ≥ 0`, at most
//! 6 equality rows — is solved exactly by the dedicated bounded-variable simplex of
//! `authority_lp`, started from `u = 0` (feasible whenever every box contains zero thrust) and a
//! crash basis shared by the `2k` programmes of a configuration, with a duality-gap
//! certificate, in about a microsecond and without allocating. Each programme starts from the
//! same crash, a function of the configuration's data, so its answer is a function of its own
//! data: bit-identical for any order and any number of workers.
//!
//! Clarabel is the fallback: for a programme the simplex cannot certify, and for every programme
//! when some box excludes zero (the programme may then be infeasible: NaN). One Clarabel solver
//! is built per [`AuthoritySolver`], on first use, from the data the [`AuthoritySolver`] was
//! constructed with (which fixes its equilibration), and reused: only the values of `A` (the
//! configuration's `T_r` and the `α` column) and of `b` (the bounds of a removed thruster)
//! change, updated in place. Clarabel keeps no state between solves except that equilibration,
//! so its answers too depend only on the construction data and the programme's data. It is also
//! the reference of the tests (`authority_lp_tests`).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{Matrix6xX, Vector3};
use serde::Serialize;

use super::authority_lp::BoxLp;
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

/// The authority programmes of a vehicle's thrusters (see the module documentation): built
/// once, then [`AuthoritySolver::solve`] per configuration and
/// [`AuthoritySolver::solve_without`] per removed thruster.
///
/// Each programme is solved by the dedicated simplex of `authority_lp` (exact vertex, no
/// allocation, ≈ 1 µs) when every box contains zero thrust; a programme whose answer that
/// solver cannot certify (the duality gap, residual or clamp above its tolerances, or its
/// iteration cap), and every programme when a box excludes zero thrust, goes to Clarabel
/// ([`AuthoritySolver::clarabel_programmes`] counts them).
pub struct AuthoritySolver {
    n_thrusters: usize,
    /// The commanded axes, in order (the rows of the equality block).
    rows: Vec<usize>,
    u_min: Vec<f64>,
    u_max: Vec<f64>,
    /// Whether the dedicated solver applies (`u_min ≤ 0 ≤ u_max` for every thruster).
    dedicated: bool,
    /// The dedicated solver's workspace.
    lp: BoxLp,
    /// The fallback and reference solver.
    clarabel: ClarabelProgrammes,
    /// The thruster held at zero by [`AuthoritySolver::solve_without`], during it.
    removed: Option<usize>,
    /// `T_r` of the last [`AuthoritySolver::solve`].
    t_ref: Matrix6xX<f64>,
}

impl AuthoritySolver {
    /// A solver for `t` (6×n_thrusters, base frame, N and N·m per N), bounds `u_min ≤ u ≤
    /// u_max` (N) and the `commanded` axes (surge … yaw), with `t`'s moments about
    /// `reference` (base frame [m]); `t` also fixes the equilibration of the Clarabel fallback
    /// (built from it on first use). Errors only on bad input.
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
        let mut t_ref = Matrix6xX::zeros(n_thrusters);
        transport_moments(t, reference, &mut t_ref);
        let dedicated = u_min
            .iter()
            .zip(u_max)
            .all(|(&lo, &hi)| lo <= 0.0 && 0.0 <= hi);
        Ok(Self {
            n_thrusters,
            lp: BoxLp::new(n_thrusters, rows.len()),
            clarabel: ClarabelProgrammes::new(&t_ref, &rows, u_min, u_max),
            rows,
            u_min: u_min.to_vec(),
            u_max: u_max.to_vec(),
            dedicated,
            removed: None,
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
        self.removed = None;
        Ok(self.programmes())
    }

    /// The authority of the `T` of the last [`AuthoritySolver::solve`] with thruster `removed`
    /// held at zero thrust (its bounds set to `[0, 0]`): the N−1 authority. All NaN for an
    /// index out of range.
    pub fn solve_without(&mut self, removed: usize) -> AttainableAuthority {
        if removed >= self.n_thrusters {
            return AttainableAuthority::NAN;
        }
        self.removed = Some(removed);
        let out = self.programmes();
        self.removed = None;
        out
    }

    /// Programmes solved by Clarabel since this solver was built: those the dedicated solver
    /// could not certify, or all of them when a thrust box excludes zero.
    pub fn clarabel_programmes(&self) -> usize {
        self.clarabel.solves
    }

    /// Solve every programme with Clarabel from now on (the reference of the tests).
    #[cfg(test)]
    pub(crate) fn clarabel_only(mut self) -> Self {
        self.dedicated = false;
        self
    }

    /// The 2·k programmes on the current data.
    fn programmes(&mut self) -> AttainableAuthority {
        let mut out = AttainableAuthority::NAN;
        if self.rows.is_empty() {
            return out;
        }
        if self.dedicated {
            self.load();
        }
        for r in 0..self.rows.len() {
            let axis = self.rows[r];
            for sign in [1.0, -1.0] {
                let alpha = self
                    .dedicated
                    .then(|| self.lp.solve(r, sign))
                    .flatten()
                    .unwrap_or_else(|| {
                        self.clarabel.solve(
                            &self.t_ref,
                            &self.rows,
                            (&self.u_min, &self.u_max, self.removed),
                            (r, sign),
                        )
                    });
                if sign > 0.0 {
                    out.positive[axis] = alpha;
                } else {
                    out.negative[axis] = alpha;
                }
            }
        }
        out
    }

    /// The dedicated solver's data: `M = S T_r`, the boxes (the removed thruster's `[0, 0]`),
    /// and its crash basis.
    fn load(&mut self) {
        for j in 0..self.n_thrusters {
            let col = self.lp.column(j);
            for (slot, &axis) in col.iter_mut().zip(&self.rows) {
                *slot = self.t_ref[(axis, j)];
            }
            let (lo, hi) = if self.removed == Some(j) {
                (0.0, 0.0)
            } else {
                (self.u_min[j], self.u_max[j])
            };
            self.lp.set_bounds(j, lo, hi);
        }
        self.lp.crash();
    }
}

/// The Clarabel solver of [`ClarabelProgrammes`].
enum Fallback {
    /// Not needed yet.
    Unbuilt,
    /// Built from the constructor's data.
    Built(Box<DefaultSolver<f64>>),
    /// Clarabel refused the data: every answer NaN.
    Refused,
}

/// The Clarabel form of the programmes, `x = [u; α]`: `k` equalities `[S T_r, −s e_k] x = 0`,
/// then the box rows. Built on first use from the constructor's data (which fixes its
/// equilibration), so its answers depend only on that data and the programme's.
struct ClarabelProgrammes {
    /// The solver, once built.
    solver: Fallback,
    /// The constructor's `A` values, column-major (per thruster `k` rows of `S T_r` then its
    /// two box rows; then the `α` column), and `b`.
    build: (Vec<f64>, Vec<f64>),
    nz: Vec<f64>,
    b: Vec<f64>,
    /// Programmes solved.
    solves: usize,
}

impl ClarabelProgrammes {
    fn new(t_ref: &Matrix6xX<f64>, rows: &[usize], u_min: &[f64], u_max: &[f64]) -> Self {
        let (k, n) = (rows.len(), t_ref.ncols());
        let mut nz = vec![0.0; n * (k + 2) + k];
        let mut b = vec![0.0; k + 2 * n];
        Self::fill(&mut nz, t_ref, rows, 0, 1.0);
        Self::fill_bounds(&mut b, k, u_min, u_max, None);
        Self {
            solver: Fallback::Unbuilt,
            build: (nz.clone(), b.clone()),
            nz,
            b,
            solves: 0,
        }
    }

    /// `A`'s values for the programme of row `r` and sign `sign`.
    fn fill(nz: &mut [f64], t_ref: &Matrix6xX<f64>, rows: &[usize], r: usize, sign: f64) {
        let k = rows.len();
        for j in 0..t_ref.ncols() {
            let col = &mut nz[j * (k + 2)..(j + 1) * (k + 2)];
            for (i, &axis) in rows.iter().enumerate() {
                col[i] = t_ref[(axis, j)];
            }
            col[k] = 1.0;
            col[k + 1] = -1.0;
        }
        let alpha = &mut nz[t_ref.ncols() * (k + 2)..];
        for (i, a) in alpha.iter_mut().enumerate() {
            *a = if i == r { -sign } else { 0.0 };
        }
    }

    /// `b`'s box rows: the bounds, with thruster `removed` (if any) at `[0, 0]`.
    fn fill_bounds(b: &mut [f64], k: usize, u_min: &[f64], u_max: &[f64], removed: Option<usize>) {
        let n = u_min.len();
        for j in 0..n {
            let off = removed == Some(j);
            b[k + j] = if off { 0.0 } else { u_max[j] };
            b[k + n + j] = if off { 0.0 } else { -u_min[j] };
        }
    }

    /// Build the solver from the constructor's data.
    fn build(&self, k: usize, n_thrusters: usize) -> Fallback {
        let n = n_thrusters + 1;
        let m = k + 2 * n_thrusters;
        let mut colptr = Vec::with_capacity(n + 1);
        let mut rowval = Vec::with_capacity(self.nz.len());
        for j in 0..n_thrusters {
            colptr.push(rowval.len());
            rowval.extend(0..k);
            rowval.push(k + j);
            rowval.push(k + n_thrusters + j);
        }
        colptr.push(rowval.len());
        rowval.extend(0..k);
        colptr.push(rowval.len());
        let a = CscMatrix::new(m, n, colptr, rowval, self.build.0.clone());
        let p = CscMatrix::zeros((n, n));
        let mut q = vec![0.0; n];
        q[n_thrusters] = -1.0;
        let cones = [
            SupportedConeT::ZeroConeT(k),
            SupportedConeT::NonnegativeConeT(2 * n_thrusters),
        ];
        match DefaultSolver::new(&p, &q, &a, &self.build.1, &cones, clarabel_settings()) {
            Ok(s) => Fallback::Built(Box::new(s)),
            Err(_) => Fallback::Refused,
        }
    }

    /// `max α` of the programme of row `r` (of `rows`) and sign `s`, on `T_r` and the bounds
    /// (`u_min`, `u_max`, the removed thruster); NaN when Clarabel fails.
    fn solve(
        &mut self,
        t_ref: &Matrix6xX<f64>,
        rows: &[usize],
        (u_min, u_max, removed): (&[f64], &[f64], Option<usize>),
        (r, s): (usize, f64),
    ) -> f64 {
        self.solves += 1;
        let (k, n) = (rows.len(), t_ref.ncols());
        if matches!(self.solver, Fallback::Unbuilt) {
            self.solver = self.build(k, n);
        }
        Self::fill(&mut self.nz, t_ref, rows, r, s);
        Self::fill_bounds(&mut self.b, k, u_min, u_max, removed);
        let Fallback::Built(solver) = &mut self.solver else {
            return f64::NAN;
        };
        if solver.update_A(&self.nz).is_err() || solver.update_b(&self.b).is_err() {
            return f64::NAN;
        }
        solver.solve();
        let sol = &solver.solution;
        if matches!(
            sol.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ) {
            sol.x[n].max(0.0)
        } else {
            f64::NAN
        }
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

#[cfg(test)]
#[path = "authority_reference_tests.rs"]
mod reference_tests;

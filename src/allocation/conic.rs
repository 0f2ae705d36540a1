//! Clarabel formulations of the constrained allocation forms (docs/model.md §5).
//!
//! Clarabel solves `min ½xᵀPx + qᵀx` s.t. `Ax + s = b`, `s ∈ K`. With `n_u` thrusters
//! (`n_uhrusters` in the code) the variables are
//! `x = [u (n_u) | s (6, slack-kept form only) | t (1 for minimax, n_u for power)]` and the rows
//! are, in order:
//! 1. slack-kept form only: `ZeroConeT(6)`, `T u − s = τ`;
//! 2. `NonnegativeConeT`: `u_j ≤ hi_j` (n_u rows), `−u_j ≤ −lo_j` (n_u rows) and, for minimax,
//!    `u_j − t ≤ 0` (n_u rows), `−u_j − t ≤ 0` (n_u rows);
//! 3. power only: n_u × `PowerConeT(2/3)` on `(t_j, 1, u_j)`, i.e. `|u_j|^{3/2} ≤ t_j`.
//!
//! `P` carries the factor 2 that turns Clarabel's ½ into the module's ½-free objectives. In the
//! slack-eliminated form `s = T u − τ` is substituted, giving `P_uu = 2(diag(c + r) + q TᵀT)` and
//! `q_u = −2(q Tᵀτ + r ∘ u_prev)`; the constant `q‖τ‖² + Σ r_j u_prev,j²` is dropped.
//! The sparsity pattern depends only on method, n_thrusters and formulation (structural zeros are kept), so
//! one solver is built and its data updated in place (`update_P/q/A/b`) on every later step.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{Matrix6xX, Vector6};

use super::settings::{Formulation, Method};

/// Inputs of one constrained allocation step.
pub(crate) struct Params<'a> {
    pub t: &'a Matrix6xX<f64>,
    pub tau: &'a Vector6<f64>,
    /// Effective lower bound (bounds ∩ rate limit), N.
    pub lo: &'a [f64],
    /// Effective upper bound, N.
    pub hi: &'a [f64],
    pub w: &'a [f64],
    pub rate_w: &'a [f64],
    pub u_prev: &'a [f64],
    pub q: f64,
    pub eps: f64,
}

/// What one solve produced.
pub(crate) struct Outcome {
    pub ok: bool,
    pub status_text: &'static str,
    pub iterations: u32,
}

/// Row and column layout of the conic problem.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Layout {
    pub n_thrusters: usize,
    /// Number of variables.
    pub n: usize,
    /// Number of constraint rows.
    pub rows: usize,
    /// First slack variable (slack-kept form), else `n`.
    pub s0: Option<usize>,
    /// First epigraph variable t (read by the KKT tests).
    #[cfg_attr(not(test), allow(dead_code))]
    pub t0: usize,
    /// First box row.
    pub r_box: usize,
    /// First minimax row (minimax only).
    pub r_mm: usize,
    /// First power-cone row (power only).
    pub r_pow: usize,
}

/// A constrained allocation problem with its (reused) Clarabel solver.
pub(crate) struct ConicProblem {
    method: Method,
    formulation: Formulation,
    reuse: bool,
    layout: Layout,
    p_colptr: Vec<usize>,
    p_rowval: Vec<usize>,
    p_nz: Vec<f64>,
    q: Vec<f64>,
    a_colptr: Vec<usize>,
    a_rowval: Vec<usize>,
    a_nz: Vec<f64>,
    b: Vec<f64>,
    cones: Vec<SupportedConeT<f64>>,
    settings: DefaultSettings<f64>,
    solver: Option<DefaultSolver<f64>>,
}

/// Clarabel settings for allocation: silent, no presolve, structural zeros kept (so that the
/// data can be updated in place, see NOTES.md), iterative refinement off (measured ~30 % faster
/// on the 7-thruster problems with the KKT tests still met to 1e-6 and no extra failures over
/// 4 500 random problems; re-measured for issue 11: turning it back on costs +60–80 % CPU time
/// per solve).
///
/// Also measured for issue 11 (CPU time of 3 840 solves with every bound-active, 64 bent-USM
/// T's, loaded 2-core machine, best of 3): without equilibration, with 3 instead of 10
/// equilibration passes, or without static regularisation, `qp` and `minimax` change by
/// −2 … +4 % with the same iteration counts (11.0 and 13.0 per solve) — noise, so Clarabel's
/// defaults stay (static regularisation also guards the quasi-definite KKT factorisation).
/// Presolve only drops rows with infinite bounds, which these problems never have (no change);
/// the direct solve method has one choice here (`qdldl`; `faer` is a cargo feature not
/// enabled). Tolerances stay at 1e-8: looser ones would trade exactness for iterations.
pub(crate) fn clarabel_settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        presolve_enable: false,
        input_sparse_dropzeros: false,
        iterative_refinement_enable: false,
        ..DefaultSettings::default()
    }
}

/// Clarabel's status as static text.
pub(crate) fn status_text(s: SolverStatus) -> &'static str {
    match s {
        SolverStatus::Unsolved => "Unsolved",
        SolverStatus::Solved => "Solved",
        SolverStatus::PrimalInfeasible => "PrimalInfeasible",
        SolverStatus::DualInfeasible => "DualInfeasible",
        SolverStatus::AlmostSolved => "AlmostSolved",
        SolverStatus::AlmostPrimalInfeasible => "AlmostPrimalInfeasible",
        SolverStatus::AlmostDualInfeasible => "AlmostDualInfeasible",
        SolverStatus::MaxIterations => "MaxIterations",
        SolverStatus::MaxTime => "MaxTime",
        SolverStatus::NumericalError => "NumericalError",
        SolverStatus::InsufficientProgress => "InsufficientProgress",
        SolverStatus::CallbackTerminated => "CallbackTerminated",
    }
}

impl ConicProblem {
    pub(crate) fn new(
        method: Method,
        n_thrusters: usize,
        formulation: Formulation,
        reuse: bool,
        tol: f64,
    ) -> Self {
        let n_s = match formulation {
            Formulation::SlackKept => 6,
            Formulation::SlackEliminated => 0,
        };
        let n_epi = match method {
            Method::Minimax => 1,
            Method::Power => n_thrusters,
            _ => 0,
        };
        let r_box = n_s;
        let r_mm = r_box + 2 * n_thrusters;
        let n_mm = if method == Method::Minimax {
            2 * n_thrusters
        } else {
            0
        };
        let r_pow = r_mm + n_mm;
        let n_pow = if method == Method::Power {
            3 * n_thrusters
        } else {
            0
        };
        let layout = Layout {
            n_thrusters,
            n: n_thrusters + n_s + n_epi,
            rows: r_pow + n_pow,
            s0: (n_s > 0).then_some(n_thrusters),
            t0: n_thrusters + n_s,
            r_box,
            r_mm,
            r_pow,
        };
        let mut cones = Vec::with_capacity(2 + n_thrusters);
        if n_s > 0 {
            cones.push(SupportedConeT::ZeroConeT(6));
        }
        cones.push(SupportedConeT::NonnegativeConeT(2 * n_thrusters + n_mm));
        if method == Method::Power {
            for _ in 0..n_thrusters {
                cones.push(SupportedConeT::PowerConeT(2.0 / 3.0));
            }
        }
        Self {
            method,
            formulation,
            reuse,
            layout,
            p_colptr: Vec::with_capacity(layout.n + 1),
            p_rowval: Vec::with_capacity(n_thrusters * (n_thrusters + 1) / 2 + n_s),
            p_nz: Vec::with_capacity(n_thrusters * (n_thrusters + 1) / 2 + n_s),
            q: Vec::with_capacity(layout.n),
            a_colptr: Vec::with_capacity(layout.n + 1),
            a_rowval: Vec::with_capacity(n_thrusters * 12 + 2 * n_thrusters + n_s),
            a_nz: Vec::with_capacity(n_thrusters * 12 + 2 * n_thrusters + n_s),
            b: Vec::with_capacity(layout.rows),
            cones,
            settings: DefaultSettings {
                tol_gap_abs: tol,
                tol_gap_rel: tol,
                tol_feas: tol,
                ..clarabel_settings()
            },
            solver: None,
        }
    }

    #[cfg(test)]
    pub(crate) fn layout(&self) -> Layout {
        self.layout
    }

    /// Limit the interior-point iterations (tests force a solver failure with it).
    #[cfg(test)]
    pub(crate) fn set_max_iter(&mut self, n: u32) {
        self.settings.max_iter = n;
        self.solver = None;
    }

    /// Clarabel's last solution (test access to primal and dual values).
    #[cfg(test)]
    pub(crate) fn solution(&self) -> Option<&clarabel::solver::DefaultSolution<f64>> {
        self.solver.as_ref().map(|s| &s.solution)
    }

    /// Fill pattern and values of P, q, A, b for `p` (buffers are cleared and refilled; after the
    /// first call their capacity suffices, so nothing is allocated).
    fn assemble(&mut self, p: &Params<'_>) {
        self.assemble_objective(p);
        self.assemble_constraints(p);
        self.assemble_rhs(p);
        debug_assert_eq!(self.q.len(), self.layout.n);
        debug_assert_eq!(self.b.len(), self.layout.rows);
    }

    /// `P` (upper triangle, column-major) and `q`: the weights, rate and slack terms (with
    /// `q TᵀT` in the slack-eliminated form), the minimax `t` and the power epigraph costs.
    fn assemble_objective(&mut self, p: &Params<'_>) {
        let l = self.layout;
        let n_thrusters = l.n_thrusters;
        let eliminated = self.formulation == Formulation::SlackEliminated;
        let (pc, pr, pv) = (&mut self.p_colptr, &mut self.p_rowval, &mut self.p_nz);
        pc.clear();
        pr.clear();
        pv.clear();
        self.q.clear();
        for j in 0..n_thrusters {
            pc.push(pr.len());
            let base = match self.method {
                Method::Qp => p.w[j],
                Method::Minimax => p.eps,
                _ => 0.0,
            };
            let diag = 2.0 * (base + p.rate_w[j]);
            let cj = p.t.fixed_view::<6, 1>(0, j);
            if eliminated {
                for i in 0..=j {
                    let ci = p.t.fixed_view::<6, 1>(0, i);
                    let mut v = 2.0 * p.q * ci.dot(&cj);
                    if i == j {
                        v += diag;
                    }
                    pr.push(i);
                    pv.push(v);
                }
                self.q
                    .push(-2.0 * (p.q * cj.dot(p.tau) + p.rate_w[j] * p.u_prev[j]));
            } else {
                pr.push(j);
                pv.push(diag);
                self.q.push(-2.0 * p.rate_w[j] * p.u_prev[j]);
            }
        }
        if let Some(s0) = l.s0 {
            for i in 0..6 {
                pc.push(pr.len());
                pr.push(s0 + i);
                pv.push(2.0 * p.q);
                self.q.push(0.0);
            }
        }
        match self.method {
            Method::Minimax => {
                pc.push(pr.len());
                self.q.push(1.0);
            }
            Method::Power => {
                for j in 0..n_thrusters {
                    pc.push(pr.len());
                    self.q.push(p.w[j]);
                }
            }
            _ => {}
        }
        pc.push(pr.len());
    }

    /// `A` (column-major, rows ascending): `T u − s` (slack-kept form), the box rows, the
    /// minimax rows and the power-cone rows, in the order of the module doc.
    fn assemble_constraints(&mut self, p: &Params<'_>) {
        let l = self.layout;
        let n_thrusters = l.n_thrusters;
        let (ac, ar, av) = (&mut self.a_colptr, &mut self.a_rowval, &mut self.a_nz);
        ac.clear();
        ar.clear();
        av.clear();
        for j in 0..n_thrusters {
            ac.push(ar.len());
            if l.s0.is_some() {
                for i in 0..6 {
                    ar.push(i);
                    av.push(p.t[(i, j)]);
                }
            }
            ar.push(l.r_box + j);
            av.push(1.0);
            ar.push(l.r_box + n_thrusters + j);
            av.push(-1.0);
            if self.method == Method::Minimax {
                ar.push(l.r_mm + j);
                av.push(1.0);
                ar.push(l.r_mm + n_thrusters + j);
                av.push(-1.0);
            }
            if self.method == Method::Power {
                ar.push(l.r_pow + 3 * j + 2);
                av.push(-1.0);
            }
        }
        if l.s0.is_some() {
            for i in 0..6 {
                ac.push(ar.len());
                ar.push(i);
                av.push(-1.0);
            }
        }
        match self.method {
            Method::Minimax => {
                ac.push(ar.len());
                for r in 0..2 * n_thrusters {
                    ar.push(l.r_mm + r);
                    av.push(-1.0);
                }
            }
            Method::Power => {
                for j in 0..n_thrusters {
                    ac.push(ar.len());
                    ar.push(l.r_pow + 3 * j);
                    av.push(-1.0);
                }
            }
            _ => {}
        }
        ac.push(ar.len());
    }

    /// `b`: `τ` (slack-kept form), the bounds `hi`, `−lo`, and the cone constants.
    fn assemble_rhs(&mut self, p: &Params<'_>) {
        let l = self.layout;
        let n_thrusters = l.n_thrusters;
        self.b.clear();
        if l.s0.is_some() {
            self.b.extend_from_slice(p.tau.as_slice());
        }
        self.b.extend_from_slice(p.hi);
        self.b.extend(p.lo.iter().map(|x| -x));
        if self.method == Method::Minimax {
            self.b.extend(std::iter::repeat_n(0.0, 2 * n_thrusters));
        }
        if self.method == Method::Power {
            for _ in 0..n_thrusters {
                self.b.extend_from_slice(&[0.0, 1.0, 0.0]);
            }
        }
    }

    /// Update the existing solver in place; false if that is not possible.
    fn update(&mut self) -> bool {
        let Some(solver) = self.solver.as_mut() else {
            return false;
        };
        if !solver.is_data_update_allowed() {
            return false;
        }
        solver.update_P(&self.p_nz).is_ok()
            && solver.update_q(&self.q).is_ok()
            && solver.update_A(&self.a_nz).is_ok()
            && solver.update_b(&self.b).is_ok()
    }

    fn rebuild(&mut self) -> bool {
        let l = self.layout;
        let p = CscMatrix::new(
            l.n,
            l.n,
            self.p_colptr.clone(),
            self.p_rowval.clone(),
            self.p_nz.clone(),
        );
        let a = CscMatrix::new(
            l.rows,
            l.n,
            self.a_colptr.clone(),
            self.a_rowval.clone(),
            self.a_nz.clone(),
        );
        match DefaultSolver::new(&p, &self.q, &a, &self.b, &self.cones, self.settings.clone()) {
            Ok(s) => {
                self.solver = Some(s);
                true
            }
            Err(_) => {
                self.solver = None;
                false
            }
        }
    }

    /// Solve for `p`, writing the thrusts (clipped to `[lo, hi]` against interior-point
    /// round-off) into `u` on success.
    pub(crate) fn solve(&mut self, p: &Params<'_>, u: &mut [f64]) -> Outcome {
        self.assemble(p);
        let updated = self.reuse && self.update();
        if !updated && !self.rebuild() {
            return Outcome {
                ok: false,
                status_text: "SetupError",
                iterations: 0,
            };
        }
        let Some(solver) = self.solver.as_mut() else {
            return Outcome {
                ok: false,
                status_text: "SetupError",
                iterations: 0,
            };
        };
        solver.solve();
        let sol = &solver.solution;
        let status = sol.status;
        let x = &sol.x[..self.layout.n_thrusters];
        let usable = matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved)
            && x.iter().all(|v| v.is_finite());
        if usable {
            for (j, uj) in u.iter_mut().enumerate() {
                *uj = x[j].clamp(p.lo[j], p.hi[j]);
            }
        }
        Outcome {
            ok: usable,
            status_text: status_text(status),
            iterations: sol.iterations,
        }
    }
}

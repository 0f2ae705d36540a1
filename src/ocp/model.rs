//! The discrete dynamics an optimal-control problem is posed on (docs/ocp.md §2):
//! `x_{k+1} = f(x_k, u_k)` on a manifold, with a retraction `x ⊕ δ` and its inverse
//! `x₁ ⊖ x₀` on the tangent space (size nx), and a terminal equality `c(x_N) = 0`.
//!
//! Derivatives default to central differences in tangent coordinates,
//! `∂f/∂x e_i ≈ (f(x ⊕ εe_i, u) ⊖ f(x ⊕ −εe_i, u)) ⊖-relative to f(x, u) / 2ε` with ε = 1e-6
//! (truncation O(ε²), rounding O(1e-16/ε)); an implementation may override them with
//! analytic ones.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use nalgebra::{DMatrix, DVector};

/// Error of a model evaluation (a singular mass matrix, a non-finite state): `what` failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("dynamics failed: {0}")]
pub struct ModelError(pub String);

/// Step of the central differences in tangent coordinates.
pub const FD_STEP: f64 = 1e-6;

/// Step of the forward second differences of the Lagrangian Hessians (truncation O(ε),
/// rounding O(1e-16/ε²) relative to the weighted state).
pub const HESS_STEP: f64 = 1e-4;

/// `wᵀ (f(x ⊕ δx, u + δu) ⊖ f0)` for the perturbation `Σ_{i ∈ idx} ε e_i` of `(δx, δu)`.
#[allow(clippy::too_many_arguments)]
fn weighted_step<M: OcpModel + ?Sized>(
    m: &mut M,
    x: &[f64],
    u: &[f64],
    w: &[f64],
    f0: &[f64],
    idx: &[usize],
    buf: &mut HessBuf,
) -> Result<f64, ModelError> {
    let nx = buf.e.len();
    buf.e.fill(0.0);
    buf.u.copy_from_slice(u);
    for &i in idx {
        if i < nx {
            buf.e[i] += HESS_STEP;
        } else {
            buf.u[i - nx] += HESS_STEP;
        }
    }
    m.retract(x, &buf.e, &mut buf.xp);
    m.step(&buf.xp, &buf.u, &mut buf.fp)?;
    m.difference(f0, &buf.fp, &mut buf.d);
    Ok(w.iter().zip(&buf.d).map(|(a, b)| a * b).sum())
}

/// Scratch of [`OcpModel::weighted_hessian`].
struct HessBuf {
    e: Vec<f64>,
    u: Vec<f64>,
    xp: Vec<f64>,
    fp: Vec<f64>,
    d: Vec<f64>,
    phi: Vec<f64>,
}

/// Scratch of the chain's structured differences (`ocp::derivatives`), sized on first use.
#[derive(Clone, Debug, Default)]
pub struct FdScratch {
    pub(super) f0: Vec<f64>,
    pub(super) xp: Vec<f64>,
    pub(super) fp: Vec<f64>,
    pub(super) fm: Vec<f64>,
    pub(super) dp: Vec<f64>,
    pub(super) dm: Vec<f64>,
    pub(super) e: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) phi: Vec<f64>,
    pub(super) bias: Vec<f64>,
    pub(super) mass: Option<faer::Mat<f64>>,
    pub(super) gmap: Option<faer::Mat<f64>>,
}

impl FdScratch {
    pub(super) fn size(&mut self, nq: usize, nx: usize, nu: usize) {
        for (v, n) in [
            (&mut self.f0, nq),
            (&mut self.xp, nq),
            (&mut self.fp, nq),
            (&mut self.fm, nq),
            (&mut self.dp, nx),
            (&mut self.dm, nx),
            (&mut self.e, nx),
            (&mut self.u, nu),
            (&mut self.phi, nx + nu),
        ] {
            v.resize(n, 0.0);
        }
    }
}

/// Discrete dynamics on a manifold, with a terminal equality (see the module documentation).
pub trait OcpModel {
    /// Size of the state's representation (e.g. 13 + 2n with a unit quaternion).
    fn nq(&self) -> usize;
    /// Size of the tangent space (the Newton variables of a state).
    fn nx(&self) -> usize;
    /// Number of controls.
    fn nu(&self) -> usize;
    /// Number of terminal equalities.
    fn nc(&self) -> usize;
    /// `out = f(x, u)` (representations, nq).
    fn step(&mut self, x: &[f64], u: &[f64], out: &mut [f64]) -> Result<(), ModelError>;
    /// `out = x ⊕ dx` (dx in the tangent space at x).
    fn retract(&self, x: &[f64], dx: &[f64], out: &mut [f64]);
    /// `out = x1 ⊖ x0`, the tangent vector at x0 with `x0 ⊕ out = x1`.
    fn difference(&self, x0: &[f64], x1: &[f64], out: &mut [f64]);
    /// `out = c(x)` (nc).
    fn terminal(&mut self, x: &[f64], out: &mut [f64]);

    /// Whether the model adds path costs ([`OcpModel::stage_cost`],
    /// [`OcpModel::terminal_cost`]) to the quadratic objective. Default no.
    fn has_path_costs(&self) -> bool {
        false
    }

    /// Stage cost `l(x_k, u_k)` added to the objective for every k < N (0 unless
    /// overridden); `+∞` outside its domain (a barrier), which the line search rejects.
    fn stage_cost(&mut self, _x: &[f64], _u: &[f64]) -> f64 {
        0.0
    }

    /// Add the gradient (`g`, nx + nu, order `[δx, δu]`, tangent coordinates at x) and the
    /// Hessian (`h`, (nx+nu)²) of [`OcpModel::stage_cost`]; with `exact` false, a positive
    /// semidefinite part of the Hessian only (for Gauss–Newton iterations, which are not
    /// convexified).
    fn stage_cost_derivatives(
        &mut self,
        _x: &[f64],
        _u: &[f64],
        _exact: bool,
        _g: &mut [f64],
        _h: &mut DMatrix<f64>,
    ) {
    }

    /// Largest step α ≤ 1 along the tangent step `dx` at x that keeps the stage cost's
    /// barrier domain by the fraction to the boundary (1 unless overridden).
    fn max_step(&mut self, _x: &[f64], _dx: &[f64]) -> f64 {
        1.0
    }

    /// Terminal cost `l_N(x_N)` added to the objective (0 unless overridden).
    fn terminal_cost(&mut self, _x: &[f64]) -> f64 {
        0.0
    }

    /// Add the gradient (nx) and Hessian (nx×nx) of [`OcpModel::terminal_cost`].
    fn terminal_cost_derivatives(&mut self, _x: &[f64], _g: &mut [f64], _h: &mut DMatrix<f64>) {}

    /// `A = ∂f/∂x` (nx×nx) and `B = ∂f/∂u` (nx×nu) at (x, u), tangent coordinates; central
    /// differences unless overridden.
    fn jacobians(
        &mut self,
        x: &[f64],
        u: &[f64],
        a: &mut DMatrix<f64>,
        b: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        central_jacobians(self, x, u, a, b)
    }

    /// `H = ∇²φ` ((nx+nu)², order `[δx, δu]`) of `φ(δx, δu) = wᵀ (f(x ⊕ δx, u + δu) ⊖ f(x, u))`
    /// at 0: the dynamics' curvature weighted by the costate `w` (nx), the exact-Hessian
    /// term of the Lagrangian. Forward second differences with step [`HESS_STEP`]:
    /// `H_ij = (φ(εe_i + εe_j) − φ(εe_i) − φ(εe_j) + φ(0)) / ε²`, `(nx+nu)(nx+nu+3)/2 + 1`
    /// steps. Unless overridden.
    fn weighted_hessian(
        &mut self,
        x: &[f64],
        u: &[f64],
        w: &[f64],
        h: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        second_difference_hessian(self, x, u, w, h)
    }

    /// `H = ∇²ψ` (nx×nx) of `ψ(δ) = νᵀ c(x ⊕ δ)` at 0 (the terminal equality's curvature
    /// weighted by its multiplier ν), forward second differences as
    /// [`OcpModel::weighted_hessian`]; unless overridden.
    fn terminal_hessian(&mut self, x: &[f64], nu: &[f64], h: &mut DMatrix<f64>) {
        let (nq, nx, nc) = (self.nq(), self.nx(), self.nc());
        let mut xp = vec![0.0; nq];
        let mut c = vec![0.0; nc];
        let mut e = vec![0.0; nx];
        let mut psi = |this: &mut Self, e: &[f64]| -> f64 {
            this.retract(x, e, &mut xp);
            this.terminal(&xp, &mut c);
            nu.iter().zip(&c).map(|(a, b)| a * b).sum()
        };
        let p0 = psi(self, &e);
        let mut p1 = vec![0.0; nx];
        for i in 0..nx {
            e[i] = HESS_STEP;
            p1[i] = psi(self, &e);
            e[i] = 0.0;
        }
        let e2 = HESS_STEP * HESS_STEP;
        for i in 0..nx {
            for j in i..nx {
                e[i] += HESS_STEP;
                e[j] += HESS_STEP;
                let v = (psi(self, &e) - p1[i] - p1[j] + p0) / e2;
                e[i] = 0.0;
                e[j] = 0.0;
                h[(i, j)] = v;
                h[(j, i)] = v;
            }
        }
    }

    /// `C = ∂c/∂x` (nc×nx) at x, tangent coordinates; central differences unless overridden.
    fn terminal_jacobian(&mut self, x: &[f64], c: &mut DMatrix<f64>) {
        let (nq, nx, nc) = (self.nq(), self.nx(), self.nc());
        let mut xp = vec![0.0; nq];
        let (mut cp, mut cm) = (vec![0.0; nc], vec![0.0; nc]);
        let mut e = vec![0.0; nx];
        for i in 0..nx {
            e[i] = FD_STEP;
            self.retract(x, &e, &mut xp);
            self.terminal(&xp, &mut cp);
            e[i] = -FD_STEP;
            self.retract(x, &e, &mut xp);
            self.terminal(&xp, &mut cm);
            e[i] = 0.0;
            for r in 0..nc {
                c[(r, i)] = (cp[r] - cm[r]) / (2.0 * FD_STEP);
            }
        }
    }
}

/// `A = ∂f/∂x`, `B = ∂f/∂u` by central differences with step [`FD_STEP`] in tangent
/// coordinates, `2(nx + nu) + 1` steps: the reference path of [`OcpModel::jacobians`].
pub fn central_jacobians<M: OcpModel + ?Sized>(
    m: &mut M,
    x: &[f64],
    u: &[f64],
    a: &mut DMatrix<f64>,
    b: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let (nq, nx, nu) = (m.nq(), m.nx(), m.nu());
    let mut f0 = vec![0.0; nq];
    m.step(x, u, &mut f0)?;
    let (mut xp, mut fp, mut fm) = (vec![0.0; nq], vec![0.0; nq], vec![0.0; nq]);
    let (mut dp, mut dm) = (vec![0.0; nx], vec![0.0; nx]);
    let mut e = vec![0.0; nx];
    for i in 0..nx {
        e[i] = FD_STEP;
        m.retract(x, &e, &mut xp);
        m.step(&xp, u, &mut fp)?;
        e[i] = -FD_STEP;
        m.retract(x, &e, &mut xp);
        m.step(&xp, u, &mut fm)?;
        e[i] = 0.0;
        m.difference(&f0, &fp, &mut dp);
        m.difference(&f0, &fm, &mut dm);
        for r in 0..nx {
            a[(r, i)] = (dp[r] - dm[r]) / (2.0 * FD_STEP);
        }
    }
    let mut up = u.to_vec();
    for i in 0..nu {
        up[i] = u[i] + FD_STEP;
        m.step(x, &up, &mut fp)?;
        up[i] = u[i] - FD_STEP;
        m.step(x, &up, &mut fm)?;
        up[i] = u[i];
        m.difference(&f0, &fp, &mut dp);
        m.difference(&f0, &fm, &mut dm);
        for r in 0..nx {
            b[(r, i)] = (dp[r] - dm[r]) / (2.0 * FD_STEP);
        }
    }
    Ok(())
}

/// `H = ∇²(wᵀ (f(x ⊕ δx, u + δu) ⊖ f(x, u)))` at 0 by forward second differences with step
/// [`HESS_STEP`], `(nx+nu)(nx+nu+3)/2 + 1` steps: the reference path of
/// [`OcpModel::weighted_hessian`].
pub fn second_difference_hessian<M: OcpModel + ?Sized>(
    model: &mut M,
    x: &[f64],
    u: &[f64],
    w: &[f64],
    h: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let (nq, nx, nu) = (model.nq(), model.nx(), model.nu());
    let m = nx + nu;
    let mut f0 = vec![0.0; nq];
    model.step(x, u, &mut f0)?;
    let mut buf = HessBuf {
        e: vec![0.0; nx],
        u: vec![0.0; nu],
        xp: vec![0.0; nq],
        fp: vec![0.0; nq],
        d: vec![0.0; nx],
        phi: vec![0.0; m],
    };
    for i in 0..m {
        buf.phi[i] = weighted_step(model, x, u, w, &f0, &[i], &mut buf)?;
    }
    let e2 = HESS_STEP * HESS_STEP;
    for i in 0..m {
        for j in i..m {
            let pij = weighted_step(model, x, u, w, &f0, &[i, j], &mut buf)?;
            let v = (pij - buf.phi[i] - buf.phi[j]) / e2;
            h[(i, j)] = v;
            h[(j, i)] = v;
        }
    }
    Ok(())
}

/// A linear model `x_{k+1} = A x + B u + w` on ℝⁿ with the terminal equality `C x = c`
/// (the closed-form test problems; exact analytic Jacobians).
#[derive(Clone, Debug)]
pub struct LinearModel {
    /// `A` (nx×nx).
    pub a: DMatrix<f64>,
    /// `B` (nx×nu).
    pub b: DMatrix<f64>,
    /// Offset `w` (nx).
    pub w: DVector<f64>,
    /// `C` (nc×nx).
    pub c: DMatrix<f64>,
    /// Target `c` (nc).
    pub target: DVector<f64>,
}

impl OcpModel for LinearModel {
    fn nq(&self) -> usize {
        self.a.nrows()
    }
    fn nx(&self) -> usize {
        self.a.nrows()
    }
    fn nu(&self) -> usize {
        self.b.ncols()
    }
    fn nc(&self) -> usize {
        self.c.nrows()
    }
    fn step(&mut self, x: &[f64], u: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let y = &self.a * DVector::from_column_slice(x)
            + &self.b * DVector::from_column_slice(u)
            + &self.w;
        out.copy_from_slice(y.as_slice());
        Ok(())
    }
    fn retract(&self, x: &[f64], dx: &[f64], out: &mut [f64]) {
        for ((o, a), b) in out.iter_mut().zip(x).zip(dx) {
            *o = a + b;
        }
    }
    fn difference(&self, x0: &[f64], x1: &[f64], out: &mut [f64]) {
        for ((o, a), b) in out.iter_mut().zip(x0).zip(x1) {
            *o = b - a;
        }
    }
    fn terminal(&mut self, x: &[f64], out: &mut [f64]) {
        let y = &self.c * DVector::from_column_slice(x) - &self.target;
        out.copy_from_slice(y.as_slice());
    }
    fn jacobians(
        &mut self,
        _x: &[f64],
        _u: &[f64],
        a: &mut DMatrix<f64>,
        b: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        a.copy_from(&self.a);
        b.copy_from(&self.b);
        Ok(())
    }
    fn terminal_jacobian(&mut self, _x: &[f64], c: &mut DMatrix<f64>) {
        c.copy_from(&self.c);
    }
    fn weighted_hessian(
        &mut self,
        _x: &[f64],
        _u: &[f64],
        _w: &[f64],
        h: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        h.fill(0.0);
        Ok(())
    }
    fn terminal_hessian(&mut self, _x: &[f64], _nu: &[f64], h: &mut DMatrix<f64>) {
        h.fill(0.0);
    }
}

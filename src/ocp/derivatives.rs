//! Structured differences of the chain's step (docs/ocp.md §2): the central-difference
//! Jacobians `A = ∂f/∂x`, `B = ∂f/∂u` and the second-difference Hessian of the weighted step
//! `∇²(wᵀ (f(x ⊕ δx, u + δu) ⊖ f(x, u)))` of [`ChainModel`], the **same numbers** as the
//! reference paths [`central_jacobians`](super::model::central_jacobians) and
//! [`second_difference_hessian`](super::model::second_difference_hessian) (same steps, same
//! perturbations, same arithmetic), with every dynamics term a perturbation leaves unchanged
//! reused instead of recomputed.
//!
//! A step is `load` (the terms of USM-19 at the state: `M(q)` by CRBA, `h(q, ζ)` by
//! Newton–Euler, `G(q)` with thrusters) then `finish` (`τ`, the Cholesky solve
//! `ζ̇ = M⁻¹(τ − h)`, the symplectic Euler update on SE(3)). What a tangent perturbation
//! `[δp, δθ, δq, δV, δq̇]` changes:
//!
//! - a control perturbation: nothing in the terms → `finish` only;
//! - `δV`, `δq̇` (and `δp`, `δθ` when the dynamics need the orientation: restoring forces or a
//!   current): `h` only (`M` and `G` depend on q alone) → Newton–Euler, no CRBA;
//! - `δp`, `δθ` without restoring forces or current (the rigid chain): nothing → `finish`;
//! - `δq`: everything → the full step.
//!
//! For the rigid 5-link chain (nx = 20, nu = 10) the second differences take 496 steps: 79
//! with the full terms, 125 with Newton–Euler only, the rest `finish` only (reference: 496
//! full); the Jacobians 61: 9 full, 20 Newton–Euler only (reference: 61 full). The unchanged terms are restored from a
//! copy taken at the unperturbed state, so the order of the perturbations does not matter and
//! the results equal the reference paths' (test `ocp::tests_derivatives`). No allocation after
//! the first call (the scratch lives in the model).

use super::chain::ChainModel;
use super::model::{FdScratch, ModelError, OcpModel, FD_STEP, HESS_STEP};
use crate::dynamics::bias;
use nalgebra::DMatrix;

/// Which dynamics terms a perturbation changes (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Terms {
    /// None: the unperturbed state's `M`, `h`, `G`.
    Same,
    /// `h` only.
    Bias,
    /// `M`, `h` and `G`.
    All,
}

impl ChainModel {
    /// The terms a perturbation of the tangent components `idx` (< nx) changes.
    fn terms_changed(&self, idx: &[usize]) -> Terms {
        let n = self.n_joints();
        // As `dynamics::passes::needs_orientation`: the pose enters h only through these.
        let orientation = self.opts.restoring || self.opts.current;
        // `x ⊕ 0` renormalises the quaternion (an ulp off x's): with the pose in h, even the
        // empty perturbation reloads h there, as the reference path does.
        let mut t = if orientation {
            Terms::Bias
        } else {
            Terms::Same
        };
        for &i in idx {
            if (6..6 + n).contains(&i) {
                return Terms::All;
            }
            if i >= 6 + n || orientation {
                t = Terms::Bias;
            }
        }
        t
    }

    /// Copy the terms in the workspace (just loaded at the unperturbed state).
    fn save_terms(&mut self, s: &mut FdScratch) {
        s.bias.clear();
        s.bias.extend_from_slice(&self.ws.bias);
        match s.mass.as_mut() {
            Some(m) => m.copy_from(&self.ws.mass),
            None => s.mass = Some(self.ws.mass.clone()),
        }
        if let Some(g) = self.gmap.as_ref() {
            match s.gmap.as_mut() {
                Some(m) => m.copy_from(g),
                None => s.gmap = Some(g.clone()),
            }
        }
    }

    /// Put the terms for the state `x` (a perturbation changing `terms` of the saved state)
    /// into the workspace.
    fn terms_for(&mut self, x: &[f64], terms: Terms, s: &FdScratch) {
        if terms == Terms::All {
            self.load_terms(x);
            return;
        }
        if let Some(m) = s.mass.as_ref() {
            self.ws.mass.copy_from(m);
        }
        if let (Some(g), Some(saved)) = (self.gmap.as_mut(), s.gmap.as_ref()) {
            g.copy_from(saved);
        }
        if terms == Terms::Same {
            self.ws.bias.copy_from_slice(&s.bias);
        } else {
            let n = self.n_joints();
            let pose = Self::pose(x);
            bias(
                &self.vehicle,
                &mut self.ws,
                &pose,
                &x[7..7 + n],
                &x[7 + n..13 + 2 * n],
                &self.opts,
            );
        }
    }

    /// The unperturbed step `f(x, u)` of the last structured differences at `(x, u)`.
    pub(super) fn step_origin(&self) -> &[f64] {
        &self.fd.f0
    }

    /// [`OcpModel::jacobians`]: central differences, structured (module documentation).
    pub(super) fn structured_jacobians(
        &mut self,
        x: &[f64],
        u: &[f64],
        a: &mut DMatrix<f64>,
        b: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        let mut s = std::mem::take(&mut self.fd);
        let r = self.jacobians_with(x, u, a, b, &mut s);
        self.fd = s;
        r
    }

    fn jacobians_with(
        &mut self,
        x: &[f64],
        u: &[f64],
        a: &mut DMatrix<f64>,
        b: &mut DMatrix<f64>,
        s: &mut FdScratch,
    ) -> Result<(), ModelError> {
        let (nq, nx, nu) = (self.nq(), self.nx(), self.nu());
        s.size(nq, nx, nu);
        self.load_terms(x);
        self.save_terms(s);
        self.finish_step(x, u, &mut s.f0)?;
        s.u.copy_from_slice(u);
        for i in 0..nu {
            s.u[i] = u[i] + FD_STEP;
            self.finish_step(x, &s.u, &mut s.fp)?;
            s.u[i] = u[i] - FD_STEP;
            self.finish_step(x, &s.u, &mut s.fm)?;
            s.u[i] = u[i];
            self.difference(&s.f0, &s.fp, &mut s.dp);
            self.difference(&s.f0, &s.fm, &mut s.dm);
            for r in 0..nx {
                b[(r, i)] = (s.dp[r] - s.dm[r]) / (2.0 * FD_STEP);
            }
        }
        s.e.fill(0.0);
        for i in 0..nx {
            let terms = self.terms_changed(&[i]);
            s.e[i] = FD_STEP;
            self.retract(x, &s.e, &mut s.xp);
            self.terms_for(&s.xp, terms, s);
            self.finish_step(&s.xp, u, &mut s.fp)?;
            s.e[i] = -FD_STEP;
            self.retract(x, &s.e, &mut s.xp);
            self.terms_for(&s.xp, terms, s);
            self.finish_step(&s.xp, u, &mut s.fm)?;
            s.e[i] = 0.0;
            self.difference(&s.f0, &s.fp, &mut s.dp);
            self.difference(&s.f0, &s.fm, &mut s.dm);
            for r in 0..nx {
                a[(r, i)] = (s.dp[r] - s.dm[r]) / (2.0 * FD_STEP);
            }
        }
        Ok(())
    }

    /// [`OcpModel::weighted_hessian`]: forward second differences, structured (module
    /// documentation).
    pub(super) fn structured_hessian(
        &mut self,
        x: &[f64],
        u: &[f64],
        w: &[f64],
        h: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        let mut s = std::mem::take(&mut self.fd);
        let r = self.hessian_with(x, u, w, h, &mut s);
        self.fd = s;
        r
    }

    /// `wᵀ (f(x ⊕ e, u + Σ_{a ∈ ui} ε e_a) ⊖ f0)` with the terms for `x ⊕ e` loaded and
    /// `s.xp = x ⊕ e`.
    fn phi(
        &mut self,
        u: &[f64],
        ui: &[usize],
        w: &[f64],
        s: &mut FdScratch,
    ) -> Result<f64, ModelError> {
        s.u.copy_from_slice(u);
        for &a in ui {
            s.u[a] += HESS_STEP;
        }
        self.finish_step(&s.xp, &s.u, &mut s.fp)?;
        self.difference(&s.f0, &s.fp, &mut s.dp);
        Ok(w.iter().zip(&s.dp).map(|(a, b)| a * b).sum())
    }

    /// Retract `x` by `Σ_{i ∈ xi} ε e_i` into `s.xp` and load its terms.
    fn perturbed(&mut self, x: &[f64], xi: &[usize], s: &mut FdScratch) {
        s.e.fill(0.0);
        for &i in xi {
            s.e[i] += HESS_STEP;
        }
        self.retract(x, &s.e, &mut s.xp);
        let terms = self.terms_changed(xi);
        self.terms_for(&s.xp, terms, s);
    }

    fn hessian_with(
        &mut self,
        x: &[f64],
        u: &[f64],
        w: &[f64],
        h: &mut DMatrix<f64>,
        s: &mut FdScratch,
    ) -> Result<(), ModelError> {
        let (nq, nx, nu) = (self.nq(), self.nx(), self.nu());
        s.size(nq, nx, nu);
        self.load_terms(x);
        self.save_terms(s);
        self.finish_step(x, u, &mut s.f0)?;
        let e2 = HESS_STEP * HESS_STEP;
        // Control-only perturbations: the unperturbed terms.
        self.perturbed(x, &[], s);
        for a in 0..nu {
            s.phi[nx + a] = self.phi(u, &[a], w, s)?;
        }
        for a in 0..nu {
            for b in a..nu {
                let v = (self.phi(u, &[a, b], w, s)? - s.phi[nx + a] - s.phi[nx + b]) / e2;
                h[(nx + a, nx + b)] = v;
                h[(nx + b, nx + a)] = v;
            }
        }
        // One state component, with and without one control.
        for i in 0..nx {
            self.perturbed(x, &[i], s);
            s.phi[i] = self.phi(u, &[], w, s)?;
            for a in 0..nu {
                let v = (self.phi(u, &[a], w, s)? - s.phi[i] - s.phi[nx + a]) / e2;
                h[(i, nx + a)] = v;
                h[(nx + a, i)] = v;
            }
        }
        // Two state components.
        for i in 0..nx {
            for j in i..nx {
                self.perturbed(x, &[i, j], s);
                let v = (self.phi(u, &[], w, s)? - s.phi[i] - s.phi[j]) / e2;
                h[(i, j)] = v;
                h[(j, i)] = v;
            }
        }
        Ok(())
    }
}

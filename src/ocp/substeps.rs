//! Substeps of the chain's step (docs/ocp.md §2, "Substeps"): an interval Δt integrated by S
//! symplectic Euler steps of `h = Δt / S` under the interval's constant control,
//! `f = f_{S-1} ∘ ⋯ ∘ f_0` with `x_{i+1} = f_i(x_i, u)`, and its derivatives by the chain
//! rule in the tangent charts of the intermediate states (exact, since `⊖` inverts `⊕` at each
//! of them):
//!
//! - (S1) `A = A_{S-1} ⋯ A_0`, `B = Σ_i A_{S-1} ⋯ A_{i+1} B_i` with `A_i, B_i` the structured
//!   central differences of one substep at `x_i` ([`super::derivatives`]);
//! - (S2) `∇²(wᵀ f) = Σ_i P_iᵀ ∇²(w_iᵀ f_i) P_i`, with the back-propagated weights
//!   `w_{S-1} = w`, `w_i = A_{i+1}ᵀ w_{i+1}` and `P_i = [[Φ_i, Γ_i], [0, I]]` the Jacobian of
//!   `(x_i, u)` with respect to `(x, u)` (`Φ_i = A_{i-1} ⋯ A_0`, `Γ_i = Σ_{j<i} A_{i-1} ⋯ A_{j+1} B_j`).
//!
//! One substep (S = 1) never reaches this file: the plain step, bit for bit. The scratch is
//! sized on the first call and reused (no allocation after it).
// Stage and component loops read clearest with indices (i: substep).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::model::{ModelError, OcpModel};
use super::sub_scratch::SubScratch;
use nalgebra::DMatrix;

impl ChainModel {
    /// The composite step: `out = f_{S-1}(⋯ f_0(x, u) ⋯, u)`.
    pub(super) fn substep_chain(
        &mut self,
        x: &[f64],
        u: &[f64],
        out: &mut [f64],
        s: &mut SubScratch,
    ) -> Result<(), ModelError> {
        let n = self.substeps();
        s.size(n, self.nq(), self.nx(), self.nu());
        s.xs[0].copy_from_slice(x);
        for i in 0..n {
            let (done, rest) = s.xs.split_at_mut(i + 1);
            self.load_terms(&done[i]);
            self.finish_step(&done[i], u, &mut rest[0])?;
        }
        out.copy_from_slice(&s.xs[n]);
        Ok(())
    }

    /// Each substep's structured Jacobians `A_i, B_i` at `x_i` into the scratch, with the
    /// intermediate states (the unperturbed step of each difference is the step itself).
    fn substep_jacobians(
        &mut self,
        x: &[f64],
        u: &[f64],
        s: &mut SubScratch,
    ) -> Result<(), ModelError> {
        let n = self.substeps();
        s.size(n, self.nq(), self.nx(), self.nu());
        s.xs[0].copy_from_slice(x);
        for i in 0..n {
            let (done, rest) = s.xs.split_at_mut(i + 1);
            self.structured_jacobians(&done[i], u, &mut s.a[i], &mut s.b[i])?;
            rest[0].copy_from_slice(self.step_origin());
        }
        Ok(())
    }

    /// (S1): the composite step's Jacobians.
    pub(super) fn chained_jacobians(
        &mut self,
        x: &[f64],
        u: &[f64],
        a: &mut DMatrix<f64>,
        b: &mut DMatrix<f64>,
        s: &mut SubScratch,
    ) -> Result<(), ModelError> {
        self.substep_jacobians(x, u, s)?;
        s.phi.fill_with_identity();
        s.gamma.fill(0.0);
        for i in 0..self.substeps() {
            accumulate(s, i);
        }
        a.copy_from(&s.phi);
        b.copy_from(&s.gamma);
        Ok(())
    }

    /// (S2): the composite step's weighted Hessian, `(nx + nu)²`.
    pub(super) fn chained_hessian(
        &mut self,
        x: &[f64],
        u: &[f64],
        w: &[f64],
        h: &mut DMatrix<f64>,
        s: &mut SubScratch,
    ) -> Result<(), ModelError> {
        let (n, nx, nu) = (self.substeps(), self.nx(), self.nu());
        self.substep_jacobians(x, u, s)?;
        s.w[n - 1].copy_from_slice(w);
        for i in (0..n - 1).rev() {
            let (lo, hi) = s.w.split_at_mut(i + 1);
            lo[i].gemv_tr(1.0, &s.a[i + 1], &hi[0], 0.0);
        }
        h.fill(0.0);
        s.phi.fill_with_identity();
        s.gamma.fill(0.0);
        for i in 0..n {
            let wi = std::mem::take(&mut s.w[i]);
            let r = self.structured_hessian(&s.xs[i], u, wi.as_slice(), &mut s.hi);
            s.w[i] = wi;
            r?;
            // P_i = [[Φ_i, Γ_i], [0, I]]; H += P_iᵀ H_i P_i.
            s.p.fill(0.0);
            s.p.view_mut((0, 0), (nx, nx)).copy_from(&s.phi);
            s.p.view_mut((0, nx), (nx, nu)).copy_from(&s.gamma);
            for k in 0..nu {
                s.p[(nx + k, nx + k)] = 1.0;
            }
            s.hp.gemm(1.0, &s.hi, &s.p, 0.0);
            h.gemm_tr(1.0, &s.p, &s.hp, 1.0);
            accumulate(s, i);
        }
        Ok(())
    }
}

/// `Φ ← A_i Φ`, `Γ ← A_i Γ + B_i` (the running products of (S1)).
fn accumulate(s: &mut SubScratch, i: usize) {
    s.tmp_x.gemm(1.0, &s.a[i], &s.phi, 0.0);
    std::mem::swap(&mut s.phi, &mut s.tmp_x);
    s.tmp_u.copy_from(&s.b[i]);
    s.tmp_u.gemm(1.0, &s.a[i], &s.gamma, 1.0);
    std::mem::swap(&mut s.gamma, &mut s.tmp_u);
}

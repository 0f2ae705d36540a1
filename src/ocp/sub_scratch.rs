//! The scratch of the substepped step (docs/ocp.md §2, "Substeps"; used by
//! [`super::substeps`]): sized on the first call, reused after it (no allocation in a solver
//! iteration).

use nalgebra::{DMatrix, DVector};

/// Scratch of the composite step: the intermediate states, each substep's Jacobians, the
/// back-propagated weights and the products of (S1)–(S2).
#[derive(Clone, Debug, Default)]
pub(super) struct SubScratch {
    pub(super) xs: Vec<Vec<f64>>,
    pub(super) a: Vec<DMatrix<f64>>,
    pub(super) b: Vec<DMatrix<f64>>,
    pub(super) w: Vec<DVector<f64>>,
    pub(super) phi: DMatrix<f64>,
    pub(super) gamma: DMatrix<f64>,
    pub(super) tmp_x: DMatrix<f64>,
    pub(super) tmp_u: DMatrix<f64>,
    pub(super) hi: DMatrix<f64>,
    pub(super) p: DMatrix<f64>,
    pub(super) hp: DMatrix<f64>,
}

impl SubScratch {
    /// Size for `s` substeps of a model with state size `nq`, tangent `nx` and `nu` controls.
    pub(super) fn size(&mut self, s: usize, nq: usize, nx: usize, nu: usize) {
        let m = nx + nu;
        if self.xs.len() == s + 1 && self.xs[0].len() == nq && self.b[0].ncols() == nu {
            return;
        }
        self.xs = vec![vec![0.0; nq]; s + 1];
        self.a = vec![DMatrix::zeros(nx, nx); s];
        self.b = vec![DMatrix::zeros(nx, nu); s];
        self.w = vec![DVector::zeros(nx); s];
        self.phi = DMatrix::zeros(nx, nx);
        self.gamma = DMatrix::zeros(nx, nu);
        self.tmp_x = DMatrix::zeros(nx, nx);
        self.tmp_u = DMatrix::zeros(nx, nu);
        self.hi = DMatrix::zeros(m, m);
        self.p = DMatrix::zeros(m, m);
        self.hp = DMatrix::zeros(m, m);
    }
}

//! The damped weighted pseudoinverse kernel (USM-37) shared by the `pinv` method and the
//! solver fallback, and the wrench map `T u`.

use nalgebra::{Matrix6, Matrix6xX, Vector6};

/// Iteration cap of the 6×6 SVD fallback (it converges in a few dozen on finite data).
const SVD_MAX_ITERATIONS: usize = 1000;

/// `T u` (base frame; N, N·m).
pub fn wrench(t: &Matrix6xX<f64>, u: &[f64]) -> Vector6<f64> {
    let mut f = Vector6::zeros();
    for (j, &uj) in u.iter().enumerate().take(t.ncols()) {
        f += t.column(j) * uj;
    }
    f
}

/// Damped weighted pseudoinverse (USM-37): `u = W⁻¹Tᵀ(TW⁻¹Tᵀ + λ²I)⁻¹τ`, written into `u`
/// (length `n_thrusters`). `w_inv` is the diagonal of `W⁻¹`. Uses a fixed 6×6 Cholesky factorisation and
/// allocates nothing; if the 6×6 matrix is not positive definite (λ = 0 and `T` singular) the
/// minimum-norm solution from a 6×6 SVD is used instead. If `TW⁻¹Tᵀ` overflows (extreme
/// weights on large entries) there is no meaningful solution: `u` is NaN, which the callers
/// report (nalgebra's SVD panics on such data, so it is never attempted).
pub(super) fn pinv_into(
    t: &Matrix6xX<f64>,
    tau: &Vector6<f64>,
    w_inv: &[f64],
    lambda: f64,
    u: &mut [f64],
) {
    let mut a = Matrix6::<f64>::identity() * (lambda * lambda);
    for (j, &wi) in w_inv.iter().enumerate() {
        let c = t.fixed_view::<6, 1>(0, j);
        a.ger(wi, &c, &c, 1.0);
    }
    if !a.iter().all(|x| x.is_finite()) {
        u.fill(f64::NAN);
        return;
    }
    let y = match a.cholesky() {
        Some(ch) => ch.solve(tau),
        // A capped SVD: on non-finite data an uncapped one iterates forever.
        None => a
            .try_svd(true, true, f64::EPSILON, SVD_MAX_ITERATIONS)
            .and_then(|svd| svd.solve(tau, 1e-12 * a.norm().max(f64::MIN_POSITIVE)).ok())
            .unwrap_or_else(Vector6::zeros),
    };
    for (j, (uj, &wi)) in u.iter_mut().zip(w_inv).enumerate() {
        *uj = wi * t.fixed_view::<6, 1>(0, j).dot(&y);
    }
}

//! The linear-algebra room, below `spatial` and above `dynamics`: the crate's one dense
//! Cholesky factorisation.
//!
//! The dense Cholesky factorisation `A = L Lᵀ` and its solve, as one named algorithm shared
//! by forward dynamics (`M ζ̇ = τ − h`, USM-19) and the damped pseudoinverse of kinematic
//! control (`(J U Jᵀ + λ² I) y = r`, USM-31) — Pinocchio's `cholesky.hpp` habit: one
//! factorisation, reused by every algorithm that solves with an SPD matrix.
//!
//! Storage: an n×n matrix column-major in the first `n·n` entries of a slice, element
//! `(r, c)` at `a[c·n + r]`; only the lower triangle is read and overwritten by `L`.
//!
//! Arithmetic: the factorisation is right-looking — after pivot `j`, the trailing columns are
//! updated down contiguous memory with independent elements, so the update vectorises — yet
//! every entry sees exactly the operations of the textbook dot-product form
//! `L_ij = (A_ij − Σ_{k<j} L_ik L_jk) / L_jj` (subtractions in increasing `k`, then one
//! division), so results do not depend on the loop order.

/// A pivot of the factorisation that was not accepted: `pivot` is its index, `value` the
/// pivot `A_jj − Σ_k L_jk²` before the square root (≤ the tolerance, or not finite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PivotFailure {
    /// Index `j` of the failed pivot.
    pub pivot: usize,
    /// The rejected pivot value.
    pub value: f64,
}

/// Relative pivot tolerance `n·ε·max_j |A_jj|` of the n×n matrix in `a`: pivots below it are
/// rounding noise, i.e. `A` is numerically singular (for callers that must report that rather
/// than regularise).
pub(crate) fn relative_tolerance(a: &[f64], n: usize) -> f64 {
    let mut max_diag: f64 = 0.0;
    for j in 0..n {
        max_diag = max_diag.max(a[j * n + j].abs());
    }
    n as f64 * f64::EPSILON * max_diag
}

/// In-place Cholesky `A = L Lᵀ` of the n×n matrix in `a` (column-major lower triangle, see the
/// module doc). A pivot is accepted if it is finite and greater than `tol` (`0.0`: any
/// positive pivot; [`relative_tolerance`]: numerically non-singular). Allocates nothing.
pub(crate) fn factor(a: &mut [f64], n: usize, tol: f64) -> Result<(), PivotFailure> {
    let a = &mut a[..n * n];
    for j in 0..n {
        let (left, right) = a.split_at_mut((j + 1) * n);
        let col_j = &mut left[j * n..];
        let d = col_j[j];
        // (NaN fails `d > tol` too.)
        if d.partial_cmp(&tol) != Some(std::cmp::Ordering::Greater) || !d.is_finite() {
            return Err(PivotFailure { pivot: j, value: d });
        }
        let d = d.sqrt();
        col_j[j] = d;
        for x in &mut col_j[j + 1..] {
            *x /= d;
        }
        let col_j = &left[j * n..];
        for k in j + 1..n {
            let l_kj = col_j[k];
            let off = (k - j - 1) * n;
            for (x, l) in right[off + k..off + n].iter_mut().zip(&col_j[k..]) {
                *x -= l * l_kj;
            }
        }
    }
    Ok(())
}

/// Solve `L Lᵀ x = b` in place (`x` overwrites `b`, length n) with the factor from
/// [`factor`]: forward substitution by columns, then back substitution by dot products down
/// the contiguous columns of `L`.
pub(crate) fn solve(l: &[f64], n: usize, b: &mut [f64]) {
    for j in 0..n {
        let y = b[j] / l[j * n + j];
        b[j] = y;
        for (x, l) in b[j + 1..n].iter_mut().zip(&l[j * n + j + 1..(j + 1) * n]) {
            *x -= l * y;
        }
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for (l, x) in l[i * n + i + 1..(i + 1) * n].iter().zip(&b[i + 1..n]) {
            s -= l * x;
        }
        b[i] = s / l[i * n + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook dot-product (Cholesky–Crout) form, row by row: the reference the
    /// right-looking [`factor`] must match bit for bit.
    fn crout(a: &[f64], n: usize) -> Vec<f64> {
        let mut l = vec![0.0; n * n];
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= l[j * n + k] * l[j * n + k];
            }
            let d = d.sqrt();
            l[j * n + j] = d;
            for i in j + 1..n {
                let mut s = a[j * n + i];
                for k in 0..j {
                    s -= l[i * n + k] * l[j * n + k];
                }
                l[i * n + j] = s / d;
            }
        }
        l
    }

    fn spd(n: usize) -> Vec<f64> {
        // B Bᵀ + I for a fixed pseudo-random B.
        let b: Vec<f64> = (0..n * n).map(|k| ((k as f64) * 0.731).sin()).collect();
        let mut a = vec![0.0; n * n];
        for r in 0..n {
            for c in 0..n {
                let s: f64 = (0..n).map(|k| b[r * n + k] * b[c * n + k]).sum();
                a[c * n + r] = s + if r == c { 1.0 } else { 0.0 };
            }
        }
        a
    }

    #[test]
    fn factor_is_bitwise_the_dot_product_form_and_solves() {
        for n in [1, 2, 6, 14] {
            let a = spd(n);
            let mut l = a.clone();
            factor(&mut l, n, relative_tolerance(&a, n)).unwrap();
            let reference = crout(&a, n);
            for c in 0..n {
                for r in c..n {
                    // reference is row-major (r, c) at r·n + c.
                    assert_eq!(l[c * n + r].to_bits(), reference[r * n + c].to_bits());
                }
            }
            let b: Vec<f64> = (0..n).map(|k| k as f64 - 0.5).collect();
            let mut x = b.clone();
            solve(&l, n, &mut x);
            for r in 0..n {
                let ax: f64 = (0..n).map(|c| a[c * n + r] * x[c]).sum();
                assert!((ax - b[r]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn singular_and_non_finite_pivots_fail() {
        // [[1, 1], [1, 1]]: second pivot is 0.
        let mut a = vec![1.0, 1.0, 1.0, 1.0];
        assert_eq!(factor(&mut a, 2, 0.0).unwrap_err().pivot, 1);
        let mut a = vec![f64::NAN, 0.0, 0.0, 1.0];
        assert_eq!(factor(&mut a, 2, 0.0).unwrap_err().pivot, 0);
        // A tiny positive pivot passes a zero tolerance but not the relative one.
        // (Pivot ε against the tolerance 2·ε·(1 + ε).)
        let a0 = vec![1.0, 1.0, 1.0, 1.0 + f64::EPSILON];
        let mut a = a0.clone();
        assert!(factor(&mut a, 2, 0.0).is_ok());
        let mut a = a0.clone();
        assert!(factor(&mut a, 2, relative_tolerance(&a0, 2)).is_err());
    }
}

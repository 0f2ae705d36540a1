//! Singular values of small matrices (at most 6 rows) without heap allocation, for the
//! commanded-subspace singularity metrics (docs/model.md §6): the eigenvalues of a symmetric `k×k`
//! (Gram) matrix by Householder tridiagonalisation and implicit QL; a row-by-row Givens QR into
//! a `k×k` triangle and one-sided (Hestenes) Jacobi on it; and shifted inverse iteration for an
//! eigenvector. Fixed 6×6 arrays on the stack; only the leading `k×k` block is used.

// Dense k×k kernels read clearest with index loops over rows and columns.
#![allow(clippy::needless_range_loop)]

/// `√(a² + b²)` without `hypot`'s care for extreme exponents (several times slower in glibc):
/// exact enough and safe for |a|, |b| < 1e150; beyond, the larger magnitude (the other term is
/// then below its rounding).
#[inline]
fn pythag(a: f64, b: f64) -> f64 {
    let (x, y) = (a.abs(), b.abs());
    let big = x.max(y);
    if big > 1e150 {
        big
    } else {
        (x * x + y * y).sqrt()
    }
}

/// Rotate columns `p` and `q` of the leading `k` rows of `m`:
/// `(m_p, m_q) ← (c m_p − s m_q, s m_p + c m_q)`.
#[inline]
fn rotate_columns(m: &mut [[f64; 6]; 6], k: usize, p: usize, q: usize, c: f64, s: f64) {
    for row in m.iter_mut().take(k) {
        let (a, b) = (row[p], row[q]);
        row[p] = c * a - s * b;
        row[q] = s * a + c * b;
    }
}

/// Largest number of Jacobi sweeps (quadratic convergence needs 4–6 for 6×6).
const MAX_SWEEPS: usize = 30;

/// Rotation `(c, s)` annihilating the off-diagonal entry `apq` of the symmetric 2×2 block
/// `[[app, apq], [apq, aqq]]` (the smaller-angle root, Golub & Van Loan §8.5.2).
#[inline]
fn jacobi_rotation(app: f64, aqq: f64, apq: f64) -> (f64, f64, f64) {
    let theta = (aqq - app) / (2.0 * apq);
    let t = if theta.abs() > 1e150 {
        0.5 / theta
    } else {
        theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
    };
    let c = 1.0 / (t * t + 1.0).sqrt();
    (c, t * c, t)
}

/// Fold the row `x` (k entries) into the upper-triangular `r` by Givens rotations, so that
/// `rᵀr` gains `x xᵀ` (QR of a matrix given one row at a time).
#[inline]
pub(crate) fn givens_add_row(r: &mut [[f64; 6]; 6], mut x: [f64; 6], k: usize) {
    for i in 0..k {
        if x[i] == 0.0 {
            continue;
        }
        let h = pythag(r[i][i], x[i]);
        let (c, s) = (r[i][i] / h, x[i] / h);
        r[i][i] = h;
        for l in i + 1..k {
            let (ril, xl) = (r[i][l], x[l]);
            r[i][l] = c * ril + s * xl;
            x[l] = c * xl - s * ril;
        }
    }
}

/// Squared singular values of the `k×k` leading block of `w` (destroyed) by one-sided
/// (Hestenes) Jacobi on its columns: rotate column pairs until all are orthogonal to working
/// precision (`|w_p·w_q| ≤ ε‖w_p‖‖w_q‖`, or `ε²‖w‖²_F` in absolute terms); the squared column
/// norms are then the squared singular values.
pub(crate) fn one_sided_jacobi_sq(w: &mut [[f64; 6]; 6], k: usize) -> [f64; 6] {
    let norm2: f64 = w.iter().take(k).flat_map(|r| &r[..k]).map(|x| x * x).sum();
    let tiny = f64::EPSILON * f64::EPSILON * norm2;
    for _ in 0..MAX_SWEEPS {
        let mut rotated = false;
        for p in 0..k {
            for q in p + 1..k {
                let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
                for row in w.iter().take(k) {
                    alpha += row[p] * row[p];
                    beta += row[q] * row[q];
                    gamma += row[p] * row[q];
                }
                if gamma.abs() <= tiny || gamma.abs() <= f64::EPSILON * (alpha * beta).sqrt() {
                    continue;
                }
                rotated = true;
                let (c, s, _) = jacobi_rotation(alpha, beta, gamma);
                rotate_columns(w, k, p, q, c, s);
            }
        }
        if !rotated {
            break;
        }
    }
    std::array::from_fn(|j| w.iter().take(k).map(|row| row[j] * row[j]).sum())
}

/// Eigenvalues of the symmetric `k×k` leading block of `a` (destroyed), in the first `k`
/// entries (unordered): Householder reduction to tridiagonal form, then the implicit QL
/// algorithm with Wilkinson-like shifts (Numerical Recipes `tred2`/`tqli`, eigenvalues only).
/// Backward stable like Jacobi (absolute error about `ε‖a‖`) at a third of its cost.
pub(crate) fn tridiagonal_eigenvalues(a: &mut [[f64; 6]; 6], k: usize) -> [f64; 6] {
    let mut d = [0.0; 6];
    let mut e = [0.0; 6];
    householder_tridiagonal(a, k, &mut d, &mut e);
    implicit_ql(&mut d, &mut e, k);
    d
}

/// The smallest and largest eigenvalues of the symmetric positive semi-definite `k×k`
/// leading block of `a` (a Gram matrix; destroyed): Householder reduction to tridiagonal
/// form, then Laguerre's iteration on the characteristic polynomial from a bound on each side
/// of the spectrum (Gershgorin, tightened by `0 ≤ λ ≤ trace`; [`laguerre_extremes`]); the
/// implicit QL algorithm ([`tridiagonal_eigenvalues`]' second half) when Laguerre's iteration
/// does not settle. Same absolute accuracy (about `ε‖a‖`) as [`tridiagonal_eigenvalues`] at about a
/// third of its cost: only the two extreme roots are sought.
pub(crate) fn extreme_eigenvalues(a: &mut [[f64; 6]; 6], k: usize) -> (f64, f64) {
    let mut t = Tridiagonal::of(a, k);
    if k <= 1 {
        return (t.d[0], t.d[0]);
    }
    let [r] = laguerre_extremes([&t]);
    t.settle(r)
}

/// [`extreme_eigenvalues`] of two Gram blocks at once (`a`'s leading `ka×ka`, `b`'s `kb×kb`;
/// both destroyed), each result equal to its own call bit for bit: the four Laguerre
/// iterations share one loop (more independent chains for the processor to overlap).
pub(crate) fn extreme_eigenvalues_pair(
    a: &mut [[f64; 6]; 6],
    ka: usize,
    b: &mut [[f64; 6]; 6],
    kb: usize,
) -> [(f64, f64); 2] {
    if ka <= 1 || kb <= 1 {
        return [extreme_eigenvalues(a, ka), extreme_eigenvalues(b, kb)];
    }
    let (mut ta, mut tb) = (Tridiagonal::of(a, ka), Tridiagonal::of(b, kb));
    let [ra, rb] = laguerre_extremes([&ta, &tb]);
    [ta.settle(ra), tb.settle(rb)]
}

/// The smallest and largest eigenvalues of the symmetric positive semi-definite 6×6 block `a`
/// (destroyed) and of its leading `kc×kc` principal block (`kc` 5 or 6), from one Householder
/// reduction: [`householder_nested`] reduces the rows from the last one up, so the leading 5×5
/// block of the tridiagonal form is similar to `a`'s leading 5×5 block (the first reflection
/// acts on exactly that block, the others within it). Laguerre's iteration then runs on the
/// two tridiagonal matrices in one loop as in [`extreme_eigenvalues_pair`]. The static
/// analysis puts its commanded rows first, so all six rows and five commanded ones (the
/// transport mode drops roll) cost one reduction instead of two; same accuracy as
/// [`extreme_eigenvalues`] (about `ε‖a‖` absolute). A smaller block would be mixed with the
/// rows after it by the first reflection.
pub(crate) fn extreme_eigenvalues_nested(a: &mut [[f64; 6]; 6], kc: usize) -> [(f64, f64); 2] {
    debug_assert!(kc == 5 || kc == 6, "nested block of {kc} rows");
    let mut d = [0.0; 6];
    let mut e = [0.0; 6];
    householder_nested(a, &mut d, &mut e);
    let mut tf = Tridiagonal::bounded(6, d, e);
    if kc == 6 {
        let [r] = laguerre_extremes([&tf]);
        let x = tf.settle(r);
        return [x, x];
    }
    e[kc - 1] = 0.0;
    let mut tc = Tridiagonal::bounded(kc, d, e);
    let [rf, rc] = laguerre_extremes([&tf, &tc]);
    [tf.settle(rf), tc.settle(rc)]
}

/// The tridiagonal form of a Gram block and where Laguerre's iteration starts on it.
struct Tridiagonal {
    k: usize,
    d: [f64; 6],
    e: [f64; 6],
    e2: [f64; 6],
    /// A bound below and a bound above the spectrum.
    starts: [f64; 2],
    /// ≥ ‖T‖ (Gershgorin).
    scale: f64,
}

impl Tridiagonal {
    /// Householder reduction of the `k×k` block of `a` (destroyed) and the spectrum's bounds.
    fn of(a: &mut [[f64; 6]; 6], k: usize) -> Self {
        let mut d = [0.0; 6];
        let mut e = [0.0; 6];
        householder_tridiagonal(a, k, &mut d, &mut e);
        Self::bounded(k, d, e)
    }

    /// The tridiagonal `(d, e)` of `k` entries with the spectrum's bounds.
    fn bounded(k: usize, d: [f64; 6], e: [f64; 6]) -> Self {
        let mut e2 = [0.0; 6];
        let (mut lo_bound, mut hi_bound) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut scale = 0.0_f64;
        for i in 0..k {
            let left = if i > 0 { e[i - 1].abs() } else { 0.0 };
            let right = if i + 1 < k { e[i].abs() } else { 0.0 };
            lo_bound = lo_bound.min(d[i] - left - right);
            hi_bound = hi_bound.max(d[i] + left + right);
            scale = scale.max(d[i].abs() + left + right);
            if i + 1 < k {
                e2[i] = e[i] * e[i];
            }
        }
        // A Gram matrix is positive semi-definite: its spectrum lies in [0, trace] up to
        // rounding, often much tighter than Gershgorin's discs.
        let slack = 4.0 * f64::EPSILON * scale;
        lo_bound = lo_bound.max(-slack);
        hi_bound = hi_bound.min(d[..k].iter().sum::<f64>() + slack);
        Self {
            k,
            d,
            e,
            e2,
            starts: [lo_bound, hi_bound],
            scale,
        }
    }

    /// The extremes from Laguerre's results, or by the implicit QL algorithm when either side
    /// did not settle.
    fn settle(&mut self, r: [Option<f64>; 2]) -> (f64, f64) {
        match r {
            [Some(lo), Some(hi)] => (lo, hi),
            _ => {
                implicit_ql(&mut self.d, &mut self.e, self.k);
                min_max(&self.d[..self.k])
            }
        }
    }
}

/// The smallest and largest eigenvalues of each symmetric tridiagonal matrix of `tris`
/// (`k ≥ 2` entries), from its `starts` (a bound below and a bound above the spectrum):
/// Laguerre's iteration on `p(λ) = det(T − λI)` (three-term recurrences for `p`, `p'`, `p''`).
/// With all roots real it moves monotonically from an outer bound to the extreme root and
/// converges cubically to a simple one (Wilkinson, *The Algebraic Eigenvalue Problem*, §7.6).
/// A side stops when its step falls below `4ε·scale` (`scale` ≥ ‖T‖) or stops moving
/// outward-in; `None` after 40 iterations (a multiple root converges only linearly).
///
/// The `2M` sides are independent iterations run in the same loop, so that the processor
/// overlaps their dependency chains (the recurrence is latency-bound); each side's arithmetic
/// is exactly that of iterating it alone (`interleaved_equals_one_side_at_a_time` below).
fn laguerre_extremes<const M: usize>(tris: [&Tridiagonal; M]) -> [[Option<f64>; 2]; M] {
    let mut x: [[f64; 2]; M] = std::array::from_fn(|m| tris[m].starts);
    // Per side: `None` while iterating, `Some(result)` once settled.
    let mut out = [[None::<Option<f64>>; 2]; M];
    for _ in 0..40 {
        // p_j(x) = (d_j − x) p_{j−1} − e²_{j−1} p_{j−2}, and its first two derivatives.
        let mut p0 = [[1.0; 2]; M];
        let mut p1: [[f64; 2]; M] =
            std::array::from_fn(|m| [tris[m].d[0] - x[m][0], tris[m].d[0] - x[m][1]]);
        let (mut dp0, mut dp1) = ([[0.0; 2]; M], [[-1.0; 2]; M]);
        let (mut ddp0, mut ddp1) = ([[0.0; 2]; M], [[0.0; 2]; M]);
        for j in 1..6 {
            for m in 0..M {
                let t = tris[m];
                if j >= t.k {
                    continue;
                }
                let b = t.e2[j - 1];
                for s in 0..2 {
                    let a = t.d[j] - x[m][s];
                    let p2 = a * p1[m][s] - b * p0[m][s];
                    let dp2 = a * dp1[m][s] - b * dp0[m][s] - p1[m][s];
                    let ddp2 = a * ddp1[m][s] - b * ddp0[m][s] - 2.0 * dp1[m][s];
                    (p0[m][s], p1[m][s]) = (p1[m][s], p2);
                    (dp0[m][s], dp1[m][s]) = (dp1[m][s], dp2);
                    (ddp0[m][s], ddp1[m][s]) = (ddp1[m][s], ddp2);
                }
            }
        }
        for m in 0..M {
            let n = tris[m].k as f64;
            let tiny = 4.0 * f64::EPSILON * tris[m].scale.max(f64::MIN_POSITIVE);
            for s in 0..2 {
                if out[m][s].is_none() {
                    let pd = [p1[m][s], dp1[m][s], ddp1[m][s]];
                    out[m][s] = laguerre_update(&mut x[m][s], pd, n, s == 0, tiny);
                }
            }
        }
        if out.iter().all(|o| o[0].is_some() && o[1].is_some()) {
            break;
        }
    }
    std::array::from_fn(|m| [out[m][0].flatten(), out[m][1].flatten()])
}

/// One Laguerre step of [`laguerre_extremes`] at `x` from `[p, p', p'']`: `None` to go on
/// (`x` updated), `Some(Some(root))` when settled, `Some(None)` when the step is unusable.
fn laguerre_update(
    x: &mut f64,
    [p, dp, ddp]: [f64; 3],
    n: f64,
    from_below: bool,
    tiny: f64,
) -> Option<Option<f64>> {
    if p == 0.0 {
        return Some(Some(*x));
    }
    let g = dp / p;
    let h = g * g - ddp / p;
    let root = ((n - 1.0) * (n * h - g * g)).max(0.0).sqrt();
    let den = if g >= 0.0 { g + root } else { g - root };
    if den == 0.0 || !den.is_finite() {
        return Some(None);
    }
    let step = n / den;
    let next = *x - step;
    // From below the iterates rise, from above they fall; a step the other way is
    // rounding at the root.
    let inward = if from_below { next > *x } else { next < *x };
    if !inward {
        return Some(Some(*x));
    }
    if step.abs() <= tiny {
        return Some(Some(next));
    }
    *x = next;
    None
}

/// The smallest and largest of `xs` (`(inf, -inf)` when empty).
pub(crate) fn min_max(xs: &[f64]) -> (f64, f64) {
    xs.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

/// Reduce the symmetric `k×k` block of `a` to tridiagonal form by Householder reflections
/// `H = I − 2vvᵀ` from the left and right: diagonal into `d`, subdiagonal (`e[i]` between
/// rows `i` and `i + 1`) into `e`, `e[k − 1] = 0`.
fn householder_tridiagonal(a: &mut [[f64; 6]; 6], k: usize, d: &mut [f64; 6], e: &mut [f64; 6]) {
    // One copy per size, so that every loop bound is a constant (unrolled, no bounds checks).
    match k {
        6 => householder_k::<6>(a, d, e),
        5 => householder_k::<5>(a, d, e),
        4 => householder_k::<4>(a, d, e),
        3 => householder_k::<3>(a, d, e),
        2 => householder_k::<2>(a, d, e),
        1 => householder_k::<1>(a, d, e),
        _ => {}
    }
}

/// [`householder_tridiagonal`] of the `K×K` block. Each reflection is `H = I − β v vᵀ` with
/// `v = x − α e_1` unnormalised and `β = 2/(vᵀv) = 1/(‖x‖(‖x‖ + |x_1|))`.
fn householder_k<const K: usize>(a: &mut [[f64; 6]; 6], d: &mut [f64; 6], e: &mut [f64; 6]) {
    for j in 0..K.saturating_sub(2) {
        householder_step::<K>(a, j, e);
    }
    householder_finish::<K>(a, d, e);
}

/// Householder reduction of the symmetric 6×6 `a` to tridiagonal form from the last row up
/// (the order of Numerical Recipes' `tred2`): reflection `i` (`i = 5, 4, 3, 2`) acts on the
/// indices `0..i` only and leaves row `i` with its entry at `i − 1`, so the leading 5×5 block
/// of the result is similar to `a`'s (the first reflection is a similarity on it, the others
/// act within it). Diagonal into `d`,
/// subdiagonal (`e[i]` between rows `i` and `i + 1`) into `e`, `e[5] = 0`.
fn householder_nested(a: &mut [[f64; 6]; 6], d: &mut [f64; 6], e: &mut [f64; 6]) {
    // One copy per reflection, so that every loop bound is a constant (unrolled).
    householder_step_up::<5>(a, e);
    householder_step_up::<4>(a, e);
    householder_step_up::<3>(a, e);
    householder_step_up::<2>(a, e);
    for i in 0..6 {
        d[i] = a[i][i];
    }
    e[0] = a[1][0];
    e[5] = 0.0;
}

/// Reflection `i = I` of [`householder_nested`]: `H = 1 − β v vᵀ` on the indices `0..i` maps
/// row `i`'s entries there onto its last one, `e[i − 1]`, and the leading `i×i` block becomes
/// `H A H` ([`reflect_block`]).
#[inline(always)]
fn householder_step_up<const I: usize>(a: &mut [[f64; 6]; 6], e: &mut [f64; 6]) {
    let row = a[I];
    e[I - 1] = match reflector(&row, 0, I, I - 1) {
        Some((v, beta, alpha)) => {
            reflect_block(a, &v, beta, 0, I);
            alpha
        }
        None => 0.0,
    };
}

/// Reflection `j` of [`householder_k`]: zero column `j` below its subdiagonal, `e[j]` the
/// subdiagonal entry.
#[inline(always)]
fn householder_step<const K: usize>(a: &mut [[f64; 6]; 6], j: usize, e: &mut [f64; 6]) {
    let lo = j + 1;
    let column: [f64; 6] = std::array::from_fn(|i| a[i][j]);
    e[j] = match reflector(&column, lo, K, lo) {
        Some((v, beta, alpha)) => {
            reflect_block(a, &v, beta, lo, K);
            alpha
        }
        None => 0.0,
    };
}

/// The Householder reflection of the entries `lo..hi` of `x` onto its entry `pivot`:
/// `(v, β, α)` with `H = I − β v vᵀ`, `H x = α e_pivot` (`v = x − α e_pivot` unnormalised,
/// zero outside `lo..hi`; `β = 2/(vᵀv) = 1/(‖x‖(‖x‖ + |x_pivot|))`, `α = −sgn(x_pivot)‖x‖`);
/// `None` when those entries are all zero.
#[inline(always)]
fn reflector(x: &[f64; 6], lo: usize, hi: usize, pivot: usize) -> Option<([f64; 6], f64, f64)> {
    let mut norm2 = 0.0;
    for xi in &x[lo..hi] {
        norm2 += xi * xi;
    }
    if norm2 == 0.0 {
        return None;
    }
    let norm = norm2.sqrt();
    let alpha = if x[pivot] > 0.0 { -norm } else { norm };
    let mut v = [0.0; 6];
    v[lo..hi].copy_from_slice(&x[lo..hi]);
    v[pivot] -= alpha;
    let beta = 1.0 / (norm * (norm + x[pivot].abs()));
    Some((v, beta, alpha))
}

/// `A ← H A H` on the block `lo..hi` of the symmetric `a` for `H = I − β v vᵀ` (`v` zero
/// outside the block): `p = β A v`, `q = p − (β vᵀp / 2) v`, `A ← A − v qᵀ − q vᵀ`. The block
/// stays exactly symmetric (the Gram matrices are built so, and entry (l, i) gets the same two
/// products summed the other way round, which rounds the same): one triangle is updated and
/// mirrored.
#[inline(always)]
fn reflect_block(a: &mut [[f64; 6]; 6], v: &[f64; 6], beta: f64, lo: usize, hi: usize) {
    let mut p = [0.0; 6];
    for i in lo..hi {
        let mut acc = 0.0;
        for l in lo..hi {
            acc += a[i][l] * v[l];
        }
        p[i] = beta * acc;
    }
    let mut vp = 0.0;
    for i in lo..hi {
        vp += v[i] * p[i];
    }
    let half = 0.5 * beta * vp;
    for i in lo..hi {
        p[i] -= half * v[i];
    }
    for i in lo..hi {
        for l in i..hi {
            let x = a[i][l] - (v[i] * p[l] + p[i] * v[l]);
            a[i][l] = x;
            a[l][i] = x;
        }
    }
}

/// The diagonal and the last subdiagonal entry of [`householder_k`]'s reduced block.
#[inline(always)]
fn householder_finish<const K: usize>(a: &[[f64; 6]; 6], d: &mut [f64; 6], e: &mut [f64; 6]) {
    for i in 0..K {
        d[i] = a[i][i];
    }
    if K >= 2 {
        e[K - 2] = a[K - 1][K - 2];
    }
    if K >= 1 {
        e[K - 1] = 0.0;
    }
}

/// Eigenvalues of the symmetric tridiagonal matrix `(d, e)` (`k` entries, `e[k − 1] = 0`)
/// into `d`, by the implicit QL algorithm with shifts; `e` is destroyed.
fn implicit_ql(d: &mut [f64; 6], e: &mut [f64; 6], k: usize) {
    for l in 0..k {
        for _ in 0..60 {
            let mut m = l;
            while m + 1 < k {
                let dd = d[m].abs() + d[m + 1].abs();
                if e[m].abs() <= f64::EPSILON * dd {
                    break;
                }
                m += 1;
            }
            if m == l {
                break;
            }
            let mut g = (d[l + 1] - d[l]) / (2.0 * e[l]);
            let mut r = pythag(g, 1.0);
            g = d[m] - d[l] + e[l] / (g + r.copysign(g));
            let (mut s, mut c, mut p) = (1.0, 1.0, 0.0);
            let mut underflow = false;
            for i in (l..m).rev() {
                let f = s * e[i];
                let b = c * e[i];
                r = pythag(f, g);
                e[i + 1] = r;
                if r == 0.0 {
                    d[i + 1] -= p;
                    e[m] = 0.0;
                    underflow = true;
                    break;
                }
                s = f / r;
                c = g / r;
                g = d[i + 1] - p;
                r = (d[i] - g) * s + 2.0 * c * b;
                p = s * r;
                d[i + 1] = g + p;
                g = c * r - b;
            }
            if underflow {
                continue;
            }
            d[l] -= p;
            e[l] = g;
            e[m] = 0.0;
        }
    }
}

/// The eigenvector of the symmetric `k×k` block of `a` whose eigenvalue lies just above
/// `shift`: two steps of inverse iteration `(a − shift·I) y ← x` by an `LDLᵀ` factorisation
/// without pivoting (pivots of magnitude below `ε²·trace` are raised to it, so a singular
/// shifted matrix amplifies its null direction instead of dividing by zero), from a start with
/// every component non-zero. Unit length, first `k` entries.
pub(crate) fn shifted_inverse_iteration(a: [[f64; 6]; 6], k: usize, shift: f64) -> [f64; 6] {
    // One copy per size, so that every loop bound is a constant (unrolled, no bounds checks).
    match k {
        6 => inverse_iteration_k::<6>(a, shift),
        5 => inverse_iteration_k::<5>(a, shift),
        4 => inverse_iteration_k::<4>(a, shift),
        3 => inverse_iteration_k::<3>(a, shift),
        2 => inverse_iteration_k::<2>(a, shift),
        1 => inverse_iteration_k::<1>(a, shift),
        _ => std::array::from_fn(|i| 1.0 + 0.1 * i as f64),
    }
}

/// [`shifted_inverse_iteration`] of the `K×K` block.
fn inverse_iteration_k<const K: usize>(mut a: [[f64; 6]; 6], shift: f64) -> [f64; 6] {
    let k = K;
    let trace: f64 = (0..k).map(|i| a[i][i].abs()).sum();
    let tiny = f64::EPSILON * f64::EPSILON * trace.max(f64::MIN_POSITIVE);
    for (i, row) in a.iter_mut().enumerate().take(k) {
        row[i] -= shift;
    }
    // LDLᵀ in place: a[i][j] (i > j) holds L, a[i][i] holds D.
    for j in 0..k {
        let mut dj = a[j][j];
        for m in 0..j {
            dj -= a[j][m] * a[j][m] * a[m][m];
        }
        if dj.abs() < tiny {
            dj = tiny.copysign(if dj == 0.0 { 1.0 } else { dj });
        }
        a[j][j] = dj;
        for i in j + 1..k {
            let mut x = a[i][j];
            for m in 0..j {
                x -= a[i][m] * a[j][m] * a[m][m];
            }
            a[i][j] = x / dj;
        }
    }
    let mut y: [f64; 6] = std::array::from_fn(|i| 1.0 + 0.1 * i as f64);
    for _ in 0..2 {
        for i in 0..k {
            for m in 0..i {
                y[i] -= a[i][m] * y[m];
            }
        }
        for i in 0..k {
            y[i] /= a[i][i];
        }
        for i in (0..k).rev() {
            for m in i + 1..k {
                y[i] -= a[m][i] * y[m];
            }
        }
        let norm = y[..k].iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            break;
        }
        y[..k].iter_mut().for_each(|x| *x /= norm);
    }
    y
}

#[cfg(test)]
#[path = "small_svd_tests.rs"]
mod tests;

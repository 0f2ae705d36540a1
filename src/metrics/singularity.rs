//! Thruster-configuration-matrix (TCM) singularity metrics (docs/model.md §6).
//!
//! `T` (6 × n_thrusters, base frame, rows force x, y, z in N per N of thrust then moment x, y, z
//! in N·m per N) is made dimensionally homogeneous by dividing its moment rows by a
//! characteristic length `L` [m] (callers default it to half the vehicle length):
//! `T_L = diag(1, 1, 1, 1/L, 1/L, 1/L) T`.
//! The metrics are the singular values of `T_L`, σ_min, σ_max, the condition number, the rank under
//! a relative tolerance, the lost wrench directions, and (with thrust limits) the attainable wrench
//! along each base axis (an LP per axis, solved by [`crate::allocation::attainable_wrench`]).
//! All functions are pure.

use nalgebra::{Matrix6xX, Vector6};
use serde::Serialize;

use super::small_svd::{
    givens_add_row, min_max, one_sided_jacobi_sq, shifted_inverse_iteration,
    tridiagonal_eigenvalues,
};
use crate::allocation::{attainable_wrench, AllocError, AttainableWrench};

/// Default relative rank tolerance: a singular value counts as zero below `1e-6 · σ_max`.
pub const DEFAULT_RANK_REL_TOL: f64 = 1e-6;

/// The one threshold on the scaled σ_min (N per N) below which a configuration counts as
/// singular, shared by the static analysis (`[static] threshold`, `tcm --threshold`) and the
/// trajectory metrics (`[metrics] threshold`, `singularity_exposure`) (docs/model.md §6).
/// See `docs/singularity.md` for its calibration.
pub const SINGULARITY_THRESHOLD: f64 = 0.05;

/// Default relative tolerance of [`residual_exceeds`] (`[metrics] residual_tolerance`): the
/// allocator counts as not delivering the commanded wrench when the commanded slack exceeds
/// 1 % of it, the allocator's own `slack_tol` (docs/model.md §5).
pub const RESIDUAL_TOLERANCE: f64 = 1e-2;

/// Names of the six base-frame wrench axes, in row order of `T`.
pub const AXIS_NAMES: [&str; 6] = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

/// Bad input to the singularity metrics.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SingularityError {
    /// The characteristic length must be finite and > 0.
    #[error("characteristic length `char_length` = {0} must be finite and > 0 (m)")]
    CharLength(f64),
    /// The rank tolerance must be finite and ≥ 0.
    #[error("rank tolerance `rank_rel_tol` = {0} must be finite and >= 0")]
    RankTol(f64),
    /// `T` or the thrust limits are malformed.
    #[error(transparent)]
    Input(#[from] AllocError),
}

/// A wrench direction the thrusters cannot produce (docs/model.md §6): a left singular vector of `T_L` whose
/// singular value is below the rank tolerance.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LostDirection {
    /// The singular value (same units as `T_L`, N per N).
    pub sigma: f64,
    /// Unit direction in the scaled wrench space `[f (N); moment/L (N)]`, base frame, signed so that
    /// its largest-magnitude component is positive.
    pub direction: [f64; 6],
    /// Name of the dominant axis of `direction`: `surge`, `sway`, `heave`, `roll`, `pitch`, `yaw`.
    pub dominant_axis: &'static str,
}

/// TCM singularity metrics of one configuration (docs/model.md §6).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TcmMetrics {
    /// Characteristic length `L` used to scale the moment rows (m).
    pub char_length: f64,
    /// The six singular values of `T_L`, descending (zeros appended when n_thrusters < 6).
    pub singular_values: [f64; 6],
    /// Smallest singular value σ_6 (0 when n_thrusters < 6).
    pub sigma_min: f64,
    /// Largest singular value σ_1.
    pub sigma_max: f64,
    /// Condition number σ_max/σ_min; `+inf` (JSON `null`) when rank < 6.
    pub condition_number: f64,
    /// Number of singular values above `rank_tol`.
    pub rank: usize,
    /// Absolute rank tolerance used, `rank_rel_tol · σ_max`.
    pub rank_tol: f64,
    /// Lost wrench directions, one per singular value ≤ `rank_tol`, in ascending σ.
    pub lost_directions: Vec<LostDirection>,
    /// Attainable wrench along `±e_k` under the thrust limits (unscaled: N, N·m); `None` when no
    /// limits were given.
    pub attainable: Option<AttainableWrench>,
}

/// `T_L = diag(1, 1, 1, 1/L, 1/L, 1/L) T`: moment rows of `T` divided by `char_length` (m)
/// (docs/model.md §6).
pub fn scale_moment_rows(t: &Matrix6xX<f64>, char_length: f64) -> Matrix6xX<f64> {
    let mut s = t.clone();
    for mut col in s.column_iter_mut() {
        for i in 3..6 {
            col[i] /= char_length;
        }
    }
    s
}

fn check_inputs(
    t: &Matrix6xX<f64>,
    char_length: f64,
    rank_rel_tol: f64,
) -> Result<(), SingularityError> {
    if !(char_length.is_finite() && char_length > 0.0) {
        return Err(SingularityError::CharLength(char_length));
    }
    if !(rank_rel_tol.is_finite() && rank_rel_tol >= 0.0) {
        return Err(SingularityError::RankTol(rank_rel_tol));
    }
    crate::allocation::check_t(t, None)?;
    Ok(())
}

/// Singular values of `T_L` (docs/model.md §6), six of them, descending (zeros appended when
/// n_thrusters < 6).
/// `t` must be finite (checked by the public entry points).
fn scaled_svd(t: &Matrix6xX<f64>, char_length: f64) -> ([f64; 6], nalgebra::Matrix6<f64>) {
    let n_thrusters = t.ncols();
    // Pad to at least 6 columns so that U is a full 6×6 basis of the wrench space.
    let mut tl = Matrix6xX::<f64>::zeros(n_thrusters.max(6));
    tl.columns_mut(0, n_thrusters)
        .copy_from(&scale_moment_rows(t, char_length));
    let svd = tl.svd(true, false);
    let mut idx = [0usize, 1, 2, 3, 4, 5];
    idx.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let mut sv = [0.0; 6];
    let mut u = nalgebra::Matrix6::<f64>::zeros();
    if let Some(svd_u) = svd.u.as_ref() {
        for (k, &i) in idx.iter().enumerate() {
            sv[k] = svd.singular_values[i];
            u.set_column(k, &svd_u.column(i));
        }
    }
    (sv, u)
}

/// Whether the allocator failed to deliver the commanded wrench (docs/model.md §6,
/// `allocation_residual_fraction`): the commanded rows of the wrench slack `s = T u − τ` exceed
/// `tol` times the commanded wrench, `‖S s_L‖ > tol·‖S τ_L‖`, both scaled like `T_L` (moments
/// divided by `char_length` L [m]) so that forces [N] and moments [N·m] weigh alike. A zero
/// demand met exactly is not a failure.
pub fn residual_exceeds(
    s: &Vector6<f64>,
    tau: &Vector6<f64>,
    char_length: f64,
    dofs: CommandedDofs,
    tol: f64,
) -> bool {
    let (mut ss, mut tt) = (0.0, 0.0);
    for i in (0..6).filter(|&i| dofs.contains(i)) {
        let w = if i < 3 { 1.0 } else { 1.0 / char_length };
        ss += (s[i] * w).powi(2);
        tt += (tau[i] * w).powi(2);
    }
    ss.sqrt() > tol * tt.sqrt()
}

/// The base wrench axes a controller commands (docs/model.md §5): a subset of surge, sway, heave, roll,
/// pitch, yaw, in the row order of `T`. The selection matrix `S` of the commanded-subspace
/// metrics keeps exactly these rows of `T_L`.
///
/// Derived from the controller's gains, not from a preset: in transport the base controller
/// always commands surge and yaw (USM-40/41) and regulates sway, heave, roll and pitch only where
/// `K_p,i > 0` (USM-34; the paper's `K_p` leaves roll free), see
/// [`CommandedDofs::transport`]; in work mode an axis is commanded when the kinematic controller
/// may move it (base usage weight `U_i > 0`, USM-42) or the base controller regulates it
/// (`K_p,i > 0` or `K_i,i > 0`, USM-34), see [`CommandedDofs::work`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct CommandedDofs([bool; 6]);

impl CommandedDofs {
    /// All six axes (the full 6-DOF figure).
    pub const ALL: Self = Self([true; 6]);

    /// The axes whose entry in `mask` (surge … yaw) is true.
    pub const fn new(mask: [bool; 6]) -> Self {
        Self(mask)
    }

    /// Transport mode (USM-34, USM-40/41): surge and yaw always, the other axes where the
    /// base controller's proportional gain `kp[i]` [1/s] is positive.
    pub fn transport(kp: &[f64; 6]) -> Self {
        Self(std::array::from_fn(|i| i == 0 || i == 5 || kp[i] > 0.0))
    }

    /// Work mode (USM-42, USM-34): an axis is commanded when the base usage weight
    /// `base_weights[i]` of the task-priority solver is positive (the kinematic controller
    /// moves the base along it) or the base controller regulates it (`kp[i] > 0` [1/s] or
    /// `ki[i] > 0` [1/s²]).
    pub fn work(base_weights: &[f64; 6], kp: &[f64; 6], ki: &[f64; 6]) -> Self {
        Self(std::array::from_fn(|i| {
            base_weights[i] > 0.0 || kp[i] > 0.0 || ki[i] > 0.0
        }))
    }

    /// The selection as a mask, surge … yaw.
    pub const fn mask(self) -> [bool; 6] {
        self.0
    }

    /// Whether axis `axis` (0 = surge … 5 = yaw) is commanded.
    pub fn contains(self, axis: usize) -> bool {
        axis < 6 && self.0[axis]
    }

    /// Number of commanded axes `k` (the rows of `S·T_L`).
    pub fn len(self) -> usize {
        self.0.iter().filter(|b| **b).count()
    }

    /// Whether no axis is commanded.
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }

    /// The commanded axes' names joined by `+` (`surge+sway+heave+pitch+yaw`), `none` when
    /// empty.
    pub fn label(self) -> String {
        let names: Vec<&str> = (0..6)
            .filter(|&i| self.0[i])
            .map(|i| AXIS_NAMES[i])
            .collect();
        if names.is_empty() {
            "none".into()
        } else {
            names.join("+")
        }
    }
}

/// Singular values of the commanded rows `S·T_L` of the scaled TCM (docs/model.md §6): how strongly
/// the thrusters can push along the weakest and strongest commanded wrench directions.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CommandedSigma {
    /// The `k` singular values of `S·T_L`, descending, in the first `k` entries (the rest 0);
    /// zero when there are fewer thrusters than commanded axes. N per N.
    pub singular_values: [f64; 6],
    /// Number of commanded axes `k`.
    pub k: usize,
    /// σ_min of `S·T_L` (N per N): the largest scaled wrench `[f; m/L]` the thrusters can make
    /// along the weakest commanded direction per newton of thrust norm `‖u‖₂`. `+inf` when
    /// nothing is commanded; NaN for a non-finite `T` or a bad length.
    pub sigma_min: f64,
    /// σ_max of `S·T_L` (N per N); 0 when nothing is commanded.
    pub sigma_max: f64,
    /// Condition number σ_max/σ_min; `+inf` when σ_min = 0.
    pub condition_number: f64,
}

impl CommandedSigma {
    /// Number of singular values above `rank_rel_tol · σ_max`.
    pub fn rank(&self, rank_rel_tol: f64) -> usize {
        let tol = rank_rel_tol * self.sigma_max;
        self.singular_values[..self.k]
            .iter()
            .filter(|&&s| s > tol)
            .count()
    }

    /// The [`SigmaExtremes`] of these singular values, the rank under `rank_rel_tol`.
    pub fn extremes(&self, rank_rel_tol: f64) -> SigmaExtremes {
        SigmaExtremes {
            k: self.k,
            sigma_min: self.sigma_min,
            sigma_max: self.sigma_max,
            condition_number: self.condition_number,
            rank: self.rank(rank_rel_tol),
        }
    }
}

/// `σ_max/σ_min`, `+inf` unless `σ_min > 0`.
pub(super) fn condition(sigma_max: f64, sigma_min: f64) -> f64 {
    if sigma_min > 0.0 {
        sigma_max / sigma_min
    } else {
        f64::INFINITY
    }
}

/// Below this ratio `λ_min/λ_max` of the Gram matrix (κ > 100) [`commanded_sigma`] leaves the
/// Gram route for the QR + one-sided Jacobi route: the Gram eigenvalues carry an absolute error
/// of about `ε·σ_max²`, a relative error of about `ε κ²/2` on σ_min (≤ 1e-12 for κ ≤ 100).
pub const GRAM_MIN_RATIO: f64 = 1e-4;

/// σ_min, σ_max and κ of the commanded rows `S·T_L` of the scaled TCM (docs/model.md §6; `S` keeps the
/// rows of `dofs`, `T_L = diag(1, 1, 1, 1/L, 1/L, 1/L) T`, `char_length` = L [m]).
///
/// σ_min is the weakest commanded wrench per unit thrust: for every unit-norm direction `w` of
/// the commanded (scaled) wrench space some thrust `u` with `‖u‖₂ = 1 N` makes `S T_L u = σ w`
/// with `σ ≥ σ_min`, and along the weakest direction no thrust of that norm does better.
///
/// Pure and allocation-free (fixed 6×6 work arrays on the stack, any number of thrusters): the
/// eigenvalues of the `k×k` Gram matrix `S T_L T_Lᵀ Sᵀ` (Householder tridiagonalisation and
/// implicit QL), or, when that matrix
/// is ill-conditioned (`λ_min < GRAM_MIN_RATIO·λ_max`), the singular values of the triangular
/// factor of `(S T_L)ᵀ` (Givens QR, one thruster column at a time) by one-sided Jacobi, which
/// keeps small singular values accurate. Agrees with a full SVD to about 1e-12 relative
/// (absolute `ε·σ_max` for rank-deficient matrices).
pub fn commanded_sigma(
    t: &Matrix6xX<f64>,
    char_length: f64,
    dofs: CommandedDofs,
) -> CommandedSigma {
    commanded_sigma_with(&ScaledGram::new(t, char_length), t, dofs)
}

/// The scaled Gram matrix `T_L T_Lᵀ` of all six rows of one `T` (moments divided by
/// `char_length` L [m]), built in one pass over its columns. The Gram matrix of any axis
/// selection `S` is a principal submatrix of it (entry for entry the same sums), so
/// [`commanded_sigma_with`] and [`weakest_direction_with`] score several selections of one
/// configuration — the static analysis does all six axes and the commanded ones — without
/// reading `T` again.
#[derive(Clone, Copy, Debug)]
pub struct ScaledGram {
    gram: [[f64; 6]; 6],
    char_length: f64,
    /// L finite and > 0 and every sum of squares finite (so every entry of `T`).
    pub(super) valid: bool,
}

impl ScaledGram {
    /// The Gram matrix of `t` scaled by `char_length` (zero, and invalid, for a bad L or a
    /// non-finite `t`, or a `t` so large that the sums of squares overflow).
    pub fn new(t: &Matrix6xX<f64>, char_length: f64) -> Self {
        let l_ok = char_length.is_finite() && char_length > 0.0;
        let mut gram = if l_ok {
            full_gram(t, char_length)
        } else {
            [[0.0; 6]; 6]
        };
        // A non-finite entry of `t` makes its row's diagonal entry (a sum of squares) infinite
        // or NaN, so the six diagonal entries stand for the 6·n entries of `t`.
        let valid = l_ok && (0..6).all(|i| gram[i][i].is_finite());
        if !valid {
            gram = [[0.0; 6]; 6];
        }
        Self {
            gram,
            char_length,
            valid,
        }
    }

    /// The whole Gram matrix with its rows and columns in the order `order` (a permutation of
    /// `0..6`).
    pub(super) fn permuted(&self, order: &[usize; 6]) -> [[f64; 6]; 6] {
        std::array::from_fn(|a| std::array::from_fn(|b| self.gram[order[a]][order[b]]))
    }

    /// The `k×k` Gram matrix `S T_L T_Lᵀ Sᵀ` of the rows `rows[..k]`.
    pub(super) fn select(&self, rows: &[usize; 6], k: usize) -> [[f64; 6]; 6] {
        if k == 6 {
            // Six rows of six are all of them, in order.
            return self.gram;
        }
        let mut g = [[0.0; 6]; 6];
        for (ga, &ra) in g.iter_mut().zip(rows).take(k) {
            for (gab, &rb) in ga.iter_mut().zip(rows).take(k) {
                *gab = self.gram[ra][rb];
            }
        }
        g
    }
}

/// [`commanded_sigma`] of the `T` whose [`ScaledGram`] is `g` (`t` is read again only on the
/// ill-conditioned route).
pub fn commanded_sigma_with(
    g: &ScaledGram,
    t: &Matrix6xX<f64>,
    dofs: CommandedDofs,
) -> CommandedSigma {
    let k = dofs.len();
    let mut out = CommandedSigma {
        singular_values: [0.0; 6],
        k,
        sigma_min: f64::INFINITY,
        sigma_max: 0.0,
        condition_number: f64::INFINITY,
    };
    if !g.valid {
        out.sigma_min = f64::NAN;
        out.sigma_max = f64::NAN;
        out.condition_number = f64::NAN;
        return out;
    }
    if k == 0 {
        return out;
    }
    let rows = selected_rows(dofs);
    let mut gram = g.select(&rows, k);
    let mut ev = tridiagonal_eigenvalues(&mut gram, k);
    let (lo, hi) = min_max(&ev[..k]);
    if lo < GRAM_MIN_RATIO * hi {
        ev = triangle_sigma_sq(g, t, &rows, k);
    }
    from_squares(&ev, k)
}

/// The [`CommandedSigma`] of `k` squared singular values `ev[..k]` (any order; negative
/// rounding clipped to 0).
pub(super) fn from_squares(ev: &[f64; 6], k: usize) -> CommandedSigma {
    let mut sv = [0.0; 6];
    for (s, e) in sv.iter_mut().zip(&ev[..k]) {
        *s = e.max(0.0).sqrt();
    }
    sv[..k].sort_by(|a, b| b.total_cmp(a));
    CommandedSigma {
        singular_values: sv,
        k,
        sigma_max: sv[0],
        sigma_min: sv[k - 1],
        condition_number: condition(sv[0], sv[k - 1]),
    }
}

/// The extreme singular values of the commanded rows `S·T_L` and the rank (docs/model.md §6): what
/// the static analysis reports per configuration, at a third of [`commanded_sigma_with`]'s
/// cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmaExtremes {
    /// Number of commanded rows.
    pub k: usize,
    /// σ_min of `S·T_L` (N per N), as [`CommandedSigma::sigma_min`].
    pub sigma_min: f64,
    /// σ_max of `S·T_L` (N per N).
    pub sigma_max: f64,
    /// σ_max/σ_min; `+inf` when σ_min = 0.
    pub condition_number: f64,
    /// Number of singular values above `rank_rel_tol · σ_max`.
    pub rank: usize,
}

/// The squared singular values of `S·T_L` (the rows `rows[..k]` of the `T` whose Gram matrix
/// is `g`) by the route that keeps small ones accurate: the triangular factor of `(S T_L)ᵀ`
/// (Givens QR, one thruster column at a time), then one-sided Jacobi on it.
pub(super) fn triangle_sigma_sq(
    g: &ScaledGram,
    t: &Matrix6xX<f64>,
    rows: &[usize; 6],
    k: usize,
) -> [f64; 6] {
    let mut r = [[0.0; 6]; 6];
    for col in t.column_iter() {
        let x = select_scaled(col.as_slice(), rows, k, g.char_length);
        givens_add_row(&mut r, x, k);
    }
    one_sided_jacobi_sq(&mut r, k)
}

/// The weakest commanded wrench direction of `S·T_L` whose smallest singular value
/// `sigma_min` ([`commanded_sigma`]) is known: the unit left singular vector of σ_min in the
/// scaled wrench space `[f (N); moment/L (N)]` (zero on the uncommanded axes), signed so that
/// its largest-magnitude component is positive. By two steps of inverse iteration on the Gram
/// matrix shifted just below σ_min² (the eigenvector converges by the factor
/// `10⁻⁶σ_min²/(σ_2² − σ_min²)` per step; within a cluster of equal singular values any
/// direction of the cluster). Zero when nothing is commanded or the input is bad.
/// Allocation-free, about a tenth of the cost of [`commanded_sigma`].
pub fn weakest_direction(
    t: &Matrix6xX<f64>,
    char_length: f64,
    dofs: CommandedDofs,
    sigma_min: f64,
) -> [f64; 6] {
    weakest_direction_with(&ScaledGram::new(t, char_length), dofs, sigma_min)
}

/// [`weakest_direction`] of the `T` whose [`ScaledGram`] is `g`.
pub fn weakest_direction_with(g: &ScaledGram, dofs: CommandedDofs, sigma_min: f64) -> [f64; 6] {
    let k = dofs.len();
    let mut dir = [0.0; 6];
    if k == 0 || !sigma_min.is_finite() || !g.valid {
        return dir;
    }
    let rows = selected_rows(dofs);
    let gram = g.select(&rows, k);
    let y = shifted_inverse_iteration(gram, k, sigma_min * sigma_min * (1.0 - 1e-6));
    for (a, &r) in rows.iter().take(k).enumerate() {
        dir[r] = y[a];
    }
    let imax = (0..6).fold(0, |m, i| if dir[i].abs() > dir[m].abs() { i } else { m });
    if dir[imax] < 0.0 {
        dir.iter_mut().for_each(|x| *x = -*x);
    }
    dir
}

/// The `k×k` Gram matrix `S T_L T_Lᵀ Sᵀ` of the rows `rows[..k]` (moments divided by `l`).
#[cfg(test)]
#[allow(clippy::needless_range_loop)] // a symmetric fill reads clearest with indices
fn commanded_gram(t: &Matrix6xX<f64>, l: f64, rows: &[usize; 6], k: usize) -> [[f64; 6]; 6] {
    let mut gram = [[0.0; 6]; 6];
    for col in t.column_iter() {
        let x = select_scaled(col.as_slice(), rows, k, l);
        for a in 0..k {
            for b in 0..=a {
                gram[a][b] += x[a] * x[b];
            }
        }
    }
    for a in 0..k {
        for b in 0..a {
            gram[b][a] = gram[a][b];
        }
    }
    gram
}

/// [`commanded_gram`] of all six rows with the row count and order known at compile time:
/// the same operations in the same order (so the same bits), unrolled.
#[allow(clippy::needless_range_loop)] // a symmetric fill reads clearest with indices
fn full_gram(t: &Matrix6xX<f64>, l: f64) -> [[f64; 6]; 6] {
    let mut gram = [[0.0; 6]; 6];
    for col in t.column_iter() {
        let c = col.as_slice();
        let x = [c[0], c[1], c[2], c[3] / l, c[4] / l, c[5] / l];
        for a in 0..6 {
            for b in 0..=a {
                gram[a][b] += x[a] * x[b];
            }
        }
    }
    for a in 0..6 {
        for b in 0..a {
            gram[b][a] = gram[a][b];
        }
    }
    gram
}

/// The row indices of `dofs`, in order, in the first `dofs.len()` entries.
pub(super) fn selected_rows(dofs: CommandedDofs) -> [usize; 6] {
    let mut rows = [0; 6];
    let mut k = 0;
    for (i, on) in dofs.mask().iter().enumerate() {
        if *on {
            rows[k] = i;
            k += 1;
        }
    }
    rows
}

/// The commanded entries of one column of `T`, moment rows divided by `l`: a column of
/// `S·T_L`.
#[inline]
fn select_scaled(col: &[f64], rows: &[usize; 6], k: usize, l: f64) -> [f64; 6] {
    let mut x = [0.0; 6];
    for (xi, &r) in x.iter_mut().zip(rows).take(k) {
        *xi = if r < 3 { col[r] } else { col[r] / l };
    }
    x
}

/// Fraction of samples whose σ_min is below `threshold` (docs/model.md §6, "how often T is singular");
/// 0 for an empty slice. NaN samples count as singular.
pub fn singular_fraction(sigma_mins: &[f64], threshold: f64) -> f64 {
    if sigma_mins.is_empty() {
        return 0.0;
    }
    let n = sigma_mins
        .iter()
        .filter(|&&s| s.is_nan() || s < threshold)
        .count();
    n as f64 / sigma_mins.len() as f64
}

/// TCM singularity metrics without the attainable-wrench LPs (docs/model.md §6).
///
/// `t`: 6 × n_thrusters, base frame; `char_length`: L [m] (> 0); `rank_rel_tol`: relative rank
/// tolerance (e.g. [`DEFAULT_RANK_REL_TOL`]).
pub fn tcm_svd_metrics(
    t: &Matrix6xX<f64>,
    char_length: f64,
    rank_rel_tol: f64,
) -> Result<TcmMetrics, SingularityError> {
    check_inputs(t, char_length, rank_rel_tol)?;
    let (sv, u) = scaled_svd(t, char_length);
    let sigma_max = sv[0];
    let sigma_min = sv[5];
    let rank_tol = rank_rel_tol * sigma_max;
    let rank = sv.iter().filter(|&&s| s > rank_tol).count();
    let condition_number = if rank < 6 {
        f64::INFINITY
    } else {
        sigma_max / sigma_min
    };
    let mut lost_directions = Vec::new();
    for k in (rank..6).rev() {
        let mut d: Vector6<f64> = u.column(k).into_owned();
        let (imax, _) = d.iamax_full();
        if d[imax] < 0.0 {
            d = -d;
        }
        let mut direction = [0.0; 6];
        direction.copy_from_slice(d.as_slice());
        lost_directions.push(LostDirection {
            sigma: sv[k],
            direction,
            dominant_axis: AXIS_NAMES[imax],
        });
    }
    Ok(TcmMetrics {
        char_length,
        singular_values: sv,
        sigma_min,
        sigma_max,
        condition_number,
        rank,
        rank_tol,
        lost_directions,
        attainable: None,
    })
}

/// Full TCM singularity metrics (docs/model.md §6): [`tcm_svd_metrics`] plus the attainable wrench along
/// each base axis under `u_min ≤ u ≤ u_max` (N), see [`attainable_wrench`].
pub fn tcm_metrics(
    t: &Matrix6xX<f64>,
    u_min: &[f64],
    u_max: &[f64],
    char_length: f64,
    rank_rel_tol: f64,
) -> Result<TcmMetrics, SingularityError> {
    let mut metrics = tcm_svd_metrics(t, char_length, rank_rel_tol)?;
    metrics.attainable = Some(attainable_wrench(t, u_min, u_max)?);
    Ok(metrics)
}

#[cfg(test)]
#[path = "singularity_tests.rs"]
mod tests;

//! Thruster-configuration-matrix (TCM) singularity metrics (SPEC §6).
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

use crate::allocation::{attainable_wrench, AllocError, AttainableWrench};

/// Default relative rank tolerance: a singular value counts as zero below `1e-6 · σ_max`.
pub const DEFAULT_RANK_REL_TOL: f64 = 1e-6;

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

/// A wrench direction the thrusters cannot produce (SPEC §6): a left singular vector of `T_L` whose
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

/// TCM singularity metrics of one configuration (SPEC §6).
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
/// (SPEC §6).
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

/// Iteration cap of the SVD of `T_L` (a 6 × n SVD converges in a few dozen sweeps).
const SVD_MAX_ITERATIONS: usize = 1000;

/// Singular values of `T_L` (SPEC §6), six of them, descending (zeros appended when
/// n_thrusters < 6); NaN when the SVD does not converge within [`SVD_MAX_ITERATIONS`].
/// `t` must be finite (checked by the public entry points).
fn scaled_svd(t: &Matrix6xX<f64>, char_length: f64) -> ([f64; 6], nalgebra::Matrix6<f64>) {
    let n_thrusters = t.ncols();
    // Pad to at least 6 columns so that U is a full 6×6 basis of the wrench space.
    let mut tl = Matrix6xX::<f64>::zeros(n_thrusters.max(6));
    tl.columns_mut(0, n_thrusters)
        .copy_from(&scale_moment_rows(t, char_length));
    // Capped: nalgebra's uncapped SVD iterates forever when scaling overflowed to ±inf. The
    // tolerance is `svd()`'s own (5ε), so the values are bit-identical to it.
    let Some(svd) = tl.try_svd(true, false, 5.0 * f64::EPSILON, SVD_MAX_ITERATIONS) else {
        return ([f64::NAN; 6], nalgebra::Matrix6::zeros());
    };
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

/// Smallest singular value of `T_L` (SPEC §6), the cheap score for "how often T is singular"
/// sampling. `char_length` [m], > 0.
pub fn sigma_min_scaled(t: &Matrix6xX<f64>, char_length: f64) -> Result<f64, SingularityError> {
    check_inputs(t, char_length, 0.0)?;
    Ok(scaled_svd(t, char_length).0[5])
}

/// σ_min of `T_L` (SPEC §6) from the eigenvalues of the 6×6 Gram matrix `T_L T_Lᵀ`, without
/// heap allocation (for logging inside a simulation loop). Accurate to about
/// `√ε · σ_max` ≈ 1e-8·σ_max, ample for comparing with singularity thresholds of 1e-2; use
/// [`sigma_min_scaled`] where exact small singular values matter. NaN if `t` is not finite
/// or `char_length` is not positive.
pub fn sigma_min_scaled_gram(t: &Matrix6xX<f64>, char_length: f64) -> f64 {
    if !(char_length.is_finite() && char_length > 0.0) {
        return f64::NAN;
    }
    let mut gram = nalgebra::Matrix6::<f64>::zeros();
    for col in t.column_iter() {
        let mut c: Vector6<f64> = col.into_owned();
        for i in 3..6 {
            c[i] /= char_length;
        }
        gram += c * c.transpose();
    }
    if !gram.iter().all(|x| x.is_finite()) {
        return f64::NAN;
    }
    let ev = gram.symmetric_eigenvalues();
    ev.min().max(0.0).sqrt()
}

/// Fraction of samples whose σ_min is below `threshold` (SPEC §6, "how often T is singular");
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

/// TCM singularity metrics without the attainable-wrench LPs (SPEC §6).
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

/// Full TCM singularity metrics (SPEC §6): [`tcm_svd_metrics`] plus the attainable wrench along
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
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    fn approx(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    /// A straight USM: 7 thrusters on the body x axis, so no thruster makes a roll moment
    /// (the allocation tests' fixture).
    fn straight_usm() -> Matrix6xX<f64> {
        crate::allocation::tests::straight_t()
    }

    #[test]
    fn known_singular_values_of_diagonal_t() {
        // T = diag(1..6), L = 2: T_L = diag(1, 2, 3, 2, 2.5, 3).
        let mut t = Matrix6xX::zeros(6);
        for i in 0..6 {
            t[(i, i)] = (i + 1) as f64;
        }
        let r = tcm_svd_metrics(&t, 2.0, DEFAULT_RANK_REL_TOL).unwrap();
        let want = [3.0, 3.0, 2.5, 2.0, 2.0, 1.0];
        for k in 0..6 {
            assert!(approx(r.singular_values[k], want[k], 1e-12), "{r:?}");
        }
        assert_eq!(r.rank, 6);
        assert!(approx(r.condition_number, 3.0, 1e-12));
        assert!(r.lost_directions.is_empty());
    }

    #[test]
    fn straight_usm_loses_roll() {
        let t = straight_usm();
        let r = tcm_svd_metrics(&t, 1.0, DEFAULT_RANK_REL_TOL).unwrap();
        assert_eq!(r.rank, 5, "{r:?}");
        assert!(r.condition_number.is_infinite());
        assert_eq!(r.lost_directions.len(), 1);
        let lost = &r.lost_directions[0];
        assert_eq!(lost.dominant_axis, "roll");
        assert!(approx(lost.direction[3], 1.0, 1e-9), "{lost:?}");
        assert!(r.sigma_min < 1e-9);
    }

    #[test]
    fn fewer_than_six_thrusters_is_rank_deficient() {
        let t = straight_usm().columns(2, 3).into_owned();
        let r = tcm_svd_metrics(&t, 1.0, DEFAULT_RANK_REL_TOL).unwrap();
        assert_eq!(r.rank, 3);
        assert_eq!(r.lost_directions.len(), 3);
        assert_eq!(r.sigma_min, 0.0);
    }

    #[test]
    fn attainable_wrench_by_hand() {
        // Thrusters: two along x at the origin, one along each of y, z, and pure moment
        // "thrusters" about x, y, z. Bounds [-10, 20] N.
        let mut t = Matrix6xX::zeros(7);
        t[(0, 0)] = 1.0;
        t[(0, 1)] = 1.0;
        t[(1, 2)] = 1.0;
        t[(2, 3)] = 1.0;
        t[(3, 4)] = 0.5;
        t[(4, 5)] = 2.0;
        t[(5, 6)] = 1.0;
        let r = tcm_metrics(&t, &[-10.0; 7], &[20.0; 7], 1.0, DEFAULT_RANK_REL_TOL).unwrap();
        let a = r.attainable.unwrap();
        let pos = [40.0, 20.0, 20.0, 10.0, 40.0, 20.0];
        let neg = [20.0, 10.0, 10.0, 5.0, 20.0, 10.0];
        for k in 0..6 {
            assert!(approx(a.positive[k], pos[k], 1e-6), "{a:?}");
            assert!(approx(a.negative[k], neg[k], 1e-6), "{a:?}");
        }
    }

    #[test]
    fn attainable_roll_of_straight_usm_is_zero() {
        let t = straight_usm();
        let a = attainable_wrench(&t, &[-40.0; 7], &[40.0; 7]).unwrap();
        assert!(
            a.positive[3].abs() < 1e-6 && a.negative[3].abs() < 1e-6,
            "{a:?}"
        );
        assert!(a.positive[0] > 79.0, "{a:?}");
    }

    #[test]
    fn bad_inputs_are_errors() {
        let t = straight_usm();
        assert!(matches!(
            tcm_svd_metrics(&t, 0.0, 1e-6),
            Err(SingularityError::CharLength(_))
        ));
        let mut bad = t.clone();
        bad[(2, 3)] = f64::NAN;
        assert!(tcm_svd_metrics(&bad, 1.0, 1e-6).is_err());
        assert!(tcm_metrics(&t, &[1.0; 7], &[0.0; 7], 1.0, 1e-6).is_err());
    }

    #[test]
    fn singular_fraction_counts() {
        assert_eq!(singular_fraction(&[0.0, 0.5, 1.0, f64::NAN], 0.6), 0.75);
        assert_eq!(singular_fraction(&[], 0.6), 0.0);
    }

    #[test]
    fn gram_sigma_min_matches_svd_to_its_precision() {
        // sqrt(eps)·σ_max bounds the Gram route's error; 1e-6 is far above it and far
        // below any singularity threshold in use.
        let v = crate::model::presets::usm_paper();
        let mut ws = crate::kinematics::KinWorkspace::new(&v);
        for k in 0..8 {
            let mut q = vec![0.0; 8];
            q[k] = 0.3 * (k as f64 + 1.0) / 8.0;
            crate::kinematics::forward_kinematics(&v, &q, &mut ws);
            let t = crate::kinematics::thruster_matrix_owned(&v, &ws);
            let a = sigma_min_scaled(&t, 1.65).unwrap();
            let b = sigma_min_scaled_gram(&t, 1.65);
            assert!((a - b).abs() < 1e-6, "joint {k}: {a} vs {b}");
        }
        assert!(sigma_min_scaled_gram(&Matrix6xX::zeros(3), 0.0).is_nan());
    }
}

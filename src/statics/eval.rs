//! The per-configuration kernel of the static TCM analysis (docs/model.md §6): forward kinematics,
//! `T(q)` and the scaled singularity metrics of one joint configuration, full and over the
//! commanded axes, with per-worker scratch so that nothing allocates per configuration.

use nalgebra::Matrix6xX;
use serde::Serialize;

use crate::kinematics::{forward_kinematics, thruster_matrix, KinWorkspace};
use crate::metrics::extremes::{commanded_extremes_pair_planned, PairPlan};
use crate::metrics::singularity::{
    tcm_svd_metrics, weakest_direction_with, CommandedDofs, ScaledGram, SingularityError,
    AXIS_NAMES,
};
use crate::model::Vehicle;

/// The metrics of one joint configuration (docs/model.md §6), all in N per N of the scaled `T_L`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SampleMetrics {
    /// Smallest singular value of the scaled `T_L`, all six rows.
    pub sigma_min: f64,
    /// Condition number σ_max/σ_min (`inf` when rank-deficient; JSON `null`).
    pub kappa: f64,
    /// Numerical rank of `T_L`.
    pub rank: usize,
    /// Dominant axis of the weakest wrench direction of `T_L` when σ_min is below the
    /// threshold or the rank is below 6 (`surge` … `yaw`); `None` otherwise.
    pub lost_axis: Option<&'static str>,
    /// Smallest singular value of the commanded rows `S·T_L` (the weakest commanded wrench
    /// per unit thrust, [`commanded_sigma`]).
    pub sigma_min_commanded: f64,
    /// Condition number of `S·T_L` (`inf` when rank-deficient).
    pub kappa_commanded: f64,
    /// Numerical rank of `S·T_L` (at most the number of commanded axes).
    pub rank_commanded: usize,
}

/// Per-worker scratch: kinematics workspace, `T`, the unit-cube sample and the joint angles.
pub(super) struct Scratch {
    ws: KinWorkspace,
    t: Matrix6xX<f64>,
    /// The sampler's point in the unit cube, one entry per joint.
    pub u: Vec<f64>,
    /// The joint angles to evaluate [rad].
    pub q: Vec<f64>,
}

impl Scratch {
    /// Scratch sized for `v`.
    pub fn new(v: &Vehicle) -> Self {
        Self {
            ws: KinWorkspace::new(v),
            t: Matrix6xX::zeros(v.n_thrusters()),
            u: vec![0.0; v.n_joints()],
            q: vec![0.0; v.n_joints()],
        }
    }
}

/// Settings resolved for one vehicle; the vehicle is built once per case and shared.
pub(super) struct Eval<'a> {
    v: &'a Vehicle,
    l: f64,
    tol: f64,
    threshold: f64,
    /// All six rows and the commanded ones, resolved once.
    pair: PairPlan,
}

impl<'a> Eval<'a> {
    /// The evaluator on `v` with characteristic length `l` [m], relative rank tolerance `tol`,
    /// singularity threshold `threshold` (N per N) and the commanded axes `commanded`.
    pub fn new(v: &'a Vehicle, l: f64, tol: f64, threshold: f64, commanded: CommandedDofs) -> Self {
        Self {
            v,
            l,
            tol,
            threshold,
            pair: PairPlan::new([CommandedDofs::ALL, commanded]),
        }
    }

    /// Check that the design can be scored at all (thrusters present, `T` finite at the
    /// straight configuration), with the metric's own error.
    pub fn check(&self, s: &mut Scratch) -> Result<(), SingularityError> {
        s.q.fill(0.0);
        forward_kinematics(self.v, &s.q, &mut s.ws);
        thruster_matrix(self.v, &s.ws, &mut s.t);
        tcm_svd_metrics(&s.t, self.l, self.tol).map(|_| ())
    }

    /// Metrics at the scratch's `q`, without allocating.
    pub fn at(&self, s: &mut Scratch) -> SampleMetrics {
        forward_kinematics(self.v, &s.q, &mut s.ws);
        thruster_matrix(self.v, &s.ws, &mut s.t);
        let g = ScaledGram::new(&s.t, self.l);
        let [full, cmd] = commanded_extremes_pair_planned(&g, &s.t, &self.pair, self.tol);
        let rank = full.rank;
        let flagged = rank < 6 || full.sigma_min < self.threshold;
        let lost_axis = (flagged && full.sigma_min.is_finite()).then(|| {
            let d = weakest_direction_with(&g, CommandedDofs::ALL, full.sigma_min);
            let imax = (0..6).fold(0, |m, i| if d[i].abs() > d[m].abs() { i } else { m });
            AXIS_NAMES[imax]
        });
        let rank_commanded = cmd.rank;
        SampleMetrics {
            sigma_min: full.sigma_min,
            kappa: if rank < 6 {
                f64::INFINITY
            } else {
                full.condition_number
            },
            rank,
            lost_axis,
            sigma_min_commanded: cmd.sigma_min,
            kappa_commanded: if rank_commanded < cmd.k {
                f64::INFINITY
            } else {
                cmd.condition_number
            },
            rank_commanded,
        }
    }
}

/// Joint angles `q` [rad] of the unit-cube point `u`: uniform within each joint's limits.
pub(super) fn map_joint(v: &Vehicle, u: &[f64], q: &mut [f64]) {
    for ((qk, uk), j) in q.iter_mut().zip(u).zip(&v.joints) {
        *qk = j.min + uk * (j.max - j.min);
    }
}

/// A local pool of `threads` workers (0: all cores), or none for 1 (inline evaluation).
pub(super) fn local_pool(
    threads: usize,
) -> Result<Option<rayon::ThreadPool>, rayon::ThreadPoolBuildError> {
    if threads == 1 {
        return Ok(None);
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map(Some)
}

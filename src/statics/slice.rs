//! Slices of the static TCM analysis (docs/model.md §6): σ_min over a 2-D grid of two joints (others
//! straight) and the two joints whose bending most restores the TCM.

use rayon::prelude::*;
use serde::Serialize;

use super::analysis::{evaluator, pool, StaticError, StaticSpec};
use super::eval::Scratch;
use crate::model::Vehicle;

/// σ_min over a 2-D slice of joint space: joints `i` and `j` on a `resolution × resolution`
/// grid within their limits, every other joint at 0.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SliceGrid {
    /// Index of the joint along x.
    pub joint_x: usize,
    /// Index of the joint along y.
    pub joint_y: usize,
    /// Grid angles of joint x [rad].
    pub x: Vec<f64>,
    /// Grid angles of joint y [rad].
    pub y: Vec<f64>,
    /// σ_min, row-major by y: `sigma_min[b * x.len() + a]` at `(x[a], y[b])`.
    pub sigma_min: Vec<f64>,
}

fn linspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![0.5 * (lo + hi)];
    }
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
        .collect()
}

/// σ_min on a grid over joints `i` and `j` (others 0); see [`SliceGrid`]. Errors if a joint
/// index is out of range or equal.
pub fn slice_grid(
    vehicle: &Vehicle,
    spec: &StaticSpec,
    i: usize,
    j: usize,
    resolution: usize,
    threads: usize,
) -> Result<SliceGrid, StaticError> {
    let n = vehicle.n_joints();
    if i >= n || j >= n || i == j {
        return Err(StaticError::Setting {
            key: "slice",
            message: format!("needs two different joint indices in 0..{n}, got {i},{j}"),
        });
    }
    let eval = evaluator(
        vehicle,
        spec,
        spec.char_length_for(vehicle),
        &mut Scratch::new(vehicle),
    )?;
    let res = resolution.clamp(2, 1000);
    let (ji, jj) = (&vehicle.joints[i], &vehicle.joints[j]);
    let x = linspace(ji.min, ji.max, res);
    let y = linspace(jj.min, jj.max, res);
    let cell = |s: &mut Scratch, k: usize| {
        s.q.iter_mut().for_each(|q| *q = 0.0);
        s.q[i] = x[k % res];
        s.q[j] = y[k / res];
        eval.at(s).sigma_min
    };
    let compute = || -> Vec<f64> {
        if threads == 1 {
            let mut s = Scratch::new(vehicle);
            (0..res * res).map(|k| cell(&mut s, k)).collect()
        } else {
            (0..res * res)
                .into_par_iter()
                .map_init(|| Scratch::new(vehicle), |s, k| cell(s, k))
                .collect()
        }
    };
    let sigma_min = match pool(threads)? {
        None => compute(),
        Some(pool) => pool.install(compute),
    };
    Ok(SliceGrid {
        joint_x: i,
        joint_y: j,
        x,
        y,
        sigma_min,
    })
}

/// The two joints whose bending most restores the TCM: among the yaw joints (axis along z;
/// all joints when fewer than two are yaw), the two with the largest mean σ_min when swept
/// alone over their range (others 0). Ties go to the lower index. `None` with fewer than two
/// joints.
pub fn influential_joints(
    vehicle: &Vehicle,
    spec: &StaticSpec,
) -> Result<Option<(usize, usize)>, StaticError> {
    let n = vehicle.n_joints();
    if n < 2 {
        return Ok(None);
    }
    let yaw: Vec<usize> = (0..n)
        .filter(|&k| vehicle.joints[k].axis.z.abs() > 0.9)
        .collect();
    let cands: Vec<usize> = if yaw.len() >= 2 {
        yaw
    } else {
        (0..n).collect()
    };
    let mut s = Scratch::new(vehicle);
    let eval = evaluator(vehicle, spec, spec.char_length_for(vehicle), &mut s)?;
    let mut scores = Vec::new();
    for &k in &cands {
        let j = &vehicle.joints[k];
        let mut sum = 0.0;
        for a in linspace(j.min, j.max, 21) {
            s.q.iter_mut().for_each(|q| *q = 0.0);
            s.q[k] = a;
            sum += eval.at(&mut s).sigma_min;
        }
        scores.push((k, sum));
    }
    scores.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let (a, b) = (scores[0].0, scores[1].0);
    Ok(Some((a.min(b), a.max(b))))
}

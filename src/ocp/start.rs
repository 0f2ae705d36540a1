//! Starts of a solve (docs/ocp.md §4): the column names of `trajectory.csv`, a warm start
//! read back from such a file, and the seeded perturbations of a multi-start.
//!
//! A warm start is an `ocp` trajectory of the same design, actuation and knot count: its
//! header must be [`trajectory_columns`] exactly and it must have N + 1 rows; the states
//! (base pose from position and ZYX angles, joint angles, base twist, joint rates) and the
//! controls (rows 0 … N−1) become the initial iterate of start 0. Start s ≥ 1 adds to start
//! 0's controls a uniform perturbation in `± a·b_i` (b_i the smaller magnitude of control
//! i's bounds, 1 where unbounded; a = `solver.perturbation`) drawn from ChaCha8 seeded with
//! `(seed, s)`, and rolls the states out from `x_0` (single-shooting initialisation).
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use crate::input::document::read_text;
use crate::input::located::{InputError, Location};
use crate::kinematics::BasePose;
use crate::scenario::channels::{Channel, Pose, Twist};
use crate::spatial::Vec3;
use nalgebra::UnitQuaternion;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// The column names of `trajectory.csv`: with `n_thrusters` = Some(m) the thrusts
/// (`simulate`'s actual-thrust names), else the base wrench.
pub fn trajectory_columns(n_joints: usize, n_thrusters: Option<usize>) -> Vec<String> {
    let mut c = vec![Channel::T.name()];
    c.extend(Pose::ALL.map(|p| Channel::BasePose(p).name()));
    c.extend(Twist::ALL.map(|t| Channel::BaseTwist(t).name()));
    c.extend(Pose::ALL.map(|p| Channel::EePose(p).name()));
    c.extend((0..n_joints).map(|k| Channel::Q(k).name()));
    c.extend((0..n_joints).map(|k| Channel::Qd(k).name()));
    c.extend((0..n_joints).map(|k| Channel::Tau(k).name()));
    if let Some(m) = n_thrusters {
        c.extend((0..m).map(|j| Channel::U(j).name()));
        return c;
    }
    c.extend(
        [
            "wrench_fx",
            "wrench_fy",
            "wrench_fz",
            "wrench_mx",
            "wrench_my",
            "wrench_mz",
        ]
        .map(String::from),
    );
    c
}

/// A warm start: states x_0 … x_N and controls u_0 … u_{N−1}.
pub type Trajectory = (Vec<Vec<f64>>, Vec<Vec<f64>>);

/// Read a warm start for `model` with `knots` intervals from `path` (module documentation);
/// errors name the file, the line and the column.
pub fn read_warm_start(
    path: &Path,
    model: &ChainModel,
    knots: usize,
) -> Result<Trajectory, InputError> {
    let origin = path.display().to_string();
    let at = |line: Option<usize>, key: &str, error: String| InputError {
        at: Location {
            origin: origin.clone(),
            line,
            column: None,
            key: key.to_string(),
        },
        error,
    };
    let text = read_text(path).map_err(|e| at(None, "", format!("cannot read: {e}")))?;
    let n = model.n_joints();
    let nb = model.n_body_controls();
    let cols = trajectory_columns(n, model.thruster_actuated().then_some(nb));
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    if header.split(',').ne(cols.iter().map(String::as_str)) {
        let want = cols.join(",");
        return Err(at(
            Some(1),
            "",
            format!("header is not the problem's `{want}`"),
        ));
    }
    let (mut xs, mut us) = (Vec::new(), Vec::new());
    for (r, line) in lines.enumerate() {
        let lno = r + 2;
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != cols.len() {
            let msg = format!("has {} cells, the header {}", cells.len(), cols.len());
            return Err(at(Some(lno), "", msg));
        }
        let num = |c: usize| -> Result<f64, InputError> {
            cells[c]
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    at(
                        Some(lno),
                        &cols[c],
                        format!("`{}` is not a finite number", cells[c]),
                    )
                })
        };
        let v: Vec<f64> = (0..19 + 2 * n).map(&num).collect::<Result<_, _>>()?;
        let pose = BasePose {
            position: Vec3::new(v[1], v[2], v[3]),
            orientation: UnitQuaternion::from_euler_angles(v[4], v[5], v[6]),
        };
        let (q, qd) = (&v[19..19 + n], &v[19 + n..19 + 2 * n]);
        xs.push(ChainModel::pack(&pose, q, &v[7..13], qd));
        if r < knots {
            let mut u: Vec<f64> = (19 + 3 * n..cols.len())
                .map(&num)
                .collect::<Result<_, _>>()?;
            for c in 19 + 2 * n..19 + 3 * n {
                u.push(num(c)?);
            }
            us.push(u);
        }
    }
    if xs.len() != knots + 1 {
        let msg = format!("has {} rows, the problem {} knots + 1", xs.len(), knots);
        return Err(at(None, "", msg));
    }
    Ok((xs, us))
}

/// Start `s`'s controls: `base` perturbed by ChaCha8(`seed`, `s`) within `± a·b_i` (module
/// documentation); `s = 0` returns `base`.
pub fn perturbed_controls(
    base: &[Vec<f64>],
    lo: &[f64],
    hi: &[f64],
    a: f64,
    seed: u64,
    s: usize,
) -> Vec<Vec<f64>> {
    let mut us = base.to_vec();
    if s == 0 {
        return us;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(s as u64);
    for u in us.iter_mut() {
        for i in 0..u.len() {
            let b = lo[i].abs().min(hi[i].abs());
            let b = if b.is_finite() { b } else { 1.0 };
            u[i] += a * b * rng.random_range(-1.0..=1.0);
        }
    }
    us
}

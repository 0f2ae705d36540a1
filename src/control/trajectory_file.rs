//! A [`Reference`] source read from a trajectory file (docs/model.md §5 "References"): a CSV
//! table with the time-series column names of `simulate`'s `timeseries.csv` and of `ocp`'s
//! `trajectory.csv` (docs/columns.md):
//!
//! | columns | need | meaning |
//! |---|---|---|
//! | `t` | required | time [s], strictly increasing, at least two rows |
//! | `base_x, base_y, base_z, base_roll, base_pitch, base_yaw` | required | base pose in `I` [m, rad] (ZYX) |
//! | `q_1 … q_n` | required (n = the design's joints) | joint angles [rad] |
//! | `base_u … base_r` | optional (0) | base twist in `F_b` [m/s, rad/s] |
//! | `qd_1 … qd_n` | optional (0) | joint rates [rad/s] |
//! | `ee_x … ee_yaw` | optional | end-effector pose in `I` [m, rad] |
//! | `wrench_fx … wrench_mz` | optional | feed-forward base wrench in `F_b` [N, N·m] |
//! | `tau_1 … tau_n` | optional | joint torques [N·m] |
//! | `u_1 … u_m` | optional | thrusts [N] (only for [`TrajectoryTable::effort`]) |
//!
//! Other columns are ignored. State cells must be finite numbers; control cells (wrench,
//! torques, thrusts) may be empty (`ocp` leaves the last knot's controls empty), read as NaN.
//!
//! **Interpolation rule** at time `t` in `[t_k, t_{k+1}]`, `s = (t − t_k)/(t_{k+1} − t_k)`:
//! positions, joint angles, twists and joint rates are linear in `s`; the base (and
//! end-effector) attitude is the slerp of the rows' unit quaternions (the geodesic on SO(3) at
//! constant angular rate, the shorter way round); the controls (wrench, torques) are held
//! from row `k` (zero-order hold, the optimal-control discretisation). Outside `[t_0, t_N]`
//! the first (last) row's pose and joint angles are held with zero twist and rates.

use super::reference::{EeReference, Reference};
use crate::spatial::{Vec3, Vec6};
use nalgebra::UnitQuaternion;
use std::path::Path;
use thiserror::Error;

/// Largest trajectory file read (bytes).
pub const MAX_FILE_BYTES: u64 = 512 << 20;

/// The base-pose columns, in order.
pub const BASE_POSE: [&str; 6] = [
    "base_x",
    "base_y",
    "base_z",
    "base_roll",
    "base_pitch",
    "base_yaw",
];
/// The base-twist columns, in order.
pub const BASE_TWIST: [&str; 6] = ["base_u", "base_v", "base_w", "base_p", "base_q", "base_r"];
/// The end-effector pose columns, in order.
pub const EE_POSE: [&str; 6] = ["ee_x", "ee_y", "ee_z", "ee_roll", "ee_pitch", "ee_yaw"];
/// The feed-forward wrench columns, in order.
pub const WRENCH: [&str; 6] = [
    "wrench_fx",
    "wrench_fy",
    "wrench_fz",
    "wrench_mx",
    "wrench_my",
    "wrench_mz",
];

/// A trajectory file that cannot be a reference: the file, and the line (1 = the header) and
/// column where it is wrong.
#[derive(Debug, Error)]
pub enum ReferenceFileError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The file-system error.
        #[source]
        source: std::io::Error,
    },
    /// The file is larger than [`MAX_FILE_BYTES`].
    #[error("{path}: {bytes} bytes, more than the {MAX_FILE_BYTES} a trajectory file may have")]
    TooLarge {
        /// The file.
        path: String,
        /// Its size.
        bytes: u64,
    },
    /// A column the reference needs is not in the header.
    #[error("{path}:1: no column `{column}` (a reference needs t, base_x … base_yaw and q_1 … q_{joints})")]
    MissingColumn {
        /// The file.
        path: String,
        /// The missing column.
        column: String,
        /// The design's joint count.
        joints: usize,
    },
    /// A column name appears twice in the header.
    #[error("{path}:1: column `{column}` appears twice")]
    DuplicateColumn {
        /// The file.
        path: String,
        /// The repeated column.
        column: String,
    },
    /// The file has joint columns beyond the design's joints.
    #[error("{path}:1: column `{column}`, but the design has {joints} joints")]
    ExtraJoint {
        /// The file.
        path: String,
        /// The first joint column beyond the design.
        column: String,
        /// The design's joint count.
        joints: usize,
    },
    /// A row has a different number of cells from the header.
    #[error("{path}:{line}: {found} cells, the header has {expected}")]
    RowLength {
        /// The file.
        path: String,
        /// File line (1 = the header).
        line: usize,
        /// Cells found.
        found: usize,
        /// Cells in the header.
        expected: usize,
    },
    /// A cell is not a number (or a state cell not finite).
    #[error("{path}:{line}: column `{column}`: `{text}` is not a finite number")]
    BadNumber {
        /// The file.
        path: String,
        /// File line.
        line: usize,
        /// The column.
        column: String,
        /// The cell as written.
        text: String,
    },
    /// Time does not strictly increase.
    #[error("{path}:{line}: t = {t} does not increase (the row before has t = {previous})")]
    TimeNotIncreasing {
        /// The file.
        path: String,
        /// File line.
        line: usize,
        /// This row's time.
        t: f64,
        /// The previous row's time.
        previous: f64,
    },
    /// Fewer than two data rows.
    #[error("{path}: {rows} data rows; a reference needs at least 2")]
    TooFewRows {
        /// The file.
        path: String,
        /// Data rows found.
        rows: usize,
    },
}

/// A trajectory read from a file, ready to be sampled without allocating (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct TrajectoryTable {
    n: usize,
    t: Vec<f64>,
    position: Vec<Vec3>,
    attitude: Vec<UnitQuaternion<f64>>,
    twist: Vec<Vec6>,
    q: Vec<f64>,
    qd: Vec<f64>,
    ee: Option<(Vec<Vec3>, Vec<UnitQuaternion<f64>>)>,
    wrench: Option<Vec<Vec6>>,
    tau: Option<Vec<f64>>,
    thrust: Option<(usize, Vec<f64>)>,
}

/// The columns of one parsed header.
struct Header<'a> {
    names: Vec<&'a str>,
}

impl<'a> Header<'a> {
    fn find(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|c| *c == name)
    }
}

/// The parsed cells of a file: one `Vec<f64>` per column, with the file name for errors.
struct Cells<'a> {
    path: &'a str,
    header: Header<'a>,
    columns: Vec<Vec<f64>>,
    joints: usize,
}

impl Cells<'_> {
    fn missing(&self, column: &str) -> ReferenceFileError {
        ReferenceFileError::MissingColumn {
            path: self.path.to_string(),
            column: column.to_string(),
            joints: self.joints,
        }
    }

    /// The column `name`, required.
    fn required(&self, name: &str) -> Result<&[f64], ReferenceFileError> {
        self.optional(name).ok_or_else(|| self.missing(name))
    }

    fn optional(&self, name: &str) -> Option<&[f64]> {
        self.header.find(name).map(|i| self.columns[i].as_slice())
    }

    /// All of `names`, if every one is present; `Err` naming the first missing one if some
    /// but not all are (a partial group is a mistake), `Ok(None)` if none is.
    fn group<S: AsRef<str>>(&self, names: &[S]) -> Result<Option<Vec<&[f64]>>, ReferenceFileError> {
        let found: Vec<Option<&[f64]>> = names.iter().map(|n| self.optional(n.as_ref())).collect();
        if found.iter().all(Option::is_none) {
            return Ok(None);
        }
        match found.iter().position(Option::is_none) {
            Some(i) => Err(self.missing(names[i].as_ref())),
            None => Ok(Some(found.into_iter().flatten().collect())),
        }
    }
}

/// Parse one cell: a finite number, or (for a control column, `lenient`) empty / NaN.
fn cell(text: &str, lenient: bool) -> Option<f64> {
    let s = text.trim();
    if lenient && s.is_empty() {
        return Some(f64::NAN);
    }
    let v: f64 = s.parse().ok()?;
    (v.is_finite() || (lenient && v.is_nan())).then_some(v)
}

/// Whether a column holds controls (may be empty at the last knot).
fn is_control(name: &str) -> bool {
    name.starts_with("wrench_") || name.starts_with("tau_") || name.starts_with("u_")
}

/// Whether a column is read into the reference (state cells must be finite).
fn is_read(name: &str, joints: usize) -> bool {
    let joint = |prefix: &str| {
        name.strip_prefix(prefix)
            .and_then(|k| k.parse::<usize>().ok())
            .is_some_and(|k| k >= 1 && k <= joints)
    };
    name == "t"
        || BASE_POSE.contains(&name)
        || BASE_TWIST.contains(&name)
        || EE_POSE.contains(&name)
        || joint("q_")
        || joint("qd_")
}

fn quaternion(roll: f64, pitch: f64, yaw: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_euler_angles(roll, pitch, yaw)
}

/// Unit quaternions of ZYX angle columns, each in the hemisphere of the one before (so
/// that slerp between neighbours takes the shorter way).
fn attitudes(roll: &[f64], pitch: &[f64], yaw: &[f64]) -> Vec<UnitQuaternion<f64>> {
    let mut out: Vec<UnitQuaternion<f64>> = Vec::with_capacity(roll.len());
    for k in 0..roll.len() {
        let mut q = quaternion(roll[k], pitch[k], yaw[k]);
        if let Some(prev) = out.last() {
            if prev.coords.dot(&q.coords) < 0.0 {
                q = UnitQuaternion::new_unchecked(-q.into_inner());
            }
        }
        out.push(q);
    }
    out
}

impl TrajectoryTable {
    /// Read `path` for a design with `n_joints` joints (module docs); errors name the file,
    /// the line and the column.
    pub fn read(path: &Path, n_joints: usize) -> Result<Self, ReferenceFileError> {
        let name = path.display().to_string();
        let io = |source| ReferenceFileError::Io {
            path: name.clone(),
            source,
        };
        let bytes = std::fs::metadata(path).map_err(io)?.len();
        if bytes > MAX_FILE_BYTES {
            return Err(ReferenceFileError::TooLarge { path: name, bytes });
        }
        let text = std::fs::read_to_string(path).map_err(io)?;
        Self::parse(&text, &name, n_joints)
    }

    /// Parse CSV `text` named `origin` in errors (see [`TrajectoryTable::read`]).
    pub fn parse(text: &str, origin: &str, n_joints: usize) -> Result<Self, ReferenceFileError> {
        let cells = parse_cells(text, origin, n_joints)?;
        let t = cells.required("t")?.to_vec();
        let table = Self::columns(&cells, t, n_joints)?;
        let t = &table.t;
        if t.len() < 2 {
            return Err(ReferenceFileError::TooFewRows {
                path: origin.to_string(),
                rows: t.len(),
            });
        }
        for (k, w) in t.windows(2).enumerate() {
            if w[1] <= w[0] {
                return Err(ReferenceFileError::TimeNotIncreasing {
                    path: origin.to_string(),
                    line: k + 3,
                    t: w[1],
                    previous: w[0],
                });
            }
        }
        Ok(table)
    }

    /// The table of the parsed `cells` with times `t`, before the checks of the rows.
    fn columns(cells: &Cells, t: Vec<f64>, n_joints: usize) -> Result<Self, ReferenceFileError> {
        let rows = t.len();
        let pose: Vec<&[f64]> = (BASE_POSE.iter())
            .map(|c| cells.required(c))
            .collect::<Result<_, _>>()?;
        let position = (0..rows)
            .map(|k| Vec3::new(pose[0][k], pose[1][k], pose[2][k]))
            .collect();
        let attitude = attitudes(pose[3], pose[4], pose[5]);
        let q_names: Vec<String> = (1..=n_joints).map(|k| format!("q_{k}")).collect();
        let q_cols: Vec<&[f64]> = (q_names.iter())
            .map(|c| cells.required(c))
            .collect::<Result<_, _>>()?;
        let qd_names: Vec<String> = (1..=n_joints).map(|k| format!("qd_{k}")).collect();
        let qd_cols = cells.group(&qd_names)?;
        let tau_names: Vec<String> = (1..=n_joints).map(|k| format!("tau_{k}")).collect();
        let tau = cells.group(&tau_names)?.map(|c| row_major(&c, rows));
        let twist = match cells.group(&BASE_TWIST)? {
            Some(c) => (0..rows).map(|k| Vec6::from_fn(|i, _| c[i][k])).collect(),
            None => vec![Vec6::zeros(); rows],
        };
        let ee = cells.group(&EE_POSE)?.map(|c| {
            let p = (0..rows).map(|k| Vec3::new(c[0][k], c[1][k], c[2][k]));
            (p.collect(), attitudes(c[3], c[4], c[5]))
        });
        let wrench = (cells.group(&WRENCH)?)
            .map(|c| (0..rows).map(|k| Vec6::from_fn(|i, _| c[i][k])).collect());
        let m = (1..).take_while(|j| cells.header.find(&format!("u_{j}")).is_some());
        let m = m.count();
        let thrust = (m > 0).then(|| {
            let c: Vec<&[f64]> = (1..=m)
                .filter_map(|j| cells.optional(&format!("u_{j}")))
                .collect();
            (m, row_major(&c, rows))
        });
        Ok(Self {
            n: n_joints,
            position,
            attitude,
            twist,
            q: row_major(&q_cols, rows),
            qd: qd_cols.map_or_else(|| vec![0.0; rows * n_joints], |c| row_major(&c, rows)),
            ee,
            wrench,
            tau,
            thrust,
            t,
        })
    }

    /// The number of joints of each row.
    pub fn n_joints(&self) -> usize {
        self.n
    }

    /// The first and last time of the table [s].
    pub fn span(&self) -> (f64, f64) {
        (self.t[0], self.t[self.t.len() - 1])
    }

    /// The control effort of the table, `J = Σ_k (t_{k+1} − t_k) (‖u_k‖² + ‖τ_k‖² + ‖w_k‖²)`
    /// over the rows before the last, with the thrusts `u`, joint torques `τ` and wrench `w`
    /// it has (the `effort` objective of `usm-study ocp` when its weight is 1); `None` when it
    /// has no control column.
    pub fn effort(&self) -> Option<f64> {
        if self.tau.is_none() && self.wrench.is_none() && self.thrust.is_none() {
            return None;
        }
        let sq = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>();
        let mut j = 0.0;
        for k in 0..self.t.len() - 1 {
            let mut s = 0.0;
            if let Some(tau) = &self.tau {
                s += sq(&tau[k * self.n..(k + 1) * self.n]);
            }
            if let Some(w) = &self.wrench {
                s += w[k].norm_squared();
            }
            if let Some((m, u)) = &self.thrust {
                s += sq(&u[k * m..(k + 1) * m]);
            }
            j += (self.t[k + 1] - self.t[k]) * s;
        }
        Some(j)
    }

    /// `Σ_k (t_{k+1} − t_k) Σ_j f(u_jk)` over the thrust columns `u_j` and the rows before the
    /// last (e.g. `f` the static actuator-disk power: the reference's thruster energy [J]);
    /// `None` without thrust columns.
    pub fn thrust_integral(&self, f: impl Fn(f64) -> f64) -> Option<f64> {
        let (m, u) = self.thrust.as_ref()?;
        let mut e = 0.0;
        for k in 0..self.t.len() - 1 {
            let p: f64 = u[k * m..(k + 1) * m].iter().map(|x| f(*x)).sum();
            e += (self.t[k + 1] - self.t[k]) * p;
        }
        Some(e)
    }

    /// Fill `out` with the reference at `t` [s] by the rule of the module docs; sets the base,
    /// the joints and, when the file has them, the end effector (with zero twist), the wrench
    /// and the torques. Allocation-free.
    pub fn sample_into(&self, t: f64, out: &mut Reference) {
        let (first, last) = (0, self.t.len() - 1);
        let n = self.n;
        let outside = t < self.t[first] || t > self.t[last];
        // Interval k with t_k <= t < t_{k+1} (clamped), and the fraction s inside it.
        let k = self.t[1..last].partition_point(|&x| x <= t);
        let (t0, t1) = (self.t[k], self.t[k + 1]);
        let s = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let lerp = |a: f64, b: f64| a + (b - a) * s;
        out.has_base = true;
        out.base_position = self.position[k].lerp(&self.position[k + 1], s);
        out.base_orientation = slerp(&self.attitude[k], &self.attitude[k + 1], s);
        out.has_joints = true;
        for i in 0..n {
            out.q[i] = lerp(self.q[k * n + i], self.q[(k + 1) * n + i]);
            out.qd[i] = lerp(self.qd[k * n + i], self.qd[(k + 1) * n + i]);
        }
        out.base_twist = self.twist[k].lerp(&self.twist[k + 1], s);
        if outside {
            out.base_twist = Vec6::zeros();
            out.qd.fill(0.0);
        }
        out.ee = self.ee.as_ref().map(|(p, r)| EeReference {
            position: p[k].lerp(&p[k + 1], s),
            orientation: slerp(&r[k], &r[k + 1], s),
            twist: Vec6::zeros(),
        });
        // Controls: held from the row the interval starts at (row k; the last row's
        // controls, often empty, are never used).
        out.wrench = self.wrench.as_ref().map(|w| w[k]);
        out.has_torques = self.tau.is_some();
        if let Some(tau) = &self.tau {
            out.torques.copy_from_slice(&tau[k * n..(k + 1) * n]);
        }
    }
}

/// Slerp from `a` to `b` at `s`, the shorter way; `a` if they are opposite (never: the rows
/// are made to share a hemisphere).
fn slerp(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>, s: f64) -> UnitQuaternion<f64> {
    a.try_slerp(b, s, 1e-12).unwrap_or(*a)
}

/// Columns `c[i][k]` as rows `out[k * c.len() + i]`.
fn row_major(c: &[&[f64]], rows: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(rows * c.len());
    for k in 0..rows {
        out.extend(c.iter().map(|col| col[k]));
    }
    out
}

/// Split `text` into its header and numeric columns; the columns the reference reads must
/// hold finite numbers, control columns may be empty, other columns are skipped.
fn parse_cells<'a>(
    text: &'a str,
    path: &'a str,
    joints: usize,
) -> Result<Cells<'a>, ReferenceFileError> {
    let mut lines = text.lines().map(|l| l.trim_end_matches('\r'));
    let names: Vec<&str> = match lines.next() {
        Some(h) if !h.trim().is_empty() => h.split(',').map(str::trim).collect(),
        _ => {
            return Err(ReferenceFileError::TooFewRows {
                path: path.to_string(),
                rows: 0,
            })
        }
    };
    for (i, c) in names.iter().enumerate() {
        if names[..i].contains(c) {
            return Err(ReferenceFileError::DuplicateColumn {
                path: path.to_string(),
                column: c.to_string(),
            });
        }
    }
    for prefix in ["q_", "qd_"] {
        let extra = format!("{prefix}{}", joints + 1);
        if names.contains(&extra.as_str()) {
            return Err(ReferenceFileError::ExtraJoint {
                path: path.to_string(),
                column: extra,
                joints,
            });
        }
    }
    let wanted: Vec<Option<bool>> = (names.iter())
        .map(|c| {
            if is_read(c, joints) {
                Some(false)
            } else if is_control(c) {
                Some(true)
            } else {
                None
            }
        })
        .collect();
    let mut columns = vec![Vec::new(); names.len()];
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let row: Vec<&str> = line.split(',').collect();
        if row.len() != names.len() {
            return Err(ReferenceFileError::RowLength {
                path: path.to_string(),
                line: i + 2,
                found: row.len(),
                expected: names.len(),
            });
        }
        for (c, text) in row.iter().enumerate() {
            let Some(lenient) = wanted[c] else { continue };
            let v = cell(text, lenient).ok_or_else(|| ReferenceFileError::BadNumber {
                path: path.to_string(),
                line: i + 2,
                column: names[c].to_string(),
                text: text.trim().to_string(),
            })?;
            columns[c].push(v);
        }
    }
    Ok(Cells {
        path,
        header: Header { names },
        columns,
        joints,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-joint table: header and rows `t, base pose, q_1, q_2, qd_1, qd_2, tau_1, tau_2`.
    fn text(rows: &[&str]) -> String {
        let mut s = String::from(
            "t,base_x,base_y,base_z,base_roll,base_pitch,base_yaw,q_1,q_2,qd_1,qd_2,tau_1,tau_2,psi\n",
        );
        for r in rows {
            s.push_str(r);
            s.push('\n');
        }
        s
    }

    fn ok() -> TrajectoryTable {
        let t = text(&[
            "0,0,0,0,0,0,3.1,0.0,0.2,0,1,1,2,9",
            "1,1,2,0,0,0,-3.1,0.2,0.0,1,0,3,4,9",
            "2,1,2,0,0,0,-3.1,0.2,0.0,0,0,,,9",
        ]);
        TrajectoryTable::parse(&t, "r.csv", 2).unwrap()
    }

    #[test]
    fn interpolation_is_linear_in_position_slerp_in_attitude_held_in_controls() {
        let tab = ok();
        let mut r = Reference::new(2);
        tab.sample_into(0.25, &mut r);
        assert!((r.base_position - Vec3::new(0.25, 0.5, 0.0)).norm() < 1e-15);
        assert!((r.q[0] - 0.05).abs() < 1e-15 && (r.q[1] - 0.15).abs() < 1e-15);
        assert!((r.qd[0] - 0.25).abs() < 1e-15 && (r.qd[1] - 0.75).abs() < 1e-15);
        // Yaw 3.1 → −3.1 the short way through π (0.0832 rad), not back through 0.
        let yaw = |r: &Reference| {
            let m = r.base_orientation.to_rotation_matrix();
            m.matrix()[(1, 0)].atan2(m.matrix()[(0, 0)])
        };
        tab.sample_into(0.5, &mut r);
        assert!(
            (yaw(&r).abs() - std::f64::consts::PI).abs() < 1e-12,
            "{}",
            yaw(&r)
        );
        // Zero-order hold of the torques from the interval's first row.
        assert_eq!(r.torques, vec![1.0, 2.0]);
        assert!(r.has_torques && r.wrench.is_none() && r.ee.is_none());
        // Outside the span: held pose, zero rates.
        tab.sample_into(5.0, &mut r);
        assert_eq!(r.base_position, Vec3::new(1.0, 2.0, 0.0));
        assert_eq!(r.qd, vec![0.0, 0.0]);
        assert_eq!(r.torques, vec![3.0, 4.0]);
        // Effort Σ Δt ‖τ‖² over the rows before the last: 1·(1+4) + 1·(9+16).
        assert_eq!(tab.effort(), Some(30.0));
        assert_eq!(tab.span(), (0.0, 2.0));
    }

    #[test]
    fn a_bad_file_names_its_line_and_column() {
        let err = |t: &str| {
            TrajectoryTable::parse(t, "r.csv", 2)
                .unwrap_err()
                .to_string()
        };
        let e = err(&text(&[
            "0,0,0,0,0,0,0,0,0,0,0,0,0,0",
            "1,0,x,0,0,0,0,0,0,0,0,0,0,0",
        ]));
        assert_eq!(e, "r.csv:3: column `base_y`: `x` is not a finite number");
        let e = err(&text(&[
            "0,0,0,0,0,0,0,0,0,0,0,0,0,0",
            "1,0,0,0,0,0,0,nan,0,0,0,0,0,0",
        ]));
        assert_eq!(e, "r.csv:3: column `q_1`: `nan` is not a finite number");
        let e = err(&text(&[
            "0,0,0,0,0,0,0,0,0,0,0,0,0,0",
            "0,0,0,0,0,0,0,0,0,0,0,0,0,0",
        ]));
        assert!(e.starts_with("r.csv:3: t = 0 does not increase"), "{e}");
        let e = err(&text(&["0,0,0,0,0,0,0,0,0,0,0,0,0,0", "1,0,0"]));
        assert_eq!(e, "r.csv:3: 3 cells, the header has 14");
        let e = err(&text(&["0,0,0,0,0,0,0,0,0,0,0,0,0,0"]));
        assert_eq!(e, "r.csv: 1 data rows; a reference needs at least 2");
        let e = TrajectoryTable::parse(&text(&[]), "r.csv", 3)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.csv:1: no column `q_3`"), "{e}");
        let e = TrajectoryTable::parse(&text(&[]), "r.csv", 1)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "r.csv:1: column `q_2`, but the design has 1 joints");
        let partial = "t,base_x,base_y,base_z,base_roll,base_pitch,base_yaw,q_1,base_u\n";
        let e = TrajectoryTable::parse(partial, "r.csv", 1)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("r.csv:1: no column `base_v`"), "{e}");
        let e = TrajectoryTable::parse("t,t\n", "r.csv", 0)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "r.csv:1: column `t` appears twice");
        let e = TrajectoryTable::read(Path::new("/no/such/file.csv"), 0).unwrap_err();
        assert!(matches!(e, ReferenceFileError::Io { .. }), "{e}");
    }
}

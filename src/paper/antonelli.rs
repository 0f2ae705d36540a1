//! The kinematic case studies of Antonelli & Chiaverini (1998), section 5 (docs/model.md §8), on the
//! planar UVMS preset `uvms-planar`: closed-loop task-priority inverse kinematics (AC-7…9)
//!
//! `ζ = J_p^# w_p + (I − J_p^# J_p) J_s^# w_s`, `w_p = ξ̇_p,d + K_p(ξ_p,d − ξ_p)`,
//! `w_s = ξ̇_s,d + K_s(ξ_s,d − ξ_s)`,
//!
//! resolved by the crate's task-priority solver ([`Srmtp`], singularity-robust form) on
//! inertial-frame task variables ([`InertialTask`]), and integrated directly (`ζ = ζ_r`: the
//! paper's case studies 1 and 2 are kinematic, no dynamics).
//!
//! | case | primary `ξ_p` (AC-10/12) | secondary `ξ_s` (AC-11/13) | references (quintic, 10 s) |
//! |---|---|---|---|
//! | `case1` | `x_e, y_e, ψ_e, ψ` | `x, y` | end-effector held, `ψ_d`: 0 → 0.78 rad |
//! | `case1b` | `x_e, y_e, ψ_e, ψ` | `x, y` | end-effector along the line to (8.00 m, 9.00 m, 0.78 rad), `ψ_d`: 0 → 0.78 |
//! | `case2` | `x_e, y_e, ψ_e, q₂` | `x, y` | the same line, `q₂,d`: −1.00 → −0.78 rad |
//!
//! All: vehicle at (0, 0, 0), `q = (1.47, −1.00, 0.30)` rad (end-effector at (5.92, 4.29, 0.77)),
//! `K_p = diag(10, 10, 10, 1)`, `K_s = diag(2, 2)`, the vehicle position held at its initial
//! value by the secondary task. Choices the paper does not state (inferred, overridable in
//! [`KinematicCase`]): the run lasts the 10 s of the quintic; RK4 at 1 ms (the closed loop has
//! time constants ≥ 0.1 s); samples every 50 ms (20 Hz: the motions are smooth over 10 s). The Jacobians' pseudoinverses are the
//! Moore–Penrose ones of the planar system (λ = 0, usage weights selecting u, v, r and the
//! joints: [`planar_weights`]); heave, roll and pitch stay zero, so the state is
//! `(x, y, ψ, q)` with `ẋ = u cos ψ − v sin ψ`, `ẏ = u sin ψ + v cos ψ`, `ψ̇ = r`.
//!
//! Case 3 (the dynamic NPS AUV II runs behind Table I) is in [`dynamic`].

pub mod dynamic;

use crate::control::{InertialTask, Quintic, Srmtp, TaskInverse, TaskVariable};
use crate::kinematics::{forward_kinematics, BasePose, KinWorkspace};
use crate::model::Vehicle;
use crate::scenario::ScenarioError;
use crate::spatial::Vec3;
use nalgebra::UnitQuaternion;
use serde::Serialize;

/// The paper's kinematic simulations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AntonelliCase {
    /// Case 1: re-orientation of the vehicle (ψ → 0.78 rad) with the end-effector held.
    Case1,
    /// Case 1b: the same tasks, the end-effector along a straight line to (8, 9, 0.78).
    Case1b,
    /// Case 2: dexterity, `q₂ → −0.78` rad, the end-effector along the same line.
    Case2,
}

impl AntonelliCase {
    /// All three, in the paper's order.
    pub const ALL: [AntonelliCase; 3] = [
        AntonelliCase::Case1,
        AntonelliCase::Case1b,
        AntonelliCase::Case2,
    ];

    /// `case1`, `case1b`, `case2`.
    pub fn name(self) -> &'static str {
        match self {
            AntonelliCase::Case1 => "case1",
            AntonelliCase::Case1b => "case1b",
            AntonelliCase::Case2 => "case2",
        }
    }
}

/// One scalar task row: its variable, its final desired value (`None`: hold the initial
/// value) and its closed-loop gain (a diagonal entry of `K_p` or `K_s`, 1/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaskRow {
    /// The task coordinate.
    pub variable: TaskVariable,
    /// Final desired value (task units), reached by a quintic over [`KinematicCase::ramp`].
    pub target: Option<f64>,
    /// Gain of AC-8/9 [1/s].
    pub gain: f64,
}

/// A kinematic task-priority simulation on a planar floating-base chain.
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicCase {
    /// Name used for outputs.
    pub name: String,
    /// Primary task rows (AC-8).
    pub primary: Vec<TaskRow>,
    /// Secondary task rows (AC-9).
    pub secondary: Vec<TaskRow>,
    /// Initial vehicle pose `(x [m], y [m], ψ [rad])` in `I`.
    pub base: [f64; 3],
    /// Initial joint angles [rad].
    pub q0: Vec<f64>,
    /// Duration of the quintic references [s] (paper: 10).
    pub ramp: f64,
    /// Simulated time [s] (inferred: 10).
    pub duration: f64,
    /// RK4 step [s] (inferred: 0.001).
    pub dt: f64,
    /// Record every this many steps (default 50: 20 Hz).
    pub record_every: usize,
}

fn row(variable: TaskVariable, target: Option<f64>, gain: f64) -> TaskRow {
    TaskRow {
        variable,
        target,
        gain,
    }
}

/// The paper's set-up of `which` (section 5; see the module table).
pub fn antonelli_case(which: AntonelliCase) -> KinematicCase {
    use TaskVariable::*;
    let line = |v: f64| match which {
        AntonelliCase::Case1 => None,
        _ => Some(v),
    };
    let fourth = match which {
        AntonelliCase::Case2 => row(Joint(1), Some(-0.78), 1.0),
        _ => row(BaseHeading, Some(0.78), 1.0),
    };
    KinematicCase {
        name: which.name().into(),
        primary: vec![
            row(EePosition(0), line(8.0), 10.0),
            row(EePosition(1), line(9.0), 10.0),
            row(EeHeading, line(0.78), 10.0),
            fourth,
        ],
        secondary: vec![
            row(BasePosition(0), None, 2.0),
            row(BasePosition(1), None, 2.0),
        ],
        base: [0.0; 3],
        q0: vec![1.47, -1.00, 0.30],
        ramp: 10.0,
        duration: 10.0,
        dt: 1e-3,
        record_every: 50,
    }
}

/// Usage weights selecting the planar motions of a chain with `n` joints: surge, sway, yaw
/// rate and every joint (1); heave, roll and pitch rates excluded (0).
pub fn planar_weights(n: usize) -> Vec<f64> {
    let mut u = vec![1.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    u.extend(std::iter::repeat_n(1.0, n));
    u
}

/// Time history of one task row: desired and actual values (task units).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TaskTrace {
    /// Column name of the variable (`x_e`, `psi`, `q2`, …).
    pub name: String,
    /// Whether the variable is a heading (errors wrapped).
    pub heading: bool,
    /// Desired value `ξ_d(t)`.
    pub desired: Vec<f64>,
    /// Actual value `ξ(t)`.
    pub value: Vec<f64>,
}

impl TaskTrace {
    /// Largest `|ξ_d − ξ|` over the run (headings wrapped).
    pub fn max_abs_error(&self) -> f64 {
        self.desired
            .iter()
            .zip(&self.value)
            .map(|(d, v)| {
                let e = d - v;
                if self.heading {
                    crate::spatial::wrap_angle(e).abs()
                } else {
                    e.abs()
                }
            })
            .fold(0.0, f64::max)
    }

    /// The last value.
    pub fn final_value(&self) -> f64 {
        self.value.last().copied().unwrap_or(f64::NAN)
    }
}

/// Sampled time histories of a kinematic case (SI units, angles in rad, inertial frame unless
/// stated).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KinematicHistory {
    /// Case name.
    pub name: String,
    /// Time [s].
    pub t: Vec<f64>,
    /// Vehicle pose `x, y` [m], `ψ` [rad].
    pub base: [Vec<f64>; 3],
    /// Vehicle velocity `ẋ, ẏ` [m/s], `ψ̇` [rad/s] (inertial).
    pub base_rate: [Vec<f64>; 3],
    /// Commanded body twist `u, v` [m/s], `r` [rad/s] (vehicle frame).
    pub twist: [Vec<f64>; 3],
    /// Joint angles [rad], one vector per joint.
    pub q: Vec<Vec<f64>>,
    /// Joint rates [rad/s], one vector per joint.
    pub qd: Vec<Vec<f64>>,
    /// End-effector `x_e, y_e` [m], `ψ_e` [rad].
    pub ee: [Vec<f64>; 3],
    /// Primary task rows.
    pub primary: Vec<TaskTrace>,
    /// Secondary task rows.
    pub secondary: Vec<TaskTrace>,
    /// Algorithmic-singularity measure `σ_min(J_s N_p)` ([`Srmtp::projected_singular_value`]).
    pub sigma_s: Vec<f64>,
}

impl KinematicHistory {
    /// Every sampled series as `(column name, values)`, time first — for CSV writers and
    /// figures.
    pub fn columns(&self) -> Vec<(String, &[f64])> {
        let mut c: Vec<(String, &[f64])> = vec![("t".into(), &self.t)];
        for (k, name) in ["x", "y", "psi"].iter().enumerate() {
            c.push((name.to_string(), &self.base[k]));
        }
        for (k, name) in ["x_dot", "y_dot", "psi_dot"].iter().enumerate() {
            c.push((name.to_string(), &self.base_rate[k]));
        }
        for (k, name) in ["u", "v", "r"].iter().enumerate() {
            c.push((name.to_string(), &self.twist[k]));
        }
        for (k, s) in self.q.iter().enumerate() {
            c.push((format!("q{}", k + 1), s));
        }
        for (k, s) in self.qd.iter().enumerate() {
            c.push((format!("q{}_dot", k + 1), s));
        }
        for (k, name) in ["x_e", "y_e", "psi_e"].iter().enumerate() {
            c.push((name.to_string(), &self.ee[k]));
        }
        for (level, traces) in [("p", &self.primary), ("s", &self.secondary)] {
            for tr in traces {
                c.push((format!("{level}_{}_d", tr.name), &tr.desired));
                c.push((format!("{level}_{}", tr.name), &tr.value));
            }
        }
        c.push(("sigma_s".into(), &self.sigma_s));
        c
    }
}

/// The per-step state of a run: vehicle, kinematics, tasks, references and the solver.
struct Resolver {
    n: usize,
    ws: KinWorkspace,
    primary: InertialTask,
    secondary: InertialTask,
    refs: [Vec<Quintic>; 2],
    gains: [Vec<f64>; 2],
    srmtp: Srmtp,
    desired: Vec<f64>,
    rate_d: Vec<f64>,
    w: Vec<f64>,
}

/// The planar state `s = (x, y, ψ, q)` as a base pose.
fn base_pose(s: &[f64]) -> BasePose {
    BasePose {
        orientation: UnitQuaternion::from_axis_angle(&Vec3::z_axis(), s[2]),
        position: Vec3::new(s[0], s[1], 0.0),
    }
}

impl Resolver {
    /// Refresh kinematics and task values at state `s`.
    fn update(&mut self, v: &Vehicle, s: &[f64]) {
        let q = &s[3..];
        forward_kinematics(v, q, &mut self.ws);
        let base = base_pose(s);
        self.primary.update(&base, &self.ws, q);
        self.secondary.update(&base, &self.ws, q);
    }

    /// Closed-loop rate of `level` (0 primary, 1 secondary) at time `t` into `self.w`.
    fn rate(&mut self, level: usize, t: f64) -> Result<(), ScenarioError> {
        let task = if level == 0 {
            &self.primary
        } else {
            &self.secondary
        };
        let m = task.dim();
        for (i, r) in self.refs[level].iter().enumerate() {
            let x = r.sample(t);
            self.desired[i] = x.value;
            self.rate_d[i] = x.rate;
        }
        task.closed_loop_rate(
            &self.desired[..m],
            &self.rate_d[..m],
            &self.gains[level],
            &mut self.w[..m],
        )
        .map_err(ScenarioError::from)
    }

    /// AC-7 at state `s`, time `t`: writes `ṡ` into `ds`; returns `σ_min(J_s N_p)` when
    /// `measure` is set (else NaN).
    fn derivative(
        &mut self,
        v: &Vehicle,
        t: f64,
        s: &[f64],
        ds: &mut [f64],
        measure: bool,
    ) -> Result<f64, ScenarioError> {
        self.update(v, s);
        self.srmtp.reset();
        let exact = TaskInverse::weighted(0.0);
        self.rate(0, t)?;
        let m = self.primary.dim();
        self.srmtp
            .push_task(self.primary.jacobian(), &self.w[..m], exact)?;
        let sigma = if measure {
            self.srmtp
                .projected_singular_value(self.secondary.jacobian())
        } else {
            f64::NAN
        };
        self.rate(1, t)?;
        let m = self.secondary.dim();
        self.srmtp
            .push_task(self.secondary.jacobian(), &self.w[..m], exact)?;
        let z = self.srmtp.zeta();
        let (c, sn) = (s[2].cos(), s[2].sin());
        ds[0] = c * z[0] - sn * z[1];
        ds[1] = sn * z[0] + c * z[1];
        ds[2] = z[5];
        ds[3..3 + self.n].copy_from_slice(&z[6..6 + self.n]);
        Ok(sigma)
    }
}

impl KinematicCase {
    /// Check the settings against a chain of `n` joints: one initial angle per joint,
    /// positive times and sampling, finite non-negative gains, finite targets.
    pub fn validate(&self, n: usize) -> Result<(), ScenarioError> {
        let bad = |e: ScenarioError| Err(e.in_case(&self.name));
        if self.q0.len() != n {
            return bad(ScenarioError::JointCount {
                key: "q0",
                found: self.q0.len(),
                joints: n,
            });
        }
        let positive = [self.ramp, self.duration, self.dt];
        if positive.iter().any(|x| !x.is_finite() || *x <= 0.0) || self.record_every == 0 {
            return bad(ScenarioError::Rule(
                "ramp, duration, dt and record_every must be > 0",
            ));
        }
        let rows = self.primary.iter().chain(&self.secondary);
        if rows.clone().any(|r| !r.gain.is_finite() || r.gain < 0.0) {
            return bad(ScenarioError::Rule("task gains must be finite and >= 0"));
        }
        if rows
            .clone()
            .any(|r| r.target.is_some_and(|x| !x.is_finite()))
        {
            return bad(ScenarioError::Rule("task targets must be finite"));
        }
        Ok(())
    }
}

fn trace(task: &InertialTask) -> Vec<TaskTrace> {
    task.variables()
        .iter()
        .map(|v| TaskTrace {
            name: v.name(),
            heading: v.is_heading(),
            desired: Vec::new(),
            value: Vec::new(),
        })
        .collect()
}

fn build(v: &Vehicle, case: &KinematicCase) -> Result<Resolver, ScenarioError> {
    let n = v.n_joints();
    let vars = |rows: &[TaskRow]| rows.iter().map(|r| r.variable).collect::<Vec<_>>();
    let primary = InertialTask::new(&vars(&case.primary), n)?;
    let secondary = InertialTask::new(&vars(&case.secondary), n)?;
    let max_rows = primary.dim() + secondary.dim();
    let srmtp = Srmtp::new(6 + n, max_rows, &planar_weights(n), 0.0)?;
    let gains = |rows: &[TaskRow]| rows.iter().map(|r| r.gain).collect::<Vec<_>>();
    let mut r = Resolver {
        n,
        ws: KinWorkspace::new(v),
        primary,
        secondary,
        refs: [Vec::new(), Vec::new()],
        gains: [gains(&case.primary), gains(&case.secondary)],
        srmtp,
        desired: vec![0.0; max_rows],
        rate_d: vec![0.0; max_rows],
        w: vec![0.0; max_rows],
    };
    let mut s0 = case.base.to_vec();
    s0.extend_from_slice(&case.q0);
    r.update(v, &s0);
    // References start at the initial task values ("coincident with their initial value").
    for (level, rows) in [&case.primary, &case.secondary].into_iter().enumerate() {
        let task = if level == 0 { &r.primary } else { &r.secondary };
        r.refs[level] = rows
            .iter()
            .zip(task.value())
            .map(|(row, &x0)| Quintic::new(x0, row.target.unwrap_or(x0), case.ramp))
            .collect::<Result<_, _>>()?;
    }
    Ok(r)
}

/// Run a kinematic case on `v` (the paper's cases: [`antonelli_case`] on `uvms-planar`):
/// RK4 on `(x, y, ψ, q)` with `ṡ` from AC-7 (see the module doc). Errors on inconsistent
/// settings; never on singular configurations (the solver regularises and counts them).
pub fn run_kinematic_case(
    v: &Vehicle,
    case: &KinematicCase,
) -> Result<KinematicHistory, ScenarioError> {
    case.validate(v.n_joints())?;
    let n = v.n_joints();
    let mut r = build(v, case)?;
    let dim = 3 + n;
    let mut s: Vec<f64> = case.base.iter().chain(&case.q0).copied().collect();
    let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
        vec![0.0; dim],
        vec![0.0; dim],
        vec![0.0; dim],
        vec![0.0; dim],
        vec![0.0; dim],
    );
    let e = Vec::new;
    let mut h = KinematicHistory {
        name: case.name.clone(),
        t: e(),
        base: [e(), e(), e()],
        base_rate: [e(), e(), e()],
        twist: [e(), e(), e()],
        q: vec![e(); n],
        qd: vec![e(); n],
        ee: [e(), e(), e()],
        primary: trace(&r.primary),
        secondary: trace(&r.secondary),
        sigma_s: e(),
    };
    let steps = (case.duration / case.dt).round() as usize;
    let dt = case.dt;
    for step in 0..=steps {
        let t = step as f64 * dt;
        let rec = step % case.record_every == 0 || step == steps;
        let sigma = r.derivative(v, t, &s, &mut k1, rec)?;
        if rec {
            record(&mut h, &r, t, &s, &k1, sigma);
        }
        if step == steps {
            break;
        }
        for (x, (a, b)) in tmp.iter_mut().zip(s.iter().zip(&k1)) {
            *x = a + 0.5 * dt * b;
        }
        r.derivative(v, t + 0.5 * dt, &tmp, &mut k2, false)?;
        for (x, (a, b)) in tmp.iter_mut().zip(s.iter().zip(&k2)) {
            *x = a + 0.5 * dt * b;
        }
        r.derivative(v, t + 0.5 * dt, &tmp, &mut k3, false)?;
        for (x, (a, b)) in tmp.iter_mut().zip(s.iter().zip(&k3)) {
            *x = a + dt * b;
        }
        r.derivative(v, t + dt, &tmp, &mut k4, false)?;
        for i in 0..dim {
            s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    Ok(h)
}

/// Append one sample: state `s`, its derivative `ds` and `σ_min(J_s N_p)`.
fn record(h: &mut KinematicHistory, r: &Resolver, t: f64, s: &[f64], ds: &[f64], sigma: f64) {
    // `derivative` left the tasks evaluated at `s`; its ζ is the solver's.
    let z = r.srmtp.zeta();
    h.t.push(t);
    for k in 0..3 {
        h.base[k].push(s[k]);
        h.base_rate[k].push(ds[k]);
    }
    for (k, idx) in [0, 1, 5].into_iter().enumerate() {
        h.twist[k].push(z[idx]);
    }
    for j in 0..r.n {
        h.q[j].push(s[3 + j]);
        h.qd[j].push(ds[3 + j]);
    }
    let g_ie = crate::control::ee_pose(&base_pose(s), &r.ws.g_be);
    h.ee[0].push(g_ie.p.x);
    h.ee[1].push(g_ie.p.y);
    h.ee[2].push(crate::spatial::heading(&g_ie.r));
    h.sigma_s.push(sigma);
    for (level, traces) in [&mut h.primary, &mut h.secondary].into_iter().enumerate() {
        let task = if level == 0 { &r.primary } else { &r.secondary };
        for ((tr, q), x) in traces.iter_mut().zip(&r.refs[level]).zip(task.value()) {
            tr.desired.push(q.sample(t).value);
            tr.value.push(*x);
        }
    }
}

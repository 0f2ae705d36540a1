//! Transport mode (docs/model.md §5, USM section V-A): LOS path following with joint bending and base
//! surge/yaw accelerations.
//!
//! - **Joint references (USM-38)**: `q_r,i = s_q k_ψ wrap(ψ − ψ_r)` for the yaw joints, 0 for the
//!   others (pitch), clamped to the joint limits. `ψ` is the heading of the front link (the yaw of
//!   the end-effector frame about inertial +z), `ψ_r` from [`super::guidance`] (USM-39).
//!
//!   **Sign `s_q` (`joint_sign`, default −1).** Our joint convention (docs/model.md §1) makes a positive
//!   yaw-joint angle rotate the child counter-clockwise about +z (seen from above, z up)
//!   relative to its parent, so in a level configuration the head's heading relative to the tail
//!   is `ψ − ψ_b = Σ q_yaw`. If the head points left of the reference (`ψ > ψ_r`) the body must
//!   bend so that the head turns right relative to the tail, i.e. `Σ q_yaw < 0`: hence
//!   `q_r,i = −k_ψ (ψ − ψ_r)`. The paper's `+k_ψ(ψ − ψ_r)` comes from the snake-robot literature it
//!   builds on (Liljebäck et al.; ref. [6]), where the joint angle is the *rear* link angle minus
//!   the *front* link angle, the opposite sense of ours. With a quasi-static base and first-order
//!   servos the head heading obeys `d/dt Σq = −(Σq + 4 s_q k_ψ (ψ_b + Σq − ψ_r))/T`, stable for
//!   `s_q = −1` (pole `−(1 + 4k_ψ)/T`) and unstable for `+1` with the paper's `k_ψ = 0.45`
//!   (pole `+(4k_ψ − 1)/T`) — pinned by a kinematic test below.
//! - **Surge (USM-40)**: `a_1 = −k_1p (u − u_c) − k_1I ∫(u − u_c) dt` ([`SurgeLaw::ProportionalIntegral`],
//!   as printed), or `a_1 = −k_1p (u − u_c) − k_1d d/dt (u − u_c)`
//!   ([`SurgeLaw::ProportionalDerivative`], the OCR'd table header "k_1p, k_1d"; the derivative is a
//!   first-order filtered backward difference with time constant
//!   [`TransportGains::derivative_time_constant`]). `u` is the end-effector surge `v_e,x` (its
//!   `F_e` x component) in Method 1 and the base surge `v_b,x` in Method 2 ([`SurgeSource`]); `u_c`
//!   = `u0`. In both methods `a_1` is applied as the **base** surge acceleration (x of `F_b`) —
//!   as the paper does.
//! - **Yaw (USM-41)**: `a_6 = −k_6p wrap(ψ − ψ_r) − k_6d (ψ̇ − ψ̇_r)`, applied as the base yaw
//!   acceleration (z of `F_b`). `ψ̇` is, by default, the rate of the same heading ψ (the front
//!   link's, [`YawRateSource::FrontHeading`]) so that the law is a PD on one signal; the base
//!   body yaw rate `r = ω_b,z` is selectable ([`YawRateSource::BaseYawRate`]), and so is
//!   dropping the reference rate `ψ̇_r` ([`TransportGains::yaw_rate_reference`]).
//! - **Secondary objectives** (optional, `[secondary]`; [`TransportController::set_secondary`]):
//!   a bounded joint offset δ in the null space of the head's heading and pitch relative to
//!   the tail, climbing the commanded-subspace σ_min / manipulability. Off by default: a
//!   persistent null-space bend biases the steering, and neither method then converges to the
//!   second segment (`usm-study paper secondary`).
//! - The other components of `a^b`: the paper says they are "set to zero". We read this as
//!   USM-34 with a zero reference on those axes, `a_i = −K_p,i v_b,i` (sway, heave, roll,
//!   pitch; the paper's `K_p = diag(1,1,1,0,1,1)`), applied with `τ_c = M_11 a^b` in
//!   [`super::dynamic::DynamicController::transport_control`], without `n` by default
//!   ([`super::dynamic::DynamicGains::transport`]). Both are interpretation choices, justified
//!   below; the literal form is `base_control.nonlinear = true, uncommanded_feedback = false`.
//!
//! # Interpretation choices and why (results/paper/FINDINGS.md has the numbers)
//!
//! `usm-study paper readings` (`crate::paper::readings`) runs both Table III methods under
//! all 32 combinations of the open choices (n or not, feedback on the uncommanded axes or not,
//! front-heading or base yaw rate, with or without `ψ̇_r`, PI or PD surge). Only the default
//! below (no `n`, feedback, front-heading rate, `ψ̇ − ψ̇_r`, PI: two departures from the
//! printed text) makes both methods converge — it was adopted *for that outcome*, and it
//! reverses the paper's ranking (Method 1 24.6 / 26.4 s, Method 2 71.7 / 71.4 s). Under the
//! printed reading, and under two others (PD surge; no `n` with the base yaw rate and no
//! `ψ̇_r`), only Method 2 converges, on one segment (printed: segment 1 in 74.9 s), while
//! Method 1 converges on none (printed: a ±1.7 m limit cycle): the paper's ranking, if not its
//! "both converge". Under the adopted reading the ordering follows the yaw gains, not the
//! surge source: Method 2 with Method 1's `k_6p = 0.13` alone converges in 20.0 / 30.5 s.
//! `results/paper/readings/claims.md` judges each of the paper's transport claims under the
//! printed and the adopted reading, with and without cross-flow lift (`hydro.lift_slope`).
//!
//! - **Zero-velocity feedback on the uncommanded axes.** With `n` included and those
//!   accelerations literally zero, USM-33 makes sway, heave and pitch pure integrators
//!   (`v̇ = 0`): the sideslip the joint motion kicks in at the start (≈ −0.1 m/s at the tail)
//!   is never removed, so the heading converges but the course does not, and the cross-track
//!   error settles at `≈ Δ tan(crab)` instead of zero. A real vehicle damps this through
//!   cross-flow drag, which `n` cancels; `K_p` towards zero velocity restores it.
//! - **No `n` (τ_c = M_11 a^b).** With exact feedback linearisation every hydrodynamic force on
//!   the base is cancelled — including the lateral force of the bent body, which is how bending
//!   the joints (USM-38) steers a vehicle through water. The base yaw then obeys `ψ̈_b = a_6`
//!   only, and with quasi-static joints (`ψ − ψ_r = (ψ_b − ψ_r)/(1 + 4k_ψ)`), straight-line
//!   LOS `ė_y = U ψ_b`, `ψ_r = −e_y/Δ`, USM-41 gives the cubic
//!   `s³ + b s² + (a + bU/Δ) s + aU/Δ` with `a = k_6p/(1+4k_ψ)`, `b = k_6d/(1+4k_ψ)`. With the
//!   Table III gains its roots are `0.040 ± 0.248i` for Method 1 (unstable: the simulated
//!   limit cycle of ±1.7 m with 40 N saturations) and `−0.014 ± 0.142i` for Method 2 (a 44 s
//!   oscillation decaying over ~70 s: the simulated one). The Table III gains were tuned
//!   (trial and error) on Vortex, whose hydrodynamics the controller's model does not cancel
//!   exactly, so we keep the hydrodynamics in the loop, as the paper's own work-mode
//!   simulation does. No gain is changed.
//! - `ψ̇` in USM-41 is the front-heading rate (one signal for the PD); the base yaw rate
//!   changes little (Method 1 converges slower, Method 2 a little faster on segment 0).
//! - The initial 40 N burst (first 0.5 s) is the servo (ω_n = 5 rad/s) snapping the joints to
//!   `k_ψ(ψ − ψ_r) ≈ 0.44 rad` while USM-41's `k_6d` term reacts to the head's resulting yaw
//!   rate; ω_n = 1 rad/s halves it. We keep the servo and report it.

use super::error::{check_finite, check_nonneg, check_pos, ControlError};
use super::guidance::{LosGuidance, LosOutput, PathSpec};
use super::kinematic::SecondaryTasks;
use crate::kinematics::{BasePose, KinWorkspace};
use crate::model::Vehicle;
use crate::spatial::{ang, lin, Vec3, Vec6};
use crate::spatial::{heading, heading_rate, wrap_angle};
use serde::{Deserialize, Serialize};

/// The paper's two transport methods (USM section VI-B, Table III).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransportMethod {
    /// Method 1: regulate the end-effector surge ("dragging the USM by its head").
    Method1,
    /// Method 2: regulate the base surge ("pushing at the back end"); the paper's recommendation.
    Method2,
}

/// Whose surge velocity `u` USM-40 regulates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurgeSource {
    /// `u = v_e,x`, the end-effector's surge in `F_e` (Method 1).
    EndEffector,
    /// `u = v_b,x`, the base surge in `F_b` (Method 2).
    Base,
}

/// Form of the surge law USM-40.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurgeLaw {
    /// `−k_1p e − k_1I ∫e dt` (as printed in USM-40).
    ProportionalIntegral,
    /// `−k_1p e − k_1d ė` (as the OCR'd Table III header "k_1p, k_1d" suggests).
    ProportionalDerivative,
}

/// Which yaw rate is `ψ̇` in USM-41.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum YawRateSource {
    /// The rate of the front-link heading ψ (exact heading rate of `F_e`).
    FrontHeading,
    /// The base body yaw rate `r = ω_b,z` (z component of the base angular velocity in `F_b`).
    BaseYawRate,
}

/// Transport-mode gains (USM Table III) and the choices the paper leaves open.
///
/// Deserialises from a table whose every key is optional: `method = "method1" | "method2"`
/// (default `method2`) picks the Table III row and its surge source, and any other key
/// overrides that preset. `k_1d` is accepted as an alias of `k_1i`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TransportGainsSpec")]
pub struct TransportGains {
    /// The Table III row these gains started from.
    pub method: TransportMethod,
    /// Commanded surge velocity `u_c = u0` [m/s].
    pub u0: f64,
    /// LOS look-ahead distance Δ [m] (USM-39).
    pub look_ahead: f64,
    /// Joint gain `k_ψ` [rad/rad] (USM-38).
    pub k_psi: f64,
    /// Surge proportional gain `k_1p` [1/s] (USM-40).
    pub k_1p: f64,
    /// Surge integral gain `k_1I` [1/s²] (or derivative gain `k_1d` [—] in the PD form).
    pub k_1i: f64,
    /// Yaw proportional gain `k_6p` [1/s²] (USM-41).
    pub k_6p: f64,
    /// Yaw derivative gain `k_6d` [1/s] (USM-41).
    pub k_6d: f64,
    /// Form of USM-40.
    pub surge_law: SurgeLaw,
    /// Whose surge is regulated.
    pub surge_source: SurgeSource,
    /// Which yaw rate is ψ̇.
    pub yaw_rate_source: YawRateSource,
    /// Whether USM-41 damps the rate error `ψ̇ − ψ̇_r` (true, as printed; `ψ̇_r` the LOS
    /// reference rate of [`super::guidance`]) or the rate `ψ̇` alone (false: a reading of the
    /// OCR'd "k_6d(ψ̇ − ψ̇," that drops the reference rate). Default true.
    pub yaw_rate_reference: bool,
    /// Sign `s_q` of USM-38 in our joint convention (default −1; see the module docs).
    pub joint_sign: f64,
    /// Bound on `|∫(u − u_c) dt|` [m] (anti-windup; `None` = unbounded, as in the paper).
    pub integral_limit: Option<f64>,
    /// Time constant [s] of the filtered difference in the PD surge law.
    pub derivative_time_constant: f64,
    /// Whether the depth and attitude autopilot adds its terms (docs/model.md §5 "Autopilot",
    /// `TransportController::autopilot`). Default false: the paper's laws alone, bit for bit.
    pub autopilot: bool,
    /// Depth gain `k_zp` [1/s²] (default 0.25, **inferred**: with `K_p,heave = 1/s` and `k_zi`
    /// the loop `s³ + s² + k_zp s + k_zi` has roots −0.70, −0.15 ± 0.08i).
    pub k_depth_p: f64,
    /// Depth integral gain `k_zi` [1/s³] on `∫(z − z_r) dt` (default 0.02, **inferred**).
    pub k_depth_i: f64,
    /// Anti-windup bound on `|∫(z − z_r) dt|` [m·s] (default 10: `k_zi` × 10 = 0.2 m/s², about
    /// twice what a 2 % buoyancy error of the paper design needs).
    pub depth_integral_limit: f64,
    /// Roll gain `k_φp` [1/s²] (default 0.25, **inferred**), applied only when the design can
    /// command roll ([`TransportMeasurement::roll_authority`]).
    pub k_roll_p: f64,
    /// Roll rate gain `k_φd` [1/s] (default 1: with `k_φp`, critically damped at 0.5 rad/s).
    pub k_roll_d: f64,
    /// Pitch gain `k_θp` [1/s²] (default 0.25, **inferred**; USM-34's `K_p,pitch` damps).
    pub k_pitch_p: f64,
    /// Pitch rate gain `k_θd` [1/s], added to USM-34's `K_p,pitch` (default 0).
    pub k_pitch_d: f64,
}

impl TransportGains {
    fn common(method: TransportMethod) -> Self {
        Self {
            method,
            u0: 0.5,
            look_ahead: 2.0,
            k_psi: 0.45,
            k_1p: 0.5,
            k_1i: 0.0625,
            k_6p: 0.01,
            k_6d: 0.2,
            surge_law: SurgeLaw::ProportionalIntegral,
            surge_source: SurgeSource::Base,
            yaw_rate_source: YawRateSource::FrontHeading,
            yaw_rate_reference: true,
            joint_sign: -1.0,
            integral_limit: None,
            derivative_time_constant: 0.5,
            autopilot: false,
            k_depth_p: 0.25,
            k_depth_i: 0.02,
            depth_integral_limit: 10.0,
            k_roll_p: 0.25,
            k_roll_d: 1.0,
            k_pitch_p: 0.25,
            k_pitch_d: 0.0,
        }
    }

    /// USM Table III, Method 1: `u0 = 0.5, Δ = 3, k_ψ = 0.45, k_1p = 0.5, k_1I = 0.0625,
    /// k_6p = 0.13, k_6d = 0.12`; end-effector surge.
    pub fn method1() -> Self {
        Self {
            look_ahead: 3.0,
            k_6p: 0.13,
            k_6d: 0.12,
            surge_source: SurgeSource::EndEffector,
            ..Self::common(TransportMethod::Method1)
        }
    }

    /// USM Table III, Method 2: `u0 = 0.5, Δ = 2, k_ψ = 0.45, k_1p = 0.5, k_1I = 0.0625,
    /// k_6p = 0.01, k_6d = 0.2`; base surge.
    pub fn method2() -> Self {
        Self::common(TransportMethod::Method2)
    }

    /// The preset of a method.
    pub fn preset(method: TransportMethod) -> Self {
        match method {
            TransportMethod::Method1 => Self::method1(),
            TransportMethod::Method2 => Self::method2(),
        }
    }

    /// Check the values; errors name `transport.<key>`.
    pub fn validate(&self) -> Result<(), ControlError> {
        check_finite("transport.u0", self.u0)?;
        check_pos("transport.look_ahead", self.look_ahead)?;
        for (k, v) in [
            ("transport.k_psi", self.k_psi),
            ("transport.k_1p", self.k_1p),
            ("transport.k_1i", self.k_1i),
            ("transport.k_6p", self.k_6p),
            ("transport.k_6d", self.k_6d),
            (
                "transport.derivative_time_constant",
                self.derivative_time_constant,
            ),
            ("transport.k_depth_p", self.k_depth_p),
            ("transport.k_depth_i", self.k_depth_i),
            ("transport.depth_integral_limit", self.depth_integral_limit),
            ("transport.k_roll_p", self.k_roll_p),
            ("transport.k_roll_d", self.k_roll_d),
            ("transport.k_pitch_p", self.k_pitch_p),
            ("transport.k_pitch_d", self.k_pitch_d),
        ] {
            check_nonneg(k, v)?;
        }
        if self.joint_sign != 1.0 && self.joint_sign != -1.0 {
            return Err(ControlError::new(
                "transport.joint_sign",
                format!("must be 1 or -1, got {}", self.joint_sign),
            ));
        }
        if let Some(l) = self.integral_limit {
            check_pos("transport.integral_limit", l)?;
        }
        Ok(())
    }
}

impl Default for TransportGains {
    /// Method 2, the paper's recommendation.
    fn default() -> Self {
        Self::method2()
    }
}

/// Wire form of [`TransportGains`]: every key optional over the chosen preset.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransportGainsSpec {
    method: Option<TransportMethod>,
    u0: Option<f64>,
    look_ahead: Option<f64>,
    k_psi: Option<f64>,
    k_1p: Option<f64>,
    #[serde(alias = "k_1d")]
    k_1i: Option<f64>,
    k_6p: Option<f64>,
    k_6d: Option<f64>,
    surge_law: Option<SurgeLaw>,
    surge_source: Option<SurgeSource>,
    yaw_rate_source: Option<YawRateSource>,
    yaw_rate_reference: Option<bool>,
    joint_sign: Option<f64>,
    integral_limit: Option<f64>,
    derivative_time_constant: Option<f64>,
    autopilot: Option<bool>,
    k_depth_p: Option<f64>,
    k_depth_i: Option<f64>,
    depth_integral_limit: Option<f64>,
    k_roll_p: Option<f64>,
    k_roll_d: Option<f64>,
    k_pitch_p: Option<f64>,
    k_pitch_d: Option<f64>,
}

impl TryFrom<TransportGainsSpec> for TransportGains {
    type Error = ControlError;

    fn try_from(s: TransportGainsSpec) -> Result<Self, ControlError> {
        let mut g = TransportGains::preset(s.method.unwrap_or(TransportMethod::Method2));
        macro_rules! set {
            ($($f:ident),*) => { $( if let Some(x) = s.$f { g.$f = x; } )* };
        }
        set!(
            u0,
            look_ahead,
            k_psi,
            k_1p,
            k_1i,
            k_6p,
            k_6d,
            surge_law,
            surge_source,
            yaw_rate_source,
            yaw_rate_reference,
            joint_sign,
            derivative_time_constant
        );
        set!(autopilot, k_depth_p, k_depth_i, depth_integral_limit);
        set!(k_roll_p, k_roll_d, k_pitch_p, k_pitch_d);
        if s.integral_limit.is_some() {
            g.integral_limit = s.integral_limit;
        }
        g.validate()?;
        Ok(g)
    }
}

/// Which joints are yaw joints: those whose axis, expressed in the base frame at the zero
/// configuration, is within ~11° of the base z axis (`|axis_b · e_z| > 0.98`). All others are
/// treated as pitch (or other) joints and get a zero reference in USM-38.
pub fn yaw_joint_mask(v: &Vehicle) -> Vec<bool> {
    let ws = KinWorkspace::new(v);
    ws.joint_twist_b
        .iter()
        .map(|t| ang(t).z.abs() > 0.98)
        .collect()
}

/// USM-38 into `out` (see [`TransportController::joint_references`]).
fn fill_joint_references(
    gains: &TransportGains,
    yaw: &[bool],
    limits: &[(f64, f64)],
    psi: f64,
    psi_r: f64,
    out: &mut [f64],
) {
    let e = wrap_angle(psi - psi_r);
    for (i, o) in out.iter_mut().enumerate().take(yaw.len()) {
        let (lo, hi) = limits[i];
        let q = if yaw[i] {
            gains.joint_sign * gains.k_psi * e
        } else {
            0.0
        };
        *o = if q.is_finite() { q } else { 0.0 }.clamp(lo, hi);
    }
}

/// The measured signals transport mode needs, in the frames the laws use.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransportMeasurement {
    /// Heading ψ of the front link (`F_e` yaw about inertial +z) [rad].
    pub psi: f64,
    /// Its rate ψ̇ [rad/s].
    pub psi_dot: f64,
    /// Heading of the base frame [rad].
    pub base_heading: f64,
    /// Base body yaw rate `r = ω_b,z` (in `F_b`) [rad/s].
    pub base_yaw_rate: f64,
    /// End-effector surge `v_e,x` (in `F_e`) [m/s].
    pub surge_ee: f64,
    /// Base surge `v_b,x` (in `F_b`) [m/s].
    pub surge_base: f64,
    /// End-effector position in `I` [m] (the "front of the vehicle" for LOS).
    pub ee_position: Vec3,
    /// End-effector velocity in `I` [m/s].
    pub ee_velocity: Vec3,
    /// Base origin depth `z_b` (inertial z, up) [m].
    pub base_z: f64,
    /// The inertial up direction in `F_b`, `R_Ibᵀ e_z` ((0, 0, 1) when level).
    pub base_up: Vec3,
    /// Base angular velocity `ω_b` in `F_b` [rad/s].
    pub base_rates: Vec3,
    /// Whether T(q) can command roll now (σ_min of all six scaled rows ≥ `[metrics]
    /// threshold`; set by the closed loop with the autopilot on, else false).
    pub roll_authority: bool,
}

/// Compute [`TransportMeasurement`] from the state: base pose, a workspace after
/// [`crate::kinematics::forward_kinematics`] at the measured joints, the base twist `v_b` (in
/// `F_b`) and the joint rates `qd` [rad/s]. The end-effector twist is
/// `V_e = Ad_{g_be}⁻¹ (V_b + Σ_k X_k^b q̇_k)` (USM-18 without forming `J_e`). Allocation-free.
pub fn measure_transport(
    base: &BasePose,
    ws: &KinWorkspace,
    v_b: &Vec6,
    qd: &[f64],
) -> TransportMeasurement {
    let mut v_in_b = *v_b;
    for (x, r) in ws.joint_twist_b.iter().zip(qd) {
        v_in_b += x * *r;
    }
    let v_e = ws.g_be.twist_to_child(&v_in_b);
    let g_ib = base.to_se3();
    let g_ie = g_ib.compose(&ws.g_be);
    TransportMeasurement {
        psi: heading(&g_ie.r),
        psi_dot: heading_rate(&g_ie.r, &ang(&v_e)),
        base_heading: heading(&g_ib.r),
        base_yaw_rate: v_b[5],
        surge_ee: v_e[0],
        surge_base: v_b[0],
        ee_position: g_ie.p,
        ee_velocity: g_ie.r * lin(&v_e),
        base_z: g_ib.p.z,
        base_up: g_ib.r.transpose() * Vec3::z(),
        base_rates: ang(v_b),
        roll_authority: false,
    }
}

/// Result of one transport step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TransportOutput {
    /// Guidance output (ψ_r, ψ̇_r, cross-track error, segment …).
    pub los: LosOutput,
    /// Commanded base acceleration `a^b = [a_1, 0, 0, 0, 0, a_6]` in `F_b` [m/s², rad/s²].
    pub a_b: Vec6,
    /// Heading error `wrap(ψ − ψ_r)` [rad].
    pub heading_error: f64,
    /// Surge error `u − u_c` [m/s].
    pub surge_error: f64,
    /// Whether the autopilot commanded roll in this step.
    pub roll_commanded: bool,
}

/// The transport-mode controller: LOS guidance, USM-38 joint references, USM-40/41 base
/// accelerations, with the integral / derivative-filter state. Allocation-free per step.
#[derive(Clone, Debug)]
pub struct TransportController {
    gains: TransportGains,
    guidance: LosGuidance,
    yaw: Vec<bool>,
    limits: Vec<(f64, f64)>,
    q_ref: Vec<f64>,
    integral: f64,
    prev_error: Option<f64>,
    error_rate: f64,
    secondary: Option<Box<SecondaryTasks>>,
    offset: Vec<f64>,
    q_sec: Vec<f64>,
    step: Vec<f64>,
    depth_ref: Option<f64>,
    depth_integral: f64,
}

impl TransportController {
    /// Build for a design, with gains and a path (LOS look-ahead Δ = `gains.look_ahead`).
    pub fn new(v: &Vehicle, gains: TransportGains, path: &PathSpec) -> Result<Self, ControlError> {
        gains.validate()?;
        let guidance = LosGuidance::new(path, gains.look_ahead)?;
        Ok(Self {
            yaw: yaw_joint_mask(v),
            limits: v.joint_limits(),
            q_ref: vec![0.0; v.n_joints()],
            gains,
            guidance,
            integral: 0.0,
            prev_error: None,
            error_rate: 0.0,
            secondary: None,
            offset: vec![0.0; v.n_joints()],
            q_sec: vec![0.0; v.n_joints()],
            step: vec![0.0; v.n_joints()],
            depth_ref: None,
            depth_integral: 0.0,
        })
    }

    /// Add the paper's secondary objectives (USM section IV-A; [`SecondaryTasks`]) below
    /// USM-38: the joint references become `q_r = q_r,USM-38 + δ`, with the offset δ integrating
    /// the secondary joint velocity projected onto `Σ_yaw δ = 0, Σ_pitch δ = 0` (the null space
    /// of the head's heading and pitch relative to the tail, so steering is unchanged to first
    /// order), each `|δ_i|` bounded by `max_offset`.
    pub fn set_secondary(&mut self, tasks: SecondaryTasks) {
        self.secondary = Some(Box::new(tasks));
    }

    /// Advance δ over `dt` [s] at the current references and add it to them (see
    /// [`TransportController::set_secondary`]). Allocation-free.
    fn apply_secondary(&mut self, dt: f64) {
        let Some(sec) = self.secondary.as_deref_mut() else {
            return;
        };
        let n = self.q_ref.len();
        let max = sec.settings().max_offset;
        if dt.is_finite() && dt > 0.0 {
            for i in 0..n {
                self.q_sec[i] = self.q_ref[i] + self.offset[i];
            }
            let v = sec.joint_velocity(&self.q_sec);
            // Project onto Σ_yaw δ̇ = 0, Σ_other δ̇ = 0: remove each group's mean.
            let (mut sum, mut count) = ([0.0; 2], [0usize; 2]);
            for (&vi, &yaw) in v.iter().zip(&self.yaw) {
                let g = usize::from(!yaw);
                sum[g] += vi;
                count[g] += 1;
            }
            let mean = |g: usize| sum[g] / count[g].max(1) as f64;
            let mut alpha: f64 = 1.0;
            for (i, &vi) in v.iter().enumerate() {
                let step = (vi - mean(usize::from(!self.yaw[i]))) * dt;
                self.step[i] = step;
                if step != 0.0 && (self.offset[i] + step).abs() > max {
                    let room = (max.copysign(step) - self.offset[i]) / step;
                    alpha = alpha.min(room.max(0.0));
                }
            }
            for i in 0..n {
                self.offset[i] += alpha * self.step[i];
            }
        }
        for i in 0..n {
            let (lo, hi) = self.limits[i];
            self.q_ref[i] = (self.q_ref[i] + self.offset[i]).clamp(lo, hi);
        }
    }

    /// The gains.
    pub fn gains(&self) -> &TransportGains {
        &self.gains
    }

    /// The guidance (active segment, look-ahead).
    pub fn guidance(&self) -> &LosGuidance {
        &self.guidance
    }

    /// Which joints are yaw joints (see [`yaw_joint_mask`]).
    pub fn yaw_joints(&self) -> &[bool] {
        &self.yaw
    }

    /// Joint angle references `q_r` [rad] of the last step (USM-38).
    pub fn q_ref(&self) -> &[f64] {
        &self.q_ref
    }

    /// The surge integral `∫(u − u_c) dt` [m].
    pub fn surge_integral(&self) -> f64 {
        self.integral
    }

    /// Clear the integral and filter state and restart the path at segment 0.
    pub fn reset(&mut self) {
        self.integral = 0.0;
        self.prev_error = None;
        self.error_rate = 0.0;
        self.guidance.reset();
        self.q_ref.fill(0.0);
        self.offset.fill(0.0);
        self.depth_ref = None;
        self.depth_integral = 0.0;
    }

    /// USM-38: `out[i] = s_q k_ψ wrap(ψ − ψ_r)` for yaw joints, 0 otherwise, clamped to the
    /// joint limits. `psi`, `psi_r` [rad]; `out` of length n (extra entries untouched).
    pub fn joint_references(&self, psi: f64, psi_r: f64, out: &mut [f64]) {
        fill_joint_references(&self.gains, &self.yaw, &self.limits, psi, psi_r, out);
    }

    /// USM-40: the surge acceleration for measured surge `u` [m/s], advancing the integral /
    /// filter state over `dt` [s] (no state change unless `dt` is positive and finite).
    pub fn surge_acceleration(&mut self, u: f64, dt: f64) -> f64 {
        let g = &self.gains;
        let e = u - g.u0;
        let advance = dt.is_finite() && dt > 0.0 && e.is_finite();
        match g.surge_law {
            SurgeLaw::ProportionalIntegral => {
                if advance {
                    self.integral += e * dt;
                    if let Some(l) = g.integral_limit {
                        self.integral = self.integral.clamp(-l, l);
                    }
                }
                -g.k_1p * e - g.k_1i * self.integral
            }
            SurgeLaw::ProportionalDerivative => {
                if advance {
                    if let Some(prev) = self.prev_error {
                        let raw = (e - prev) / dt;
                        let alpha = dt / (g.derivative_time_constant + dt);
                        self.error_rate += alpha * (raw - self.error_rate);
                    }
                    self.prev_error = Some(e);
                }
                -g.k_1p * e - g.k_1i * self.error_rate
            }
        }
    }

    /// USM-41: `a_6 = −k_6p wrap(ψ − ψ_r) − k_6d (ψ̇ − ψ̇_r)` [rad/s²]; `ψ̇_r` is dropped
    /// (`− k_6d ψ̇`) unless [`TransportGains::yaw_rate_reference`].
    pub fn yaw_acceleration(&self, psi: f64, psi_dot: f64, psi_r: f64, psi_r_dot: f64) -> f64 {
        let rate_ref = if self.gains.yaw_rate_reference {
            psi_r_dot
        } else {
            0.0
        };
        -self.gains.k_6p * wrap_angle(psi - psi_r) - self.gains.k_6d * (psi_dot - rate_ref)
    }

    /// One transport step at time `t` [s] over `dt` [s]: LOS guidance at the end-effector
    /// (USM-39), joint references (USM-38, read with [`TransportController::q_ref`]) and the
    /// commanded base acceleration (USM-40/41). Allocation-free.
    pub fn step(&mut self, t: f64, meas: &TransportMeasurement, dt: f64) -> TransportOutput {
        let los = self
            .guidance
            .update(t, &meas.ee_position, &meas.ee_velocity);
        fill_joint_references(
            &self.gains,
            &self.yaw,
            &self.limits,
            meas.psi,
            los.psi_r,
            &mut self.q_ref,
        );
        self.apply_secondary(dt);
        let u = match self.gains.surge_source {
            SurgeSource::EndEffector => meas.surge_ee,
            SurgeSource::Base => meas.surge_base,
        };
        let a1 = self.surge_acceleration(u, dt);
        let psi_dot = match self.gains.yaw_rate_source {
            YawRateSource::FrontHeading => meas.psi_dot,
            YawRateSource::BaseYawRate => meas.base_yaw_rate,
        };
        let a6 = self.yaw_acceleration(meas.psi, psi_dot, los.psi_r, los.psi_r_dot);
        let mut a_b = Vec6::new(a1, 0.0, 0.0, 0.0, 0.0, a6);
        let mut roll_commanded = false;
        if self.gains.autopilot {
            let (a, roll) = self.autopilot(meas, dt);
            a_b += a;
            roll_commanded = roll;
        }
        TransportOutput {
            los,
            a_b,
            heading_error: wrap_angle(meas.psi - los.psi_r),
            surge_error: u - self.gains.u0,
            roll_commanded,
        }
    }
}

/// The depth and attitude autopilot (`impl TransportController`, docs/model.md §5).
#[path = "transport_autopilot.rs"]
mod autopilot;

#[cfg(test)]
#[path = "transport_tests.rs"]
mod tests;

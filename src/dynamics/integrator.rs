//! The adaptive time integrator of the [`Simulator`](super::Simulator): Dormand–Prince
//! 5(4) (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.5, Table 5.2) with FSAL and the
//! standard step-size controller, over one span with the commands held.
//!
//! The state is the simulator's flat vector (see `sim`); the derivative is a closure
//! `f(s, x, dx, boundary)` of the time `s` since the span start, so that the
//! exactly-integrated thruster states can be evaluated at any stage time; `boundary` says
//! the stage lies on a step boundary (RK4: the step's start; Dormand–Prince: the start of
//! the span and the end of every step). The fixed-step [`rk4_step`] lives here too. After every accepted step the
//! quaternion block is projected back onto the unit sphere (as the RK4 step does); the
//! derivative normalises the stage quaternion itself, so the projection changes the next
//! FSAL derivative only by rounding.
//!
//! Every buffer lives in [`Dopri5`], sized once: stepping allocates nothing.

use super::error::DynError;

/// Iteration cap of [`Dopri5::span`]: trial steps (accepted or rejected) over one span. The
/// step-size floor alone (1e-12 of the span) would allow 1e12 steps; a run needing more than
/// this fails with the time of the span instead of running for hours.
pub(super) const MAX_STEPS_PER_SPAN: usize = 100_000;

/// Nodes `c_i` of the Dormand–Prince tableau.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];

/// Coefficients `a_ij` (row `i`, the first `i` entries used).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Error weights `b_i − b̂_i` (fifth- minus fourth-order solution).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Step-size controller: safety factor and the bounds on the step ratio.
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 5.0;

/// Tolerances of the error norm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Tolerance {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
}

/// Counts of the work an integrator did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StepStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected (repeated) steps.
    pub rejected: u64,
    /// Derivative evaluations (each one dynamics solve; counted by the simulator).
    pub evaluations: u64,
}

/// Buffers and the carried step size of the Dormand–Prince integrator.
#[derive(Clone, Debug)]
pub(super) struct Dopri5 {
    /// Stage derivatives `k_1 … k_7`.
    k: [Vec<f64>; 7],
    /// Stage state.
    xs: Vec<f64>,
    /// Fifth-order solution of the step being tried.
    x_new: Vec<f64>,
    /// Step size to try next [s].
    h: f64,
}

impl Dopri5 {
    /// Buffers for a state of `nx` components; `first_step` [s] is the first trial step.
    pub fn new(nx: usize, first_step: f64) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; nx]),
            xs: vec![0.0; nx],
            x_new: vec![0.0; nx],
            h: first_step,
        }
    }

    /// Integrate `x` over `[0, span]` with `ẋ = f(s, x)`, adapting the step to `tol`.
    /// `quad.quat` is the offset of the unit quaternion in `x`, projected after every step.
    /// The components from `quad.start` on are quadrature states (integrals of the state,
    /// never read by `f`): they stay out of the error norm, and `quad.abs` gains
    /// `∫ |ẋ_i| dt` of each of them over every accepted step ([`abs_increment`]).
    /// The last evaluation is `f(span, x)` at the end (FSAL), flagged as a boundary.
    ///
    /// Errors carry the span time of the failing evaluation; `x` is then unspecified.
    pub fn span<F>(
        &mut self,
        x: &mut [f64],
        span: f64,
        tol: Tolerance,
        quad: Quadrature<'_>,
        stats: &mut StepStats,
        mut f: F,
    ) -> Result<(), (f64, DynError)>
    where
        F: FnMut(f64, &[f64], &mut [f64], bool) -> Result<(), DynError>,
    {
        let mut s = 0.0;
        let [k0, ..] = &mut self.k;
        f(0.0, x, k0, true).map_err(|e| (0.0, e))?;
        let h_min = 1e-12 * span.max(1e-300);
        let mut trials = 0usize;
        while s < span {
            trials += 1;
            if trials > MAX_STEPS_PER_SPAN {
                return Err((
                    s,
                    DynError::new(
                        "integrator.step",
                        format!(
                            "more than {MAX_STEPS_PER_SPAN} steps in one span of {span} s: the \
                             tolerance cannot be met at a reasonable cost"
                        ),
                    ),
                ));
            }
            // Take the remainder when it is within 1 % of the step (no sliver step).
            let mut h = self.h.min(span - s);
            if span - s - h < 0.01 * h {
                h = span - s;
            }
            let err = self.try_step(x, s, h, tol, quad.start, &mut f)?;
            if err <= 1.0 {
                s = if h == span - s { span } else { s + h };
                let (k0, k6) = (&self.k[0], &self.k[6]);
                for (i, (x0, x1)) in x.iter().zip(&self.x_new).enumerate().skip(quad.start) {
                    *quad.abs += abs_increment(*x0, *x1, k0[i], k6[i], h);
                }
                x.copy_from_slice(&self.x_new);
                project_quaternion(&mut x[quad.quat..quad.quat + 4]);
                self.k.swap(0, 6);
                stats.steps += 1;
                let fac = if err == 0.0 {
                    FAC_MAX
                } else {
                    (SAFETY * err.powf(-0.2)).clamp(FAC_MIN, FAC_MAX)
                };
                // A step shortened to end the span does not shrink the next span's step.
                self.h = if h < self.h {
                    (h * fac).max(self.h)
                } else {
                    h * fac
                };
            } else {
                stats.rejected += 1;
                self.h = h * (SAFETY * err.powf(-0.2)).clamp(FAC_MIN, 1.0);
                if self.h < h_min {
                    return Err((
                        s,
                        DynError::new(
                            "integrator.step",
                            format!("fell below {h_min:e} s: the tolerance cannot be met"),
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// One trial step of size `h` from `(s, x)` with `k_1 = f(s, x)` given: stages
    /// 2 … 7 into `k`, the fifth-order solution into `x_new`, and the error norm.
    fn try_step<F>(
        &mut self,
        x: &[f64],
        s: f64,
        h: f64,
        tol: Tolerance,
        n_err: usize,
        f: &mut F,
    ) -> Result<f64, (f64, DynError)>
    where
        F: FnMut(f64, &[f64], &mut [f64], bool) -> Result<(), DynError>,
    {
        for stage in 1..7 {
            let a = &A[stage];
            for (i, (xs, x0)) in self.xs.iter_mut().zip(x).enumerate() {
                let mut acc = 0.0;
                for (j, aj) in a.iter().enumerate().take(stage) {
                    acc += aj * self.k[j][i];
                }
                *xs = x0 + h * acc;
            }
            let t = s + C[stage] * h;
            let (_, rest) = self.k.split_at_mut(stage);
            f(t, &self.xs, &mut rest[0], stage == 6).map_err(|e| (t, e))?;
        }
        // Stage 7 is evaluated at the fifth-order solution (a_7 = b): x_new = xs.
        self.x_new.copy_from_slice(&self.xs);
        let mut sum = 0.0;
        for (i, (x0, x1)) in x.iter().zip(&self.x_new).enumerate().take(n_err) {
            let mut e = 0.0;
            for (j, ej) in E.iter().enumerate() {
                e += ej * self.k[j][i];
            }
            let scale = tol.atol + tol.rtol * x0.abs().max(x1.abs());
            let r = h * e / scale;
            sum += r * r;
        }
        let err = (sum / n_err.max(1) as f64).sqrt();
        Ok(if err.is_finite() { err } else { f64::INFINITY })
    }
}

/// The special components of the flat state: the unit quaternion at `quat..quat + 4`, the
/// quadrature states from `start` on, and the accumulator of `Σ_i ∫ |ẋ_i| dt` over the latter.
pub(super) struct Quadrature<'a> {
    /// Offset of the unit quaternion `[w, i, j, k]`.
    pub quat: usize,
    /// First quadrature component.
    pub start: usize,
    /// Accumulated `Σ_i ∫ |ẋ_i| dt`.
    pub abs: &'a mut f64,
}

/// `∫ |ẏ| dt` over one step of length `h` of a quadrature state `y` that goes from `y0` to
/// `y1` with rates `p0` at the start and `p1` at the end: `|y1 − y0|` when the rate keeps
/// its sign, else the sum of `|Δy|` over the pieces between the sign changes of the rate,
/// located on the cubic Hermite interpolant of `(y0, p0, y1, p1)` (its derivative is a
/// quadratic; the pieces add up to `y1 − y0` exactly). This keeps the kinks of `|ẏ|` out of
/// the integrator: the joint work `Σ_k ∫ |τ_k q̇_k| dt` (docs/model.md §6) is integrated as the smooth
/// signed work of each joint and folded here, so its error is the integrator's own plus
/// `O(h⁴)` at each sign change, instead of the `O(h²)` of integrating a kinked integrand.
pub(crate) fn abs_increment(y0: f64, y1: f64, p0: f64, p1: f64, h: f64) -> f64 {
    // Y(θ) = y0 + a θ + b θ² + c θ³ on θ ∈ [0, 1]; Y' = a + 2bθ + 3cθ².
    let d = y1 - y0;
    let a = h * p0;
    let c = h * p1 + a - 2.0 * d;
    let b = d - a - c;
    let eval = |t: f64| ((c * t + b) * t + a) * t;
    // Roots of 3c θ² + 2b θ + a in (0, 1).
    let mut roots = [0.0; 2];
    let mut n = 0;
    let mut push = |t: f64| {
        if t > 0.0 && t < 1.0 {
            roots[n] = t;
            n += 1;
        }
    };
    let (qa, qb, qc) = (3.0 * c, 2.0 * b, a);
    if qa.abs() <= 1e-14 * (qb.abs() + qc.abs()) {
        if qb != 0.0 {
            push(-qc / qb);
        }
    } else {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc > 0.0 {
            // Numerically stable pair of roots.
            let q = -0.5 * (qb + disc.sqrt().copysign(qb));
            let (r1, r2) = (q / qa, if q != 0.0 { qc / q } else { f64::NAN });
            let (lo, hi) = if r1 <= r2 { (r1, r2) } else { (r2, r1) };
            push(lo);
            push(hi);
        }
    }
    if n == 0 {
        return d.abs();
    }
    let mut total = 0.0;
    let mut prev = 0.0;
    for &t in &roots[..n] {
        let yt = eval(t);
        total += (yt - prev).abs();
        prev = yt;
    }
    total + (d - prev).abs()
}

/// Project a quaternion `[w, i, j, k]` onto the unit sphere (no-op on a zero vector; the
/// simulator checks for that).
fn project_quaternion(q: &mut [f64]) {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if norm > 0.0 {
        q.iter_mut().for_each(|c| *c /= norm);
    }
}

/// One classical RK4 step of size `h` from `(s, x)` into `x` (stage derivatives in `k`,
/// stage state in `xs`), then the quaternion block at `quad.quat` projected onto the unit sphere
/// (a change of `O(h⁵)`). `f(s, x, dx, boundary)` is told which stage starts the step.
/// `quad.abs` gains `∫ |ẋ_i| dt` of the quadrature states `i ≥ quad.start` over the step
/// ([`abs_increment`], with the last stage's derivative standing for the end's).
pub(super) fn rk4_step<F>(
    x: &mut [f64],
    s: f64,
    h: f64,
    k: &mut [Vec<f64>; 4],
    xs: &mut [f64],
    quad: Quadrature<'_>,
    f: &mut F,
) -> Result<(), (f64, DynError)>
where
    F: FnMut(f64, &[f64], &mut [f64], bool) -> Result<(), DynError>,
{
    const NODES: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
    for (stage, c) in NODES.iter().enumerate() {
        let hc = c * h;
        if stage == 0 {
            xs.copy_from_slice(x);
        } else {
            for ((xs, x0), kp) in xs.iter_mut().zip(x.iter()).zip(&k[stage - 1]) {
                *xs = x0 + hc * kp;
            }
        }
        f(s + hc, xs, &mut k[stage], stage == 0).map_err(|e| (s + hc, e))?;
    }
    let [k1, k2, k3, k4] = &*k;
    for i in 0..x.len() {
        let x1 = x[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        if i >= quad.start {
            *quad.abs += abs_increment(x[i], x1, k1[i], k4[i], h);
        }
        x[i] = x1;
    }
    project_quaternion(&mut x[quad.quat..quad.quat + 4]);
    Ok(())
}

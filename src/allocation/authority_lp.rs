//! The dedicated exact solver of the attainable-authority programmes (docs/model.md §6): a dense
//! bounded-variable primal simplex for
//!
//! ```text
//! max g·u   s.t.   E u = 0,   l ≤ u ≤ h,   with l ≤ 0 ≤ h
//! ```
//!
//! `E` has at most [`MAX_ROWS`] rows (the commanded rows other than the programme's axis, so
//! `α = ±(T_r u)_k` is eliminated: `g = ±` row `k` of `S T_r`), `u` one entry per thruster.
//!
//! - **Start.** `u = 0` is feasible because every box contains 0. Each equality row gets an
//!   artificial variable with bounds `[0, 0]`, basic at the start (`B = I`); the structural
//!   variables start nonbasic at 0, which may lie strictly inside their box (state `Zero`: such a
//!   variable may enter in either direction, and once basic it only ever leaves at a bound).
//!   The first pivots swap the artificials out at zero step (a crash basis); an artificial never
//!   re-enters (its box is a point), one that stays basic marks a dependent row (`E` rank
//!   deficient).
//! - **Pricing.** The largest `|d_j| · room_j` (reduced cost times the distance to the bound it
//!   moves towards). After [`DEGENERATE_LIMIT`] zero-length pivots that leave a structural
//!   variable the solve switches to Bland's rule (lowest index enters, lowest index leaves among
//!   ties) for the rest of the solve, so it cannot cycle. The ratio test prefers, among ties, the
//!   largest pivot (Bland: the lowest index); pivots below [`PIVOT_TOL`] are not taken.
//! - **Certificate.** At the end the basic values are recomputed from the nonbasic ones, clamped
//!   into their boxes, and the answer is accepted only when (i) the equality residual and the
//!   clamp are at most [`FEAS_TOL`] of the data's scale and (ii) the dual bound
//!   `Σ_j max(l_j d_j, h_j d_j)` with `d = g − Eᵀy` for the final multipliers `y` — an upper bound
//!   on the optimum for **any** `y` (weak duality: `g·u = d·u + yᵀE u ≤ Σ_j max(l_j d_j, h_j
//!   d_j)` whenever `E u = 0`) — exceeds `g·u` by at most [`GAP_TOL`] of `Σ_j |g_j| max(|l_j|,
//!   |h_j|)`. Otherwise (or after the iteration cap) [`BoxLp::solve`] returns `None` and the caller
//!   falls back to Clarabel.
//!
//! Every solve starts from the same state, so its result is a function of the programme's data
//! only (no warm start): bit-identical for any order of solves and any thread count. Nothing is
//! allocated per solve: the workspace is sized once.

/// The largest number of equality rows (six commanded rows, one of them the objective).
pub(crate) const MAX_ROWS: usize = 5;

/// Zero-length pivots leaving a structural variable before the switch to Bland's rule.
const DEGENERATE_LIMIT: usize = 8;

/// Pivot tolerance, relative to `max(1, ‖B⁻¹a_q‖∞)`.
const PIVOT_TOL: f64 = 1e-9;

/// Reduced-cost (dual feasibility) tolerance, relative to `max_j |g_j|`.
const DUAL_TOL: f64 = 1e-11;

/// Primal feasibility tolerance of the certificate, relative to the data's scale.
const FEAS_TOL: f64 = 1e-9;

/// Duality-gap tolerance of the certificate, relative to `Σ_j |g_j| max(|l_j|, |h_j|)`.
const GAP_TOL: f64 = 1e-9;

/// Where a variable sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// In the basis.
    Basic,
    /// Nonbasic at its lower bound (`l < h`).
    Lower,
    /// Nonbasic at its upper bound (`l < h`).
    Upper,
    /// Nonbasic at 0 strictly inside its box (only before it first enters).
    Zero,
    /// Nonbasic with `l = h` (a removed thruster, a departed artificial): never enters.
    Fixed,
}

/// What the last [`BoxLp::solve`] established (read by the tests).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(not(test), allow(dead_code))]
pub(crate) struct Certificate {
    /// `g·u` of the returned point.
    pub primal: f64,
    /// `Σ_j max(l_j d_j, h_j d_j)` for the final multipliers: an upper bound on the optimum.
    pub dual_bound: f64,
    /// `max_i |(E u)_i|` of the returned point.
    pub residual: f64,
    /// How far the recomputed basic values lay outside their boxes (clamped).
    pub violation: f64,
    /// Simplex iterations (pivots and bound flips).
    pub iterations: usize,
    /// Whether the solve switched to Bland's rule.
    pub bland: bool,
    /// Whether the certificate's tests passed.
    pub certified: bool,
}

impl Certificate {
    const NONE: Self = Self {
        primal: f64::NAN,
        dual_bound: f64::NAN,
        residual: f64::NAN,
        violation: f64::NAN,
        iterations: 0,
        bland: false,
        certified: false,
    };
}

/// The workspace of the box-constrained programme: the data (set through [`BoxLp::column`],
/// [`BoxLp::objective`], [`BoxLp::set_bounds`]) and the simplex state.
pub(crate) struct BoxLp {
    /// Structural variables (thrusters).
    m: usize,
    /// Equality rows (≤ [`MAX_ROWS`]).
    p: usize,
    /// Column `j` of `E` (the first `p` entries used).
    cols: Vec<[f64; MAX_ROWS]>,
    g: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// Values of the `m` structural then `p` artificial variables.
    x: Vec<f64>,
    state: Vec<State>,
    /// The basic variable of each row.
    basis: [usize; MAX_ROWS],
    /// `B⁻¹`, row-major.
    binv: [[f64; MAX_ROWS]; MAX_ROWS],
    /// Zero-length pivots leaving a structural variable before the switch to Bland's rule
    /// ([`DEGENERATE_LIMIT`]; 0: Bland's rule from the start).
    pub degenerate_limit: usize,
    /// What the last solve established.
    pub last: Certificate,
}

impl BoxLp {
    /// A workspace for `m` variables and `p ≤ MAX_ROWS` equality rows; data all zero.
    pub fn new(m: usize, p: usize) -> Self {
        assert!(p <= MAX_ROWS, "at most {MAX_ROWS} equality rows");
        Self {
            m,
            p,
            cols: vec![[0.0; MAX_ROWS]; m],
            g: vec![0.0; m],
            lo: vec![0.0; m],
            hi: vec![0.0; m],
            x: vec![0.0; m + p],
            state: vec![State::Fixed; m + p],
            basis: [0; MAX_ROWS],
            binv: [[0.0; MAX_ROWS]; MAX_ROWS],
            degenerate_limit: DEGENERATE_LIMIT,
            last: Certificate::NONE,
        }
    }

    /// Column `j` of `E` (its first `p` entries are read).
    pub fn column(&mut self, j: usize) -> &mut [f64; MAX_ROWS] {
        &mut self.cols[j]
    }

    /// The objective `g`.
    pub fn objective(&mut self) -> &mut [f64] {
        &mut self.g
    }

    /// The box of variable `j`; `lo ≤ 0 ≤ hi` is the caller's promise.
    pub fn set_bounds(&mut self, j: usize, lo: f64, hi: f64) {
        debug_assert!(lo <= 0.0 && 0.0 <= hi);
        self.lo[j] = lo;
        self.hi[j] = hi;
    }

    /// `max g·u` over the programme, when certified (see the module documentation); `None`
    /// otherwise. [`BoxLp::last`] says what was established.
    pub fn solve(&mut self) -> Option<f64> {
        self.start();
        let gmax = self.g.iter().fold(0.0_f64, |a, g| a.max(g.abs()));
        if gmax == 0.0 {
            self.last = Certificate {
                primal: 0.0,
                dual_bound: 0.0,
                residual: 0.0,
                violation: 0.0,
                certified: true,
                ..Certificate::NONE
            };
            return Some(0.0);
        }
        let dual_tol = DUAL_TOL * gmax;
        let max_iter = 20 * (self.m + self.p) + 50;
        let (mut bland, mut degenerate) = (self.degenerate_limit == 0, 0);
        for it in 0..max_iter {
            let y = self.duals();
            let Some((q, dir)) = self.price(&y, dual_tol, bland) else {
                return self.certify(it, bland);
            };
            let w = self.ftran(q);
            let (t, leave) = self.ratio(q, dir, &w, bland);
            if let Some(r) = leave {
                if t == 0.0 && self.basis[r] < self.m {
                    degenerate += 1;
                    bland |= degenerate >= self.degenerate_limit;
                }
            }
            self.step(q, dir, t, leave, &w);
        }
        self.last = Certificate {
            iterations: max_iter,
            bland,
            ..Certificate::NONE
        };
        None
    }

    /// `u = 0`; artificials basic, `B⁻¹ = I`.
    fn start(&mut self) {
        for j in 0..self.m {
            self.x[j] = 0.0;
            let (l, h) = (self.lo[j], self.hi[j]);
            self.state[j] = if l == h {
                State::Fixed
            } else if l == 0.0 {
                State::Lower
            } else if h == 0.0 {
                State::Upper
            } else {
                State::Zero
            };
        }
        for i in 0..self.p {
            self.x[self.m + i] = 0.0;
            self.state[self.m + i] = State::Basic;
            self.basis[i] = self.m + i;
            self.binv[i] = [0.0; MAX_ROWS];
            self.binv[i][i] = 1.0;
        }
    }

    /// The box of variable `j` (artificials: `[0, 0]`).
    fn bounds(&self, j: usize) -> (f64, f64) {
        if j < self.m {
            (self.lo[j], self.hi[j])
        } else {
            (0.0, 0.0)
        }
    }

    /// `y = B⁻ᵀ g_B` (artificials cost nothing).
    fn duals(&self) -> [f64; MAX_ROWS] {
        let mut y = [0.0; MAX_ROWS];
        for i in 0..self.p {
            let v = self.basis[i];
            if v < self.m && self.g[v] != 0.0 {
                let c = self.g[v];
                for (yk, b) in y.iter_mut().zip(&self.binv[i]).take(self.p) {
                    *yk += c * b;
                }
            }
        }
        y
    }

    /// The reduced cost `g_j − yᵀE_j`.
    fn reduced_cost(&self, j: usize, y: &[f64; MAX_ROWS]) -> f64 {
        let c = &self.cols[j];
        y.iter()
            .zip(c)
            .take(self.p)
            .fold(self.g[j], |d, (yi, ci)| d - yi * ci)
    }

    /// The entering variable and its direction (±1), `None` at optimality.
    fn price(&self, y: &[f64; MAX_ROWS], tol: f64, bland: bool) -> Option<(usize, f64)> {
        let mut best = None;
        let mut best_score = 0.0;
        for j in 0..self.m {
            let state = self.state[j];
            if matches!(state, State::Basic | State::Fixed) {
                continue;
            }
            let d = self.reduced_cost(j, y);
            let dir = match state {
                State::Lower if d > tol => 1.0,
                State::Upper if d < -tol => -1.0,
                State::Zero if d.abs() > tol => d.signum(),
                _ => continue,
            };
            if bland {
                return Some((j, dir));
            }
            let room = if dir > 0.0 {
                self.hi[j] - self.x[j]
            } else {
                self.x[j] - self.lo[j]
            };
            let score = d.abs() * room;
            if score > best_score {
                best_score = score;
                best = Some((j, dir));
            }
        }
        best
    }

    /// `w = B⁻¹ E_q`.
    fn ftran(&self, q: usize) -> [f64; MAX_ROWS] {
        let c = &self.cols[q];
        let mut w = [0.0; MAX_ROWS];
        for (wi, row) in w.iter_mut().zip(&self.binv).take(self.p) {
            *wi = row.iter().zip(c).take(self.p).map(|(b, a)| b * a).sum();
        }
        w
    }

    /// The step length and the leaving row (`None`: the entering variable reaches its other
    /// bound first, a bound flip).
    fn ratio(&self, q: usize, dir: f64, w: &[f64; MAX_ROWS], bland: bool) -> (f64, Option<usize>) {
        let mut t = if dir > 0.0 {
            self.hi[q] - self.x[q]
        } else {
            self.x[q] - self.lo[q]
        };
        let wmax = w[..self.p].iter().fold(1.0_f64, |a, v| a.max(v.abs()));
        let tol = PIVOT_TOL * wmax;
        let mut leave: Option<usize> = None;
        for (i, (&wi, &v)) in w.iter().zip(&self.basis).enumerate().take(self.p) {
            let rate = -dir * wi;
            if rate.abs() <= tol {
                continue;
            }
            let (l, h) = self.bounds(v);
            let ti = if rate < 0.0 {
                (self.x[v] - l) / -rate
            } else {
                (h - self.x[v]) / rate
            }
            .max(0.0);
            let take = if ti < t {
                true
            } else if ti == t {
                match leave {
                    Some(r) if bland => v < self.basis[r],
                    Some(r) => wi.abs() > w[r].abs(),
                    None => false,
                }
            } else {
                false
            };
            if take {
                t = ti;
                leave = Some(i);
            }
        }
        (t, leave)
    }

    /// Move the entering variable `q` by `dir·t`, the basics along `−dir·t·w`; pivot or flip.
    fn step(&mut self, q: usize, dir: f64, t: f64, leave: Option<usize>, w: &[f64; MAX_ROWS]) {
        let dx = dir * t;
        self.x[q] += dx;
        for (&v, wi) in self.basis.iter().zip(w).take(self.p) {
            self.x[v] -= dx * wi;
        }
        let Some(r) = leave else {
            (self.x[q], self.state[q]) = if dir > 0.0 {
                (self.hi[q], State::Upper)
            } else {
                (self.lo[q], State::Lower)
            };
            return;
        };
        let v = self.basis[r];
        let (l, h) = self.bounds(v);
        let falls = dir * w[r] > 0.0;
        self.x[v] = if falls { l } else { h };
        self.state[v] = if l == h {
            State::Fixed
        } else if falls {
            State::Lower
        } else {
            State::Upper
        };
        self.basis[r] = q;
        self.state[q] = State::Basic;
        let piv = w[r];
        let p = self.p;
        for b in self.binv[r].iter_mut().take(p) {
            *b /= piv;
        }
        let pivot_row = self.binv[r];
        for (i, (row, &wi)) in self.binv.iter_mut().zip(w).enumerate().take(p) {
            if i != r && wi != 0.0 {
                for (b, pr) in row.iter_mut().zip(&pivot_row).take(p) {
                    *b -= wi * pr;
                }
            }
        }
    }

    /// Recompute the basics, clamp, and check the certificate (module documentation).
    fn certify(&mut self, iterations: usize, bland: bool) -> Option<f64> {
        let (m, p) = (self.m, self.p);
        let mut rhs = [0.0; MAX_ROWS];
        for j in (0..m).filter(|&j| self.state[j] != State::Basic) {
            for (r, c) in rhs.iter_mut().zip(&self.cols[j]).take(p) {
                *r -= c * self.x[j];
            }
        }
        let mut violation = 0.0_f64;
        for i in 0..p {
            let v = self.basis[i];
            let xv: f64 = self.binv[i]
                .iter()
                .zip(&rhs)
                .take(p)
                .map(|(b, r)| b * r)
                .sum();
            let (l, h) = self.bounds(v);
            violation = violation.max(l - xv).max(xv - h);
            self.x[v] = xv.clamp(l, h);
        }
        let y = self.duals();
        let (mut primal, mut dual_bound, mut scale) = (0.0, 0.0, 0.0);
        let (mut col_max, mut bound_max) = (0.0_f64, 0.0_f64);
        let mut resid = [0.0; MAX_ROWS];
        for j in 0..m {
            let (u, l, h) = (self.x[j], self.lo[j], self.hi[j]);
            let d = self.reduced_cost(j, &y);
            primal += self.g[j] * u;
            dual_bound += (l * d).max(h * d);
            let b = l.abs().max(h.abs());
            scale += self.g[j].abs() * b;
            bound_max = bound_max.max(b);
            for (r, c) in resid.iter_mut().zip(&self.cols[j]).take(p) {
                *r += c * u;
                col_max = col_max.max(c.abs());
            }
        }
        let residual = resid[..p].iter().fold(0.0_f64, |a, r| a.max(r.abs()));
        let feas = FEAS_TOL * bound_max.max(f64::MIN_POSITIVE);
        let certified = violation <= feas
            && residual <= feas * col_max.max(1.0)
            && (dual_bound - primal).abs() <= GAP_TOL * scale;
        self.last = Certificate {
            primal,
            dual_bound,
            residual,
            violation,
            iterations,
            bland,
            certified,
        };
        certified.then_some(primal.max(0.0))
    }
}

#[cfg(test)]
#[path = "authority_lp_tests.rs"]
mod tests;

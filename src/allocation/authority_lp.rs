//! The dedicated exact solver of the attainable-authority programmes (docs/model.md §6): a dense
//! bounded-variable primal simplex (tableau form) for
//!
//! ```text
//! max α   s.t.   M u − s α e_r = 0,   l ≤ u ≤ h,   0 ≤ α ≤ ᾱ,   with l ≤ 0 ≤ h
//! ```
//!
//! `M = S T_r` has `c ≤` [`MAX_ROWS`] rows (the commanded axes), `u` one entry per thruster,
//! `r` is the programme's row and `s = ±1` its sign; `ᾱ = Σ_j |M_rj| max(|l_j|, |h_j|)` bounds
//! `α = s (M u)_r` anyway, so the box on `α` cuts nothing.
//!
//! - **Start.** `u = 0, α = 0` is feasible because every box contains 0. Each row has an
//!   artificial variable boxed to `[0, 0]`. A **crash** shared by all `2c` programmes of a
//!   configuration (and redone per removed thruster) pivots thruster columns into the basis
//!   in place of the artificials at zero step, by complete pivoting on `M` (largest entry first,
//!   none below [`CRASH_TOL`] of `max |M|`): `B⁻¹` and the tableau `B⁻¹ [M | I]` are then
//!   copied into each programme, whose `α` column is `−s B⁻¹ e_r`. An artificial left basic
//!   marks a dependent row (`M` rank deficient); artificials never re-enter (their box is a
//!   point). Thrusters start nonbasic at 0, which may lie strictly inside their box (state
//!   `Zero`: such a variable may enter in either direction; once basic it only ever leaves at a
//!   bound).
//! - **Iterations.** Pricing takes the largest `|d_j| · room_j` (reduced cost times the distance
//!   to the bound it moves towards). After [`DEGENERATE_LIMIT`] zero-length pivots that leave a
//!   non-artificial variable the solve switches to Bland's rule (lowest index enters, lowest
//!   index leaves among ties) for the rest of the solve, so it cannot cycle. The ratio test
//!   prefers, among ties, the largest pivot (Bland: the lowest index); pivots below
//!   [`PIVOT_TOL`] are not taken.
//! - **Certificate.** At the end the basic values are recomputed from the nonbasic ones
//!   (`x_B = −B⁻¹ N x_N`), clamped into their boxes, and the answer is accepted only when (i)
//!   the equality residual and the clamp are at most [`FEAS_TOL`] of the data's scale and (ii)
//!   the dual bound `Σ_j max(l_j d_j, h_j d_j) + max(0, ᾱ d_α)`, with the reduced costs `d`
//!   recomputed from the data for the final multipliers `y` — an upper bound on the optimum for
//!   **any** `y` (weak duality: `α = d·x + yᵀA x` and `A x = 0`) — exceeds the attained `α` by
//!   at most [`GAP_TOL`] of `ᾱ`. Otherwise (or after the iteration cap) [`BoxLp::solve`]
//!   returns `None` and the caller falls back to Clarabel.
//!
//! A programme's result is a function of its own data (`M`, the boxes, `r`, `s`): the crash
//! depends only on `M` and which boxes are points, and each programme starts from it afresh.
//! So results are bit-identical for any order of solves and any thread count. Nothing is
//! allocated per solve: the workspace is sized once.

/// The largest number of equality rows (all six axes commanded).
pub(crate) const MAX_ROWS: usize = 6;

/// Zero-length pivots leaving a non-artificial variable before the switch to Bland's rule.
const DEGENERATE_LIMIT: usize = 8;

/// Crash pivots below this fraction of `max |M|` are not taken (the rows are dependent).
const CRASH_TOL: f64 = 1e-9;

/// Pivot tolerance of the ratio test, relative to `max(1, ‖B⁻¹a_q‖∞)`.
const PIVOT_TOL: f64 = 1e-9;

/// Reduced-cost (dual feasibility) tolerance (the objective's only coefficient is 1).
const DUAL_TOL: f64 = 1e-11;

/// Primal feasibility tolerance of the certificate, relative to the data's scale.
const FEAS_TOL: f64 = 1e-9;

/// Duality-gap tolerance of the certificate, relative to `ᾱ`.
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
    /// The attained `α`.
    pub primal: f64,
    /// The dual bound for the final multipliers: an upper bound on the optimum.
    pub dual_bound: f64,
    /// `max_i |(M u − s α e_r)_i|` of the returned point.
    pub residual: f64,
    /// How far the recomputed basic values lay outside their boxes (clamped).
    pub violation: f64,
    /// Simplex iterations after the crash (pivots and bound flips).
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

    /// A programme whose answer is 0 by inspection (`ᾱ = 0`).
    const ZERO: Self = Self {
        primal: 0.0,
        dual_bound: 0.0,
        residual: 0.0,
        violation: 0.0,
        certified: true,
        ..Self::NONE
    };
}

/// A simplex state: tableau `B⁻¹ [M | α column | I]` (row-major, `c` rows of `width`), basis,
/// variable states.
#[derive(Clone)]
struct Tableau {
    tab: Vec<f64>,
    basis: [usize; MAX_ROWS],
    state: Vec<State>,
}

/// The workspace of the authority programmes of one `M`: the data (set through
/// [`BoxLp::column`] and [`BoxLp::set_bounds`], then [`BoxLp::crash`]) and the simplex state.
/// Variables: thrusters `0..m`, `α` = `m`, artificials `m + 1 + i`.
pub(crate) struct BoxLp {
    /// Thrusters.
    m: usize,
    /// Rows (≤ [`MAX_ROWS`]).
    c: usize,
    /// Tableau row length `m + 1 + c`.
    width: usize,
    /// Column `j` of `M` (the first `c` entries used).
    cols: Vec<[f64; MAX_ROWS]>,
    /// Boxes of all variables (thrusters, `α`: `[0, ᾱ]`, artificials: `[0, 0]`).
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// The state after the crash, shared by the programmes.
    crashed: Tableau,
    /// The working state.
    work: Tableau,
    /// Reduced costs.
    d: Vec<f64>,
    /// Values of all variables.
    x: Vec<f64>,
    /// The programme's `ᾱ` and sign.
    alpha_hi: f64,
    sign: f64,
    /// Zero-length pivots leaving a non-artificial variable before the switch to Bland's rule
    /// ([`DEGENERATE_LIMIT`]; 0: Bland's rule from the start).
    pub degenerate_limit: usize,
    /// What the last solve established.
    pub last: Certificate,
}

impl BoxLp {
    /// A workspace for `m` thrusters and `c ≤ MAX_ROWS` rows; data all zero.
    pub fn new(m: usize, c: usize) -> Self {
        assert!(c <= MAX_ROWS, "at most {MAX_ROWS} rows");
        let width = m + 1 + c;
        let tableau = Tableau {
            tab: vec![0.0; c * width],
            basis: [0; MAX_ROWS],
            state: vec![State::Fixed; width],
        };
        Self {
            m,
            c,
            width,
            cols: vec![[0.0; MAX_ROWS]; m],
            lo: vec![0.0; width],
            hi: vec![0.0; width],
            crashed: tableau.clone(),
            work: tableau,
            d: vec![0.0; width],
            x: vec![0.0; width],
            alpha_hi: 0.0,
            sign: 1.0,
            degenerate_limit: DEGENERATE_LIMIT,
            last: Certificate::NONE,
        }
    }

    /// Column `j` of `M` (its first `c` entries are read); call [`BoxLp::crash`] after changes.
    pub fn column(&mut self, j: usize) -> &mut [f64; MAX_ROWS] {
        &mut self.cols[j]
    }

    /// The box of thruster `j`; `lo ≤ 0 ≤ hi` is the caller's promise. Call [`BoxLp::crash`]
    /// after changes.
    pub fn set_bounds(&mut self, j: usize, lo: f64, hi: f64) {
        debug_assert!(lo <= 0.0 && 0.0 <= hi);
        self.lo[j] = lo;
        self.hi[j] = hi;
    }

    /// The box of variable `j` (`α`: `[0, ᾱ]`, artificials: `[0, 0]`).
    #[inline]
    fn bounds(&self, j: usize) -> (f64, f64) {
        (self.lo[j], self.hi[j])
    }

    /// The crash basis of the current `M` and boxes (module documentation).
    pub fn crash(&mut self) {
        let (m, c, w) = (self.m, self.c, self.width);
        let t = &mut self.crashed;
        let mut mmax = 0.0_f64;
        for i in 0..c {
            let row = &mut t.tab[i * w..(i + 1) * w];
            for (j, e) in row[..m].iter_mut().enumerate() {
                *e = self.cols[j][i];
                mmax = mmax.max(e.abs());
            }
            row[m..].fill(0.0);
            row[m + 1 + i] = 1.0;
            t.basis[i] = m + 1 + i;
        }
        for j in 0..m {
            let (l, h) = (self.lo[j], self.hi[j]);
            t.state[j] = if l == h {
                State::Fixed
            } else if l == 0.0 {
                State::Lower
            } else if h == 0.0 {
                State::Upper
            } else {
                State::Zero
            };
        }
        t.state[m] = State::Lower;
        t.state[m + 1..].fill(State::Basic);
        let tol = CRASH_TOL * mmax;
        for _ in 0..c {
            let mut best: Option<(usize, usize)> = None;
            let mut size = tol;
            for i in (0..c).filter(|&i| t.basis[i] > m) {
                for j in (0..m).filter(|&j| !matches!(t.state[j], State::Basic | State::Fixed)) {
                    let v = t.tab[i * w + j].abs();
                    if v > size {
                        (size, best) = (v, Some((i, j)));
                    }
                }
            }
            let Some((r, q)) = best else { break };
            pivot(&mut t.tab, w, (r, q), None);
            t.state[t.basis[r]] = State::Fixed;
            t.basis[r] = q;
            t.state[q] = State::Basic;
        }
    }

    /// `max α` of row `r` and sign `sign` (±1) on the data of the last [`BoxLp::crash`], when
    /// certified (module documentation); `None` otherwise. [`BoxLp::last`] says what was
    /// established.
    pub fn solve(&mut self, r: usize, sign: f64) -> Option<f64> {
        if !self.start(r, sign) {
            self.last = Certificate::ZERO;
            return Some(0.0);
        }
        let max_iter = 20 * (self.m + self.c) + 50;
        let (mut bland, mut degenerate) = (self.degenerate_limit == 0, 0);
        for it in 0..max_iter {
            let Some((q, dir)) = self.price(bland) else {
                return self.certify(r, it, bland);
            };
            let (t, leave) = self.ratio(q, dir, bland);
            if let Some(i) = leave {
                if t == 0.0 && self.work.basis[i] <= self.m {
                    degenerate += 1;
                    bland |= degenerate >= self.degenerate_limit;
                }
            }
            self.step(q, dir, t, leave);
        }
        self.last = Certificate {
            iterations: max_iter,
            bland,
            ..Certificate::NONE
        };
        None
    }

    /// The crash state with the `α` column of row `r` and sign `sign`; `false` when `ᾱ = 0`.
    fn start(&mut self, r: usize, sign: f64) -> bool {
        let (m, w) = (self.m, self.width);
        self.alpha_hi = (0..m)
            .map(|j| self.cols[j][r].abs() * self.lo[j].abs().max(self.hi[j].abs()))
            .sum();
        if self.alpha_hi == 0.0 {
            return false;
        }
        self.hi[m] = self.alpha_hi;
        self.sign = sign;
        self.work.tab.copy_from_slice(&self.crashed.tab);
        self.work.basis = self.crashed.basis;
        self.work.state.copy_from_slice(&self.crashed.state);
        for row in self.work.tab.chunks_exact_mut(w) {
            row[m] = -sign * row[m + 1 + r];
        }
        self.x.fill(0.0);
        self.d.fill(0.0);
        self.d[m] = 1.0;
        true
    }

    /// The entering variable and its direction (±1), `None` at optimality.
    fn price(&self, bland: bool) -> Option<(usize, f64)> {
        let mut best = None;
        let mut best_score = 0.0;
        for j in 0..=self.m {
            let d = self.d[j];
            let dir = match self.work.state[j] {
                State::Lower if d > DUAL_TOL => 1.0,
                State::Upper if d < -DUAL_TOL => -1.0,
                State::Zero if d.abs() > DUAL_TOL => d.signum(),
                _ => continue,
            };
            if bland {
                return Some((j, dir));
            }
            let (l, h) = self.bounds(j);
            let room = if dir > 0.0 {
                h - self.x[j]
            } else {
                self.x[j] - l
            };
            let score = d.abs() * room;
            if score > best_score {
                best_score = score;
                best = Some((j, dir));
            }
        }
        best
    }

    /// The step length and the leaving row (`None`: the entering variable reaches its other
    /// bound first, a bound flip).
    fn ratio(&self, q: usize, dir: f64, bland: bool) -> (f64, Option<usize>) {
        let (c, w) = (self.c, self.width);
        let col = |i: usize| self.work.tab[i * w + q];
        let (l, h) = self.bounds(q);
        let mut t = if dir > 0.0 {
            h - self.x[q]
        } else {
            self.x[q] - l
        };
        let wmax = (0..c).fold(1.0_f64, |a, i| a.max(col(i).abs()));
        let tol = PIVOT_TOL * wmax;
        let mut leave: Option<usize> = None;
        for i in 0..c {
            let wi = col(i);
            let rate = -dir * wi;
            if rate.abs() <= tol {
                continue;
            }
            let v = self.work.basis[i];
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
                    Some(k) if bland => v < self.work.basis[k],
                    Some(k) => wi.abs() > col(k).abs(),
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

    /// Move the entering variable `q` by `dir·t`, the basics along `−dir·t·B⁻¹a_q`; pivot
    /// (updating the tableau and the reduced costs) or flip.
    fn step(&mut self, q: usize, dir: f64, t: f64, leave: Option<usize>) {
        let (c, w) = (self.c, self.width);
        let dx = dir * t;
        self.x[q] += dx;
        for i in 0..c {
            self.x[self.work.basis[i]] -= dx * self.work.tab[i * w + q];
        }
        let Some(r) = leave else {
            let (l, h) = self.bounds(q);
            (self.x[q], self.work.state[q]) = if dir > 0.0 {
                (h, State::Upper)
            } else {
                (l, State::Lower)
            };
            return;
        };
        let v = self.work.basis[r];
        let (l, h) = self.bounds(v);
        let piv = self.work.tab[r * w + q];
        let falls = dir * piv > 0.0;
        self.x[v] = if falls { l } else { h };
        self.work.state[v] = if l == h {
            State::Fixed
        } else if falls {
            State::Lower
        } else {
            State::Upper
        };
        self.work.basis[r] = q;
        self.work.state[q] = State::Basic;
        pivot(&mut self.work.tab, w, (r, q), Some(&mut self.d));
    }

    /// Recompute the basics, clamp, and check the certificate (module documentation).
    fn certify(&mut self, r: usize, iterations: usize, bland: bool) -> Option<f64> {
        let (m, c, w) = (self.m, self.c, self.width);
        // x_B = −B⁻¹ N x_N, with B⁻¹ the artificial columns of the tableau.
        let mut rhs = [0.0; MAX_ROWS];
        for j in (0..m).filter(|&j| self.work.state[j] != State::Basic) {
            for (e, a) in rhs.iter_mut().zip(&self.cols[j]).take(c) {
                *e -= a * self.x[j];
            }
        }
        if self.work.state[m] != State::Basic {
            rhs[r] += self.sign * self.x[m];
        }
        let mut violation = 0.0_f64;
        for i in 0..c {
            let binv = &self.work.tab[i * w + m + 1..(i + 1) * w];
            let xv: f64 = binv.iter().zip(&rhs).map(|(b, e)| b * e).sum();
            let v = self.work.basis[i];
            let (l, h) = self.bounds(v);
            violation = violation.max(l - xv).max(xv - h);
            self.x[v] = xv.clamp(l, h);
        }
        // y = −(reduced costs of the artificials); d recomputed from the data.
        let mut y = [0.0; MAX_ROWS];
        for (yi, d) in y.iter_mut().zip(&self.d[m + 1..]) {
            *yi = -d;
        }
        let alpha = self.x[m];
        let mut resid = [0.0; MAX_ROWS];
        resid[r] = -self.sign * alpha;
        let (mut dual_bound, mut bound_max, mut col_max) = (0.0, 0.0_f64, 0.0_f64);
        for j in 0..m {
            let (u, l, h) = (self.x[j], self.lo[j], self.hi[j]);
            let col = &self.cols[j];
            let d: f64 = -y.iter().zip(col).take(c).map(|(a, b)| a * b).sum::<f64>();
            dual_bound += (l * d).max(h * d);
            bound_max = bound_max.max(l.abs().max(h.abs()));
            for (e, a) in resid.iter_mut().zip(col).take(c) {
                *e += a * u;
                col_max = col_max.max(a.abs());
            }
        }
        let d_alpha = 1.0 + self.sign * y[r];
        dual_bound += (self.alpha_hi * d_alpha).max(0.0);
        let residual = resid[..c].iter().fold(0.0_f64, |a, e| a.max(e.abs()));
        let feas = FEAS_TOL * bound_max.max(self.alpha_hi);
        let certified = violation <= feas
            && residual <= feas * col_max.max(1.0)
            && (dual_bound - alpha).abs() <= GAP_TOL * self.alpha_hi;
        self.last = Certificate {
            primal: alpha,
            dual_bound,
            residual,
            violation,
            iterations,
            bland,
            certified,
        };
        certified.then_some(alpha.max(0.0))
    }
}

/// Pivot the tableau `tab` (rows of `w`) on row `r`, column `q`, and the reduced costs `d`
/// with it when given.
fn pivot(tab: &mut [f64], w: usize, (r, q): (usize, usize), d: Option<&mut [f64]>) {
    let (before, rest) = tab.split_at_mut(r * w);
    let (pivot_row, after) = rest.split_at_mut(w);
    let inv = 1.0 / pivot_row[q];
    for e in pivot_row.iter_mut() {
        *e *= inv;
    }
    pivot_row[q] = 1.0;
    let eliminate = |row: &mut [f64]| {
        let f = row[q];
        if f != 0.0 {
            for (e, p) in row.iter_mut().zip(pivot_row.iter()) {
                *e -= f * p;
            }
            row[q] = 0.0;
        }
    };
    before.chunks_exact_mut(w).for_each(eliminate);
    after.chunks_exact_mut(w).for_each(eliminate);
    if let Some(d) = d {
        eliminate(d);
    }
}

#[cfg(test)]
#[path = "authority_lp_tests.rs"]
mod tests;

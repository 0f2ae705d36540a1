//! CMA-ES, the (μ/μ_w, λ) covariance matrix adaptation evolution strategy of Hansen's
//! tutorial ("The CMA Evolution Strategy: A Tutorial", 2016), with pycma's default
//! population, weights and learning rates, as an ask/tell state machine over the unit box.
//!
//! The driver ([`super::search`]) asks for a generation, evaluates it through the search's
//! cost function (projected onto the box, `PENALTY · distance²` added: no evaluation is ever
//! outside the bounds) and tells the costs back; [`Cmaes::tell`] adds
//! [`BOUND_WEIGHT`]` · distance²` for the ranking on top (pycma's BoundPenalty idea with a
//! fixed weight), so the mean is pulled back towards the box.
//!
//! Defaults (`n` the dimension): `λ = 4 + ⌊3 ln n⌋` (doubled per IPOP restart by the
//! driver), `μ = ⌊λ/2⌋`, positive log-rank weights `ln((λ+1)/2) − ln i` normalised to sum 1
//! (no active, negative weights), `c_σ = (μ_eff+2)/(n+μ_eff+5)`,
//! `d_σ = 1 + 2 max(0, √((μ_eff−1)/(n+1)) − 1) + c_σ`, `c_c = (4+μ_eff/n)/(n+4+2μ_eff/n)`,
//! `c_1 = 2/((n+1.3)² + μ_eff)`, `c_μ = min(1 − c_1, 2(μ_eff − 2 + 1/μ_eff)/((n+2)² + μ_eff))`.
//! The covariance is decomposed (nalgebra `SymmetricEigen`) every generation, fine for the
//! few parameters of a tuning. Normal deviates come from the seeded ChaCha8 generator by
//! Box–Muller, so a run is a function of the seed alone.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Weight of the squared distance outside the unit box in the ranking, on top of the
/// search's own penalty.
pub const BOUND_WEIGHT: f64 = 10.0;

/// Largest condition number of the covariance before a run stops.
const MAX_CONDITION: f64 = 1e14;

/// The default population size `4 + ⌊3 ln n⌋` of an `n`-dimensional problem.
pub fn default_lambda(n: usize) -> usize {
    4 + (3.0 * (n.max(1) as f64).ln()).floor() as usize
}

/// The state of one CMA-ES run.
pub struct Cmaes {
    n: usize,
    lambda: usize,
    weights: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    chi_n: f64,
    mean: DVector<f64>,
    sigma: f64,
    cov: DMatrix<f64>,
    /// Eigenvectors (columns) and the square roots of the eigenvalues of `cov`.
    b: DMatrix<f64>,
    d: DVector<f64>,
    p_sigma: DVector<f64>,
    p_c: DVector<f64>,
    generation: u64,
    rng: ChaCha8Rng,
    /// The steps `y_k = B D z_k` of the last generation asked for.
    steps: Vec<DVector<f64>>,
    /// Best cost of each generation told (for the flat-fitness stop).
    best_costs: Vec<f64>,
}

impl Cmaes {
    /// A run from `mean` (unit box) with step size `sigma` and population `lambda` (≥ 2).
    pub fn new(mean: &[f64], sigma: f64, lambda: usize, rng: ChaCha8Rng) -> Self {
        let n = mean.len();
        let nf = n as f64;
        let lambda = lambda.max(2);
        let mu = lambda / 2;
        let raw: Vec<f64> = (1..=mu)
            .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - (i as f64).ln())
            .collect();
        let sum: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / sum).collect();
        let mu_eff = 1.0 / weights.iter().map(|w| w * w).sum::<f64>();
        let c_sigma = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let d_sigma = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma;
        let c_c = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let c_1 = 2.0 / ((nf + 1.3).powi(2) + mu_eff);
        let c_mu =
            (1.0 - c_1).min(2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((nf + 2.0).powi(2) + mu_eff));
        Cmaes {
            n,
            lambda,
            weights,
            mu_eff,
            c_sigma,
            d_sigma,
            c_c,
            c_1,
            c_mu,
            chi_n: nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf)),
            mean: DVector::from_column_slice(mean),
            sigma,
            cov: DMatrix::identity(n, n),
            b: DMatrix::identity(n, n),
            d: DVector::from_element(n, 1.0),
            p_sigma: DVector::zeros(n),
            p_c: DVector::zeros(n),
            generation: 0,
            rng,
            steps: Vec::new(),
            best_costs: Vec::new(),
        }
    }

    /// The population size λ.
    pub fn lambda(&self) -> usize {
        self.lambda
    }

    /// The current mean (unit-box coordinates, possibly outside the box).
    pub fn mean(&self) -> &[f64] {
        self.mean.as_slice()
    }

    /// The current step size σ.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// A standard normal deviate (Box–Muller on two uniforms in (0, 1]).
    fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.rng.random::<f64>();
        let u2 = self.rng.random::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// Sample the next generation: λ points `m + σ B D z`, `z ~ N(0, I)`.
    pub fn ask(&mut self) -> Vec<Vec<f64>> {
        self.steps.clear();
        let mut points = Vec::with_capacity(self.lambda);
        for _ in 0..self.lambda {
            let z = DVector::from_fn(self.n, |_, _| self.normal());
            let y = &self.b * z.component_mul(&self.d);
            let x = &self.mean + self.sigma * &y;
            points.push(x.as_slice().to_vec());
            self.steps.push(y);
        }
        points
    }

    /// Update the distribution from the costs of the generation last asked for (in its
    /// order); the ranking adds [`BOUND_WEIGHT`] times each point's squared distance
    /// outside the unit box. Ties keep the earlier point.
    pub fn tell(&mut self, costs: &[f64]) {
        let nf = self.n as f64;
        let ranked: Vec<f64> = self
            .steps
            .iter()
            .zip(costs)
            .map(|(y, c)| {
                let x = &self.mean + self.sigma * y;
                let d2: f64 = x.iter().map(|v| (v - v.clamp(0.0, 1.0)).powi(2)).sum();
                let c = if c.is_nan() { f64::INFINITY } else { *c };
                c + BOUND_WEIGHT * d2
            })
            .collect();
        let mut order: Vec<usize> = (0..ranked.len()).collect();
        order.sort_by(|&i, &j| ranked[i].total_cmp(&ranked[j]).then(i.cmp(&j)));
        self.best_costs.push(ranked[order[0]]);
        let mut y_w = DVector::zeros(self.n);
        for (w, &i) in self.weights.iter().zip(&order) {
            y_w += *w * &self.steps[i];
        }
        self.mean += self.sigma * &y_w;
        // C^{-1/2} y_w = B D^{-1} Bᵀ y_w.
        let inv_sqrt_y = &self.b * (self.b.transpose() * &y_w).component_div(&self.d);
        let cs = self.c_sigma;
        self.p_sigma =
            (1.0 - cs) * &self.p_sigma + (cs * (2.0 - cs) * self.mu_eff).sqrt() * inv_sqrt_y;
        self.generation += 1;
        let norm_ps = self.p_sigma.norm();
        let decay = 1.0 - (1.0 - cs).powi(2 * self.generation.min(100_000) as i32);
        let h_sigma = norm_ps / decay.sqrt() < (1.4 + 2.0 / (nf + 1.0)) * self.chi_n;
        let cc = self.c_c;
        let h = if h_sigma { 1.0 } else { 0.0 };
        self.p_c = (1.0 - cc) * &self.p_c + h * (cc * (2.0 - cc) * self.mu_eff).sqrt() * &y_w;
        let delta = (1.0 - h) * cc * (2.0 - cc);
        let mut rank_mu = DMatrix::zeros(self.n, self.n);
        for (w, &i) in self.weights.iter().zip(&order) {
            let y = &self.steps[i];
            rank_mu += *w * y * y.transpose();
        }
        self.cov = (1.0 + self.c_1 * delta - self.c_1 - self.c_mu) * &self.cov
            + self.c_1 * &self.p_c * self.p_c.transpose()
            + self.c_mu * rank_mu;
        self.sigma *= ((cs / self.d_sigma) * (norm_ps / self.chi_n - 1.0)).exp();
        self.decompose();
    }

    /// Symmetrise the covariance and refresh `B` and `D` (eigenvalues kept ≥ 1e-300).
    fn decompose(&mut self) {
        let c = (&self.cov + self.cov.transpose()) * 0.5;
        let eig = SymmetricEigen::new(c.clone());
        self.cov = c;
        self.b = eig.eigenvectors;
        self.d = eig.eigenvalues.map(|l| l.max(1e-300).sqrt());
    }

    /// Why the run should stop, if it should: the step `σ · max(√C_ii, |p_c,i|)` below
    /// `tol` in every coordinate, the best costs of the last `10 + ⌈30 n / λ⌉` generations
    /// and this generation's best within `tol` of each other, a covariance condition beyond
    /// 1e14, or a non-finite step size.
    pub fn stop(&self, tol: f64) -> Option<&'static str> {
        if !self.sigma.is_finite() || self.sigma <= 0.0 {
            return Some("step size not finite");
        }
        let tolx =
            (0..self.n).all(|i| self.sigma * self.cov[(i, i)].sqrt().max(self.p_c[i].abs()) < tol);
        if tolx {
            return Some("step size below tolerance");
        }
        let window = 10 + (30 * self.n).div_ceil(self.lambda);
        if self.best_costs.len() >= window {
            let recent = &self.best_costs[self.best_costs.len() - window..];
            let (lo, hi) = recent
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
                    (a.min(*c), b.max(*c))
                });
            if hi - lo < tol {
                return Some("best cost flat within tolerance");
            }
        }
        let (dmin, dmax) = self
            .d
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(a, b), d| (a.min(*d), b.max(*d)));
        if (dmax / dmin).powi(2) > MAX_CONDITION {
            return Some("covariance condition above 1e14");
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::rng_for;

    #[test]
    fn pycma_defaults_for_four_parameters() {
        let c = Cmaes::new(&[0.5; 4], 0.3, default_lambda(4), rng_for(1, 0));
        assert_eq!(c.lambda(), 8);
        assert_eq!(c.weights.len(), 4);
        assert!((c.weights.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        // The tutorial's formulas for n = 4, λ = 8 (computed independently in Python).
        assert!(
            (c.mu_eff - 2.600_178_826_113_18).abs() < 1e-12,
            "{}",
            c.mu_eff
        );
        assert!((c.c_sigma - 0.396_561_026_779_838_2).abs() < 1e-12);
        assert!((c.d_sigma - 1.396_561_026_779_838).abs() < 1e-12);
        assert!((c.c_1 - 0.065_167_427_382_282_68).abs() < 1e-12);
        assert!((c.c_mu - 0.051_023_999_832_594_5).abs() < 1e-12);
        assert!((c.c_c - 0.5).abs() < 1e-15);
    }

    #[test]
    fn a_sphere_converges_and_the_same_seed_repeats_bit_for_bit() {
        let run = |seed| {
            let mut c = Cmaes::new(&[0.9, 0.1, 0.8], 0.3, default_lambda(3), rng_for(seed, 0));
            let mut gens = 0;
            while c.stop(1e-10).is_none() && gens < 2000 {
                let pop = c.ask();
                let f: Vec<f64> = pop
                    .iter()
                    .map(|x| x.iter().map(|v| (v - 0.4).powi(2)).sum())
                    .collect();
                c.tell(&f);
                gens += 1;
            }
            (c.mean().to_vec(), gens)
        };
        let (m, gens) = run(7);
        assert!(
            m.iter().all(|v| (v - 0.4).abs() < 1e-5),
            "{m:?} after {gens}"
        );
        assert!(gens < 400, "{gens} generations");
        assert_eq!(run(7), (m.clone(), gens));
        assert_ne!(run(8).0, m);
    }
}

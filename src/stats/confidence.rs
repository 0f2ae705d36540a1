//! Confidence, not proportions (issue 36 item 6): the one-sided Wilson lower bound of a success
//! probability, the exact one-sided sign test of paired wins, and Holm's step-down correction
//! across several comparisons. Formulas and sources: `docs/statistics.md` ("Confidence").

use super::normal::inv_cdf;

/// One-sided lower confidence bound of a binomial proportion by Wilson's score interval:
/// with `k` successes in `n` trials, `p̂ = k/n` and `z = Φ⁻¹(confidence)`,
///
/// `L = (p̂ + z²/(2n) − z √(p̂(1−p̂)/n + z²/(4n²))) / (1 + z²/n)`
///
/// (E. B. Wilson 1927, "Probable inference, the law of succession, and statistical inference",
/// *JASA* 22(158); scipy's `binomtest(k, n).proportion_ci(confidence_level = 2c − 1,
/// method = "wilson")` gives the same lower end for the two-sided level `2c − 1`). `0` when
/// `n = 0`; `confidence` in (0, 1).
pub fn wilson_lower(k: usize, n: usize, confidence: f64) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let n_f = n as f64;
    let p = (k.min(n) as f64) / n_f;
    let z = inv_cdf(confidence);
    let z2 = z * z;
    let centre = p + z2 / (2.0 * n_f);
    let half = z * (p * (1.0 - p) / n_f + z2 / (4.0 * n_f * n_f)).sqrt();
    ((centre - half) / (1.0 + z2 / n_f)).clamp(0.0, 1.0)
}

/// The least number of trials `n` in which `n` successes out of `n` give a Wilson lower bound
/// ([`wilson_lower`]) of at least `required` (`None` when `required ≥ 1`): the fewest worlds in
/// which a design that never fails can be shown to succeed with probability ≥ `required`.
/// From `L(n, n) = n/(n + z²)`: `n ≥ z² r/(1 − r)`.
pub fn wilson_worlds_needed(required: f64, confidence: f64) -> Option<usize> {
    if required >= 1.0 {
        return None;
    }
    if required <= 0.0 {
        return Some(1);
    }
    let z = inv_cdf(confidence);
    let mut n = ((z * z * required / (1.0 - required)).ceil() as usize).max(1);
    // Guard the rounding of the closed form with the bound itself.
    while wilson_lower(n, n, confidence) < required {
        n += 1;
    }
    while n > 1 && wilson_lower(n - 1, n - 1, confidence) >= required {
        n -= 1;
    }
    Some(n)
}

/// The fewest worlds `n ≥ from` at which the same share of favourable worlds, `⌊share·n⌋` of
/// `n`, passes `passes(k, n)` (a lower bound reached, a p-value small enough): searched in steps
/// of `max(1, n/64)` up to 65 536 worlds, `None` beyond. Serves both "how many worlds would
/// qualify this design" and "how many worlds would decide this comparison".
pub fn worlds_at_share(
    share: f64,
    from: usize,
    passes: impl Fn(usize, usize) -> bool,
) -> Option<usize> {
    let mut n = from.max(1);
    while n <= 1 << 16 {
        let k = (share * n as f64).floor() as usize;
        if passes(k, n) {
            return Some(n);
        }
        n += 1.max(n / 64);
    }
    None
}

/// `ln C(n, i)` through `ln Γ` (libm's `lgamma`).
fn ln_choose(n: usize, i: usize) -> f64 {
    let (n, i) = (n as f64, i as f64);
    libm::lgamma(n + 1.0) - libm::lgamma(i + 1.0) - libm::lgamma(n - i + 1.0)
}

/// The exact one-sided p-value of the sign test: `P(X ≥ wins)` for `X ~ Binomial(n, ½)`, the
/// probability of at least `wins` wins in `n` paired trials when neither side is better
/// (scipy's `binomtest(wins, n, 0.5, alternative = "greater").pvalue`). Summed term by term
/// from `2⁻ⁿ` up to `n = 1000`, in log space (log-sum-exp) beyond; `1` when `wins = 0`, `0`
/// when `wins > n`.
pub fn sign_test_p(wins: usize, n: usize) -> f64 {
    if wins == 0 {
        return 1.0;
    }
    if wins > n {
        return 0.0;
    }
    if n <= 1000 {
        // Exact to rounding: P(X = n) = 2⁻ⁿ (a normal double for n ≤ 1022), then
        // P(X = i − 1) = P(X = i) · i/(n − i + 1), summed from the smallest term up.
        let mut term = 0.5f64.powi(n as i32);
        let mut terms = Vec::with_capacity(n - wins + 1);
        terms.push(term);
        for i in (wins + 1..=n).rev() {
            term *= i as f64 / (n - i + 1) as f64;
            terms.push(term);
        }
        return terms.iter().sum::<f64>().min(1.0);
    }
    let ln_half_n = -(n as f64) * std::f64::consts::LN_2;
    let terms: Vec<f64> = (wins..=n).map(|i| ln_choose(n, i) + ln_half_n).collect();
    let max = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let sum: f64 = terms.iter().map(|t| (t - max).exp()).sum();
    (max + sum.ln()).exp().min(1.0)
}

/// The fewest paired worlds `n` in which `n` wins of `n` reach a sign-test p-value
/// ([`sign_test_p`]) of at most `alpha`: `2⁻ⁿ ≤ alpha`, `n = ⌈log₂(1/alpha)⌉`.
pub fn sign_worlds_needed(alpha: f64) -> usize {
    if alpha >= 1.0 {
        return 0;
    }
    if alpha <= 0.0 {
        return usize::MAX;
    }
    (-alpha.log2()).ceil().max(1.0) as usize
}

/// The indices of `p` by increasing value, NaN last, ties by index.
fn increasing(p: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by(|&a, &b| {
        p[a].is_nan()
            .cmp(&p[b].is_nan())
            .then(p[a].total_cmp(&p[b]))
            .then(a.cmp(&b))
    });
    order
}

/// Holm's step-down procedure at family-wise level `alpha` (S. Holm 1979, "A simple
/// sequentially rejective multiple test procedure", *Scand. J. Statist.* 6(2), 65–70): sort the
/// `m` p-values increasingly, reject the `i`-th smallest (1-based) while
/// `p₍ᵢ₎ ≤ alpha/(m − i + 1)`, and stop at the first that is not. Returns, per input (in input
/// order), whether its hypothesis is rejected. NaN p-values are never rejected.
pub fn holm(p: &[f64], alpha: f64) -> Vec<bool> {
    let m = p.len();
    let order = increasing(p);
    let mut rejected = vec![false; m];
    for (i, &j) in order.iter().enumerate() {
        if p[j].is_nan() || p[j] > alpha / (m - i) as f64 {
            break;
        }
        rejected[j] = true;
    }
    rejected
}

/// The Holm-adjusted p-values (`min(1, max over j ≤ i of (m − j + 1) p₍ⱼ₎)`, in input order): a
/// hypothesis is rejected by [`holm`] at level `alpha` iff its adjusted p-value is ≤ `alpha`.
pub fn holm_adjusted(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let order = increasing(p);
    let mut out = vec![f64::NAN; m];
    let mut running = 0.0f64;
    for (i, &j) in order.iter().enumerate() {
        if p[j].is_nan() {
            break;
        }
        running = running.max(((m - i) as f64 * p[j]).min(1.0));
        out[j] = running;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values from scipy 1.11: `binomtest(k, n, 0.5, alternative="greater").pvalue`.
    #[test]
    fn sign_test_matches_the_binomial_tail() {
        assert_eq!(sign_test_p(4, 4), 0.0625);
        assert!((sign_test_p(15, 16) - 17.0 / 65536.0).abs() < 1e-15);
        // 12 of 16: Σ_{i=12}^{16} C(16,i) / 2^16 = (1820+560+120+16+1)/65536.
        assert!((sign_test_p(12, 16) - 2517.0 / 65536.0).abs() < 1e-14);
        assert_eq!(sign_test_p(0, 10), 1.0);
        assert!((sign_test_p(32, 32) - 2f64.powi(-32)).abs() < 1e-22);
        // Half or fewer wins: p ≥ 0.5.
        assert!(sign_test_p(8, 16) > 0.5);
        // Large n stays finite and exact in log space: P(X ≥ 600 | n = 1000) ≈ 1.36e-10.
        let p = sign_test_p(600, 1000);
        assert!(p > 1.0e-10 && p < 1.5e-10, "{p}");
        assert_eq!(sign_worlds_needed(0.05), 5);
        assert_eq!(sign_worlds_needed(0.05 / 3.0), 6);
    }

    /// Wilson's one-sided lower bound against the closed form and values computed from the
    /// formula in Python (`statistics.NormalDist().inv_cdf(0.95)`, double precision): 15 of 16
    /// → 0.762510286198, 31 of 32 → 0.871418009354, 30 of 32 → 0.827690178760.
    #[test]
    fn wilson_lower_bound() {
        for (k, n, want) in [
            (15, 16, 0.762_510_286_198_476_3),
            (31, 32, 0.871_418_009_353_826_9),
            (30, 32, 0.827_690_178_760_341_6),
        ] {
            let l = wilson_lower(k, n, 0.95);
            assert!((l - want).abs() < 1e-12, "{k}/{n}: {l}");
        }
        let z = inv_cdf(0.95);
        for n in [1usize, 4, 16, 25, 64] {
            let closed = n as f64 / (n as f64 + z * z);
            assert!((wilson_lower(n, n, 0.95) - closed).abs() < 1e-12);
        }
        assert_eq!(wilson_lower(0, 0, 0.95), 0.0);
        assert!(wilson_lower(0, 10, 0.95) == 0.0);
        // All of 16 is not enough for 0.9; all of 25 is.
        assert_eq!(wilson_worlds_needed(0.9, 0.95), Some(25));
        assert!(wilson_lower(16, 16, 0.95) < 0.9 && wilson_lower(25, 25, 0.95) >= 0.9);
        assert_eq!(wilson_worlds_needed(1.0, 0.95), None);
    }

    /// Holm on a textbook example: p = (0.01, 0.04, 0.03, 0.005) at 0.05: sorted 0.005 ≤
    /// 0.0125, 0.01 ≤ 0.0167, 0.03 > 0.025 → only the first two rejected.
    #[test]
    fn holm_step_down() {
        let p = [0.01, 0.04, 0.03, 0.005];
        assert_eq!(holm(&p, 0.05), vec![true, false, false, true]);
        let adj = holm_adjusted(&p);
        let want = [0.03, 0.06, 0.06, 0.02];
        for (a, w) in adj.iter().zip(want) {
            assert!((a - w).abs() < 1e-15, "{adj:?}");
        }
        assert_eq!(holm(&[], 0.05), Vec::<bool>::new());
        assert_eq!(holm(&[f64::NAN, 0.001], 0.05), vec![false, true]);
    }
}

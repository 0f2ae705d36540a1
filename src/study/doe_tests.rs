//! Tests of the designs of experiments.

use super::*;

#[test]
fn normal_quantiles() {
    assert!(inverse_normal_cdf(0.5).abs() < 1e-6);
    assert!((inverse_normal_cdf(0.975) - 1.959964).abs() < 1e-5);
    assert!((inverse_normal_cdf(0.01) + 2.326348).abs() < 1e-5);
    assert!(inverse_normal_cdf(0.0).is_finite());
}

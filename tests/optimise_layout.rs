//! The shipped layout study (`studies/layout.toml`) on a reduced budget: from the paper's
//! thruster layout (docs/model.md §2, feasible), Nelder–Mead finds positions along the links and
//! directions whose commanded-subspace singular fraction is lower and whose p05 σ_min of the
//! commanded rows is higher than the paper layout's, while the short transport run still
//! meets its success criteria. Nelder–Mead's earlier full budget (240 evaluations) found its best
//! at evaluation 9 (fraction 0.0703 → 0.0508, p05 σ_min 0.0435 → 0.0506), inside this budget.

mod common;

use common::optimise_study_with;
use usm_study::optimise::problem::Method;

#[test]
fn optimised_layout_beats_the_paper_layout_on_both_static_figures() {
    // The study ships Bayesian optimisation, whose first improvement on the start comes after
    // 300 of its 400 evaluations (0.500 → −0.324 at the 397th; docs/optimise.md): too long for
    // a test. This one runs the study's earlier Nelder–Mead (step 0.1, one restart), whose
    // best came at its 9th evaluation.
    let (p, o) = optimise_study_with("studies/layout.toml", 60, |s| {
        s.method = Method::NelderMead;
        s.step = 0.1;
        s.restarts = 1;
    });
    let names = p.spec.metrics();
    let at = |n: &str| names.iter().position(|m| m == n).unwrap();
    let (frac, p05) = (
        at("tcm_singular_fraction_commanded"),
        at("tcm_sigma_min_commanded_p05"),
    );
    let (s, b) = (o.start(), o.best());
    // The start point is the paper's layout: every parameter at its file value.
    assert!(s.score.feasible, "the paper layout's short run succeeds");
    assert!(b.score.feasible, "the best layout meets every constraint");
    for k in 0..p.spec.constraints.len() {
        assert_eq!(o.scorer.constraint_violation(k, &b.metrics[0]), 0.0, "{k}");
    }
    let (sm, bm) = (&s.metrics[0], &b.metrics[0]);
    assert!(
        bm[frac] < sm[frac],
        "singular fraction {} → {}",
        sm[frac],
        bm[frac]
    );
    assert!(bm[p05] > sm[p05], "p05 σ_min {} → {}", sm[p05], bm[p05]);
    assert!(b.score.objective < s.score.objective);
}

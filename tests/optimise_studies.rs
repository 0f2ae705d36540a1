//! The shipped tuning studies, on a reduced budget: from the paper's gains (feasible), the
//! optimiser finds gains that meet every constraint and improve the objective by a margin.
//! The full budgets (docs/optimise.md, 400 evaluations each) reach 2.000 → 1.2732 (transport,
//! Bayesian optimisation) and 2.250 → 0.4932 (work, Bayesian optimisation then a Nelder–Mead
//! polish, at the `work-setpoint` pose within reach), under the hull drag of issue 44; these
//! runs stop early (45 evaluations: 1.339; 61, the polish keeping its half: 0.566).

mod common;

use common::optimise_study;

/// Run `file` with `max_evals` evaluations; returns (start objective, best objective).
fn tuned(file: &str, max_evals: usize) -> (f64, f64) {
    let (p, o) = optimise_study(file, max_evals);
    assert!(
        o.start().score.feasible,
        "{file}: the paper's gains meet the constraints"
    );
    let b = o.best();
    assert!(
        b.score.feasible,
        "{file}: the best point meets every constraint"
    );
    for k in 0..p.spec.constraints.len() {
        assert_eq!(
            o.scorer.constraint_violation(k, &b.metrics[0]),
            0.0,
            "{file}: {k}"
        );
    }
    (o.start().score.objective, b.score.objective)
}

#[test]
fn tuned_transport_gains_beat_table_iii_by_over_a_quarter() {
    // Under the hull drag the paper's gains spend less than under the per-body drag (Method 2
    // converges in 40.8 s, was 71.7 s); Bayesian optimisation's 45 evaluations (12 of them its
    // Latin hypercube) reach 1.339 (−33 %; Nelder–Mead's reached 1.381).
    let (start, best) = tuned("studies/tune_transport.toml", 45);
    assert!((start - 2.0).abs() < 1e-12, "{start}");
    assert!(best < 0.7 * start, "{best}");
}

#[test]
fn tuned_work_gains_beat_the_papers_by_over_a_twentieth() {
    // At the in-reach default pose the paper's gains already keep the base home (drift 2 mm)
    // and spend 144 J. Nelder–Mead crept from there (61 evaluations: 2.035, −10 %; 180:
    // 1.482); Bayesian optimisation's 31 evaluations and a 30-evaluation polish reach 0.566
    // (−75 %; the full 400: 0.4932).
    let (start, best) = tuned("studies/tune_work.toml", 61);
    assert!((start - 2.25).abs() < 1e-12, "{start}");
    assert!(best < 0.3 * start, "{best}");
}

//! The shipped tuning studies, on a reduced budget: from the paper's gains (feasible), the
//! optimiser finds gains that meet every constraint and improve the objective by a margin.
//! The full budgets (docs/optimise.md) reach 2.000 → 1.355 (transport) and 2.250 → 1.482
//! (work, at the `work-setpoint` pose within reach), under the hull drag of issue 44; these
//! runs stop early (45 and 61 evaluations: 1.381 and 2.035).

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
    // Under the per-body drag the same budget reached 1.260 (−37 %); under the hull drag the
    // paper's gains spend less (Method 2 converges in 40.8 s, was 71.7 s), so there is less
    // to gain: 1.381 (−31 %).
    let (start, best) = tuned("studies/tune_transport.toml", 45);
    assert!((start - 2.0).abs() < 1e-12, "{start}");
    assert!(best < 0.75 * start, "{best}");
}

#[test]
fn tuned_work_gains_beat_the_papers_by_over_a_twentieth() {
    // At the in-reach default pose the paper's gains already keep the base home (drift 2 mm)
    // and spend 144 J, so there is less to gain than at the far pose: Nelder–Mead creeps
    // (41 evaluations: 2.187, −3 %; 61: 2.035, −10 %; the full 180: 1.482, −34 %, under the
    // hull drag of issue 44).
    let (start, best) = tuned("studies/tune_work.toml", 61);
    assert!((start - 2.25).abs() < 1e-12, "{start}");
    assert!(best < 0.95 * start, "{best}");
}

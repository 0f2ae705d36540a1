//! Static TCM analysis benchmarks (docs/model.md §6, issue 11 item 3): the pieces of one joint
//! configuration of the `usm-paper` design and whole analyses.
//!
//! Groups:
//! - `static_config`: `kinematics` (forward kinematics and `T(q)`), `svd` (σ of `T_L` by a
//!   general SVD, [`tcm_svd_metrics`], the route before issue 11), `sigma_full` and
//!   `sigma_transport` ([`commanded_sigma`] for all six rows and for transport's five);
//!   `extremes_full` and `extremes_transport` ([`commanded_extremes_with`] from the scaled Gram
//!   matrix: σ_min, σ_max and rank only, the static analysis' route); each iteration takes the
//!   next of 64 seeded configurations; `kinematics_and_sigma_min` is the whole per-configuration
//!   work of σ_min alone (T(q) and the extremes of all six rows);
//! - `static_analyse`: [`analyse`] of 20 000 Sobol configurations on one thread (throughput
//!   in configurations/s), with and without a row sink.
//!
//! A counting allocator checks that [`commanded_sigma`] allocates nothing.
//!
//! Run with `cargo bench --bench static_tcm -- --warm-up-time 1 --measurement-time 3`.
//! Target (issue 11): ≥ 1 M configurations/s/core.

mod common;

use common::ALLOCS;
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::Matrix6xX;
use std::sync::atomic::Ordering;
use usm_study::kinematics::{forward_kinematics, thruster_matrix, KinWorkspace};
use usm_study::metrics::extremes::commanded_extremes_with;
use usm_study::metrics::singularity::{
    commanded_sigma, tcm_svd_metrics, CommandedDofs, ScaledGram, DEFAULT_RANK_REL_TOL,
};
use usm_study::model::presets::usm_paper;
use usm_study::statics::{analyse, StaticSpec};

fn bench_static(c: &mut Criterion) {
    let v = usm_paper();
    let l = v.characteristic_length();
    let qs = common::random_configurations(&v, 11, 64);
    let mut ws = KinWorkspace::new(&v);
    let ts: Vec<Matrix6xX<f64>> = qs
        .iter()
        .map(|q| {
            let mut t = Matrix6xX::zeros(v.n_thrusters());
            forward_kinematics(&v, q, &mut ws);
            thruster_matrix(&v, &ws, &mut t);
            t
        })
        .collect();
    let transport = CommandedDofs::new([true, true, true, false, true, true]);
    let before = ALLOCS.load(Ordering::Relaxed);
    for t in &ts {
        black_box(commanded_sigma(t, l, CommandedDofs::ALL));
        black_box(commanded_sigma(t, l, transport));
        let gram = ScaledGram::new(t, l);
        black_box(commanded_extremes_with(
            &gram,
            t,
            transport,
            DEFAULT_RANK_REL_TOL,
        ));
    }
    let n = ALLOCS.load(Ordering::Relaxed) - before;
    assert_eq!(n, 0, "commanded_sigma allocated {n} times");

    let mut g = c.benchmark_group("static_config");
    let mut t = Matrix6xX::zeros(v.n_thrusters());
    let mut k = 0;
    g.bench_function("kinematics", |b| {
        b.iter(|| {
            k = (k + 1) % qs.len();
            forward_kinematics(&v, &qs[k], &mut ws);
            thruster_matrix(&v, &ws, &mut t);
            black_box(t[(0, 0)])
        })
    });
    g.bench_function("svd", |b| {
        b.iter(|| {
            k = (k + 1) % ts.len();
            black_box(
                tcm_svd_metrics(&ts[k], l, DEFAULT_RANK_REL_TOL)
                    .unwrap()
                    .sigma_min,
            )
        })
    });
    for (name, dofs) in [
        ("sigma_full", CommandedDofs::ALL),
        ("sigma_transport", transport),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                k = (k + 1) % ts.len();
                black_box(commanded_sigma(&ts[k], l, dofs).sigma_min)
            })
        });
    }
    for (name, dofs) in [
        ("extremes_full", CommandedDofs::ALL),
        ("extremes_transport", transport),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                k = (k + 1) % ts.len();
                let gram = ScaledGram::new(&ts[k], l);
                black_box(
                    commanded_extremes_with(&gram, &ts[k], dofs, DEFAULT_RANK_REL_TOL).sigma_min,
                )
            })
        });
    }
    // The baseline's workload (issue 11's 80 k configurations/s): T(q) and its σ_min, one
    // configuration after the other, nothing else.
    g.bench_function("kinematics_and_sigma_min", |b| {
        b.iter(|| {
            k = (k + 1) % qs.len();
            forward_kinematics(&v, &qs[k], &mut ws);
            thruster_matrix(&v, &ws, &mut t);
            let gram = ScaledGram::new(&t, l);
            black_box(
                commanded_extremes_with(&gram, &t, CommandedDofs::ALL, DEFAULT_RANK_REL_TOL)
                    .sigma_min,
            )
        })
    });
    g.finish();

    let mut g = c.benchmark_group("static_analyse");
    let samples = 20_000;
    g.throughput(Throughput::Elements(samples as u64));
    g.sample_size(10);
    let spec = StaticSpec {
        samples,
        worst: 0,
        ..Default::default()
    };
    g.bench_function("no_sink", |b| {
        b.iter(|| {
            let s = analyse(&v, &spec, 1, &mut |_, _, _| Ok(()), &|_| {}).unwrap();
            black_box(s.singular_fraction)
        })
    });
    g.bench_function("sink", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            let s = analyse(
                &v,
                &spec,
                1,
                &mut |_, q, m| {
                    acc += q[0] + m.sigma_min_commanded;
                    Ok(())
                },
                &|_| {},
            )
            .unwrap();
            black_box((s.singular_fraction, acc))
        })
    });
    g.finish();
}

criterion_group!(benches, bench_static);
criterion_main!(benches);

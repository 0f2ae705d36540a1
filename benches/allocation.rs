//! Thrust-allocation benchmarks (SPEC §5): one allocation step per method on a 6×7 T typical of a
//! bent USM (seeded random unit thrust directions, positions within ±1.5 m), with the
//! [`Allocator`] reused across steps as in a closed loop. Each iteration takes the next of 8
//! precomputed (T, τ) pairs, so every solve sees new data. Also compares the Clarabel
//! formulations (slack kept / eliminated) and solver reuse against a rebuild per step.
//!
//! Targets: `qp` median ≤ 30 µs, `pinv` ≤ 2 µs.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{Matrix6xX, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use usm_study::allocation::{AllocSettings, Allocation, Allocator, Formulation, Method};

/// A bent-USM-like T: 7 thrusters with random unit directions and positions in ±1.5 m.
fn bent_t(rng: &mut rand_chacha::ChaCha8Rng) -> Matrix6xX<f64> {
    let mut t = Matrix6xX::zeros(7);
    for j in 0..7 {
        let d = loop {
            let v = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if v.norm() > 0.2 {
                break v.normalize();
            }
        };
        let p = Vector3::new(
            rng.random_range(-1.5..1.5),
            rng.random_range(-1.5..1.5),
            rng.random_range(-1.5..1.5),
        );
        t.fixed_view_mut::<3, 1>(0, j).copy_from(&d);
        t.fixed_view_mut::<3, 1>(3, j).copy_from(&p.cross(&d));
    }
    t
}

fn cases() -> Vec<(Matrix6xX<f64>, Vector6<f64>)> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2024);
    (0..8)
        .map(|_| {
            let t = bent_t(&mut rng);
            let tau = Vector6::from_fn(|i, _| {
                let s = if i < 3 { 30.0 } else { 10.0 };
                rng.random_range(-s..s)
            });
            (t, tau)
        })
        .collect()
}

fn bench_step(c: &mut Criterion, group: &str, id: &str, method: Method, settings: AllocSettings) {
    let cases = cases();
    let mut alloc = Allocator::new(method, 7, &[-40.0; 7], &[40.0; 7], &[1.0; 7], settings)
        .expect("valid bench case");
    let mut out = Allocation::new(7);
    let mut k = 0usize;
    let mut g = c.benchmark_group(group);
    g.bench_function(BenchmarkId::from_parameter(id), |b| {
        b.iter(|| {
            let (t, tau) = &cases[k % cases.len()];
            k += 1;
            alloc
                .allocate_into(t, tau, &mut out)
                .expect("valid bench case");
            std::hint::black_box(&out);
        })
    });
    g.finish();
}

fn methods(c: &mut Criterion) {
    for method in Method::ALL {
        bench_step(
            c,
            "allocate",
            method.name(),
            method,
            AllocSettings::default(),
        );
    }
}

fn formulations(c: &mut Criterion) {
    for method in [Method::Qp, Method::Minimax, Method::Power] {
        for (name, formulation, reuse) in [
            ("eliminated_reuse", Formulation::SlackEliminated, true),
            ("eliminated_rebuild", Formulation::SlackEliminated, false),
            ("kept_reuse", Formulation::SlackKept, true),
            ("kept_rebuild", Formulation::SlackKept, false),
        ] {
            let settings = AllocSettings {
                formulation,
                reuse_solver: reuse,
                ..AllocSettings::default()
            };
            bench_step(c, &format!("formulation_{method}"), name, method, settings);
        }
    }
}

criterion_group!(benches, methods, formulations);
criterion_main!(benches);

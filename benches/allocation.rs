//! Thrust-allocation benchmarks (docs/model.md §5): one allocation step per path on a 6×7 T typical of
//! a bent USM (seeded random unit thrust directions, positions within ±1.5 m), with the
//! [`Allocator`] reused across steps as in a closed loop. Each iteration takes the next of 8
//! precomputed (T, τ) pairs, so every solve sees new data.
//!
//! Groups:
//! - `path`: `qp_interior` (the certified interior shortcut: every case's unconstrained optimum
//!   lies inside ±40 N), `qp_interior_clarabel` (the same cases with the shortcut off, Clarabel
//!   every step), `qp_active` (Clarabel: τ up to 40 N, bounds ±5 N active in every case), `pinv`,
//!   `minimax`, `power` (Clarabel, same cases as `qp_active`);
//! - `formulation_<method>`: the Clarabel formulations (slack kept / eliminated) and solver
//!   reuse against a rebuild per step (shortcut off).
//!
//! Before measuring, every case is checked to take the path its group names, and a counting
//! allocator checks that the `qp_interior` and `pinv` steps allocate nothing (Clarabel's solve
//! may allocate internally; its count is printed).
//!
//! Run with `cargo bench --bench allocation -- --warm-up-time 1 --measurement-time 3`.
//! Target (issue 11): the qp step ≤ 5 µs median in closed loop, where nearly every step takes
//! the interior shortcut.

mod common;

use common::ALLOCS;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::{Matrix6xX, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use std::sync::atomic::Ordering;
use usm_study::allocation::{AllocPath, AllocSettings, Allocation, Allocator, Formulation, Method};

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

/// 8 seeded (T, τ) pairs with forces in ±`force` N and moments in ±`force`/3 N·m.
fn cases(force: f64) -> Vec<(Matrix6xX<f64>, Vector6<f64>)> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2024);
    (0..8)
        .map(|_| {
            let t = bent_t(&mut rng);
            let tau = Vector6::from_fn(|i, _| {
                let s = if i < 3 { force } else { force / 3.0 };
                rng.random_range(-s..s)
            });
            (t, tau)
        })
        .collect()
}

/// One benchmarked configuration: method, bounds (±`bound` N), settings, the cases and the
/// path every case must take (`None`: not checked).
struct Case {
    method: Method,
    bound: f64,
    settings: AllocSettings,
    cases: Vec<(Matrix6xX<f64>, Vector6<f64>)>,
    path: Option<AllocPath>,
}

impl Case {
    fn allocator(&self) -> Allocator {
        let b = self.bound;
        Allocator::new(
            self.method,
            7,
            &[-b; 7],
            &[b; 7],
            &[1.0; 7],
            self.settings.clone(),
        )
        .expect("valid bench case")
    }

    /// Check the path of every case, then count the heap allocations of one more pass
    /// (after a warm-up pass); returns that count.
    fn check(&self, id: &str) -> usize {
        let mut alloc = self.allocator();
        let mut out = Allocation::new(7);
        for (t, tau) in &self.cases {
            alloc
                .allocate_into(t, tau, &mut out)
                .expect("valid bench case");
            if let Some(path) = self.path {
                assert_eq!(out.path, path, "{id}: a case takes another path");
            }
        }
        let before = ALLOCS.load(Ordering::Relaxed);
        for (t, tau) in &self.cases {
            alloc
                .allocate_into(t, tau, &mut out)
                .expect("valid bench case");
        }
        ALLOCS.load(Ordering::Relaxed) - before
    }
}

fn bench_step(c: &mut Criterion, group: &str, id: &str, case: &Case) {
    let mut alloc = case.allocator();
    let mut out = Allocation::new(7);
    let mut k = 0usize;
    let mut g = c.benchmark_group(group);
    g.bench_function(BenchmarkId::from_parameter(id), |b| {
        b.iter(|| {
            let (t, tau) = &case.cases[k % case.cases.len()];
            k += 1;
            alloc
                .allocate_into(t, tau, &mut out)
                .expect("valid bench case");
            std::hint::black_box(&out);
        })
    });
    g.finish();
}

fn paths(c: &mut Criterion) {
    let d = AllocSettings::default;
    let forced = || AllocSettings {
        interior_shortcut: false,
        ..d()
    };
    let interior = |settings, path| Case {
        method: Method::Qp,
        bound: 40.0,
        settings,
        cases: cases(3.0),
        path: Some(path),
    };
    let active = |method, path| Case {
        method,
        bound: 5.0,
        settings: d(),
        cases: cases(40.0),
        path,
    };
    let list = [
        ("qp_interior", interior(d(), AllocPath::Interior)),
        (
            "qp_interior_clarabel",
            interior(forced(), AllocPath::Clarabel),
        ),
        ("qp_active", active(Method::Qp, Some(AllocPath::Clarabel))),
        ("pinv", active(Method::Pinv, Some(AllocPath::Pinv))),
        (
            "minimax",
            active(Method::Minimax, Some(AllocPath::Clarabel)),
        ),
        ("power", active(Method::Power, Some(AllocPath::Clarabel))),
    ];
    for (id, case) in &list {
        let n = case.check(id);
        if matches!(case.path, Some(AllocPath::Interior | AllocPath::Pinv)) {
            assert_eq!(n, 0, "{id}: a step allocated on the heap");
        } else {
            println!(
                "{id}: {n} heap allocations over {} Clarabel steps",
                case.cases.len()
            );
        }
        bench_step(c, "path", id, case);
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
            let case = Case {
                method,
                bound: 40.0,
                settings: AllocSettings {
                    formulation,
                    reuse_solver: reuse,
                    interior_shortcut: false,
                    ..AllocSettings::default()
                },
                cases: cases(30.0),
                path: None,
            };
            bench_step(c, &format!("formulation_{method}"), name, &case);
        }
    }
}

criterion_group!(benches, paths, formulations);
criterion_main!(benches);

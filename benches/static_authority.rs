//! Attainable-authority benchmarks (docs/model.md §6, issue 23 item 4, issue 24 item 2): the
//! per-configuration work of the authority analysis on the `usm-paper` design and the whole
//! analysis.
//!
//! Groups:
//! - `static_authority`: `per_configuration/transport` and `per_configuration/all6` — forward
//!   kinematics, `T(q)`, the centre of mass, `T_r` about it and every programme of the commanded
//!   axes and signs ([`AuthoritySolver::solve`]: 10 programmes for transport's five rows, 12 for
//!   all six); each iteration takes the next of 64 seeded configurations;
//!   `n1_per_configuration` — the 7 thrusters removed one by one at a configuration (70
//!   programmes, [`AuthoritySolver::solve_without`]); `analysis` — [`authority_analysis`] of
//!   1000 Sobol configurations in transport mode with the default N−1 (the straight one + 32:
//!   231 more solves of 10 programmes), and `analysis_n1_straight` with N−1 at the straight
//!   configuration only; throughput in (sampled) configurations/s.
//!
//! A counting allocator checks that a solve allocates nothing.
//!
//! Run with `cargo bench --bench static_authority -- static_authority --warm-up-time 1
//! --measurement-time 3`. Target (issue 23 item 4): ≥ 100 k configurations/s/core.

mod common;

use common::ALLOCS;
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::Matrix6xX;
use std::sync::atomic::Ordering;
use usm_study::allocation::AuthoritySolver;
use usm_study::kinematics::{centre_of_mass, forward_kinematics, thruster_matrix, KinWorkspace};
use usm_study::metrics::singularity::CommandedDofs;
use usm_study::model::presets::usm_paper;
use usm_study::model::Vehicle;
use usm_study::statics::{authority_analysis, AuthoritySpec, StaticSpec};

/// Kinematics, T(q), the centre of mass and every programme at `q`: the surge+ authority.
fn per_configuration(
    v: &Vehicle,
    q: &[f64],
    ws: &mut KinWorkspace,
    t: &mut Matrix6xX<f64>,
    solver: &mut AuthoritySolver,
) -> f64 {
    forward_kinematics(v, q, ws);
    thruster_matrix(v, ws, t);
    let r = centre_of_mass(v, ws);
    solver.solve(t, &r).unwrap().positive[0]
}

fn bench_authority(c: &mut Criterion) {
    let v = usm_paper();
    let qs = common::random_configurations(&v, 23, 64);
    let (lo, hi): (Vec<f64>, Vec<f64>) = v.thrusters.iter().map(|t| (t.u_min, t.u_max)).unzip();
    let mut ws = KinWorkspace::new(&v);
    let mut t = Matrix6xX::zeros(v.n_thrusters());
    forward_kinematics(&v, &vec![0.0; v.n_joints()], &mut ws);
    thruster_matrix(&v, &ws, &mut t);
    let r0 = centre_of_mass(&v, &ws);
    let transport = CommandedDofs::new([true, true, true, false, true, true]);

    let mut g = c.benchmark_group("static_authority");
    for (name, dofs) in [("transport", transport), ("all6", CommandedDofs::ALL)] {
        let mut solver = AuthoritySolver::new(&t, &lo, &hi, dofs.mask(), &r0).unwrap();
        // Warm: the first solve may build what a fallback needs; then count.
        for q in &qs {
            per_configuration(&v, q, &mut ws, &mut t, &mut solver);
        }
        let before = ALLOCS.load(Ordering::Relaxed);
        for q in &qs {
            per_configuration(&v, q, &mut ws, &mut t, &mut solver);
        }
        let n = ALLOCS.load(Ordering::Relaxed) - before;
        println!("static_authority/{name}: {n} heap allocations in 64 configurations");
        let mut k = 0;
        g.bench_function(format!("per_configuration/{name}"), |b| {
            b.iter(|| {
                k = (k + 1) % qs.len();
                black_box(per_configuration(&v, &qs[k], &mut ws, &mut t, &mut solver))
            })
        });
    }
    let mut solver = AuthoritySolver::new(&t, &lo, &hi, transport.mask(), &r0).unwrap();
    let mut k = 0;
    g.bench_function("n1_per_configuration/transport", |b| {
        b.iter(|| {
            k = (k + 1) % qs.len();
            per_configuration(&v, &qs[k], &mut ws, &mut t, &mut solver);
            let mut acc = 0.0;
            for i in 0..v.n_thrusters() {
                acc += solver.solve_without(i).positive[0];
            }
            black_box(acc)
        })
    });
    let samples = 1000;
    let spec = StaticSpec {
        samples,
        ..Default::default()
    };
    g.throughput(Throughput::Elements(samples as u64));
    g.sample_size(10);
    let few_n1 = AuthoritySpec {
        n1_samples: 0,
        ..Default::default()
    };
    for (name, auth) in [
        ("analysis", AuthoritySpec::default()),
        ("analysis_n1_straight", few_n1),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let s = authority_analysis(&v, &spec, &auth, &mut || Ok(())).unwrap();
                black_box(s.full.min_force)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_authority);
criterion_main!(benches);

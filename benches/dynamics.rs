//! Benchmarks of the dynamics core on `usm-paper` (docs/model.md §4): mass matrix (CRBA), bias
//! forces (RNEA), forward and hybrid dynamics by the dense route (CRBA + Cholesky) and by
//! the O(n) route the simulator uses (articulated-body forward dynamics, O(n) hybrid
//! dynamics: its terms and its solve), one RK4 step with full hydrodynamics, and one
//! 50 ms control period advanced by the adaptive Dormand–Prince integrator.
//!
//! Group `whole_run`: a whole closed-loop run of the presets `transport-method1` (140 s,
//! qp allocation) and `work-setpoint` (80 s), as `usm-study simulate` runs them without
//! writing files (scenario parsed and design built once, outside the measurement).
//!
//! Run with `cargo bench --bench dynamics -- --warm-up-time 1 --measurement-time 3`
//! (`-- whole_run` for the whole runs alone; issue 11 target: ≤ 70 ms for the 140 s run).
//! Before measuring, a counting allocator checks that neither a simulator RK4 step nor an
//! adaptive span allocates.

mod common;

use common::ALLOCS;
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::sync::atomic::Ordering;
use usm_study::dynamics::{
    bias, dynamics_terms, forward_dynamics, forward_dynamics_aba, hybrid_dynamics,
    hybrid_dynamics_on, hybrid_terms, mass_matrix, solve_forward, solve_hybrid_on, ActuatorCommand,
    DynOptions, DynWorkspace, Integrator, SimConfig, SimState, Simulator,
};
use usm_study::kinematics::BasePose;
use usm_study::model::presets::usm_paper;
use usm_study::scenario;
use usm_study::spatial::Vec3;

/// A bent, moving state of the paper's USM in a current.
fn state() -> (BasePose, Vec<f64>, Vec<f64>) {
    let pose = BasePose {
        orientation: nalgebra::UnitQuaternion::from_euler_angles(0.1, -0.2, 0.7),
        position: Vec3::new(1.0, 2.0, -3.0),
    };
    let q: Vec<f64> = (0..8).map(|k| 0.3 * ((k as f64) * 1.3).sin()).collect();
    let zeta: Vec<f64> = (0..14).map(|k| 0.2 * ((k as f64) * 0.7).cos()).collect();
    (pose, q, zeta)
}

fn bench_dynamics(c: &mut Criterion) {
    let mut v = usm_paper();
    v.fluid.current = Vec3::new(0.2, 0.1, 0.0);
    let opts = DynOptions::full();
    let (pose, q, zeta) = state();
    let mut ws = DynWorkspace::new(&v);
    let tau: Vec<f64> = (0..14).map(|k| k as f64 - 6.0).collect();
    let qdd: Vec<f64> = (0..8).map(|k| 0.1 * k as f64).collect();

    // One-off allocation check of a full RK4 step (after a warm-up step).
    let rk4 = SimConfig {
        integrator: Integrator::Rk4 { dt: 1e-3 },
        ..SimConfig::default()
    };
    let mut sim = Simulator::new(&v, rk4).unwrap();
    let mut adaptive = Simulator::new(&v, SimConfig::default()).unwrap();
    let mut st = SimState::rest(&v);
    st.pose = pose;
    st.joint_angles = q.clone();
    st.set_zeta(&zeta);
    sim.set_state(st.clone()).unwrap();
    adaptive.set_state(st).unwrap();
    let thrust = [5.0, -3.0, 10.0, 10.0, 2.0, -1.0, 4.0];
    let qr: Vec<f64> = q.iter().map(|x| 0.9 * x).collect();
    let qdr = vec![0.0; 8];
    let cmd = ActuatorCommand {
        thrust: &thrust,
        joint_ref: &qr,
        joint_rate_ref: &qdr,
    };
    sim.step(1e-3, &cmd).unwrap();
    let before = ALLOCS.load(Ordering::Relaxed);
    for _ in 0..100 {
        sim.step(1e-3, &cmd).unwrap();
    }
    let allocs = ALLOCS.load(Ordering::Relaxed) - before;
    println!("heap allocations in 100 RK4 steps: {allocs}");
    assert_eq!(allocs, 0, "Simulator::step must not allocate");
    adaptive.advance(0.05, &cmd).unwrap();
    let before = ALLOCS.load(Ordering::Relaxed);
    for _ in 0..20 {
        adaptive.advance(0.05, &cmd).unwrap();
    }
    let allocs = ALLOCS.load(Ordering::Relaxed) - before;
    let stats = adaptive.step_stats();
    println!(
        "heap allocations in 20 Dormand-Prince spans of 50 ms: {allocs} ({} steps, {} rejected, {} evaluations in all)",
        stats.steps, stats.rejected, stats.evaluations
    );
    assert_eq!(allocs, 0, "Simulator::advance must not allocate");

    c.bench_function("mass_matrix", |b| {
        b.iter(|| mass_matrix(&v, &mut ws, black_box(&q), &opts))
    });
    c.bench_function("bias_full_hydro", |b| {
        b.iter(|| bias(&v, &mut ws, &pose, black_box(&q), black_box(&zeta), &opts))
    });
    c.bench_function("dynamics_terms", |b| {
        b.iter(|| dynamics_terms(&v, &mut ws, &pose, black_box(&q), black_box(&zeta), &opts))
    });
    c.bench_function("forward_dynamics", |b| {
        b.iter(|| {
            forward_dynamics(
                &v,
                &mut ws,
                &pose,
                black_box(&q),
                black_box(&zeta),
                &tau,
                &opts,
            )
            .unwrap()
        })
    });
    dynamics_terms(&v, &mut ws, &pose, &q, &zeta, &opts);
    c.bench_function("solve_forward_cholesky", |b| {
        b.iter(|| solve_forward(&mut ws, black_box(&tau)).unwrap())
    });
    c.bench_function("hybrid_dynamics", |b| {
        b.iter(|| {
            hybrid_dynamics(&v, &mut ws, &pose, black_box(&q), &zeta, &tau, &qdd, &opts).unwrap()
        })
    });
    c.bench_function("forward_dynamics_aba", |b| {
        b.iter(|| {
            forward_dynamics_aba(
                &v,
                &mut ws,
                &pose,
                black_box(&q),
                black_box(&zeta),
                &tau,
                &opts,
            )
            .unwrap()
        })
    });
    c.bench_function("hybrid_terms_on", |b| {
        b.iter(|| hybrid_terms(&v, &mut ws, &pose, black_box(&q), black_box(&zeta), &opts))
    });
    hybrid_terms(&v, &mut ws, &pose, &q, &zeta, &opts);
    c.bench_function("solve_hybrid_on", |b| {
        b.iter(|| solve_hybrid_on(&mut ws, black_box(&tau), &qdd).unwrap())
    });
    c.bench_function("hybrid_dynamics_on", |b| {
        b.iter(|| {
            hybrid_dynamics_on(&v, &mut ws, &pose, black_box(&q), &zeta, &tau, &qdd, &opts).unwrap()
        })
    });
    c.bench_function("rk4_step_full_hydro", |b| {
        b.iter(|| sim.step(1e-3, black_box(&cmd)).unwrap())
    });
    c.bench_function("dopri5_control_period_50ms", |b| {
        b.iter(|| adaptive.advance(0.05, black_box(&cmd)).unwrap())
    });
}

/// Scaling: the dense and the O(n) routes on the generated 9-link design (17 bodies, 16
/// joints, 22 DOF), full hydrodynamics with current.
fn bench_scaling(c: &mut Criterion) {
    let spec = usm_study::model::generator::GeneratorSpec {
        links: 9,
        ..Default::default()
    };
    let mut v = spec.build("gen9").unwrap();
    v.fluid.current = Vec3::new(0.2, 0.1, 0.0);
    let opts = DynOptions::full();
    let n = v.n_joints();
    let pose = state().0;
    let q: Vec<f64> = (0..n).map(|k| 0.3 * ((k as f64) * 1.3).sin()).collect();
    let zeta: Vec<f64> = (0..6 + n).map(|k| 0.2 * ((k as f64) * 0.7).cos()).collect();
    let tau: Vec<f64> = (0..6 + n).map(|k| k as f64 - 6.0).collect();
    let qdd: Vec<f64> = (0..n).map(|k| 0.1 * k as f64).collect();
    let mut ws = DynWorkspace::new(&v);
    let mut g = c.benchmark_group("gen9");
    g.bench_function("forward_dynamics", |b| {
        b.iter(|| forward_dynamics(&v, &mut ws, &pose, black_box(&q), &zeta, &tau, &opts).unwrap())
    });
    g.bench_function("forward_dynamics_aba", |b| {
        b.iter(|| {
            forward_dynamics_aba(&v, &mut ws, &pose, black_box(&q), &zeta, &tau, &opts).unwrap()
        })
    });
    g.bench_function("hybrid_dynamics", |b| {
        b.iter(|| {
            hybrid_dynamics(&v, &mut ws, &pose, black_box(&q), &zeta, &tau, &qdd, &opts).unwrap()
        })
    });
    g.bench_function("hybrid_dynamics_on", |b| {
        b.iter(|| {
            hybrid_dynamics_on(&v, &mut ws, &pose, black_box(&q), &zeta, &tau, &qdd, &opts).unwrap()
        })
    });
    g.finish();
}

fn bench_whole_run(c: &mut Criterion) {
    let mut g = c.benchmark_group("whole_run");
    g.sample_size(10);
    for preset in ["transport-method1", "work-setpoint"] {
        let (table, src) = scenario::load_table(preset).unwrap();
        let file = scenario::parse_table(&table, &src).unwrap();
        let v = scenario::resolve_design(&file, &src).unwrap();
        g.bench_function(preset, |b| {
            b.iter(|| {
                let r = usm_study::outcome::run_scenario(&v, black_box(&file)).unwrap();
                assert!(r.failure.is_none(), "{preset}: {:?}", r.failure);
                black_box(r)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_dynamics, bench_scaling, bench_whole_run);
criterion_main!(benches);

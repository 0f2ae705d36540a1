//! Tests of the allocation module: input validation, KKT conditions of every constrained form,
//! pinv/QP equivalence, slack behaviour, method orderings, singular T, property tests.

#![allow(clippy::needless_range_loop)]

use super::*;
use nalgebra::Vector3;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};

const TOL: f64 = 1e-6;

/// A bent USM-like T: 7 thrusters with seeded random unit directions and positions in ±1.5 m.
pub(crate) fn bent_t(seed: u64) -> Matrix6xX<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
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

/// A straight USM: 7 thrusters on the body x axis, roll row of T identically zero (rank 5).
pub(crate) fn straight_t() -> Matrix6xX<f64> {
    let dirs = [
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
        [0.6, 0.0, 0.8],
    ];
    let xs = [0.2, 1.8, 0.4, 1.6, 0.6, 1.4, 1.0];
    let mut t = Matrix6xX::zeros(7);
    for j in 0..7 {
        let d = Vector3::from(dirs[j]);
        let p = Vector3::new(xs[j], 0.0, 0.0);
        t.fixed_view_mut::<3, 1>(0, j).copy_from(&d);
        t.fixed_view_mut::<3, 1>(3, j).copy_from(&p.cross(&d));
    }
    t
}

fn tau(v: [f64; 6]) -> Vector6<f64> {
    Vector6::from(v)
}

fn run(
    method: Method,
    t: &Matrix6xX<f64>,
    tau: &Vector6<f64>,
    lo: f64,
    hi: f64,
    settings: AllocSettings,
) -> (Allocation, Allocator) {
    let n_thrusters = t.ncols();
    let mut a = Allocator::new(
        method,
        n_thrusters,
        &vec![lo; n_thrusters],
        &vec![hi; n_thrusters],
        &vec![1.0; n_thrusters],
        settings,
    )
    .expect("valid input");
    let r = a.allocate(t, tau).expect("valid input");
    (r, a)
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= TOL * scale.max(1.0)
}

/// Check the KKT conditions of the original (slack-kept, ½-free) problem at the returned `u`,
/// with the multipliers taken from Clarabel's dual `z` (valid for both formulations).
/// A `qp` result of the interior shortcut is checked with zero bound multipliers instead.
fn check_kkt(a: &Allocator, r: &Allocation, t: &Matrix6xX<f64>, u_prev: &[f64]) {
    if r.path == AllocPath::Interior {
        return check_kkt_interior(a, r, t, u_prev);
    }
    let conic = a.conic().expect("constrained method");
    let l = conic.layout();
    let sol = conic.solution().expect("solved");
    let z = &sol.z;
    let x = &sol.x;
    let n_thrusters = l.n_thrusters;
    let st = a.settings();
    let (lo, hi) = a.effective_bounds();
    let (lo, hi) = (lo.to_vec(), hi.to_vec());
    let rate_w = st
        .rate
        .as_ref()
        .map(|r| r.weights.clone())
        .unwrap_or(vec![0.0; n_thrusters]);
    let ts = t.transpose() * r.s;
    // Global scale, as Clarabel normalises its residuals: max(1, ‖x‖∞, ‖z‖∞, |objective|).
    let big = x
        .iter()
        .chain(z.iter())
        .fold(r.objective.abs().max(1.0), |a, v| a.max(v.abs()));
    // The slack-eliminated form drops the constant q‖τ‖² from Clarabel's objective, so its
    // relative gap tolerance is loose in absolute terms (cancellation): it meets the KKT
    // conditions only to ~1e-4. The default slack-kept form meets them to 1e-6.
    let tol = match st.formulation {
        Formulation::SlackKept => TOL * big,
        Formulation::SlackEliminated => 1e-3 * big,
    };
    let tag = format!(
        "{} {:?} reuse={}",
        a.method(),
        st.formulation,
        st.reuse_solver
    );
    // slack stationarity (kept form): 2 q s − ν = 0
    if let Some(s0) = l.s0 {
        for i in 0..6 {
            assert!(
                (2.0 * st.q * x[s0 + i] - z[i]).abs() <= tol,
                "s-stationarity"
            );
        }
    }
    let mut sum_ab = 0.0;
    for j in 0..n_thrusters {
        let mu_up = z[l.r_box + j];
        let mu_lo = z[l.r_box + n_thrusters + j];
        assert!(
            mu_up >= -TOL && mu_lo >= -TOL,
            "dual feasibility {mu_up} {mu_lo}"
        );
        // bounds (primal feasibility) and complementarity
        assert!(r.u[j] >= lo[j] - 1e-12 && r.u[j] <= hi[j] + 1e-12);
        let ctol = tol;
        assert!(
            mu_up * (hi[j] - r.u[j]) <= ctol,
            "{tag} compl up {j}: {mu_up} {}",
            hi[j] - r.u[j]
        );
        assert!(
            mu_lo * (r.u[j] - lo[j]) <= ctol,
            "{tag} compl lo {j}: {mu_lo} {}",
            r.u[j] - lo[j]
        );
        let rate = 2.0 * rate_w[j] * (r.u[j] - u_prev[j]);
        let slack = 2.0 * st.q * ts[j];
        let (obj, extra) = match a.method() {
            Method::Qp => (2.0 * a.w[j] * r.u[j], 0.0),
            Method::Minimax => {
                let al = z[l.r_mm + j];
                let be = z[l.r_mm + n_thrusters + j];
                assert!(al >= -TOL && be >= -TOL);
                let tt = x[l.t0];
                assert!(
                    al * (tt - r.u[j]) <= ctol && be * (tt + r.u[j]) <= ctol,
                    "compl mm"
                );
                sum_ab += al + be;
                (2.0 * st.eps * r.u[j], al - be)
            }
            Method::Power => {
                // Derivative of w|u|^{3/2}; cross-check against the power-cone dual.
                let d = 1.5 * a.w[j] * r.u[j].signum() * r.u[j].abs().sqrt();
                let zc = &z[l.r_pow + 3 * j..l.r_pow + 3 * j + 3];
                // Conic stationarity: w_j − z0 = 0 (t_j) and z2 = −d (u_j, as A has −1 there).
                assert!((zc[0] - a.w[j]).abs() <= tol, "{tag} t-stationarity {zc:?}");
                assert!((zc[2] + d).abs() <= tol, "{tag} power dual {zc:?} vs {d}");
                (d, 0.0)
            }
            Method::Pinv => unreachable!(),
        };
        let res = obj + rate + slack + mu_up - mu_lo + extra;
        assert!(
            res.abs() <= tol,
            "{tag} stationarity {j}: res {res} (scale {big})"
        );
    }
    if a.method() == Method::Minimax {
        assert!(
            (sum_ab - 1.0).abs() <= tol,
            "{tag} t-stationarity minimax: {sum_ab}"
        );
        let umax = r.max_abs_u();
        assert!((x[l.t0] - umax).abs() <= tol, "{tag} t = max|u|");
    }
}

/// KKT of the `qp` problem at an interior-shortcut result: bounds hold, and stationarity
/// `2Wu + 2R(u − u_prev) + 2q Tᵀs = 0` holds with zero bound multipliers (relative to the
/// largest term).
fn check_kkt_interior(a: &Allocator, r: &Allocation, t: &Matrix6xX<f64>, u_prev: &[f64]) {
    assert_eq!(a.method(), Method::Qp);
    let st = a.settings();
    let (lo, hi) = a.effective_bounds();
    let rate_w = st.rate.as_ref().map(|r| r.weights.clone());
    let ts = t.transpose() * r.s;
    for j in 0..r.u.len() {
        assert!(
            lo[j] <= r.u[j] && r.u[j] <= hi[j],
            "interior path outside the bounds"
        );
        let rw = rate_w.as_ref().map_or(0.0, |w| w[j]);
        let terms = [
            2.0 * a.w[j] * r.u[j],
            2.0 * rw * (r.u[j] - u_prev[j]),
            2.0 * st.q * ts[j],
        ];
        let scale = terms.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        let res: f64 = terms.iter().sum();
        assert!(
            res.abs() <= 1e-9 * scale,
            "interior stationarity {j}: {res}"
        );
    }
}

/// Default settings with a tight Clarabel tolerance, for the KKT checks.
fn tight() -> AllocSettings {
    AllocSettings {
        tol: 1e-10,
        ..AllocSettings::default()
    }
}

/// The default (interior shortcut on), then Clarabel forced in every formulation.
fn all_formulations() -> [AllocSettings; 4] {
    [
        tight(),
        AllocSettings {
            interior_shortcut: false,
            ..tight()
        },
        AllocSettings {
            formulation: Formulation::SlackEliminated,
            interior_shortcut: false,
            ..tight()
        },
        AllocSettings {
            reuse_solver: false,
            interior_shortcut: false,
            ..tight()
        },
    ]
}

#[test]
fn method_names_roundtrip() {
    for method in Method::ALL {
        assert_eq!(method.to_string().parse::<Method>().unwrap(), method);
        let j = serde_json::to_string(&method).unwrap();
        assert_eq!(j, format!("\"{method}\""));
        assert_eq!(serde_json::from_str::<Method>(&j).unwrap(), method);
    }
    assert!("lsq".parse::<Method>().is_err());
    assert_eq!("QP".parse::<Method>().unwrap(), Method::Qp);
}

#[test]
fn bad_input_is_a_typed_error_naming_the_argument() {
    let t = bent_t(1);
    let ok = vec![1.0; 7];
    let e = Allocator::new(
        Method::Qp,
        7,
        &[-1.0; 6],
        &ok,
        &ok,
        AllocSettings::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("u_min"), "{e}");
    let mut lo = vec![-1.0; 7];
    lo[3] = 2.0;
    let e = Allocator::new(Method::Qp, 7, &lo, &ok, &ok, AllocSettings::default()).unwrap_err();
    assert_eq!(
        e,
        AllocError::BoundsOrder {
            index: 3,
            min: 2.0,
            max: 1.0
        }
    );
    assert!(e.to_string().contains("u_min[3]"), "{e}");
    let mut w = ok.clone();
    w[5] = 0.0;
    let e = Allocator::new(
        Method::Pinv,
        7,
        &[-1.0; 7],
        &ok,
        &w,
        AllocSettings::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("weights[5]"), "{e}");
    let mut up = ok.clone();
    up[2] = f64::NAN;
    let e = Allocator::new(
        Method::Qp,
        7,
        &[-1.0; 7],
        &up,
        &ok,
        AllocSettings::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("u_max[2]"), "{e}");

    let mut a = Allocator::new(
        Method::Qp,
        7,
        &[-1.0; 7],
        &ok,
        &ok,
        AllocSettings::default(),
    )
    .unwrap();
    let mut bad_t = t.clone();
    bad_t[(4, 2)] = f64::INFINITY;
    let e = a.allocate(&bad_t, &Vector6::zeros()).unwrap_err();
    assert!(e.to_string().contains("T[4][2]"), "{e}");
    let e = a.allocate(&bent_t(1).columns(0, 6).into_owned(), &Vector6::zeros());
    assert!(matches!(e, Err(AllocError::Dimension { arg: "T", .. })));
    let mut bad_tau = Vector6::zeros();
    bad_tau[1] = f64::NAN;
    let e = a.allocate(&t, &bad_tau).unwrap_err();
    assert!(e.to_string().contains("tau[1]"), "{e}");
    let s = AllocSettings {
        q: -1.0,
        ..AllocSettings::default()
    };
    assert!(Allocator::new(Method::Qp, 7, &[-1.0; 7], &ok, &ok, s).is_err());
}

#[test]
fn pinv_equals_qp_without_active_bounds() {
    // qp with s eliminated is min uᵀWu + q‖Tu − τ‖²; dividing by q, it is the damped LS problem
    // whose solution is Tᵀ(TTᵀ + λ²I)⁻¹τ with λ² = 1/q (W = I).
    for seed in 0..5 {
        let t = bent_t(seed);
        let tau = tau([10.0, -5.0, 3.0, 2.0, -1.0, 4.0]);
        for q in [1e2, 1e4] {
            let s = AllocSettings {
                q,
                lambda: (1.0 / q).sqrt(),
                ..AllocSettings::default()
            };
            let (p, _) = run(Method::Pinv, &t, &tau, -1e3, 1e3, s.clone());
            for s in [
                s.clone(),
                AllocSettings {
                    formulation: Formulation::SlackEliminated,
                    ..s.clone()
                },
            ] {
                let (qp, _) = run(Method::Qp, &t, &tau, -1e3, 1e3, s);
                assert_eq!(qp.status.label(), p.status.label());
                for j in 0..7 {
                    assert!(
                        close(p.u[j], qp.u[j], p.u[j].abs()),
                        "{:?} vs {:?}",
                        p.u,
                        qp.u
                    );
                }
                assert!(close(p.objective, qp.objective, p.objective));
            }
        }
    }
}

#[test]
fn pinv_matches_closed_form_with_weights() {
    let t = bent_t(3);
    let tau = tau([1.0, 2.0, 3.0, 0.5, -0.5, 1.0]);
    let w = [1.0, 2.0, 0.5, 1.0, 3.0, 1.0, 1.0];
    let u = damped_pinv(&t, &tau, &w, 0.1).unwrap();
    let winv = nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        7,
        w.iter().map(|x| 1.0 / x),
    ));
    let td = nalgebra::DMatrix::from_column_slice(6, 7, t.as_slice());
    let a = &td * &winv * td.transpose() + nalgebra::DMatrix::identity(6, 6) * 0.01;
    let y = a
        .lu()
        .solve(&nalgebra::DVector::from_column_slice(tau.as_slice()))
        .unwrap();
    let want = &winv * td.transpose() * y;
    for j in 0..7 {
        assert!((u[j] - want[j]).abs() < 1e-10);
    }
}

#[test]
fn pinv_reports_bound_violation() {
    let t = bent_t(2);
    let (r, _) = run(
        Method::Pinv,
        &t,
        &tau([200.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        -5.0,
        5.0,
        AllocSettings::default(),
    );
    assert!(
        matches!(r.status, AllocStatus::BoundsViolated { .. }),
        "{r:?}"
    );
    assert!(r.max_abs_u() > 5.0);
}

#[test]
fn kkt_of_every_constrained_form() {
    for seed in [0, 7, 11] {
        let t = bent_t(seed);
        // A moderately large τ so that some bounds are active.
        for tau in [
            tau([30.0, -20.0, 10.0, 5.0, -8.0, 6.0]),
            tau([3.0, -2.0, 1.0, 0.5, -0.8, 0.6]),
        ] {
            for method in [Method::Qp, Method::Minimax, Method::Power] {
                for s in all_formulations() {
                    let (r, a) = run(method, &t, &tau, -15.0, 12.0, s);
                    assert!(r.status.is_ok(), "{method} {r:?}");
                    check_kkt(&a, &r, &t, &[0.0; 7]);
                }
            }
        }
    }
}

#[test]
fn kkt_with_rate_terms() {
    let t = bent_t(5);
    let rate = RateSettings {
        weights: vec![2.0; 7],
        max_step: vec![3.0; 7],
    };
    let u_prev = [1.0, -2.0, 0.5, 4.0, 0.0, -1.0, 2.0];
    for method in [Method::Qp, Method::Minimax, Method::Power] {
        for f in [Formulation::SlackEliminated, Formulation::SlackKept] {
            let s = AllocSettings {
                rate: Some(rate.clone()),
                formulation: f,
                ..tight()
            };
            let mut a = Allocator::new(method, 7, &[-10.0; 7], &[10.0; 7], &[1.0; 7], s).unwrap();
            a.set_u_prev(&u_prev).unwrap();
            let r = a
                .allocate(&t, &tau([20.0, 5.0, -4.0, 2.0, 1.0, -3.0]))
                .unwrap();
            for j in 0..7 {
                assert!((r.u[j] - u_prev[j]).abs() <= 3.0 + 1e-12, "rate limit");
                assert!(r.u[j].abs() <= 10.0);
            }
            check_kkt(&a, &r, &t, &u_prev);
            // u_prev advances to the new output
            assert_eq!(a.u_prev(), &r.u[..]);
        }
    }
}

#[test]
fn unattainable_tau_gives_bounded_u_and_active_slack() {
    let t = bent_t(4);
    let tau = tau([500.0, 300.0, -200.0, 100.0, 50.0, -80.0]);
    for method in [Method::Qp, Method::Minimax, Method::Power] {
        for s in all_formulations() {
            let (r, a) = run(method, &t, &tau, -40.0, 40.0, s);
            assert!(
                matches!(r.status, AllocStatus::SlackActive { .. }),
                "{method}: {r:?}"
            );
            assert!(r.u.iter().all(|u| u.abs() <= 40.0));
            assert!(r.s.norm() > 1.0);
            check_kkt(&a, &r, &t, &[0.0; 7]);
        }
    }
}

#[test]
fn minimax_and_power_beat_qp_on_their_own_criteria() {
    let p32 = |r: &Allocation| r.u.iter().map(|u| u.abs().powf(1.5)).sum::<f64>();
    for seed in 0..6 {
        let t = bent_t(seed);
        let tau = tau([20.0, -10.0, 5.0, 3.0, -4.0, 2.0]);
        // (a) Optimality in each method's own objective (exact statement, any q): the minimax /
        // power solution scores no worse than the QP solution in the minimax / power objective.
        let d = AllocSettings::default();
        let (qp, _) = run(Method::Qp, &t, &tau, -40.0, 40.0, d.clone());
        let (mm, _) = run(Method::Minimax, &t, &tau, -40.0, 40.0, d.clone());
        let (pw, _) = run(Method::Power, &t, &tau, -40.0, 40.0, d.clone());
        let qs = d.q * qp.s.norm_squared();
        let uu: f64 = qp.u.iter().map(|u| u * u).sum();
        assert!(mm.objective <= qp.max_abs_u() + qs + d.eps * uu + 1e-6 * mm.objective);
        assert!(pw.objective <= p32(&qp) + qs + 1e-6 * pw.objective);
        // (b) The raw criteria, with the slack made negligible (large q) so the three methods
        // produce (nearly) the same wrench.
        let s = AllocSettings {
            q: 1e8,
            ..AllocSettings::default()
        };
        let (qp, _) = run(Method::Qp, &t, &tau, -40.0, 40.0, s.clone());
        let (mm, _) = run(Method::Minimax, &t, &tau, -40.0, 40.0, s.clone());
        let (pw, _) = run(Method::Power, &t, &tau, -40.0, 40.0, s);
        assert!(mm.max_abs_u() <= qp.max_abs_u() + 1e-4, "{mm:?} {qp:?}");
        assert!(
            p32(&pw) <= p32(&qp) + 1e-4 * p32(&qp),
            "{} {}",
            p32(&pw),
            p32(&qp)
        );
    }
}

#[test]
fn singular_t_is_handled_by_every_method() {
    let t = straight_t();
    // Roll is unattainable (zero roll row); the rest is attainable.
    let with_roll = tau([10.0, 5.0, -3.0, 4.0, 2.0, -1.0]);
    let without_roll = tau([10.0, 5.0, -3.0, 0.0, 2.0, -1.0]);
    for method in Method::ALL {
        for s in all_formulations() {
            let (r, a) = run(method, &t, &with_roll, -40.0, 40.0, s.clone());
            assert!(
                matches!(r.status, AllocStatus::SlackActive { .. }),
                "{method}: {r:?}"
            );
            assert!(
                (r.s[3] + 4.0).abs() < 1e-6,
                "roll slack = −τ_roll: {:?}",
                r.s
            );
            if method != Method::Pinv {
                check_kkt(&a, &r, &t, &[0.0; 7]);
                let (r, _) = run(method, &t, &without_roll, -40.0, 40.0, s);
                assert_eq!(r.status, AllocStatus::Solved, "{method}: {r:?}");
            }
        }
    }
}

#[test]
fn reuse_matches_rebuild_over_a_sequence() {
    // Closed-loop-like use: T and τ change every step; results must not depend on reuse or
    // formulation.
    for method in [Method::Qp, Method::Minimax, Method::Power] {
        let mut allocs: Vec<Allocator> = all_formulations()
            .into_iter()
            .map(|s| Allocator::new(method, 7, &[-20.0; 7], &[20.0; 7], &[1.0; 7], s).unwrap())
            .collect();
        for step in 0..8u64 {
            let t = bent_t(100 + step);
            let k = step as f64;
            let tau = tau([10.0 + k, -3.0 * k, 2.0, 1.0, -0.5 * k, 3.0]);
            let rs: Vec<Allocation> = allocs
                .iter_mut()
                .map(|a| a.allocate(&t, &tau).unwrap())
                .collect();
            for r in &rs[1..] {
                for j in 0..7 {
                    assert!(
                        // Interior-point accuracy (relative gap 1e-8 with q = 1e4).
                        (r.u[j] - rs[0].u[j]).abs() < 1e-4 * (1.0 + rs[0].u[j].abs()),
                        "{method} step {step}: {:?} vs {:?}",
                        r.u,
                        rs[0].u
                    );
                }
            }
        }
        assert!(allocs.iter().all(|a| a.failures() == 0));
    }
}

#[test]
fn solver_failure_falls_back_to_clipped_pinv() {
    let t = bent_t(9);
    let tau = tau([30.0, -20.0, 10.0, 5.0, -8.0, 6.0]);
    for fallback in [true, false] {
        let s = AllocSettings {
            fallback,
            ..AllocSettings::default()
        };
        let mut a = Allocator::new(Method::Qp, 7, &[-10.0; 7], &[10.0; 7], &[1.0; 7], s).unwrap();
        a.conic_mut().unwrap().set_max_iter(1);
        let r = a.allocate(&t, &tau).unwrap();
        assert_eq!(
            r.status,
            AllocStatus::SolverFailed {
                solver_status: "MaxIterations",
                fallback
            }
        );
        assert_eq!(a.failures(), 1);
        assert!(r.u.iter().all(|u| u.abs() <= 10.0));
        if fallback {
            let p = damped_pinv(&t, &tau, &[1.0; 7], 0.1).unwrap();
            for j in 0..7 {
                assert!((r.u[j] - p[j].clamp(-10.0, 10.0)).abs() < 1e-12);
            }
        } else {
            assert!(r.u.iter().all(|&u| u == 0.0));
        }
    }
}

#[test]
fn allocate_into_reuses_the_output_buffer() {
    let t = bent_t(1);
    let mut a = Allocator::new(
        Method::Qp,
        7,
        &[-40.0; 7],
        &[40.0; 7],
        &[1.0; 7],
        Default::default(),
    )
    .unwrap();
    let mut out = Allocation::new(7);
    let ptr = out.u.as_ptr();
    for k in 0..3 {
        a.allocate_into(&t, &tau([k as f64, 1.0, 0.0, 0.0, 0.0, 0.0]), &mut out)
            .unwrap();
        assert_eq!(out.u.as_ptr(), ptr);
    }
    assert_eq!(a.steps(), 3);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn prop_no_panic_and_bounds_respected(
        n_thrusters in 1usize..10,
        tvals in proptest::collection::vec(-2.0f64..2.0, 60),
        tauv in proptest::collection::vec(-60.0f64..60.0, 6),
        lov in proptest::collection::vec(-40.0f64..5.0, 10),
        width in proptest::collection::vec(0.0f64..50.0, 10),
        zero_col in proptest::option::of(0usize..10),
    ) {
        let mut t = Matrix6xX::from_iterator(n_thrusters, tvals.iter().copied().take(6 * n_thrusters));
        if let Some(c) = zero_col {
            if c < n_thrusters {
                t.column_mut(c).fill(0.0);
            }
        }
        let tau = Vector6::from_iterator(tauv.iter().copied());
        let lo: Vec<f64> = lov[..n_thrusters].to_vec();
        let hi: Vec<f64> = lo.iter().zip(&width).map(|(l, w)| l + w).collect();
        for method in Method::ALL {
            let r = allocate(method, &t, &tau, &lo, &hi, &vec![1.0; n_thrusters], AllocSettings::default())
                .unwrap();
            prop_assert!(r.u.iter().all(|u| u.is_finite()));
            prop_assert!(r.objective.is_finite());
            if method != Method::Pinv {
                for j in 0..n_thrusters {
                    prop_assert!(r.u[j] >= lo[j] && r.u[j] <= hi[j], "{} {:?}", method, r);
                }
            }
        }
    }
}

/// Thruster-matrix entries beyond 1e150 (whose Gram matrix overflows: 1e200² = inf) are
/// refused naming the entry; a Gram matrix that overflows through extreme weights on allowed
/// entries gives NaN thrusts (no meaningful solution), never an SVD on infinite data (nalgebra's
/// panics on some of it: `Singular value was NaN`, found by tests/fuzz.rs with T entries of
/// ±1e308) and never an endless loop.
#[test]
fn pinv_on_an_overflowing_gram_matrix_terminates() {
    let mut t = Matrix6xX::<f64>::zeros(3);
    t[(0, 0)] = 1e200;
    t[(1, 1)] = 1.0;
    t[(2, 2)] = 1.0;
    let e = damped_pinv(&t, &tau([1.0, 2.0, 3.0, 0.0, 0.0, 0.0]), &[1.0; 3], 0.0).unwrap_err();
    assert!(
        e.to_string().contains("`T[0][0]` = 1e200 exceeds 1e150"),
        "{e}"
    );
    t[(0, 0)] = 1e60;
    t[(5, 0)] = -1e60;
    let u = damped_pinv(&t, &tau([1.0, 2.0, 3.0, 0.0, 0.0, 0.0]), &[1e-200; 3], 0.0).unwrap();
    assert!(u.iter().all(|x| x.is_nan()), "{u:?}");
}

//! The span integrators of [`Simulator::advance`]: Dormand–Prince 5(4) against a closed-form
//! solution and the conservation laws, RK4 spans against single steps, the joint work.

use super::*;

/// A simulator of `v` with ideal critically damped servos (ω_n = 4 rad/s) and `integrator`.
fn servo_sim(v: &Vehicle, options: DynOptions, integrator: Integrator) -> Simulator {
    Simulator::new(
        v,
        SimConfig {
            options,
            servo: ServoModel::SecondOrder {
                omega_n: 4.0,
                zeta: 1.0,
            },
            integrator,
            ..SimConfig::default()
        },
    )
    .unwrap()
}

/// Largest error of the joint angles against the closed form of the critically damped
/// servo from rest, `q(t) = q_r (1 − (1 + ωt) e^{−ωt})`, over 1.5 s of 0.5 s spans, and
/// the accepted steps taken.
fn servo_error(rtol: f64, atol: f64) -> (f64, u64) {
    let v = usm_paper();
    let integ = Integrator::Dopri5 {
        rtol,
        atol,
        first_step: 0.01,
    };
    let mut sim = servo_sim(&v, DynOptions::full(), integ);
    let qr: Vec<f64> = (0..8).map(|k| 0.1 * (k as f64 - 3.5)).collect();
    let zero = vec![0.0; 8];
    let u = vec![0.0; 7];
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &qr,
        joint_rate_ref: &zero,
    };
    let w = 4.0;
    let mut err = 0.0f64;
    for _ in 0..3 {
        sim.advance(0.5, &cmd).unwrap();
        let t = sim.time();
        for (k, qr_k) in qr.iter().enumerate() {
            let expect = qr_k * (1.0 - (1.0 + w * t) * (-w * t).exp());
            err = err.max((sim.state().joint_angles[k] - expect).abs());
        }
    }
    assert!((sim.time() - 1.5).abs() < 1e-12);
    (err, sim.step_stats().steps)
}

#[test]
fn dopri5_meets_its_tolerance_on_the_servo_closed_form() {
    // The joints of ideal servos follow the linear filter exactly (hybrid dynamics), so
    // their closed form tests the adaptive integrator inside the full vehicle. The filter is
    // contractive, so the global error stays of the order of the local tolerance
    // atol + rtol·|q| ≤ atol + 0.35 rtol; allow a factor 10. Tighter tolerances must cost
    // more steps and give smaller errors (the error control is doing the work).
    let mut last = (f64::INFINITY, 0);
    for (rtol, atol) in [(1e-5, 1e-7), (1e-7, 1e-9), (1e-9, 1e-11)] {
        let (err, steps) = servo_error(rtol, atol);
        assert!(
            err <= 10.0 * (atol + 0.35 * rtol),
            "rtol {rtol:e}: error {err:e}"
        );
        assert!(
            err < last.0 && steps > last.1,
            "rtol {rtol:e}: {err:e}, {steps} steps"
        );
        last = (err, steps);
    }
}

#[test]
fn dopri5_conserves_energy_and_momentum_without_dissipation() {
    // docs/model.md §4 invariants with the adaptive integrator: torque-free joints, rigid and with
    // added mass (Kirchhoff), 100 s in 1 s spans at rtol 1e-10: the drift must stay below
    // the 1e-6 the RK4 tests require.
    for opts in [
        DynOptions::rigid(),
        DynOptions {
            added_mass: true,
            ..DynOptions::rigid()
        },
    ] {
        let dopri = Integrator::Dopri5 {
            rtol: 1e-10,
            atol: 1e-12,
            first_step: 0.01,
        };
        let (de, dp) = super::conservation::conservation_drift(&toy(3), opts, dopri, 41);
        assert!(de < 1e-6 && dp < 1e-6, "energy {de:e}, momentum {dp:e}");
    }
}

#[test]
fn rk4_span_equals_single_steps_and_integrates_the_joint_work() {
    // `advance` with RK4 is the same method as repeated `step`s (thrust states in closed
    // form from the span start are the same flow); and the joint work integrated with the
    // motion agrees between RK4 at 1 ms and Dormand–Prince at tight tolerance.
    let v = usm_paper();
    let opts = DynOptions::full();
    let mut a = servo_sim(&v, opts, Integrator::Rk4 { dt: 1e-3 });
    let mut b = servo_sim(&v, opts, Integrator::Rk4 { dt: 1e-3 });
    let mut c = servo_sim(
        &v,
        opts,
        Integrator::Dopri5 {
            rtol: 1e-10,
            atol: 1e-12,
            first_step: 0.01,
        },
    );
    let qr: Vec<f64> = (0..8).map(|k| 0.2 * ((k as f64) * 0.9).sin()).collect();
    let zero = vec![0.0; 8];
    let u = [3.0, -2.0, 5.0, 5.0, 1.0, -1.0, 2.0];
    let cmd = ActuatorCommand {
        thrust: &u,
        joint_ref: &qr,
        joint_rate_ref: &zero,
    };
    for _ in 0..20 {
        a.advance(0.05, &cmd).unwrap();
        for _ in 0..50 {
            b.step(1e-3, &cmd).unwrap();
        }
        c.advance(0.05, &cmd).unwrap();
    }
    let (sa, sb) = (a.state(), b.state());
    for (x, y) in sa.zeta().iter().zip(sb.zeta()) {
        assert!((x - y).abs() < 1e-12, "{x} vs {y}");
    }
    assert!((a.joint_work() - b.joint_work()).abs() < 1e-12 * b.joint_work());
    assert_eq!(a.step_stats().steps, 1000);
    let w = c.joint_work();
    assert!(w > 1e-3, "the servos work: {w}");
    assert!(
        (a.joint_work() - w).abs() < 1e-7 * w,
        "{} vs {w}",
        a.joint_work()
    );
}

#[test]
fn abs_increment_is_the_exact_absolute_integral_of_a_cubic() {
    use crate::dynamics::integrator::abs_increment;
    // y(t) = y0 + α t + β t² + γ t³ is its own Hermite interpolant, so ∫|ẏ| is exact: compare
    // with a fine midpoint sum over random cubics with 0, 1 and 2 sign changes of ẏ.
    let mut seed = 7_u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut crossings = [0usize; 3];
    for _ in 0..400 {
        let (y0, al, be, ga, h) = (rnd(), rnd(), 3.0 * rnd(), 3.0 * rnd(), 0.05 + rnd().abs());
        let y = |t: f64| y0 + al * t + be * t * t + ga * t * t * t;
        let p = |t: f64| al + 2.0 * be * t + 3.0 * ga * t * t;
        let n = 20_000;
        let mut exact = 0.0;
        let mut changes = 0;
        for i in 0..n {
            let t = (i as f64 + 0.5) * h / n as f64;
            exact += p(t).abs() * h / n as f64;
            if i > 0 && p(t).signum() != p(t - h / n as f64).signum() {
                changes += 1;
            }
        }
        crossings[changes.min(2)] += 1;
        let got = abs_increment(y(0.0), y(h), p(0.0), p(h), h);
        assert!(
            (got - exact).abs() < 1e-6 * (exact + 1e-3),
            "{got} vs {exact} ({changes} sign changes)"
        );
        // Without a sign change it is |Δy| exactly.
        if changes == 0 {
            assert_eq!(got, (y(h) - y(0.0)).abs());
        }
    }
    assert!(crossings.iter().all(|&c| c >= 5), "{crossings:?}");
}

//! Tests of the attainable authority: hand-computed support values of planar layouts, the
//! uncommanded axes left free, the reference-point transport, N−1 symmetry, solver reuse.

use super::*;
use crate::allocation::tests::bent_t;

const SURGE_YAW: [bool; 6] = [true, false, false, false, false, true];

/// Column of a unit thrust along `d` applied at `p` (moments about the origin).
fn column(t: &mut Matrix6xX<f64>, j: usize, p: [f64; 3], d: [f64; 3]) {
    let (p, d) = (Vector3::from(p), Vector3::from(d));
    t.fixed_view_mut::<3, 1>(0, j).copy_from(&d);
    t.fixed_view_mut::<3, 1>(3, j).copy_from(&p.cross(&d));
}

/// Two surge thrusters at y = +d (thruster 0) and y = −d (thruster 1), d = 0.5 m.
fn two_surge() -> Matrix6xX<f64> {
    let mut t = Matrix6xX::zeros(2);
    column(&mut t, 0, [0.0, 0.5, 0.0], [1.0, 0.0, 0.0]);
    column(&mut t, 1, [0.0, -0.5, 0.0], [1.0, 0.0, 0.0]);
    t
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * (1.0 + b.abs())
}

#[test]
fn two_surge_thrusters_have_the_hand_computed_support() {
    // Limits [−a, b] = [−10, 30] N, d = 0.5 m, moments about the origin (midway).
    // Thruster 0 at y = +d: f = (1,0,0), m = p × f = (0, 0, −d); thruster 1: m_z = +d.
    // surge = u0 + u1, yaw = d (u1 − u0).
    // surge+ with yaw = 0: u0 = u1 ≤ b → 2b = 60 N; surge−: u0 = u1 ≥ −a → 2a = 20 N.
    // yaw± with surge = 0: u1 = −u0 = v, |v| ≤ min(a, b) → 2 d min(a, b) = 10 N·m.
    let t = two_surge();
    let a =
        attainable_authority(&t, &[-10.0; 2], &[30.0; 2], SURGE_YAW, &Vector3::zeros()).unwrap();
    assert!(close(a.positive[0], 60.0), "{a:?}");
    assert!(close(a.negative[0], 20.0), "{a:?}");
    assert!(close(a.positive[5], 10.0), "{a:?}");
    assert!(close(a.negative[5], 10.0), "{a:?}");
    for k in 1..5 {
        assert!(a.positive[k].is_nan() && a.negative[k].is_nan(), "{a:?}");
    }
    assert!(close(a.min_force(SURGE_YAW), 20.0));
    assert!(close(a.min_moment(SURGE_YAW), 10.0));
    assert!(a
        .min_force([false, false, false, false, false, true])
        .is_nan());
}

#[test]
fn the_reference_point_moves_the_moment_balance() {
    // Reference r = (0, 0.25, 0): m_r = m − r × f, r × (1,0,0) = (0, 0, −0.25), so thruster 0
    // has m_z = −0.5 + 0.25 = −0.25 and thruster 1 m_z = 0.5 + 0.25 = 0.75.
    // surge+ with yaw = 0: −0.25 u0 + 0.75 u1 = 0 → u0 = 3 u1 ≤ 30 → u1 = 10, surge = 40 N.
    // surge−: u0 = 3 u1 ≥ −10 → surge = 4 · 10/3 = 13.33 N.
    // yaw with surge = 0 is a pure moment: 2 d min(a, b) = 10 N·m about any point.
    let t = two_surge();
    let r = Vector3::new(0.0, 0.25, 0.0);
    let a = attainable_authority(&t, &[-10.0; 2], &[30.0; 2], SURGE_YAW, &r).unwrap();
    assert!(close(a.positive[0], 40.0), "{a:?}");
    assert!(close(a.negative[0], 40.0 / 3.0), "{a:?}");
    assert!(close(a.positive[5], 10.0), "{a:?}");
    assert!(close(a.negative[5], 10.0), "{a:?}");
}

#[test]
fn transport_equals_thrusters_placed_about_the_reference() {
    // T about r equals T built from the thruster positions p − r (a finite example: seeded
    // 3-D layout), and so does the authority.
    let t = bent_t(3);
    let r = Vector3::new(0.4, -0.3, 0.2);
    let mut tr = Matrix6xX::zeros(t.ncols());
    transport_moments(&t, &r, &mut tr);
    for j in 0..t.ncols() {
        let f = Vector3::new(t[(0, j)], t[(1, j)], t[(2, j)]);
        let m = Vector3::new(t[(3, j)], t[(4, j)], t[(5, j)]);
        // m = p × f with p ⊥-component recoverable only up to f: check m_r = (p − r) × f
        // through m_r − m = −r × f, and by hand for one column.
        let mr = Vector3::new(tr[(3, j)], tr[(4, j)], tr[(5, j)]);
        assert!((mr - (m - r.cross(&f))).norm() < 1e-12);
    }
    let mut hand = Matrix6xX::zeros(1);
    column(&mut hand, 0, [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]);
    let mut hand_r = Matrix6xX::zeros(1);
    transport_moments(&hand, &Vector3::new(1.0, 0.0, 0.0), &mut hand_r);
    // (p − r) × f = (0, 2, 0) × (0, 0, 1) = (2, 0, 0).
    assert_eq!(hand_r.column(0).as_slice(), &[0.0, 0.0, 1.0, 2.0, 0.0, 0.0]);
    let dofs = [true, true, true, false, true, true];
    let lo = [-20.0; 7];
    let hi = [30.0; 7];
    let about_r = attainable_authority(&t, &lo, &hi, dofs, &r).unwrap();
    let moved = attainable_authority(&tr, &lo, &hi, dofs, &Vector3::zeros()).unwrap();
    for (k, &on) in dofs.iter().enumerate() {
        assert_eq!(about_r.positive[k].is_nan(), !on);
        if on {
            assert!(close(about_r.positive[k], moved.positive[k]));
            assert!(close(about_r.negative[k], moved.negative[k]));
        }
    }
}

#[test]
fn uncommanded_axes_are_free() {
    // One surge thruster at y = 0.5 m: with yaw commanded (held at zero) it can push nothing;
    // with only surge commanded it gives its full 30 N (the yaw it makes is free).
    let mut t = Matrix6xX::zeros(1);
    column(&mut t, 0, [0.0, 0.5, 0.0], [1.0, 0.0, 0.0]);
    let z = Vector3::zeros();
    let both = attainable_authority(&t, &[-10.0], &[30.0], SURGE_YAW, &z).unwrap();
    assert!(both.positive[0].abs() < 1e-6 && both.negative[0].abs() < 1e-6);
    let surge = [true, false, false, false, false, false];
    let alone = attainable_authority(&t, &[-10.0], &[30.0], surge, &z).unwrap();
    assert!(close(alone.positive[0], 30.0) && close(alone.negative[0], 10.0));
    assert!(alone.positive[5].is_nan());
}

/// Two surge thrusters at y = ±0.5 m (0, 1) and two sway thrusters at x = ±0.8 m (2, 3).
fn four_planar() -> Matrix6xX<f64> {
    let mut t = Matrix6xX::zeros(4);
    column(&mut t, 0, [0.0, 0.5, 0.0], [1.0, 0.0, 0.0]);
    column(&mut t, 1, [0.0, -0.5, 0.0], [1.0, 0.0, 0.0]);
    column(&mut t, 2, [0.8, 0.0, 0.0], [0.0, 1.0, 0.0]);
    column(&mut t, 3, [-0.8, 0.0, 0.0], [0.0, 1.0, 0.0]);
    t
}

#[test]
fn mirrored_thrusters_lose_the_same_authority() {
    // Mirroring y → −y swaps thrusters 0 and 1 and flips the yaw sign: removing either gives
    // the same surge authority and mirrored yaw authority. Likewise x → −x for 2 and 3.
    let t = four_planar();
    let dofs = [true, true, false, false, false, true];
    let (lo, hi) = ([-10.0; 4], [30.0; 4]);
    let full = attainable_authority(&t, &lo, &hi, dofs, &Vector3::zeros()).unwrap();
    let n1 = attainable_authority_n1(&t, &lo, &hi, dofs, &Vector3::zeros()).unwrap();
    assert_eq!(n1.len(), 4);
    for (a, b) in [(0, 1), (2, 3)] {
        let (x, y) = (&n1[a], &n1[b]);
        for k in [0, 1] {
            assert!(close(x.along(k), y.along(k)), "{k}: {x:?} {y:?}");
        }
        assert!(close(x.positive[5], y.negative[5]), "{x:?} {y:?}");
        assert!(close(x.negative[5], y.positive[5]), "{x:?} {y:?}");
    }
    // Removing a surge thruster costs surge authority: surge+ with u0 = 0, yaw balanced by the
    // sway pair (u2 = −u3 = w, yaw = 0.5 u1 + 1.6 w = 0 → w = −u1/3.2, |w| ≤ 10 → u1 ≤ 30).
    assert!(close(n1[0].positive[0], 30.0), "{:?}", n1[0]);
    assert!(n1[0].positive[0] < full.positive[0]);
    // The solver state is restored after a removal: solving again gives the full figures.
    let mut s = AuthoritySolver::new(&t, &lo, &hi, dofs, &Vector3::zeros()).unwrap();
    let first = s.solve(&t, &Vector3::zeros()).unwrap();
    let _ = s.solve_without(2);
    let again = s.solve(&t, &Vector3::zeros()).unwrap();
    assert_eq!(format!("{first:?}"), format!("{again:?}"));
    assert!(s.solve_without(9).positive[0].is_nan());
}

#[test]
fn a_reused_solver_depends_only_on_its_build_data_and_the_programme() {
    // Two solvers built from the same T give bit-identical results for another T whatever
    // was solved before (no warm start): the static analysis's determinism across workers.
    let (t0, t1, t2) = (bent_t(1), bent_t(2), bent_t(5));
    let dofs = [true, true, true, false, true, true];
    let (lo, hi) = ([-20.0; 7], [30.0; 7]);
    let r = Vector3::new(0.1, 0.0, 0.0);
    let mut a = AuthoritySolver::new(&t0, &lo, &hi, dofs, &r).unwrap();
    let mut b = AuthoritySolver::new(&t0, &lo, &hi, dofs, &r).unwrap();
    a.solve(&t1, &r).unwrap();
    let _ = a.solve_without(3);
    let x = a.solve(&t2, &r).unwrap();
    let y = b.solve(&t2, &r).unwrap();
    assert_eq!(format!("{x:?}"), format!("{y:?}"));
    // And close to a solver built from t2 itself.
    let z = attainable_authority(&t2, &lo, &hi, dofs, &r).unwrap();
    for k in (0..6).filter(|&k| dofs[k]) {
        assert!(close(x.positive[k], z.positive[k]) && close(x.negative[k], z.negative[k]));
    }
}

#[test]
fn bad_input_is_an_error_and_no_commanded_axis_is_all_nan() {
    let t = two_surge();
    let z = Vector3::zeros();
    assert!(attainable_authority(&t, &[-1.0], &[1.0; 2], SURGE_YAW, &z).is_err());
    let nan = Vector3::new(f64::NAN, 0.0, 0.0);
    assert!(attainable_authority(&t, &[-1.0; 2], &[1.0; 2], SURGE_YAW, &nan).is_err());
    let none = attainable_authority(&t, &[-1.0; 2], &[1.0; 2], [false; 6], &z).unwrap();
    assert!(none.positive.iter().all(|x| x.is_nan()));
}

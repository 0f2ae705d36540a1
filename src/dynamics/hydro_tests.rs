//! Tests of the hydrodynamic and hydrostatic kernels (docs/model.md §2, §4).

use super::*;
use crate::spatial::{ang, lin};
use proptest::prelude::*;

fn cyl() -> CylinderDrag {
    CylinderDrag::new(
        1026.0,
        0.085,
        0.6,
        0.8,
        1.0,
        1.2,
        [1.0, 2.0, 3.0, 0.05, 0.1, 0.2],
        7,
    )
}

/// Reference: the same integral written point by point in a different way (wrench of
/// each strip moved to the origin with the general formula `m = p × f`).
fn reference(c: &CylinderDrag, v: &Vec6) -> Vec6 {
    let ds = c.length / c.strips as f64;
    let mut w = Vec6::zeros();
    for k in 0..c.strips {
        let p = Vec3::new((k as f64 + 0.5) * ds, 0.0, 0.0);
        let vp = lin(v) + ang(v).cross(&p);
        let perp = Vec3::new(0.0, vp.y, vp.z);
        let f = Vec3::new(
            0.0,
            -c.k_strip_y * perp.norm() * perp.y,
            -c.k_strip_z * perp.norm() * perp.z,
        );
        let m = p.cross(&f);
        w += Vec6::new(f.x, f.y, f.z, m.x, m.y, m.z);
    }
    w[0] -= c.k_axial * v[0].abs() * v[0];
    let cc = Vec3::new(c.length / 2.0, 0.0, 0.0);
    let vc = lin(v) + ang(v).cross(&cc);
    let fl = -Vec3::new(c.linear[0] * vc.x, c.linear[1] * vc.y, c.linear[2] * vc.z);
    let ml = -Vec3::new(c.linear[3] * v[3], c.linear[4] * v[4], c.linear[5] * v[5]);
    let m = ml + cc.cross(&fl);
    w + Vec6::new(fl.x, fl.y, fl.z, m.x, m.y, m.z)
}

#[test]
fn pure_translation_drag_closed_form() {
    // A cylinder in pure cross-flow v_y: every strip sees the same v, so the total is
    // exactly −½ρ C_d,y (2r) l v|v| − d_y v (docs/model.md §2), acting at the centre.
    let c = cyl();
    let v = 0.7;
    let w = c.wrench(&Vec6::new(0.0, v, 0.0, 0.0, 0.0, 0.0));
    let expect = -0.5 * 1026.0 * 1.0 * 2.0 * 0.085 * 0.6 * v * v - 2.0 * v;
    // Sum of 7 equal terms: a few ulps of relative error.
    assert!((w[1] - expect).abs() < 1e-12 * expect.abs());
    // Moment about the origin = centre × force.
    assert!((w[5] - 0.3 * w[1]).abs() < 1e-12 * expect.abs());
    // Axial.
    let w = c.wrench(&Vec6::new(-0.4, 0.0, 0.0, 0.0, 0.0, 0.0));
    let expect = 0.5 * 1026.0 * 0.8 * std::f64::consts::PI * 0.085f64.powi(2) * 0.16 + 0.4;
    assert!((w[0] - expect).abs() < 1e-12 * expect);
}

#[test]
fn pure_rotation_about_centre_has_no_net_strip_force() {
    // Yaw about the geometric centre: v_y(s) = ω (s − l/2) is odd about the centre, so the
    // strip forces cancel in pairs (midpoint rule is symmetric) and only a moment remains.
    let c = cyl();
    let w = 0.9;
    let v = Vec6::new(0.0, -w * 0.3, 0.0, 0.0, 0.0, w);
    let f = c.wrench(&v);
    // Cancellation of O(10) N terms: 1e-12 absolute.
    assert!(f[1].abs() < 1e-12, "{}", f[1]);
    assert!(f[5] < 0.0, "the moment opposes the rotation");
}

proptest! {
    #[test]
    fn cylinder_matches_reference_and_dissipates(
        v in proptest::array::uniform6(-2.0f64..2.0)
    ) {
        let c = cyl();
        let v = Vec6::from_row_slice(&v);
        let w = c.wrench(&v);
        // Two evaluation orders of the same O(100) N sums: 1e-10 absolute.
        prop_assert!((w - reference(&c, &v)).norm() < 1e-10);
        // Drag and linear damping only remove energy: Vᵀ F ≤ 0.
        prop_assert!(v.dot(&w) <= 1e-12);
    }

    #[test]
    fn coefficient_damping_dissipates_for_diagonal_psd(
        v in proptest::array::uniform6(-2.0f64..2.0)
    ) {
        let v = Vec6::from_row_slice(&v);
        let dl = Mat6::from_diagonal(&Vec6::new(1.0, 2.0, 3.0, 0.1, 0.2, 0.3));
        let dq = Mat6::from_diagonal(&Vec6::new(10.0, 20.0, 30.0, 1.0, 2.0, 3.0));
        let w = coefficient_damping(&dl, &dq, &v);
        prop_assert!(v.dot(&w) <= 0.0);
        for i in 0..6 {
            let e = -(dl[(i, i)] * v[i] + dq[(i, i)] * v[i].abs() * v[i]);
            prop_assert!((w[i] - e).abs() < 1e-12);
        }
    }
}

/// The paper's link: ρ = 1026, r = 0.085 m, 0.6 m, with slender-body lift `C_Lα = 2` at
/// its free rear face.
fn lifting() -> CylinderDrag {
    cyl().with_lift(1026.0, 0.085, 2.0, true, false)
}

#[test]
fn lift_is_perpendicular_to_the_flow_zero_at_zero_incidence_and_odd() {
    let k = lifting().k_lift;
    let (u, a) = (0.5, 0.1f64);
    let v = Vec3::new(u * a.cos(), u * a.sin(), 0.0);
    let f = slender_lift(k, &v);
    // Hand value: ½ρ πr² U² C_Lα sin α cos α = ½·1026·π·0.085²·0.25·2·sin 0.1·cos 0.1.
    let hand =
        0.5 * 1026.0 * std::f64::consts::PI * 0.085f64.powi(2) * 0.25 * 2.0 * a.sin() * a.cos();
    assert!((hand - 0.5783).abs() < 1e-4, "{hand}");
    assert!((f.norm() - hand).abs() < 1e-14, "{} {hand}", f.norm());
    // Perpendicular to the relative velocity (no work), in the plane of the axis and v,
    // opposing the cross-flow component (a fin's lift).
    assert!(f.dot(&v).abs() < 1e-15, "{}", f.dot(&v));
    assert_eq!(f.z, 0.0);
    assert!(f.y < 0.0 && f.x > 0.0);
    // Odd in α: mirroring the incidence mirrors the force.
    let g = slender_lift(k, &Vec3::new(v.x, -v.y, 0.0));
    assert_eq!((g.x, g.y), (f.x, -f.y));
    // Zero at α = 0 (pure axial flow), at α = 90° (pure cross-flow) and at rest.
    assert_eq!(slender_lift(k, &Vec3::new(0.5, 0.0, 0.0)), Vec3::zeros());
    assert_eq!(slender_lift(k, &Vec3::new(-0.5, 0.0, 0.0)), Vec3::zeros());
    assert_eq!(slender_lift(k, &Vec3::new(0.0, 0.5, 0.2)), Vec3::zeros());
    assert_eq!(slender_lift(k, &Vec3::zeros()), Vec3::zeros());
    // Linear in α at small α: C_L = C_Lα α, i.e. ρ U² πr² α for C_Lα = 2.
    let small = 1e-4f64;
    let fs = slender_lift(k, &Vec3::new(u * small.cos(), u * small.sin(), 0.0));
    let slope = 1026.0 * 0.25 * std::f64::consts::PI * 0.085f64.powi(2) * small;
    assert!((fs.norm() - slope).abs() < 1e-8 * slope);
}

#[test]
fn lift_acts_at_the_free_trailing_face_only() {
    let c = lifting();
    let v = Vec6::new(0.5, 0.05, 0.0, 0.0, 0.0, 0.1);
    // Moving head first (u > 0): the trailing face is the rear one (x = 0), free: the
    // force is the lift of the rear face's velocity (v_y + ω_z·0) and makes no moment
    // about the origin, which is that face.
    let w = c.lift(&v);
    let f = slender_lift(c.k_lift, &Vec3::new(0.5, 0.05, 0.0));
    assert_eq!(Vec3::new(w[0], w[1], w[2]), f);
    assert_eq!((w[3], w[4], w[5]), (0.0, 0.0, 0.0));
    // The drag wrench with lift is the drag without it plus the lift.
    assert_eq!(c.wrench(&v), cyl().wrench(&v) + w);
    // Moving tail first: the trailing face is the front one, joined to the next body
    // here: no lift. Free, it carries the lift of its own velocity and its moment.
    let back = Vec6::new(-0.5, 0.05, 0.0, 0.0, 0.0, 0.1);
    assert_eq!(c.lift(&back), Vec6::zeros());
    let head = cyl().with_lift(1026.0, 0.085, 2.0, false, true);
    let wb = head.lift(&back);
    let fb = slender_lift(head.k_lift, &Vec3::new(-0.5, 0.05 + 0.1 * 0.6, 0.0));
    assert_eq!(Vec3::new(wb[0], wb[1], wb[2]), fb);
    assert!((wb[5] - 0.6 * fb.y).abs() < 1e-15);
    // No lift where no face is free.
    let inner = cyl().with_lift(1026.0, 0.085, 2.0, false, false);
    assert_eq!(inner.lift(&v), Vec6::zeros());
    assert_eq!(inner.lift(&back), Vec6::zeros());
}

#[test]
fn a_body_gets_lift_at_its_free_faces_or_at_every_face_when_asked() {
    let mut body = crate::model::presets::usm_paper().bodies[4].clone();
    let set = |b: &mut Body, slope: f64, every: bool| {
        if let Hydro::Cylinder {
            lift_slope,
            lift_every_body,
            ..
        } = &mut b.hydro
        {
            *lift_slope = slope;
            *lift_every_body = every;
        }
    };
    let flags = |k: &DampingKernel| match k {
        DampingKernel::Cylinder(c) => (c.k_lift, c.free_rear, c.free_front),
        _ => panic!("a cylinder"),
    };
    // No lift by default, whatever the faces.
    let site = |rear: bool, front: bool| HullSite {
        free_rear: rear,
        free_front: front,
        ..HullSite::default()
    };
    assert_eq!(
        flags(&DampingKernel::of(&body, 1026.0, &site(true, true))).0,
        0.0
    );
    set(&mut body, 2.0, false);
    let (k, rear, front) = flags(&DampingKernel::of(&body, 1026.0, &site(true, false)));
    let expect = 0.5 * 1026.0 * 2.0 * std::f64::consts::PI * body.radius * body.radius;
    assert!((k - expect).abs() < 1e-12 * expect);
    assert_eq!((rear, front), (true, false));
    assert!(!flags(&DampingKernel::of(&body, 1026.0, &site(false, false))).1);
    set(&mut body, 2.0, true);
    let (_, rear, front) = flags(&DampingKernel::of(&body, 1026.0, &site(false, false)));
    assert_eq!((rear, front), (true, true));
}

proptest! {
    #[test]
    fn lift_does_no_work(v in proptest::array::uniform6(-2.0f64..2.0)) {
        // Vᵀ W_lift = f · (v + ω × p) = f · v_p = 0 for any twist, rotation included.
        let v = Vec6::from_row_slice(&v);
        for c in [lifting(), cyl().with_lift(1026.0, 0.085, 2.0, false, true)] {
            let w = c.lift(&v);
            prop_assert!(v.dot(&w).abs() <= 1e-12 * (1.0 + w.norm() * v.norm()));
        }
    }
}

#[test]
fn ittc57_line_values() {
    // C_F = 0.075/(log10 Re − 2)²: 0.075/16 at Re = 1e6, 0.075/25 at 1e7; held below 1e5.
    assert!((ittc57(1e6) - 0.075 / 16.0).abs() < 1e-15);
    assert!((ittc57(1e7) - 0.075 / 25.0).abs() < 1e-15);
    assert_eq!(ittc57(10.0), ittc57(ITTC57_RE_MIN));
    assert_eq!(ittc57(0.0), ittc57(ITTC57_RE_MIN));
    // Hoerner's form factor: 1 + 1.5·0.1^1.5 + 7·0.001 at d/L = 0.1.
    let k = hoerner_form_factor(0.1, 1.0);
    assert!((k - (1.0 + 1.5 * 0.1f64.powf(1.5) + 0.007)).abs() < 1e-15);
}

#[test]
fn hull_sites_of_the_paper_design() {
    let v = crate::model::presets::usm_paper();
    let sites = HullSite::of_chain(&v);
    let a = std::f64::consts::PI * 0.085 * 0.085;
    // Only the tail's rear and the head's front are exposed (one radius throughout).
    assert_eq!((sites[0].rear_area, sites[0].front_area), (a, 0.0));
    assert_eq!((sites[8].rear_area, sites[8].front_area), (0.0, a));
    assert!(sites[1..8]
        .iter()
        .all(|s| s.rear_area == 0.0 && s.front_area == 0.0));
    // Thrusters: 2 on L1 (tunnels), 3 on L2 (2 pods, 1 tunnel), 2 on L3 (tunnels).
    let count = |f: fn(&HullSite) -> usize| sites.iter().map(f).collect::<Vec<_>>();
    assert_eq!(count(|s| s.pods), [0, 0, 0, 0, 2, 0, 0, 0, 0]);
    assert_eq!(count(|s| s.tunnels), [0, 0, 2, 0, 1, 0, 2, 0, 0]);
    assert_eq!(count(|s| s.gaps), [0, 1, 1, 1, 1, 1, 1, 1, 1]);
    assert!(sites.iter().all(|s| s.hull_length == v.total_length()));
    // A step in diameter exposes the annulus of the larger body.
    let mut w = v.clone();
    w.bodies[4].radius = 0.1;
    let s = HullSite::of_chain(&w);
    let ring = std::f64::consts::PI * (0.01 - 0.085 * 0.085);
    assert!((s[4].rear_area - ring).abs() < 1e-15 && (s[4].front_area - ring).abs() < 1e-15);
    assert_eq!((s[3].front_area, s[5].rear_area), (0.0, 0.0));
}

/// A paper-like head link with hull drag: free front face, one tunnel, one gap.
fn hull_head() -> CylinderDrag {
    let site = HullSite {
        free_front: true,
        front_area: std::f64::consts::PI * 0.085 * 0.085,
        hull_length: 3.3,
        form_factor: 1.02,
        tunnels: 1,
        gaps: 1,
        ..HullSite::default()
    };
    cyl().with_hull(1026.0, 0.085, &HullDrag::default(), &site)
}

#[test]
fn hull_axial_drag_is_its_written_out_sum() {
    let c = hull_head();
    let h = HullDrag::default();
    let (q, a) = (0.5 * 1026.0, std::f64::consts::PI * 0.085 * 0.085);
    let side = 2.0 * std::f64::consts::PI * 0.085 * 0.6;
    let appendage = q * (h.tunnel_drag_area + h.gap_drag_area);
    let friction = |u: f64| q * 1.02 * side * ittc57(u.abs() * 3.3 / h.viscosity);
    let cd_x = q * 0.8 * a; // the per-body C_d,x of `cyl()` stays on top
                            // Head first: the free front face leads (nose); tail first: it trails (base).
    for (u, form) in [(0.5, q * 0.8 * a), (-0.5, q * 0.1 * a)] {
        let k = cd_x + appendage + form + friction(u);
        let w = c.wrench(&Vec6::new(u, 0.0, 0.0, 0.0, 0.0, 0.0));
        let expect = -k * u.abs() * u - 1.0 * u;
        assert!((w[0] - expect).abs() < 1e-12 * expect.abs(), "{u}: {w}");
        assert_eq!((w[1], w[2], w[3], w[4], w[5]), (0.0, 0.0, 0.0, 0.0, 0.0));
    }
}

proptest! {
    #[test]
    fn hull_drag_dissipates(v in proptest::array::uniform6(-2.0f64..2.0)) {
        let v = Vec6::from_row_slice(&v);
        prop_assert!(v.dot(&hull_head().wrench(&v)) <= 1e-12);
    }
}

#[test]
fn restoring_upright_and_tilted() {
    let r = Restoring {
        weight: 100.0,
        buoyancy: 120.0,
        cg: Vec3::new(0.3, 0.0, -0.05),
        cb: Vec3::new(0.3, 0.0, 0.0),
    };
    // Level: net +20 N up; weight at x = 0.3 gives +30 N·m about y, buoyancy −36 N·m.
    let w = r.wrench(&Mat3::identity());
    assert!((w - Vec6::new(0.0, 0.0, 20.0, 0.0, 30.0 - 36.0, 0.0)).norm() < 1e-12);
    // Rolled by 0.3 rad: the metacentric moment −(m g) z_g sin φ about x brings it back.
    let rot = *nalgebra::Rotation3::from_euler_angles(0.3, 0.0, 0.0).matrix();
    let w = r.wrench(&rot);
    let expect_mx = -100.0 * 0.05 * 0.3f64.sin();
    assert!((w[3] - expect_mx).abs() < 1e-12);
}

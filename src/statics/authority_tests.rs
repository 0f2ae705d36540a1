//! Tests of the authority analysis: under-actuation of distributed/3 in transport mode, the
//! paper design's straight authority and N−1, mission ranges, explicit configurations.

use super::*;
use crate::model::generator::{GeneratorSpec, ThrusterRule};
use crate::model::presets::usm_paper;
use crate::scenario::Mode;

fn generated(rule: ThrusterRule, links: usize) -> Vehicle {
    GeneratorSpec {
        links,
        thruster_rule: rule,
        ..Default::default()
    }
    .build("g")
    .unwrap()
}

fn spec(samples: usize) -> StaticSpec {
    StaticSpec {
        samples,
        seed: 3,
        ..Default::default()
    }
    .for_mode(Mode::Transport)
}

fn analyse(v: &Vehicle, s: &StaticSpec, a: &AuthoritySpec) -> AuthoritySummary {
    authority_analysis(v, s, a, &mut || Ok(())).unwrap()
}

#[test]
fn distributed_three_links_is_under_actuated_in_transport() {
    // 4 thrusters (a lateral and a vertical on the one inner link, the longitudinal pair) for
    // 5 commanded axes (surge, sway, heave, pitch, yaw).
    let v = generated(ThrusterRule::Distributed, 3);
    assert_eq!(v.n_thrusters(), 4);
    let s = analyse(&v, &spec(64), &AuthoritySpec::default());
    assert_eq!(s.commanded_axes, "surge+sway+heave+pitch+yaw");
    assert!(s.under_actuated, "{:?}", s.full);
    assert!(!s.full.under_actuated_axes.is_empty());
    assert_eq!(
        s.under_actuated_mask.count_ones() as usize,
        s.full.under_actuated_axes.len()
    );
    // The paper layout on 5 links is not.
    let p = analyse(
        &generated(ThrusterRule::Paper, 5),
        &spec(64),
        &AuthoritySpec::default(),
    );
    assert!(!p.under_actuated, "{:?}", p.full);
    assert_eq!(p.under_actuated_mask, 0);
}

#[test]
fn usm_paper_straight_authority_in_newtons_and_n1() {
    let v = usm_paper();
    let s = analyse(
        &v,
        &spec(16),
        &AuthoritySpec {
            n1_samples: 4,
            ..Default::default()
        },
    );
    // Roll is not commanded in transport: NaN; the others positive and at most the sum of the
    // thrust limits (N), the figures about the centre of mass.
    assert!(s.straight.positive[3].is_nan());
    let sum: f64 = v.thrusters.iter().map(|t| t.u_max).sum();
    for k in [0, 1, 2, 4, 5] {
        assert!(
            s.straight.positive[k] > 0.0 && s.straight.negative[k] > 0.0,
            "{k}"
        );
        assert!(s.straight.positive[k] <= sum * 3.4, "{k}");
    }
    assert!(s.straight_min_force > 0.0 && s.straight_min_force <= s.full.median.along(0));
    assert!(s.full.min_force <= s.straight_min_force);
    assert!(s.straight_reference[0] > 0.0);
    assert_eq!(s.n1.samples, 5);
    assert_eq!(s.n1.thrusters.len(), 7);
    assert!(s.n1.worst_force <= s.straight_min_force);
    let w = &s.n1.thrusters[s.n1.worst_thruster];
    assert!(s
        .n1
        .thrusters
        .iter()
        .all(|t| t.loss <= w.loss && (0.0..=1.0).contains(&t.loss)));
    assert!(w.loss > 0.0 && w.loss_axis != "none");
}

#[test]
fn a_mission_range_is_reported_beside_the_full_limits() {
    // With ±0 rad every mission sample is the straight configuration.
    let v = usm_paper();
    let a = AuthoritySpec {
        mission: Some(JointRanges::Symmetric(0.0)),
        n1_samples: 0,
        ..Default::default()
    };
    let s = analyse(&v, &spec(8), &a);
    let m = s.mission.as_ref().unwrap();
    assert_eq!(m.samples, 8);
    assert_eq!(format!("{:?}", m.min), format!("{:?}", s.straight));
    assert_eq!(s.n1.samples, 1);
    // Per-joint ranges of the wrong length, or outside the limits, are located errors.
    let bad = AuthoritySpec {
        mission: Some(JointRanges::PerJoint(vec![[-0.1, 0.1]])),
        ..Default::default()
    };
    let e = authority_analysis(&v, &spec(8), &bad, &mut || Ok(())).unwrap_err();
    assert!(e.to_string().contains("joint_ranges"), "{e}");
    let neg = AuthoritySpec {
        mission: Some(JointRanges::Symmetric(-1.0)),
        ..Default::default()
    };
    assert!(authority_analysis(&v, &spec(8), &neg, &mut || Ok(())).is_err());
}

#[test]
fn explicit_configurations_and_the_straight_one_agree() {
    let v = usm_paper();
    let s = analyse(
        &v,
        &spec(4),
        &AuthoritySpec {
            n1_samples: 0,
            ..Default::default()
        },
    );
    let q0 = vec![0.0; v.n_joints()];
    let over = authority_over(&v, spec(4).commanded, &AuthorityReference::Com, [&q0]).unwrap();
    assert_eq!(format!("{:?}", over.min), format!("{:?}", s.straight));
    assert!(authority_over(&v, spec(4).commanded, &AuthorityReference::Com, [&q0[1..]]).is_err());
    // About the base origin (the tail) a force with the commanded moments held at zero is
    // another programme (m_r = m_b − r × f); a pure moment with every force row held at zero
    // is the same about any point.
    let base = authority_over(&v, spec(4).commanded, &AuthorityReference::Base, [&q0]).unwrap();
    assert!(
        (base.min.positive[1] - over.min.positive[1]).abs() > 1e-3,
        "{base:?} {over:?}"
    );
    assert!((base.min.positive[5] - over.min.positive[5]).abs() < 1e-6 * over.min.positive[5]);
}

#[test]
fn the_analysis_is_a_function_of_its_settings_and_stops_when_told() {
    let v = generated(ThrusterRule::Ends, 4);
    let a = AuthoritySpec::default();
    let x = analyse(&v, &spec(20), &a);
    let y = analyse(&v, &spec(20), &a);
    assert_eq!(format!("{x:?}"), format!("{y:?}"));
    let mut calls = 0;
    let r = authority_analysis(&v, &spec(20), &a, &mut || {
        calls += 1;
        if calls > 3 {
            Err("late".into())
        } else {
            Ok(())
        }
    });
    assert!(matches!(r, Err(StaticError::Sink(_))));
}

#[test]
fn the_weakest_ratio_needs_a_requirement() {
    let a = AttainableAuthority {
        positive: [10.0, 5.0, f64::NAN, f64::NAN, f64::NAN, 2.0],
        negative: [8.0, 5.0, f64::NAN, f64::NAN, f64::NAN, 4.0],
    };
    let dofs = CommandedDofs::new([true, true, false, false, false, true]);
    assert!(weakest_ratio(&a, dofs, &[0.0; 6]).is_nan());
    // surge 8/4 = 2, yaw 2/4 = 0.5.
    assert_eq!(
        weakest_ratio(&a, dofs, &[4.0, 0.0, 0.0, 0.0, 0.0, 4.0]),
        0.5
    );
}

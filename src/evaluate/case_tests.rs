//! The case evaluator: statuses, named metrics, overrides, the deadline, the cache.

use std::time::{Duration, Instant};

use super::*;
use crate::evaluate::{Deadline, Override, Side, AUTHORITY_COLUMNS, DESIGN_COLUMNS, TCM_COLUMNS};
use crate::input::keypath::Seg;

fn design() -> toml::Table {
    toml::from_str("preset = \"usm-paper\"\n").unwrap()
}

fn static_scenario(samples: i64) -> toml::Table {
    toml::from_str(&format!(
        "[scenario]\nmode = \"static\"\n[static]\nsamples = {samples}\n"
    ))
    .unwrap()
}

fn input<'a>(
    design: &'a toml::Table,
    scenario: &'a toml::Table,
    overrides: &'a Overrides,
    deadline: Deadline,
) -> CaseInput<'a> {
    CaseInput {
        design,
        design_hash: "d",
        scenario,
        overrides,
        seed: 7,
        deadline,
        phases: Phases {
            static_analysis: true,
            closed_loop: false,
        },
        trajectory: false,
        label: "test design",
    }
}

#[test]
fn a_static_case_has_its_design_and_tcm_metrics_by_name() {
    let (d, s) = (design(), static_scenario(64));
    let r = Evaluator::new().evaluate(&input(&d, &s, &[], Deadline::NONE));
    assert_eq!(r.status(), CaseStatus::Ok, "{}", r.reason);
    assert!(r.success() && r.criterion().is_none() && r.failure().is_none());
    assert_eq!(
        r.metrics.len(),
        DESIGN_COLUMNS.len() + TCM_COLUMNS.len() + AUTHORITY_COLUMNS.len()
    );
    assert_eq!(r.metrics.get("design_thrusters"), Some(7.0));
    assert!(r.metrics.value("tcm_singular_fraction").is_finite());
    // Same seed, same numbers (a second evaluator: no cache involved).
    // Bit for bit (the uncommanded roll authority is NaN, which `==` would not equal).
    let again = Evaluator::new().evaluate(&input(&d, &s, &[], Deadline::NONE));
    let bits = |m: &Metrics| -> Vec<(String, u64)> {
        m.iter()
            .map(|(n, x)| (n.to_string(), x.to_bits()))
            .collect()
    };
    assert_eq!(bits(&again.metrics), bits(&r.metrics));
}

#[test]
fn a_static_case_has_its_authority_columns_and_bad_authority_keys_skip_it() {
    // usm-paper in transport (the default static mode): roll uncommanded, 7 thrusters.
    let d = design();
    let s: toml::Table = toml::from_str(
        "[scenario]\nmode = \"static\"\n[static]\nsamples = 8\njoint_range = 0.0\nn1_samples = 2\n",
    )
    .unwrap();
    let r = Evaluator::new().evaluate(&input(&d, &s, &[], Deadline::NONE));
    assert_eq!(r.status(), CaseStatus::Ok, "{}", r.reason);
    let m = |n: &str| r.metrics.value(n);
    assert!(m("authority_roll_pos").is_nan() && m("authority_surge_pos") > 0.0);
    assert_eq!(m("under_actuated"), 0.0);
    assert_eq!(m("under_actuated_axes"), 0.0);
    // The mission range ±0 is the straight configuration.
    assert_eq!(
        m("authority_mission_min_force"),
        m("authority_straight_min_force")
    );
    assert!(m("n1_loss_t7").is_finite() && m("n1_loss_t8").is_nan());
    assert_eq!(
        m("n1_worst_loss"),
        m(&format!("n1_loss_t{}", m("n1_worst_thruster")))
    );
    for bad in [
        "authority_reference = \"tail\"",
        "joint_range = -1.0",
        "joint_ranges = [[1.0, 0.0]]",
    ] {
        let s: toml::Table = toml::from_str(&format!(
            "[scenario]\nmode = \"static\"\n[static]\nsamples = 8\n{bad}\n"
        ))
        .unwrap();
        let r = Evaluator::new().evaluate(&input(&d, &s, &[], Deadline::NONE));
        assert_eq!(r.status(), CaseStatus::Skipped, "{bad}");
        let key = bad.split(' ').next().unwrap();
        assert!(r.reason.contains(key), "{bad}: {}", r.reason);
    }
}

#[test]
fn an_invalid_design_is_skipped_and_a_bad_override_too() {
    let bad: toml::Table = toml::from_str("preset = \"no-such-preset\"\n").unwrap();
    let s = static_scenario(8);
    let r = Evaluator::new().evaluate(&input(&bad, &s, &[], Deadline::NONE));
    assert_eq!(r.status(), CaseStatus::Skipped);
    assert!(r.reason.starts_with("invalid design: "), "{}", r.reason);
    assert!(r.metrics.is_empty());
    assert_eq!(r.failure(), Some(r.reason.as_str()));
    let d = design();
    let o = [Override {
        side: Side::Design,
        path: vec![Seg::Key("preset".into()), Seg::Index(3)],
        value: toml::Value::Integer(1),
        shown: "design.preset[3]".into(),
    }];
    let r = Evaluator::new().evaluate(&input(&d, &s, &o, Deadline::NONE));
    assert_eq!(r.status(), CaseStatus::Skipped);
    assert!(r.reason.contains("design.preset[3]"), "{}", r.reason);
}

#[test]
fn overrides_change_the_case_and_key_the_design_cache() {
    let (d, s) = (design(), static_scenario(8));
    let mut ev = Evaluator::new();
    let nominal = ev.evaluate(&input(&d, &s, &[], Deadline::NONE));
    let o = [Override {
        side: Side::Design,
        path: vec![Seg::Key("preset".into())],
        value: toml::Value::String("uvms-planar".into()),
        shown: "design.preset".into(),
    }];
    // Same design hash, other design: the cache must not serve the nominal vehicle.
    let other = ev.evaluate(&input(&d, &s, &o, Deadline::NONE));
    assert_eq!(other.status(), CaseStatus::Ok, "{}", other.reason);
    assert_ne!(
        other.metrics.get("design_thrusters"),
        nominal.metrics.get("design_thrusters")
    );
    let so = [Override {
        side: Side::Scenario,
        path: vec![Seg::Key("static".into()), Seg::Key("samples".into())],
        value: toml::Value::Integer(0),
        shown: "static.samples".into(),
    }];
    let r = ev.evaluate(&input(&d, &s, &so, Deadline::NONE));
    assert_ne!(r.status(), CaseStatus::Ok, "0 samples must not pass");
}

#[test]
fn a_passed_deadline_stops_the_static_analysis_with_the_sweeps_message() {
    let (d, s) = (design(), static_scenario(20_000));
    let past = Deadline::at(Instant::now() - Duration::from_millis(1));
    let r = Evaluator::new().evaluate(&input(&d, &s, &[], past));
    assert_eq!(r.status(), CaseStatus::Failed);
    assert_eq!(
        r.reason,
        "timeout: the case's wall-clock budget ran out in the static analysis"
    );
    assert_eq!(r.criterion(), Some("no_failure"));
    assert!(r.end.timed_out(), "{:?}", r.end);
    // The design columns computed before the deadline are kept.
    assert_eq!(r.metrics.len(), DESIGN_COLUMNS.len());
}

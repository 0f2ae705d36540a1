//! The N−1 bound (issue 41): removing a thruster never lowers the optimal-control bound.

use super::bound::intact_and_n_minus_one;
use super::problem::parse_problem;
use super::sqp::Status;

#[test]
fn n_minus_one_bound_is_never_below_the_intact_bound() {
    // The shipped usm-paper problem shortened (as the thruster test of `tests.rs`), two
    // starts: for the first and the last thruster, the N−1 optimum converges and the
    // intact design's bound (own starts, and warm-started from the N−1 optimum) is not
    // above it.
    let text = std::fs::read_to_string("studies/ocp_usm_paper.toml")
        .unwrap()
        .replace("knots = 40", "knots = 6")
        .replace("duration = 4.0", "duration = 1.5")
        .replace("[0.0, 0.10, -0.05]", "[0.0, 0.02, -0.01]");
    let path = std::path::Path::new("studies/ocp_usm_paper.toml");
    let mut spec = parse_problem(&text, path).unwrap();
    spec.starts = 2;
    for j in [0, spec.vehicle.n_thrusters() - 1] {
        let (intact, minus) = intact_and_n_minus_one(&spec, j);
        assert_eq!(minus.status, Status::Converged, "N−1 of thruster {j}");
        assert!(minus.kkt.iter().all(|r| *r <= 1e-6), "{:?}", minus.kkt);
        assert!(intact.kkt[0] <= 1e-6, "intact primal {}", intact.kkt[0]);
        assert!(
            intact.objective <= minus.objective,
            "thruster {j}: intact {} above N−1 {}",
            intact.objective,
            minus.objective
        );
        assert_eq!(minus.solution.us[0].len() + 1, intact.solution.us[0].len());
    }
}

/// The bound's leg (`leg_problem`, what issue 41's `[ocp]` in studies will solve) and the
/// shipped reproducer `studies/ocp_transport.toml` pose the same problem: 10 m along +x in
/// 20 s on 20 knots, the 0.05 m/s cross current, thrusters and ±20 N·m joint torques, the
/// base level and at rest with the joints straight at T, the same thruster-energy and effort
/// and joint-energy weights, 10 substeps per interval (docs/ocp.md §6).
#[test]
fn the_bound_leg_is_the_shipped_transport_problem() {
    use super::bound::{leg_problem, LegSpec};
    let path = std::path::Path::new("studies/ocp_transport.toml");
    let file = parse_problem(&std::fs::read_to_string(path).unwrap(), path).unwrap();
    let leg = LegSpec {
        current: [0.0, 0.05, 0.0],
        ..LegSpec::default()
    };
    let spec = leg_problem(&file.vehicle, &leg);
    assert_eq!(spec.vehicle.name, file.vehicle.name);
    assert_eq!(
        (spec.hydrodynamics, spec.thrusters),
        (file.hydrodynamics, file.thrusters)
    );
    assert_eq!(
        (spec.duration, spec.knots, spec.substeps),
        (file.duration, file.knots, file.substeps)
    );
    assert_eq!(spec.current, file.current);
    assert_eq!(spec.base_displacement, file.base_displacement);
    assert_eq!(spec.base_rpy, file.base_rpy);
    assert_eq!(spec.terminal_joints, file.terminal_joints);
    assert_eq!(spec.zero_velocity, file.zero_velocity);
    assert_eq!(spec.bounds[2], file.bounds[2]);
    assert_eq!(spec.effort, file.effort);
    assert_eq!(
        spec.energy, file.energy,
        "thruster and joint energy weights"
    );
}

/// The multi-start of a cruise-started leg (docs/ocp.md §6): start s ≥ 1 is the cruise start
/// with its own seeded ramp fraction, dynamically consistent like start 0, so the starts
/// converge and the spread is a number; the ramps are deterministic and within range; the
/// optimum's work balance holds 10× finer.
#[test]
fn cruise_starts_of_other_ramps_converge_and_give_the_spread() {
    use super::bound::{leg_problem, solve_bound, start_ramp, LegSpec, RAMP_RANGE};
    use super::cruise::RAMP;
    assert_eq!(start_ramp(7, 0), RAMP);
    for s in 1..6 {
        let r = start_ramp(7, s);
        assert!((RAMP_RANGE.0..=RAMP_RANGE.1).contains(&r), "{r}");
        assert_eq!(r, start_ramp(7, s), "deterministic");
    }
    assert_ne!(start_ramp(7, 1), start_ramp(8, 1), "seeded");
    let design: toml::Table =
        toml::from_str("[generator]\nlinks = 4\nbody_profile = \"paper\"\nthrust_limit = 40.0\n")
            .unwrap();
    let vehicle = crate::model::design::parse_design_table(&design, "test").unwrap();
    let leg = LegSpec {
        distance: 5.0,
        duration: 12.0,
        knots: 12,
        substeps: 5,
        starts: 3,
        seed: 3,
        ..LegSpec::default()
    };
    let b = solve_bound(&leg_problem(&vehicle, &leg), None);
    // Two of the three converge (the third stalls): enough for a spread.
    assert!(
        b.converged >= 2,
        "converged starts {}: {:?}",
        b.converged,
        b.status
    );
    assert!(
        b.spread.is_finite() && b.spread >= 0.0,
        "spread {}",
        b.spread
    );
    assert!(b.work_error <= 0.05, "work error {}", b.work_error);
}

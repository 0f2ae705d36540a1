//! The σ_min floor (`[bounds] sigma_min`, [`super::sigma_floor`], docs/ocp.md §1): the
//! optimum keeps the commanded-axis σ_min of the scaled T(q) above the floor at every knot,
//! costs no less than the free optimum, and the keys are checked with located errors.

use super::problem::parse_problem;
use super::run::solve_spec;
use super::sigma_floor::SigmaFloor;
use super::sqp::Status;
use crate::metrics::singularity::CommandedDofs;
use std::path::Path;

/// usm-paper with thrusters and the full hydrodynamics, from a bent body (σ_min 0.0183 over
/// the six axes) to the end effector moved 11 cm in 4 s, N = 10; `bounds` extra lines.
fn problem(bounds: &str) -> String {
    format!(
        r#"design = "usm-paper"
actuation = "thrusters"
[physics]
hydrodynamics = true
[horizon]
duration = 4.0
knots = 10
[initial]
joint_angles = [0.3, 0.3, -0.3, 0.3, 0.3, -0.3, 0.3, 0.3]
[terminal]
ee_displacement = [0.0, 0.10, -0.05]
[objective]
effort = 1.0
[bounds]
joint_torque = 20.0
{bounds}
[solver]
max_iterations = 300
"#
    )
}

const FLOOR: f64 = 0.012;

#[test]
fn the_optimum_keeps_sigma_min_above_the_floor_and_costs_no_less() {
    let at = Path::new("sigma.toml");
    let free = solve_spec(&parse_problem(&problem(""), at).unwrap()).unwrap();
    assert_eq!(free.solution.status, Status::Converged);
    let spec = parse_problem(&problem(&format!("sigma_min = {FLOOR}")), at).unwrap();
    let v = &spec.vehicle;
    let mut sigma = SigmaFloor::new(v, FLOOR, 1.0, CommandedDofs::ALL, 0.5 * v.total_length());
    // Without the floor the optimum passes below it (else the test could not fail).
    let free_least = sigma.least_along(v, &free.solution.xs);
    assert!(
        free_least < FLOOR,
        "free optimum's least σ_min {free_least}"
    );
    let mut floored = solve_spec(&spec).unwrap();
    assert_eq!(
        floored.solution.status,
        Status::Converged,
        "{}",
        floored.solution.message
    );
    let least = sigma.least_along(v, &floored.solution.xs);
    assert!(
        least > FLOOR,
        "least σ_min {least} at or below the floor {FLOOR}"
    );
    // A constraint only removes trajectories (the barrier adds a positive term near it, so
    // compare the costs without it: the effort part).
    let effort =
        |r: &super::run::OcpRun| r.solution.us.iter().flatten().map(|u| u * u).sum::<f64>() * r.dt;
    assert!(
        effort(&floored) >= effort(&free) * (1.0 - 1e-6),
        "floored {} below free {}",
        effort(&floored),
        effort(&free)
    );
    // The summary's figure is the same.
    let least_reported = floored.model.least_sigma(&floored.solution.xs);
    assert_eq!(least_reported, Some(least));
}

#[test]
fn sigma_floor_keys_are_checked_with_located_errors() {
    let at = Path::new("sigma.toml");
    let err = |bounds: &str| parse_problem(&problem(bounds), at).unwrap_err().to_string();
    let e = err("sigma_min = 0.5");
    assert!(
        e.contains("bounds.sigma_min") && e.contains("initial joint angles have σ_min = 0.0183"),
        "{e}"
    );
    assert!(e.contains("sigma.toml:"), "{e}");
    let e = err("sigma_min = 0.01\nsigma_axes = [\"surge\", \"warp\"]");
    assert!(
        e.contains("bounds.sigma_axes") && e.contains("unknown axis \"warp\""),
        "{e}"
    );
    let e = err("sigma_min = 0.01\nsigma_axes = [\"yaw\", \"yaw\"]");
    assert!(e.contains("given twice"), "{e}");
    let e = err("char_length = 1.0");
    assert!(
        e.contains("bounds.char_length") && e.contains("only with bounds.sigma_min"),
        "{e}"
    );
    let e = err("sigma_min = -1.0");
    assert!(e.contains("must be positive"), "{e}");
    // The straight body is singular: a floor cannot start there.
    let straight = problem("sigma_min = 0.001").replace(
        "joint_angles = [0.3, 0.3, -0.3, 0.3, 0.3, -0.3, 0.3, 0.3]",
        "joint_angles = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]",
    );
    let e = parse_problem(&straight, at).unwrap_err().to_string();
    assert!(e.contains("start bent"), "{e}");
    // Fewer axes are accepted.
    let spec = parse_problem(
        &problem("sigma_min = 0.01\nsigma_axes = [\"heave\", \"pitch\"]"),
        at,
    )
    .unwrap();
    let f = spec.sigma_floor.unwrap();
    assert_eq!(f.axes, [false, false, true, false, true, false]);
}

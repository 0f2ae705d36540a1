//! The body along an optimal trajectory (issue 40 item 5): `plots/shapes.svg` of an `ocp`
//! run (no animation: 60 frames of a long chain are half a megabyte, and `results/ocp` stays
//! small), drawn as `simulate`'s ([`super::shapes`]) from the
//! solution's knots — base pose (inertial frame) and joint angles of each state `x_k`, the
//! thrust of the interval that starts there (the last knot: the last interval's) as arrows —
//! with the base and end-effector traces through every knot.

use std::path::Path;

use super::draw::vehicle_scene;
use super::error::PipelineError;
use super::shapes::{even_picks, set_thrust, thrust_scale, SHAPE_SNAPSHOTS};
use crate::model::Vehicle;
use crate::ocp::chain::ChainModel;
use crate::ocp::OcpRun;
use crate::report::atomic_write;
use crate::report::drawing::run_drawing::{render_shapes_svg, RunDrawing, Snapshot};
use crate::state::VehicleState;

/// The drawing of `run` (the design `v`) with `count` snapshots at evenly spaced knots (first
/// and last included).
pub fn ocp_drawing(v: &Vehicle, run: &mut OcpRun, count: usize) -> RunDrawing {
    let sol = &run.solution;
    let n = v.n_joints();
    let knots = sol.xs.len();
    let picks = even_picks(knots.max(1), count);
    let thrusters = run.model.thruster_actuated();
    let m = v.n_thrusters();
    let thrust: Vec<Vec<f64>> = (0..m)
        .map(|j| sol.us.iter().map(|u| u[j]).collect())
        .collect();
    let columns: Vec<&[f64]> = thrust.iter().map(|c| c.as_slice()).collect();
    let m_per_n = thrust_scale(v, if thrusters { &columns } else { &[] });
    let snapshots = picks
        .iter()
        .map(|&k| {
            let x = &sol.xs[k];
            let mut s = VehicleState::rest(v);
            s.base = ChainModel::pose(x);
            s.q = x[7..7 + n].to_vec();
            let mut scene = vehicle_scene(v, &s);
            let u = sol.us.get(k.min(sol.us.len().saturating_sub(1)));
            match u.filter(|_| thrusters) {
                Some(u) => set_thrust(&mut scene.arrows, &u[..m], m_per_n),
                None => set_thrust(&mut scene.arrows, &[], m_per_n),
            }
            Snapshot {
                t: k as f64 * run.dt,
                scene,
            }
        })
        .collect();
    let base_trace = sol
        .xs
        .iter()
        .map(|x| ChainModel::pose(x).position)
        .collect();
    let xs = sol.xs.clone();
    let ee_trace = xs.iter().map(|x| run.model.ee_pose(x).1).collect();
    let arrows = if thrusters {
        format!(
            "arrows: each thruster's thrust over the interval from that knot, signed, {} m per N",
            crate::report::fmt_short(m_per_n)
        )
    } else {
        "base-wrench actuation: no thrust arrows".into()
    };
    RunDrawing {
        caption: vec![
            format!("{} — optimal trajectory ({})", v.name, sol.status.word()),
            format!(
                "{} knots over {} s, J = {}; base and end-effector traces through every knot",
                knots,
                crate::report::fmt_short((knots.saturating_sub(1)) as f64 * run.dt),
                crate::report::fmt_short(sol.objective)
            ),
            arrows,
        ],
        snapshots,
        base_trace,
        ee_trace,
    }
}

/// Write `shapes.svg` of `run` (the design `v`) into `plots` (which must exist:
/// [`crate::ocp::write_outputs`] creates it).
pub fn write_ocp_shapes(v: &Vehicle, run: &mut OcpRun, plots: &Path) -> Result<(), PipelineError> {
    let d = ocp_drawing(v, run, SHAPE_SNAPSHOTS);
    atomic_write(&plots.join("shapes.svg"), render_shapes_svg(&d).as_bytes())?;
    Ok(())
}

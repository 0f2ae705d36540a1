//! Tests of `scenario::nominal` and of the world keys that break the symmetry (issue 36): the
//! controller's model stays nominal while the plant takes the world, and each world key
//! (`physics.current_vertical`, `hydro.cb_offset_z`/`_x`, `mission.payload_wet_weight`)
//! reaches the plant and changes a run.

use super::config::ScenarioFile;
use super::setup::ClosedLoop;
use super::{parse_table, parse_text, preset_text, resolve_design, run_loop, Stop};
use crate::model::Vehicle;
use crate::spatial::{Vec3, Vec6};

/// `transport-method2` with `extra` appended, parsed, and its design.
fn scenario(extra: &str) -> (ScenarioFile, Vehicle) {
    let text = format!("{}\n{extra}", preset_text("transport-method2").unwrap());
    let (table, src) = parse_text(&text, "t.toml").unwrap();
    let file = parse_table(&table, &src).unwrap();
    let v = resolve_design(&file, &src).unwrap();
    (file, v)
}

const WORLD: &str = "added_mass_scale = 1.5\ndrag_scale = 1.2\ncb_offset_z = 0.01";

#[test]
fn the_controller_sees_the_nominal_design_while_the_plant_sees_the_world() {
    let (file, v) = scenario(&format!(
        "[hydro]\n{WORLD}\ncontroller_nominal = true\n[physics]\ncurrent_vertical = 0.05"
    ));
    let mut cl = ClosedLoop::new(&v, &file).unwrap();
    // Move off rest so that n has velocity terms too.
    let mut st = cl.sim.state().clone();
    st.base_twist = Vec6::new(0.3, 0.05, -0.02, 0.01, 0.02, 0.03);
    st.joint_rates.iter_mut().for_each(|r| *r = 0.1);
    cl.sim.set_state(st.clone()).unwrap();
    let (m_plant, n_plant) = cl.sim.base_control_terms().unwrap();
    let (m_ctl, n_ctl) = cl.nominal.as_mut().unwrap().terms(&st);
    // The plant's added mass is 1.5 times the controller's: M11 differs, n too.
    assert!(
        (m_plant - m_ctl).amax() > 0.1 * m_ctl.amax(),
        "{m_plant} {m_ctl}"
    );
    assert!((n_plant - n_ctl).amax() > 1e-3, "{n_plant} {n_ctl}");
    // The controller's terms are those of the design itself in still water.
    let (nominal_file, _) = scenario("");
    let mut plain = ClosedLoop::new(&v, &nominal_file).unwrap();
    plain.sim.set_state(st).unwrap();
    let (m_ref, n_ref) = plain.sim.base_control_terms().unwrap();
    assert!((m_ctl - m_ref).amax() <= 1e-12 * m_ref.amax());
    assert!((n_ctl - n_ref).amax() <= 1e-12 * (1.0 + n_ref.amax()));
    // Without the key there is no second model: the controller cancels the plant's terms.
    let (same, _) = scenario(&format!("[hydro]\n{WORLD}"));
    assert!(ClosedLoop::new(&v, &same).unwrap().nominal.is_none());
}

#[test]
fn a_nominal_controller_changes_the_run_in_a_perturbed_world() {
    // Transport's default base control τ_c = M_11 a^b: the plant's M_11 has 1.5 times the
    // added mass of the controller's; 20 s.
    let run = |extra: &str| {
        let (mut file, v) = scenario(&format!("[hydro]\n{WORLD}\n{extra}"));
        file.scenario.duration = 20.0;
        let r = run_loop(&v, &file, Stop::NEVER).unwrap();
        assert!(r.failure.is_none(), "{:?}", r.failure);
        r.energy.thruster_energy
    };
    let own = run("");
    let nominal = run("controller_nominal = true");
    assert!(own.is_finite() && nominal.is_finite());
    assert_ne!(own, nominal);
}

#[test]
fn world_keys_reach_the_plant() {
    // Each key changes the plant the simulator integrates, and a short run with it.
    let (file0, v) = scenario("");
    let plant0 = ClosedLoop::new(&v, &file0).unwrap().vehicle;
    let (file, _) = scenario(
        "[physics]\ncurrent_vertical = 0.02\n[hydro]\ncb_offset_z = 0.01\ncb_offset_x = -0.002\n\
         [mission]\npayload_mass = 2.0\npayload_wet_weight = 1.5",
    );
    let plant = ClosedLoop::new(&v, &file).unwrap().vehicle;
    assert_eq!(plant.fluid.current.z, 0.02);
    for (b, b0) in plant.bodies.iter().zip(&plant0.bodies).take(8) {
        let shift = b.cb - b0.cb - Vec3::new(-0.002, 0.0, 0.01);
        assert!(shift.norm() < 1e-15, "{}: {shift}", b.name);
    }
    let (last, g) = (plant.bodies.last().unwrap(), plant.fluid.g);
    let last0 = v.bodies.last().unwrap();
    let wet = |m: f64, vol: f64| (m - plant.fluid.rho * vol) * g;
    let payload_wet = wet(last.mass, last.volume) - wet(last0.mass, last0.volume);
    assert!((payload_wet - 1.5).abs() < 1e-9, "{payload_wet}");
    let energy = |extra: &str| {
        let (mut f, v) = scenario(extra);
        f.scenario.duration = 10.0;
        run_loop(&v, &f, Stop::NEVER)
            .unwrap()
            .energy
            .thruster_energy
    };
    let nominal = energy("");
    let trim = "[hydro]\ncb_offset_x = -0.002";
    for extra in ["[physics]\ncurrent_vertical = 0.02", trim] {
        assert_ne!(energy(extra), nominal, "{extra}");
    }
    // The paper design's transport is planar (roll and pitch exactly 0), where a CB moved
    // up makes no moment: it acts once something tilts the vehicle, here the trim moment.
    assert_ne!(energy(&format!("{trim}\ncb_offset_z = 0.01")), energy(trim));
    let payload = "[mission]\npayload_mass = 2.0";
    assert_ne!(
        energy(&format!("{payload}\npayload_wet_weight = 1.5")),
        energy(payload)
    );
}

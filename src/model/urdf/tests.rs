//! Tests of URDF import and export: malformed files name the element and its line; the round
//! trip import(export(d)) = d to 1e-12 on the presets and on generated designs (proptest).

use super::*;
use crate::model::generator::{GeneratorSpec, ThrusterRule};
use crate::model::presets::preset;
use crate::model::{Hydro, Vehicle};
use crate::spatial::{Mat3, Mat6, Se3, Vec3};
use proptest::prelude::*;

fn close(what: &str, a: &[f64], b: &[f64], tol: f64) -> Result<(), String> {
    if a.len() != b.len() {
        return Err(format!("{what}: lengths {} != {}", a.len(), b.len()));
    }
    for (x, y) in a.iter().zip(b) {
        if (x - y).abs() > tol * x.abs().max(1.0) {
            return Err(format!("{what}: {x} != {y}"));
        }
    }
    Ok(())
}

fn hydro_values(h: &Hydro) -> Vec<f64> {
    match h {
        Hydro::Coefficients {
            added_mass,
            linear,
            quadratic,
        } => [added_mass, linear, quadratic]
            .iter()
            .flat_map(|m| m.as_slice().to_vec())
            .collect(),
        Hydro::Cylinder {
            cd_x,
            cd_y,
            cd_z,
            linear_damping,
            strips,
            axial_added_mass_ratio,
            added_mass_scale,
            lift_slope,
            lift_every_body,
            hull,
        } => {
            let mut v = vec![*cd_x, *cd_y, *cd_z, *strips as f64, *axial_added_mass_ratio];
            v.extend([
                *added_mass_scale,
                *lift_slope,
                f64::from(u8::from(*lift_every_body)),
            ]);
            v.extend(linear_damping);
            v.push(f64::from(u8::from(hull.is_some())));
            if let Some(h) = hull {
                v.extend(h.fields().iter().map(|f| f.1));
            }
            v
        }
        Hydro::Manoeuvring(_) => vec![f64::NAN],
    }
}

fn frame(g: &Se3) -> Vec<f64> {
    let mut v = g.p.as_slice().to_vec();
    v.extend(g.r.as_slice());
    v
}

/// Every body, joint, thruster and hydrodynamic value of `a` equals `b`'s to `tol` (relative
/// to max(1, |x|)); names equal.
pub(crate) fn same_design(a: &Vehicle, b: &Vehicle, tol: f64) -> Result<(), String> {
    if a.bodies.len() != b.bodies.len() || a.joints.len() != b.joints.len() {
        return Err("body or joint count differs".into());
    }
    if a.thrusters.len() != b.thrusters.len() {
        return Err("thruster count differs".into());
    }
    for (i, (x, y)) in a.bodies.iter().zip(&b.bodies).enumerate() {
        let k = |f: &str| format!("body[{i}].{f}");
        if x.name != y.name || std::mem::discriminant(&x.hydro) != std::mem::discriminant(&y.hydro)
        {
            return Err(format!("body[{i}]: name or hydro kind differs"));
        }
        close(
            &k("mass"),
            &[x.mass, x.length, x.radius, x.volume],
            &[y.mass, y.length, y.radius, y.volume],
            tol,
        )?;
        close(&k("cg"), x.cg.as_slice(), y.cg.as_slice(), tol)?;
        close(&k("cb"), x.cb.as_slice(), y.cb.as_slice(), tol)?;
        close(
            &k("inertia"),
            x.inertia.as_slice(),
            y.inertia.as_slice(),
            tol,
        )?;
        close(
            &k("hydro"),
            &hydro_values(&x.hydro),
            &hydro_values(&y.hydro),
            tol,
        )?;
    }
    for (i, (x, y)) in a.joints.iter().zip(&b.joints).enumerate() {
        if x.name != y.name {
            return Err(format!("joint[{i}] name"));
        }
        let mut u = frame(&x.placement);
        u.extend(x.axis.as_slice());
        u.extend([x.min, x.max]);
        let mut w = frame(&y.placement);
        w.extend(y.axis.as_slice());
        w.extend([y.min, y.max]);
        close(&format!("joint[{i}]"), &u, &w, tol)?;
    }
    for (i, (x, y)) in a.thrusters.iter().zip(&b.thrusters).enumerate() {
        if x.name != y.name || x.body != y.body {
            return Err(format!("thruster[{i}] name or body"));
        }
        if x.time_constant.is_some() != y.time_constant.is_some()
            || x.rate_limit.is_some() != y.rate_limit.is_some()
        {
            return Err(format!("thruster[{i}] options"));
        }
        let f = |t: &crate::model::Thruster| {
            let mut v = t.position.as_slice().to_vec();
            v.extend(t.direction.as_slice());
            v.extend([
                t.u_min,
                t.u_max,
                t.time_constant.unwrap_or(0.0),
                t.rate_limit.unwrap_or(0.0),
            ]);
            v
        };
        close(&format!("thruster[{i}]"), &f(x), &f(y), tol)?;
    }
    close("base", &frame(&a.base), &frame(&b.base), tol)?;
    close(
        "end_effector",
        &frame(&a.end_effector),
        &frame(&b.end_effector),
        tol,
    )?;
    let fl = |v: &Vehicle| {
        vec![
            v.fluid.rho,
            v.fluid.g,
            v.fluid.current.x,
            v.fluid.current.y,
            v.fluid.current.z,
        ]
    };
    close("fluid", &fl(a), &fl(b), tol)?;
    if a.name != b.name {
        return Err("name".into());
    }
    Ok(())
}

fn round_trip(v: &Vehicle) -> Vehicle {
    let text = vehicle_to_urdf(v).unwrap();
    match import_urdf(&text, "export.urdf", &ImportOptions::default()) {
        Ok(i) => {
            assert!(
                i.inferred.is_empty(),
                "an exported file gives every value: {:?}",
                i.inferred
            );
            i.vehicle
        }
        Err(e) => panic!("{e}\n{text}"),
    }
}

#[test]
fn presets_round_trip_exactly() {
    for name in ["usm-paper", "uvms-planar"] {
        let v = preset(name).unwrap();
        same_design(&v, &round_trip(&v), 1e-12).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

fn err_of(text: &str) -> UrdfError {
    import_urdf(text, "bad.urdf", &ImportOptions::default()).unwrap_err()
}

const GOOD: &str = r#"<robot name="r">
  <link name="a"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="q1" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>
</robot>"#;

#[test]
fn a_minimal_chain_imports_with_its_rules_inferred() {
    let i = import_urdf(GOOD, "good.urdf", &ImportOptions::default()).unwrap();
    assert_eq!(i.vehicle.bodies.len(), 2);
    assert_eq!(i.vehicle.joints[0].placement.p, Vec3::new(1.0, 0.0, 0.0));
    assert!(i.inferred.iter().any(|x| x.key.contains("volume")));
    assert!(i.inferred.iter().any(|x| x.key == "fluid.rho"));
}

#[test]
fn malformed_files_name_the_element_and_its_line() {
    // Missing inertial on the child of a revolute joint (line 3).
    let e = err_of(&GOOD.replace(
        r#"<link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>"#,
        r#"<link name="b"/>"#,
    ));
    assert_eq!(
        (e.line, e.element.as_str()),
        (3, "<link name=\"b\">"),
        "{e}"
    );
    assert!(e.message.contains("missing <inertial>"), "{e}");
    // Bad axis (line 5).
    let e = err_of(&GOOD.replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 0"/>"#));
    assert_eq!((e.line, e.element.as_str()), (5, "<axis>"), "{e}");
    let e = err_of(&GOOD.replace(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 x 1"/>"#));
    assert_eq!(e.line, 5, "{e}");
    // Unknown joint type (line 4).
    let e = err_of(&GOOD.replace("type=\"revolute\"", "type=\"hinge\""));
    assert_eq!(
        (e.line, e.element.as_str()),
        (4, "<joint name=\"q1\">"),
        "{e}"
    );
    assert!(e.message.contains("unknown joint type `hinge`"), "{e}");
    // A loop: a second joint back from b to a (line 6).
    let e = err_of(&GOOD.replace(
        "</robot>",
        "  <joint name=\"back\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>",
    ));
    assert_eq!(
        (e.line, e.element.as_str()),
        (6, "<joint name=\"back\">"),
        "{e}"
    );
    assert!(e.message.contains("loop"), "{e}");
    // XML syntax error.
    let e = err_of("<robot name=\"r\">\n<link name=\"a\">\n</robot>");
    assert_eq!(e.line, 3, "{e}");
    let s = e.to_string();
    assert!(s.starts_with("bad.urdf:3:"), "{s}");
}

#[test]
fn a_branching_tree_is_refused() {
    let text = GOOD.replace(
        "</robot>",
        r#"  <link name="c"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="q2" type="revolute"><parent link="a"/><child link="c"/><limit lower="-1" upper="1"/></joint>
</robot>"#,
    );
    let e = err_of(&text);
    assert_eq!(
        (e.line, e.element.as_str()),
        (7, "<joint name=\"q2\">"),
        "{e}"
    );
    assert!(e.message.contains("branching tree"), "{e}");
}

#[test]
fn fixed_links_merge_with_the_parallel_axis_theorem() {
    let text = GOOD.replace(
        "</robot>",
        r#"  <link name="s"><inertial><origin xyz="0 1 0"/><mass value="2"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
  <joint name="f" type="fixed"><parent link="a"/><child link="s"/></joint>
</robot>"#,
    );
    let v = import_urdf(&text, "m.urdf", &ImportOptions::default())
        .unwrap()
        .vehicle;
    let b = &v.bodies[0];
    assert_eq!(b.mass, 4.0);
    assert!((b.cg - Vec3::new(0.0, 0.5, 0.0)).norm() < 1e-15);
    // Ixx = 1 + 2·0.5² + 2·0.5² = 2, Iyy = 1, Izz = 2.
    assert!((b.inertia - Mat3::from_diagonal(&Vec3::new(2.0, 1.0, 2.0))).norm() < 1e-14);
}

#[test]
fn a_branching_tree_imports_with_the_branch_held_fixed() {
    let text = GOOD.replace(
        "</robot>",
        r#"  <link name="c"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="q2" type="revolute"><parent link="a"/><child link="c"/><limit lower="-1" upper="1"/></joint>
</robot>"#,
    );
    let opts = ImportOptions {
        fixed_joints: vec!["q2".into()],
        ..ImportOptions::default()
    };
    let i = import_urdf(&text, "f.urdf", &opts).unwrap();
    assert_eq!((i.vehicle.bodies.len(), i.vehicle.joints.len()), (2, 1));
    assert_eq!(i.vehicle.bodies[0].mass, 3.0);
    assert!(i.inferred.iter().any(|x| x.key == "joint q2"));
    let bad = ImportOptions {
        fixed_joints: vec!["nope".into()],
        ..ImportOptions::default()
    };
    let e = import_urdf(&text, "f.urdf", &bad).unwrap_err();
    assert!(e.message.contains("`nope`"), "{e}");
}

#[test]
fn uuv_cylinder_model_is_evaluated_as_uuv_simulator_does() {
    // UUV's HMCylinder on a 0.1 × 0.6 × 0.2 box along i: r = 0.1 (the smallest extent), L = 0.6,
    // L/(2r) = 3: C_d 0.87 (circular face), 0.74 (side).
    let text = GOOD.replace(
        "</robot>",
        r#"  <gazebo><plugin filename="libuuv_underwater_object_ros_plugin.so" name="u">
    <fluid_density>1000</fluid_density>
    <link name="b"><volume>0.01</volume><box><width>0.1</width><length>0.6</length><height>0.2</height></box>
      <hydrodynamic_model><type>cylinder</type><axis>i</axis></hydrodynamic_model></link>
  </plugin></gazebo>
</robot>"#,
    );
    let i = import_urdf(&text, "c.urdf", &ImportOptions::default()).unwrap();
    let Hydro::Coefficients {
        added_mass,
        quadratic,
        linear,
    } = &i.vehicle.bodies[1].hydro
    else {
        panic!("coefficients expected");
    };
    let pi = std::f64::consts::PI;
    let (rho, r, l) = (1000.0, 0.1, 0.6);
    let want_a = [
        rho * pi * r * r,
        rho * pi * r * r * l,
        rho * pi * r * r * l,
        0.0,
        rho * pi * r * r * l.powi(3) / 12.0,
        rho * pi * r * r * l.powi(3) / 12.0,
    ];
    let want_q = [
        0.5 * 0.87 * pi * r * r * rho,
        0.5 * 0.74 * r * l * rho,
        0.5 * 0.74 * r * l * rho,
        0.0,
        0.0,
        0.0,
    ];
    for k in 0..6 {
        assert!(
            (added_mass[(k, k)] - want_a[k]).abs() < 1e-12,
            "{added_mass}"
        );
        assert!((quadratic[(k, k)] - want_q[k]).abs() < 1e-12, "{quadratic}");
    }
    assert_eq!(
        added_mass.norm_squared(),
        want_a.iter().map(|x| x * x).sum::<f64>()
    );
    assert_eq!(linear.norm(), 0.0);
    let e = err_of(&text.replace("<axis>i</axis>", "<axis>q</axis>"));
    assert!(e.message.contains("must be i, j or k"), "{e}");
    let e = err_of(&text.replace("<type>cylinder</type>", "<type>sphere</type>"));
    assert!(e.message.contains("`sphere` is not supported"), "{e}");
}

/// Generated designs with random rotations, coefficient bodies, frames and thruster options.
fn arb_design() -> impl Strategy<Value = Vehicle> {
    (
        2usize..8,
        0usize..4,
        prop::collection::vec(-3.0f64..3.0, 80),
        prop::collection::vec(any::<bool>(), 8),
    )
        .prop_map(|(n, rule, r, flags)| {
            let spec = GeneratorSpec {
                links: n,
                thruster_rule: ThrusterRule::ALL[if n < 3 && rule == 0 { 1 } else { rule }],
                ..GeneratorSpec::default()
            };
            let mut v = spec.build("gen").unwrap();
            let rot = |a: f64, b: f64, c: f64| super::parse::rot_rpy(&Vec3::new(a, b / 2.0, c));
            for (k, j) in v.joints.iter_mut().enumerate() {
                j.placement.r = rot(r[(k) % 80], r[(k + 8) % 80], r[(k + 16) % 80]);
                j.axis = Vec3::new(r[(k + 24) % 80], r[(k + 32) % 80], 1.0).normalize();
            }
            for (k, b) in v.bodies.iter_mut().enumerate() {
                b.cg += Vec3::new(0.01 * r[(k + 40) % 80], 0.01 * r[(k + 48) % 80], 0.0);
                b.cb = b.cg + Vec3::new(0.0, 0.0, 0.01 * r[(k + 56) % 80].abs());
                let q = rot(r[(k + 64) % 80], r[(k + 72) % 80], r[(k) % 80]);
                b.inertia = q * b.inertia * q.transpose();
                if flags[k % 8] {
                    let a = Mat6::from_fn(|i, jj| r[(i * 6 + jj + k) % 80] / 3.0);
                    b.hydro = Hydro::Coefficients {
                        added_mass: a * a.transpose() * 10.0,
                        linear: Mat6::from_fn(|i, jj| r[(i + jj * 7 + k) % 80]),
                        quadratic: Mat6::from_diagonal(&nalgebra::Vector6::from_fn(|i, _| {
                            r[(i + k) % 80].abs()
                        })),
                    };
                }
            }
            for (k, t) in v.thrusters.iter_mut().enumerate() {
                t.direction =
                    Vec3::new(r[k % 80], r[(k + 3) % 80], r[(k + 5) % 80] + 4.0).normalize();
                t.time_constant = flags[k % 8].then_some(0.05 + r[k % 80].abs());
                t.rate_limit = flags[(k + 1) % 8].then_some(100.0 + r[k % 80]);
            }
            v.base = Se3::new(rot(r[1], r[2], r[3]), Vec3::new(r[4], r[5], r[6]) * 0.1);
            v.end_effector = Se3::new(rot(r[7], r[9], r[11]), Vec3::new(r[12], 0.0, 0.0).abs());
            v.fluid.current = Vec3::new(r[13], r[14], 0.0) * 0.1;
            v
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn generated_designs_round_trip_to_1e_12(v in arb_design()) {
        prop_assert!(v.validate().is_ok());
        let back = round_trip(&v);
        if let Err(e) = same_design(&v, &back, 1e-12) {
            prop_assert!(false, "{}", e);
        }
    }
}

#[test]
fn mjcf_export_has_every_body_joint_and_motor() {
    let v = preset("usm-paper").unwrap();
    let m = vehicle_to_mjcf(&v).unwrap();
    let doc = roxmltree::Document::parse(&m).unwrap();
    let count = |t: &str| doc.descendants().filter(|n| n.has_tag_name(t)).count();
    assert_eq!(count("body"), v.bodies.len());
    assert_eq!(count("joint"), v.joints.len());
    assert_eq!(count("motor"), v.thrusters.len());
    assert_eq!(count("freejoint"), 1);
    assert!(m.contains("gravcomp=") && m.contains("fluidshape=\"ellipsoid\""));
    assert!(m.contains("cannot represent"));
}

//! Located errors: every bad input names the file, the key and the line.

use super::*;

fn expect_err(text: &str, key: &str, line: Option<usize>, msg: &str) -> DesignError {
    let e = match parse_design(text, "designs/bad.toml") {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e,
    };
    let shown = e.to_string();
    assert_eq!(e.at.key, key, "{shown}");
    assert_eq!(e.at.line, line, "{shown}");
    assert!(shown.contains(msg), "'{msg}' not in: {shown}");
    match line {
        Some(l) => assert!(
            shown.starts_with(&format!("designs/bad.toml:{l}:")),
            "{shown}"
        ),
        None => assert!(shown.starts_with("designs/bad.toml: "), "{shown}"),
    }
    if !key.is_empty() {
        assert!(shown.contains(&format!(": {key}: ")), "{shown}");
    }
    e
}

/// A small valid explicit design; tests replace one line to break it.
const BASE: &str = "name = \"t\"\n\
[[body]]\n\
name = \"a\"\n\
mass = 2.0\n\
length = 0.5\n\
radius = 0.1\n\
[[body]]\n\
name = \"b\"\n\
mass = 2.0\n\
length = 0.5\n\
radius = 0.1\n\
[[joint]]\n\
axis = [0, 0, 1]\n\
limits_deg = [-90, 90]\n\
[[thruster]]\n\
body = \"b\"\n\
position = [0.2, 0, 0]\n\
direction = [1, 0, 0]\n\
u_min = -40\n\
[fluid]\n\
rho = 1026\n";

/// `BASE` with line `n` (1-based) replaced by `with`.
fn base_with(n: usize, with: &str) -> String {
    let mut lines: Vec<&str> = BASE.lines().collect();
    lines[n - 1] = with;
    lines.join("\n") + "\n"
}

#[test]
fn base_is_valid() {
    let v = parse_design(BASE, "b.toml").unwrap();
    assert_eq!((v.bodies.len(), v.n_joints(), v.n_thrusters()), (2, 1, 1));
}

#[test]
fn unknown_keys_types_and_syntax() {
    use DesignErrorKind::*;
    let e = expect_err(
        &base_with(10, "colour = \"red\""),
        "body[1].colour",
        Some(10),
        "unknown field `colour`",
    );
    assert_eq!(e.at.column, Some(1));
    assert_eq!(e.error.kind, Schema);
    expect_err(
        &base_with(1, "nmae = \"t\""),
        "nmae",
        Some(1),
        "unknown field `nmae`",
    );
    expect_err(
        &base_with(4, "mass = \"heavy\""),
        "body[0].mass",
        Some(4),
        "invalid type",
    );
    expect_err(
        &base_with(13, "axis = [0, 1]"),
        "joint[0].axis",
        Some(13),
        "invalid length 2",
    );
    // An unterminated array is reported where the parser gives up (the next line).
    let e = expect_err(
        &base_with(17, "position = [0.2, 0"),
        "",
        Some(18),
        "TOML syntax error",
    );
    assert_eq!(e.error.kind, Syntax);
    expect_err(
        &base_with(4, "mass = 2.0 2.0"),
        "",
        Some(4),
        "TOML syntax error",
    );
    expect_err(&base_with(5, "mass = 3.0"), "", Some(5), "duplicate key");
    // Missing required key: reported at the [[body]] header.
    expect_err(
        &base_with(6, ""),
        "body[0]",
        Some(2),
        "missing field `radius`",
    );
}

#[test]
fn non_finite_literals_and_body_references() {
    // Non-finite literals.
    let e = expect_err(
        &base_with(17, "position = [0.2, nan, 0]"),
        "thruster[0].position[1]",
        Some(17),
        "must be a finite number",
    );
    assert_eq!(e.at.column, Some(18));
    expect_err(
        &base_with(4, "mass = inf"),
        "body[0].mass",
        Some(4),
        "finite",
    );
    expect_err(
        &base_with(21, "rho = -inf"),
        "fluid.rho",
        Some(21),
        "finite",
    );
    // Wrong body reference type.
    expect_err(
        &base_with(16, "body = 1.5"),
        "thruster[0].body",
        Some(16),
        "body name (string) or a 0-based body index",
    );
}

#[test]
fn conflicting_and_missing_forms() {
    // Forms.
    expect_err(
        &format!("preset = \"usm-paper\"\n{BASE}"),
        "body",
        Some(3),
        "cannot be combined with `preset`",
    );
    expect_err(
        &format!("{BASE}[generator]\nlinks = 3\n"),
        "generator",
        Some(22),
        "cannot be combined",
    );
    expect_err(
        "[generator]\n[[body]]\nname=\"x\"\nmass=1\nlength=1\nradius=1\n",
        "generator",
        Some(1),
        "cannot be combined",
    );
    expect_err("name = \"x\"\n", "", None, "no design found");
    expect_err(
        "[[thruster]]\nbody=0\nposition=[0,0,0]\ndirection=[1,0,0]\n",
        "",
        None,
        "no design found",
    );
    expect_err(
        "preset = \"usm-paper\"\n[[thruster]]\nbody=0\nposition=[0,0,0]\ndirection=[1,0,0]\n",
        "thruster",
        Some(2),
        "not allowed with `preset`",
    );
}

#[test]
fn hydro_schema_errors() {
    // Hydro keys of the wrong kind.
    expect_err(
        &base_with(
            6,
            "radius = 0.1\n[body.hydro]\nkind = \"coefficients\"\ncd_x = 1",
        ),
        "body[0].hydro.cd_x",
        Some(9),
        "not a key of hydro kind",
    );
    expect_err(
        &base_with(6, "radius = 0.1\n[body.hydro]\nkind = \"foil\""),
        "body[0].hydro.kind",
        Some(8),
        "unknown hydro kind",
    );
    expect_err(
        &base_with(6, "radius = 0.1\n[body.hydro]\nkind = \"coefficients\""),
        "body[0].hydro.added_mass",
        Some(7),
        "required",
    );
    expect_err(
        &base_with(6, "radius = 0.1\n[body.hydro]\nstrips = 0"),
        "body[0].hydro.strips",
        Some(8),
        "between 1 and",
    );
    expect_err(
        &base_with(6, "radius = 0.1\nvolume = 0.1\nneutral = true"),
        "body[0].neutral",
        Some(8),
        "not both",
    );
}

#[test]
fn generator_schema_errors() {
    // Generator schema.
    expect_err(
        "[generator]\nlinks = 4\nthruster_rule = \"diagonal\"\n",
        "generator.thruster_rule",
        Some(3),
        "unknown thruster rule",
    );
    expect_err(
        "[generator]\nlinks = -4\n",
        "generator.links",
        Some(2),
        "invalid value",
    );
    expect_err(
        "[generator]\nlinkz = 4\n",
        "generator.linkz",
        Some(2),
        "unknown field",
    );
}

#[test]
fn body_scalars_must_be_positive() {
    use DesignErrorKind::*;
    let e = expect_err(
        &base_with(4, "mass = -2.0"),
        "body[0].mass",
        Some(4),
        "body[0].mass: must be > 0",
    );
    assert_eq!(e.error.kind, Invalid);
    assert_eq!(e.at.column, Some(1));
    expect_err(
        &base_with(9, "mass = 0"),
        "body[1].mass",
        Some(9),
        "must be > 0",
    );
    expect_err(
        &base_with(5, "length = 0.0"),
        "body[0].length",
        Some(5),
        "must be > 0",
    );
    expect_err(
        &base_with(11, "radius = -0.1"),
        "body[1].radius",
        Some(11),
        "must be > 0",
    );
}

#[test]
fn references_directions_and_limits() {
    expect_err(
        &base_with(16, "body = \"c\""),
        "thruster[0].body",
        Some(16),
        "no body named 'c'",
    );
    expect_err(
        &base_with(16, "body = 2"),
        "thruster[0].body",
        Some(16),
        "body index 2 does not exist",
    );
    expect_err(
        &base_with(16, "body = -1"),
        "thruster[0].body",
        Some(16),
        "does not exist",
    );
    expect_err(
        &base_with(18, "direction = [0, 0, 0]"),
        "thruster[0].direction",
        Some(18),
        "thruster[0].direction: must be a nonzero vector",
    );
    expect_err(
        &base_with(18, "direction = [0, 1e-300, 1e-300]"),
        "thruster[0].direction",
        Some(18),
        "nonzero",
    );
    expect_err(
        &base_with(13, "axis = [0.0, 0.0, 0.0]"),
        "joint[0].axis",
        Some(13),
        "nonzero",
    );
    expect_err(
        &base_with(14, "limits_deg = [30, -30]"),
        "joint[0].limits_deg",
        Some(14),
        "min <= max",
    );
    expect_err(
        &base_with(19, "u_min = 50"),
        "thruster[0].u_min",
        Some(19),
        "u_min <= u_max",
    );
    expect_err(
        &base_with(19, "u_max = -50"),
        "thruster[0].u_max",
        Some(19),
        "u_min <= u_max",
    );
}

#[test]
fn validate_errors_are_mapped_to_lines() {
    use DesignErrorKind::*;
    // Errors found by Vehicle::validate are mapped back to their lines.
    expect_err(
        &base_with(21, "rho = -1"),
        "fluid.rho",
        Some(21),
        "must be > 0",
    );
    expect_err(
        &base_with(19, "time_constant = -1"),
        "thruster[0].time_constant",
        Some(19),
        "must be > 0",
    );
    expect_err(
        &base_with(6, "radius = 0.1\nvolume = -1"),
        "body[0].volume",
        Some(7),
        "must be > 0",
    );
    expect_err(
        &base_with(
            6,
            "radius = 0.1\ninertia = [[1, 0, 0], [0, -1, 0], [0, 0, 1]]",
        ),
        "body[0].inertia",
        Some(7),
        "positive definite",
    );
    expect_err(
        &base_with(6, "radius = 0.1\n[body.hydro]\ncd_y = -1"),
        "body[0].hydro.cd_y",
        Some(8),
        ">= 0",
    );
    // Wrong joint count: reported at the joint list.
    let e = expect_err(
        &format!("{BASE}[[joint]]\naxis = [0, 1, 0]\n"),
        "joint",
        Some(12),
        "needs 1 joints, got 2",
    );
    assert_eq!(e.error.kind, Invalid);
    expect_err(
        &base_with(12, "[[joint]]\naxis = [0, 1, 0]\n[[joint]]"),
        "joint",
        Some(12),
        "got 2",
    );
}

#[test]
fn generator_physics_errors() {
    // Generator checks with the key of the generator table.
    expect_err(
        "[generator]\nlinks = 4\nlink_length = [0.5, 0.5]\n",
        "generator.link_length",
        Some(3),
        "needs 1 or 4 values",
    );
    expect_err(
        "[generator]\nlinks = 30\n",
        "generator.links",
        Some(2),
        "between 2 and 20",
    );
    expect_err(
        "[generator]\njoint_limit_deg = -5\n",
        "generator.joint_limit_deg",
        Some(2),
        "> 0",
    );
    expect_err(
        "[generator]\nlink_mass = [1, -1, 1, 1, 1]\n",
        "generator.link_mass",
        Some(2),
        "> 0",
    );
    expect_err(
        "[generator]\nlink_length = []\n",
        "generator.link_length",
        Some(2),
        "at least one",
    );
    expect_err("[generator]\nlinks = 3\n[[thruster]]\nbody = \"L9\"\nposition = [0,0,0]\ndirection = [1,0,0]\n", "thruster[0].body", Some(4), "no body named 'L9'");
}

#[test]
fn table_path_has_keys_but_no_lines() {
    let mut table: toml::Table = toml::from_str(&design_to_toml(&usm_paper())).unwrap();
    let v = parse_design_table(&table, "sweep").unwrap();
    close(&v, &usm_paper(), 1e-12).unwrap();
    let thr = table
        .get_mut("thruster")
        .and_then(|t| t.as_array_mut())
        .unwrap();
    let t2 = thr[2].as_table_mut().unwrap();
    t2.insert(
        "direction".into(),
        toml::Value::Array(vec![0.0.into(), 0.0.into(), 0.0.into()]),
    );
    let e = parse_design_table(&table, "sweep case 3").unwrap_err();
    assert_eq!(e.at.key, "thruster[2].direction");
    assert_eq!(e.at.line, None);
    assert_eq!(
        e.to_string(),
        "sweep case 3: thruster[2].direction: must be a nonzero vector"
    );
    // Generator overrides.
    let mut g: toml::Table = toml::from_str("[generator]\nlinks = 5\n").unwrap();
    let gen = g
        .get_mut("generator")
        .and_then(|t| t.as_table_mut())
        .unwrap();
    gen.insert("links".into(), 7.into());
    assert_eq!(parse_design_table(&g, "s").unwrap().bodies.len(), 13);
    let gen = g
        .get_mut("generator")
        .and_then(|t| t.as_table_mut())
        .unwrap();
    gen.insert("radius".into(), f64::NAN.into());
    let e = parse_design_value(&toml::Value::Table(g), "s").unwrap_err();
    assert_eq!(e.at.key, "generator.radius");
    assert!(parse_design_value(&toml::Value::Integer(3), "s").is_err());
    // load_design_table gives the explicit form of presets.
    let t = load_design_table("usm-paper").unwrap();
    assert_eq!(
        t.get("thruster")
            .and_then(|x| x.as_array())
            .map(|a| a.len()),
        Some(7)
    );
}

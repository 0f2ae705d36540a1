//! Property tests: generated designs round-trip, mutated files never panic.

use super::*;
use proptest::prelude::*;
use std::fmt::Write as _;

fn arb_spec() -> impl Strategy<Value = GeneratorSpec> {
    (2usize..=12)
        .prop_flat_map(|n| {
            (
                Just(n),
                prop_oneof![
                    (0.1f64..1.5).prop_map(|l| vec![l]),
                    prop::collection::vec(0.1f64..1.5, n),
                ],
                prop_oneof![
                    Just(Vec::new()),
                    (1.0f64..30.0).prop_map(|m| vec![m]),
                    prop::collection::vec(1.0f64..30.0, n),
                ],
                (0.03f64..0.3, 0.05f64..0.3, 0.5f64..10.0, 0.1f64..3.1),
                (0usize..4, 1.0f64..100.0, 0.0f64..0.2),
                (0.0f64..1.5, 0.0f64..1.5, 0.0f64..2.0),
            )
        })
        .prop_map(
            |(n, ll, lm, (r, ml, mm, jl), (rule, tl, off), (ce, ca, cc))| GeneratorSpec {
                links: n,
                link_length: ll,
                link_mass: lm,
                body_profile: Default::default(),
                radius: r,
                module_length: ml,
                module_mass: mm,
                joint_limit: jl,
                // The paper rule needs 3 links (tested in model::generator).
                thruster_rule: ThrusterRule::ALL[if n < 3 && rule == 0 { 1 } else { rule }],
                thrust_limit: tl,
                thrust_per_kg: 0.0,
                longitudinal_offset: off,
                cd_axial_ends: Some(ce),
                cd_axial: Some(ca),
                cd_cross: cc,
                metacentric_height: crate::model::generator::DEFAULT_METACENTRIC_HEIGHT,
                wet_weight: 0.0,
            },
        )
}

/// The `[generator]` form of a spec.
fn generator_toml(s: &GeneratorSpec) -> String {
    let mut o = String::from("[generator]\n");
    let _ = writeln!(o, "links = {}", s.links);
    let _ = writeln!(o, "link_length = {}", farr(&s.link_length));
    if !s.link_mass.is_empty() {
        let _ = writeln!(o, "link_mass = {}", farr(&s.link_mass));
    }
    for (k, v) in [
        ("radius", s.radius),
        ("module_length", s.module_length),
        ("module_mass", s.module_mass),
        ("joint_limit_deg", deg(s.joint_limit)),
        ("thrust_limit", s.thrust_limit),
        ("longitudinal_offset", s.longitudinal_offset),
        ("cd_axial_ends", s.cd_axial_ends.unwrap_or(0.8)),
        ("cd_axial", s.cd_axial.unwrap_or(0.1)),
        ("cd_cross", s.cd_cross),
    ] {
        let _ = writeln!(o, "{k} = {}", fnum(v));
    }
    let _ = writeln!(o, "thruster_rule = \"{}\"", s.thruster_rule);
    o
}

/// Byte ranges of number-like tokens (outside comments and strings, roughly).
fn number_tokens(text: &str) -> Vec<Range<usize>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let starts =
            c.is_ascii_digit() || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        let prev_ok = i == 0 || matches!(b[i - 1], b' ' | b'[' | b',' | b'=');
        if starts && prev_ok {
            let s = i;
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_digit() || matches!(b[i], b'.' | b'e' | b'E' | b'-' | b'+'))
            {
                i += 1;
            }
            out.push(s..i);
        } else {
            i += 1;
        }
    }
    out
}

#[derive(Clone, Debug)]
enum Mutation {
    DeleteLine(usize),
    DuplicateLine(usize),
    ReplaceNumber(usize, String),
    InsertGarbage(usize, String),
    Truncate(usize),
    SwapLines(usize, usize),
}

fn arb_mutation() -> impl Strategy<Value = Mutation> {
    let replacement = prop_oneof![
        Just("-1.0".to_string()),
        Just("0".to_string()),
        Just("nan".to_string()),
        Just("-inf".to_string()),
        Just("1e308".to_string()),
        Just("1e400".to_string()),
        Just("-1e-320".to_string()),
        Just("\"x\"".to_string()),
        Just("[]".to_string()),
        Just("9223372036854775807".to_string()),
        Just("99999999999999999999".to_string()),
        Just("{a = 1}".to_string()),
        "[ -~]{0,6}",
    ];
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), replacement).prop_map(|(i, s)| Mutation::ReplaceNumber(i, s)),
        (any::<usize>(), "[ -~\n]{0,12}").prop_map(|(i, s)| Mutation::InsertGarbage(i, s)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Mutation::SwapLines(i, j)),
    ]
}

fn floor_boundary(s: &str, mut i: usize) -> usize {
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    let n = lines.len().max(1);
    match m {
        Mutation::DeleteLine(i) => {
            if !lines.is_empty() {
                lines.remove(i % n);
            }
            lines.join("\n")
        }
        Mutation::DuplicateLine(i) => {
            if !lines.is_empty() {
                let l = lines[i % n];
                lines.insert(i % n, l);
            }
            lines.join("\n")
        }
        Mutation::SwapLines(i, j) => {
            if !lines.is_empty() {
                lines.swap(i % n, j % n);
            }
            lines.join("\n")
        }
        Mutation::ReplaceNumber(i, s) => {
            let toks = number_tokens(text);
            if toks.is_empty() {
                return text.to_string();
            }
            let r = toks[i % toks.len()].clone();
            format!("{}{}{}", &text[..r.start], s, &text[r.end..])
        }
        Mutation::InsertGarbage(i, s) => {
            let p = floor_boundary(text, i % (text.len() + 1));
            format!("{}{}{}", &text[..p], s, &text[p..])
        }
        Mutation::Truncate(i) => {
            let p = floor_boundary(text, i % (text.len() + 1));
            text[..p].to_string()
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn generated_designs_round_trip(spec in arb_spec()) {
        let v = spec.build("gen").unwrap();
        // The thruster array written directly is the one the explicit text parses to (none
        // written: empty).
        let text: toml::Table = toml::from_str(&design_to_toml(&v)).unwrap();
        let parsed = text.get("thruster").cloned();
        prop_assert_eq!(thrusters_to_toml(&v), parsed.unwrap_or(toml::Value::Array(Vec::new())));
        let back = round_trip(&v).map_err(TestCaseError::fail)?;
        prop_assert!(close(&v, &back, 1e-12).is_ok(), "{:?}", close(&v, &back, 1e-12));
        // The [generator] form builds the same vehicle.
        let g = parse_design(&generator_toml(&spec), "gen.toml")
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(close(&v, &g, 1e-12).is_ok(), "{:?}", close(&v, &g, 1e-12));
    }

    #[test]
    fn rotated_frames_round_trip(
        a in prop::array::uniform3(-3.1f64..3.1),
        b in prop::array::uniform3(-3.1f64..3.1),
        lock in any::<bool>(),
    ) {
        let mut v = usm_paper();
        let mut rb = vec3(b);
        if lock {
            rb[1] = std::f64::consts::FRAC_PI_2;
        }
        v.joints[0].placement.r = rot_rpy(&vec3(a));
        v.base.r = rot_rpy(&rb);
        v.end_effector.r = rot_rpy(&vec3(a).map(|x| -x));
        let back = round_trip(&v).map_err(TestCaseError::fail)?;
        prop_assert!(close(&v, &back, 1e-12).is_ok(), "{:?}", close(&v, &back, 1e-12));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn mutated_files_never_panic(muts in prop::collection::vec(arb_mutation(), 1..4)) {
        let mut text = design_to_toml(&usm_paper());
        for m in &muts {
            text = apply(&text, m);
        }
        match parse_design(&text, "mut.toml") {
            Ok(v) => prop_assert!(v.validate().is_ok()),
            Err(e) => {
                // Every error names its origin and has a readable message.
                let s = e.to_string();
                prop_assert!(s.starts_with("mut.toml"));
                prop_assert!(!e.error.message.is_empty());
                if let Some(l) = e.at.line {
                    prop_assert!(l >= 1 && l <= text.lines().count().max(1) + 1, "{} {}", l, s);
                }
            }
        }
        // The table path must not panic either.
        if let Ok(t) = toml::from_str::<toml::Table>(&text) {
            let _ = parse_design_table(&t, "mut");
        }
    }
}

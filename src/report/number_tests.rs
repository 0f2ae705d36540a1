//! Pins [`format_f64`] to polars' own CSV float formatting: the appender writes CSV without
//! polars, so a change of polars' float writer must fail here, not silently change files.

use super::*;
use crate::report::{read_csv, write_csv, Table};

/// Deterministic pseudo-random 64-bit words (SplitMix64).
fn splitmix(seed: u64, n: usize) -> Vec<u64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        })
        .collect()
}

/// Special values, powers of ten around the positional/scientific switch (1e-5, 1e15..1e17),
/// integers, short decimals, subnormals and random bit patterns.
fn values() -> Vec<f64> {
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.1,
        1.0 / 3.0,
        f64::MAX,
        f64::MIN,
        f64::MIN_POSITIVE,
        -f64::MIN_POSITIVE,
        f64::MIN_POSITIVE / 2.0,
        f64::MIN_POSITIVE - 5e-324,
        5e-324,
        -5e-324,
        1e-323,
        f64::EPSILON,
        123456789012345680.0,
        9007199254740993.0,
        9007199254740992.0,
        9007199254740991.0,
        0.00001,
        0.000009999999999999999,
        0.0001,
        f64::NAN,
        -f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for e in -330..=310 {
        let p = 10f64.powi(e);
        values.extend([p, 1.5 * p, -p, 9.999999 * p, p * (1.0 + f64::EPSILON)]);
        values.extend([p * (1.0 - f64::EPSILON / 2.0), 1.2345678901234567 * p]);
    }
    // Integers: small ones, and around the switch to scientific at 1e15..1e17 and 2^53.
    values.extend((-1000..=1000).map(f64::from));
    for base in [1e15, 1e16, 1e17, 9_007_199_254_740_992.0] {
        for k in -50..=50 {
            values.push(base + f64::from(k) * if base >= 1e16 { 2.0 } else { 1.0 });
            values.push(-(base + f64::from(k) * 16.0));
        }
        values.extend([base * 0.999_999_999_999_9, base * 1.5, base * 9.99]);
    }
    // Short decimals, as typed by people: k / 1000 and k / 10^6.
    values.extend((0..=5000).map(|k| f64::from(k) / 1000.0));
    values.extend((0..=2000).map(|k| -f64::from(k * 37) / 1e6));
    let words = splitmix(0x9E37_79B9_7F4A_7C15, 20_000);
    for &z in &words {
        values.push(f64::from_bits(z));
        values.push((z >> 11) as f64 / (1u64 << 40) as f64);
        // Subnormals: zero exponent, random mantissa, either sign.
        values.push(f64::from_bits(z & 0x800F_FFFF_FFFF_FFFF));
        // Random magnitudes within the positional range and around its edges.
        let unit = (z >> 11) as f64 / (1u64 << 53) as f64;
        values.push(10f64.powf(-7.0 + 25.0 * unit));
    }
    values
}

fn canon_nan(v: &[f64]) -> Vec<f64> {
    v.iter()
        .map(|x| if x.is_nan() { f64::NAN } else { *x })
        .collect()
}

/// [`format_f64`] equals polars' CSV float format on every value, and the text reads back to
/// the same bits.
#[test]
fn float_format_matches_polars() {
    let values = values();
    let t = Table::new().with("x", values.clone()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("f.csv");
    write_csv(&t, &p).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x"));
    assert_eq!(text.lines().count(), values.len() + 1);
    let mut mismatches = Vec::new();
    for (v, line) in values.iter().zip(lines) {
        let ours = format_f64(*v);
        if ours != line {
            mismatches.push(format!("{:#018x}: ours {ours}, polars {line}", v.to_bits()));
        }
        if !v.is_nan() {
            assert_eq!(line.parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
    }
    assert!(
        mismatches.is_empty(),
        "{} of {} values differ, e.g.\n{}",
        mismatches.len(),
        values.len(),
        mismatches[..mismatches.len().min(20)].join("\n")
    );
    assert!(read_csv(&p)
        .unwrap()
        .bit_eq(&Table::new().with("x", canon_nan(&values)).unwrap()));
}

#[test]
fn short_display_format() {
    assert_eq!(fmt_num(0.0), "0");
    assert_eq!(fmt_num(-0.0), "0");
    assert_eq!(fmt_num(1.0), "1.0000");
    assert_eq!(fmt_num(-0.00123456), "-0.0012");
    assert_eq!(fmt_num(9999.99999), "10000.0000");
    assert_eq!(fmt_num(12345.678), "1.235e4");
    assert_eq!(fmt_num(0.0009), "9.000e-4");
    assert_eq!(fmt_num(f64::NAN), "NaN");
    assert_eq!(fmt_num(f64::INFINITY), "inf");
}

#[test]
fn values_print_short_for_people() {
    assert_eq!(fmt_value(&toml::Value::Float(1e200)), "1e+200");
    assert_eq!(fmt_value(&toml::Value::Float(0.25)), "0.25");
    assert_eq!(fmt_value(&toml::Value::Float(2.0)), "2.0");
    assert_eq!(fmt_value(&toml::Value::Integer(7)), "7");
    assert_eq!(fmt_value(&toml::Value::String("qp".into())), "qp");
    assert_eq!(fmt_short(1e200), "1.000e200");
    assert_eq!(fmt_num(-1e200), "-1.000e200");
}

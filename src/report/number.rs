//! Number formatting: the float format of CSV files ([`format_f64`], polars' own) and the short
//! display formats of printed reports ([`fmt_num`]) and Markdown summaries ([`fmt_short`]).

/// Formats a float exactly as the polars CSV writer does: the shortest decimal that parses back
/// to the same `f64` (the closest one when several of that length do); positional with at
/// least one fractional digit when the decimal exponent `e` (value = d.ddd × 10^e) is in
/// `-5..=15`, scientific `d.ddde±x` otherwise; `NaN`, `inf`, `-inf` for the non-finite values;
/// `-0.0` keeps its sign. It is polars' own formatter (`zmij`, which polars' CSV serializer
/// calls per value); `number_tests` pins the two together.
pub fn format_f64(v: f64) -> String {
    let mut s = String::new();
    push_f64(&mut s, v);
    s
}

/// Appends [`format_f64`]`(v)` to `buf` without allocating (beyond `buf`'s growth).
#[inline]
pub fn push_f64(buf: &mut String, v: f64) {
    buf.push_str(zmij::Buffer::new().format(v));
}

/// Formats a number for printed reports and Markdown tables: `0`, four decimals for magnitudes
/// in `[1e-3, 1e4)`, else scientific with three decimals (`1.235e5`); `NaN`, `inf`, `-inf`.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if x.abs() >= 1e4 || x.abs() < 1e-3 {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

/// A number as Markdown summaries show it (a short, trimmed display style): 4 decimals without trailing zeros, scientific beyond
/// [1e-3, 1e5), `–` for NaN.
pub fn fmt_short(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else if x == 0.0 || (x.abs() >= 1e-3 && x.abs() < 1e5) {
        format!("{x:.4}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.3e}")
    }
}

/// A TOML value as printed for people (dry-run listings, string columns of mixed axes): a
/// string as is, a float in the tables' format ([`format_f64`]: `1e+200`, never its 200-digit
/// decimal), anything else (arrays included) in TOML notation.
pub fn fmt_value(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Float(x) => format_f64(*x),
        other => other.to_string(),
    }
}

#[cfg(test)]
#[path = "number_tests.rs"]
mod tests;

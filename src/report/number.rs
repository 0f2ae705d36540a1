//! Number formatting: the float format of CSV files ([`format_f64`], polars' own) and the short
//! display formats of printed reports ([`fmt_num`]) and Markdown summaries ([`fmt_short`]).

/// Formats a float exactly as the polars CSV writer does: the shortest decimal that parses back
/// to the same `f64`; positional with at least one fractional digit when the decimal exponent
/// `e` (value = d.ddd × 10^e) is in `-5..=15`, scientific `d.ddde±x` otherwise; `NaN`, `inf`,
/// `-inf` for the non-finite values; `-0.0` keeps its sign.
pub fn format_f64(v: f64) -> String {
    if v.is_nan() {
        return "NaN".to_owned();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf" } else { "-inf" }.to_owned();
    }
    // `{:e}` gives the shortest round-trip digits: "-1.2345e-7", "1e16", "0e0", "-0e0". When
    // several decimals of that length round-trip, polars (zmij) prints the one closest to the
    // exact binary value (ties to even), which is the correctly rounded one at that precision.
    let shortest = format!("{v:e}");
    let n_digits = shortest
        .split('e')
        .next()
        .unwrap_or("")
        .bytes()
        .filter(u8::is_ascii_digit)
        .count();
    let closest = format!("{v:.prec$e}", prec = n_digits.saturating_sub(1));
    let sci = if closest.parse::<f64>().map(f64::to_bits) == Ok(v.to_bits()) {
        closest
    } else {
        shortest
    };
    let (mantissa, exp) = sci.split_once('e').unwrap_or((sci.as_str(), "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let (sign, mantissa) = match mantissa.strip_prefix('-') {
        Some(m) => ("-", m),
        None => ("", mantissa),
    };
    if !(-5..=15).contains(&exp) {
        let exp_sign = if exp > 0 { "+" } else { "" };
        return format!("{sign}{mantissa}e{exp_sign}{exp}");
    }
    let digits: String = mantissa.chars().filter(|c| *c != '.').collect();
    let mut out = String::with_capacity(digits.len() + 8);
    out.push_str(sign);
    if exp >= 0 {
        let int_len = exp as usize + 1;
        if digits.len() <= int_len {
            out.push_str(&digits);
            out.extend(std::iter::repeat_n('0', int_len - digits.len()));
            out.push_str(".0");
        } else {
            out.push_str(&digits[..int_len]);
            out.push('.');
            out.push_str(&digits[int_len..]);
        }
    } else {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', (-exp - 1) as usize));
        out.push_str(&digits);
    }
    out
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

#[cfg(test)]
#[path = "number_tests.rs"]
mod tests;

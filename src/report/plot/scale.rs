//! How an axis maps values to ticks: plain numbers, integers, named categories or a
//! logarithmic scale.

/// The scale of one axis of a panel or a heat map.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Scale {
    /// Numbers, "nice" ticks chosen by plotters.
    #[default]
    Linear,
    /// Whole numbers (counts, link numbers): ticks only at integers, printed without a
    /// decimal point (`3`, not `3.0`).
    Integer,
    /// Named categories: the data are the positions `0, 1, …, n − 1`; the axis spans
    /// `[−0.5, n − 0.5]` and has one tick per category, labelled with its name.
    Categories(Vec<String>),
    /// Logarithmic (base 10): positive data only (others are not drawn); ticks are printed as
    /// the data values.
    Log,
}

impl Scale {
    /// The drawn coordinate of data value `v` (log10 for [`Scale::Log`], NaN for `v ≤ 0`).
    pub(super) fn forward(&self, v: f64) -> f64 {
        match self {
            Scale::Log if v > 0.0 => v.log10(),
            Scale::Log => f64::NAN,
            _ => v,
        }
    }

    /// A fixed range for the axis, in drawn coordinates, when the scale imposes one.
    pub(super) fn fixed_range(&self) -> Option<(f64, f64)> {
        match self {
            Scale::Categories(names) => Some((-0.5, names.len().max(1) as f64 - 0.5)),
            _ => None,
        }
    }

    /// The largest number of ticks for a drawn range `r` when `default` fit the space.
    pub(super) fn tick_count(&self, r: (f64, f64), default: usize) -> usize {
        match self {
            Scale::Categories(names) => names.len().max(1),
            // A unit step at most: no tick falls between two integers.
            // Up to 8 integers all get a tick even in a narrow panel.
            Scale::Integer => ((r.1 - r.0).floor().max(0.0) as usize + 1).clamp(1, default.max(8)),
            _ => default,
        }
    }

    /// The tick text at drawn coordinate `v`.
    pub(super) fn label(&self, v: f64) -> String {
        match self {
            Scale::Linear => plain_number(v),
            Scale::Integer => {
                let r = v.round();
                if (v - r).abs() < 1e-9 * v.abs().max(1.0) {
                    format!("{}", r as i64)
                } else {
                    String::new()
                }
            }
            Scale::Categories(names) => {
                let r = v.round();
                if (v - r).abs() < 1e-6 && r >= 0.0 && (r as usize) < names.len() {
                    names[r as usize].clone()
                } else {
                    String::new()
                }
            }
            Scale::Log => trim_number(10f64.powf(v)),
        }
    }
}

/// A tick number as short as it can be without losing the tick's digits: rounded to 10
/// significant digits (hides binary noise such as `0.30000000000000004`), no trailing `.0`.
fn plain_number(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    let rounded: f64 = format!("{v:.9e}").parse().unwrap_or(v);
    let mag = rounded.abs();
    if mag != 0.0 && !(1e-5..1e9).contains(&mag) {
        return trim_number(rounded);
    }
    format!("{rounded}")
}

/// A tick number in at most four significant digits, without trailing zeros (`0.5`, `3`,
/// `1200`, `1.5e-5`).
pub(super) fn trim_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            v.to_string()
        };
    }
    let mag = v.abs();
    if !(1e-4..1e6).contains(&mag) {
        let s = format!("{v:.3e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let decimals = (3 - mag.log10().floor() as i32).clamp(0, 8) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::{trim_number, Scale};

    #[test]
    fn integers_print_without_a_decimal_point_and_only_at_integers() {
        assert_eq!(Scale::Integer.label(3.0), "3");
        assert_eq!(Scale::Integer.label(3.5), "");
        assert_eq!(Scale::Integer.tick_count((2.85, 6.15), 12), 4);
    }

    #[test]
    fn categories_label_their_positions_only() {
        let s = Scale::Categories(vec!["paper".into(), "ends".into()]);
        assert_eq!(s.label(0.0), "paper");
        assert_eq!(s.label(1.0), "ends");
        assert_eq!(s.label(-0.5), "");
        assert_eq!(s.label(2.0), "");
        assert_eq!(s.fixed_range(), Some((-0.5, 1.5)));
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(trim_number(0.5), "0.5");
        assert_eq!(trim_number(3.0), "3");
        assert_eq!(trim_number(1.23456), "1.235");
        assert_eq!(trim_number(1234.0), "1234");
        assert_eq!(trim_number(1.5e-5), "1.5e-5");
        assert_eq!(Scale::Log.label(2.0), "100");
        assert_eq!(Scale::Linear.label(700000.0), "700000");
        assert_eq!(Scale::Linear.label(0.1 + 0.2), "0.3");
        assert_eq!(Scale::Linear.label(1000.25), "1000.25");
        assert!(Scale::Log.forward(0.0).is_nan());
    }
}

//! What the issue-23 harnesses (`solver_efficiency`, `tuning_protocol`) share: the `SHARD`
//! setting and the design label of a main-study case.

use usm_study::study::doe::Case;

/// `SHARD=i/n` from the environment: run only the cases whose id is `i` modulo `n` (one
/// process per core). Unset: `(0, 1)`, every case. A malformed value is an error, not a
/// silent full run.
pub fn shard() -> Result<(usize, usize), String> {
    let Ok(s) = std::env::var("SHARD") else {
        return Ok((0, 1));
    };
    s.split_once('/')
        .and_then(|(i, n)| Some((i.parse::<usize>().ok()?, n.parse::<usize>().ok()?)))
        .filter(|(i, n)| i < n)
        .ok_or(format!("SHARD={s}: expected i/n with 0 <= i < n"))
}

/// The main study's axes of `case`: thruster rule, link count and longitudinal offset [m].
pub fn design_axes(case: &Case) -> (String, i64, f64) {
    (
        case.values[0].as_str().unwrap_or_default().to_string(),
        case.values[1]
            .as_integer()
            .or(case.values[1].as_float().map(|v| v as i64))
            .unwrap_or_default(),
        case.values[2].as_float().unwrap_or_default(),
    )
}

//! The USM paper's transport claims (section VI-B, Fig. 8; issue 26 item 2) under the printed
//! and the adopted reading, each with and without cross-flow lift: `claims.md` of
//! `usm-study paper readings` ([`run_readings_and_claims`]). Each claim is judged by a stated
//! rule ([`CLAIMS`]) from the readings runs' metrics (the trajectory figures among them are
//! defined in [`super::transport_metrics`]); a cell shows the numbers (Method 1 / Method 2)
//! and whether they support the claim.

use std::fmt::Write as _;

use std::path::Path;

use super::readings::{
    pair, run_readings, short, ReadingRun, ReadingsOutcome, TransportReading, LIFT_SLOPE,
};
use crate::control::transport::TransportMethod;
use crate::pipeline::error::PipelineError;
use crate::report::{atomic_write, MarkdownTable};

/// [`run_readings`], then `out/claims.md` ([`claims_md`]) from its outcome.
pub fn run_readings_and_claims(
    out: &Path,
    on_run: &mut dyn FnMut(&ReadingRun),
) -> Result<ReadingsOutcome, PipelineError> {
    let outcome = run_readings(out, on_run)?;
    atomic_write(&out.join("claims.md"), claims_md(&outcome).as_bytes())?;
    Ok(outcome)
}

/// One claim of the paper's transport section and the rule that judges it from the two
/// methods' runs (Method 1, Method 2): the cell text and whether the numbers support it.
#[derive(Clone, Copy)]
pub struct Claim {
    /// The claim, in the paper's words where it has them.
    pub text: &'static str,
    /// The rule, stated for the table.
    pub rule: &'static str,
    /// `(cell, supported)` for Method 1's and Method 2's runs.
    pub judge: fn(&ReadingRun, &ReadingRun) -> (String, bool),
}

/// A convergence time with "not converged" as +∞ (for the comparisons).
fn time_or_inf(r: &ReadingRun, key: &str) -> f64 {
    let t = r.get(key);
    if t.is_nan() || r.failed {
        f64::INFINITY
    } else {
        t
    }
}

/// `t0/t1` of one run ([`short`], `–` not converged).
fn times(r: &ReadingRun) -> String {
    format!(
        "{}/{}",
        short(r.get("seg0_convergence_time")),
        short(r.get("seg1_convergence_time"))
    )
}

/// The larger of the two segments' overshoots [m].
fn overshoot(r: &ReadingRun) -> f64 {
    r.get("seg0_overshoot").max(r.get("seg1_overshoot"))
}

/// Thrust below which cruise counts as "far below" the 40 N limit [N] (half of it).
pub const FAR_BELOW_N: f64 = 20.0;

/// "Slightly more" effort: Method 2's `effort_abs` above Method 1's by at most this fraction.
pub const SLIGHTLY_MORE: f64 = 0.25;

/// The paper's transport claims (USM section VI-B), in its order.
pub const CLAIMS: [Claim; 8] = [
    Claim {
        text: "both methods converge to the path and complete the 180° turn",
        rule: r"\|e_y\| < 0.1 m and staying, on both segments, for both methods",
        judge: |a, b| {
            let yes = |r: &ReadingRun| if r.converged() { "yes" } else { "no" };
            (
                format!("{} / {}", yes(a), yes(b)),
                a.converged() && b.converged(),
            )
        },
    },
    Claim {
        text: "on the path before the turn at 95 s and again by 140 s (Fig. 8a/b)",
        rule: "both methods: segment 0 converged before 95 s, segment 1 within 45 s of the turn",
        judge: |a, b| {
            let ok = |r: &ReadingRun| {
                time_or_inf(r, "seg0_convergence_time") < 95.0
                    && time_or_inf(r, "seg1_convergence_time") < 45.0
            };
            (format!("{} · {}", times(a), times(b)), ok(a) && ok(b))
        },
    },
    Claim {
        text: "Method 2 provides faster convergence to the desired path",
        rule: "Method 2 no later on either segment and earlier on one (not converged = never)",
        judge: |a, b| {
            let k = ["seg0_convergence_time", "seg1_convergence_time"];
            let (t1, t2) = (k.map(|k| time_or_inf(a, k)), k.map(|k| time_or_inf(b, k)));
            let ok = t2.iter().zip(&t1).all(|(x, y)| x <= y)
                && t2.iter().zip(&t1).any(|(x, y)| x < y);
            (format!("{} · {}", times(a), times(b)), ok)
        },
    },
    Claim {
        text: "Method 2 converges with less overshoot than Method 1",
        rule: "larger of the two segments' overshoot [m]: Method 2 smaller",
        judge: |a, b| {
            let (x, y) = (overshoot(a), overshoot(b));
            (pair(x, y), y < x)
        },
    },
    Claim {
        text: "Method 2's back end follows the front's trajectory more closely (Method 1: pendulum-like)",
        rule: "`tail_deviation_rms` [m]: Method 2 smaller",
        judge: |a, b| {
            let (x, y) = (a.get("tail_deviation_rms"), b.get("tail_deviation_rms"));
            (pair(x, y), y < x)
        },
    },
    Claim {
        text: "Method 2's faster convergence needs a higher end-effector sideways velocity (Fig. 8c/d)",
        rule: "`ee_sway_peak` [m/s]: Method 2 larger",
        judge: |a, b| {
            let (x, y) = (a.get("ee_sway_peak"), b.get("ee_sway_peak"));
            (pair(x, y), y > x)
        },
    },
    Claim {
        text: "thrust far below the 40 N limit, except in the 180° turn",
        rule: "`cruise_peak_thrust` [N] (outside the start and turn transients) ≤ 20 N for both",
        judge: |a, b| {
            let (x, y) = (a.get("cruise_peak_thrust"), b.get("cruise_peak_thrust"));
            (pair(x, y), x <= FAR_BELOW_N && y <= FAR_BELOW_N)
        },
    },
    Claim {
        text: "Method 2 uses slightly more thruster effort",
        rule: "`effort_abs` [N·s]: Method 2 above Method 1 by more than 0 and at most 25 %",
        judge: |a, b| {
            let (x, y) = (a.get("effort_abs"), b.get("effort_abs"));
            let rel = y / x - 1.0;
            (
                format!("{} ({:+.0} %)", pair(x, y), 100.0 * rel),
                rel > 0.0 && rel <= SLIGHTLY_MORE,
            )
        },
    },
];

/// Every claim's `(cell, supported)` for Method 1's run `a` and Method 2's run `b`.
pub fn judge_claims(a: &ReadingRun, b: &ReadingRun) -> Vec<(String, bool)> {
    CLAIMS.iter().map(|c| (c.judge)(a, b)).collect()
}

/// One column of the claims table: a reading, a lift slope and both methods' runs.
pub struct ClaimColumn<'a> {
    /// Column header.
    pub label: String,
    /// Method 1's run.
    pub m1: &'a ReadingRun,
    /// Method 2's run.
    pub m2: &'a ReadingRun,
}

/// How a column applies lift: none, at the chain's free trailing face (the model), or at
/// every body's trailing face (`hydro.lift_every_body`, an upper bound).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lift {
    Off,
    FreeFace,
    EveryBody,
}

/// The six columns: printed and adopted reading, each without lift, with lift, and with lift
/// at every body (those of them the outcome holds).
pub fn claim_columns(o: &ReadingsOutcome) -> Vec<ClaimColumn<'_>> {
    let adopted = o.adopted.unwrap_or(TransportReading::DEFAULT);
    let mut cols = Vec::new();
    for (name, reading) in [("printed", TransportReading::PRINTED), ("adopted", adopted)] {
        for lift in [Lift::Off, Lift::FreeFace, Lift::EveryBody] {
            let runs = if lift == Lift::Off {
                &o.runs
            } else {
                &o.lifted
            };
            let find = |m: TransportMethod| {
                runs.iter().find(|r| {
                    r.reading == reading
                        && r.method == m
                        && r.yaw_gains_of == m
                        && r.lift_every_body == (lift == Lift::EveryBody)
                })
            };
            if let (Some(m1), Some(m2)) = (
                find(TransportMethod::Method1),
                find(TransportMethod::Method2),
            ) {
                let key = reading.key();
                let label = match lift {
                    Lift::Off => format!("{name} `{key}`, no lift"),
                    Lift::FreeFace => format!("{name} `{key}`, lift C_Lα = {LIFT_SLOPE}"),
                    Lift::EveryBody => {
                        format!("{name} `{key}`, lift C_Lα = {LIFT_SLOPE} at every body")
                    }
                };
                cols.push(ClaimColumn { label, m1, m2 });
            }
        }
    }
    cols
}

/// `claims.md`: the claims table, which claims each column supports, and the runs' numbers.
pub fn claims_md(o: &ReadingsOutcome) -> String {
    let cols = claim_columns(o);
    let mut md = String::from(
        "# The paper's transport claims under the printed and the adopted reading, with and without lift\n\n\
         Regenerate with `cargo run --release -- paper readings --out results/paper/readings`.\n\
         Table III gains, QP allocation, 170 s, turn commanded at 95 s. Each cell: Method 1 /\n\
         Method 2 (convergence times: segment 0/segment 1 [s], segment 1 counted from the turn,\n\
         – = not converged), then **yes** if the numbers support the claim by the rule given, no\n\
         if not. Lift: slender-body cross-flow lift at the chain's free trailing face\n\
         (`hydro.lift_slope`, docs/model.md §2 \"Lift\"); \"at every body\": at each body's\n\
         trailing face (`hydro.lift_every_body`), an upper bound.\n\n",
    );
    let mut header = vec!["claim (USM §VI-B)".to_string(), "rule".to_string()];
    header.extend(cols.iter().map(|c| c.label.clone()));
    let mut t = MarkdownTable::new(header);
    let verdicts: Vec<Vec<(String, bool)>> =
        cols.iter().map(|c| judge_claims(c.m1, c.m2)).collect();
    for (i, claim) in CLAIMS.iter().enumerate() {
        let mut row = vec![claim.text.to_string(), claim.rule.to_string()];
        for v in &verdicts {
            let (cell, ok) = &v[i];
            row.push(format!("{cell} {}", if *ok { "**yes**" } else { "no" }));
        }
        t.row(row);
    }
    md.push_str(&t.finish());
    md.push_str("\nClaims each column supports (numbered as in the table):\n\n");
    for (c, v) in cols.iter().zip(&verdicts) {
        let yes: Vec<String> = v
            .iter()
            .enumerate()
            .filter(|(_, (_, ok))| *ok)
            .map(|(i, _)| (i + 1).to_string())
            .collect();
        let _ = writeln!(
            md,
            "- {}: {} of {} ({})",
            c.label,
            yes.len(),
            CLAIMS.len(),
            if yes.is_empty() {
                "none".into()
            } else {
                yes.join(", ")
            }
        );
    }
    md.push_str("\n## The runs' numbers (Method 1 / Method 2)\n\n");
    let mut header = vec!["metric".to_string()];
    header.extend(cols.iter().map(|c| c.label.clone()));
    let mut t = MarkdownTable::new(header);
    for (name, key) in [
        ("seg 0 convergence [s]", "seg0_convergence_time"),
        ("seg 1 convergence [s]", "seg1_convergence_time"),
        ("overshoot seg 0 [m]", "seg0_overshoot"),
        ("overshoot seg 1 [m]", "seg1_overshoot"),
        ("final cross-track e_y [m]", "final_cross_track"),
        ("base RMS after convergence [m]", "base_cross_track_rms"),
        ("saturated fraction", "saturation_fraction"),
        ("thruster energy [J]", "thruster_energy"),
    ] {
        let mut row = vec![name.to_string()];
        row.extend(cols.iter().map(|c| pair(c.m1.get(key), c.m2.get(key))));
        t.row(row);
    }
    md.push_str(&t.finish());
    md
}

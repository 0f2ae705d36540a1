//! The transport readings comparison (`usm-study paper readings`, issue 10 item 4): the
//! paper's text leaves several choices of transport mode's base control (USM-33/34) and yaw law
//! (USM-40/41) open; this pipeline runs both Table III methods under every combination of them
//! (a [`TransportReading`]) with the Table III gains unchanged, and writes
//! `readings.csv` (one row per reading and method), `readings.md` (one row per reading, the
//! two methods side by side, the reading adopted as default marked) and `claims.md`.
//!
//! The choices (the printed text first):
//! - **n in USM-33**: `τ_c = M_11 a^b + n` as printed ("we apply the dynamic control law in
//!   (33)"), or without `n` as the paper's own work-mode simulation does;
//! - **the uncommanded axes** (sway, heave, roll, pitch): `a_i = 0` as printed ("the remaining
//!   acceleration components are set to zero"), or USM-34 with a zero reference,
//!   `a_i = −K_p,i v_b,i` with the paper's `K_p = diag(1,1,1,0,1,1)`;
//! - **ψ̇ in USM-41**: the rate of ψ, the front link's heading (the paper defines ψ so), or the
//!   base body yaw rate;
//! - **ψ̇_r in USM-41**: the rate error `ψ̇ − ψ̇_r` as printed, or `ψ̇` alone;
//! - **USM-40**: PI as printed, or PD as the OCR'd Table III header "k_1p, k_1d" suggests.
//!
//! Each run lasts 170 s (the paper's 140 s leave only 45 s after the turn commanded at 95 s).
//! Beside the scenario metrics, three figures are computed from the trajectory
//! (`tail_deviation_rms`, `cruise_peak_thrust`, `ee_sway_peak`; defined in
//! [`super::transport_metrics`]). The printed and the adopted reading are also run with
//! cross-flow lift ([`LIFT_SLOPE`], docs/model.md §2 "Lift"); `claims.md`, written by
//! `super::transport_claims::run_readings_and_claims`, judges the paper's transport claims
//! under them.

use std::fmt::Write as _;
use std::path::Path;

use super::transport_metrics::{cruise_peak_thrust, ee_sway_peak, tail_deviation_rms};
use crate::control::transport::{SurgeLaw, TransportGains, TransportMethod, YawRateSource};
use crate::outcome::run_scenario;
use crate::pipeline::error::{create_dir, PipelineError};
use crate::report::{atomic_write, fmt_num, MarkdownTable};
use crate::scenario::{load_table, parse_table, resolve_design};

/// Simulated time of each readings run [s].
pub const READINGS_DURATION: f64 = 170.0;

/// One reading of the transport-mode control laws the paper leaves open (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TransportReading {
    /// USM-33 includes `n` (`base_control.nonlinear`).
    pub nonlinear: bool,
    /// `a_i = −K_p,i v_b,i` on the uncommanded axes instead of 0
    /// (`base_control.uncommanded_feedback`).
    pub uncommanded_feedback: bool,
    /// ψ̇ of USM-41 (`control.yaw_rate_source`).
    pub yaw_rate_source: YawRateSource,
    /// USM-41 damps `ψ̇ − ψ̇_r` (true) or `ψ̇` (`control.yaw_rate_reference`).
    pub yaw_rate_reference: bool,
    /// Form of USM-40 (`control.surge_law`).
    pub surge_law: SurgeLaw,
}

impl TransportReading {
    /// The reading of the printed text: `n` included, the other accelerations zero, ψ̇ the
    /// front heading's rate, `ψ̇ − ψ̇_r`, PI surge law.
    pub const PRINTED: Self = Self {
        nonlinear: true,
        uncommanded_feedback: false,
        yaw_rate_source: YawRateSource::FrontHeading,
        yaw_rate_reference: true,
        surge_law: SurgeLaw::ProportionalIntegral,
    };

    /// The project's default reading (the scenario defaults of
    /// [`crate::control::dynamic::DynamicGains::transport`] and
    /// [`crate::control::transport::TransportGains`]): the printed one without `n` and with
    /// zero-velocity feedback on the uncommanded axes.
    pub const DEFAULT: Self = Self {
        nonlinear: false,
        uncommanded_feedback: true,
        ..Self::PRINTED
    };

    /// All 32 readings, the printed one first, then by the number of departures from it.
    pub fn all() -> Vec<Self> {
        let mut v = Vec::with_capacity(32);
        for bits in 0u8..32 {
            let flip = |k: u8| bits & (1 << k) != 0;
            v.push(Self {
                nonlinear: !flip(0),
                uncommanded_feedback: flip(1),
                yaw_rate_source: if flip(2) {
                    YawRateSource::BaseYawRate
                } else {
                    YawRateSource::FrontHeading
                },
                yaw_rate_reference: !flip(3),
                surge_law: if flip(4) {
                    SurgeLaw::ProportionalDerivative
                } else {
                    SurgeLaw::ProportionalIntegral
                },
            });
        }
        v.sort_by_key(|r| r.departures().len());
        v
    }

    /// The choices in which this reading departs from the printed text, as short phrases.
    pub fn departures(&self) -> Vec<&'static str> {
        let p = Self::PRINTED;
        let mut d = Vec::new();
        if self.nonlinear != p.nonlinear {
            d.push("no n");
        }
        if self.uncommanded_feedback != p.uncommanded_feedback {
            d.push("−K_p v on sway/heave/pitch");
        }
        if self.yaw_rate_source != p.yaw_rate_source {
            d.push("ψ̇ = base yaw rate");
        }
        if self.yaw_rate_reference != p.yaw_rate_reference {
            d.push("no ψ̇_r");
        }
        if self.surge_law != p.surge_law {
            d.push("PD surge");
        }
        d
    }

    /// A compact identifier for tables and CSV: `n1-a0-front-ref1-pi` (n included, zero on the
    /// uncommanded axes, front heading rate, `ψ̇_r` used, PI).
    pub fn key(&self) -> String {
        format!(
            "n{}-{}-{}-ref{}-{}",
            u8::from(self.nonlinear),
            if self.uncommanded_feedback {
                "kp"
            } else {
                "a0"
            },
            match self.yaw_rate_source {
                YawRateSource::FrontHeading => "front",
                YawRateSource::BaseYawRate => "base",
            },
            u8::from(self.yaw_rate_reference),
            match self.surge_law {
                SurgeLaw::ProportionalIntegral => "pi",
                SurgeLaw::ProportionalDerivative => "pd",
            }
        )
    }

    /// Write this reading's keys into a scenario table (`base_control.nonlinear`,
    /// `base_control.uncommanded_feedback`, `control.yaw_rate_source`,
    /// `control.yaw_rate_reference`, `control.surge_law`).
    pub fn apply(&self, table: &mut toml::Table) {
        let mut set = |section: &str, key: &str, value: toml::Value| {
            if let Some(t) = table
                .entry(section)
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                .as_table_mut()
            {
                t.insert(key.into(), value);
            }
        };
        set(
            "base_control",
            "nonlinear",
            toml::Value::Boolean(self.nonlinear),
        );
        set(
            "base_control",
            "uncommanded_feedback",
            toml::Value::Boolean(self.uncommanded_feedback),
        );
        set(
            "control",
            "yaw_rate_source",
            toml::Value::String(wire_name(&self.yaw_rate_source)),
        );
        set(
            "control",
            "yaw_rate_reference",
            toml::Value::Boolean(self.yaw_rate_reference),
        );
        set(
            "control",
            "surge_law",
            toml::Value::String(wire_name(&self.surge_law)),
        );
    }
}

/// The scenario-file (serde) name of a unit enum variant, e.g. `"front_heading"`.
fn wire_name<T: serde::Serialize>(x: &T) -> String {
    toml::Value::try_from(x)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// The lift slope `hydro.lift_slope` of the runs with lift (slender-body theory's `C_Lα`,
/// docs/model.md §2 "Lift"): the printed and the adopted reading are also run with it.
pub const LIFT_SLOPE: f64 = 2.0;

/// The metrics of one run shown in the tables, in CSV column order (scenario metrics, then the
/// three computed by [`super::transport_metrics`]).
pub const READING_KEYS: [&str; 14] = [
    "converged",
    "seg0_convergence_time",
    "seg1_convergence_time",
    "seg0_overshoot",
    "seg1_overshoot",
    "base_cross_track_rms",
    "tail_deviation_rms",
    "final_cross_track",
    "peak_thrust",
    "cruise_peak_thrust",
    "ee_sway_peak",
    "saturation_fraction",
    "effort_abs",
    "thruster_energy",
];

/// One run of the comparison: a reading, a method and its metrics (keys of [`READING_KEYS`]).
#[derive(Clone, Debug)]
pub struct ReadingRun {
    /// The reading.
    pub reading: TransportReading,
    /// The Table III method (its row's surge source, surge gains and `k_ψ`).
    pub method: TransportMethod,
    /// The Table III row whose yaw gains `k_6p`, `k_6d` and look-ahead Δ the run used (the
    /// method's own, except in the gain-swap runs).
    pub yaw_gains_of: TransportMethod,
    /// `hydro.lift_slope` of the run (0: no lift, the default model).
    pub lift_slope: f64,
    /// `hydro.lift_every_body` of the run (lift at every body's trailing face).
    pub lift_every_body: bool,
    /// Whether the run stopped early (then its metrics cover the run up to the failure).
    pub failed: bool,
    /// `(key, value)` in the order of [`READING_KEYS`]; NaN where undefined.
    pub metrics: Vec<(&'static str, f64)>,
}

impl ReadingRun {
    /// A metric of [`READING_KEYS`] (NaN if unknown).
    pub fn get(&self, key: &str) -> f64 {
        self.metrics
            .iter()
            .find(|(k, _)| *k == key)
            .map_or(f64::NAN, |(_, v)| *v)
    }

    /// Converged on every segment without stopping early.
    pub fn converged(&self) -> bool {
        !self.failed && self.get("converged") == 1.0
    }
}

/// What [`run_readings`] found.
#[derive(Clone, Debug)]
pub struct ReadingsOutcome {
    /// Every run, readings in [`TransportReading::all`] order, Method 1 then Method 2.
    pub runs: Vec<ReadingRun>,
    /// Under the adopted reading (or [`TransportReading::DEFAULT`] if none), each method with
    /// the other method's yaw gains and look-ahead: separates what the surge source (the
    /// methods' stated difference) does from what the Table III yaw gains do.
    pub gain_swaps: Vec<ReadingRun>,
    /// The reading closest to the printed text (fewest departures; ties: the earlier in
    /// [`TransportReading::all`]) under which both methods converge, if any.
    pub adopted: Option<TransportReading>,
    /// The printed reading, then the adopted one (or [`TransportReading::DEFAULT`]), each
    /// method, with cross-flow lift of slope [`LIFT_SLOPE`] at the chain's free trailing face,
    /// then the same at every body's trailing face (`hydro.lift_every_body`, an upper bound).
    pub lifted: Vec<ReadingRun>,
}

/// The preset of a Table III method.
fn preset(method: TransportMethod) -> &'static str {
    match method {
        TransportMethod::Method1 => "transport-method1",
        TransportMethod::Method2 => "transport-method2",
    }
}

/// Run one method under one reading (`READINGS_DURATION` s, QP allocation, the method's
/// preset otherwise unchanged); with `yaw_gains_of`, the yaw law's gains and the look-ahead
/// (`k_6p`, `k_6d`, Δ) are those of that method's Table III row instead of its own.
pub fn run_reading(
    reading: TransportReading,
    method: TransportMethod,
    yaw_gains_of: Option<TransportMethod>,
) -> Result<ReadingRun, PipelineError> {
    run_reading_with(reading, method, yaw_gains_of, &[])
}

/// [`run_reading`] with further scenario keys `(section, key, value)` set last (e.g.
/// `("hydro", "lift_slope", 2.0.into())`, `("control", "k_6p", 0.13.into())`).
pub fn run_reading_with(
    reading: TransportReading,
    method: TransportMethod,
    yaw_gains_of: Option<TransportMethod>,
    overrides: &[(&str, &str, toml::Value)],
) -> Result<ReadingRun, PipelineError> {
    let (mut table, src) = load_table(preset(method))?;
    if let Some(s) = table.get_mut("scenario").and_then(|s| s.as_table_mut()) {
        s.insert("duration".into(), toml::Value::Float(READINGS_DURATION));
    }
    reading.apply(&mut table);
    if let (Some(other), Some(c)) = (
        yaw_gains_of,
        table.get_mut("control").and_then(|c| c.as_table_mut()),
    ) {
        let g = TransportGains::preset(other);
        for (k, v) in [
            ("k_6p", g.k_6p),
            ("k_6d", g.k_6d),
            ("look_ahead", g.look_ahead),
        ] {
            c.insert(k.into(), toml::Value::Float(v));
        }
    }
    for (section, key, value) in overrides {
        if let Some(t) = table
            .entry(*section)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
        {
            t.insert((*key).into(), value.clone());
        }
    }
    let mut file = parse_table(&table, &src)?;
    // A reproduction shows the whole run, whatever its [success] verdict.
    file.success.stop_on_failure = false;
    let v = resolve_design(&file, &src)?;
    let r = run_scenario(&v, &file)?;
    let path = file.path.clone().unwrap_or_default();
    let metrics = READING_KEYS
        .iter()
        .map(|&k| {
            let x = match k {
                "tail_deviation_rms" => tail_deviation_rms(&r, &path),
                "cruise_peak_thrust" => cruise_peak_thrust(&r),
                "ee_sway_peak" => ee_sway_peak(&r),
                _ => r.metric(k).unwrap_or(f64::NAN),
            };
            (k, x)
        })
        .collect();
    Ok(ReadingRun {
        reading,
        method,
        yaw_gains_of: yaw_gains_of.unwrap_or(method),
        lift_slope: file.hydro.lift_slope,
        lift_every_body: file.hydro.lift_every_body,
        failed: r.failure.is_some(),
        metrics,
    })
}

/// Run both Table III methods under every [`TransportReading`], write `out/readings.csv` and
/// `out/readings.md`, and report each run through `on_run`. A run that stops early is a row
/// (not converged), not an error.
pub fn run_readings(
    out: &Path,
    on_run: &mut dyn FnMut(&ReadingRun),
) -> Result<ReadingsOutcome, PipelineError> {
    create_dir(out)?;
    let mut runs = Vec::new();
    let methods = [TransportMethod::Method1, TransportMethod::Method2];
    for reading in TransportReading::all() {
        for method in methods {
            let run = run_reading(reading, method, None)?;
            on_run(&run);
            runs.push(run);
        }
    }
    let adopted = TransportReading::all().into_iter().find(|r| {
        let both: Vec<&ReadingRun> = runs.iter().filter(|x| x.reading == *r).collect();
        both.len() == 2 && both.iter().all(|x| x.converged())
    });
    let mut gain_swaps = Vec::new();
    for (method, other) in [(methods[0], methods[1]), (methods[1], methods[0])] {
        let run = run_reading(
            adopted.unwrap_or(TransportReading::DEFAULT),
            method,
            Some(other),
        )?;
        on_run(&run);
        gain_swaps.push(run);
    }
    let mut lifted = Vec::new();
    for every in [false, true] {
        let lift = [
            ("hydro", "lift_slope", toml::Value::Float(LIFT_SLOPE)),
            ("hydro", "lift_every_body", toml::Value::Boolean(every)),
        ];
        for reading in [
            TransportReading::PRINTED,
            adopted.unwrap_or(TransportReading::DEFAULT),
        ] {
            for method in methods {
                let run = run_reading_with(reading, method, None, &lift)?;
                on_run(&run);
                lifted.push(run);
            }
        }
    }
    let outcome = ReadingsOutcome {
        runs,
        gain_swaps,
        adopted,
        lifted,
    };
    atomic_write(&out.join("readings.csv"), readings_csv(&outcome).as_bytes())?;
    atomic_write(&out.join("readings.md"), readings_md(&outcome).as_bytes())?;
    Ok(outcome)
}

/// `readings.csv`: one row per reading and method.
pub fn readings_csv(o: &ReadingsOutcome) -> String {
    let mut s = String::from(
        "reading,departures,nonlinear,uncommanded_feedback,yaw_rate_source,\
         yaw_rate_reference,surge_law,method,yaw_gains_of,lift_slope,lift_every_body,failed",
    );
    for k in READING_KEYS {
        let _ = write!(s, ",{k}");
    }
    s.push('\n');
    for r in o.runs.iter().chain(&o.gain_swaps).chain(&o.lifted) {
        let g = r.reading;
        let _ = write!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            g.key(),
            g.departures().len(),
            g.nonlinear,
            g.uncommanded_feedback,
            wire_name(&g.yaw_rate_source),
            g.yaw_rate_reference,
            wire_name(&g.surge_law),
            wire_name(&r.method),
            wire_name(&r.yaw_gains_of),
            r.lift_slope,
            r.lift_every_body,
            r.failed
        );
        for (_, v) in &r.metrics {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    s
}

/// A number with three significant digits (no exponent below 1e5; `–` for NaN, `0` for 0).
pub(crate) fn short(x: f64) -> String {
    if x.is_nan() {
        return "–".into();
    }
    if x == 0.0 || x.abs() >= 1e5 || x.abs() < 1e-3 {
        return fmt_num(x);
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

/// `a / b`, each [`short`].
pub(crate) fn pair(a: f64, b: f64) -> String {
    format!("{} / {}", short(a), short(b))
}

/// `readings.md`: the readings table (Method 1 / Method 2 in each cell).
pub fn readings_md(o: &ReadingsOutcome) -> String {
    let mut md = String::from(
        "# Transport readings: the paper's two methods under every reading\n\n\
         Regenerate with `cargo run --release -- paper readings --out results/paper/readings`.\n\
         USM Table III gains unchanged, QP allocation, 170 s, turn commanded at 95 s. Each cell\n\
         is **Method 1 / Method 2**; – = not converged (|e_y| < 0.1 m and staying) or undefined.\n\
         Convergence times per segment [s] (segment 1 counted from the turn command);\n\
         overshoot = the larger of the two segments' [m]; tail = `tail_deviation_rms` [m] (the\n\
         back end's RMS lateral distance from the front's track on segment 0); base RMS =\n\
         `base_cross_track_rms` [m] after convergence; cruise peak = the largest thrust outside\n\
         the start (t < 2 s) and turn (30 s) transients [N]; effort = `effort_abs` [N·s].\n\n",
    );
    let _ = writeln!(
        md,
        "Printed text: `{}` (n in USM-33, the other accelerations zero, ψ̇ of the front \
         heading, ψ̇ − ψ̇_r, PI surge). Adopted default: **{}**.\n",
        TransportReading::PRINTED.key(),
        o.adopted
            .map_or("none: no reading makes both methods converge".into(), |r| {
                format!("`{}`", r.key())
            })
    );
    let mut t = MarkdownTable::new([
        "reading",
        "departures from the text",
        "converged",
        "seg 0 conv. [s]",
        "seg 1 conv. [s]",
        "overshoot [m]",
        "tail [m]",
        "base RMS [m]",
        "cruise peak [N]",
        "saturated",
        "effort [N·s]",
    ]);
    for reading in TransportReading::all() {
        let find = |m| {
            o.runs
                .iter()
                .find(|r| r.reading == reading && r.method == m)
        };
        let (Some(a), Some(b)) = (
            find(TransportMethod::Method1),
            find(TransportMethod::Method2),
        ) else {
            continue;
        };
        let cell = |k: &str| pair(a.get(k), b.get(k));
        let overshoot = |r: &ReadingRun| r.get("seg0_overshoot").max(r.get("seg1_overshoot"));
        let yes = |r: &ReadingRun| if r.converged() { "yes" } else { "no" };
        let mark = if Some(reading) == o.adopted {
            " **(adopted)**"
        } else if reading == TransportReading::PRINTED {
            " (printed)"
        } else {
            ""
        };
        let dep = reading.departures();
        t.row([
            format!("`{}`{mark}", reading.key()),
            if dep.is_empty() {
                "–".to_string()
            } else {
                dep.join(", ")
            },
            format!("{} / {}", yes(a), yes(b)),
            cell("seg0_convergence_time"),
            cell("seg1_convergence_time"),
            pair(overshoot(a), overshoot(b)),
            cell("tail_deviation_rms"),
            cell("base_cross_track_rms"),
            cell("cruise_peak_thrust"),
            cell("saturation_fraction"),
            cell("effort_abs"),
        ]);
    }
    md.push_str(&t.finish());
    swap_table(&mut md, o);
    md
}

/// The gain-swap section of `readings.md`: each method with its own and with the other
/// row's yaw gains (`k_6p`, `k_6d`, Δ), under the adopted reading.
fn swap_table(md: &mut String, o: &ReadingsOutcome) {
    let reading = o.adopted.unwrap_or(TransportReading::DEFAULT);
    let _ = writeln!(
        md,
        "\n## Surge source or yaw gains? (reading `{}`)\n\n\
         The methods differ in whose surge USM-40 regulates (Method 1 the front's, Method 2 the\n\
         base's) and in their Table III yaw gains and look-ahead (Method 1: k_6p = 0.13,\n\
         k_6d = 0.12, Δ = 3 m; Method 2: 0.01, 0.2, 2 m). Swapping the yaw gains and Δ\n\
         between them shows which of the two makes the difference.\n",
        reading.key()
    );
    let mut t = MarkdownTable::new([
        "surge source",
        "yaw gains and Δ",
        "converged",
        "seg 0 / seg 1 conv. [s]",
        "overshoot seg 0 / seg 1 [m]",
        "tail [m]",
        "effort [N·s]",
    ]);
    let own = o.runs.iter().filter(|r| r.reading == reading);
    for r in own.chain(&o.gain_swaps) {
        let name = |m: TransportMethod| match m {
            TransportMethod::Method1 => "Method 1",
            TransportMethod::Method2 => "Method 2",
        };
        t.row([
            format!(
                "{} ({})",
                name(r.method),
                if r.method == TransportMethod::Method1 {
                    "front"
                } else {
                    "base"
                }
            ),
            name(r.yaw_gains_of).to_string(),
            if r.converged() { "yes" } else { "no" }.to_string(),
            pair(
                r.get("seg0_convergence_time"),
                r.get("seg1_convergence_time"),
            ),
            pair(r.get("seg0_overshoot"), r.get("seg1_overshoot")),
            short(r.get("tail_deviation_rms")),
            short(r.get("effort_abs")),
        ]);
    }
    md.push_str(&t.finish());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readings_cover_every_combination_once_printed_first() {
        let all = TransportReading::all();
        assert_eq!(all.len(), 32);
        assert_eq!(all[0], TransportReading::PRINTED);
        assert!(all[0].departures().is_empty());
        let mut keys: Vec<String> = all.iter().map(TransportReading::key).collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), 32);
        assert!(all
            .windows(2)
            .all(|w| w[0].departures().len() <= w[1].departures().len()));
        assert_eq!(
            TransportReading::DEFAULT.departures(),
            ["no n", "−K_p v on sway/heave/pitch"]
        );
    }

    #[test]
    fn a_reading_sets_the_scenario_keys_it_names() {
        use crate::control::transport::TransportGains;
        use crate::scenario::config::ModeGains;
        let (mut t, src) = load_table("transport-method1").unwrap();
        let r = TransportReading {
            nonlinear: true,
            uncommanded_feedback: false,
            yaw_rate_source: YawRateSource::BaseYawRate,
            yaw_rate_reference: false,
            surge_law: SurgeLaw::ProportionalDerivative,
        };
        r.apply(&mut t);
        let f = parse_table(&t, &src).unwrap();
        let b = f.base_gains();
        assert!(b.nonlinear && !b.uncommanded_feedback);
        let ModeGains::Transport(g) = f.mode_gains().unwrap() else {
            panic!("transport");
        };
        let expect = TransportGains {
            yaw_rate_source: YawRateSource::BaseYawRate,
            yaw_rate_reference: false,
            surge_law: SurgeLaw::ProportionalDerivative,
            ..TransportGains::method1()
        };
        assert_eq!(g, expect);
        // The project default is what a preset runs without overrides.
        let (t, src) = load_table("transport-method2").unwrap();
        let f = parse_table(&t, &src).unwrap();
        let b = f.base_gains();
        let ModeGains::Transport(g) = f.mode_gains().unwrap() else {
            panic!("transport");
        };
        let d = TransportReading::DEFAULT;
        assert_eq!(
            (
                b.nonlinear,
                b.uncommanded_feedback,
                g.yaw_rate_source,
                g.yaw_rate_reference,
                g.surge_law
            ),
            (
                d.nonlinear,
                d.uncommanded_feedback,
                d.yaw_rate_source,
                d.yaw_rate_reference,
                d.surge_law
            )
        );
    }
}

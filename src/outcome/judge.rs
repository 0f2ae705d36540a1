//! The verdict on a closed-loop run (docs/model.md §6 "Success"): its summary metrics judged against
//! the scenario's `[success]` criteria ([`SuccessSpec`]), in the order of [`Criterion::ALL`].

use crate::input::located::{fmt_exact as num, fmt_fixed as fixed};
use crate::scenario::config::{MissionSpec, Mode};
use crate::scenario::criteria::{Criterion, Missed, SuccessSpec};

/// Judge a run of `mode` by its summary `metrics` (see [`super::run_summary`]) against
/// `spec` and the `mission`'s requirements: `None` when it met every criterion, else the
/// first one missed (the mission's reach first, its deadline after the transport criteria;
/// in transport the attitude and depth bounds right after `no_failure`, see
/// [`judge_attitude`]). `metrics` must hold `completed`, `peak_thrust`, `saturation_fraction`
/// and the mode's metrics; a missing or NaN value misses its criterion.
pub fn judge(
    spec: &SuccessSpec,
    mission: &MissionSpec,
    mode: Mode,
    metrics: &[(String, f64)],
) -> Option<Missed> {
    let get = |k: &str| {
        metrics
            .iter()
            .find(|(n, _)| n == k)
            .map_or(f64::NAN, |x| x.1)
    };
    let reach = get("reach");
    if mission.reach > 0.0 && (reach.is_nan() || reach < mission.reach) {
        return Some(Missed {
            criterion: Criterion::MissionReach,
            detail: format!(
                "reach = {} m < the mission's {} m (the end effector cannot get there)",
                fixed(reach, 3),
                num(mission.reach)
            ),
        });
    }
    if get("completed") != 1.0 {
        return Some(Missed {
            criterion: Criterion::NoFailure,
            detail: "the run stopped early".into(),
        });
    }
    // The metric `name` against its upper `limit` (NaN misses).
    let check = |c, name, limit, unit| exceeds(c, name, get(name), limit, unit);
    if mode == Mode::Transport {
        if let Some(m) = judge_attitude(spec, &get) {
            return Some(m);
        }
    }
    if spec.max_peak_thrust > 0.0 {
        let m = check(
            Criterion::MaxPeakThrust,
            "peak_thrust",
            spec.max_peak_thrust,
            " N",
        );
        if m.is_some() {
            return m;
        }
    }
    let sat = spec.max_saturation_fraction;
    let m = check(
        Criterion::MaxSaturationFraction,
        "saturation_fraction",
        sat,
        "",
    );
    if m.is_some() {
        return m;
    }
    match mode {
        Mode::Transport => judge_transport(spec, &get)
            .or_else(|| judge_deadline(mission.deadline, &get))
            .or_else(|| judge_progress(&get)),
        Mode::Work => {
            let (p, a) = (spec.position_tolerance, spec.orientation_tolerance_deg);
            check(
                Criterion::PositionTolerance,
                "final_position_error",
                p,
                " m",
            )
            .or_else(|| {
                check(
                    Criterion::OrientationTolerance,
                    "final_orientation_error_deg",
                    a,
                    "",
                )
            })
        }
    }
}

/// `criterion` missed when `x` (the value of `label`, in `unit`) is NaN or above `limit`.
fn exceeds(criterion: Criterion, label: &str, x: f64, limit: f64, unit: &str) -> Option<Missed> {
    (x.is_nan() || x > limit).then(|| Missed {
        criterion,
        detail: format!("{label} = {}{unit} > {}{unit}", fixed(x, 4), num(limit)),
    })
}

/// The transport attitude and depth bounds, each judged when its bound is positive: the base's
/// largest |roll| (`max_abs_roll_deg` against `max_roll_deg`), its largest |pitch|
/// (`max_abs_pitch_deg` against `max_pitch_deg`), then the largest depth deviation from the
/// path (`max_vertical_error` against `max_vertical_error`). They come before the thrust and
/// path criteria because a capsize causes their misses (a vehicle on its back saturates its
/// thrusters and leaves the path): the verdict names the axis that failed.
fn judge_attitude(spec: &SuccessSpec, get: &dyn Fn(&str) -> f64) -> Option<Missed> {
    [
        (
            Criterion::MaxRoll,
            "max_abs_roll_deg",
            spec.max_roll_deg,
            "°",
        ),
        (
            Criterion::MaxPitch,
            "max_abs_pitch_deg",
            spec.max_pitch_deg,
            "°",
        ),
        (
            Criterion::MaxVerticalError,
            "max_vertical_error",
            spec.max_vertical_error,
            " m",
        ),
    ]
    .into_iter()
    .filter(|(_, _, bound, _)| *bound > 0.0)
    .find_map(|(c, name, bound, unit)| exceeds(c, name, get(name), bound, unit))
}

/// The transport criteria: the final cross-track bound, then each reached segment's
/// convergence window in the order the segments became active.
fn judge_transport(spec: &SuccessSpec, get: &dyn Fn(&str) -> f64) -> Option<Missed> {
    let e = get("final_cross_track").abs();
    let bound = spec.cross_track_bound;
    if let Some(m) = exceeds(
        Criterion::CrossTrackBound,
        "|final_cross_track|",
        e,
        bound,
        " m",
    ) {
        return Some(m);
    }
    let reached = get("segments_reached");
    let n = if reached.is_finite() && reached > 0.0 {
        reached as usize
    } else {
        0
    };
    for k in 0..n {
        let c = get(&format!("seg{k}_convergence_time"));
        let detail = if c.is_nan() {
            format!("segment {k} never stayed within metrics.band before it ended")
        } else if c > spec.convergence_window {
            format!(
                "segment {k} converged after {} s > {} s",
                fixed(c, 1),
                num(spec.convergence_window)
            )
        } else {
            continue;
        };
        return Some(Missed {
            criterion: Criterion::ConvergenceWindow,
            detail,
        });
    }
    None
}

/// Transport, last (issue 39): the run advanced along the path (`path_progress` > 0 — a run
/// carried backwards by a current meets every bound on the path's error) and its objective
/// `mission_cost` is finite (NaN without progress, infinite with an overflowing
/// `mission.tracking_weight`): a run that misses either cannot be ranked.
fn judge_progress(get: &dyn Fn(&str) -> f64) -> Option<Missed> {
    let progress = get("path_progress");
    if progress.is_nan() || progress <= 0.0 {
        return Some(Missed {
            criterion: Criterion::ForwardProgress,
            detail: format!(
                "path_progress = {} m: the run did not advance along the path",
                fixed(progress, 3)
            ),
        });
    }
    let cost = get("mission_cost");
    if !cost.is_finite() {
        return Some(Missed {
            criterion: Criterion::FiniteObjective,
            detail: format!(
                "mission_cost = {}: the objective is not a finite number",
                num(cost)
            ),
        });
    }
    None
}

/// The run's signed, normalised distance to its `[success]` and `[mission]` bounds (metric
/// `success_margin`): the smallest over the criteria that apply of `(bound − value) / bound`
/// (`|final_cross_track|`, each reached segment's convergence time, the judged attitude and
/// depth bounds of transport, the saturation fraction,
/// the peak thrust when bounded, the work pose errors, the reach requirement as
/// `(reach − required) / required`). Positive: every bound met with at least that relative room;
/// negative: the worst miss relative to its bound ("missed by 1 cm of 0.1 m" is −0.1); −1 for a
/// run that failed numerically (`completed` = 0) or a segment that never converged. A run ended
/// on a certain miss (`stopped_at`, `scenario::watch`) is measured on its metrics up to then.
pub fn success_margin(
    spec: &SuccessSpec,
    mission: &MissionSpec,
    mode: Mode,
    metrics: &[(String, f64)],
) -> f64 {
    let get = |k: &str| {
        metrics
            .iter()
            .find(|(n, _)| n == k)
            .map_or(f64::NAN, |x| x.1)
    };
    if get("completed") != 1.0 {
        return -1.0;
    }
    // Room below an upper bound, relative to it; a NaN value is a full miss.
    let room = |x: f64, bound: f64| {
        if x.is_nan() {
            -1.0
        } else if bound > 0.0 {
            (bound - x) / bound
        } else if x <= 0.0 {
            0.0
        } else {
            -1.0
        }
    };
    let mut m = room(get("saturation_fraction"), spec.max_saturation_fraction);
    if spec.max_peak_thrust > 0.0 {
        m = m.min(room(get("peak_thrust"), spec.max_peak_thrust));
    }
    if mission.reach > 0.0 {
        let r = get("reach");
        m = m.min(if r.is_nan() {
            -1.0
        } else {
            (r - mission.reach) / mission.reach
        });
    }
    match mode {
        Mode::Transport => {
            for (name, bound) in [
                ("max_abs_roll_deg", spec.max_roll_deg),
                ("max_abs_pitch_deg", spec.max_pitch_deg),
                ("max_vertical_error", spec.max_vertical_error),
            ] {
                if bound > 0.0 {
                    m = m.min(room(get(name), bound));
                }
            }
            m = m.min(room(get("final_cross_track").abs(), spec.cross_track_bound));
            let reached = get("segments_reached");
            let n = if reached.is_finite() && reached > 0.0 {
                reached as usize
            } else {
                0
            };
            let window = if mission.deadline > 0.0 {
                spec.convergence_window.min(mission.deadline)
            } else {
                spec.convergence_window
            };
            for k in 0..n {
                m = m.min(room(get(&format!("seg{k}_convergence_time")), window));
            }
            if judge_progress(&get).is_some() {
                m = m.min(-1.0);
            }
        }
        Mode::Work => {
            m = m.min(room(get("final_position_error"), spec.position_tolerance));
            m = m.min(room(
                get("final_orientation_error_deg"),
                spec.orientation_tolerance_deg,
            ));
        }
    }
    m
}

/// The mission's deadline: every reached segment converged within `deadline` [s] of becoming
/// active (0 = none; a segment that never converged already missed `convergence_window`).
fn judge_deadline(deadline: f64, get: &dyn Fn(&str) -> f64) -> Option<Missed> {
    if deadline <= 0.0 {
        return None;
    }
    let reached = get("segments_reached");
    let n = if reached.is_finite() && reached > 0.0 {
        reached as usize
    } else {
        0
    };
    (0..n).find_map(|k| {
        let c = get(&format!("seg{k}_convergence_time"));
        (c.is_nan() || c > deadline).then(|| Missed {
            criterion: Criterion::MissionDeadline,
            detail: format!(
                "segment {k} converged after {} s > the mission's {} s",
                fixed(c, 1),
                num(deadline)
            ),
        })
    })
}

#[cfg(test)]
mod tests {
    use crate::outcome::judge::{judge, success_margin};
    use crate::scenario::config::{MissionSpec, Mode};
    use crate::scenario::criteria::{Criterion, SuccessSpec};

    /// Issue 39: a reason printed a limit of 1e308 as 309 digits and 1e-300 as `0.0000`.
    #[test]
    fn numbers_in_reasons_are_short() {
        let m = super::exceeds(
            Criterion::MaxPeakThrust,
            "peak_thrust",
            1e-300,
            1e-308,
            " N",
        )
        .unwrap();
        assert_eq!(m.detail, "peak_thrust = 1.000e-300 N > 1e-308 N");
        let m =
            super::exceeds(Criterion::MaxPeakThrust, "peak_thrust", 1e308, 1e300, " N").unwrap();
        assert_eq!(m.detail, "peak_thrust = 1.000e308 N > 1e300 N");
    }

    fn metrics(kv: &[(&str, f64)]) -> Vec<(String, f64)> {
        kv.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    const COMMON: [(&str, f64); 3] = [
        ("completed", 1.0),
        ("peak_thrust", 40.0),
        ("saturation_fraction", 0.01),
    ];

    fn transport(final_ct: f64, seg: &[f64]) -> Vec<(String, f64)> {
        let mut m = metrics(&COMMON);
        m.extend(
            seg.iter()
                .enumerate()
                .map(|(k, c)| (format!("seg{k}_convergence_time"), *c)),
        );
        m.extend(metrics(&[
            ("path_progress", 5.0),
            ("mission_cost", 12.0),
            ("segments_reached", seg.len() as f64),
            ("final_cross_track", final_ct),
            ("max_abs_roll_deg", 0.5),
            ("max_abs_pitch_deg", 1.0),
            ("max_vertical_error", 0.02),
        ]));
        m
    }

    /// `m` with metric `k` set to `x`.
    fn with(mut m: Vec<(String, f64)>, k: &str, x: f64) -> Vec<(String, f64)> {
        m.iter_mut().find(|(n, _)| n == k).unwrap().1 = x;
        m
    }

    #[test]
    fn a_capsize_is_named_by_its_axis_before_its_symptoms() {
        let s = SuccessSpec::default();
        let none = MissionSpec::default();
        let id = |m: &[(String, f64)]| judge(&s, &none, Mode::Transport, m).map(|x| x.criterion);
        // On its back, saturated and off the path: the roll is named, not the saturation or
        // the cross-track error it caused.
        let mut capsized = with(
            transport(-1.3, &[30.0, f64::NAN]),
            "max_abs_roll_deg",
            178.6,
        );
        capsized[2].1 = 0.4;
        let m = judge(&s, &none, Mode::Transport, &capsized).unwrap();
        assert_eq!(m.criterion, Criterion::MaxRoll);
        assert_eq!(
            m.to_string(),
            "max_roll_deg: max_abs_roll_deg = 178.6000° > 30°"
        );
        let ok = transport(0.05, &[30.0]);
        assert_eq!(id(&ok), None);
        assert_eq!(
            id(&with(ok.clone(), "max_abs_pitch_deg", 31.0)),
            Some(Criterion::MaxPitch)
        );
        assert_eq!(
            id(&with(ok.clone(), "max_vertical_error", 5.2)),
            Some(Criterion::MaxVerticalError)
        );
        // A missing or NaN metric misses its bound; a bound of 0 is not judged.
        assert_eq!(
            id(&with(ok.clone(), "max_abs_roll_deg", f64::NAN)),
            Some(Criterion::MaxRoll)
        );
        let off = SuccessSpec {
            max_roll_deg: 0.0,
            max_pitch_deg: 0.0,
            max_vertical_error: 0.0,
            ..SuccessSpec::default()
        };
        let rolled = with(
            with(ok.clone(), "max_abs_roll_deg", 90.0),
            "max_vertical_error",
            3.0,
        );
        assert_eq!(judge(&off, &none, Mode::Transport, &rolled), None);
        // A run that stopped early still names `no_failure` first.
        let mut stopped = capsized.clone();
        stopped[0].1 = 0.0;
        assert_eq!(id(&stopped), Some(Criterion::NoFailure));
        // The margin sees the attitude: 20° of 30° leaves a third.
        let margin = success_margin(
            &s,
            &none,
            Mode::Transport,
            &with(ok, "max_abs_roll_deg", 20.0),
        );
        assert!((margin - 1.0 / 3.0).abs() < 1e-12, "{margin}");
        // Work mode is not judged on them (the base's attitude is free to the task there).
        let mut w = metrics(&COMMON);
        w.extend(metrics(&[
            ("final_position_error", 0.01),
            ("final_orientation_error_deg", 0.1),
            ("max_abs_roll_deg", 90.0),
        ]));
        assert_eq!(judge(&s, &none, Mode::Work, &w), None);
    }

    #[test]
    fn transport_criteria_in_order() {
        let s = SuccessSpec::default();
        let id = |m: &[(String, f64)]| {
            judge(&s, &MissionSpec::default(), Mode::Transport, m).map(|x| x.criterion)
        };
        assert_eq!(id(&transport(-0.05, &[30.0, 44.0])), None);
        // Signed cross-track: judged by magnitude.
        assert_eq!(
            id(&transport(-1.24, &[f64::NAN, f64::NAN])),
            Some(Criterion::CrossTrackBound)
        );
        assert_eq!(
            id(&transport(0.05, &[71.5, 40.0])),
            Some(Criterion::ConvergenceWindow)
        );
        let m = judge(
            &s,
            &MissionSpec::default(),
            Mode::Transport,
            &transport(0.05, &[30.0, f64::NAN]),
        )
        .unwrap();
        assert!(m.detail.starts_with("segment 1 never"), "{}", m.detail);
        assert!(m.to_string().starts_with("convergence_window: segment 1"));
        // Earlier criteria come first: a run that stopped early misses `no_failure` only.
        let mut stopped = transport(-1.24, &[f64::NAN]);
        stopped[0].1 = 0.0;
        assert_eq!(id(&stopped), Some(Criterion::NoFailure));
        let mut sat = transport(0.0, &[1.0]);
        sat[2].1 = 0.2;
        assert_eq!(id(&sat), Some(Criterion::MaxSaturationFraction));
        // The peak bound only binds when set.
        let tight = SuccessSpec {
            max_peak_thrust: 30.0,
            ..SuccessSpec::default()
        };
        let m = judge(
            &tight,
            &MissionSpec::default(),
            Mode::Transport,
            &transport(0.0, &[1.0]),
        );
        assert_eq!(m.map(|x| x.criterion), Some(Criterion::MaxPeakThrust));

        // Last: the run advanced along the path and its objective is finite (issue 39).
        let ok = transport(0.0, &[1.0]);
        for (k, x, c) in [
            ("path_progress", -1.08, Criterion::ForwardProgress),
            ("path_progress", f64::NAN, Criterion::ForwardProgress),
            ("mission_cost", f64::INFINITY, Criterion::FiniteObjective),
            ("mission_cost", f64::NAN, Criterion::FiniteObjective),
        ] {
            let m = with(ok.clone(), k, x);
            assert_eq!(id(&m), Some(c), "{k} = {x}");
            let margin = success_margin(&s, &MissionSpec::default(), Mode::Transport, &m);
            assert_eq!(margin, -1.0, "{k} = {x}");
        }
        assert!(judge(&s, &MissionSpec::default(), Mode::Transport, &ok).is_none());
    }

    #[test]
    fn work_criteria_and_missing_metrics() {
        let s = SuccessSpec::default();
        let mut m = metrics(&COMMON);
        m.extend(metrics(&[
            ("final_position_error", 0.01),
            ("final_orientation_error_deg", 0.1),
        ]));
        assert_eq!(judge(&s, &MissionSpec::default(), Mode::Work, &m), None);
        m[3].1 = 0.5;
        let x = judge(&s, &MissionSpec::default(), Mode::Work, &m).unwrap();
        assert_eq!(x.criterion, Criterion::PositionTolerance);
        m[3].1 = 0.01;
        m[4].1 = f64::NAN;
        let x = judge(&s, &MissionSpec::default(), Mode::Work, &m).unwrap();
        assert_eq!(x.criterion, Criterion::OrientationTolerance);
        // A missing metric misses its criterion.
        assert_eq!(
            judge(&s, &MissionSpec::default(), Mode::Work, &metrics(&COMMON)).map(|x| x.criterion),
            Some(Criterion::PositionTolerance)
        );
    }

    #[test]
    fn mission_reach_comes_first_and_the_deadline_after_the_windows() {
        let s = SuccessSpec::default();
        let mission = MissionSpec {
            reach: 2.5,
            deadline: 35.0,
            ..MissionSpec::default()
        };
        let id = |m: &[(String, f64)]| judge(&s, &mission, Mode::Transport, m).map(|x| x.criterion);
        let mut m = transport(0.05, &[30.0, 34.0]);
        m.push(("reach".into(), 2.6));
        assert_eq!(id(&m), None);
        m.last_mut().unwrap().1 = 2.4;
        // Even a run that stopped early names the reach first: the design cannot do it.
        m[0].1 = 0.0;
        assert_eq!(id(&m), Some(Criterion::MissionReach));
        let mut m = transport(0.05, &[30.0, 40.0]);
        m.push(("reach".into(), 2.6));
        let x = judge(&s, &mission, Mode::Transport, &m).unwrap();
        assert_eq!(x.criterion, Criterion::MissionDeadline);
        assert!(
            x.detail.starts_with("segment 1 converged after 40.0 s"),
            "{}",
            x.detail
        );
        // Without a mission the same run succeeds.
        assert_eq!(
            judge(&s, &MissionSpec::default(), Mode::Transport, &m),
            None
        );
    }

    #[test]
    fn the_success_margin_says_by_how_much_a_bound_was_met_or_missed() {
        let s = SuccessSpec::default();
        let none = MissionSpec::default();
        let margin = |m: &[(String, f64)]| success_margin(&s, &none, Mode::Transport, m);
        // 0.05 m of 0.1 m: half the room left; convergence 30 of 60 s, saturation 0.01 of 0.05.
        assert!((margin(&transport(0.05, &[30.0])) - 0.5).abs() < 1e-12);
        // Missed by 1 cm: −0.1.
        assert!((margin(&transport(-0.11, &[30.0])) + 0.1).abs() < 1e-12);
        // A segment that never converged, or a run that stopped: −1.
        assert_eq!(margin(&transport(0.0, &[f64::NAN])), -1.0);
        let mut stopped = transport(0.0, &[1.0]);
        stopped[0].1 = 0.0;
        assert_eq!(margin(&stopped), -1.0);
    }
}

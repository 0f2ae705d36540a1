//! Tests of the static TCM analysis: determinism across threads, the paper design's singular
//! straight configuration, quantiles, slices and joint influence.

use super::super::slice::{influential_joints, slice_grid};
use super::*;
use crate::model::presets::usm_paper;
use crate::statics::dist::quantile_sorted;

fn run(threads: usize, samples: usize, sampling: Sampling) -> (StaticSummary, Vec<SampleEval>) {
    let spec = StaticSpec {
        samples,
        seed: 7,
        sampling,
        ..Default::default()
    };
    run_spec(&usm_paper(), &spec, threads)
}

/// [`analyse`] of `v` under `spec`: the summary and every row the sink saw.
fn run_spec(v: &Vehicle, spec: &StaticSpec, threads: usize) -> (StaticSummary, Vec<SampleEval>) {
    let mut rows = Vec::new();
    let s = analyse(
        v,
        spec,
        threads,
        &mut |index, q, m| {
            rows.push(SampleEval {
                index,
                q: q.to_vec(),
                metrics: *m,
            });
            Ok(())
        },
        &|_| {},
    )
    .unwrap();
    (s, rows)
}

#[test]
fn deterministic_across_threads() {
    for m in [Sampling::Sobol, Sampling::Lhs, Sampling::Random] {
        let (a, ra) = run(1, 5000, m);
        let (b, rb) = run(3, 5000, m);
        assert_eq!(a, b);
        assert_eq!(ra, rb);
        assert!(ra.iter().enumerate().all(|(i, r)| r.index == i));
    }
}

#[test]
fn text_output_is_the_same_for_any_thread_count_and_in_index_order() {
    // More than one chunk and a partial last batch: formatted on the workers with several
    // threads, inline with one; the row sink sees the same samples as `analyse`'s.
    let v = usm_paper();
    let samples = CHUNK + BATCH + 7;
    let spec = StaticSpec {
        samples,
        seed: 3,
        ..Default::default()
    };
    let format = |i: usize, q: &[f64], m: &SampleMetrics, t: &mut String| {
        t.push_str(&format!("{i} {:?} {:e}\n", q, m.sigma_min));
    };
    let text = |threads| {
        let (mut out, mut seen) = (String::new(), Vec::new());
        let s = analyse_text(
            &v,
            &spec,
            threads,
            &format,
            &mut |t| {
                out.push_str(t);
                Ok(())
            },
            &mut |i, _, m| {
                seen.push((i, m.sigma_min));
                Ok(())
            },
            &|_| {},
        )
        .unwrap();
        (s, out, seen)
    };
    let (s1, t1, seen1) = text(1);
    let (s2, t2, seen2) = text(2);
    assert_eq!(s1, s2);
    assert_eq!(t1, t2);
    assert_eq!(seen1, seen2);
    let lines: Vec<&str> = t1.lines().collect();
    assert_eq!(lines.len(), samples);
    let (_, rows) = run_spec(&v, &spec, 2);
    for (k, (line, r)) in lines.iter().zip(&rows).enumerate() {
        assert!(line.starts_with(&format!("{k} ")), "{line}");
        assert_eq!(seen1[k], (r.index, r.metrics.sigma_min));
    }
}

#[test]
fn paper_straight_is_singular_in_roll() {
    let (s, _) = run(1, 300, Sampling::Sobol);
    assert_eq!(s.straight.metrics.rank, 5);
    assert_eq!(s.straight.metrics.lost_axis, Some("roll"));
    // Transport does not command roll: the straight body has full commanded authority.
    assert_eq!(s.commanded_axes, "surge+sway+heave+pitch+yaw");
    assert_eq!(s.straight.metrics.rank_commanded, 5);
    assert!(s.straight.metrics.sigma_min_commanded > s.threshold);
    assert!(s.singular_fraction_commanded <= s.singular_fraction);
    assert!((0.0..=1.0).contains(&s.singular_fraction));
    assert!(s
        .worst
        .windows(2)
        .all(|w| w[0].metrics.sigma_min <= w[1].metrics.sigma_min));
    assert_eq!(s.worst.len(), 10);
    let total: usize = s.lost_axes.iter().map(|a| a.count).sum();
    assert!(total >= (s.singular_fraction * 300.0).round() as usize);
}

#[test]
fn quantiles() {
    let v = vec![3.0, 1.0, 2.0, 4.0];
    let d = distribution(v);
    assert_eq!(d.min, 1.0);
    assert_eq!(d.max, 4.0);
    assert_eq!(quantile_sorted(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.5);
    assert_eq!(quantile_sorted(&[1.0, f64::INFINITY], 0.5), f64::INFINITY);
    assert_eq!(quantile_sorted(&[1.0, f64::INFINITY], 0.0), 1.0);
}

#[test]
fn slice_and_influence() {
    let v = usm_paper();
    let spec = StaticSpec::default();
    let (i, j) = influential_joints(&v, &spec).unwrap().unwrap();
    assert!(i < j && v.joints[i].axis.z.abs() > 0.9 && v.joints[j].axis.z.abs() > 0.9);
    let g = slice_grid(&v, &spec, i, j, 9, 2).unwrap();
    assert_eq!(g.sigma_min.len(), 81);
    assert_eq!(g, slice_grid(&v, &spec, i, j, 9, 1).unwrap());
    assert!(slice_grid(&v, &spec, 0, 0, 9, 1).is_err());
}

//! Tests of the paired ranking and the verdict.

use super::*;
use proptest::prelude::*;

fn all_ok(cases: usize, worlds: usize) -> Vec<Vec<bool>> {
    vec![vec![true; worlds]; cases]
}

/// A world-dependent factor within ±`amp` (deterministic, not periodic over a few worlds).
fn wobble(w: usize, amp: f64) -> f64 {
    1.0 + amp * ((w as f64) * 2.399_963).sin()
}

#[test]
fn identical_cases_are_tied_with_half_the_wins_each() {
    let row: Vec<f64> = (0..20).map(|w| 50.0 * wobble(w, 0.1)).collect();
    let obj = vec![row.clone(), row];
    let ok = all_ok(2, 20);
    let r = rank_stats(&obj, &ok);
    assert_eq!((r[0].p_best, r[1].p_best), (0.5, 0.5));
    assert_eq!(
        (r[0].rank_p05, r[0].rank_p95, r[1].rank_mean),
        (1.0, 1.0, 1.0)
    );
    let v = verdict(&obj, &ok, &[true, true], &VerdictSettings::default());
    let Verdict::Tied { leader: 0, tied } = v else {
        panic!("expected a tie, got {v:?}");
    };
    assert_eq!(tied.len(), 1);
    let c: Contender = tied[0];
    assert_eq!((c.case, c.p_beats, c.margin, c.wins), (1, 0.0, 0.0, 0));
    assert_eq!((c.p_value, c.needs_worlds), (1.0, None));
}

#[test]
fn a_ten_percent_paired_margin_names_the_winner() {
    // Worlds move every case by up to ±20 %; each case also has its own ±2 % noise.
    let worlds = 24;
    let obj: Vec<Vec<f64>> = [1.0, 1.10, 1.25]
        .iter()
        .enumerate()
        .map(|(c, k)| {
            (0..worlds)
                .map(|w| 100.0 * k * wobble(w, 0.2) * wobble(w * 7 + c * 3 + 1, 0.02))
                .collect()
        })
        .collect();
    let ok = all_ok(3, worlds);
    let Verdict::Winner {
        leader,
        runner_up,
        p_beats,
        margin,
        p_value,
    } = verdict(&obj, &ok, &[true; 3], &VerdictSettings::default())
    else {
        panic!("expected a winner");
    };
    assert_eq!((leader, runner_up, p_beats), (0, 1, 1.0));
    assert!((margin - 0.10).abs() < 0.03, "{margin}");
    // Both comparisons won in 24 of 24 worlds: Holm-adjusted p = 2 · 2⁻²⁴.
    assert!((p_value - 2.0 * 2f64.powi(-24)).abs() < 1e-15, "{p_value}");
    let r = rank_stats(&obj, &ok);
    assert_eq!(r[0].p_best, 1.0);
    assert_eq!(
        (r[1].rank_p05, r[1].rank_p95, r[2].rank_p50),
        (2.0, 2.0, 3.0)
    );
}

#[test]
fn a_margin_inside_the_equivalence_or_the_noise_is_a_tie() {
    let worlds = 16;
    let base: Vec<f64> = (0..worlds).map(|w| 10.0 * wobble(w, 0.3)).collect();
    let scaled = |k: f64| base.iter().map(|v| v * k).collect::<Vec<_>>();
    let ok = all_ok(2, worlds);
    // 0.1 %: below the default 1 % equivalence margin.
    let obj = vec![scaled(1.0), scaled(1.001)];
    match verdict(&obj, &ok, &[true, true], &VerdictSettings::default()) {
        Verdict::Tied { leader: 0, tied } => {
            assert_eq!(tied.len(), 1);
            assert_eq!((tied[0].case, tied[0].p_beats), (1, 0.0));
            assert!((tied[0].margin - 0.001).abs() < 1e-9);
        }
        v => panic!("expected a tie, got {v:?}"),
    }
    // 3 %: a winner without tuning noise, a tie with 5 % noise.
    let obj = vec![scaled(1.03), scaled(1.0)];
    let quiet = VerdictSettings::default();
    assert!(matches!(
        verdict(&obj, &ok, &[true, true], &quiet),
        Verdict::Winner {
            leader: 1,
            runner_up: 0,
            ..
        }
    ));
    let noisy = VerdictSettings {
        noise: 0.05,
        ..quiet
    };
    assert!(matches!(
        verdict(&obj, &ok, &[true, true], &noisy),
        Verdict::Tied { leader: 1, .. }
    ));
}

#[test]
fn failures_are_beaten_and_never_lead() {
    let worlds = 10;
    let obj = vec![vec![100.0; worlds], vec![100.0; worlds], vec![90.0; worlds]];
    let mut ok = all_ok(3, worlds);
    // Case 1 matches the leader but fails in half the worlds: beaten exactly there.
    ok[1][..5].fill(false);
    // Case 2 is better but never succeeds: it cannot lead.
    ok[2] = vec![false; worlds];
    let s = VerdictSettings::default();
    match verdict(&obj, &ok, &[true; 3], &s) {
        Verdict::Tied { leader: 0, tied } => {
            assert_eq!(tied.len(), 1);
            assert_eq!(
                (tied[0].case, tied[0].p_beats, tied[0].margin),
                (1, 0.5, 0.0)
            );
        }
        v => panic!("expected a tie, got {v:?}"),
    }
    // Worse by 20 % where it succeeds: beaten everywhere, case 2 has no margin.
    let obj2 = vec![obj[0].clone(), vec![120.0; worlds], obj[2].clone()];
    match verdict(&obj2, &ok, &[true; 3], &s) {
        Verdict::Winner {
            leader: 0,
            runner_up: 1,
            p_beats,
            margin,
            ..
        } => assert_eq!((p_beats, margin), (1.0, 0.2)),
        v => panic!("expected a winner, got {v:?}"),
    }
    let r = rank_stats(&obj2, &ok);
    // Case 2 ties with case 1 behind case 0 where case 1 fails, last elsewhere.
    assert_eq!((r[2].rank_p05, r[2].rank_p95), (2.0, 3.0));
    assert_eq!(r[2].p_best, 0.0);
    assert_eq!((r[1].rank_p05, r[1].rank_p95), (2.0, 2.0));
    // A leader failing in a world does not beat anyone there; 3 wins of 4 at a 100 % margin
    // lean to the leader but cannot reach 95 % (p = 5/16): undecided, not tied.
    let mut ok3 = all_ok(2, 4);
    ok3[0][0] = false;
    let obj3 = vec![vec![1.0; 4], vec![2.0; 4]];
    match verdict(&obj3, &ok3, &[true, true], &s) {
        Verdict::Undecided {
            leader: 0, open, ..
        } => {
            assert_eq!(open[0].p_beats, 0.75);
            assert_eq!(open[0].p_value, 5.0 / 16.0);
        }
        v => panic!("expected undecided, got {v:?}"),
    }
}

#[test]
fn eligibility_decides_who_is_compared() {
    let obj = vec![vec![1.0, 1.0], vec![2.0, 2.0], vec![0.5, 0.5]];
    let ok = all_ok(3, 2);
    let s = VerdictSettings::default();
    // The best case is not eligible: the next one wins alone.
    match verdict(&obj, &ok, &[false, true, false], &s) {
        Verdict::Winner {
            leader: 1,
            runner_up: 1,
            p_beats,
            margin,
            ..
        } => assert!(p_beats == 1.0 && margin.is_nan()),
        v => panic!("expected a lone winner, got {v:?}"),
    }
    assert_eq!(verdict(&obj, &ok, &[false; 3], &s), Verdict::NoneEligible);
    assert_eq!(verdict(&obj, &ok, &[], &s), Verdict::NoneEligible);
    // Two worlds cannot show anything at 95 %: 2 of 2 has p = 0.25; five would do.
    match verdict(&obj, &ok, &[true, true, false], &s) {
        Verdict::Undecided {
            leader: 0,
            open,
            needs_worlds: 5,
        } => assert_eq!(open[0].case, 1),
        v => panic!("expected undecided needing 5 worlds, got {v:?}"),
    }
}

/// Issue 36 item 6, "must show": one design beats another by ≈ 10 % in every world. At 4
/// worlds the sign test cannot reach 95 % (4 of 4: p = 0.0625), so the verdict is undecided and
/// says how many worlds it needs; at 32 worlds it is a Winner (p = 2⁻³²).
#[test]
fn ten_percent_in_every_world_is_undecided_at_4_worlds_and_a_winner_at_32() {
    let obj_at = |worlds: usize| -> Vec<Vec<f64>> {
        [1.0, 1.10]
            .iter()
            .map(|k| (0..worlds).map(|w| 60.0 * k * wobble(w, 0.3)).collect())
            .collect()
    };
    let s = VerdictSettings::default();
    match verdict(&obj_at(4), &all_ok(2, 4), &[true, true], &s) {
        Verdict::Undecided {
            leader: 0,
            open,
            needs_worlds,
        } => {
            assert_eq!((open[0].wins, open[0].p_value), (4, 0.0625));
            assert_eq!(needs_worlds, 5);
        }
        v => panic!("expected undecided at 4 worlds, got {v:?}"),
    }
    match verdict(&obj_at(32), &all_ok(2, 32), &[true, true], &s) {
        Verdict::Winner {
            leader: 0,
            runner_up: 1,
            p_value,
            ..
        } => assert_eq!(p_value, 2f64.powi(-32)),
        v => panic!("expected a winner at 32 worlds, got {v:?}"),
    }
    // One failed world of 16 does not turn a 2.3× gap into a tie (15 of 16: p = 17/65536).
    let mut obj = vec![vec![60.0; 16], vec![140.0; 16]];
    obj[0][3] = 61.0;
    let mut ok = all_ok(2, 16);
    ok[0][5] = false;
    assert!(matches!(
        verdict(&obj, &ok, &[true, true], &s),
        Verdict::Winner { leader: 0, .. }
    ));
}

/// Holm across competitors: the leader beats an easy rival in every world and a close one in
/// 12 of 16 worlds (p = 0.0384). Alone, 0.0384 ≤ 0.05 wins; Holm tests the smaller p first at
/// 0.05/2 (2⁻¹⁶, rejected), then 0.0384 at 0.05: rejected too, so the leader wins. With 11 of
/// 16 (p = 0.105) the close rival stays open.
#[test]
fn holm_corrects_across_the_competitors() {
    let w = 16;
    let leader = vec![100.0; w];
    let easy = vec![200.0; w];
    let close_with = |wins: usize| -> Vec<f64> {
        (0..w)
            .map(|i| if i < wins { 110.0 } else { 100.0 })
            .collect()
    };
    let s = VerdictSettings::default();
    let obj = vec![leader.clone(), easy.clone(), close_with(12)];
    assert!(matches!(
        verdict(&obj, &all_ok(3, w), &[true; 3], &s),
        Verdict::Winner { leader: 0, .. }
    ));
    let obj = vec![leader, easy, close_with(11)];
    match verdict(&obj, &all_ok(3, w), &[true; 3], &s) {
        // The median of 11 × 0.10 and 5 × 0 is 0.10 > δ and 11 > 8 wins: it leads without
        // reaching 95 %, so it is open (undecided), not tied.
        Verdict::Undecided {
            leader: 0, open, ..
        } => {
            assert_eq!((open.len(), open[0].case, open[0].wins), (1, 2, 11));
        }
        v => panic!("expected the close rival left open, got {v:?}"),
    }
}

#[test]
fn rank_quantiles_of_a_three_case_toy_by_hand() {
    // World:        0  1  2  3
    // case 0 obj:   1  2  3  1
    // case 1 obj:   2  1  3  5 (fails in world 3)
    // case 2 obj:   3  3  1  2
    // ranks c0: 1 2 2 1; c1: 2 1 2 3; c2: 3 3 1 2. Best: c0, c1, c2, c0.
    let obj = vec![
        vec![1.0, 2.0, 3.0, 1.0],
        vec![2.0, 1.0, 3.0, 5.0],
        vec![3.0, 3.0, 1.0, 2.0],
    ];
    let mut ok = all_ok(3, 4);
    ok[1][3] = false;
    let r = rank_stats(&obj, &ok);
    let want = [
        (0.5, 1.0, 1.5, 2.0, 1.5),
        (0.25, 1.15, 2.0, 2.85, 2.0),
        (0.25, 1.15, 2.5, 3.0, 2.25),
    ];
    for (c, (got, w)) in r.iter().zip(want).enumerate() {
        let g = (
            got.p_best,
            got.rank_p05,
            got.rank_p50,
            got.rank_p95,
            got.rank_mean,
        );
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(
            close(g.0, w.0)
                && close(g.1, w.1)
                && close(g.2, w.2)
                && close(g.3, w.3)
                && close(g.4, w.4),
            "case {c}: {g:?} vs {w:?}"
        );
    }
    // A world in which nobody succeeds counts for nobody; NaN objectives are failures.
    let obj = vec![vec![1.0, f64::NAN], vec![2.0, 3.0]];
    let ok = vec![vec![true, true], vec![true, false]];
    let r = rank_stats(&obj, &ok);
    assert_eq!((r[0].p_best, r[1].p_best), (0.5, 0.0));
    assert_eq!(r[0].rank_mean, 1.0);
    assert!(rank_stats(&[], &[]).is_empty());
    assert!(rank_stats(&[vec![]], &[vec![]])[0].rank_p50.is_nan());
}

#[test]
fn settings_are_checked() {
    assert!(VerdictSettings::default().validate().is_ok());
    let bad = |f: fn(&mut VerdictSettings)| {
        let mut s = VerdictSettings::default();
        f(&mut s);
        s.validate().unwrap_err()
    };
    assert_eq!(
        bad(|s| s.confidence = 0.0),
        VerdictSettingsError::Confidence(0.0)
    );
    assert!(matches!(
        bad(|s| s.confidence = f64::NAN),
        VerdictSettingsError::Confidence(_)
    ));
    assert_eq!(
        bad(|s| s.equivalence = -0.1),
        VerdictSettingsError::Equivalence(-0.1)
    );
    assert!(matches!(
        bad(|s| s.noise = f64::INFINITY),
        VerdictSettingsError::Noise(_)
    ));
}

proptest! {
    #[test]
    fn ranks_stay_in_range_and_wins_never_exceed_one(
        cases in 1usize..6,
        worlds in 1usize..12,
        cells in proptest::collection::vec((0u8..4, any::<bool>()), 72),
    ) {
        // Objectives from a small set, so that ties are common.
        let obj: Vec<Vec<f64>> = (0..cases)
            .map(|c| (0..worlds).map(|w| cells[c * worlds + w].0 as f64).collect())
            .collect();
        let ok: Vec<Vec<bool>> = (0..cases)
            .map(|c| (0..worlds).map(|w| cells[c * worlds + w].1).collect())
            .collect();
        let r = rank_stats(&obj, &ok);
        let total: f64 = r.iter().map(|s| s.p_best).sum();
        prop_assert!(total <= 1.0 + 1e-12);
        let any_success_everywhere = (0..worlds).all(|w| (0..cases).any(|c| ok[c][w]));
        if any_success_everywhere {
            prop_assert!((total - 1.0).abs() < 1e-12);
        }
        for s in &r {
            for v in [s.rank_p05, s.rank_p50, s.rank_p95, s.rank_mean] {
                prop_assert!((1.0..=cases as f64).contains(&v));
            }
            prop_assert!(s.rank_p05 <= s.rank_p50 && s.rank_p50 <= s.rank_p95);
            prop_assert!((0.0..=1.0).contains(&s.p_best));
        }
        let eligible: Vec<bool> = (0..cases).map(|c| c % 2 == 0 || ok[c][0]).collect();
        let s = VerdictSettings::default();
        match verdict(&obj, &ok, &eligible, &s) {
            Verdict::Winner { leader, runner_up, p_beats, p_value, .. } => {
                prop_assert!(eligible[leader] && eligible[runner_up]);
                prop_assert!(p_beats > 0.5 && p_value <= 1.0 - s.confidence);
            }
            Verdict::Tied { leader, tied } => {
                prop_assert!(eligible[leader] && !tied.is_empty());
                prop_assert!(tied.iter().all(|c| c.case != leader));
                prop_assert!(tied.iter().any(|c| c.needs_worlds.is_none()));
            }
            Verdict::Undecided { leader, open, needs_worlds } => {
                prop_assert!(eligible[leader] && !open.is_empty());
                prop_assert!(open.iter().all(|c| c.needs_worlds.is_some() && c.case != leader));
                prop_assert!(needs_worlds > worlds);
            }
            Verdict::NoneEligible => prop_assert!(eligible.iter().all(|e| !e)),
        }
    }
}

/// Adaptive worlds: rows of different lengths. Each comparison is over the worlds both cases
/// met (the shorter row); an ineligible case with a short row does not shorten the others'.
#[test]
fn each_comparison_is_over_the_worlds_both_cases_met() {
    // Case 0 is 10 % cheaper than case 1 in every world; both met 8 worlds, case 2 (not
    // eligible) only 4, case 3 (eligible, 30 % dearer) only 6.
    let base: Vec<f64> = (0..8).map(|w| 50.0 * wobble(w, 0.1)).collect();
    let obj = vec![
        base.clone(),
        base.iter().map(|x| 1.1 * x).collect(),
        base[..4].to_vec(),
        base[..6].iter().map(|x| 1.3 * x).collect(),
    ];
    let ok: Vec<Vec<bool>> = obj.iter().map(|r| vec![true; r.len()]).collect();
    let s = VerdictSettings::default();
    // Without case 3: 8 of 8 wins against case 1 (p = 2⁻⁸) whatever case 2's row is.
    let v = verdict(&obj, &ok, &[true, true, false, false], &s);
    let Verdict::Winner {
        leader: 0,
        runner_up: 1,
        p_beats,
        ..
    } = v
    else {
        panic!("expected a winner, got {v:?}");
    };
    assert_eq!(p_beats, 1.0);
    // With case 3: its comparison is over its 6 worlds, 6 of 6 (p = 2⁻⁶); Holm over the two:
    // 2⁻⁸ ≤ 0.025, then 2⁻⁶ ≤ 0.05: still a winner, largest adjusted p = 2⁻⁶.
    let v = verdict(&obj, &ok, &[true, true, false, true], &s);
    let Verdict::Winner { p_value, .. } = v else {
        panic!("expected a winner, got {v:?}");
    };
    assert!((p_value - 2f64.powi(-6)).abs() < 1e-15, "{p_value}");
    // Rows of one length read as before: the same verdict as rows cut to the shortest.
    let cut: Vec<Vec<f64>> = obj.iter().map(|r| r[..4].to_vec()).collect();
    let ok4 = all_ok(4, 4);
    let v = verdict(&cut, &ok4, &[true, true, false, true], &s);
    assert!(matches!(v, Verdict::Undecided { leader: 0, .. }), "{v:?}");
}

//! Paired ranking of cases over common worlds, and the winner-or-tie verdict.
//!
//! Inputs are `obj[c][w]`, case c's objective in world w (smaller is better: callers negate
//! maximised objectives), and `ok[c][w]`, whether case c met its success criteria in world w.
//! Every case meets the same worlds (common random numbers), so comparisons are paired world by
//! world. A case whose objective is not finite in a world counts as failed there. The ranks
//! read rows up to the shortest one's length; the verdict compares two cases over the worlds
//! both met (the shorter row's length: with adaptive worlds, the designs in contention meet
//! more worlds of the same sequence, so the worlds of a shorter row are a prefix of a longer).

use super::confidence::{holm, holm_adjusted, sign_test_p, worlds_at_share};
use super::describe::quantile_sorted;

/// How a case ranks among all cases over the worlds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RankStats {
    /// Mean over worlds of `[successful and best] / (number of cases tied for best)`: two
    /// identical best cases get 0.5 each. A world where no case succeeds counts for nobody, so
    /// the values of all cases sum to at most 1.
    pub p_best: f64,
    /// 5 % quantile of the case's rank over the worlds ([`quantile_sorted`]).
    pub rank_p05: f64,
    /// Median rank.
    pub rank_p50: f64,
    /// 95 % quantile of the rank.
    pub rank_p95: f64,
    /// Mean rank.
    pub rank_mean: f64,
}

/// The number of worlds every row has (the shortest row's length; 0 without rows).
fn worlds(obj: &[Vec<f64>], ok: &[Vec<bool>]) -> usize {
    obj.iter()
        .map(Vec::len)
        .chain(ok.iter().map(Vec::len))
        .min()
        .unwrap_or(0)
}

/// Whether case `c` succeeded in world `w` with a finite objective.
fn success(obj: &[Vec<f64>], ok: &[Vec<bool>], c: usize, w: usize) -> bool {
    ok[c][w] && obj[c][w].is_finite()
}

/// Per case, its [`RankStats`] over the worlds. In each world a case's rank is 1 + the number
/// of cases strictly better: a successful case is better than another with a smaller
/// objective and better than any failed case; failed cases tie behind all successful ones.
/// Ranks lie in `1..=C` for C cases. With no worlds every field is NaN. Cases beyond
/// `min(obj.len(), ok.len())` are not ranked.
pub fn rank_stats(obj: &[Vec<f64>], ok: &[Vec<bool>]) -> Vec<RankStats> {
    let cases = obj.len().min(ok.len());
    let (obj, ok) = (&obj[..cases], &ok[..cases]);
    let nw = worlds(obj, ok);
    let mut ranks = vec![Vec::with_capacity(nw); cases];
    let mut p_best = vec![0.0; cases];
    let mut good: Vec<f64> = Vec::with_capacity(cases);
    for w in 0..nw {
        good.clear();
        good.extend(
            (0..cases)
                .filter(|&c| success(obj, ok, c, w))
                .map(|c| obj[c][w]),
        );
        good.sort_by(f64::total_cmp);
        let best = good.first().copied();
        let tied = good.iter().take_while(|&&v| Some(v) == best).count();
        for c in 0..cases {
            let rank = if success(obj, ok, c, w) {
                let v = obj[c][w];
                if Some(v) == best {
                    p_best[c] += 1.0 / tied as f64;
                }
                1 + good.partition_point(|&g| g < v)
            } else {
                1 + good.len()
            };
            ranks[c].push(rank as f64);
        }
    }
    ranks
        .into_iter()
        .zip(p_best)
        .map(|(mut r, pb)| {
            r.sort_by(f64::total_cmp);
            let n = r.len() as f64;
            RankStats {
                p_best: pb / n,
                rank_p05: quantile_sorted(&r, 0.05),
                rank_p50: quantile_sorted(&r, 0.5),
                rank_p95: quantile_sorted(&r, 0.95),
                rank_mean: r.iter().sum::<f64>() / n,
            }
        })
        .collect()
}

/// The rule of [`verdict`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VerdictSettings {
    /// Confidence level `1 − α` of the verdict's tests (default 0.95): a winner is named only
    /// when the one-sided sign tests against every other eligible case reject "not better" at
    /// family-wise level `α` after Holm's correction.
    pub confidence: f64,
    /// Relative margin below which a difference in one world is a tie (default 0.01).
    pub equivalence: f64,
    /// Relative tuning noise (e.g. the median spread of tuned objectives across restarts;
    /// default 0): differences inside it are ties too.
    pub noise: f64,
}

impl Default for VerdictSettings {
    fn default() -> Self {
        VerdictSettings {
            confidence: 0.95,
            equivalence: 0.01,
            noise: 0.0,
        }
    }
}

/// A [`VerdictSettings`] field out of its range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VerdictSettingsError {
    /// `confidence` must lie in (0, 1).
    #[error("confidence must be in (0, 1), got {0}")]
    Confidence(f64),
    /// `equivalence` must be finite and ≥ 0.
    #[error("equivalence must be a finite relative margin ≥ 0, got {0}")]
    Equivalence(f64),
    /// `noise` must be finite and ≥ 0.
    #[error("noise must be a finite relative spread ≥ 0, got {0}")]
    Noise(f64),
}

impl VerdictSettings {
    /// Checks every field's range (callers locate the error in their file).
    pub fn validate(&self) -> Result<(), VerdictSettingsError> {
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return Err(VerdictSettingsError::Confidence(self.confidence));
        }
        if !(self.equivalence.is_finite() && self.equivalence >= 0.0) {
            return Err(VerdictSettingsError::Equivalence(self.equivalence));
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return Err(VerdictSettingsError::Noise(self.noise));
        }
        Ok(())
    }
}

/// How the leader compares with one other case.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contender {
    /// The case's index.
    pub case: usize,
    /// Fraction of all worlds in which the leader succeeds and beats this case (the case fails,
    /// or the leader is better by more than the relative margin δ): `wins / W`.
    pub p_beats: f64,
    /// Median over the worlds where both succeed of `(obj_c − obj_L) / |obj_L|` (NaN when
    /// there is no such world).
    pub margin: f64,
    /// Worlds the leader wins ([`Contender::p_beats`] × W).
    pub wins: usize,
    /// The one-sided sign test's p-value of the wins ([`super::confidence::sign_test_p`]).
    pub p_value: f64,
    /// The Holm-adjusted p-value over the leader's comparisons
    /// ([`super::confidence::holm_adjusted`]).
    pub p_adjusted: f64,
    /// For a case the leader does not beat with confidence but leads (more wins than half the
    /// worlds and a median margin beyond δ): the fewest worlds in which the same share of wins
    /// would reach the confidence (`None`: a tie, or more than 65 536 worlds).
    pub needs_worlds: Option<usize>,
}

/// The answer of [`verdict`].
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// The leader beats every other eligible case with the stated confidence (Holm-corrected
    /// one-sided sign tests of the paired margin).
    Winner {
        /// The winning case.
        leader: usize,
        /// The other eligible case with the smallest margin; the leader itself when it is the
        /// only eligible case.
        runner_up: usize,
        /// The leader's `p_beats` against the runner-up (1 when alone).
        p_beats: f64,
        /// The leader's margin over the runner-up (NaN when alone).
        margin: f64,
        /// The largest Holm-adjusted p-value over the comparisons (0 when alone).
        p_value: f64,
    },
    /// Some eligible cases are not beaten with the required confidence and the data do not
    /// lean to the leader against at least one of them (a tie).
    Tied {
        /// The case with the lowest mean objective.
        leader: usize,
        /// Every other eligible case the leader does not beat with confidence, by increasing
        /// margin (NaN margins last, then by index).
        tied: Vec<Contender>,
    },
    /// The leader leads every case it does not beat with confidence, but there are too few
    /// worlds to reach the confidence: more worlds could decide.
    Undecided {
        /// The case with the lowest mean objective.
        leader: usize,
        /// The cases not yet beaten with confidence (each with its `needs_worlds`).
        open: Vec<Contender>,
        /// The most worlds any open comparison needs.
        needs_worlds: usize,
    },
    /// No case is eligible.
    NoneEligible,
}

impl Verdict {
    /// The leader (winner, first of a tie, or undecided leader), if any case is eligible.
    pub fn leader(&self) -> Option<usize> {
        match self {
            Verdict::Winner { leader, .. }
            | Verdict::Tied { leader, .. }
            | Verdict::Undecided { leader, .. } => Some(*leader),
            Verdict::NoneEligible => None,
        }
    }
}

/// The worlds case `c` met: its row's length.
fn met(obj: &[Vec<f64>], ok: &[Vec<bool>], c: usize) -> usize {
    obj[c].len().min(ok[c].len())
}

/// Mean objective of case `c` over the worlds where it succeeds (NaN when it never does).
fn mean_success(obj: &[Vec<f64>], ok: &[Vec<bool>], c: usize, nw: usize) -> f64 {
    let v: Vec<f64> = (0..nw)
        .filter(|&w| success(obj, ok, c, w))
        .map(|w| obj[c][w])
        .collect();
    if v.is_empty() {
        f64::NAN
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

/// Compares leader `l` with case `c` (see [`Contender`]), δ the relative tie margin; the
/// p-values are filled in by the caller.
fn contend(
    obj: &[Vec<f64>],
    ok: &[Vec<bool>],
    l: usize,
    c: usize,
    nw: usize,
    delta: f64,
) -> Contender {
    let mut beats = 0usize;
    let mut rel = Vec::with_capacity(nw);
    for w in 0..nw {
        if !success(obj, ok, l, w) {
            continue;
        }
        let (ol, oc) = (obj[l][w], obj[c][w]);
        if !success(obj, ok, c, w) {
            beats += 1;
            continue;
        }
        if ol < oc - delta * ol.abs() {
            beats += 1;
        }
        let r = (oc - ol) / ol.abs();
        if !r.is_nan() {
            rel.push(r);
        }
    }
    rel.sort_by(f64::total_cmp);
    Contender {
        case: c,
        p_beats: if nw == 0 {
            0.0
        } else {
            beats as f64 / nw as f64
        },
        margin: quantile_sorted(&rel, 0.5),
        wins: beats,
        p_value: sign_test_p(beats, nw),
        p_adjusted: f64::NAN,
        needs_worlds: None,
    }
}

/// The fewest worlds `n > nw` in which the share of wins `wins/nw` reaches a sign-test p-value
/// of at most `level` (`None` when the share is at most ½ or `n` would pass 65 536).
fn worlds_to_reach(wins: usize, nw: usize, level: f64) -> Option<usize> {
    if nw == 0 || 2 * wins <= nw {
        return None;
    }
    let share = wins as f64 / nw as f64;
    worlds_at_share(share, nw, |k, n| sign_test_p(k, n) <= level)
}

/// Orders contenders by increasing margin, NaN margins last, then by case index.
fn by_margin(a: &Contender, b: &Contender) -> std::cmp::Ordering {
    a.margin
        .is_nan()
        .cmp(&b.margin.is_nan())
        .then(a.margin.total_cmp(&b.margin))
        .then(a.case.cmp(&b.case))
}

/// Names a winner only when the data support it with the stated confidence
/// (`docs/statistics.md`, "The verdict").
///
/// Rows may differ in length (adaptive worlds): each case's mean is over its own row, each
/// comparison over the worlds both cases met (`W` = the shorter row's length); with rows of
/// one length this is the same as reading every row up to that length.
///
/// The leader is the eligible case (`eligible[c]`; missing entries count as not eligible) with
/// the lowest mean objective over the worlds where it succeeds (cases that never succeed come
/// last; ties go to the lower index). For every other eligible case c, the leader *wins* a
/// world when it succeeds there and either c fails or `obj_L < obj_c − δ·|obj_L|`, with
/// `δ = max(equivalence, noise)`; `p_beats = wins/W` and `margin` is the median relative
/// difference where both succeed ([`Contender`]). Each comparison is a one-sided exact sign test
/// of H₀ "the leader wins at most half of the worlds" (`p = P(Binomial(W, ½) ≥ wins)`), and
/// the comparisons are corrected together by Holm's procedure at `α = 1 − confidence`. The
/// leader is a [`Verdict::Winner`] iff every comparison is rejected; the runner-up is then the
/// case with the smallest margin. A single eligible case is a winner over itself:
/// `runner_up = leader`, `p_beats = 1`, `margin = NaN`. Otherwise the cases not beaten are
/// either *open* — the leader wins more than half of the worlds against them and the median
/// margin exceeds δ, so more worlds (`needs_worlds`) could decide — or *tied*. All open →
/// [`Verdict::Undecided`]; any tied → [`Verdict::Tied`].
pub fn verdict(
    obj: &[Vec<f64>],
    ok: &[Vec<bool>],
    eligible: &[bool],
    s: &VerdictSettings,
) -> Verdict {
    let cases = obj.len().min(ok.len()).min(eligible.len());
    let candidates: Vec<(usize, f64)> = (0..cases)
        .filter(|&c| eligible[c])
        .map(|c| (c, mean_success(obj, ok, c, met(obj, ok, c))))
        .collect();
    let Some(&(leader, _)) = candidates.iter().min_by(|a, b| {
        a.1.is_nan()
            .cmp(&b.1.is_nan())
            .then(a.1.total_cmp(&b.1))
            .then(a.0.cmp(&b.0))
    }) else {
        return Verdict::NoneEligible;
    };
    let delta = s.equivalence.max(s.noise);
    let alpha = 1.0 - s.confidence;
    let mut others: Vec<Contender> = candidates
        .iter()
        .filter(|&&(c, _)| c != leader)
        .map(|&(c, _)| {
            let nw = met(obj, ok, leader).min(met(obj, ok, c));
            contend(obj, ok, leader, c, nw, delta)
        })
        .collect();
    let p: Vec<f64> = others.iter().map(|c| c.p_value).collect();
    let rejected = holm(&p, alpha);
    for (c, a) in others.iter_mut().zip(holm_adjusted(&p)) {
        c.p_adjusted = a;
    }
    // The open comparisons must reach, each, at least the last Holm threshold α/m_open.
    let m_open = rejected.iter().filter(|r| !**r).count().max(1);
    for (c, r) in others.iter_mut().zip(&rejected) {
        if !*r && c.margin > delta {
            let nw = met(obj, ok, leader).min(met(obj, ok, c.case));
            c.needs_worlds = worlds_to_reach(c.wins, nw, alpha / m_open as f64);
        }
    }
    // Each comparison with whether Holm rejected it, by increasing margin.
    let mut judged: Vec<(Contender, bool)> = others.into_iter().zip(rejected).collect();
    judged.sort_by(|a, b| by_margin(&a.0, &b.0));
    if judged.iter().all(|(_, r)| *r) {
        let p_value = judged
            .iter()
            .map(|(c, _)| c.p_adjusted)
            .fold(0.0f64, f64::max);
        return match judged.first() {
            Some((r, _)) => Verdict::Winner {
                leader,
                runner_up: r.case,
                p_beats: r.p_beats,
                margin: r.margin,
                p_value,
            },
            None => Verdict::Winner {
                leader,
                runner_up: leader,
                p_beats: 1.0,
                margin: f64::NAN,
                p_value: 0.0,
            },
        };
    }
    let others: Vec<Contender> = judged
        .into_iter()
        .filter(|(_, beaten)| !beaten)
        .map(|(c, _)| c)
        .collect();
    if others.iter().all(|c| c.needs_worlds.is_some()) {
        let needs_worlds = others
            .iter()
            .filter_map(|c| c.needs_worlds)
            .max()
            .unwrap_or(met(obj, ok, leader));
        return Verdict::Undecided {
            leader,
            open: others,
            needs_worlds,
        };
    }
    Verdict::Tied {
        leader,
        tied: others,
    }
}

//! The parts of `summary.md` a study with uncertain worlds adds (issue 22): the verdict it
//! opens with ("Winner: #N …" or "Statistically tied: #a, #b, …"), the ranking over the
//! paired worlds with its rank-interval plot, tuning adequacy (tuning noise beside the top
//! margin, bound hits), the sensitivity of each tracked metric to the uncertain parameters
//! (pooled SRRC, or Sobol indices with a Saltelli design) with tornado plots, and the
//! held-out validation gaps. Everything is read from the output directory (`cases`,
//! `worlds.csv`, `manifest.json`), so `usm-study report` regenerates it.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::plots_ranked::{write_pdf, write_plot};
use super::selection::cell_text;
use super::verdict_box::{verdict_box, BoxInput};
use crate::batch::conditions::Condition;
use crate::batch::manifest::Manifest;
use crate::batch::records::CASE_ID;
use crate::batch::robust::{
    study_verdict, RobustInfo, StudyVerdict, P_BEST, RANK_COLUMNS, WORLDS_CSV,
};
use crate::batch::worlds::{SUCCESS_PROBABILITY, VALIDATE_PREFIX};
use crate::report::plot::{
    rank_interval_pdf, rank_interval_svg, tornado_pdf, tornado_svg, RankRow, TornadoRow,
};
use crate::report::{fmt_short, read_csv, MarkdownTable, Table};
use crate::report::{Colour, Figure, Panel, Series};
use crate::stats::ranking::Verdict;
use crate::stats::sobol::{sobol_indices, SaltelliDesign};
use crate::stats::srrc::srrc;
use crate::study::schema::{TUNED_PREFIX, TUNE_BOUND_HITS, TUNE_NOISE};

/// How the verdict line [`Robust::verdict_line`] writes opens.
pub const VERDICT_OPENINGS: [&str; 5] = [
    crate::batch::conditions::PER_CONDITION,
    "**Winner:",
    "**Statistically tied:",
    "**Undecided:",
    "**No winner",
];

/// The verdict line of a `summary.md` text: its first paragraph after the title when it is one
/// ([`VERDICT_OPENINGS`]); `None` for a study without uncertain worlds.
pub fn summary_verdict(md: &str) -> Option<&str> {
    let first = md.lines().skip(1).find(|l| !l.trim().is_empty())?;
    VERDICT_OPENINGS
        .iter()
        .any(|p| first.starts_with(p))
        .then_some(first)
}

/// The line that ends the verdict and its box in `summary.md` (an HTML comment: Markdown
/// viewers hide it; the review page takes the block above it as its verdict box).
pub const VERDICT_END: &str = "<!-- end of the verdict -->";

/// The verdict line and its box ([`Robust::opening`]) of a `summary.md` text, without the
/// end marker; `None` for a study without uncertain worlds.
pub fn summary_opening(md: &str) -> Option<&str> {
    let first = summary_verdict(md)?;
    let start = md.find(first)?;
    let end = md[start..]
        .find(VERDICT_END)
        .map_or(start + first.len(), |e| start + e);
    Some(md[start..end].trim_end())
}

/// Most designs listed in the ranking table and drawn in the rank-interval plot.
const TOP: usize = 12;

/// What the robust sections read.
pub struct Robust<'a> {
    table: &'a Table,
    info: &'a RobustInfo,
    worlds: std::rc::Rc<Table>,
    verdict: StudyVerdict,
    ids: Vec<i64>,
    axes: Vec<&'a str>,
    /// The condition this view judges (a child view of a study with condition axes,
    /// [`Robust::views`]); `None` for the study as a whole.
    condition: Option<Condition>,
    /// The "how firm" paragraph of the box ([`super::verdict_firm`]; empty in a condition's
    /// view: the study states it once).
    firm: String,
}

impl<'a> Robust<'a> {
    /// The robust view of an output directory (`None` without worlds).
    pub fn load(dir: &Path, table: &'a Table, m: &'a Manifest) -> Option<Robust<'a>> {
        let info = m.robust.as_ref()?;
        let worlds = read_csv(&dir.join(WORLDS_CSV)).ok()?;
        let verdict = study_verdict(table, &worlds, info)?;
        let firm = super::verdict_firm::how_firm(dir, m.seed, info, &verdict);
        Some(Robust {
            firm,
            table,
            info,
            worlds: std::rc::Rc::new(worlds),
            verdict,
            ids: table.i64(CASE_ID).ok()?.to_vec(),
            axes: m.axes.iter().map(|a| a.name.as_str()).collect(),
            condition: None,
        })
    }

    fn label(&self, r: usize) -> String {
        let axes: Vec<String> = self
            .axes
            .iter()
            .map(|a| cell_text(self.table, a, r))
            .collect();
        format!("#{} ({})", self.ids[r], axes.join(", "))
    }

    /// The leader of the verdict (winner or first of the tie), if any design is ranked; none
    /// for a study with condition axes as a whole (each condition has its own).
    fn leader(&self) -> Option<usize> {
        if self.across_conditions() {
            return None;
        }
        self.verdict.verdict.leader()
    }

    fn pct(x: f64) -> String {
        if x.is_finite() {
            format!("{:.2} %", 100.0 * x)
        } else {
            "–".into()
        }
    }

    /// The verdict line and the box under it ([`super::verdict_box`]): the leader's caveats
    /// and the top designs side by side.
    pub fn opening(&self) -> String {
        if self.across_conditions() {
            return self.opening_per_condition();
        }
        let ranked = self.ranked_rows();
        let label = |r: usize| self.label(r);
        let inp = BoxInput {
            table: self.table,
            ranked: &ranked,
            objective: self.info.objective(),
            label: &label,
            axes: &self.axes,
            within: None,
            min_success: self.info.min_success_probability,
        };
        let (line, boxed) = (self.verdict_line(), verdict_box(&inp));
        format!("{line}\n\n{}{boxed}{VERDICT_END}", self.firm)
    }

    /// The ranking, tuning-adequacy, sensitivity and validation sections; plots into
    /// `plots`.
    pub fn sections(&self, dir: &Path, plots: &Path, warnings: &mut Vec<String>) -> String {
        let mut md = String::new();
        if self.across_conditions() {
            self.ranking_per_condition(&mut md, plots, warnings);
        } else {
            self.ranking_section(&mut md, plots, warnings);
        }
        self.tuning_section(&mut md);
        if self.tuning_curves(dir, plots, warnings) {
            let _ = writeln!(md, "![tuning curves](plots/tuning_curves.svg)\n");
        }
        self.sensitivity_section(&mut md, plots, warnings);
        self.validation_section(&mut md);
        md
    }

    fn col(&self, name: &str) -> Vec<f64> {
        self.table
            .f64(name)
            .map(<[f64]>::to_vec)
            .unwrap_or_else(|_| vec![f64::NAN; self.table.n_rows()])
    }

    /// Ranked rows by decreasing `p_best`, then increasing mean objective.
    fn ranked_rows(&self) -> Vec<usize> {
        let p = self.col(P_BEST);
        let mean = self.col(&format!("{}_mean", self.info.objective()));
        let mut rows: Vec<usize> = (0..self.table.n_rows())
            .filter(|&r| p[r].is_finite() && self.condition.as_ref().is_none_or(|c| c.rows[r]))
            .collect();
        rows.sort_by(|&a, &b| p[b].total_cmp(&p[a]).then(mean[a].total_cmp(&mean[b])));
        rows
    }

    /// The rows the sensitivity and validation sections describe: the ranked designs, or
    /// every design that ran in its worlds when none is ranked.
    fn scope(&self) -> Vec<usize> {
        let p = self.col(P_BEST);
        let ranked: Vec<usize> = (0..self.table.n_rows())
            .filter(|&r| p[r].is_finite())
            .collect();
        if !ranked.is_empty() {
            return ranked;
        }
        let sp = self.col(SUCCESS_PROBABILITY);
        (0..self.table.n_rows())
            .filter(|&r| sp[r].is_finite())
            .collect()
    }

    /// "ranked designs" or "designs that ran" for the rows of [`Robust::scope`].
    fn scope_text(&self) -> &'static str {
        if self.verdict.ranked > 0 && self.across_conditions() {
            "ranked designs of every condition"
        } else if self.verdict.ranked > 0 {
            "ranked designs"
        } else {
            "designs that ran (none is ranked)"
        }
    }

    fn ranking_section(&self, md: &mut String, plots: &Path, warnings: &mut Vec<String>) {
        let o = self.info.objective();
        let params: Vec<String> = self
            .info
            .params
            .iter()
            .map(|p| format!("`{}` {}", p.name, p.distribution))
            .collect();
        let (worlds, every) = match &self.info.adaptive {
            Some(a) if a.worlds_used > self.info.worlds => (
                format!("{}–{}", self.info.worlds, a.worlds_used),
                format!(
                    "Every design met the same first {} worlds and the designs in contention \
                     further points of the same sequence, up to {} (adaptive worlds; \
                     `worlds_met`)",
                    self.info.worlds, a.worlds_used
                ),
            ),
            _ => (
                self.info.worlds.to_string(),
                format!("Every design met the same {} worlds", self.info.worlds),
            ),
        };
        match &self.condition {
            Some(c) => writeln!(md, "### Under {}: ranking over {worlds} worlds\n", c.label),
            None => writeln!(md, "## Ranking over {worlds} uncertain worlds\n"),
        }
        .ok();
        let _ = writeln!(
            md,
            "{every} ({} sampling; common random numbers, so \
             comparisons are paired): {}. The nominal world is reported apart (the plain \
             metric columns). **{} designs are ranked**; {} ran but are not ranked because \
             their success probability is below {} (`{SUCCESS_PROBABILITY}`: fraction of \
             worlds meeting every `[success]` criterion).\n",
            self.info.sampling,
            params.join(", "),
            self.verdict.ranked,
            self.verdict.below_requirement,
            self.info.min_success_probability
        );
        // Counted over every design and world: once, not under each condition.
        if let (Ok(missed), None) = (
            self.worlds.str(crate::batch::worlds::MISSED),
            &self.condition,
        ) {
            let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
            for m in missed.iter().filter(|m| !m.is_empty()) {
                *counts.entry(m.as_str()).or_default() += 1;
            }
            if !counts.is_empty() {
                let list: Vec<String> = counts.iter().map(|(c, n)| format!("`{c}` {n}")).collect();
                let _ = writeln!(
                    md,
                    "Runs that missed a `[success]` criterion, by the first criterion missed \
                     (all designs × worlds, `worlds.csv` column `missed`): {}.\n",
                    list.join(", ")
                );
            }
        }
        let rows = self.ranked_rows();
        let mut t = MarkdownTable::new(
            [
                "case",
                P_BEST,
                "rank 5–95 %",
                &format!("{o} (nominal)"),
                "mean",
                "p05",
                "p95",
                "worst",
                SUCCESS_PROBABILITY,
            ]
            .into_iter()
            .chain(self.axes.iter().copied()),
        );
        let cells = |m: &str, r: usize| cell_text(self.table, m, r);
        for &r in rows.iter().take(TOP) {
            let mut cells_row = vec![
                format!("#{}", self.ids[r]),
                cells(P_BEST, r),
                format!(
                    "{}–{}",
                    cells(RANK_COLUMNS[0], r),
                    cells(RANK_COLUMNS[2], r)
                ),
                cells(o, r),
            ];
            for s in ["mean", "p05", "p95", "worst"] {
                cells_row.push(cells(&format!("{o}_{s}"), r));
            }
            cells_row.push(cells(SUCCESS_PROBABILITY, r));
            cells_row.extend(self.axes.iter().map(|a| cell_text(self.table, a, r)));
            t.row(cells_row);
        }
        let _ = writeln!(md, "{}", t.finish());
        self.rank_plot(&rows, md, plots, warnings);
    }

    /// Every design's best-so-far tuning curve (`tuning.csv`) relative to its final value, one
    /// faint line each: how many runs the tuning needed, and whether it had settled.
    fn tuning_curves(&self, dir: &Path, plots: &Path, warnings: &mut Vec<String>) -> bool {
        let Ok(t) = read_csv(&dir.join(crate::batch::robust::TUNING_CSV)) else {
            return false;
        };
        let (Ok(case), Ok(eval), Ok(best)) = (t.i64(CASE_ID), t.i64("evaluation"), t.f64("best"))
        else {
            return false;
        };
        let mut curves: BTreeMap<i64, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
        for i in 0..case.len() {
            let c = curves.entry(case[i]).or_default();
            c.0.push(eval[i] as f64);
            c.1.push(best[i]);
        }
        let mut panel = Panel::new(
            "best-so-far tuning objective / final value",
            "tuning run",
            "best so far / final",
        );
        // Not-ranked designs in grey under the ranked ones in blue.
        let p = self.col(P_BEST);
        let ranked: std::collections::BTreeSet<i64> = (0..self.ids.len())
            .filter(|&r| p[r].is_finite())
            .map(|r| self.ids[r])
            .collect();
        let mut order: Vec<_> = curves.iter().collect();
        order.sort_by_key(|(c, _)| ranked.contains(*c));
        let mut named = [false; 2];
        for (c, (x, y)) in order {
            let last = y
                .iter()
                .rev()
                .copied()
                .find(|v| v.is_finite())
                .unwrap_or(f64::NAN);
            let rel: Vec<f64> = y.iter().map(|v| v / last).collect();
            let k = usize::from(ranked.contains(c));
            let name = match (named[k], k) {
                (true, _) => "",
                (false, 1) => "ranked designs (one line each)",
                (false, _) => "not ranked (one line each)",
            };
            named[k] = true;
            let colour = if k == 1 {
                Colour::Palette(0)
            } else {
                Colour::Grey
            };
            panel
                .series
                .push(Series::new(name, x.clone(), rel).colour(colour));
        }
        let mut fig = Figure::new("Per-design tuning: best so far");
        fig.panels.push(panel);
        fig.size = (720, 420);
        match fig.write_svg_pdf(&plots.join("tuning_curves.svg")) {
            Ok(()) => true,
            Err(e) => {
                warnings.push(format!("tuning_curves.svg: {e}"));
                false
            }
        }
    }

    fn tuning_section(&self, md: &mut String) {
        let noise = self.col(TUNE_NOISE);
        if noise.iter().all(|x| x.is_nan()) && self.table.f64(TUNE_BOUND_HITS).is_err() {
            return;
        }
        let _ = writeln!(md, "## Tuning adequacy\n");
        let top_margin = match &self.verdict.verdict {
            Verdict::Winner { margin, .. } => *margin,
            Verdict::Tied { tied, .. } => tied.first().map_or(f64::NAN, |c| c.margin),
            Verdict::Undecided { open, .. } => open.first().map_or(f64::NAN, |c| c.margin),
            Verdict::NoneEligible => f64::NAN,
        };
        // A margin between designs under different conditions means nothing.
        let top_margin = if self.across_conditions() {
            f64::NAN
        } else {
            top_margin
        };
        let _ = writeln!(
            md,
            "Median tuning noise (relative spread of the tuned `{}` across independent tuning \
             starts, ranked designs): **{}**, beside a median margin of **{}** between the \
             leader and the closest design. A margin inside the tuning noise is a tie: a \
             winner is named only beyond both the noise and the equivalence margin.\n",
            self.info.objective(),
            if self.verdict.noise_measured {
                Self::pct(self.verdict.noise)
            } else {
                "not measured (`tune_noise` empty: one tuning start, or fewer than two reached a \
                 feasible point)"
                    .into()
            },
            Self::pct(top_margin)
        );
        if let Ok(hits) = self.table.f64(TUNE_BOUND_HITS) {
            let n_params = self
                .table
                .columns
                .iter()
                .filter(|c| c.name.starts_with(TUNED_PREFIX))
                .count();
            let tuned = hits.iter().filter(|x| x.is_finite()).count();
            let total: f64 = hits.iter().filter(|x| x.is_finite()).sum();
            let _ = writeln!(
                md,
                "Bound hits: {total:.0} of {} tuned gains ({tuned} designs × {n_params}) ended \
                 within 0.1 % of a bound of their box (`{TUNE_BOUND_HITS}`): a bound that \
                 binds says the box, not the design, decided. Best-so-far curves of every \
                 design: `tuning.csv`.\n",
                tuned * n_params
            );
        }
    }

    /// Per tracked metric: the sensitivity rows (name, value, lo, hi) and the method.
    /// Sobol total indices of `metric` per design from a Saltelli design of worlds (values by
    /// world index), the median over the designs with the median bootstrap interval.
    fn sobol_rows(
        &self,
        per_case: &BTreeMap<i64, Vec<(usize, f64)>>,
    ) -> (Vec<TornadoRow>, &'static str) {
        let d = self.info.params.len();
        let design = SaltelliDesign {
            n: self.info.worlds / (d + 2),
            d,
        };
        let mut all: Vec<Vec<crate::stats::sobol::SobolIndex>> = Vec::new();
        for (id, v) in per_case {
            let mut ys = vec![f64::NAN; self.info.worlds];
            for (w, x) in v {
                if *w < ys.len() {
                    ys[*w] = *x;
                }
            }
            all.push(sobol_indices(&design, &ys, 200, *id as u64));
        }
        let med = |f: &dyn Fn(&crate::stats::sobol::SobolIndex) -> f64, j: usize| {
            let mut v: Vec<f64> = all
                .iter()
                .map(|s| f(&s[j]))
                .filter(|x| x.is_finite())
                .collect();
            v.sort_by(f64::total_cmp);
            crate::stats::describe::quantile_sorted(&v, 0.5)
        };
        let rows = (0..d)
            .map(|j| TornadoRow {
                name: self.info.params[j].name.clone(),
                value: med(&|s| s.total, j),
                lo: med(&|s| s.total_lo, j),
                hi: med(&|s| s.total_hi, j),
            })
            .collect();
        (rows, "Sobol total index (median over the designs)")
    }

    fn sensitivity(&self, metric: &str) -> Option<(Vec<TornadoRow>, &'static str)> {
        // Every design that ran in its worlds (ranked or not): how the world moves a metric
        // is a question about the model, not about the winners.
        let sp = self.col(SUCCESS_PROBABILITY);
        let eligible: Vec<i64> = (0..self.table.n_rows())
            .filter(|&r| sp[r].is_finite())
            .map(|r| self.ids[r])
            .collect();
        let case = self.worlds.i64(CASE_ID).ok()?;
        let world = self.worlds.i64("world").ok()?;
        let y = self.worlds.f64(metric).ok()?;
        let d = self.info.params.len();
        let mut per_case: BTreeMap<i64, Vec<(usize, f64)>> = BTreeMap::new();
        for i in 0..case.len() {
            if eligible.contains(&case[i]) {
                per_case
                    .entry(case[i])
                    .or_default()
                    .push((world[i] as usize, y[i]));
            }
        }
        if self.info.sampling == "saltelli" {
            return Some(self.sobol_rows(&per_case));
        }
        // Each design's values relative to its own mean, grouped by world (the bootstrap
        // resamples worlds, the unit the parameters vary over).
        let mut by_world: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
        for v in per_case.values() {
            let finite: Vec<f64> = v
                .iter()
                .map(|(_, x)| *x)
                .filter(|x| x.is_finite())
                .collect();
            if finite.is_empty() {
                continue;
            }
            let mean = finite.iter().sum::<f64>() / finite.len() as f64;
            for (w, x) in v {
                if x.is_finite() && mean != 0.0 && *w < self.info.world_values.len() {
                    by_world.entry(*w).or_default().push(x / mean);
                }
            }
        }
        // Per world, the mean over the designs: the parameters vary only from world to world.
        let worlds: Vec<usize> = by_world.keys().copied().collect();
        let ybar: Vec<f64> = worlds
            .iter()
            .map(|w| by_world[w].iter().sum::<f64>() / by_world[w].len() as f64)
            .collect();
        let x: Vec<Vec<f64>> = worlds
            .iter()
            .map(|&w| self.info.world_values[w].clone())
            .collect();
        let n = worlds.len();
        if n < 4 {
            return None;
        }
        if n >= 3 * (d + 1) {
            // Enough worlds for a joint fit: SRRC, 95 % bootstrap over worlds.
            let coef = srrc(&x, &ybar).coef;
            let mut rng = crate::sampling::rng_for(0x5352_5243, 0); // "SRRC"
            let boots: Vec<Vec<f64>> = (0..200)
                .map(|_| {
                    let pick: Vec<usize> = (0..n)
                        .map(|_| rand::Rng::random_range(&mut rng, 0..n))
                        .collect();
                    let xs: Vec<Vec<f64>> = pick.iter().map(|&i| x[i].clone()).collect();
                    let ys: Vec<f64> = pick.iter().map(|&i| ybar[i]).collect();
                    srrc(&xs, &ys).coef
                })
                .collect();
            let rows = (0..d)
                .map(|j| {
                    let mut v: Vec<f64> = boots
                        .iter()
                        .map(|b| b[j])
                        .filter(|x| x.is_finite())
                        .collect();
                    v.sort_by(f64::total_cmp);
                    TornadoRow {
                        name: self.info.params[j].name.clone(),
                        value: coef[j],
                        lo: crate::stats::describe::quantile_sorted(&v, 0.025),
                        hi: crate::stats::describe::quantile_sorted(&v, 0.975),
                    }
                })
                .collect();
            return Some((
                rows,
                "SRRC of the per-world mean over the designs (each design relative to its \
                 mean); 95 % bootstrap over worlds",
            ));
        }
        // Fewer worlds than a joint fit of every parameter needs: each parameter's Spearman
        // rank correlation with the per-world mean (the SRRC of a one-parameter fit; the
        // space-filling worlds keep the parameters nearly uncorrelated), 95 % Fisher interval.
        let half = 1.96 / ((n - 3) as f64).sqrt();
        let rows = (0..d)
            .map(|j| {
                let col: Vec<Vec<f64>> = x.iter().map(|r| vec![r[j]]).collect();
                let rho = srrc(&col, &ybar).coef[0];
                let z = rho.clamp(-0.999_999, 0.999_999).atanh();
                TornadoRow {
                    name: self.info.params[j].name.clone(),
                    value: rho,
                    lo: (z - half).tanh(),
                    hi: (z + half).tanh(),
                }
            })
            .collect();
        Some((
            rows,
            "Spearman rank correlation with the per-world mean over the designs (each design \
             relative to its mean; too few worlds for a joint SRRC fit); 95 % Fisher interval",
        ))
    }

    fn sensitivity_section(&self, md: &mut String, plots: &Path, warnings: &mut Vec<String>) {
        let _ = writeln!(
            md,
            "## Sensitivity: which uncertain parameters drive each metric\n"
        );
        if self.info.sampling != "saltelli" && self.info.worlds < MIN_SENSITIVITY_WORLDS {
            // With a handful of worlds a rank correlation is ±1 by chance and its bootstrap
            // interval collapses onto it (issue 36 item 6): withheld, with the reason.
            let _ = writeln!(
                md,
                "Withheld: {} worlds are too few for a rank correlation to mean anything (with \
                 n worlds Spearman's ρ takes only n(n²−1)/6 + 1 values and a bootstrap over n \
                 worlds repeats them; the exact two-sided 5 % critical value is 0.648 at n = \
                 10). Run ≥ {MIN_SENSITIVITY_WORLDS} worlds for this section.\n",
                self.info.worlds
            );
            return;
        }
        for m in &self.info.metrics {
            let Some((mut rows, method)) = self.sensitivity(m) else {
                continue;
            };
            rows.sort_by(|a, b| b.value.abs().total_cmp(&a.value.abs()));
            let _ = writeln!(md, "### `{m}` — {method}; every design that ran\n");
            let mut t = MarkdownTable::new(["rank", "parameter", "index", "95 % interval"]);
            for (i, r) in rows.iter().enumerate() {
                t.row([
                    (i + 1).to_string(),
                    format!("`{}`", r.name),
                    fmt_short(r.value),
                    if r.lo.is_finite() {
                        format!("{} … {}", fmt_short(r.lo), fmt_short(r.hi))
                    } else {
                        "–".into()
                    },
                ]);
            }
            let _ = writeln!(md, "{}", t.finish());
            let file = format!("tornado_{}.svg", crate::report::file_stem_safe(m));
            match tornado_svg(&format!("What drives {m}"), method, &rows) {
                Ok(svg) => {
                    write_plot(plots, &file, &svg, warnings);
                    let pdf = tornado_pdf(&format!("What drives {m}"), method, &rows);
                    write_pdf(plots, &file, pdf, warnings);
                    let _ = writeln!(md, "![tornado {m}](plots/{file})\n");
                }
                Err(e) => warnings.push(format!("{file}: {e}")),
            }
        }
    }

    fn validation_section(&self, md: &mut String) {
        if self.info.validate.is_empty() {
            return;
        }
        let o = self.info.objective();
        let _ = writeln!(md, "## Held-out validation\n");
        let _ = writeln!(
            md,
            "Each design at its tuned values in scenario variants not used in tuning; gap = \
             relative change of `{o}` from the nominal run (median over the {}; the \
             leader's own in the last column).\n",
            self.scope_text()
        );
        let leader = self.leader();
        let scope = self.scope();
        let mut t = MarkdownTable::new(["variant", "median gap", "successful", "leader's gap"]);
        for v in &self.info.validate {
            let gap = self.col(&format!("{VALIDATE_PREFIX}{v}.gap"));
            let ok = self.col(&format!("{VALIDATE_PREFIX}{v}.success"));
            let rows = &scope;
            let mut g: Vec<f64> = rows
                .iter()
                .map(|&r| gap[r])
                .filter(|x| x.is_finite())
                .collect();
            g.sort_by(f64::total_cmp);
            let n_ok = rows.iter().filter(|&&r| ok[r] == 1.0).count();
            t.row([
                format!("`{v}`"),
                Self::pct(crate::stats::describe::quantile_sorted(&g, 0.5)),
                format!("{n_ok} of {}", rows.len()),
                leader.map_or("–".into(), |l| Self::pct(gap[l])),
            ]);
        }
        let _ = writeln!(md, "{}", t.finish());
    }
}

/// The fewest worlds for which the sensitivity section prints rank correlations or
/// regression coefficients (fewer: withheld with the reason).
pub const MIN_SENSITIVITY_WORLDS: usize = 10;

#[path = "summary_robust_verdict.rs"]
mod verdict_line;

#[path = "summary_robust_conditions.rs"]
mod per_condition;

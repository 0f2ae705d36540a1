//! The files of `usm-study optimise` (docs/optimise.md): `history.csv` and `history.parquet`
//! (every evaluation), `best.toml` (a scenario file `usm-study simulate` runs as is; a design
//! file for static problems; one `best_<scenario>.toml` per further scenario), `summary.md`
//! (start vs best: parameters, objective terms, constraints), `manifest.json`, and the plots
//! `progress.svg` (objective and best so far against evaluations), `parameters.svg` (each
//! parameter's trace) and `runs.svg` (the start and the best run side by side, laid out like
//! the paper's figures).

use std::path::Path;

use serde_json::json;

use super::error::PipelineError;
use super::optimise_plots::{parameter_figure, progress_figure};
use super::run_figure::run_figure;
use crate::batch::manifest::{git_commit, now_rfc3339};
use crate::control::transport::yaw_joint_mask;
use crate::evaluate::static_table::STATIC_TABLE;
use crate::model::design::parse_design_table;
use crate::optimise::evaluate::CaseEvaluator;
use crate::optimise::history::{history_table, Record};
use crate::optimise::score::mean_of;
use crate::optimise::{Outcome, Problem};
use crate::report::{
    atomic_write, file_stem_safe, fmt_num, write_csv, write_parquet, Figure, MarkdownTable, Panel,
};
use crate::scenario::Mode;
use crate::study::cases::Resolved;
use crate::study::runner::StudyMode;

/// The history table's file stem in an output directory.
pub const HISTORY: &str = "history";
/// The best point as a scenario (or design) file.
pub const BEST_FILE: &str = "best.toml";

/// Which optional outputs to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OptimiseFiles {
    /// The SVG plots (the side-by-side runs rerun the start and the best point with logging).
    pub plots: bool,
}

/// The scenario names of a problem (`""` for a single unnamed one).
fn scenario_names(problem: &Problem) -> Vec<String> {
    problem
        .spec
        .variants
        .iter()
        .map(|v| v.name.clone())
        .collect()
}

/// Write every output of `outcome` into `out` (which must exist).
pub fn write_outputs(
    problem: &Problem,
    outcome: &Outcome,
    out: &Path,
    files: OptimiseFiles,
) -> Result<(), PipelineError> {
    let params: Vec<String> = problem
        .spec
        .space
        .params
        .iter()
        .map(|p| p.name.clone())
        .collect();
    let table = history_table(
        &outcome.records,
        &params,
        &outcome.metrics,
        &scenario_names(problem),
    )?;
    write_csv(&table, &out.join(format!("{HISTORY}.csv")))?;
    write_parquet(&table, &out.join(format!("{HISTORY}.parquet")))?;
    let ev = CaseEvaluator::new(problem);
    write_best_files(problem, &ev, &outcome.best().x, out)?;
    atomic_write(
        &out.join("summary.md"),
        summary_md(problem, outcome).as_bytes(),
    )?;
    let manifest = serde_json::to_string_pretty(&manifest(problem, outcome))?;
    atomic_write(&out.join("manifest.json"), manifest.as_bytes())?;
    if files.plots {
        progress_figure(outcome).write_svg(&out.join("progress.svg"))?;
        parameter_figure(&problem.spec.space.params, &outcome.records, outcome.best)
            .write_svg(&out.join("parameters.svg"))?;
        if let Some(fig) = runs_figure(problem, &ev, outcome)? {
            fig.write_svg(&out.join("runs.svg"))?;
        }
    }
    Ok(())
}

/// The file name of scenario `v`'s best point: `best.toml`, then `best_<name>.toml`.
pub fn best_file_name(problem: &Problem, v: usize) -> String {
    if v == 0 {
        BEST_FILE.to_string()
    } else {
        format!(
            "best_{}.toml",
            file_stem_safe(&problem.spec.variants[v].name)
        )
    }
}

/// The text of a resolved case as a file `simulate` runs (dynamic modes: the scenario with
/// its design inline) or `inspect` reads (static mode: the design).
pub fn case_file_text(problem: &Problem, r: &Resolved, x: &[f64]) -> Result<String, PipelineError> {
    let mut head = format!(
        "# The best point of optimisation problem `{}`:\n",
        problem.study.name
    );
    for (p, v) in problem.spec.space.params.iter().zip(x) {
        head.push_str(&format!("#   {} = {v:e}\n", p.name));
    }
    let body = if problem.study.mode == StudyMode::Static {
        toml::to_string(&r.design)
    } else {
        let mut t = r.scenario.clone();
        t.remove(STATIC_TABLE);
        t.insert("design".into(), toml::Value::Table(r.design.clone()));
        toml::to_string(&t)
    };
    let body = body.map_err(crate::scenario::ScenarioError::Serialize)?;
    Ok(format!("{head}\n{body}"))
}

fn write_best_files(
    problem: &Problem,
    ev: &CaseEvaluator<'_>,
    x: &[f64],
    out: &Path,
) -> Result<(), PipelineError> {
    for v in 0..problem.spec.variants.len() {
        let r = ev.resolve(x, v)?;
        let text = case_file_text(problem, &r, x)?;
        atomic_write(&out.join(best_file_name(problem, v)), text.as_bytes())?;
    }
    Ok(())
}

fn manifest(problem: &Problem, o: &Outcome) -> serde_json::Value {
    let best = o.best();
    let params: serde_json::Map<String, serde_json::Value> = problem
        .spec
        .space
        .params
        .iter()
        .zip(&best.x)
        .map(|(p, x)| (p.name.clone(), json!(x)))
        .collect();
    json!({
        "problem": problem.study.name,
        "file": problem.study.path.display().to_string(),
        "hash": problem.study.hash,
        "mode": problem.study.mode.as_str(),
        "solver": problem.spec.solver,
        "objective": problem.spec.objective,
        "constraints": problem.spec.constraints,
        "scales": o.scorer.scales,
        "evaluations": o.records.len(),
        "fresh_evaluations": o.fresh_evaluations(),
        "replayed_from_journal": o.replayed,
        "stops": o.stops,
        "best": {
            "evaluation": best.index,
            "parameters": params,
            "score": best.score,
        },
        "start": { "score": o.start().score },
        "created": now_rfc3339(),
        "git_commit": git_commit(),
        "usm_study_version": env!("CARGO_PKG_VERSION"),
    })
}

fn change(a: f64, b: f64) -> String {
    if a.is_finite() && b.is_finite() && a != 0.0 {
        format!("{:+.1} %", 100.0 * (b - a) / a.abs())
    } else {
        "–".into()
    }
}

/// A warning when the best came in the last 10 % of the `n` evaluations (`best` its index,
/// 0-based): the budget, not convergence, may have ended the search.
fn late_best_warning(best: usize, n: usize) -> Option<String> {
    (n >= 10 && best * 10 >= n * 9).then(|| {
        format!(
            "**Warning: the best point came at evaluation {best} of {n}, in the last 10 % of the \
             budget** — the search was still improving when it stopped; a larger \
             `solver.max_evals` (or `--resume` with one) may find better.\n\n"
        )
    })
}

/// `summary.md`: the outcome, then start vs best for parameters, objective terms and
/// constraints.
pub fn summary_md(problem: &Problem, o: &Outcome) -> String {
    let (s, b) = (o.start(), o.best());
    let spec = &problem.spec;
    let mut md = format!(
        "# Optimisation `{}`\n\n{}Mode {}, solver {} (seed {}), {} evaluations ({} fresh), \
         best at evaluation {} ({}). Start = the problem file's values.\n\n",
        problem.study.name,
        if problem.study.description.is_empty() {
            String::new()
        } else {
            format!("{}\n\n", problem.study.description)
        },
        problem.study.mode,
        spec.solver.method.as_str(),
        spec.solver.seed,
        o.records.len(),
        o.fresh_evaluations(),
        b.index,
        if b.score.feasible {
            "feasible"
        } else {
            "INFEASIBLE"
        },
    );
    if let Some(w) = late_best_warning(b.index, o.records.len()) {
        md.push_str(&w);
    }
    md.push_str(&format!(
        "Objective {} → {} ({}); start {}, best {}.\n\nStops: {}.\n\n## Parameters\n\n",
        fmt_num(s.score.objective),
        fmt_num(b.score.objective),
        change(s.score.objective, b.score.objective),
        if s.score.feasible {
            "feasible"
        } else {
            "infeasible"
        },
        if b.score.feasible {
            "feasible"
        } else {
            "infeasible"
        },
        o.stops.join("; ")
    ));
    let mut t = MarkdownTable::new(["parameter", "lower", "upper", "scale", "start", "best"]);
    for (k, p) in spec.space.params.iter().enumerate() {
        let scale = if p.scale == crate::study::tune_space::Scale::Log {
            "log"
        } else {
            "lin"
        };
        t.row([
            p.name.clone(),
            fmt_num(p.lower),
            fmt_num(p.upper),
            scale.into(),
            fmt_num(s.x[k]),
            fmt_num(b.x[k]),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str("\n## Objective terms (mean over the scenarios)\n\n");
    let mut t = MarkdownTable::new([
        "metric",
        "weight",
        "scale",
        "start",
        "best",
        "change",
        "best term",
    ]);
    let terms = o.scorer.term_values(&b.metrics);
    for (i, term) in spec.objective.terms.iter().enumerate() {
        let k = o.scorer.term_columns[i];
        let (a, z) = (mean_of(&s.metrics, k), mean_of(&b.metrics, k));
        t.row([
            term.metric.clone(),
            fmt_num(term.weight),
            fmt_num(o.scorer.scales[i]),
            fmt_num(a),
            fmt_num(z),
            change(a, z),
            fmt_num(terms[i]),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str(&constraints_md(problem, o));
    md
}

fn constraints_md(problem: &Problem, o: &Outcome) -> String {
    if problem.spec.constraints.is_empty() {
        return "\nNo constraints.\n".into();
    }
    let (s, b) = (o.start(), o.best());
    let mut md = String::from("\n## Constraints (every scenario)\n\n");
    let mut t = MarkdownTable::new(["constraint", "start", "best", "start met", "best met"]);
    for (k, c) in problem.spec.constraints.iter().enumerate() {
        let col = o.scorer.constraint_columns[k];
        let met = |r: &Record| {
            let ok = r
                .metrics
                .iter()
                .all(|m| o.scorer.constraint_violation(k, m) == 0.0);
            if ok {
                "yes"
            } else {
                "no"
            }
        };
        let worst = |r: &Record| {
            r.metrics
                .iter()
                .map(|m| m.get(col).copied().unwrap_or(f64::NAN))
                .map(fmt_num)
                .collect::<Vec<_>>()
                .join(" / ")
        };
        t.row([
            format!("{} {} {}", c.metric, c.op.as_str(), fmt_num(c.value)),
            worst(s),
            worst(b),
            met(s).to_string(),
            met(b).to_string(),
        ]);
    }
    md.push_str(&t.finish());
    md
}

/// The start and the best run of the first scenario, rerun with logging, panel by panel:
/// start on the left, best on the right; `None` for static problems or a run without samples.
fn runs_figure(
    problem: &Problem,
    ev: &CaseEvaluator<'_>,
    o: &Outcome,
) -> Result<Option<Figure>, PipelineError> {
    let mode = match problem.study.mode {
        StudyMode::Static => return Ok(None),
        StudyMode::Work => Mode::Work,
        StudyMode::Transport => Mode::Transport,
    };
    let mut figs = Vec::new();
    for (label, r) in [("start", o.start()), ("best", o.best())] {
        let resolved = ev.resolve(&r.x, 0)?;
        let run = ev.run_case(&resolved, true);
        let vehicle = parse_design_table(&resolved.design, "optimised design")?;
        let yaw: Vec<usize> = yaw_joint_mask(&vehicle)
            .iter()
            .enumerate()
            .filter(|(_, y)| **y)
            .map(|(i, _)| i)
            .collect();
        let Some(traj) = run.trajectory.filter(|t| !t.is_empty()) else {
            return Ok(None);
        };
        let table = crate::evaluate::trajectory_table(&traj)?;
        figs.push(run_figure(&table, mode, &yaw, label)?);
    }
    let best = figs.pop().unwrap_or_else(|| Figure::new(""));
    let start = figs.pop().unwrap_or_else(|| Figure::new(""));
    let rows = start.panels.len().max(best.panels.len());
    let mut fig = Figure::new(format!(
        "{}: start (left) and best (right)",
        problem.study.name
    ));
    for (a, b) in start.panels.into_iter().zip(best.panels) {
        // One y range per row, so the two runs compare at a glance.
        let range = y_extent(&a).zip(y_extent(&b)).map(|(p, q)| {
            let (lo, hi) = (p.0.min(q.0), p.1.max(q.1));
            let pad = 0.05 * (hi - lo);
            (lo - pad, hi + pad)
        });
        let tag = |mut p: Panel, s: &str| {
            p.title = format!("{s}: {}", p.title);
            p.y_range = range.filter(|r| r.1 > r.0);
            p
        };
        fig.panels.push(tag(a, "start"));
        fig.panels.push(tag(b, "best"));
    }
    fig.layout = (rows, 2);
    fig.size = (1400, (300 * rows).max(400) as u32);
    Ok(Some(fig))
}

/// The finite y extent of a panel's series.
fn y_extent(p: &Panel) -> Option<(f64, f64)> {
    let ys = p.series.iter().flat_map(|s| &s.y).filter(|y| y.is_finite());
    ys.fold(None, |acc, &y| match acc {
        None => Some((y, y)),
        Some((lo, hi)) => Some((lo.min(y), hi.max(y))),
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_best_in_the_last_tenth_of_the_budget_is_warned_about() {
        assert!(super::late_best_warning(175, 180).is_some());
        assert!(super::late_best_warning(100, 180).is_none());
        assert!(super::late_best_warning(4, 5).is_none());
    }
}

//! `report.html`: the design-review page of a sweep (or any study) output directory — one
//! self-contained HTML file (inline CSS, SVG and one inline script that sorts and filters the
//! tables; no fonts, external links or requests) that a reviewer opens in a browser or prints.
//!
//! Built only from the files already in the directory, so `usm-study report DIR` can rebuild
//! it: `manifest.json` (study description and parameters), `summary.md` (its tables, with case
//! references linked to drawings), the case table `cases.parquet` / `cases.csv` (each case's
//! outcome and design name), `study.toml` (to rebuild the designs named in the tables, drawn
//! by [`super::draw`]) and every `plots/*.svg` and `*.svg` of the directory. Whatever is
//! missing is left out with a note; the page never needs a file that a sweep does not write.
//!
//! A case is *unsuccessful* when its `status` is not `ok` or its `success` column (when the
//! table has one) is false; such cases are drawn with a red frame and their table rows shaded.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::draw::draw_design;
use super::error::PipelineError;
use super::review_designs::{designs_html, rank_marks, DesignInputs};
use super::review_page::{figure_files, fold, plots_section, units_in_headers, with_toc};
use super::review_page::{PAGE_STYLE, SCRIPT};
use super::review_top::{pareto_html, top_ids, verdict_html, Drawing, TOP_STYLE};
use crate::batch::records::{CASES_CSV, CASES_PARQUET, CASE_ID, REASON, STUDY_COPY};
use crate::model::design::parse_design_table;
use crate::report::html::{escape, inline_svg, markdown_to_html, CaseLink};
use crate::report::{atomic_write, read_csv, read_parquet, Table};
use crate::review::plots::{case_name, unsuccessful_rows};
use crate::review::summary_robust::summary_opening;
use crate::state::VehicleState;
use crate::study::cases::resolve_case;
use crate::study::doe::expand;
use crate::study::parse::load_study;

/// The file name of the page.
pub const REPORT_HTML: &str = "report.html";
/// At most this many designs are drawn (the first named in the tables).
const MAX_DRAWINGS: usize = 40;

/// What [`write_review`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct ReviewOutcome {
    /// The page written.
    pub path: PathBuf,
    /// Designs drawn.
    pub drawings: usize,
    /// Figures inlined.
    pub plots: usize,
    /// Parts left out, and why (missing files, designs that could not be rebuilt).
    pub warnings: Vec<String>,
}

/// One case's outcome and name, from the case table.
#[derive(Clone, Debug, Default, PartialEq)]
struct CaseInfo {
    /// `status` is not `ok`, or `success` is false.
    unsuccessful: bool,
    /// Why (the `reason` cell, then any `success_*` / `missed*` text cell).
    why: String,
    /// Axis values joined by ` / `.
    name: String,
}

/// The cases of `table` whose id is `wanted`, by id: outcome, reason and design name (from
/// the `axes`).
fn case_infos(
    table: &Table,
    axes: &[&str],
    wanted: impl Fn(i64) -> bool,
) -> BTreeMap<i64, CaseInfo> {
    let Ok(ids) = table.i64(CASE_ID) else {
        return BTreeMap::new();
    };
    let bad = unsuccessful_rows(table);
    let why_cols: Vec<&[String]> = table
        .columns
        .iter()
        .filter(|c| {
            c.name == REASON || c.name.starts_with("success_") || c.name.starts_with("missed")
        })
        .filter_map(|c| table.str(&c.name).ok())
        .collect();
    (0..table.n_rows())
        .filter(|&r| wanted(ids[r]))
        .map(|r| {
            let why: Vec<&str> = why_cols
                .iter()
                .map(|c| c[r].as_str())
                .filter(|s| !s.is_empty())
                .collect();
            let info = CaseInfo {
                unsuccessful: bad[r],
                why: why.join("; "),
                name: case_name(table, axes, r).replace('/', " / "),
            };
            (ids[r], info)
        })
        .collect()
}

/// The case ids named (`#N`) in the table rows of a Markdown text, in order of appearance.
fn referenced_cases(md: &str) -> Vec<i64> {
    let mut seen = BTreeSet::new();
    let mut out = Vec::new();
    for l in md.lines().filter(|l| l.trim_start().starts_with('|')) {
        for part in l.split('#').skip(1) {
            let digits: String = part.chars().take_while(char::is_ascii_digit).collect();
            if let Ok(id) = digits.parse::<i64>() {
                if seen.insert(id) {
                    out.push(id);
                }
            }
        }
    }
    out
}

/// Removes the temporaries `.report.html.tmp-PID-…` a killed writer of this page left
/// (the page is written after the sweep's lock is released, so no lock takeover cleans them):
/// only those whose process is gone (Linux `/proc`; elsewhere nothing is removed).
fn remove_dead_temporaries(dir: &Path) {
    let prefix = format!(".{REPORT_HTML}.tmp-");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(token) = name.strip_prefix(&prefix) else {
            continue;
        };
        let pid = token.split('-').next().and_then(|p| p.parse::<u32>().ok());
        let alive = pid.is_none_or(|p| {
            !Path::new("/proc/self").exists() || Path::new(&format!("/proc/{p}")).exists()
        });
        if !alive && e.file_type().is_ok_and(|t| t.is_file()) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Rebuilds and draws the designs of `ids` (cases sharing a design drawn once), from the
/// original study file the manifest names (relative to `dir`) while its text is still the
/// copy's in `dir` — its relative paths (a `[design] file`) resolve only from there — else
/// from the copy.
fn drawings(dir: &Path, study_file: Option<&str>, ids: &[i64]) -> Result<Vec<Drawing>, String> {
    let copy = dir.join(STUDY_COPY);
    let original = study_file.map(|f| dir.join(f));
    let same = |p: &PathBuf| {
        let read = |p: &Path| std::fs::read(p).ok();
        read(p).is_some_and(|t| Some(t) == read(&copy))
    };
    let path = match original {
        Some(p) if !copy.is_file() || same(&p) => p,
        _ if copy.is_file() => copy,
        _ => return Err("no study.toml in the directory".into()),
    };
    let study = load_study(&path).map_err(|e| e.to_string())?;
    let all = expand(&study, None)?;
    let mut out: Vec<Drawing> = Vec::new();
    let mut by_hash: BTreeMap<String, usize> = BTreeMap::new();
    for &id in ids {
        let Some(case) = usize::try_from(id).ok().and_then(|i| all.get(i)) else {
            continue;
        };
        let Ok(r) = resolve_case(&study, case) else {
            continue;
        };
        if let Some(&k) = by_hash.get(&r.design_hash) {
            out[k].cases.push(id);
            continue;
        }
        if out.len() >= MAX_DRAWINGS {
            continue;
        }
        let Ok(v) = parse_design_table(&r.design, &format!("case {id} design")) else {
            continue;
        };
        let svg = draw_design(&v, &VehicleState::rest(&v), "straight, at rest")
            .map_err(|e| e.to_string())?;
        by_hash.insert(r.design_hash, out.len());
        out.push(Drawing {
            cases: vec![id],
            svg,
        });
    }
    Ok(out)
}

/// The case table of `dir`: `cases.parquet`, else `cases.csv`.
fn read_cases(dir: &Path) -> Option<Table> {
    let pq = dir.join(CASES_PARQUET);
    let csv = dir.join(CASES_CSV);
    let mut t = if pq.is_file() {
        read_parquet(&pq).ok()
    } else if csv.is_file() {
        read_csv(&csv).ok()
    } else {
        None
    }?;
    crate::study::dictionary::integers_for_files(&mut t, false);
    Some(t)
}

/// Inline style sheet: readable on screen and on paper; unsuccessful cases in red.
const STYLE: &str = "body{font-family:'DejaVu Sans',Arial,Helvetica,sans-serif;margin:24px auto;\
max-width:1280px;padding:0 16px;color:#111;line-height:1.4}h1{font-size:26px}h2{font-size:21px;\
border-bottom:2px solid #333;padding-bottom:3px;margin-top:34px}h3{font-size:17px}\
table{border-collapse:collapse;margin:8px 0;font-size:13px}th,td{border:1px solid #bbb;\
padding:3px 7px;text-align:left;vertical-align:top}th{background:#eee}\
tr.bad td{background:#fde2e2;color:#7f1d1d}code{font-size:12px}.r-scroll{overflow-x:auto}\
.r-name{color:#555;font-size:11px}.r-note{color:#555;font-style:italic}\
.r-ok{color:#166534;font-weight:bold}.r-badword{color:#b91c1c;font-weight:bold}\
.r-grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(380px,1fr));gap:14px}\
.r-card{border:2px solid #999;padding:6px;margin:0;break-inside:avoid}\
.r-card.bad{border-color:#b91c1c;background:#fff5f5}.r-card:target{grid-column:1/-1;\
border-color:#1d4ed8}.r-card svg{width:100%;height:auto;display:block}\
.r-plot svg{max-width:100%;height:auto;display:block}\
.r-card figcaption{font-size:13px;margin-top:4px}.r-plot{margin:14px 0;break-inside:avoid}\
.r-plot figcaption{font-size:13px;color:#333}.r-kv td:first-child{font-weight:bold}\
@media print{body{max-width:none}.r-grid{display:block}.r-card{margin-bottom:12px}\
.r-scroll{overflow:visible}table{font-size:8px;width:100%}th,td{padding:1px 3px;\
overflow-wrap:anywhere}table code{font-size:8px}}";

/// Writes `report.html` into `dir` (an existing output directory).
pub fn write_review(dir: &Path) -> Result<ReviewOutcome, PipelineError> {
    let mut warnings = Vec::new();
    let manifest: Option<serde_json::Value> = std::fs::read_to_string(dir.join("manifest.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    if manifest.is_none() {
        warnings.push("no readable manifest.json: study parameters left out".into());
    }
    let m = manifest.as_ref();
    let axes: Vec<String> = m
        .and_then(|m| m["axes"].as_array())
        .map(|a| {
            a.iter()
                .filter_map(|x| x["name"].as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let summary = std::fs::read_to_string(dir.join("summary.md")).ok();
    let named = summary.as_deref().map(referenced_cases).unwrap_or_default();
    // What the page needs of the case table: the named cases' details, the counts and whether
    // success was judged; the table itself is dropped before the page is built (a 100 000-case
    // table is tens of MB).
    let table = read_cases(dir);
    let (infos, counts, has_success) = match &table {
        Some(t) => {
            let wanted: BTreeSet<i64> = named.iter().copied().collect();
            let axes: Vec<&str> = axes.iter().map(String::as_str).collect();
            let infos = case_infos(t, &axes, |id| wanted.contains(&id));
            let bad = unsuccessful_rows(t).iter().filter(|b| **b).count();
            (
                infos,
                Some((t.n_rows(), bad)),
                t.column("success").is_some(),
            )
        }
        None => (BTreeMap::new(), None, false),
    };
    let robust = m.and_then(|m| m.get("robust")).filter(|r| r.is_object());
    let min_success = robust
        .and_then(|r| r["min_success_probability"].as_f64())
        .unwrap_or(f64::NAN);
    let marks = table
        .as_ref()
        .map(|t| rank_marks(t, &named, min_success))
        .unwrap_or_default();
    let study_file = m.and_then(|m| m["study_file"].as_str());
    let drawn = if named.is_empty() {
        Vec::new()
    } else {
        drawings(dir, study_file, &named).unwrap_or_else(|e| {
            warnings.push(format!("designs not drawn: {e}"));
            Vec::new()
        })
    };
    let top = summary
        .as_deref()
        .and_then(summary_opening)
        .map(top_ids)
        .unwrap_or_default();
    let objective = robust
        .and_then(|r| r["metrics"][0].as_str())
        .unwrap_or("mission_cost");
    let name = |id: i64| infos.get(&id).map(|i| i.name.clone()).unwrap_or_default();
    let design_html = table.as_ref().and_then(|t| {
        designs_html(&DesignInputs {
            dir,
            table: t,
            ids: &top,
            objective,
            drawings: &drawn,
            name: &name,
        })
    });
    drop(table);
    let figures = figure_files(dir);
    let page = Page {
        dir,
        manifest: m,
        axes: &axes,
        counts,
        has_success,
        infos: &infos,
        summary: summary.as_deref(),
        drawings: &drawn,
        marks: &marks,
        design_html: design_html.as_deref(),
    };
    let html = page.render(&figures, &mut warnings);
    let path = dir.join(REPORT_HTML);
    atomic_write(&path, html.as_bytes())?;
    remove_dead_temporaries(dir);
    Ok(ReviewOutcome {
        path,
        drawings: drawn.len(),
        plots: figures.len(),
        warnings,
    })
}

/// Everything the page shows.
struct Page<'a> {
    dir: &'a Path,
    manifest: Option<&'a serde_json::Value>,
    axes: &'a [String],
    /// Cases in the table and how many of them are unsuccessful (no table: `None`).
    counts: Option<(usize, usize)>,
    /// The table has a `success` column.
    has_success: bool,
    infos: &'a BTreeMap<i64, CaseInfo>,
    summary: Option<&'a str>,
    drawings: &'a [Drawing],
    /// Each named case's rank mark (empty: the study ranks nothing over worlds).
    marks: &'a BTreeMap<i64, (bool, String)>,
    /// The per-design sections of the leader and its competitors.
    design_html: Option<&'a str>,
}

impl Page<'_> {
    /// The anchor of the drawing that shows case `id`, if any.
    fn anchor(&self, id: i64) -> Option<String> {
        self.drawings
            .iter()
            .find(|d| d.cases.contains(&id))
            .map(|d| format!("case-{}", d.cases[0]))
    }

    fn link(&self, id: i64) -> Option<CaseLink> {
        let info = self.infos.get(&id);
        if info.is_none() && self.anchor(id).is_none() {
            return None;
        }
        Some(CaseLink {
            anchor: self.anchor(id),
            unsuccessful: info.is_some_and(|i| i.unsuccessful),
            name: info.map(|i| i.name.clone()).filter(|n| !n.is_empty()),
            mark: self.marks.get(&id).cloned(),
        })
    }

    fn render(&self, figures: &[PathBuf], warnings: &mut Vec<String>) -> String {
        let title = self
            .manifest
            .and_then(|m| m["study_name"].as_str())
            .map(String::from)
            .unwrap_or_else(|| {
                self.dir
                    .file_name()
                    .map_or("study".into(), |n| n.to_string_lossy().into_owned())
            });
        // The page is mostly the inlined figures: reserve for them at once instead of
        // doubling a large string (and holding two copies) while it grows.
        let figure_bytes: u64 = figures
            .iter()
            .filter_map(|f| std::fs::metadata(f).ok().map(|m| m.len()))
            .sum();
        let mut h = String::with_capacity(figure_bytes as usize + (1 << 20));
        let _ = writeln!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>Design review: {t}</title>\n<style>{STYLE}{TOP_STYLE}{PAGE_STYLE}</style>\n</head>\n<body>\n\
             <h1>Design review: <code>{t}</code></h1>",
            t = escape(&title)
        );
        self.verdict_section(&mut h);
        if let Some(p) = pareto_html(self.dir, figures) {
            h.push_str(&p);
        }
        if let Some(d) = self.design_html {
            h.push_str(d);
        }
        self.success_section(&mut h);
        self.tables_section(&mut h);
        self.designs_section(&mut h);
        plots_section(&mut h, self.dir, figures, !self.marks.is_empty(), warnings);
        self.study_section(&mut h);
        self.ledger_section(&mut h);
        self.manifest_section(&mut h);
        h.push_str(SCRIPT);
        h.push_str("</body>\n</html>\n");
        with_toc(&h)
    }

    /// The answer first: the verdict box of `summary.md` (verdict line, caveats, top three
    /// side by side with their drawings), when the study has one.
    fn verdict_section(&self, h: &mut String) {
        if let Some(block) = self.summary.and_then(summary_opening) {
            let block = units_in_headers(block);
            h.push_str(&verdict_html(&block, self.drawings, &|id| self.link(id)));
        }
    }

    /// The assumption ledger of the manifest (studies with uncertain worlds): every
    /// inferred model parameter, its value, its source and the range used for it.
    fn ledger_section(&self, h: &mut String) {
        let Some(rows) = self.manifest.and_then(|m| m["ledger"].as_array()) else {
            return;
        };
        h.push_str(
            "<section id=\"ledger\">\n<h2>Assumption ledger</h2>\n<p>Model parameters that \
             are inferred rather than taken from a source, with the range the uncertain worlds \
             use (docs/assumptions.md).</p>\n<div class=\"r-scroll\"><table class=\"r-kv\">\n<tr><th>parameter</th>\
             <th>value</th><th>source</th><th>key</th><th>range</th></tr>\n",
        );
        for r in rows {
            let cell = |k: &str| escape(&json_text(&r[k]));
            let source = format!(
                "{}: {}",
                json_text(&r["source"]["kind"]),
                json_text(&r["source"]["text"])
            );
            let range = match (&r["study_range"], &r["range"]) {
                (serde_json::Value::String(s), _) => format!("this study: {s}"),
                (_, serde_json::Value::Array(a)) if a.len() == 2 => format!(
                    "held nominal here (ledger range {} … {})",
                    json_text(&a[0]),
                    json_text(&a[1])
                ),
                _ => "–".into(),
            };
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td><code>{}</code></td><td>{}</td></tr>",
                cell("name"),
                cell("value"),
                escape(&source),
                cell("key"),
                escape(&range)
            );
        }
        h.push_str("</table></div>\n</section>\n");
    }

    /// Description, parameters and counts from the manifest.
    fn study_section(&self, h: &mut String) {
        h.push_str("<section id=\"study\">\n<h2>The study</h2>\n");
        let Some(m) = self.manifest else {
            h.push_str("<p class=\"r-note\">No manifest.json in this directory.</p>\n</section>\n");
            return;
        };
        if let Some(d) = m["description"].as_str().filter(|d| !d.is_empty()) {
            let _ = writeln!(h, "<p>{}</p>", escape(d));
        }
        if !self.axes.is_empty() {
            let _ = writeln!(
                h,
                "<p>Axes swept: {}. A design is named by its axis values in this order \
                 (e.g. in tables: <code>#case</code> followed by the name).</p>",
                self.axes
                    .iter()
                    .map(|a| format!("<code>{}</code>", escape(a)))
                    .collect::<Vec<_>>()
                    .join(" / ")
            );
        }
        let c = &m["cases"];
        if let (Some(n), Some(ok)) = (c["in_output"].as_u64(), c["ok"].as_u64()) {
            let _ = writeln!(
                h,
                "<p>Mode <code>{}</code>, design of experiments <code>{}</code>, seed {}: \
                 {n} cases, {ok} ok, {} failed, {} skipped. All parameters are listed at the \
                 end of the page.</p>",
                escape(&json_text(&m["mode"])),
                escape(&json_text(&m["doe"])),
                escape(&json_text(&m["seed"])),
                json_text(&c["failed"]),
                json_text(&c["skipped"])
            );
        }
        h.push_str("</section>\n");
    }

    /// The run's record: a link to `manifest.json` (not its raw JSON) and the fields a reader
    /// of a printed page needs to place the run.
    fn manifest_section(&self, h: &mut String) {
        let Some(m) = self.manifest else {
            return;
        };
        h.push_str(
            "<section id=\"manifest\">\n<h2>Run record</h2>\n<p>Every parameter of the run is in \
             <a href=\"manifest.json\">manifest.json</a> (appendix, not printed here).</p>\n\
             <div class=\"r-scroll\"><table class=\"r-kv\">\n",
        );
        for k in [
            "tool_version",
            "git_commit",
            "study_hash",
            "seed",
            "start_time",
            "elapsed_s",
            "jobs",
        ] {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td></tr>",
                escape(k),
                escape(&json_text(&m[k]))
            );
        }
        h.push_str("</table></div>\n</section>\n");
    }

    /// What success means here, and how many cases met it.
    fn success_section(&self, h: &mut String) {
        h.push_str("<section id=\"success\">\n<h2>What success means</h2>\n");
        let rule = if self.has_success {
            "A case is <span class=\"r-ok\">successful</span> when its run finished \
             (<code>status</code> = <code>ok</code>) and it met its scenario's success criteria \
             (<code>success</code> column true)."
        } else {
            "A case is <span class=\"r-ok\">successful</span> when its run finished \
             (<code>status</code> = <code>ok</code>). This output has no <code>success</code> \
             column, so convergence and tracking criteria are not checked: read the tracking \
             columns (e.g. <code>converged</code>) before trusting a ranking."
        };
        let _ = writeln!(h, "<p>{rule}</p>");
        if let Some((n, bad)) = self.counts.filter(|(n, _)| *n > 0) {
            let _ = writeln!(
                h,
                "<p>{} of {n} cases successful, <span class=\"r-badword\">{bad} unsuccessful</span>. \
                 Unsuccessful cases are shaded red in the tables and framed red in the drawings.</p>",
                n - bad,
            );
        }
        h.push_str("</section>\n");
    }

    /// A drawing of every design named in the tables.
    fn designs_section(&self, h: &mut String) {
        h.push_str("<section id=\"designs\">\n<h2>Designs named in the tables</h2>\n");
        if self.drawings.is_empty() {
            h.push_str("<p class=\"r-note\">No design drawings (no case is named in the tables, or the study file could not be read).</p>\n</section>\n");
            return;
        }
        h.push_str("<p>Top, side and front views of each design, straight and at rest, to scale. Click a drawing (or a case number in a table) to enlarge it.</p>\n<div class=\"r-grid\">\n");
        for d in self.drawings {
            let first = d.cases[0];
            let info = |c: &i64| self.infos.get(c).cloned().unwrap_or_default();
            let bad: Vec<String> = d
                .cases
                .iter()
                .filter(|c| info(c).unsuccessful)
                .map(|c| {
                    let why = info(c).why;
                    format!(
                        "#{c} ({})",
                        if why.is_empty() {
                            "see the tables".into()
                        } else {
                            why
                        }
                    )
                })
                .collect();
            let ids: Vec<String> = d.cases.iter().map(|c| format!("#{c}")).collect();
            // Framed red when every case of this design was unsuccessful.
            let all_bad = bad.len() == d.cases.len();
            let _ = writeln!(
                h,
                "<figure class=\"r-card{}\" id=\"case-{first}\"><a href=\"#case-{first}\">{}</a>\
                 <figcaption><strong>{}</strong> {}{}</figcaption></figure>",
                if all_bad { " bad" } else { "" },
                inline_svg(&d.svg, &format!("c{first}-")),
                escape(&ids.join(", ")),
                escape(&info(&first).name),
                if bad.is_empty() {
                    self.marks
                        .get(&first)
                        .map_or(String::new(), |m| format!(" — {}", escape(&m.1)))
                } else {
                    format!(
                        " — <span class=\"r-badword\">unsuccessful</span>: {}{}",
                        escape(&bad.join("; ")),
                        self.marks
                            .get(&first)
                            .map_or(String::new(), |m| format!(" ({})", escape(&m.1)))
                    )
                }
            );
        }
        h.push_str("</div>\n</section>\n");
    }

    /// The tables of `summary.md`, case references linked.
    fn tables_section(&self, h: &mut String) {
        h.push_str("<section id=\"tables\">\n");
        match self.summary {
            Some(md) => {
                // The verdict box is at the top of the page already.
                let rest = match summary_opening(md) {
                    Some(block) => md.replacen(block, "", 1),
                    None => md.to_string(),
                };
                let html = markdown_to_html(&units_in_headers(&rest), 1, &|id| self.link(id));
                let folded = [
                    "best-case-by-each-metric",
                    "single-thruster-faults",
                    "cases-left-out",
                ];
                h.push_str(&fold(&html, &folded));
            }
            None => h.push_str(
                "<h2>Tables</h2>\n<p class=\"r-note\">No summary.md in this directory.</p>\n",
            ),
        }
        h.push_str("</section>\n");
    }
}

/// A manifest value as text: strings bare, objects as `key: value` pairs, null as `–`.
fn json_text(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Null => "–".into(),
        serde_json::Value::Object(o) => o
            .iter()
            .map(|(k, v)| format!("{k}: {}", json_text(v)))
            .collect::<Vec<_>>()
            .join(", "),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::records::STATUS;
    use crate::report::ColumnData;

    #[test]
    fn only_a_dead_writers_page_temporaries_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let dead = dir.path().join(".report.html.tmp-4194399-ab");
        let live = dir
            .path()
            .join(format!(".report.html.tmp-{}-cd", std::process::id()));
        let other = dir.path().join(".cases.csv.tmp-4194399-ab");
        for p in [&dead, &live, &other] {
            std::fs::write(p, "x").unwrap();
        }
        remove_dead_temporaries(dir.path());
        assert!(!dead.exists() || !Path::new("/proc/self").exists());
        assert!(live.exists() && other.exists());
    }

    #[test]
    fn outcomes_read_status_and_an_optional_success_column() {
        let mut t = Table::default();
        t.push(CASE_ID, ColumnData::I64(vec![0, 1, 2])).unwrap();
        let status = ["ok", "failed", "ok"].map(String::from).to_vec();
        t.push(STATUS, ColumnData::Str(status)).unwrap();
        let reason = ["", "diverged", ""].map(String::from).to_vec();
        t.push(REASON, ColumnData::Str(reason)).unwrap();
        t.push("design.links", ColumnData::F64(vec![3.0, 4.0, 5.0]))
            .unwrap();
        let axes = ["design.links"];
        let i = case_infos(&t, &axes, |_| true);
        assert!(!i[&0].unsuccessful && i[&1].unsuccessful && !i[&2].unsuccessful);
        assert_eq!((i[&1].why.as_str(), i[&1].name.as_str()), ("diverged", "4"));
        // With a `success` column, an ok run that missed its criteria is unsuccessful too.
        t.push("success", ColumnData::Bool(vec![true, false, false]))
            .unwrap();
        let i = case_infos(&t, &axes, |_| true);
        assert!(!i[&0].unsuccessful && i[&1].unsuccessful && i[&2].unsuccessful);
    }

    #[test]
    fn case_references_come_from_table_rows_only_once_each() {
        let md =
            "# Sweep\n\nCase #7 in a sentence.\n\n| a | b |\n|---|---|\n| #3 | #12 |\n| #3 | x |\n";
        assert_eq!(referenced_cases(md), [3, 12]);
    }
}

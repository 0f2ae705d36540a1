//! Navigating, sorting and printing the review page (issue 42 item 5): units in every column
//! header of the summary's tables (from the metric dictionary), a table of contents built from
//! the page's headings, the long tables folded (`<details>`), the self-contained script that
//! makes tables sortable and filterable (no network), the narrow-screen and print style sheets,
//! and what each figure shows of the ranked and not-ranked designs.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::report::html::{escape, inline_svg};
use crate::review::plots::metric_title;

/// Header cells that take the unit of the metric column before them (the summaries of one
/// metric over the worlds: `mean`, `p05`, …).
const SUMMARY_CELLS: [&str; 7] = ["mean", "p05", "p50", "p95", "worst", "median", "std"];

/// The unit text (`[J/m]`) of a header cell naming a metric (`` `mission_cost` (ok) ``,
/// `mission_cost (nominal)`), from the dictionary; `None` when it names none.
fn cell_unit(cell: &str) -> Option<String> {
    let name = cell
        .split('`')
        .nth(1)
        .unwrap_or(cell)
        .split_whitespace()
        .next()?
        .to_string();
    let t = metric_title(&name);
    let at = t.rfind(" [")?;
    Some(t[at + 1..].to_string())
}

/// A Markdown text with the unit appended to every header cell of its tables that names a
/// metric (`mission_cost [J/m]`), a world summary (`mean`) taking the unit of the metric column
/// before it, and the first cell of each row of a `| metric |` table (its rows are metrics).
pub(super) fn units_in_headers(md: &str) -> String {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = String::with_capacity(md.len() + 4096);
    let mut metric_rows = false;
    for (k, l) in lines.iter().enumerate() {
        let is_table = l.trim_start().starts_with('|');
        let header = is_table
            && lines
                .get(k + 1)
                .is_some_and(|n| n.trim_start().starts_with("|---"))
            && !lines
                .get(k.wrapping_sub(1))
                .is_some_and(|p| p.trim_start().starts_with('|'));
        if !is_table {
            metric_rows = false;
        }
        if header {
            let cells: Vec<&str> = l.trim().trim_matches('|').split(" | ").collect();
            metric_rows = cells.first().is_some_and(|c| c.trim() == "metric");
            let mut last: Option<String> = None;
            let new: Vec<String> = cells
                .iter()
                .map(|c| {
                    let c = c.trim();
                    let unit = cell_unit(c)
                        .or_else(|| SUMMARY_CELLS.contains(&c).then(|| last.clone()).flatten());
                    if cell_unit(c).is_some() {
                        last = unit.clone();
                    }
                    match unit {
                        Some(u) if !c.contains(" [") => format!("{c} {u}"),
                        _ => c.to_string(),
                    }
                })
                .collect();
            let _ = writeln!(out, "| {} |", new.join(" | "));
            continue;
        }
        if metric_rows && !l.trim_start().starts_with("|---") {
            let rest = l.trim_start().trim_start_matches('|');
            if let Some((first, tail)) = rest.split_once(" | ") {
                if let Some(u) = cell_unit(first.trim()) {
                    let _ = writeln!(out, "| {} {u} | {tail}", first.trim());
                    continue;
                }
            }
        }
        out.push_str(l);
        out.push('\n');
    }
    out
}

/// The `<h2>`/`<h3>` headings of `html` given an `id` where they have none (`s-1`, …), and a
/// table of contents (`<nav id="toc">`) of them inserted after the page's `<h1>`.
pub(super) fn with_toc(html: &str) -> String {
    let mut out = String::with_capacity(html.len() + 8192);
    let mut toc: Vec<(u8, String, String)> = Vec::new();
    let mut rest = html;
    let mut k = 0;
    while let Some(at) = rest.find("<h").filter(|_| !rest.is_empty()) {
        let level = rest.as_bytes().get(at + 2).copied().unwrap_or(0);
        if !(level == b'2' || level == b'3') {
            out.push_str(&rest[..at + 2]);
            rest = &rest[at + 2..];
            continue;
        }
        let Some(close) = rest[at..].find('>').map(|c| at + c) else {
            break;
        };
        let Some(end) = rest[close..].find("</h").map(|e| close + e) else {
            break;
        };
        let tag = &rest[at..close];
        // A heading right after `<section id="…">` is reached by the section's id.
        let before = rest[..at].trim_end();
        let section = before
            .rfind("<section id=\"")
            .filter(|&i| before.ends_with('>') && !before[i..].contains("</"))
            .and_then(|i| before[i + 13..].split('"').next())
            .map(String::from);
        let own = tag
            .find("id=\"")
            .map(|i| tag[i + 4..].split('"').next().unwrap_or("").to_string());
        let id = match (own.clone(), section.clone()) {
            (Some(i), _) | (None, Some(i)) => i,
            (None, None) => {
                k += 1;
                format!("s-{k}")
            }
        };
        let text = strip_tags(&rest[close + 1..end]);
        out.push_str(&rest[..at]);
        if own.is_some() || section.is_some() {
            out.push_str(tag);
        } else {
            let _ = write!(out, "<h{} id=\"{id}\"", level as char);
            out.push_str(&tag[3..]);
        }
        toc.push((level, id, text));
        rest = &rest[close..];
    }
    out.push_str(rest);
    let mut nav = String::from("<nav id=\"toc\" class=\"r-toc\"><strong>Contents:</strong> ");
    let items: Vec<String> = toc
        .iter()
        .filter(|(l, _, t)| *l == b'2' || t.len() < 60)
        .map(|(l, id, t)| {
            let short: String = t.chars().take(60).collect();
            format!(
                "<a class=\"r-tl{}\" href=\"#{}\">{}</a>",
                if *l == b'3' { " sub" } else { "" },
                escape(id),
                escape(&short)
            )
        })
        .collect();
    nav.push_str(&items.join(" · "));
    nav.push_str("</nav>\n");
    match out.find("</h1>") {
        Some(i) => {
            out.insert_str(i + 5, &format!("\n{nav}"));
            out
        }
        None => nav + &out,
    }
}

/// The text of an HTML fragment without its tags.
fn strip_tags(s: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for c in s.chars() {
        match c {
            '<' => inside = true,
            '>' => inside = false,
            c if !inside => out.push(c),
            _ => {}
        }
    }
    out.replace("&amp;", "&")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
}

/// `html` with each `<h3>` whose id starts with one of `ids` and everything up to the next
/// `<h2>`/`<h3>` (or the end of its section) folded into a closed `<details>` block, the
/// heading as its summary.
pub(super) fn fold(html: &str, ids: &[&str]) -> String {
    let mut out = html.to_string();
    for id in ids {
        let Some(at) = out.find(&format!("<h3 id=\"{id}")) else {
            continue;
        };
        let Some(head_end) = out[at..].find("</h3>").map(|e| at + e + 5) else {
            continue;
        };
        let after = &out[head_end..];
        let end = ["<h2", "<h3", "</section>"]
            .iter()
            .filter_map(|t| after.find(t))
            .min()
            .map_or(out.len(), |e| head_end + e);
        let head = out[at..head_end].to_string();
        let body = out[head_end..end].to_string();
        let block =
            format!("<details class=\"r-fold\"><summary>{head}</summary>{body}</details>\n");
        out.replace_range(at..end, &block);
    }
    out
}

/// What a figure of the page shows of the ranked and not-ranked designs, by its file name
/// (`ranked` false: the study ranks nothing over worlds).
pub(super) fn figure_scope(name: &str, ranked: bool) -> &'static str {
    if !ranked {
        return "successful cases in blue or grey, unsuccessful ones apart in red (this study \
                ranks no design over worlds)";
    }
    if name.starts_with("heatmap_") {
        "over the ranked designs only (not-ranked and unsuccessful designs left out and counted \
         in the title)"
    } else if name.starts_with("axis_") || name == "pareto.svg" {
        "ranked designs in blue, successful but not-ranked designs in grey, unsuccessful ones \
         in red; axes clipped to the ranked designs, points beyond drawn at the edge"
    } else if name.starts_with("rank_intervals") {
        "ranked designs only (the designs not ranked have no rank; see the ranking table)"
    } else if name.starts_with("tornado_") {
        "a question about the model, not a ranking: over every design that ran in the worlds, \
         ranked and not ranked alike (as its heading says)"
    } else if name.starts_with("tuning_curves") {
        "every tuned design: ranked designs in blue, not-ranked ones in grey"
    } else if name.starts_with("timeseries") {
        "the best and the worst case of the nominal world, each marked ranked or not ranked in \
         the legend"
    } else {
        "designs as in the figure's legend; ranked designs are those of the ranking table"
    }
}

/// Style added to the page: contents, folds, sortable headers, narrow screens and print.
pub(super) const PAGE_STYLE: &str = ".r-toc{display:block;font-size:13px;line-height:1.7;\
margin:6px 0 10px;padding:4px 8px;background:#f4f4f4;border:1px solid #ddd}\
.r-toc a{white-space:nowrap}.r-toc a.sub{font-size:12px;color:#335}\
details.r-fold{border:1px solid #ccc;padding:2px 8px;margin:10px 0}\
details.r-fold summary{cursor:pointer}details.r-fold summary h3{display:inline}\
th.r-sort{cursor:pointer}th.r-sort:after{content:' \\2195';color:#999;font-size:10px}\
input.r-filter{font-size:13px;margin:4px 0;padding:2px 4px;max-width:100%}\
.r-unranked{color:#92400e;font-size:11px}.r-ranked{color:#166534;font-size:11px}\
.r-firm{border-left:4px solid #1d4ed8;padding-left:8px}\
.r-design{border:1px solid #99a;padding:6px 10px;margin:12px 0;break-inside:avoid}\
.r-design .r-cols{display:grid;grid-template-columns:minmax(0,1fr) minmax(0,1fr);gap:12px}\
.r-design svg{max-width:100%;height:auto;display:block}\
body{overflow-wrap:break-word}img,svg{max-width:100%}pre{white-space:pre-wrap}\
@media (max-width:700px){body{margin:8px auto;padding:0 8px}.r-top{grid-template-columns:1fr}\
.r-grid{grid-template-columns:1fr}.r-design .r-cols{grid-template-columns:1fr}\
.r-verdict{padding:4px 8px}h1{font-size:20px}code{word-break:break-all}}\
@media print{.r-toc,input.r-filter,#designs,#study-plots-extra{display:none}\
details.r-fold{border:none}details.r-fold>*:not(summary){display:none}\
.r-plot{max-width:70%;margin:6px auto}.r-top svg{max-height:150px}\
.r-design svg{max-height:170px}h2{margin-top:14px}body{font-size:11px;line-height:1.25}\
.r-plot svg{max-height:330px}}";

/// The page's one script (inline, no network): every table with a header row gets sortable
/// headers (click: ascending, again: descending; numbers as numbers) and, with more than 8
/// rows, a filter box that hides rows not containing the text typed.
pub(super) const SCRIPT: &str = r#"<script>
(function(){
function num(t){var s=t.replace(/[^0-9eE+\-.]/g,'');var v=parseFloat(s);return s.length&&!isNaN(v)?v:null;}
document.querySelectorAll('table').forEach(function(tb){
var head=tb.tHead;var body=tb.tBodies[0];if(!head||!body)return;
var ths=head.rows[0].cells;
Array.prototype.forEach.call(ths,function(th,k){th.className+=' r-sort';th.title='click to sort';
th.addEventListener('click',function(){var rows=Array.prototype.slice.call(body.rows);
var asc=th.getAttribute('data-asc')!=='1';th.setAttribute('data-asc',asc?'1':'0');
rows.sort(function(a,b){var x=a.cells[k]?a.cells[k].textContent:'',y=b.cells[k]?b.cells[k].textContent:'';
var nx=num(x),ny=num(y);var c=(nx!==null&&ny!==null)?nx-ny:x.localeCompare(y);return asc?c:-c;});
rows.forEach(function(r){body.appendChild(r);});});});
if(body.rows.length>8){var f=document.createElement('input');f.type='search';f.className='r-filter';
f.placeholder='filter rows ('+body.rows.length+')';f.setAttribute('aria-label','filter rows');
f.addEventListener('input',function(){var q=f.value.toLowerCase();
Array.prototype.forEach.call(body.rows,function(r){r.style.display=r.textContent.toLowerCase().indexOf(q)<0?'none':'';});});
var w=tb.parentNode.className==='r-scroll'?tb.parentNode:tb;w.parentNode.insertBefore(f,w);}
});
})();
</script>
"#;

/// The SVG figures of `dir`: `plots/*.svg` then `*.svg`, each sorted by name.
pub(super) fn figure_files(dir: &Path) -> Vec<PathBuf> {
    let list = |d: &Path| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(d)
            .map(|rd| {
                rd.filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.extension().is_some_and(|x| x == "svg") && p.is_file())
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    };
    let mut out = list(&dir.join("plots"));
    out.extend(list(dir));
    out
}

/// The link to the column-width PDF beside the figure `svg` of the study directory `dir`
/// (` · PDF, column width`), or nothing when there is no such file.
pub(super) fn pdf_link(dir: &Path, svg: &Path) -> String {
    let pdf = svg.with_extension("pdf");
    let Ok(rel) = pdf.strip_prefix(dir) else {
        return String::new();
    };
    if !pdf.is_file() {
        return String::new();
    }
    let href: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    format!(
        " · <a class=\"r-pdf\" href=\"{}\">PDF, column width</a>",
        escape(&href.join("/"))
    )
}

/// Every figure, inline, its caption saying what it shows of the ranked and not-ranked designs
/// and linking its column-width PDF when there is one.
pub(super) fn plots_section(
    h: &mut String,
    dir: &Path,
    figures: &[PathBuf],
    ranked: bool,
    warnings: &mut Vec<String>,
) {
    // The Pareto plot is at the top of the page already.
    let figures: Vec<&PathBuf> = figures
        .iter()
        .filter(|p| p.file_name().is_none_or(|n| n != "pareto.svg"))
        .collect();
    h.push_str("<section id=\"plots\">\n<h2>Plots</h2>\n");
    if figures.is_empty() {
        h.push_str("<p class=\"r-note\">No plots in this directory.</p>\n");
    }
    for (k, p) in figures.iter().enumerate() {
        let name = p
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        match std::fs::read_to_string(p) {
            Ok(svg) => {
                let _ = writeln!(
                    h,
                    "<figure class=\"r-plot\" id=\"plot-{k}\">{}<figcaption>{} — {}{}</figcaption></figure>",
                    inline_svg(&svg, &format!("p{k}-")),
                    escape(&name),
                    figure_scope(&name, ranked),
                    pdf_link(dir, p)
                );
            }
            Err(e) => warnings.push(format!("{}: {e}", p.display())),
        }
    }
    h.push_str("</section>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_get_units_and_the_page_a_contents() {
        let md = "| case | mission_cost (nominal) | mean | p_best |\n|---|---|---|---|\n| #1 | 2 | 3 | 0.5 |\n\n\
                  | metric | 1. #3 |\n|---|---|\n| `mission_cost` | 41 |\n";
        let u = units_in_headers(md);
        assert!(
            u.contains("| case | mission_cost (nominal) [J/m] | mean [J/m] |"),
            "{u}"
        );
        assert!(u.contains("| `mission_cost` [J/m] | 41 |"), "{u}");
        let h = with_toc(
            "<h1>T</h1><h2>A</h2><p>x</p><h3 id=\"b\">B</h3><section id=\"v\">\n<h2>V</h2>",
        );
        assert!(
            h.contains("<nav id=\"toc\"")
                && h.contains("href=\"#s-1\"")
                && h.contains("href=\"#b\""),
            "{h}"
        );
        assert!(
            h.contains("<h2 id=\"s-1\">A</h2>") && h.contains("<h2>V</h2>"),
            "{h}"
        );
        assert!(h.contains("href=\"#v\""), "{h}");
        let f = fold(
            "<h3 id=\"best-x\">B</h3><table></table><h3 id=\"n\">N</h3>",
            &["best"],
        );
        assert!(
            f.starts_with("<details class=\"r-fold\"><summary><h3 id=\"best-x\">"),
            "{f}"
        );
        assert!(f.contains("</details>\n<h3 id=\"n\">"), "{f}");
    }
}

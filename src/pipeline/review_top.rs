//! The top of the review page (issue 25 item 1): the verdict box — the verdict line, the
//! leader's caveats and the top three designs side by side with their drawings — then the
//! Pareto plot, before anything else. The study description and every parameter come at the
//! end of the page.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::report::html::{escape, inline_svg, markdown_to_html, CaseLink};

/// A design drawing and the cases that share the design.
pub(super) struct Drawing {
    /// Case ids drawn by this design (first = its anchor).
    pub cases: Vec<i64>,
    /// The SVG document.
    pub svg: String,
}

/// Style of the box and the side-by-side drawings (added to the page's style sheet).
pub(super) const TOP_STYLE: &str = ".r-verdict{border:3px solid #1d4ed8;background:#f5f8ff;\
padding:4px 16px 10px;margin:10px 0 18px}.r-verdict h2{border:none;margin-top:10px}\
.r-top{display:grid;grid-template-columns:repeat(3,minmax(0,1fr));gap:12px}\
.r-top figure{margin:0;border:1px solid #99a;background:#fff;padding:4px}\
.r-top svg{width:100%;height:auto;display:block}.r-top figcaption{font-size:14px}";

/// The case ids of the box's side-by-side table, in rank order: the `#N` of each column
/// header of the table whose first header cell is `metric`.
pub(super) fn top_ids(block: &str) -> Vec<i64> {
    let Some(header) = block.lines().find(|l| l.starts_with("| metric |")) else {
        return Vec::new();
    };
    header
        .split('|')
        .skip(2)
        .filter_map(|cell| {
            let at = cell.find('#')?;
            let digits: String = cell[at + 1..]
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            digits.parse().ok()
        })
        .collect()
}

/// The verdict box: `block` (the verdict line and its box from `summary.md`) and the drawings
/// of its top designs side by side at a readable size.
pub(super) fn verdict_html(
    block: &str,
    drawings: &[Drawing],
    link: &dyn Fn(i64) -> Option<CaseLink>,
) -> String {
    let mut h = String::from("<section id=\"verdict\" class=\"r-verdict\">\n<h2>Verdict</h2>\n");
    h.push_str(&markdown_to_html(block, 1, link));
    let top = top_ids(block);
    let shown: Vec<(usize, i64, &Drawing)> = top
        .iter()
        .enumerate()
        .filter_map(|(rank, id)| Some((rank, *id, drawings.iter().find(|d| d.cases.contains(id))?)))
        .collect();
    if !shown.is_empty() {
        h.push_str("<div class=\"r-top\">\n");
        for (rank, id, d) in shown.iter() {
            let l = link(*id);
            let name = l.as_ref().and_then(|l| l.name.clone()).unwrap_or_default();
            let mark = l
                .and_then(|l| l.mark)
                .map_or(String::new(), |m| format!(" — {}", escape(&m.1)));
            let _ = writeln!(
                h,
                "<figure>{}<figcaption><strong>{}. #{id}</strong> {}{mark}</figcaption></figure>",
                inline_svg(&d.svg, &format!("v{id}-")),
                *rank + 1,
                escape(&name)
            );
        }
        h.push_str("</div>\n");
    }
    h.push_str("</section>\n");
    h
}

/// The Pareto figure among `figures` (a file named `pareto.svg`), inlined, for the top of the
/// page; `None` when the study has none.
pub(super) fn pareto_html(dir: &Path, figures: &[PathBuf]) -> Option<String> {
    let p = figures
        .iter()
        .find(|p| p.file_name().is_some_and(|n| n == "pareto.svg"))?;
    let svg = std::fs::read_to_string(p).ok()?;
    Some(format!(
        "<section id=\"pareto\">\n<h2>Trade-off</h2>\n<figure class=\"r-plot\">{}\
         <figcaption>pareto.svg — the Pareto front of the study's two trade-off metrics over \
         the cases successful in the nominal world: ranked designs in blue, not-ranked ones in \
         grey (labelled \"not ranked\" on the front), unsuccessful ones in red; axes clipped to \
         the ranked designs, points beyond drawn at the edge{}</figcaption></figure>\n</section>\n",
        inline_svg(&svg, "top-"),
        super::review_page::pdf_link(dir, p)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_side_by_side_ids_come_from_the_box_table_in_rank_order() {
        let block = "**Winner: #45 (ends, 4)** …\n\nTop 3 side by side:\n\n\
                     | metric | 1. #45 (ends, 4) | 2. #7 (paper, 5) | 3. #12 (ends, 5) |\n\
                     |---|---|---|---|\n| `reach` | 2.7 | 3.4 | 3.4 |\n";
        assert_eq!(top_ids(block), vec![45, 7, 12]);
        assert!(top_ids("no table").is_empty());
        let d = [Drawing {
            cases: vec![7, 8],
            svg: "<svg width=\"10\" height=\"10\"></svg>".into(),
        }];
        let h = verdict_html(block, &d, &|_| None);
        assert!(h.starts_with("<section id=\"verdict\""), "{h}");
        assert_eq!(
            h.matches("<figure>").count(),
            1,
            "only #7 has a drawing: {h}"
        );
        assert!(h.contains("<strong>2. #7</strong>"), "{h}");
    }
}

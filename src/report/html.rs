//! The pieces of a self-contained HTML page: escaping, Markdown (the subset `summary.md`
//! uses) to HTML with case references turned into links, and SVG documents made ready to be
//! inlined (no XML prolog, a `viewBox` so that they scale, ids made unique per document).
//!
//! Generic text processing; what the page holds is decided by the caller
//! (`crate::pipeline::review`).

use std::fmt::Write as _;

/// `s` escaped for HTML text and attribute values.
pub fn escape(s: &str) -> String {
    super::drawing::svg::escape(s)
}

/// How a case reference `#N` in a Markdown table row is shown: the anchor it links to, and
/// whether the case was unsuccessful (its row gets the class `bad`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CaseLink {
    /// Fragment the reference links to (without `#`), if the page has one for this case.
    pub anchor: Option<String>,
    /// The case failed, was skipped, or missed its success criteria.
    pub unsuccessful: bool,
    /// A short design name shown after the number (e.g. `paper / 5 / 0.06`).
    pub name: Option<String>,
    /// Whether the design is ranked, and the short text shown after the name (`ranked`, or
    /// why not: `not ranked: success 0.19 …`); `None`: the study ranks nothing.
    pub mark: Option<(bool, String)>,
}

/// Inline Markdown: `` `code` ``, `**bold**`, links, images `![alt](src)`, and (when `link` is given) case references `#N`
/// turned into links by `link`. Returns the HTML and whether an unsuccessful case was named.
fn inline(text: &str, link: Option<&dyn Fn(i64) -> Option<CaseLink>>) -> (String, bool) {
    let mut out = String::new();
    let mut bad = false;
    let text = text.replace("\\|", "|");
    let mut rest = text.as_str();
    let mut bold = false;
    while let Some(c) = rest.chars().next() {
        if c == '`' {
            if let Some(end) = rest[1..].find('`') {
                let _ = write!(out, "<code>{}</code>", escape(&rest[1..1 + end]));
                rest = &rest[end + 2..];
                continue;
            }
        }
        if let Some((label, url, len)) = rest.strip_prefix('!').and_then(md_link) {
            let _ = write!(
                out,
                "<img src=\"{}\" alt=\"{}\" style=\"max-width:100%\">",
                escape(url),
                escape(label)
            );
            rest = &rest[1 + len..];
            continue;
        }
        if let Some((label, url, len)) = md_link(rest) {
            let _ = write!(
                out,
                "<a href=\"{}\">{}</a>",
                escape(url),
                inline(label, None).0
            );
            rest = &rest[len..];
            continue;
        }
        if rest.starts_with("**") {
            out.push_str(if bold { "</strong>" } else { "<strong>" });
            bold = !bold;
            rest = &rest[2..];
            continue;
        }
        if let (Some(link), '#') = (link, c) {
            let digits: String = rest[1..].chars().take_while(char::is_ascii_digit).collect();
            if let Some(r) = digits.parse::<i64>().ok().and_then(link) {
                bad |= r.unsuccessful;
                let mut label = match &r.name {
                    Some(n) => format!("#{digits} <span class=\"r-name\">{}</span>", escape(n)),
                    None => format!("#{digits}"),
                };
                if let Some((ranked, text)) = &r.mark {
                    let class = if *ranked { "r-ranked" } else { "r-unranked" };
                    let _ = write!(label, " <span class=\"{class}\">{}</span>", escape(text));
                }
                match &r.anchor {
                    Some(a) => {
                        let _ = write!(out, "<a href=\"#{}\">{label}</a>", escape(a));
                    }
                    None => out.push_str(&label),
                }
                rest = &rest[1 + digits.len()..];
                continue;
            }
        }
        out.push_str(&escape(&c.to_string()));
        rest = &rest[c.len_utf8()..];
    }
    if bold {
        out.push_str("</strong>");
    }
    (out, bad)
}

/// A Markdown link `[label](url)` at the start of `text`: (label, url, its length in bytes).
fn md_link(text: &str) -> Option<(&str, &str, usize)> {
    let rest = text.strip_prefix('[')?;
    let close = rest.find("](")?;
    let label = &rest[..close];
    if label.contains('[') || label.contains('\n') {
        return None;
    }
    let after = &rest[close + 2..];
    let end = after.find(')')?;
    let url = &after[..end];
    (!url.is_empty() && !url.contains(char::is_whitespace)).then_some((
        label,
        url,
        1 + close + 2 + end + 1,
    ))
}

/// The anchor a heading gets (GitHub's rule, as Markdown viewers link `#…` to it): lower
/// case, spaces as `-`, only letters, digits, `-` and `_` kept.
pub fn heading_anchor(text: &str) -> String {
    text.trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The cells of a Markdown table row `| a | b |` (escaped pipes `\|` kept inside cells).
fn cells(line: &str) -> Vec<String> {
    let t = line.trim().trim_start_matches('|');
    let t = t.strip_suffix('|').unwrap_or(t);
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut prev = ' ';
    for c in t.chars() {
        if c == '|' && prev != '\\' {
            out.push(cur.trim().to_string());
            cur.clear();
        } else {
            cur.push(c);
        }
        prev = c;
    }
    out.push(cur.trim().to_string());
    out
}

/// A Markdown table (header, separator, rows) as an HTML table; rows naming an unsuccessful
/// case get the class `bad`.
fn table(lines: &[&str], link: &dyn Fn(i64) -> Option<CaseLink>, out: &mut String) {
    out.push_str("<div class=\"r-scroll\"><table>\n<thead><tr>");
    for h in cells(lines[0]) {
        let _ = write!(out, "<th>{}</th>", inline(&h, None).0);
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for l in lines.iter().skip(2) {
        let row: Vec<(String, bool)> = cells(l).iter().map(|c| inline(c, Some(link))).collect();
        let bad = row.iter().any(|c| c.1);
        out.push_str(if bad { "<tr class=\"bad\">" } else { "<tr>" });
        for (c, _) in row {
            let _ = write!(out, "<td>{c}</td>");
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody></table></div>\n");
}

/// The Markdown subset of the sweep summary as HTML: `#`…`####` headings (shifted down by
/// `shift` levels), tables, `- ` lists and paragraphs; case references `#N` in table rows
/// resolved by `link`.
pub fn markdown_to_html(md: &str, shift: usize, link: &dyn Fn(i64) -> Option<CaseLink>) -> String {
    let lines: Vec<&str> = md.lines().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i].trim_end();
        if l.trim().is_empty() || l.starts_with("<!--") {
            i += 1;
        } else if l.starts_with('#') {
            let level = l.chars().take_while(|c| *c == '#').count();
            let h = (level + shift).min(6);
            let raw = l[level..].trim();
            let text = inline(raw, None).0;
            let id = heading_anchor(&raw.replace('`', ""));
            let _ = writeln!(out, "<h{h} id=\"{}\">{text}</h{h}>", escape(&id));
            i += 1;
        } else if l.trim_start().starts_with('|') {
            let start = i;
            while i < lines.len() && lines[i].trim_start().starts_with('|') {
                i += 1;
            }
            if i - start >= 2 {
                table(&lines[start..i], link, &mut out);
            }
        } else if l.starts_with("- ") {
            out.push_str("<ul>\n");
            while i < lines.len() && lines[i].starts_with("- ") {
                let _ = writeln!(out, "<li>{}</li>", inline(&lines[i][2..], None).0);
                i += 1;
            }
            out.push_str("</ul>\n");
        } else {
            let mut para = Vec::new();
            while i < lines.len() {
                let t = lines[i].trim_end();
                if t.trim().is_empty() || t.starts_with('#') || t.trim_start().starts_with('|') {
                    break;
                }
                para.push(t.trim());
                i += 1;
            }
            let _ = writeln!(out, "<p>{}</p>", inline(&para.join(" "), None).0);
        }
    }
    out
}

/// The value of attribute `name` in the first tag of `svg` that has it.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

/// An SVG document ready to be inlined into HTML: the XML prolog removed, a `viewBox` added
/// (from `width`/`height`) when missing so that CSS can scale it, and every `id="…"` and
/// `href="#…"` prefixed with `prefix` so that several documents share a page without id
/// clashes.
pub fn inline_svg(svg: &str, prefix: &str) -> String {
    let body = match svg.find("<svg") {
        Some(k) => &svg[k..],
        None => svg,
    };
    let tag = &body[..body.find('>').unwrap_or(0)];
    let view_box = match (
        attr(tag, "viewBox"),
        attr(tag, "width"),
        attr(tag, "height"),
    ) {
        (None, Some(w), Some(h)) => Some(format!(
            " viewBox=\"0 0 {} {}\"",
            w.trim_end_matches("px"),
            h.trim_end_matches("px")
        )),
        _ => None,
    };
    // One pass, one output string: ` id="` and `href="#` gain the prefix.
    let mut s = String::with_capacity(body.len() + body.len() / 16 + 64);
    let mut rest = body;
    if let Some(vb) = &view_box {
        s.push_str(&rest[..4.min(rest.len())]);
        s.push_str(vb);
        rest = &rest[4.min(rest.len())..];
    }
    const ID: &str = " id=\"";
    const HREF: &str = "href=\"#";
    loop {
        let next = [ID, HREF]
            .iter()
            .filter_map(|pat| rest.find(pat).map(|k| (k, *pat)))
            .min_by_key(|(k, _)| *k);
        let Some((k, pat)) = next else {
            s.push_str(rest);
            break;
        };
        s.push_str(&rest[..k + pat.len()]);
        s.push_str(prefix);
        rest = &rest[k + pat.len()..];
    }
    s
}

#[cfg(test)]
mod tests {
    #[test]
    fn links_become_anchors_and_headings_get_their_ids() {
        let h = super::markdown_to_html(
            "## Cases left out\n\nsee [the cases left out](#cases-left-out), `a|b`.\n",
            0,
            &|_| None,
        );
        assert!(h.contains("<h2 id=\"cases-left-out\">"), "{h}");
        assert!(
            h.contains("<a href=\"#cases-left-out\">the cases left out</a>"),
            "{h}"
        );
        // An image is drawn, not shown as "!" and a link.
        let h = super::markdown_to_html("![rank intervals](plots/r.svg)\n", 0, &|_| None);
        assert!(
            h.contains("<img src=\"plots/r.svg\" alt=\"rank intervals\"") && !h.contains('!'),
            "{h}"
        );
        // Not a link: brackets without a target stay text.
        let h = super::markdown_to_html("a [b] (c)\n", 0, &|_| None);
        assert!(h.contains("a [b] (c)"), "{h}");
    }

    use super::*;

    fn link(id: i64) -> Option<CaseLink> {
        (id < 10).then(|| CaseLink {
            anchor: Some(format!("case-{id}")),
            unsuccessful: id == 3,
            name: Some("paper / 5".into()),
            mark: None,
        })
    }

    #[test]
    fn summary_markdown_becomes_headings_tables_and_links() {
        let md = "# Sweep `t`\n\nMode **ok**, a < b.\n\n## Best\n\n| metric | case |\n|---|---|\n\
                  | `e` | #2 |\n| `f` | #3 |\n| `g` | #42 |\n\n- one\n- two\n";
        let h = markdown_to_html(md, 1, &link);
        assert!(
            h.contains("<h2 id=\"sweep-t\">Sweep <code>t</code></h2>"),
            "{h}"
        );
        assert!(
            h.contains("<p>Mode <strong>ok</strong>, a &lt; b.</p>"),
            "{h}"
        );
        assert!(h.contains("<h3 id=\"best\">Best</h3>"));
        assert!(h.contains(
            "<tr><td><code>e</code></td><td><a href=\"#case-2\">#2 <span class=\"r-name\">paper / 5</span></a></td></tr>"
        ), "{h}");
        assert!(h.contains("<tr class=\"bad\"><td><code>f</code>"), "{h}");
        // An id the page knows nothing of stays plain text.
        assert!(h.contains("<td>#42</td>"), "{h}");
        assert!(h.contains("<ul>\n<li>one</li>\n<li>two</li>\n</ul>"));
    }

    #[test]
    fn escaped_pipes_stay_inside_their_cell() {
        assert_eq!(cells("| a \\| b | c |"), ["a \\| b", "c"]);
        assert_eq!(inline("a \\| b", None).0, "a | b");
    }

    #[test]
    fn inlined_svg_scales_and_has_unique_ids() {
        let svg = "<?xml version=\"1.0\"?>\n<svg width=\"800\" height=\"600\" xmlns=\"x\">\
                   <g id=\"view-top\"/><use href=\"#view-top\"/></svg>";
        let s = inline_svg(svg, "d1-");
        assert!(
            s.starts_with("<svg viewBox=\"0 0 800 600\" width=\"800\""),
            "{s}"
        );
        assert!(s.contains("id=\"d1-view-top\"") && s.contains("href=\"#d1-view-top\""));
        let with_box = "<svg width=\"8\" height=\"6\" viewBox=\"0 0 8 6\"></svg>";
        assert_eq!(inline_svg(with_box, "p-"), with_box);
    }
}

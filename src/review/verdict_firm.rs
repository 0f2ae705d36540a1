//! "How firm" (issue 42 item 1): the paragraph the verdict box opens with, saying what the
//! verdict stands on — the protocol (worlds, pairing, the ranking and winner rules), the seeds
//! (the study's and the tuning's) — and what moved the answer when it was changed, quoted from
//! the `## How firm` section of `FINDINGS.md` when the output directory has one (with a link to
//! it). Read from the output directory only, so `usm-study report` rebuilds it.

use std::path::Path;

use crate::batch::robust::{RobustInfo, StudyVerdict};
use crate::report::fmt_short;

/// The findings file a study's author may put beside its output.
pub const FINDINGS_MD: &str = "FINDINGS.md";

/// The heading of the section of [`FINDINGS_MD`] the box quotes.
pub const FIRM_HEADING: &str = "## How firm";

/// The first paragraph under [`FIRM_HEADING`] in a findings text, joined to one line.
pub fn findings_firm(text: &str) -> Option<String> {
    let start = text.lines().position(|l| l.trim_end() == FIRM_HEADING)?;
    let para: Vec<&str> = text
        .lines()
        .skip(start + 1)
        .skip_while(|l| l.trim().is_empty())
        .take_while(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(str::trim)
        .collect();
    (!para.is_empty()).then(|| para.join(" "))
}

/// The `[tune]` settings of the study copy in `dir` that say how firm the tuning is: the
/// independent tuning seeds and the worlds each candidate meets (`None` without `[tune]`).
fn tuning(dir: &Path) -> Option<(i64, i64)> {
    let text = std::fs::read_to_string(dir.join(crate::batch::records::STUDY_COPY)).ok()?;
    let doc: toml::Table = toml::from_str(&text).ok()?;
    let t = doc.get("tune")?.as_table()?;
    let get = |k: &str| t.get(k).and_then(toml::Value::as_integer);
    Some((get("seeds").unwrap_or(1), get("worlds").unwrap_or(0)))
}

/// The "how firm" paragraph of a study's verdict box (Markdown, ends with a blank line).
pub fn how_firm(dir: &Path, seed: u64, info: &RobustInfo, v: &StudyVerdict) -> String {
    let worlds = match &info.adaptive {
        Some(a) => format!(
            "{} {} worlds met by every design, up to {} for the designs still in contention \
             (adaptive, {} per round, {} rounds)",
            info.worlds, info.sampling, a.worlds_used, a.batch, a.rounds
        ),
        None => format!("{} {} worlds", info.worlds, info.sampling),
    };
    let noise = if v.noise_measured {
        format!("median tuning noise {:.2} %", 100.0 * v.noise)
    } else {
        "tuning noise not measured".into()
    };
    let tune = match tuning(dir) {
        Some((seeds, w)) => format!(
            "; tuning: {seeds} independent tuning seed(s) per design, each candidate in {w} \
             tuning worlds apart from the scoring worlds ({noise})"
        ),
        None => format!(" ({noise})"),
    };
    let mut md = format!(
        "**How firm.** Protocol: {worlds}, paired (common random numbers); a design is ranked \
         when the {:.0} % lower confidence bound of its success probability reaches {}; a \
         winner only beyond max(equivalence {:.0} %, tuning noise). Seeds: study seed {seed}{tune}.",
        100.0 * info.confidence,
        fmt_short(info.min_success_probability),
        100.0 * info.equivalence,
    );
    let findings = std::fs::read_to_string(dir.join(FINDINGS_MD)).ok();
    match findings.as_deref() {
        Some(text) => {
            if let Some(p) = findings_firm(text) {
                md.push_str(&format!(" What moved the answer: {p}"));
            }
            md.push_str(&format!(
                " The argument, with what was tried: [{FINDINGS_MD}]({FINDINGS_MD})."
            ));
        }
        None => md.push_str(
            " What moves the answer is not recorded here (no FINDINGS.md in this directory): \
             rerun with another `--seed` or tuning budget to test it.",
        ),
    }
    md.push_str("\n\n");
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_firm_paragraph_is_the_first_under_its_heading() {
        let t = "# F\n\n## How firm\n\nSeed 7 ties\nmore designs.\n\nLater.\n## Next\n";
        assert_eq!(
            findings_firm(t).as_deref(),
            Some("Seed 7 ties more designs.")
        );
        assert!(findings_firm("# F\n").is_none());
    }
}

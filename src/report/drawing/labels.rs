//! Label placement without overlaps: each label tries positions around its anchor, nearest
//! first, in its preferred direction first, and takes the first whose box is free; a label
//! pushed away from its anchor gets a thin leader line. Greedy and deterministic.

use super::svg::Svg;

/// Font size of labels [px]; the class `label` in the style sheet.
const FONT: f64 = 12.0;
/// Estimated advance of one character [px] (DejaVu Sans averages about 0.6 em).
const CHAR_W: f64 = 0.62 * FONT;

/// The labels placed so far (their boxes, SVG px `[x, y, w, h]`) on a page `width` px wide.
#[derive(Debug)]
pub struct Labeller {
    placed: Vec<[f64; 4]>,
    width: f64,
}

fn overlaps(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
}

impl Labeller {
    /// No labels yet, on a page `width` px wide (labels stay inside it).
    pub fn new(width: f64) -> Self {
        Labeller {
            placed: Vec::new(),
            width,
        }
    }

    /// Reserves a box (e.g. a marker) that later labels must avoid.
    pub fn reserve(&mut self, b: [f64; 4]) {
        self.placed.push(b);
    }

    /// Writes `text` near `anchor` (SVG px), preferably in the direction `pref` (any length;
    /// zero means up-right), with `class` and `id` on the `<text>`.
    pub fn place(&mut self, s: &mut Svg, text: &str, anchor: [f64; 2], pref: [f64; 2], id: &str) {
        let w = CHAR_W * text.chars().count() as f64 + 2.0;
        let h = FONT + 2.0;
        let n = pref[0].hypot(pref[1]);
        let base = if n > 1e-9 {
            pref[1].atan2(pref[0])
        } else {
            -std::f64::consts::FRAC_PI_4
        };
        let mut first = None;
        let mut chosen = None;
        'search: for r in [5.0, 14.0, 26.0, 40.0, 56.0] {
            for turn in [0.0, 1.0, -1.0, 2.0, -2.0, 3.0, -3.0, 4.0] {
                let a = base + turn * std::f64::consts::FRAC_PI_4;
                let d = [a.cos(), a.sin()];
                let reach = r + d[0].abs() * w / 2.0 + d[1].abs() * h / 2.0;
                let c = [anchor[0] + d[0] * reach, anchor[1] + d[1] * reach];
                let b = [c[0] - w / 2.0, c[1] - h / 2.0, w, h];
                let inside = b[0] >= 0.0 && b[1] >= 0.0 && b[0] + w <= self.width;
                if !inside {
                    continue;
                }
                first.get_or_insert((c, b, r));
                if !self.placed.iter().any(|p| overlaps(p, &b)) {
                    chosen = Some((c, b, r));
                    break 'search;
                }
            }
        }
        let Some((c, b, r)) = chosen.or(first) else {
            return;
        };
        if r > 14.0 {
            let edge = [
                anchor[0].clamp(b[0], b[0] + b[2]),
                anchor[1].clamp(b[1], b[1] + b[3]),
            ];
            s.empty(
                "line",
                &[
                    ("class", "leader".into()),
                    ("x1", anchor[0].into()),
                    ("y1", anchor[1].into()),
                    ("x2", edge[0].into()),
                    ("y2", edge[1].into()),
                ],
            );
        }
        s.text(
            &[
                ("class", "label".into()),
                ("id", id.into()),
                ("x", c[0].into()),
                ("y", (c[1] + 0.35 * FONT).into()),
                ("text-anchor", "middle".into()),
            ],
            text,
        );
        self.placed.push(b);
    }
}

#[cfg(test)]
mod tests {
    use crate::report::drawing::labels::*;

    #[test]
    fn labels_at_one_anchor_do_not_overlap() {
        let mut l = Labeller::new(100.0);
        let mut s = Svg::new(100.0, 100.0, "");
        for k in 0..6 {
            l.place(&mut s, "T10", [50.0, 50.0], [1.0, 0.0], &format!("l{k}"));
        }
        for (i, a) in l.placed.iter().enumerate() {
            for b in &l.placed[i + 1..] {
                assert!(!overlaps(a, b), "{a:?} {b:?}");
            }
        }
    }
}

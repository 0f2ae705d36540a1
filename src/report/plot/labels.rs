//! Point labels that never overlap: each label tries boxes around its point in pixel space,
//! nearest first, in eight directions, and takes the first that overlaps no marker, no
//! earlier label and stays inside the plotting area. A label pushed away from its point gets
//! a leader line. Greedy and deterministic (labels are placed in input order).

/// Font size of point labels as given to plotters, which writes it into the SVG divided by
/// 1.24 (14 → 11.3 px).
pub(super) const LABEL_FONT: u32 = 14;
/// The rendered font size [px].
const RENDERED: f64 = LABEL_FONT as f64 / 1.24;
/// Estimated advance of one character [px] (about 0.6 em for a sans-serif font).
const CHAR_W: f64 = 0.6 * RENDERED;
/// Half the size of the box reserved around each marker [px].
const MARKER: i32 = 4;
/// Distances from the point to the nearest box edge that are tried [px].
const RINGS: [f64; 6] = [4.0, 12.0, 22.0, 34.0, 48.0, 64.0];
/// A label farther than this from its point [px] gets a leader line.
const LEADER_FROM: i32 = 9;

/// A box `[x, y, w, h]` in pixels.
type PxBox = [i32; 4];

fn overlaps(a: &PxBox, b: &PxBox) -> bool {
    a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
}

/// Where a label goes: its box's top-left offset from the point, and the leader line's end
/// (offset from the point) when the label is away from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Placement {
    /// Offset of the text's top-left corner from the point [px].
    pub offset: (i32, i32),
    /// End of a leader line from the point, if one is drawn [px].
    pub leader: Option<(i32, i32)>,
}

/// The size of the box of `text` [px] in a font `k` times the point labels' size.
fn text_box(text: &str, k: f64) -> (i32, i32) {
    (
        (CHAR_W * k * text.chars().count() as f64).ceil() as i32 + 2,
        (RENDERED * k).ceil() as i32 + 3,
    )
}

/// Places `texts` at `points` (pixels) inside `area` `[x0, y0, x1, y1]`, avoiding the
/// `markers` (pixel centres of every drawn point) and each other; `k` multiplies the font
/// size and the distances (1 on screen).
pub(super) fn place_labels(
    points: &[(i32, i32)],
    texts: &[&str],
    markers: &[(i32, i32)],
    area: [i32; 4],
    k: f64,
) -> Vec<Placement> {
    let marker = (f64::from(MARKER) * k).round() as i32;
    let leader_from = (f64::from(LEADER_FROM) * k).round() as i32;
    let mut taken: Vec<PxBox> = markers
        .iter()
        .map(|m| [m.0 - marker, m.1 - marker, 2 * marker, 2 * marker])
        .collect();
    let mut out = Vec::with_capacity(points.len());
    for (p, t) in points.iter().zip(texts) {
        let (w, h) = text_box(t, k);
        let mut first = None;
        let mut chosen = None;
        'search: for r in RINGS.map(|r| r * k) {
            // Up-right first (the usual label position), then around the point.
            for k in [7.0, 0.0, 1.0, 6.0, 2.0, 5.0, 3.0, 4.0] {
                let a = k * std::f64::consts::FRAC_PI_4;
                let d = (a.cos(), a.sin());
                let reach_x = r + (w as f64 / 2.0) * d.0.abs();
                let reach_y = r + (h as f64 / 2.0) * d.1.abs();
                let cx = p.0 as f64 + d.0 * reach_x;
                let cy = p.1 as f64 + d.1 * reach_y;
                let b = [
                    (cx - w as f64 / 2.0).round() as i32,
                    (cy - h as f64 / 2.0).round() as i32,
                    w,
                    h,
                ];
                let inside = b[0] >= area[0]
                    && b[1] >= area[1]
                    && b[0] + w <= area[2]
                    && b[1] + h <= area[3];
                if !inside {
                    continue;
                }
                first.get_or_insert(b);
                if !taken.iter().any(|o| overlaps(o, &b)) {
                    chosen = Some(b);
                    break 'search;
                }
            }
        }
        let b = chosen.or(first).unwrap_or([p.0 + 5, p.1 - h - 2, w, h]);
        taken.push(b);
        // The point of the box nearest the labelled point.
        let near = (
            p.0.clamp(b[0], b[0] + w) - p.0,
            p.1.clamp(b[1], b[1] + h) - p.1,
        );
        let far = near.0.abs().max(near.1.abs()) > leader_from;
        out.push(Placement {
            offset: (b[0] - p.0, b[1] - p.1),
            leader: far.then_some(near),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crowded_labels_do_not_overlap_and_far_ones_get_leaders() {
        // Six points a few pixels apart (the #9-over-#11 case of a Pareto front).
        let pts: Vec<(i32, i32)> = (0..6).map(|k| (200 + 3 * k, 150 + 2 * k)).collect();
        let texts = [
            "#9 paper/5/0.06",
            "#11 paper/5/0.14",
            "#34 ends/3/0.1",
            "#35 a",
            "#1",
            "#2",
        ];
        let placed = place_labels(&pts, &texts, &pts, [0, 0, 600, 400], 1.0);
        let boxes: Vec<PxBox> = placed
            .iter()
            .zip(&pts)
            .zip(&texts)
            .map(|((pl, p), t)| {
                let (w, h) = text_box(t, 1.0);
                [p.0 + pl.offset.0, p.1 + pl.offset.1, w, h]
            })
            .collect();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                assert!(!overlaps(&boxes[i], &boxes[j]), "{i} and {j}: {boxes:?}");
            }
        }
        assert!(placed.iter().any(|p| p.leader.is_some()));
        assert_eq!(
            placed,
            place_labels(&pts, &texts, &pts, [0, 0, 600, 400], 1.0)
        );
    }

    #[test]
    fn labels_stay_inside_the_area() {
        let placed = place_labels(&[(598, 2)], &["far corner"], &[], [0, 0, 600, 400], 1.0);
        let (w, h) = text_box("far corner", 1.0);
        let b = [598 + placed[0].offset.0, 2 + placed[0].offset.1, w, h];
        assert!(
            b[0] >= 0 && b[1] >= 0 && b[0] + w <= 600 && b[1] + h <= 400,
            "{b:?}"
        );
    }
}

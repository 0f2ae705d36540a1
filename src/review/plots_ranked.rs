//! Ranked against not-ranked designs in the sweep's plots (issue 42 item 4): the rows a study
//! with uncertain worlds ranks ([`ranked_mask`]: its `p_best` is a number), the split of a
//! scatter series into ranked and not-ranked designs, and the clipping of a panel's axes to
//! the region of the ranked designs with every point beyond it drawn at the edge in a series of
//! its own ([`clip_to_ranked`]), so that one outlier does not squash the region that matters.

use crate::batch::records::STATUS;
use crate::report::{Colour, ColumnData, Panel, PanelKind, Series, Table};

/// The legend name of the ranked designs.
pub const RANKED: &str = "ranked designs";
/// The legend name of the successful designs that are not ranked.
pub const NOT_RANKED: &str = "successful in the nominal world, not ranked";

/// Which rows are ranked (their `p_best` is a number); `None` for a study without ranking
/// over worlds (no `p_best` column).
pub fn ranked_mask(t: &Table) -> Option<Vec<bool>> {
    let p = t.f64("p_best").ok()?;
    Some(p.iter().map(|x| x.is_finite()).collect())
}

/// The ranked (blue) and not-ranked (grey) series of the rows `rows` at `xs`/`ys` (row
/// indices); series without points are left out.
pub fn split_series(rows: &[usize], xs: &[f64], ys: &[f64], ranked: &[bool]) -> Vec<Series> {
    let part = |want: bool| -> Vec<usize> {
        rows.iter()
            .copied()
            .filter(|&r| ranked.get(r).copied().unwrap_or(false) == want)
            .collect()
    };
    let mut out = Vec::new();
    for (want, name, colour) in [
        (true, RANKED, Colour::Palette(0)),
        (false, NOT_RANKED, Colour::Grey),
    ] {
        let r = part(want);
        if !r.is_empty() {
            out.push(
                Series::new(
                    name,
                    r.iter().map(|&i| xs[i]).collect(),
                    r.iter().map(|&i| ys[i]).collect(),
                )
                .colour(colour)
                .kind(PanelKind::Scatter),
            );
        }
    }
    out
}

/// The range of the finite `v` padded by 8 % of its span (or of its magnitude when flat);
/// `None` without a finite value.
fn padded(v: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = v
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if !lo.is_finite() {
        return None;
    }
    let pad = if hi > lo {
        0.08 * (hi - lo)
    } else {
        0.05 * lo.abs().max(1e-9)
    };
    Some((lo - pad, hi + pad))
}

/// Clips the panel's axes to the region of the ranked designs (`xs`, `ys` of the ranked rows;
/// `clip_x` false keeps the x axis) and draws every point of every series beyond it at the edge,
/// repeated in a series "beyond the axis, drawn at the edge (n)"; returns how many points were
/// moved. Nothing changes when the ranked designs are fewer than two or every point lies inside.
pub fn clip_to_ranked(p: &mut Panel, xs: &[f64], ys: &[f64], clip_x: bool) -> usize {
    if xs.iter().filter(|x| x.is_finite()).count() < 2 {
        return 0;
    }
    let xr = if clip_x {
        padded(xs.iter().copied())
    } else {
        None
    };
    let yr = padded(ys.iter().copied());
    let clamp = |v: f64, r: Option<(f64, f64)>| match r {
        Some((lo, hi)) if v.is_finite() => v.clamp(lo, hi),
        _ => v,
    };
    let (mut ox, mut oy) = (Vec::new(), Vec::new());
    for s in &mut p.series {
        for k in 0..s.x.len().min(s.y.len()) {
            let (x, y) = (clamp(s.x[k], xr), clamp(s.y[k], yr));
            if x != s.x[k] || y != s.y[k] {
                s.x[k] = x;
                s.y[k] = y;
                if s.kind != Some(PanelKind::Line) {
                    ox.push(x);
                    oy.push(y);
                }
            }
        }
    }
    let n = ox.len();
    if n == 0 {
        return 0;
    }
    p.x_range = xr.or(p.x_range);
    p.y_range = yr.or(p.y_range);
    p.series.push(
        Series::new(format!("beyond the axis, drawn at the edge ({n})"), ox, oy)
            .colour(Colour::Palette(1))
            .kind(PanelKind::Scatter),
    );
    n
}

/// Whether each row is unsuccessful: its `status` is not `ok`, or its `success` column (when
/// the table has one: bool, 0/1 or `true`/`yes`) says no.
pub fn unsuccessful_rows(table: &Table) -> Vec<bool> {
    let status = table.str(STATUS).ok();
    let success = table.column("success").map(|c| &c.data);
    (0..table.n_rows())
        .map(|r| {
            let failed = status.is_some_and(|s| s[r] != "ok");
            let missed = success.is_some_and(|d| match d {
                ColumnData::Bool(v) => !v[r],
                ColumnData::F64(v) => !(v[r] != 0.0 && v[r].is_finite()),
                ColumnData::I64(v) => v[r] == 0,
                ColumnData::Str(v) => !matches!(
                    v[r].trim().to_ascii_lowercase().as_str(),
                    "true" | "1" | "yes" | "ok"
                ),
            });
            failed || missed
        })
        .collect()
}

/// The unsuccessful rows with finite `xs` and `ys`, as a red series (`None` when there are
/// none).
pub(crate) fn unsuccessful_series(bad: &[bool], xs: &[f64], ys: &[f64]) -> Option<Series> {
    let rows: Vec<usize> = (0..bad.len())
        .filter(|&r| bad[r] && xs[r].is_finite() && ys[r].is_finite())
        .collect();
    (!rows.is_empty()).then(|| {
        Series::new(
            "unsuccessful cases",
            rows.iter().map(|&r| xs[r]).collect(),
            rows.iter().map(|&r| ys[r]).collect(),
        )
        .colour(Colour::Alert)
        .kind(PanelKind::Scatter)
    })
}

/// Writes the SVG `svg` of a figure as `dir/name`; a failure becomes a warning of the page.
pub(super) fn write_plot(dir: &std::path::Path, name: &str, svg: &str, warnings: &mut Vec<String>) {
    if let Err(e) = crate::report::atomic_write(&dir.join(name), svg.as_bytes()) {
        warnings.push(format!("{name}: {e}"));
    }
}

/// Writes the column-width PDF of figure `svg_name` beside it (`NAME.pdf`), as [`write_plot`].
pub(super) fn write_pdf(
    dir: &std::path::Path,
    svg_name: &str,
    pdf: crate::report::Result<Vec<u8>>,
    warnings: &mut Vec<String>,
) {
    let path = dir.join(svg_name).with_extension("pdf");
    if let Err(e) = pdf.and_then(|pdf| crate::report::atomic_write(&path, &pdf)) {
        warnings.push(format!("{svg_name} (PDF): {e}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outliers_are_drawn_at_the_edge_of_the_ranked_region() {
        let mut p = Panel::new("", "x", "y")
            .kind(PanelKind::Scatter)
            .with_series(Series::new(
                "all",
                vec![1.0, 2.0, 500.0],
                vec![1.0, 2.0, 3.0],
            ));
        let n = clip_to_ranked(&mut p, &[1.0, 2.0], &[1.0, 2.0], true);
        assert_eq!(n, 1);
        let (lo, hi) = p.x_range.unwrap();
        assert!(
            lo < 1.0 && hi < 3.0 && p.series[0].x[2] == hi,
            "{:?}",
            p.x_range
        );
        assert!(p.series.last().unwrap().name.contains("(1)"));
        let s = split_series(
            &[0, 1, 2],
            &[1.0, 2.0, 3.0],
            &[1.0, 2.0, 3.0],
            &[true, false, true],
        );
        assert_eq!(
            (s[0].name.as_str(), s[0].x.len(), s[1].x.len()),
            (RANKED, 2, 1)
        );
    }
}

//! Standardised (rank) regression coefficients: the cheap sensitivity measure for small
//! budgets (Iman & Conover 1979; Saltelli et al. 2008, §1.2.5).

use faer::Mat;

/// Regression-based sensitivity of one output to `d` inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Srrc {
    /// One standardised coefficient per input (0 for an input that does not vary).
    pub coef: Vec<f64>,
    /// Coefficient of determination of the (rank) regression: the share of the output's
    /// (rank) variance the linear model explains.
    pub r2: f64,
}

impl Srrc {
    fn nan(d: usize) -> Srrc {
        Srrc {
            coef: vec![f64::NAN; d],
            r2: f64::NAN,
        }
    }
}

/// Ranks 1..=n of `xs` (ascending), ties given the average of the ranks they span. Ordering by
/// `f64::total_cmp`, so NaN values rank last (callers leave them out first).
pub fn average_ranks(xs: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..xs.len()).collect();
    order.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    let mut ranks = vec![0.0; xs.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && xs[order[end]] == xs[order[start]] {
            end += 1;
        }
        // Positions start..end hold ranks start+1 ..= end; their mean:
        let rank = 0.5 * (start + 1 + end) as f64;
        for &k in &order[start..end] {
            ranks[k] = rank;
        }
        start = end;
    }
    ranks
}

/// Standardised rank regression coefficients (SRRC) of `y` on the columns of `x` (`x[k]` is
/// sample k's `d` inputs): every column and `y` are replaced by their average ranks
/// ([`average_ranks`]), standardised to mean 0 and sample standard deviation 1, and `y` is
/// regressed on the columns by least squares. A coefficient near ±1 marks a monotone driver,
/// near 0 none; `r2` says how much of the output's rank variance is monotone in the inputs.
///
/// Rows with a non-finite `y` or input are left out. A column that is constant over the kept
/// rows gets coefficient 0. Collinear columns share their effect (minimum-norm solution through
/// the SVD). When `y` is constant the coefficients are 0 and `r2` NaN; with fewer than two rows,
/// or when the rows of `x` and `y` do not line up (lengths), everything is NaN.
pub fn srrc(x: &[Vec<f64>], y: &[f64]) -> Srrc {
    regress(x, y, true)
}

/// Standardised regression coefficients (SRC): as [`srrc()`] on the raw values instead of their
/// ranks; they measure linear rather than monotone influence.
pub fn src(x: &[Vec<f64>], y: &[f64]) -> Srrc {
    regress(x, y, false)
}

/// The values standardised to mean 0 and sample standard deviation 1, or `None` when they are
/// all equal (or the spread is not finite).
fn standardise(mut v: Vec<f64>) -> Option<Vec<f64>> {
    if v.iter().all(|&x| x == v[0]) {
        return None;
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0)).sqrt();
    if !(sd.is_finite() && sd > 0.0) {
        return None;
    }
    for x in &mut v {
        *x = (*x - mean) / sd;
    }
    Some(v)
}

fn regress(x: &[Vec<f64>], y: &[f64], ranks: bool) -> Srrc {
    let d = x.first().map_or(0, Vec::len);
    if x.len() != y.len() || x.iter().any(|row| row.len() != d) {
        return Srrc::nan(d);
    }
    let rows: Vec<usize> = (0..y.len())
        .filter(|&k| y[k].is_finite() && x[k].iter().all(|v| v.is_finite()))
        .collect();
    let m = rows.len();
    if m < 2 {
        return Srrc::nan(d);
    }
    let prepare = |v: Vec<f64>| standardise(if ranks { average_ranks(&v) } else { v });
    let Some(ys) = prepare(rows.iter().map(|&k| y[k]).collect()) else {
        return Srrc {
            coef: vec![0.0; d],
            r2: f64::NAN,
        };
    };
    let cols: Vec<(usize, Vec<f64>)> = (0..d)
        .filter_map(|i| prepare(rows.iter().map(|&k| x[k][i]).collect()).map(|c| (i, c)))
        .collect();
    let mut coef = vec![0.0; d];
    if cols.is_empty() {
        return Srrc { coef, r2: 0.0 };
    }
    let p = cols.len();
    let a = Mat::<f64>::from_fn(m, p, |r, c| cols[c].1[r]);
    let Ok(svd) = a.thin_svd() else {
        return Srrc::nan(d);
    };
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let s_max = (0..s.nrows()).map(|k| s[k]).fold(0.0, f64::max);
    let tol = s_max * m.max(p) as f64 * f64::EPSILON;
    let mut beta = vec![0.0; p];
    for k in 0..s.nrows() {
        if s[k] > tol {
            let uty: f64 = (0..m).map(|r| u[(r, k)] * ys[r]).sum();
            for (c, b) in beta.iter_mut().enumerate() {
                *b += uty / s[k] * v[(c, k)];
            }
        }
    }
    let ss_res: f64 = (0..m)
        .map(|r| {
            let fit: f64 = (0..p).map(|c| cols[c].1[r] * beta[c]).sum();
            (ys[r] - fit) * (ys[r] - fit)
        })
        .sum();
    let ss_tot: f64 = ys.iter().map(|v| v * v).sum();
    for ((i, _), b) in cols.iter().zip(&beta) {
        coef[*i] = *b;
    }
    Srrc {
        coef,
        r2: 1.0 - ss_res / ss_tot,
    }
}

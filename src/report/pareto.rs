//! The Pareto front of a set of 2-D points.

/// Indices of the non-dominated points of `points` when **both** coordinates are minimised
/// (the Pareto front).
///
/// A point `a` dominates `b` when `a.0 <= b.0`, `a.1 <= b.1` and at least one inequality is
/// strict. Points with a NaN coordinate are excluded (never on the front, never dominating).
/// Exact duplicates do not dominate each other; of a group of identical points only the one with
/// the smallest index is kept, so the result is deterministic. The returned indices are ordered
/// by increasing first coordinate (ties by index), i.e. along the front from left to right.
///
/// Cost: O(n log n).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .collect();
    // Sort by x, then y, then index: a point can only be dominated by one earlier in this order.
    // `+ 0.0` maps -0.0 to 0.0 so that the two zeros compare equal under `total_cmp`.
    let at = |i: usize| (points[i].0 + 0.0, points[i].1 + 0.0);
    order.sort_by(|&a, &b| {
        let (pa, pb) = (at(a), at(b));
        pa.0.total_cmp(&pb.0)
            .then(pa.1.total_cmp(&pb.1))
            .then(a.cmp(&b))
    });
    let mut front = Vec::new();
    let mut best_y = f64::INFINITY;
    let mut last: Option<(f64, f64)> = None;
    for i in order {
        let p = at(i);
        if let Some(l) = last {
            if l.0 == p.0 && l.1 == p.1 {
                continue; // duplicate of a kept point
            }
        }
        if p.1 < best_y || (front.is_empty() && p.1 == f64::INFINITY) {
            best_y = p.1;
            front.push(i);
            last = Some(p);
        }
    }
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pareto_hand_case() {
        let pts = [
            (1.0, 5.0),      // 0 front
            (2.0, 3.0),      // 1 front
            (3.0, 3.0),      // 2 dominated by 1
            (2.5, 4.0),      // 3 dominated by 1
            (4.0, 1.0),      // 4 front
            (f64::NAN, 0.0), // 5 excluded
            (2.0, 3.0),      // 6 duplicate of 1
            (5.0, 1.0),      // 7 dominated by 4
            (0.5, f64::NAN), // 8 excluded
            (1.0, 6.0),      // 9 dominated by 0 (same x)
        ];
        assert_eq!(pareto_front(&[(-0.0, 1.0), (0.0, 0.5)]), vec![1]);
        assert_eq!(pareto_front(&pts), vec![0, 1, 4]);
    }

    #[test]
    fn pareto_edge_cases() {
        assert!(pareto_front(&[]).is_empty());
        assert!(pareto_front(&[(f64::NAN, f64::NAN)]).is_empty());
        assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![0]);
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0]);
        assert_eq!(
            pareto_front(&[(f64::INFINITY, f64::INFINITY), (1.0, f64::INFINITY)]),
            vec![1]
        );
        assert_eq!(pareto_front(&[(f64::INFINITY, f64::INFINITY)]), vec![0]);
        assert_eq!(
            pareto_front(&[(f64::NEG_INFINITY, 3.0), (0.0, f64::NEG_INFINITY)]),
            vec![0, 1]
        );
    }
}

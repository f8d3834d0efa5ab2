//! The Pareto frontier of (time, error) points: the routes no other route beats in both.

/// The indices of the Pareto frontier of (time, error) points: those no other point beats in
/// both (≤ in both and < in one), sorted by time. Points with a non-finite or negative
/// coordinate are never on it.
pub fn pareto_frontier(points: &[(f64, f64)]) -> Vec<usize> {
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite() && p.0 >= 0.0 && p.1 >= 0.0;
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| ok(&points[i]))
        .filter(|&i| {
            let (t, e) = points[i];
            !points
                .iter()
                .any(|q| ok(q) && q.0 <= t && q.1 <= e && (q.0 < t || q.1 < e))
        })
        .collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frontier_keeps_exactly_the_undominated_points() {
        let points = [
            (1.0, 1e-3),
            (2.0, 1e-6),
            (3.0, 1e-6),
            (0.5, 1e-2),
            (2.5, 1e-1),
        ];
        assert_eq!(pareto_frontier(&points), vec![3, 0, 1]);
        assert_eq!(pareto_frontier(&[(f64::NAN, 1.0), (1.0, 1.0)]), vec![1]);
        assert_eq!(pareto_frontier(&[(1.0, -1.0), (2.0, 0.0)]), vec![1]);
    }
}

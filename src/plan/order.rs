//! The order of visiting: a short open path through the chosen positions,
//! nearest neighbour from a start, then 2-opt (reverse a segment whenever
//! that shortens the path; Croes, *A method for solving travelling-salesman
//! problems*, Operations Research 6, 1958) until no reversal helps.
//!
//! ```
//! use nalgebra::Vector3;
//! use sagcal::plan::{path_length_m, visiting_order};
//! // Five points on a line, shuffled: the shortest open path walks the line from the end nearest the start.
//! let xs = [3.0, 0.0, 4.0, 1.0, 2.0];
//! let points: Vec<Vector3<f64>> = xs.iter().map(|&x| Vector3::new(x, 0.0, 10.0)).collect();
//! let order = visiting_order(&points, &Vector3::new(-1.0, 0.0, 10.0));
//! assert_eq!(order, [1, 3, 4, 0, 2]);
//! let visited: Vec<Vector3<f64>> = order.iter().map(|&k| points[k]).collect();
//! assert_eq!(path_length_m(&visited), 4.0);
//! ```

use nalgebra::Vector3;

/// Length of the open path through `points` in this order, metres.
pub fn path_length_m(points: &[Vector3<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// A visiting order of `points` (indices into it): nearest neighbour from the
/// point closest to `start`, improved by 2-opt on the open path.
pub fn visiting_order(points: &[Vector3<f64>], start: &Vector3<f64>) -> Vec<usize> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    let first = (0..n)
        .min_by(|&a, &b| (points[a] - start).norm().total_cmp(&(points[b] - start).norm()))
        .unwrap_or(0);
    let mut order = vec![first];
    let mut visited = vec![false; n];
    visited[first] = true;
    while order.len() < n {
        let last = points[*order.last().unwrap_or(&first)];
        let next = (0..n)
            .filter(|&k| !visited[k])
            .min_by(|&a, &b| (points[a] - last).norm().total_cmp(&(points[b] - last).norm()))
            .unwrap_or(0);
        visited[next] = true;
        order.push(next);
    }
    two_opt(points, &mut order);
    order
}

/// Reverse `order[i+1..=j]` while that shortens the open path (the start stays first).
fn two_opt(points: &[Vector3<f64>], order: &mut [usize]) {
    let n = order.len();
    let mut improved = true;
    while improved {
        improved = false;
        for i in 0..n.saturating_sub(2) {
            for j in i + 2..n {
                let a = points[order[i]];
                let b = points[order[i + 1]];
                let c = points[order[j]];
                // The open path's last edge has no successor: reversing up to the end only swaps one edge.
                let before = (b - a).norm() + order.get(j + 1).map_or(0.0, |&e| (points[e] - c).norm());
                let after = (c - a).norm() + order.get(j + 1).map_or(0.0, |&e| (points[e] - b).norm());
                if after < before - 1e-12 {
                    order[i + 1..=j].reverse();
                    improved = true;
                }
            }
        }
    }
}

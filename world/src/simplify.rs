//! Fine outlines made usable: an outline of many vertices (a CAD export, a shape traced from
//! an image) is simplified with Ramer–Douglas–Peucker (`geo`'s `SimplifyIdx`), which keeps a
//! subset of the vertices such that no dropped vertex lies farther than the tolerance from the
//! simplified outline, in O(n log n) on average. The exact simple-polygon check runs on the
//! outline as given ([`crate::polygon::check_simple`]); the simplified one is checked again,
//! and a tolerance that would make it cross itself is halved until it does not.
//!
//! Every consumer of a scene (the shapes the planners and the simulator build, their convex
//! decomposition) then works on at most a few hundred vertices for any smooth shape: a circle
//! of radius 0.4 m keeps about 150 vertices within 0.1 mm, whatever it was drawn with.

use geo::{Coord, LineString, SimplifyIdx};

use crate::polygon::check_simple;

/// Outlines with more vertices than this are simplified when a scene loads.
pub const FINE_OUTLINE: usize = 1_000;

/// The most vertices an outline may keep after simplification: the convex decomposition the
/// planners and the simulator build is quadratic in them.
pub const MOST_VERTICES: usize = 20_000;

/// The largest distance, m, between a dropped vertex and the simplified outline (0.1 mm: the
/// camera's marker accuracy, far below what a push can tell).
pub const OUTLINE_TOLERANCE: f64 = 1e-4;

/// A simplified outline and where its vertices came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Simplified {
    /// The kept vertices, in order.
    pub outline: Vec<[f64; 2]>,
    /// For each kept vertex, its index in the outline as given (increasing, starting at 0).
    pub kept: Vec<usize>,
    /// The tolerance used, m (smaller than asked when that one made the outline cross itself).
    pub tolerance: f64,
}

impl Simplified {
    /// The edge of the simplified outline that holds edge `i` of the outline as given (edge `i`
    /// runs from vertex `i` to vertex `i + 1`).
    pub fn edge_of(&self, i: usize) -> usize {
        self.kept.partition_point(|&k| k <= i).saturating_sub(1)
    }
}

/// Simplify a simple, closed outline (no repeated closing vertex) within `tolerance`, m.
/// `None` when nothing can be dropped, or when no tolerance down to a thousandth of the one
/// asked keeps the outline simple (the outline is then used as given).
pub fn simplify(outline: &[[f64; 2]], tolerance: f64) -> Option<Simplified> {
    let n = outline.len();
    if n < 4 || tolerance.is_nan() || tolerance <= 0.0 {
        return None;
    }
    // A closed ring: the first vertex repeated at the end, both ends kept.
    let ring = LineString::new(
        outline
            .iter()
            .chain(std::iter::once(&outline[0]))
            .map(|p| Coord { x: p[0], y: p[1] })
            .collect(),
    );
    let mut tol = tolerance;
    while tol >= tolerance * 1e-3 {
        let mut kept = ring.simplify_idx(tol);
        kept.retain(|&k| k < n);
        if kept.len() == n {
            return None;
        }
        if kept.len() >= 3 {
            let simplified: Vec<[f64; 2]> = kept.iter().map(|&k| outline[k]).collect();
            if check_simple(&simplified).is_ok() {
                return Some(Simplified {
                    outline: simplified,
                    kept,
                    tolerance: tol,
                });
            }
        }
        tol /= 2.0;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(n: usize, r: f64) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    /// Distance from `p` to the closed polygon's boundary.
    fn distance(p: [f64; 2], poly: &[[f64; 2]]) -> f64 {
        (0..poly.len())
            .map(|i| {
                let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy))
                    .clamp(0.0, 1.0);
                (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_fine_circle_keeps_few_vertices_within_the_tolerance() {
        let c = circle(20_000, 0.4);
        let s = simplify(&c, OUTLINE_TOLERANCE).expect("simplified");
        // A chord of a circle of radius r deviates by r(1 − cos(θ/2)); within 0.1 mm on
        // r = 0.4 m that allows θ ≈ 0.045 rad, about 140 chords.
        assert!(
            (100..400).contains(&s.outline.len()),
            "{} vertices",
            s.outline.len()
        );
        assert_eq!(s.kept[0], 0);
        assert!(s.kept.windows(2).all(|w| w[0] < w[1]));
        let worst = c
            .iter()
            .map(|p| distance(*p, &s.outline))
            .fold(0.0, f64::max);
        assert!(worst <= OUTLINE_TOLERANCE + 1e-12, "worst {worst}");
        assert!(check_simple(&s.outline).is_ok());
    }

    #[test]
    fn a_coarse_outline_is_left_alone() {
        let square = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]];
        assert_eq!(simplify(&square, OUTLINE_TOLERANCE), None);
    }

    #[test]
    fn edges_map_to_the_simplified_edge_that_holds_them() {
        // A square with extra vertices along its sides: the simplified outline is the square.
        let mut pts = Vec::new();
        for side in 0..4 {
            for k in 0..10 {
                let t = k as f64 / 10.0;
                pts.push(match side {
                    0 => [t, 0.0],
                    1 => [1.0, t],
                    2 => [1.0 - t, 1.0],
                    _ => [0.0, 1.0 - t],
                });
            }
        }
        let s = simplify(&pts, 1e-6).expect("simplified");
        assert_eq!(s.kept, vec![0, 10, 20, 30]);
        assert_eq!(s.edge_of(0), 0);
        assert_eq!(s.edge_of(9), 0);
        assert_eq!(s.edge_of(10), 1);
        assert_eq!(s.edge_of(39), 3);
    }

    #[test]
    fn a_narrow_slot_is_not_closed_by_the_simplification() {
        // A comb: teeth 1 mm wide with 0.05 mm gaps; simplifying at 0.1 mm would cut across
        // the gaps; the result must stay simple whatever tolerance is used.
        let mut pts = vec![[0.0, 0.0]];
        let mut x = 0.0;
        for _ in 0..50 {
            pts.push([x, 0.01]);
            pts.push([x + 0.001, 0.01]);
            pts.push([x + 0.001, 0.0001]);
            pts.push([x + 0.00105, 0.0001]);
            x += 0.00105;
        }
        pts.push([x, 0.0]);
        pts.push([x, -0.01]);
        pts.push([0.0, -0.01]);
        assert!(check_simple(&pts).is_ok());
        if let Some(s) = simplify(&pts, OUTLINE_TOLERANCE) {
            assert!(check_simple(&s.outline).is_ok());
        }
    }
}

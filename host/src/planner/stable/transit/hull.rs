//! The convex geometry of the transit paths (Lynch & Mason 1996, §4.6): polygons grown by the
//! robot's turning disk, segment–polygon tests and their boxes.

use crate::mechanics::{V2, convex_hull};
use crate::planner::stable::Pose;

/// Whether segment `p0 → p1` passes through the interior of the convex polygon `poly`
/// (counter-clockwise), by Cyrus–Beck clipping.
pub fn segment_hits_convex(p0: V2, p1: V2, poly: &[V2]) -> bool {
    let n = poly.len();
    clips(
        p0,
        p1,
        (0..n).map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let e = b - a;
            (a, V2::new(e.y, -e.x).normalize())
        }),
    )
}

/// Cyrus–Beck: whether segment `p0 → p1` keeps a piece of positive length inside every edge
/// given as (a point on it, its outward unit normal).
pub(super) fn clips(p0: V2, p1: V2, edges: impl Iterator<Item = (V2, V2)>) -> bool {
    let eps = 1e-9;
    let (mut tl, mut th) = (0.0f64, 1.0f64);
    let d = p1 - p0;
    for (a, out) in edges {
        let num = out.dot(&(p0 - a)) + eps;
        let den = out.dot(&d);
        if den.abs() < 1e-15 {
            if num > 0.0 {
                return false;
            }
        } else {
            let t = -num / den;
            if den > 0.0 {
                th = th.min(t);
            } else {
                tl = tl.max(t);
            }
        }
        if tl >= th {
            return false;
        }
    }
    th - tl > 1e-12
}

/// A convex polygon (counter-clockwise) ready for many [`segment_hits_convex`] tests: its
/// edges' unit outward normals and its bounding box computed once.
#[derive(Debug, Clone)]
pub(super) struct Hull {
    /// Its vertices, counter-clockwise.
    pub(super) pts: Vec<V2>,
    outs: Vec<V2>,
    lo: V2,
    hi: V2,
}

impl Hull {
    /// This polygon (slider frame) placed at `q`: its points and normals turned with it.
    pub(super) fn placed(&self, q: &Pose) -> Hull {
        let pts: Vec<V2> = self.pts.iter().map(|p| q.apply(*p)).collect();
        let (mut lo, mut hi) = (V2::repeat(f64::INFINITY), V2::repeat(f64::NEG_INFINITY));
        for p in &pts {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        Hull {
            pts,
            outs: self.outs.iter().map(|n| q.rotate(*n)).collect(),
            lo,
            hi,
        }
    }

    pub(super) fn new(pts: Vec<V2>) -> Self {
        let n = pts.len();
        let outs = (0..n)
            .map(|i| {
                let e = pts[(i + 1) % n] - pts[i];
                V2::new(e.y, -e.x).normalize()
            })
            .collect();
        let (mut lo, mut hi) = (V2::repeat(f64::INFINITY), V2::repeat(f64::NEG_INFINITY));
        for p in &pts {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        Hull { pts, outs, lo, hi }
    }

    /// [`segment_hits_convex`] for this polygon, the same arithmetic; a segment whose box
    /// misses the polygon's misses the polygon.
    pub(super) fn hits(&self, p0: V2, p1: V2) -> bool {
        if p0.x.max(p1.x) < self.lo.x
            || p0.x.min(p1.x) > self.hi.x
            || p0.y.max(p1.y) < self.lo.y
            || p0.y.min(p1.y) > self.hi.y
        {
            return false;
        }
        clips(
            p0,
            p1,
            self.pts.iter().copied().zip(self.outs.iter().copied()),
        )
    }
}

/// Whether `p` lies strictly inside the convex polygon `poly`.
pub(super) fn inside_convex(p: V2, poly: &[V2]) -> bool {
    let n = poly.len();
    (0..n).all(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        crate::mechanics::cross(b - a, p - a) > 1e-9
    })
}

/// `poly` grown by a disk of radius `r` (conservatively: a circumscribed octagon).
pub fn grow(poly: &[V2], r: f64) -> Vec<V2> {
    let k = 8;
    let rr = r / (std::f64::consts::PI / k as f64).cos();
    let mut pts = Vec::with_capacity(poly.len() * k);
    for p in poly {
        for j in 0..k {
            let a = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / k as f64;
            pts.push(p + V2::new(a.cos(), a.sin()) * rr);
        }
    }
    convex_hull(&pts)
}

/// The box of `o` grown by more than the circumradius of the octagon that [`grow`] adds for a
/// disk of radius `r`.
pub(super) fn reach_box(o: &[V2], r: f64) -> (V2, V2) {
    let reach = r / (std::f64::consts::PI / 8.0).cos() + 1e-9;
    let (mut a, mut b) = (V2::repeat(f64::INFINITY), V2::repeat(f64::NEG_INFINITY));
    for p in o {
        a = a.inf(p);
        b = b.sup(p);
    }
    (a - V2::repeat(reach), b + V2::repeat(reach))
}

/// Distance from point `p` to segment `a b`.
pub fn point_segment_distance(p: V2, a: V2, b: V2) -> f64 {
    let d = b - a;
    let t = if d.norm_squared() > 0.0 {
        ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t - p).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    pub(super) fn segment_through_square_hits_and_grazing_does_not() {
        let sq = [
            V2::new(0.0, 0.0),
            V2::new(1.0, 0.0),
            V2::new(1.0, 1.0),
            V2::new(0.0, 1.0),
        ];
        assert!(segment_hits_convex(
            V2::new(-1.0, 0.5),
            V2::new(2.0, 0.5),
            &sq
        ));
        assert!(!segment_hits_convex(
            V2::new(-1.0, 1.0),
            V2::new(2.0, 1.0),
            &sq
        ));
        assert!(!segment_hits_convex(
            V2::new(-1.0, 2.0),
            V2::new(2.0, 1.5),
            &sq
        ));
    }
}

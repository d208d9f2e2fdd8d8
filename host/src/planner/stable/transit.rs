//! Transit paths between pushing contacts for a mobile pusher confined to the plane — the open
//! problem of Lynch & Mason (1996) §4.6 (a *transit path* in the terms of Alami et al.).
//!
//! With the slider still at configuration `q`, the robot backs straight away from its edge
//! until the disk it sweeps when turning in place (about its axle centre) clears the slider,
//! drives as that disk along a shortest path of a visibility graph among the obstacles and the
//! slider, each grown by the disk's radius (Minkowski sum with a circumscribed octagon, so the
//! growth is conservative), and drives straight onto the new edge. The two straight legs are
//! checked with the exact footprint.
//!
//! The slider's octagon turns with the slider (its hull is grown once, in the slider frame), so
//! whether a contact's stand-off point lies outside it does not depend on the slider's heading:
//! with a world-aligned octagon a corner of it covered the stand-off point off an edge at some
//! headings and the transit was refused there (and with it many car plans). [`Transits`] holds
//! what a search's many transit paths share.

use std::collections::BinaryHeap;

use super::collision::{Body, Swept};
use super::{Pose, Problem};
use crate::mechanics::{V2, V3, convex_hull};

/// A transit path of the pusher between two contacts.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TransitPath {
    /// Contact index left.
    pub from_contact: usize,
    /// Contact index reached.
    pub to_contact: usize,
    /// Slider configuration during the transit.
    pub at: Pose,
    /// Way points of the robot's axle centre (world frame), from contact to contact.
    pub waypoints: Vec<[f64; 2]>,
    /// Path length (m).
    pub length: f64,
}

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
fn clips(p0: V2, p1: V2, edges: impl Iterator<Item = (V2, V2)>) -> bool {
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
struct Hull {
    pts: Vec<V2>,
    outs: Vec<V2>,
    lo: V2,
    hi: V2,
}

impl Hull {
    /// This polygon (slider frame) placed at `q`: its points and normals turned with it.
    fn placed(&self, q: &Pose) -> Hull {
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

    fn new(pts: Vec<V2>) -> Self {
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
    fn hits(&self, p0: V2, p1: V2) -> bool {
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
fn inside_convex(p: V2, poly: &[V2]) -> bool {
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

/// Shortest path for a disk of radius `r` from `s` to `g` among convex obstacles inside a
/// `w × h` table (visibility graph, A* with the straight-line distance). Returns the way points.
///
/// The obstacles are added as the path meets them: the shortest path among a subset of the
/// obstacles is found, and if it also misses all the others it is a shortest path among all of
/// them; else the obstacles it meets join the subset and the search is repeated. If there is
/// no path among a subset there is none among all. Obstacles are grown only when their box
/// comes within reach.
pub fn disk_path(
    s: V2,
    g: V2,
    r: f64,
    table: (f64, f64),
    obstacles: &[Vec<V2>],
) -> Option<Vec<V2>> {
    let boxes: Vec<(V2, V2)> = obstacles.iter().map(|o| reach_box(o, r)).collect();
    let mut grown = Grown {
        fixed: &[],
        raw: obstacles,
        lazy: vec![None; obstacles.len()],
        r,
    };
    disk_path_in(s, g, r, table, &boxes, &mut grown)
}

/// The box of `o` grown by more than the circumradius of the octagon that [`grow`] adds for a
/// disk of radius `r`.
fn reach_box(o: &[V2], r: f64) -> (V2, V2) {
    let reach = r / (std::f64::consts::PI / 8.0).cos() + 1e-9;
    let (mut a, mut b) = (V2::repeat(f64::INFINITY), V2::repeat(f64::NEG_INFINITY));
    for p in o {
        a = a.inf(p);
        b = b.sup(p);
    }
    (a - V2::repeat(reach), b + V2::repeat(reach))
}

/// The grown obstacles of one [`disk_path_in`] query: `fixed` grown beforehand (obstacles
/// `0 .. fixed.len()`), then `raw`, grown by `r` when first needed.
struct Grown<'a> {
    fixed: &'a [Hull],
    raw: &'a [Vec<V2>],
    lazy: Vec<Option<Hull>>,
    r: f64,
}

impl Grown<'_> {
    /// Obstacle `i` grown (growing it now if it was not).
    fn get(&mut self, i: usize) -> &Hull {
        let m = self.fixed.len();
        if i < m {
            return &self.fixed[i];
        }
        let (raw, r) = (self.raw, self.r);
        self.lazy[i - m].get_or_insert_with(|| Hull::new(grow(&raw[i - m], r)))
    }

    /// Obstacle `i` grown, if it was.
    fn peek(&self, i: usize) -> Option<&Hull> {
        let m = self.fixed.len();
        if i < m {
            Some(&self.fixed[i])
        } else {
            self.lazy[i - m].as_ref()
        }
    }
}

/// [`disk_path`] among the obstacles of `grown` with their boxes `boxes` ([`reach_box`]).
fn disk_path_in(
    s: V2,
    g: V2,
    r: f64,
    table: (f64, f64),
    boxes: &[(V2, V2)],
    grown: &mut Grown<'_>,
) -> Option<Vec<V2>> {
    let in_table = |p: V2| p.x >= r && p.x <= table.0 - r && p.y >= r && p.y <= table.1 - r;
    let seg_box = |a: V2, b: V2, (lo, hi): (V2, V2)| {
        a.x.max(b.x) >= lo.x && a.x.min(b.x) <= hi.x && a.y.max(b.y) >= lo.y && a.y.min(b.y) <= hi.y
    };
    for p in [s, g] {
        if !in_table(p) {
            return None;
        }
        for (i, bx) in boxes.iter().enumerate() {
            if seg_box(p, p, *bx) && inside_convex(p, &grown.get(i).pts) {
                return None;
            }
        }
    }
    let mut subset: Vec<usize> = Vec::new();
    loop {
        let refs: Vec<&Hull> = subset.iter().filter_map(|&i| grown.peek(i)).collect();
        let path = visibility_path(s, g, &refs, &in_table)?;
        let mut hit = Vec::new();
        for (i, bx) in boxes.iter().enumerate() {
            if subset.contains(&i) || !path.windows(2).any(|w| seg_box(w[0], w[1], *bx)) {
                continue;
            }
            let o = grown.get(i);
            if path.windows(2).any(|w| o.hits(w[0], w[1])) {
                hit.push(i);
            }
        }
        if hit.is_empty() {
            return Some(path);
        }
        subset.extend(hit);
    }
}

/// The shortest path from `s` to `g` (both free) in the visibility graph of the grown convex
/// obstacles `grown` (their vertices pushed out by 1 µm, those inside the table and no
/// obstacle), by A* on the straight-line distance to `g`.
fn visibility_path(
    s: V2,
    g: V2,
    grown: &[&Hull],
    in_table: &dyn Fn(V2) -> bool,
) -> Option<Vec<V2>> {
    let mut nodes = vec![s, g];
    for o in grown {
        let o = &o.pts;
        let c = o.iter().sum::<V2>() / o.len() as f64;
        for v in o.iter() {
            let p = v + (v - c).normalize() * 1e-6;
            if in_table(p) && !grown.iter().any(|q| inside_convex(p, &q.pts)) {
                nodes.push(p);
            }
        }
    }
    let visible = |a: V2, b: V2| !grown.iter().any(|o| o.hits(a, b));
    let n = nodes.len();
    let mut dist = vec![f64::INFINITY; n];
    let mut prev = vec![usize::MAX; n];
    let mut done = vec![false; n];
    dist[0] = 0.0;
    let key = |d: f64, v: usize| ((d + (nodes[v] - g).norm()) * 1e9) as u64;
    let mut heap = BinaryHeap::new();
    heap.push(std::cmp::Reverse((key(0.0, 0), 0usize)));
    while let Some(std::cmp::Reverse((_, u))) = heap.pop() {
        if done[u] {
            continue;
        }
        done[u] = true;
        if u == 1 {
            break;
        }
        for v in 0..n {
            if done[v] {
                continue;
            }
            let d = dist[u] + (nodes[v] - nodes[u]).norm();
            if d < dist[v] && visible(nodes[u], nodes[v]) {
                dist[v] = d;
                prev[v] = u;
                heap.push(std::cmp::Reverse((key(d, v), v)));
            }
        }
    }
    if !dist[1].is_finite() {
        return None;
    }
    let mut path = vec![g];
    let mut i = 1;
    while prev[i] != usize::MAX {
        i = prev[i];
        path.push(nodes[i]);
    }
    path.reverse();
    Some(path)
}

/// The robot's straight leg off contact `contact`, in the slider frame: the axle centre at
/// the contact, the way it backs off until the disk of radius `r` about it (the robot turning
/// in place) clears every slider vertex and edge, and the footprint that translates so.
#[derive(Clone)]
struct Leg {
    /// Axle centre at the contact (slider frame).
    axle: V2,
    /// Axle centre at the stand-off (slider frame).
    stand_off: V2,
    /// The footprint alone.
    foot: Body,
    /// Its translation from the contact to the stand-off (slider frame).
    xi: V3,
    /// The footprint's swept shape under `xi`.
    swept: Swept,
}

impl Leg {
    /// The leg off `contact` for the disk radius `r`, `None` if the robot would have to back
    /// off implausibly far.
    fn new(p: &Problem, contact: usize, r: f64) -> Option<Self> {
        let cm = &p.contacts[contact];
        let pl = &cm.placement;
        let axle_s = pl.to_slider(V2::new(0.0, -p.pusher.axle_offset));
        let back_dir = -pl.normal;
        // Back off until the disk about the axle clears every slider vertex and edge.
        let slider = &p.slider.vertices;
        let clear = |c: V2| {
            let n = slider.len();
            (0..n).all(|i| point_segment_distance(c, slider[i], slider[(i + 1) % n]) > r + 1e-4)
        };
        let mut b = 0.0;
        while !clear(axle_s + back_dir * b) {
            b += 0.01;
            if b > 10.0 * (r + p.slider.radius()) {
                return None;
            }
        }
        let foot = Body::new(std::slice::from_ref(&cm.footprint));
        let xi = V3::new(back_dir.x * b, back_dir.y * b, 0.0);
        Some(Leg {
            axle: axle_s,
            stand_off: axle_s + back_dir * b,
            swept: foot.swept(&xi),
            foot,
            xi,
        })
    }

    /// The world axle-centre positions at the contact and at the stand-off with the slider
    /// at `q`, or `None` if the footprint would collide on the way (checked exactly, as
    /// [`Body::step_free`] decides, mostly by one test of the precomputed swept shape).
    fn at(&self, p: &Problem, q: &Pose) -> Option<(V2, V2)> {
        if !self
            .foot
            .step_free_swept(&p.world, q, &self.xi, &self.swept)
        {
            return None;
        }
        Some((q.apply(self.axle), q.apply(self.stand_off)))
    }
}

/// What the transit paths of one problem share, computed once (a search asks for many): the
/// turning disk's radius, each contact's [`Leg`], and the obstacles grown by the disk.
#[derive(Clone)]
pub struct Transits {
    r: f64,
    legs: Vec<Option<Leg>>,
    /// The obstacles (walls excluded) grown by `r` ([`grow`]) and their boxes ([`reach_box`]).
    grown: Vec<Hull>,
    boxes: Vec<(V2, V2)>,
    /// The slider's convex hull and that hull grown by `r`, slider frame (the octagon turns
    /// with the slider: it still holds the disk about every point of the hull).
    slider_hull: Vec<V2>,
    slider_grown: Hull,
}

impl Transits {
    /// The shared parts of problem `p`'s transit paths.
    pub fn new(p: &Problem) -> Self {
        if !p.pusher.is_mobile() {
            return Transits {
                r: 0.0,
                legs: vec![],
                grown: vec![],
                boxes: vec![],
                slider_hull: vec![],
                slider_grown: Hull::new(vec![]),
            };
        }
        let r = p.pusher.turning_radius_disk();
        let statics = &p.world.obstacles[p.world.n_walls..];
        let slider_grown = Hull::new(grow(&p.slider.vertices, r));
        Transits {
            r,
            legs: (0..p.contacts.len()).map(|c| Leg::new(p, c, r)).collect(),
            grown: statics
                .iter()
                .map(|o| Hull::new(grow(&o.vertices, r)))
                .collect(),
            boxes: statics.iter().map(|o| reach_box(&o.vertices, r)).collect(),
            slider_hull: convex_hull(&p.slider.vertices),
            slider_grown,
        }
    }

    /// A transit path from contact `from` to contact `to` with the slider at `q`, or `None`
    /// (the same as [`transit`]).
    pub fn path(&self, p: &Problem, q: &Pose, from: usize, to: usize) -> Option<TransitPath> {
        if !p.pusher.is_mobile() || from == to {
            return Some(TransitPath {
                from_contact: from,
                to_contact: to,
                at: *q,
                waypoints: vec![],
                length: 0.0,
            });
        }
        let (c0, s0) = self.legs.get(from)?.as_ref()?.at(p, q)?;
        let (c1, s1) = self.legs.get(to)?.as_ref()?.at(p, q)?;
        let hull: Vec<V2> = self.slider_hull.iter().map(|v| q.apply(*v)).collect();
        let mut boxes = Vec::with_capacity(self.boxes.len() + 1);
        boxes.extend_from_slice(&self.boxes);
        boxes.push(reach_box(&hull, self.r));
        let mut grown = Grown {
            fixed: &self.grown,
            raw: &[],
            lazy: vec![Some(self.slider_grown.placed(q))],
            r: self.r,
        };
        let mid = disk_path_in(s0, s1, self.r, p.world.table, &boxes, &mut grown)?;
        let mut pts = vec![c0];
        pts.extend(mid);
        pts.push(c1);
        let length = pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        Some(TransitPath {
            from_contact: from,
            to_contact: to,
            at: *q,
            waypoints: pts.iter().map(|p| [p.x, p.y]).collect(),
            length,
        })
    }
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

/// A transit path from contact `from` to contact `to` with the slider at `q`, or `None`.
/// (A search asking for many builds [`Transits`] once.)
pub fn transit(p: &Problem, q: &Pose, from: usize, to: usize, _tag: u32) -> Option<TransitPath> {
    Transits::new(p).path(p, q, from, to)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_through_square_hits_and_grazing_does_not() {
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

    #[test]
    fn disk_goes_around_a_wall() {
        // A wall across the middle with a gap at the top: the path must pass the gap.
        let wall = vec![
            V2::new(4.5, 0.0),
            V2::new(5.5, 0.0),
            V2::new(5.5, 8.0),
            V2::new(4.5, 8.0),
        ];
        let path = disk_path(
            V2::new(1.0, 1.0),
            V2::new(9.0, 1.0),
            0.5,
            (10.0, 10.0),
            &[wall],
        )
        .unwrap();
        let len: f64 = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        // Lower bound: the centre must cross x ∈ [4.5, 5.5] at y ≥ 8 (over the wall's top).
        let lb = (V2::new(4.5, 8.0) - V2::new(1.0, 1.0)).norm()
            + 1.0
            + (V2::new(9.0, 1.0) - V2::new(5.5, 8.0)).norm();
        assert!(len >= lb - 1e-6 && len < lb + 1.5, "len {len} lb {lb}");
        assert!(
            disk_path(
                V2::new(1.0, 1.0),
                V2::new(9.0, 1.0),
                1.2,
                (10.0, 10.0),
                &[vec![
                    V2::new(4.5, 0.0),
                    V2::new(5.5, 0.0),
                    V2::new(5.5, 10.0),
                    V2::new(4.5, 10.0)
                ]]
            )
            .is_none()
        );
    }
}

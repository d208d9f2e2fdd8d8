//! Shortest paths of the robot's turning disk among convex obstacles on the table: the
//! visibility graph of the transit paths (Lynch & Mason 1996, §4.6), and the two ways around
//! one polygon.

use std::collections::BinaryHeap;

use super::hull::{Hull, grow, inside_convex, reach_box};
use crate::mechanics::V2;

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
    disk_path_in(s, g, table_region(table, r), &boxes, &mut grown)
}

/// The box (lower, upper corner) the centre of a disk of radius `r` stays in on a `w × h`
/// table.
pub(super) fn table_region(table: (f64, f64), r: f64) -> (V2, V2) {
    (V2::new(r, r), V2::new(table.0 - r, table.1 - r))
}

/// Whether `p` lies in the box `region` (lower, upper corner; borders included).
pub(super) fn in_region(p: V2, (lo, hi): (V2, V2)) -> bool {
    p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y
}

/// Whether the box of segment `a b` meets the box `(lo, hi)`.
pub(super) fn seg_box(a: V2, b: V2, (lo, hi): (V2, V2)) -> bool {
    a.x.max(b.x) >= lo.x && a.x.min(b.x) <= hi.x && a.y.max(b.y) >= lo.y && a.y.min(b.y) <= hi.y
}

/// The grown obstacles of one [`disk_path_in`] query: `fixed` grown beforehand (obstacles
/// `0 .. fixed.len()`), then `raw`, grown by `r` when first needed.
pub(super) struct Grown<'a> {
    pub(super) fixed: &'a [Hull],
    pub(super) raw: &'a [Vec<V2>],
    pub(super) lazy: Vec<Option<Hull>>,
    pub(super) r: f64,
}

impl Grown<'_> {
    /// Obstacle `i` grown (growing it now if it was not).
    pub(super) fn get(&mut self, i: usize) -> &Hull {
        let m = self.fixed.len();
        if i < m {
            return &self.fixed[i];
        }
        let (raw, r) = (self.raw, self.r);
        self.lazy[i - m].get_or_insert_with(|| Hull::new(grow(&raw[i - m], r)))
    }

    /// Obstacle `i` grown, if it was.
    pub(super) fn peek(&self, i: usize) -> Option<&Hull> {
        let m = self.fixed.len();
        if i < m {
            Some(&self.fixed[i])
        } else {
            self.lazy[i - m].as_ref()
        }
    }
}

/// [`disk_path`] among the obstacles of `grown` with their boxes `boxes` ([`reach_box`]), the
/// disk's centre kept in the box `region` ([`table_region`]).
pub(super) fn disk_path_in(
    s: V2,
    g: V2,
    region: (V2, V2),
    boxes: &[(V2, V2)],
    grown: &mut Grown<'_>,
) -> Option<Vec<V2>> {
    let in_table = |p: V2| in_region(p, region);
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

/// The vertices of `hull`, each pushed out by 1 µm from its centroid (so that a path through
/// them passes outside it).
fn nudged(hull: &Hull) -> impl Iterator<Item = V2> + '_ {
    let c = hull.pts.iter().sum::<V2>() / hull.pts.len() as f64;
    hull.pts.iter().map(move |v| v + (v - c).normalize() * 1e-6)
}

/// The shortest path from `s` to `g` (both free) in the visibility graph of the grown convex
/// obstacles `grown` (their vertices pushed out by 1 µm, those inside the table and no
/// obstacle), by A* on the straight-line distance to `g`.
pub(super) fn visibility_path(
    s: V2,
    g: V2,
    grown: &[&Hull],
    in_table: &dyn Fn(V2) -> bool,
) -> Option<Vec<V2>> {
    let mut nodes = vec![s, g];
    for o in grown {
        nodes.extend(
            nudged(o).filter(|&p| in_table(p) && !grown.iter().any(|q| inside_convex(p, &q.pts))),
        );
    }
    let visible = |a: usize, b: usize| !grown.iter().any(|o| o.hits(nodes[a], nodes[b]));
    shortest_in(&nodes, visible)
}

/// A* on the straight-line distance from `nodes[0]` to `nodes[1]` in the graph whose edges
/// are the pairs `visible` says see each other (asked only when the edge would shorten a
/// path). Returns the way points.
fn shortest_in(nodes: &[V2], mut visible: impl FnMut(usize, usize) -> bool) -> Option<Vec<V2>> {
    let g = nodes[1];
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
            if d < dist[v] && visible(u, v) {
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

/// The visibility graph among fixed grown obstacles alone, built once for many
/// [`path_among`] queries: their vertices (pushed out by 1 µm) that lie in the region and in
/// no obstacle, and which pairs of them see each other.
#[derive(Clone)]
pub(super) struct StaticGraph {
    nodes: Vec<V2>,
    /// `sees[i · n + j]`: nodes `i` and `j` see each other.
    sees: Vec<bool>,
}

impl StaticGraph {
    /// The graph of `grown` with nodes kept in `region`.
    pub(super) fn new(grown: &[Hull], region: (V2, V2)) -> Self {
        let nodes: Vec<V2> = grown
            .iter()
            .flat_map(nudged)
            .filter(|&p| in_region(p, region) && !grown.iter().any(|q| inside_convex(p, &q.pts)))
            .collect();
        let n = nodes.len();
        let mut sees = vec![false; n * n];
        for i in 0..n {
            for j in i + 1..n {
                let v = !grown.iter().any(|o| o.hits(nodes[i], nodes[j]));
                sees[i * n + j] = v;
                sees[j * n + i] = v;
            }
        }
        StaticGraph { nodes, sees }
    }
}

/// A shortest path for the disk from `s` to `g` among the fixed obstacles `grown` (with
/// their [`StaticGraph`] `graph`) and one more, `extra` (the slider where it stands), the
/// disk's centre kept in `region`: the path [`disk_path_in`] finds among them all, but the
/// fixed obstacles' visibility is looked up, not tested again.
pub(super) fn path_among(
    s: V2,
    g: V2,
    region: (V2, V2),
    grown: &[Hull],
    graph: &StaticGraph,
    extra: &Hull,
) -> Option<Vec<V2>> {
    let blocked =
        |p: V2| inside_convex(p, &extra.pts) || grown.iter().any(|o| inside_convex(p, &o.pts));
    if [s, g].iter().any(|&p| !in_region(p, region) || blocked(p)) {
        return None;
    }
    let mut nodes = vec![s, g];
    nodes.extend(nudged(extra).filter(|&p| in_region(p, region) && !blocked(p)));
    let base = nodes.len();
    // The fixed nodes outside the extra obstacle follow, `fixed[k]` being the graph's index of
    // node `base + k`.
    let fixed: Vec<usize> = (0..graph.nodes.len())
        .filter(|&i| !inside_convex(graph.nodes[i], &extra.pts))
        .collect();
    nodes.extend(fixed.iter().map(|&i| graph.nodes[i]));
    let n_fixed = graph.nodes.len();
    let visible = |u: usize, v: usize| {
        let (a, b) = (nodes[u], nodes[v]);
        if u >= base && v >= base {
            let (i, j) = (fixed[u - base], fixed[v - base]);
            graph.sees[i * n_fixed + j] && !extra.hits(a, b)
        } else {
            !extra.hits(a, b) && !grown.iter().any(|o| o.hits(a, b))
        }
    };
    shortest_in(&nodes, visible)
}

/// The ways from `s` to `g` around the one convex polygon `hull`, shortest first, as way
/// points through its vertices (each pushed out by 1 µm, as [`visibility_path`] does): the
/// straight segment when it misses the polygon, else the shortest way on each side of the
/// line from `s` to `g`. None when `s` or `g` lies inside it.
pub(super) fn ways_around(hull: &Hull, s: V2, g: V2) -> Vec<Vec<V2>> {
    let pts = &hull.pts;
    if inside_convex(s, pts) || inside_convex(g, pts) {
        return vec![];
    }
    if !hull.hits(s, g) {
        return vec![vec![s, g]];
    }
    let m = pts.len();
    let v: Vec<V2> = nudged(hull).collect();
    let from_s: Vec<bool> = v.iter().map(|p| !hull.hits(s, *p)).collect();
    let to_g: Vec<bool> = v.iter().map(|p| !hull.hits(*p, g)).collect();
    // The shortest way on each side of the line `s g` (which crosses the polygon): a way's
    // side is that of its way point farthest from the line.
    let side = |w: &[V2]| {
        let far = w
            .iter()
            .map(|p| crate::mechanics::cross(g - s, p - s))
            .fold(0.0f64, |a, b| if b.abs() > a.abs() { b } else { a });
        usize::from(far > 0.0)
    };
    let mut best: [Option<(f64, Vec<V2>)>; 2] = [None, None];
    for dir in [1, m - 1] {
        for i in (0..m).filter(|&i| from_s[i]) {
            let (mut len, mut way) = ((v[i] - s).norm(), vec![s, v[i]]);
            let mut j = i;
            for _ in 0..m {
                if to_g[j] {
                    let total = len + (g - v[j]).norm();
                    let mut w = way.clone();
                    w.push(g);
                    let b = &mut best[side(&w)];
                    if b.as_ref().is_none_or(|b| total < b.0) {
                        *b = Some((total, w));
                    }
                }
                let k = (j + dir) % m;
                if hull.hits(v[j], v[k]) {
                    break;
                }
                len += (v[k] - v[j]).norm();
                way.push(v[k]);
                j = k;
            }
        }
    }
    let mut ways: Vec<(f64, Vec<V2>)> = best.into_iter().flatten().collect();
    ways.sort_by(|a, b| a.0.total_cmp(&b.0));
    ways.into_iter().map(|(_, w)| w).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn length(path: &[V2]) -> f64 {
        path.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
    }

    /// A square of side 0.1–0.3 m at a random pose on a 2 × 1.5 m table, grown by `r`.
    fn random_square(rng: &mut rand_chacha::ChaCha8Rng, r: f64) -> Hull {
        let (cx, cy) = (rng.random_range(0.0..2.0), rng.random_range(0.0..1.5));
        let (h, a) = (rng.random_range(0.05..0.15), rng.random_range(0.0..1.6));
        let (s, c) = f64::sin_cos(a);
        let square: Vec<V2> = [(-h, -h), (h, -h), (h, h), (-h, h)]
            .iter()
            .map(|&(x, y)| V2::new(cx + c * x - s * y, cy + s * x + c * y))
            .collect();
        Hull::new(grow(&square, r))
    }

    fn bbox(h: &Hull) -> (V2, V2) {
        let lo = h
            .pts
            .iter()
            .fold(V2::repeat(f64::INFINITY), |a, p| a.inf(p));
        let hi = h
            .pts
            .iter()
            .fold(V2::repeat(f64::NEG_INFINITY), |a, p| a.sup(p));
        (lo, hi)
    }

    #[test]
    fn path_among_finds_what_the_incremental_search_finds() {
        // Against `disk_path_in` over all the obstacles (which adds them as its path meets
        // them): the same answer on whether a path exists and the same length, over random
        // tables of 3–9 obstacles and a slider.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let r = 0.1;
        let region = table_region((2.0, 1.5), r);
        let (mut found, mut none) = (0, 0);
        for _ in 0..400 {
            let n = rng.random_range(3..10);
            let statics: Vec<Hull> = (0..n).map(|_| random_square(&mut rng, r)).collect();
            let slider = random_square(&mut rng, r);
            let s = V2::new(rng.random_range(0.0..2.0), rng.random_range(0.0..1.5));
            let g = V2::new(rng.random_range(0.0..2.0), rng.random_range(0.0..1.5));
            let graph = StaticGraph::new(&statics, region);
            let fast = path_among(s, g, region, &statics, &graph, &slider);
            let mut all = statics.clone();
            all.push(slider.clone());
            let boxes: Vec<(V2, V2)> = all.iter().map(bbox).collect();
            let mut grown = Grown {
                fixed: &all,
                raw: &[],
                lazy: vec![],
                r,
            };
            let reference = disk_path_in(s, g, region, &boxes, &mut grown);
            match (&fast, &reference) {
                (Some(a), Some(b)) => {
                    found += 1;
                    assert!((length(a) - length(b)).abs() < 1e-9, "{a:?} vs {b:?}");
                    assert_eq!((a[0], a[a.len() - 1]), (s, g));
                }
                (None, None) => none += 1,
                _ => panic!("path_among {fast:?}, incremental search {reference:?}"),
            }
        }
        // Both outcomes occur often enough for the comparison to mean something.
        assert!(found > 50 && none > 50, "found {found}, none {none}");
    }

    #[test]
    fn ways_around_one_polygon_are_its_shortest_paths_round_each_side() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let everywhere = (V2::repeat(f64::NEG_INFINITY), V2::repeat(f64::INFINITY));
        let mut two = 0;
        for _ in 0..300 {
            let hull = random_square(&mut rng, 0.1);
            // Points round the polygon, mostly on opposite sides of it.
            let c = hull.pts.iter().sum::<V2>() / hull.pts.len() as f64;
            let mut round = |turn: f64| {
                let a: f64 = rng.random_range(-0.6..0.6) + turn;
                c + V2::new(a.cos(), a.sin()) * rng.random_range(0.1..0.6)
            };
            let (s, g) = (round(0.0), round(std::f64::consts::PI));
            let ways = ways_around(&hull, s, g);
            let shortest = visibility_path(s, g, &[&hull], &|p| in_region(p, everywhere));
            match shortest {
                None => assert!(ways.is_empty(), "{ways:?}"),
                Some(p) => {
                    assert!(!ways.is_empty() && ways.len() <= 2);
                    assert!((length(&ways[0]) - length(&p)).abs() < 1e-9);
                    for w in &ways {
                        assert_eq!((w[0], w[w.len() - 1]), (s, g));
                        assert!(!w.windows(2).any(|e| hull.hits(e[0], e[1])), "{w:?}");
                    }
                    if ways.len() == 2 {
                        two += 1;
                        assert!(length(&ways[1]) >= length(&ways[0]));
                        // The two ways pass on opposite sides of the line s g.
                        let side = |w: &[V2]| {
                            w.iter()
                                .map(|p| crate::mechanics::cross(g - s, p - s))
                                .fold(0.0, |a: f64, b| if b.abs() > a.abs() { b } else { a })
                        };
                        assert!(side(&ways[0]) * side(&ways[1]) < 0.0, "{ways:?}");
                    }
                }
            }
        }
        assert!(two > 100, "{two} cases with two ways");
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

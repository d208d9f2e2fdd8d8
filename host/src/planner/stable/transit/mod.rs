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

mod hull;
mod visibility;

use std::cell::OnceCell;

use super::collision::{Body, Swept};
use super::{Pose, Problem};
use crate::mechanics::{V2, V3};
use hull::{Hull, grow, reach_box};
pub use hull::{point_segment_distance, segment_hits_convex};
pub use visibility::disk_path;
use visibility::{StaticGraph, in_region, path_among, seg_box, table_region, ways_around};

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
/// turning disk's radius, each contact's `Leg`, and the obstacles grown by the disk.
#[derive(Clone)]
pub struct Transits {
    r: f64,
    legs: Vec<Option<Leg>>,
    /// The obstacles (walls excluded) grown by `r` ([`grow`]) and their boxes ([`reach_box`]).
    grown: Vec<Hull>,
    boxes: Vec<(V2, V2)>,
    /// The slider's convex hull grown by `r`, slider frame (the octagon turns with the slider:
    /// it still holds the disk about every point of the hull).
    slider_grown: Hull,
    /// Per pair of contacts (`from · n + to`), found when first asked for: the ways between
    /// their stand-off points around the slider alone, slider frame, on an unbounded table,
    /// shortest first ([`ways_around`]; none: there is no path, among more obstacles neither).
    around: Vec<OnceCell<Vec<Vec<V2>>>>,
    /// The visibility graph among the grown obstacles alone, built when a transit first needs
    /// more than a way around the slider.
    graph: OnceCell<StaticGraph>,
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
                slider_grown: Hull::new(vec![]),
                around: vec![],
                graph: OnceCell::new(),
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
            slider_grown,
            around: vec![OnceCell::new(); p.contacts.len() * p.contacts.len()],
            graph: OnceCell::new(),
        }
    }

    /// The ways around the slider alone from contact `from`'s stand-off point `s0` to contact
    /// `to`'s `s1` (slider frame; see `around`).
    fn around_slider(&self, from: usize, to: usize, s0: V2, s1: V2) -> &[Vec<V2>] {
        let n = self.legs.len();
        self.around[from * n + to].get_or_init(|| ways_around(&self.slider_grown, s0, s1))
    }

    /// A shortest transit path from contact `from` to contact `to` with the slider at `q`, or
    /// `None` (the same as [`transit`]).
    pub fn path(&self, p: &Problem, q: &Pose, from: usize, to: usize) -> Option<TransitPath> {
        self.find(p, q, from, to, 1)
    }

    /// Whether there is a transit path from contact `from` to contact `to` with the slider at
    /// `q`: `Some` exactly when [`Transits::path`] is, but the path may be longer than the
    /// shortest (the other way round the slider, when that misses every obstacle and the
    /// short way does not). A search needs only whether a transit exists.
    pub fn any_path(&self, p: &Problem, q: &Pose, from: usize, to: usize) -> Option<TransitPath> {
        self.find(p, q, from, to, 2)
    }

    /// A transit path: the first of the `ways` first ways around the slider alone that, placed
    /// at `q`, stays on the table and misses every other obstacle; else a shortest path
    /// among them all. The first way is the shortest around the slider, so if it is clear it
    /// is also a shortest path among them all (the search below would find it, its first
    /// obstacle being the slider); and a clear way is a path in that search's visibility
    /// graph, so it finds one exactly when some way is clear.
    fn find(
        &self,
        p: &Problem,
        q: &Pose,
        from: usize,
        to: usize,
        ways: usize,
    ) -> Option<TransitPath> {
        if !p.pusher.is_mobile() || from == to {
            return Some(TransitPath {
                from_contact: from,
                to_contact: to,
                at: *q,
                waypoints: vec![],
                length: 0.0,
            });
        }
        let (leg0, leg1) = (self.legs.get(from)?.as_ref()?, self.legs.get(to)?.as_ref()?);
        // The legs' exact footprint tests last: most transits that fail, fail for want of a
        // path between the stand-off points, which is cheaper to find.
        let (s0, s1) = (q.apply(leg0.stand_off), q.apply(leg1.stand_off));
        let region = table_region(p.world.table, self.r);
        let around = self.around_slider(from, to, leg0.stand_off, leg1.stand_off);
        let clear = |path: &[V2]| {
            path.iter().all(|v| in_region(*v, region))
                && !path.windows(2).any(|w| {
                    self.boxes
                        .iter()
                        .zip(&self.grown)
                        .any(|(bx, o)| seg_box(w[0], w[1], *bx) && o.hits(w[0], w[1]))
                })
        };
        let placed = around
            .iter()
            .take(ways)
            .map(|way| way.iter().map(|v| q.apply(*v)).collect::<Vec<V2>>())
            .find(|way| clear(way));
        let mid = match placed {
            Some(way) => way,
            None if around.is_empty() => return None,
            None => {
                let graph = self
                    .graph
                    .get_or_init(|| StaticGraph::new(&self.grown, region));
                let slider = self.slider_grown.placed(q);
                path_among(s0, s1, region, &self.grown, graph, &slider)?
            }
        };
        let (c0, _) = leg0.at(p, q)?;
        let (c1, _) = leg1.at(p, q)?;
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

/// A transit path from contact `from` to contact `to` with the slider at `q`, or `None`.
/// (A search asking for many builds [`Transits`] once.)
pub fn transit(p: &Problem, q: &Pose, from: usize, to: usize, _tag: u32) -> Option<TransitPath> {
    Transits::new(p).path(p, q, from, to)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::stable::random_scene::{RandomPusher, random_scene};
    use rand::{Rng, SeedableRng};
    use visibility::{Grown, disk_path_in};

    #[test]
    fn a_transit_exists_exactly_when_the_full_search_finds_one_and_is_as_short() {
        // Random car scenes, random slider poses, every pair of contacts: `path` against the
        // incremental search over all obstacles and the slider (as transits were found before
        // the ways round the slider and the obstacles' graph), and `any_path` against `path`.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let (mut some, mut none) = (0, 0);
        for seed in [11, 22, 49] {
            let p = random_scene(seed, RandomPusher::Car)
                .unwrap()
                .problem()
                .unwrap();
            let t = Transits::new(&p);
            let region = table_region(p.world.table, t.r);
            for _ in 0..60 {
                let q = Pose {
                    x: rng.random_range(0.0..p.world.table.0),
                    y: rng.random_range(0.0..p.world.table.1),
                    theta: rng.random_range(-3.2..3.2),
                };
                for (from, to) in (0..p.contacts.len())
                    .flat_map(|a| (0..p.contacts.len()).map(move |b| (a, b)))
                    .filter(|(a, b)| a != b)
                {
                    let fast = t.path(&p, &q, from, to);
                    let any = t.any_path(&p, &q, from, to);
                    assert_eq!(fast.is_some(), any.is_some());
                    let legs = t.legs[from].as_ref().zip(t.legs[to].as_ref());
                    let reference = legs.and_then(|(l0, l1)| {
                        let (c0, s0) = l0.at(&p, &q)?;
                        let (c1, s1) = l1.at(&p, &q)?;
                        let mut all = t.grown.clone();
                        all.push(t.slider_grown.placed(&q));
                        let mut boxes = t.boxes.clone();
                        let hull: Vec<V2> = p.slider.vertices.iter().map(|v| q.apply(*v)).collect();
                        boxes.push(reach_box(&hull, t.r));
                        let mut grown = Grown {
                            fixed: &all,
                            raw: &[],
                            lazy: vec![],
                            r: t.r,
                        };
                        let mid = disk_path_in(s0, s1, region, &boxes, &mut grown)?;
                        let mut pts = vec![c0];
                        pts.extend(mid);
                        pts.push(c1);
                        Some(pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum::<f64>())
                    });
                    match (&fast, reference) {
                        (Some(a), Some(b)) => {
                            some += 1;
                            assert!((a.length - b).abs() < 1e-9, "{} vs {b}", a.length);
                            assert!(any.unwrap().length >= a.length - 1e-9);
                        }
                        (None, None) => none += 1,
                        (a, b) => panic!("seed {seed} {q:?} {from}->{to}: {a:?} vs {b:?}"),
                    }
                }
            }
        }
        assert!(some > 100 && none > 100, "{some} found, {none} none");
    }
}

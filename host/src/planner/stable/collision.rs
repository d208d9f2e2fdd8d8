//! Exact collision of pusher + slider (`PS`, Lynch & Mason 1996 §4.2.1) against polygonal
//! obstacles and the table walls, checked along each push step, not only at its end.
//!
//! The paper grows a bounding disk of `PS` by the step length and checks only the step's end.
//! Here `PS` is its real polygons (parry2d-f64 convex polygons) and a step — a constant twist in the
//! slider frame, i.e. a rotation about a fixed centre or a translation — is checked by
//! *conservative advancement*: at time `t` the distance `d` from `PS(t)` to the obstacles is
//! measured, and no point of `PS` moves farther than `D·Δt` in `Δt` (`D` = largest arc length
//! of any vertex over the step), so `PS` cannot touch anything before `t + d/D`. Touching counts
//! as collision (obstacles are closed).

use parry2d_f64::math::{Pose as PPose, Vector as PVec};
use parry2d_f64::query;
use parry2d_f64::shape::{ConvexPolygon, TriMesh};
use parry2d_f64::transformation::hertel_mehlhorn;

use super::Pose;
use crate::mechanics::{V2, V3, convex_hull};

/// Clearance below which two shapes count as touching (m).
pub const CONTACT_EPS: f64 = 1e-5;

/// A convex polygon as a parry shape with its bounding box.
#[derive(Clone)]
pub struct Obstacle {
    shape: ConvexPolygon,
    sat: Sat,
    /// Axis-aligned bounds `[xmin, ymin, xmax, ymax]`.
    pub bounds: [f64; 4],
    /// Vertices (counter-clockwise) for drawing and transit planning.
    pub vertices: Vec<V2>,
}

impl std::fmt::Debug for Obstacle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Obstacle")
            .field("vertices", &self.vertices)
            .finish()
    }
}

/// Convert a point list to a parry convex polygon (the convex hull of the points).
pub fn convex(points: &[V2]) -> Option<ConvexPolygon> {
    let pts: Vec<PVec> = points.iter().map(|p| PVec::new(p.x, p.y)).collect();
    ConvexPolygon::from_convex_hull(&pts)
}

impl Obstacle {
    /// A simple polygon (either sense, convex or not) as exact convex obstacles: itself when
    /// convex, else its convex parts (triangulated by ear clipping and merged by
    /// Hertel–Mehlhorn, parry's `hertel_mehlhorn`), never its hull. `None` if degenerate or
    /// not simple.
    pub fn parts(points: &[V2]) -> Option<Vec<Obstacle>> {
        let mut pts = points.to_vec();
        if crate::mechanics::signed_area(&pts) < 0.0 {
            pts.reverse();
        }
        let n = pts.len();
        let convex = (0..n).all(|i| {
            let (a, b, c) = (pts[i], pts[(i + 1) % n], pts[(i + 2) % n]);
            let (e, f) = (b - a, c - b);
            e.x * f.y - e.y * f.x >= -1e-12 * e.norm() * f.norm()
        });
        if convex {
            return Some(vec![Obstacle::new(&pts)?]);
        }
        let mesh = TriMesh::from_polygon(pts.iter().map(|p| PVec::new(p.x, p.y)).collect())?;
        let parts: Vec<Obstacle> = hertel_mehlhorn(mesh.vertices(), mesh.indices())
            .iter()
            .filter_map(|part| {
                Obstacle::new(&part.iter().map(|q| V2::new(q.x, q.y)).collect::<Vec<_>>())
            })
            .collect();
        (!parts.is_empty()).then_some(parts)
    }

    /// The parry shape.
    pub fn shape(&self) -> &ConvexPolygon {
        &self.shape
    }

    /// An obstacle from the convex hull of `points`; `None` if degenerate.
    pub fn new(points: &[V2]) -> Option<Self> {
        let vertices = convex_hull(points);
        let shape = convex(&vertices)?;
        let xs = vertices.iter().map(|p| p.x);
        let ys = vertices.iter().map(|p| p.y);
        let bounds = [
            xs.clone().fold(f64::INFINITY, f64::min),
            ys.clone().fold(f64::INFINITY, f64::min),
            xs.fold(f64::NEG_INFINITY, f64::max),
            ys.fold(f64::NEG_INFINITY, f64::max),
        ];
        Some(Obstacle {
            shape,
            sat: Sat::new(&vertices),
            bounds,
            vertices,
        })
    }
}

/// A convex polygon prepared for the separating-axis test: counter-clockwise vertices, the
/// outward unit normal of each edge and the edge's offset along it (`n·v ≤ offset` inside).
#[derive(Clone, Debug)]
struct Sat {
    pts: Vec<V2>,
    normals: Vec<V2>,
    offsets: Vec<f64>,
}

/// A rigid placement `(x, y, sin θ, cos θ)`: the local frame's origin and rotation.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Origin x.
    pub x: f64,
    /// Origin y.
    pub y: f64,
    /// sin θ.
    pub s: f64,
    /// cos θ.
    pub c: f64,
}

impl Frame {
    /// The frame of a configuration.
    pub fn of(q: &Pose) -> Self {
        let (s, c) = q.theta.sin_cos();
        Frame {
            x: q.x,
            y: q.y,
            s,
            c,
        }
    }

    /// A local point in the world frame.
    fn apply(&self, p: V2) -> V2 {
        V2::new(
            self.x + self.c * p.x - self.s * p.y,
            self.y + self.s * p.x + self.c * p.y,
        )
    }
}

impl Sat {
    /// From the counter-clockwise vertices of a convex polygon (a [`convex_hull`]).
    fn new(hull: &[V2]) -> Self {
        let n = hull.len();
        let mut normals = Vec::with_capacity(n);
        let mut offsets = Vec::with_capacity(n);
        for i in 0..n {
            let (a, b) = (hull[i], hull[(i + 1) % n]);
            let e = b - a;
            let len = e.norm();
            let nrm = if len > 0.0 {
                V2::new(e.y / len, -e.x / len)
            } else {
                V2::zeros()
            };
            normals.push(nrm);
            // The largest projection, not just the edge's own: robust to nearly collinear
            // vertices, and a separating test on it stays exact.
            offsets.push(
                hull.iter()
                    .map(|v| nrm.dot(v))
                    .fold(f64::NEG_INFINITY, f64::max),
            );
        }
        Sat {
            pts: hull.to_vec(),
            normals,
            offsets,
        }
    }

    /// Whether this polygon, placed by `f`, is farther than `margin` from `o` (world frame)
    /// along one of the edge normals of either polygon: then the polygon grown by a disk of
    /// radius `margin` misses `o`. (Conservative: a gap only along another direction counts
    /// as no gap.)
    fn separated_by(&self, f: &Frame, o: &Sat, margin: f64) -> bool {
        for (n, &off) in o.normals.iter().zip(&o.offsets) {
            let nl = V2::new(f.c * n.x + f.s * n.y, -f.s * n.x + f.c * n.y);
            let off_l = off - (n.x * f.x + n.y * f.y) + margin;
            if self.pts.iter().all(|p| nl.dot(p) > off_l) {
                return true;
            }
        }
        for (n, &off) in self.normals.iter().zip(&self.offsets) {
            let nw = V2::new(f.c * n.x - f.s * n.y, f.s * n.x + f.c * n.y);
            let off_w = off + (nw.x * f.x + nw.y * f.y) + margin;
            if o.pts.iter().all(|p| nw.dot(p) > off_w) {
                return true;
            }
        }
        false
    }

    /// Whether this polygon, placed by `f`, overlaps `o` (world frame); touching overlaps.
    /// Exact separating-axis test over the edge normals of both polygons.
    fn overlaps(&self, f: &Frame, o: &Sat) -> bool {
        // Axes of the obstacle, in the local frame: separated if every local vertex lies
        // beyond the obstacle's edge.
        for (n, &off) in o.normals.iter().zip(&o.offsets) {
            let nl = V2::new(f.c * n.x + f.s * n.y, -f.s * n.x + f.c * n.y);
            let off_l = off - (n.x * f.x + n.y * f.y);
            if self.pts.iter().all(|p| nl.dot(p) > off_l) {
                return false;
            }
        }
        // Axes of this polygon, in the world frame.
        for (n, &off) in self.normals.iter().zip(&self.offsets) {
            let nw = V2::new(f.c * n.x - f.s * n.y, f.s * n.x + f.c * n.y);
            let off_w = off + (nw.x * f.x + nw.y * f.y);
            if o.pts.iter().all(|p| nw.dot(p) > off_w) {
                return false;
            }
        }
        true
    }
}

/// The static world: table walls and obstacles.
#[derive(Debug, Clone)]
pub struct World {
    /// Table size `(width, height)`; the free table is `(0, w) × (0, h)`.
    pub table: (f64, f64),
    /// Obstacles, including the four walls.
    pub obstacles: Vec<Obstacle>,
    /// How many leading entries of `obstacles` are walls.
    pub n_walls: usize,
    /// What each entry of `obstacles` is, as the scene names it (`obstacles[2]`, `object box`,
    /// `the left wall`): the parts of one scene obstacle share its name.
    pub names: Vec<String>,
}

impl World {
    /// A world with walls around a `w × h` table and the given convex obstacles.
    pub fn new(w: f64, h: f64, obstacles: Vec<Obstacle>) -> Self {
        let t = 1.0 + w.max(h);
        let rect = |x0: f64, y0: f64, x1: f64, y1: f64| {
            Obstacle::new(&[
                V2::new(x0, y0),
                V2::new(x1, y0),
                V2::new(x1, y1),
                V2::new(x0, y1),
            ])
            .expect("wall rectangle is not degenerate")
        };
        let mut all = vec![
            rect(-t, -t, w + t, 0.0),
            rect(-t, h, w + t, h + t),
            rect(-t, 0.0, 0.0, h),
            rect(w, 0.0, w + t, h),
        ];
        let mut names: Vec<String> = [
            "the table's bottom edge (y = 0)",
            "the table's top edge",
            "the table's left edge (x = 0)",
            "the table's right edge",
        ]
        .map(String::from)
        .to_vec();
        names.extend((0..obstacles.len()).map(|i| format!("obstacle part {i}")));
        all.extend(obstacles);
        World {
            table: (w, h),
            obstacles: all,
            n_walls: 4,
            names,
        }
    }

    /// This world with only the obstacles (walls among them) whose index `keep` accepts.
    pub fn only(&self, keep: impl Fn(usize) -> bool) -> World {
        let (mut obstacles, mut names) = (Vec::new(), Vec::new());
        let mut n_walls = 0;
        for (i, o) in self.obstacles.iter().enumerate() {
            if keep(i) {
                obstacles.push(o.clone());
                names.push(self.names[i].clone());
                n_walls += usize::from(i < self.n_walls);
            }
        }
        World {
            table: self.table,
            obstacles,
            n_walls,
            names,
        }
    }

    /// The distinct names of the obstacles `indices`, in order of first appearance.
    pub fn names_of(&self, indices: impl IntoIterator<Item = usize>) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        for i in indices {
            if let Some(n) = self.names.get(i)
                && !out.contains(n)
            {
                out.push(n.clone());
            }
        }
        out
    }
}

/// Largest rotation between two samples of a swept shape (rad).
const SWEPT_SAMPLE_ANGLE: f64 = 0.1;

/// Pieces a step is cut into when its whole swept shape touches an obstacle.
const SWEPT_PIECES: usize = 4;

/// A conservative cover of what a [`Body`] sweeps over part of a step: per body part, the
/// convex hull of the part at sampled poses, to be kept farther than `margin` (the largest
/// sagitta of the arcs between samples and a small margin) from every obstacle.
#[derive(Clone)]
struct Cover {
    parts: Vec<Sat>,
    margin: f64,
    /// Centre of a disk holding all parts grown by `margin` (slider frame at the step's start).
    centre: V2,
    /// Radius of that disk.
    radius: f64,
}

impl Cover {
    /// The cover of `body` over the motion `exp(t·xi)`, `t ∈ [t0, t1]`, from the slider
    /// frame's identity pose.
    fn new(body: &Body, xi: &V3, t0: f64, t1: f64) -> Self {
        let phi = xi.z.abs() * (t1 - t0);
        let (k, sag) = match super::cor_of(xi) {
            Some(c) => {
                let k = (phi / SWEPT_SAMPLE_ANGLE).ceil().max(1.0);
                let rho = body
                    .vertices
                    .iter()
                    .map(|v| (v - c).norm())
                    .fold(0.0, f64::max);
                (k as usize, rho * (1.0 - (phi / (2.0 * k)).cos()))
            }
            None => (1, 0.0),
        };
        // Arcs bulge beyond their chords by at most the sagitta; the margin on top makes "the
        // grown hull misses every obstacle" imply "clearance > CONTACT_EPS all along".
        let margin = sag + 3.0 * CONTACT_EPS;
        let mut parts = Vec::new();
        let mut all = Vec::new();
        for pts in &body.part_points {
            let mut cloud = Vec::with_capacity(pts.len() * (k + 1));
            for i in 0..=k {
                let t = t0 + (t1 - t0) * (i as f64 / k as f64);
                let pose = Pose::new(0.0, 0.0, 0.0).integrate(&(xi * t));
                cloud.extend(pts.iter().map(|p| pose.apply(*p)));
            }
            let hull = convex_hull(&cloud);
            if convex(&hull).is_some() {
                parts.push(Sat::new(&hull));
                all.extend(hull);
            }
        }
        let (mut lo, mut hi) = (V2::repeat(f64::INFINITY), V2::repeat(f64::NEG_INFINITY));
        for p in &all {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let centre = (lo + hi) / 2.0;
        let radius = all.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max) + margin;
        Cover {
            parts,
            margin,
            centre,
            radius,
        }
    }

    /// Whether the cover, placed by `f`, may touch an obstacle (`false`: it surely misses
    /// them all by more than its margin). A bounding disk against each obstacle's box first.
    fn hits(&self, world: &World, f: &Frame) -> bool {
        let c = f.apply(self.centre);
        let r2 = self.radius * self.radius;
        world.obstacles.iter().any(|o| {
            let b = o.bounds;
            let dx = (b[0] - c.x).max(c.x - b[2]).max(0.0);
            let dy = (b[1] - c.y).max(c.y - b[3]).max(0.0);
            dx * dx + dy * dy <= r2
                && self
                    .parts
                    .iter()
                    .any(|part| !part.separated_by(f, &o.sat, self.margin))
        })
    }
}

/// A conservative swept shape, precomputed once per control: the region a [`Body`] covers
/// while it follows a constant slider-frame twist from the slider frame's identity pose, as
/// convex parts (one per body part: the hull of the part at sampled poses, kept a margin of the
/// largest sagitta of the arcs between samples and a little more from the obstacles). Placed at
/// a configuration `q` it contains everything the body touches during the step from `q`, so one
/// static test replaces the sweep when it misses. When it does not, the same covers of
/// `SWEPT_PIECES` pieces of the step (and the poses between them) are tried before the sweep.
#[derive(Clone)]
pub struct Swept {
    whole: Cover,
    /// The pieces' covers, each with the pose at its end (`x`, `y`, `sin`, `cos`, slider frame
    /// at the step's start).
    pieces: Vec<(Cover, [f64; 4])>,
    /// Centre of a disk holding all parts (slider frame).
    pub centre: V2,
    /// Radius of that disk.
    pub radius: f64,
}

impl std::fmt::Debug for Swept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Swept")
            .field("centre", &self.centre)
            .field("radius", &self.radius)
            .finish()
    }
}

/// A rigid body moving with the slider: convex parts in the slider frame.
#[derive(Clone)]
pub struct Body {
    parts: Vec<ConvexPolygon>,
    /// The parts' convex hulls for the separating-axis test.
    sats: Vec<Sat>,
    /// The points of each part (slider frame).
    part_points: Vec<Vec<V2>>,
    /// All vertices of all parts (slider frame).
    pub vertices: Vec<V2>,
    /// Largest distance of a vertex from the slider frame's origin.
    pub radius: f64,
}

impl std::fmt::Debug for Body {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Body")
            .field("vertices", &self.vertices)
            .finish()
    }
}

impl Body {
    /// A body from convex parts (each given by its points); degenerate parts are skipped.
    pub fn new(parts: &[Vec<V2>]) -> Self {
        let mut shapes = Vec::new();
        let mut vertices = Vec::new();
        let mut part_points = Vec::new();
        let mut sats = Vec::new();
        for p in parts {
            if let Some(s) = convex(p) {
                shapes.push(s);
                sats.push(Sat::new(&convex_hull(p)));
                vertices.extend(p.iter().copied());
                part_points.push(p.clone());
            }
        }
        let radius = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        Body {
            parts: shapes,
            sats,
            part_points,
            vertices,
            radius,
        }
    }

    /// Smallest distance from the body at `q` to any obstacle whose box is within `reach` of
    /// `q`'s origin (`f64::INFINITY` if none).
    pub fn clearance(&self, world: &World, q: &Pose, reach: f64) -> f64 {
        let pose = PPose::new(PVec::new(q.x, q.y), q.theta);
        let r = self.radius + reach;
        let mut best = f64::INFINITY;
        for o in &world.obstacles {
            let b = o.bounds;
            // Distance from the origin to the box; the body lies within `radius` of it.
            let dx = (b[0] - q.x).max(q.x - b[2]).max(0.0);
            let dy = (b[1] - q.y).max(q.y - b[3]).max(0.0);
            let box_d = (dx * dx + dy * dy).sqrt();
            if box_d > r || box_d - self.radius >= best {
                continue;
            }
            for part in &self.parts {
                let d = query::distance(&pose, part, &PPose::identity(), &o.shape)
                    .map(|d| d.distance)
                    .unwrap_or(0.0);
                best = best.min(d);
                if best <= CONTACT_EPS {
                    return best;
                }
            }
        }
        best
    }

    /// The swept shape of this body under the slider-frame motion `xi` (see [`Swept`]).
    pub fn swept(&self, xi: &V3) -> Swept {
        let whole = Cover::new(self, xi, 0.0, 1.0);
        let n = SWEPT_PIECES;
        let pieces = (0..n)
            .map(|i| {
                let (t0, t1) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
                let end = Pose::new(0.0, 0.0, 0.0).integrate(&(xi * t1));
                let (s, c) = end.theta.sin_cos();
                (Cover::new(self, xi, t0, t1), [end.x, end.y, s, c])
            })
            .collect();
        Swept {
            centre: whole.centre,
            radius: whole.radius,
            whole,
            pieces,
        }
    }

    /// As [`Body::step_free`], deciding most steps with one static test of the precomputed
    /// swept shape `sw` of `xi`: if it misses every obstacle the step is free; else if the body
    /// overlaps or touches an obstacle at the step's end the step is not; else the same test on
    /// the step's pieces (free if all miss, not free if the body overlaps an obstacle where a
    /// piece that does not miss ends); else conservative advancement decides. The answer is the
    /// same as [`Body::step_free`]'s: a cover that misses keeps the body more than
    /// `CONTACT_EPS` clear, and conservative advancement stops at any overlap.
    pub fn step_free_swept(&self, world: &World, q: &Pose, xi: &V3, sw: &Swept) -> bool {
        let end = q.integrate(xi);
        let sc = end.theta.sin_cos();
        self.step_free_swept_in(world, q, &Frame::of(q), xi, sw, &end, sc)
    }

    /// [`Body::step_free_swept`] given the frame of `q` (shared by all steps from `q`), the
    /// step's end `end` and its `(sin θ, cos θ)`. The static tests are exact separating-axis
    /// tests on the convex parts, with a bounding disk against each obstacle's box first.
    #[allow(clippy::too_many_arguments)]
    pub fn step_free_swept_in(
        &self,
        world: &World,
        q: &Pose,
        f: &Frame,
        xi: &V3,
        sw: &Swept,
        end: &Pose,
        (se, ce): (f64, f64),
    ) -> bool {
        if !sw.whole.hits(world, f) {
            return true;
        }
        let fe = Frame {
            x: end.x,
            y: end.y,
            s: se,
            c: ce,
        };
        if self.overlaps_in(world, &fe) || !self.free_at(world, end) {
            return false;
        }
        // The pieces: free if every piece's cover misses; not free if the body overlaps an
        // obstacle between two pieces (conservative advancement would stop there too).
        let mut missed = true;
        for (i, (cover, [x, y, s, c])) in sw.pieces.iter().enumerate() {
            if !cover.hits(world, f) {
                continue;
            }
            missed = false;
            if i + 1 < sw.pieces.len() {
                let fi = Frame {
                    x: f.x + f.c * x - f.s * y,
                    y: f.y + f.s * x + f.c * y,
                    s: f.s * c + f.c * s,
                    c: f.c * c - f.s * s,
                };
                if self.overlaps_in(world, &fi) {
                    return false;
                }
            }
        }
        if missed {
            return true;
        }
        self.step_free_from(world, q, xi, None)
    }

    /// Whether the body at `q` overlaps or touches an obstacle (exact, no clearance margin).
    pub fn overlaps_at(&self, world: &World, q: &Pose) -> bool {
        self.overlaps_in(world, &Frame::of(q))
    }

    /// [`Body::overlaps_at`] for the placement `f`.
    fn overlaps_in(&self, world: &World, f: &Frame) -> bool {
        world.obstacles.iter().any(|o| {
            let b = o.bounds;
            let dx = (b[0] - f.x).max(f.x - b[2]).max(0.0);
            let dy = (b[1] - f.y).max(f.y - b[3]).max(0.0);
            dx * dx + dy * dy <= self.radius * self.radius
                && self.sats.iter().any(|part| part.overlaps(f, &o.sat))
        })
    }

    /// Whether the body is free at `q`.
    pub fn free_at(&self, world: &World, q: &Pose) -> bool {
        self.clearance(world, q, 0.0) > CONTACT_EPS
    }

    /// Whether the body is free along the whole motion from `q` under slider-frame twist
    /// `xi` (not unit: `xi` integrated over unit time), by conservative advancement.
    pub fn step_free(&self, world: &World, q: &Pose, xi: &V3) -> bool {
        self.step_free_from(world, q, xi, None)
    }

    /// Largest arc length of any body point over the motion `xi`.
    pub fn reach(&self, xi: &V3) -> f64 {
        match super::cor_of(xi) {
            Some(c) => {
                let rho = self
                    .vertices
                    .iter()
                    .map(|v| (v - c).norm())
                    .fold(0.0, f64::max);
                rho * xi.z.abs()
            }
            None => (xi.x * xi.x + xi.y * xi.y).sqrt(),
        }
    }

    /// As [`Body::step_free`], given (optionally) the clearance at `q` already measured with
    /// a broad phase of at least this step's reach.
    pub fn step_free_from(
        &self,
        world: &World,
        q: &Pose,
        xi: &V3,
        start_clearance: Option<f64>,
    ) -> bool {
        let reach = self.reach(xi);
        if reach <= 0.0 {
            return self.free_at(world, q);
        }
        let mut t = 0.0;
        let mut first = start_clearance;
        loop {
            let d = match first.take() {
                Some(d) => d,
                None => self.clearance(
                    world,
                    &q.integrate(&(xi * t)),
                    reach * (1.0 - t) + CONTACT_EPS,
                ),
            };
            if d <= CONTACT_EPS {
                return false;
            }
            // Nothing can close the remaining gap before the step ends.
            if t >= 1.0 || d - reach * (1.0 - t) > CONTACT_EPS {
                return true;
            }
            // d is a lower bound only for obstacles inside the broad phase; those outside are
            // farther than the remaining reach anyway.
            t = (t + d / reach).min(1.0);
        }
    }
}

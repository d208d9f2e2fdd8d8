//! Shapes, contact points and overlap tests, from `parry2d` (its `f64` build, `parry2d-f64`,
//! the same version the host uses in `f32`): every body of the world is a set of convex parts
//! (balls and convex polygons); a non-convex outline is split into convex parts by ear-clipping
//! triangulation and Hertel–Mehlhorn merging (both parry's), and contact manifolds between
//! parts come from parry's contact-manifold queries, which give two points for a face-to-face
//! (line) contact and one otherwise.

use parry2d_f64::math::{Pose as PPose, Vector};
use parry2d_f64::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry2d_f64::shape::{Ball, ConvexPolygon, HalfSpace, Shape, ShapeType, SharedShape, TriMesh};
use parry2d_f64::transformation::hertel_mehlhorn;

use crate::pose::Pose;

/// A rigid outline made of convex parts, in its own frame.
#[derive(Clone)]
pub struct Outline {
    parts: Vec<(PPose, SharedShape)>,
    /// Each part's bound in the outline's frame.
    bounds: Vec<PartBound>,
    /// Radius of a circle about the frame's origin that holds the whole outline.
    radius: f64,
}

/// Where a part lies in its outline's frame, for skipping part pairs that cannot touch.
#[derive(Clone, Copy, Debug)]
enum PartBound {
    /// A circle (centre, radius) that holds the part.
    Circle(Vector, f64),
    /// A half-plane through this point with this outward normal.
    Plane(Vector, Vector),
}

impl PartBound {
    /// The bound of `shape` placed at `at` in its outline's frame.
    fn of(at: &PPose, shape: &SharedShape) -> PartBound {
        if let Some(h) = shape.as_halfspace() {
            return PartBound::Plane(at.translation, at.transform_vector(h.normal));
        }
        let b = shape.compute_local_bounding_sphere();
        PartBound::Circle(at.transform_point(b.center()), b.radius())
    }

    /// The bound in the table frame, its outline at `w`.
    fn at(self, w: &PPose) -> PartBound {
        match self {
            PartBound::Circle(c, r) => PartBound::Circle(w.transform_point(c), r),
            PartBound::Plane(o, n) => PartBound::Plane(w.transform_point(o), w.transform_vector(n)),
        }
    }
}

/// Whether two parts with bounds `a` and `b` (table frame) are farther apart than
/// `prediction`: then none of their contacts can be closer than it, and the pair is skipped.
/// Exact: it only skips pairs whose bounding circles (or circle and half-plane) are apart by
/// more than `prediction`.
fn apart(a: PartBound, b: PartBound, prediction: f64) -> bool {
    // Margin against rounding in the parts' poses, m.
    const EPS: f64 = 1e-9;
    match (a, b) {
        (PartBound::Circle(ca, ra), PartBound::Circle(cb, rb)) => {
            let reach = ra + rb + prediction + EPS;
            (cb - ca).length_squared() > reach * reach
        }
        (PartBound::Plane(o, n), PartBound::Circle(c, r))
        | (PartBound::Circle(c, r), PartBound::Plane(o, n)) => n.dot(c - o) > r + prediction + EPS,
        (PartBound::Plane(..), PartBound::Plane(..)) => false,
    }
}

impl std::fmt::Debug for Outline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Outline {{ {} parts, radius {} }}",
            self.parts.len(),
            self.radius
        )
    }
}

/// One contact point between two outlines (table frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    /// Point on the first outline.
    pub pa: [f64; 2],
    /// Point on the second outline.
    pub pb: [f64; 2],
    /// Unit normal from the first outline towards the second.
    pub normal: [f64; 2],
    /// Signed distance along the normal (negative: penetrating).
    pub dist: f64,
    /// Which of the first outline's parts touches.
    pub part_a: usize,
}

fn v(p: [f64; 2]) -> Vector {
    Vector::new(p[0], p[1])
}

fn a(p: Vector) -> [f64; 2] {
    [p.x, p.y]
}

fn ppose(p: &Pose) -> PPose {
    PPose::new(Vector::new(p.x, p.y), p.theta)
}

pub use crate::polygon::{ShapeError, check_simple, signed_area};

/// Corner radius of polygon parts, m: each convex part is its polygon inset by this much with
/// its border rounded by as much (the same outline, corners rounded by 1 µm). With a border,
/// parry finds shallow overlaps (up to twice this) from the inner polygons' closest points,
/// which is robust, rather than from the penetration algorithm (EPA), which can miss contacts
/// that touch to within its tolerance.
pub const BORDER: f64 = 1e-6;

/// A convex polygon as an inset polygon with a rounded border of [`BORDER`] (the polygon as is
/// if it is too thin to inset).
fn rounded(c: ConvexPolygon) -> SharedShape {
    let (pts, normals) = (c.points(), c.normals());
    let n = pts.len();
    // parry's `ConvexPolygon::offsetted`, inwards: each vertex moves along the bisector.
    let inset: Vec<Vector> = (0..n)
        .map(|i2| {
            let i1 = (i2 + n - 1) % n;
            let dir = normals[i1] + normals[i2];
            pts[i2] - (BORDER / dir.dot(normals[i1])) * dir
        })
        .collect();
    // Usable if every inset edge keeps its direction (nothing flipped).
    let kept = (0..n).all(|i| {
        let (a, b) = (pts[(i + 1) % n] - pts[i], inset[(i + 1) % n] - inset[i]);
        a.dot(b) > 0.0 && b.length() > 0.0
    });
    if kept && let Some(s) = SharedShape::round_convex_polyline(inset, BORDER) {
        return s;
    }
    SharedShape::new(c)
}

/// Every turn is to the left, up to rounding (a 100 000-vertex circle turns by 63 µrad at each
/// vertex; its rounded coordinates make some turns a hair negative): a convex polygon, kept as
/// one part.
fn is_convex_ccw(pts: &[Vector]) -> bool {
    let n = pts.len();
    (0..n).all(|i| {
        let (p, q, r) = (pts[i], pts[(i + 1) % n], pts[(i + 2) % n]);
        let (e, f) = (q - p, r - q);
        e.perp_dot(f) >= -1e-9 * e.length() * f.length()
    })
}

impl Outline {
    fn of_parts(parts: Vec<(PPose, SharedShape)>, radius: f64) -> Outline {
        let bounds = parts.iter().map(|(at, s)| PartBound::of(at, s)).collect();
        Outline {
            parts,
            bounds,
            radius,
        }
    }

    /// A polygon (either sense, convex or not, but simple), split into convex parts.
    pub fn polygon(outline: &[[f64; 2]]) -> Result<Outline, ShapeError> {
        check_simple(outline)?;
        let mut pts: Vec<Vector> = outline.iter().map(|p| v(*p)).collect();
        if signed_area(outline) < 0.0 {
            pts.reverse();
        }
        let radius = pts.iter().map(|p| p.length()).fold(0.0, f64::max);
        let polys = if is_convex_ccw(&pts) {
            vec![pts]
        } else {
            let mesh = TriMesh::from_polygon(pts).ok_or(ShapeError::Decomposition)?;
            hertel_mehlhorn(mesh.vertices(), mesh.indices())
        };
        let parts = polys
            .into_iter()
            .map(|p| {
                // parry merges edges whose normals differ by less than ~1.7e-4 rad and gives
                // up when that leaves < 3 vertices (a fine circle): keep those as they are.
                ConvexPolygon::from_convex_polyline(p.clone())
                    .or_else(|| ConvexPolygon::from_convex_polyline_unmodified(p))
                    .map(|c| (PPose::IDENTITY, rounded(c)))
                    .ok_or(ShapeError::Decomposition)
            })
            .collect::<Result<Vec<_>, _>>()?;
        if parts.is_empty() {
            return Err(ShapeError::Decomposition);
        }
        Ok(Outline::of_parts(parts, radius))
    }

    /// A disc of radius `r` centred on the frame's origin.
    pub fn disc(r: f64) -> Outline {
        Outline::of_parts(vec![(PPose::IDENTITY, SharedShape::new(Ball::new(r)))], r)
    }

    /// The half-plane `{p : normal·p ≤ 0}` (a wall; `normal` points out of it).
    pub fn half_plane(normal: [f64; 2]) -> Outline {
        let n = v(normal).normalize();
        Outline::of_parts(
            vec![(PPose::IDENTITY, SharedShape::new(HalfSpace::new(n)))],
            f64::INFINITY,
        )
    }

    /// Add a convex part (the vertices must be convex; either sense).
    pub fn with_convex_part(mut self, outline: &[[f64; 2]]) -> Result<Outline, ShapeError> {
        let extra = Outline::polygon(outline)?;
        self.radius = self.radius.max(extra.radius);
        self.parts.extend(extra.parts);
        self.bounds.extend(extra.bounds);
        Ok(self)
    }

    /// Number of convex parts.
    pub fn parts(&self) -> usize {
        self.parts.len()
    }

    /// Radius of a circle about the origin that holds the outline.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Contacts between `self` at `pa` and `other` at `pb`, closer than `prediction` (m).
    /// Appends to `out`.
    pub fn contacts(
        &self,
        pa: &Pose,
        other: &Outline,
        pb: &Pose,
        prediction: f64,
        out: &mut Vec<ContactPoint>,
    ) {
        let dx = pb.x - pa.x;
        let dy = pb.y - pa.y;
        let reach = self.radius + other.radius + prediction;
        if dx * dx + dy * dy > reach * reach {
            return;
        }
        let (wa, wb) = (ppose(pa), ppose(pb));
        let dispatcher = DefaultQueryDispatcher;
        for (ia, ((la, sa), &ba)) in self.parts.iter().zip(&self.bounds).enumerate() {
            let posa = wa * *la;
            let ba = ba.at(&wa);
            for ((lb, sb), &bb) in other.parts.iter().zip(&other.bounds) {
                if apart(ba, bb.at(&wb), prediction) {
                    continue;
                }
                let posb = wb * *lb;
                let pos12 = posa.inv_mul(&posb);
                let mut m: ContactManifold<(), ()> = ContactManifold::new();
                if dispatcher
                    .contact_manifold_convex_convex(
                        &pos12,
                        &**sa as &dyn Shape,
                        &**sb as &dyn Shape,
                        None,
                        None,
                        prediction,
                        &mut m,
                    )
                    .is_err()
                {
                    continue;
                }
                if m.points.is_empty() {
                    // parry's manifold can come back empty for shapes touching to within
                    // its GJK tolerance; the single-point contact query still answers
                    // (half-planes are exact, and not handled by it when second).
                    let plane = |s: &SharedShape| s.shape_type() == ShapeType::HalfSpace;
                    if plane(sa) || plane(sb) {
                        continue;
                    }
                    if let Ok(Some(c)) = parry2d_f64::query::contact(
                        &posa,
                        &**sa as &dyn Shape,
                        &posb,
                        &**sb as &dyn Shape,
                        prediction,
                    ) {
                        out.push(ContactPoint {
                            pa: a(c.point1),
                            pb: a(c.point2),
                            normal: a(c.normal1),
                            dist: c.dist,
                            part_a: ia,
                        });
                    }
                    continue;
                }
                let n = posa.transform_vector(m.local_n1);
                for c in &m.points {
                    if c.dist > prediction {
                        continue;
                    }
                    out.push(ContactPoint {
                        pa: a(posa.transform_point(c.local_p1)),
                        pb: a(posb.transform_point(c.local_p2)),
                        normal: a(n),
                        dist: c.dist,
                        part_a: ia,
                    });
                }
            }
        }
    }

    /// Whether `self` at `pa` and `other` at `pb` overlap by more than `tolerance` (m).
    pub fn overlaps(&self, pa: &Pose, other: &Outline, pb: &Pose, tolerance: f64) -> bool {
        let mut c = Vec::new();
        self.contacts(pa, other, pb, 0.0, &mut c);
        c.iter().any(|c| c.dist < -tolerance)
    }

    /// Penetration depth of `self` at `pa` into `other` at `pb` (0 when apart or touching).
    pub fn depth(&self, pa: &Pose, other: &Outline, pb: &Pose) -> f64 {
        let mut c = Vec::new();
        self.contacts(pa, other, pb, 0.0, &mut c);
        c.iter().map(|c| -c.dist).fold(0.0, f64::max)
    }

    /// Whether a table-frame point lies inside the outline placed at `pose`.
    pub fn contains(&self, pose: &Pose, p: [f64; 2]) -> bool {
        let w = ppose(pose);
        self.parts
            .iter()
            .any(|(l, s)| s.contains_point(&(w * *l), v(p)))
    }
}

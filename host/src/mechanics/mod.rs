//! Pushing mechanics after Lynch & Mason, "Stable Pushing: Mechanics, Controllability, and
//! Planning" (IJRR 1996), §2–3.
//!
//! Conventions of the paper (§1.3): the slider frame `F_S` has its origin at the slider's centre
//! of friction; a velocity direction is a unit twist `(v_x, v_y, ω)` in `F_S` (a point on the
//! *velocity sphere*); a force is `(f_x, f_y, m)` with the moment about the centre of friction.
//! The rotation centre of a twist is `COR(v) = (-v_y/ω, v_x/ω)` (a translation has its centre
//! at infinity).
//!
//! - [`stable`]: the procedure STABLE (§3.3.1) and the extremal stable directions (§4.1).
//! - [`controllability`]: Propositions 1, 2, 4, 5 and Theorems 2, 3, 5, 6, 7 (§2–3).
//! - [`limit_surface`]: the ellipsoidal limit-surface approximation used to map forces to
//!   velocity directions where a theorem needs one concrete bounded support distribution.

pub mod controllability;
pub mod limit_surface;
pub mod stable;

use nalgebra::{Vector2, Vector3};

/// A 2-D vector in the slider frame.
pub type V2 = Vector2<f64>;
/// A twist `(v_x, v_y, ω)` or a wrench `(f_x, f_y, m)` in the slider frame.
pub type V3 = Vector3<f64>;

/// Why a slider or a contact cannot be analysed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MechanicsError {
    /// Fewer than three vertices, zero area, or non-finite coordinates.
    #[error("slider polygon must have at least 3 finite vertices and nonzero area")]
    BadPolygon,
    /// The centre of friction is not strictly inside the slider's convex hull.
    #[error("centre of friction must lie strictly inside the slider")]
    CofOutside,
    /// The edge index is out of range.
    #[error("edge {0} does not exist (slider has {1} edges)")]
    NoSuchEdge(usize, usize),
    /// The edge is not an edge of the convex hull, so a straight pusher cannot lie on it.
    #[error("edge {0} is not on the convex hull of the slider")]
    NotHullEdge(usize),
    /// Friction coefficient negative or not finite.
    #[error("friction coefficient must be finite and >= 0, got {0}")]
    BadFriction(f64),
}

/// A polygonal slider, vertices counter-clockwise in the slider frame `F_S` (origin at the
/// centre of friction).
#[derive(Debug, Clone, PartialEq)]
pub struct Slider {
    /// Vertices, counter-clockwise, relative to the centre of friction.
    pub vertices: Vec<V2>,
}

impl Slider {
    /// A slider from its outline in an object frame and its centre of friction in that frame.
    /// The outline may be given in either orientation.
    pub fn new(outline: &[V2], centre_of_friction: V2) -> Result<Self, MechanicsError> {
        if outline.len() < 3
            || outline.iter().any(|p| !p.x.is_finite() || !p.y.is_finite())
            || !centre_of_friction.x.is_finite()
            || !centre_of_friction.y.is_finite()
        {
            return Err(MechanicsError::BadPolygon);
        }
        let mut vertices: Vec<V2> = outline.iter().map(|p| p - centre_of_friction).collect();
        let area = signed_area(&vertices);
        if area.abs() < 1e-12 {
            return Err(MechanicsError::BadPolygon);
        }
        if area < 0.0 {
            vertices.reverse();
        }
        let s = Slider { vertices };
        // The centre of friction is strictly inside the convex hull: every hull edge has the
        // origin strictly on its inner side.
        let hull = convex_hull(&s.vertices);
        for i in 0..hull.len() {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            if cross(b - a, -a) <= 1e-12 * (b - a).norm() {
                return Err(MechanicsError::CofOutside);
            }
        }
        Ok(s)
    }

    /// Number of edges (edge `i` runs from vertex `i` to vertex `i+1`).
    pub fn n_edges(&self) -> usize {
        self.vertices.len()
    }

    /// Edge `i` as its two end points, counter-clockwise.
    pub fn edge(&self, i: usize) -> Result<(V2, V2), MechanicsError> {
        let n = self.vertices.len();
        if i >= n {
            return Err(MechanicsError::NoSuchEdge(i, n));
        }
        Ok((self.vertices[i], self.vertices[(i + 1) % n]))
    }

    /// Distance from the centre of friction to the most distant support point (`r` of §3.3.1).
    pub fn radius(&self) -> f64 {
        self.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max)
    }

    /// The longest distance between two vertices (the "slider length" of §4.4).
    pub fn length(&self) -> f64 {
        let mut l: f64 = 0.0;
        for a in &self.vertices {
            for b in &self.vertices {
                l = l.max((a - b).norm());
            }
        }
        l
    }

    /// Whether edge `i` lies on the convex hull (the whole slider on its inner side).
    pub fn is_hull_edge(&self, i: usize) -> Result<bool, MechanicsError> {
        let (a, b) = self.edge(i)?;
        let len = (b - a).norm();
        Ok(self
            .vertices
            .iter()
            .all(|&v| cross(b - a, v - a) >= -1e-9 * len))
    }
}

/// A line contact (§3.3): a segment on a hull edge of the slider, pushed along the edge's inward
/// normal. Equivalent to two point contacts at its end points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineContact {
    /// Index of the slider edge the contact lies on.
    pub edge: usize,
    /// First end point (the edge's own direction runs from `a` to `b`).
    pub a: V2,
    /// Second end point.
    pub b: V2,
}

impl LineContact {
    /// The whole of edge `edge` as a line contact (a sufficiently long straight pusher).
    pub fn full_edge(slider: &Slider, edge: usize) -> Result<Self, MechanicsError> {
        let (a, b) = slider.edge(edge)?;
        if !slider.is_hull_edge(edge)? {
            return Err(MechanicsError::NotHullEdge(edge));
        }
        Ok(LineContact { edge, a, b })
    }

    /// Unit tangent from `a` to `b`: the x axis of the contact frame.
    pub fn tangent(&self) -> V2 {
        (self.b - self.a).normalize()
    }

    /// Unit inward normal (into the slider): the y axis of the contact frame.
    pub fn normal(&self) -> V2 {
        let t = self.tangent();
        V2::new(-t.y, t.x)
    }

    /// A slider-frame point in the contact frame (x along the edge, y along the inward normal).
    pub fn to_contact_frame(&self, p: V2) -> V2 {
        V2::new(self.tangent().dot(&p), self.normal().dot(&p))
    }

    /// A contact-frame twist (or constraint row) expressed in the slider frame.
    pub fn twist_to_slider(&self, v: V3) -> V3 {
        let xy = self.tangent() * v.x + self.normal() * v.y;
        V3::new(xy.x, xy.y, v.z)
    }

    /// A slider-frame twist in the contact frame.
    pub fn twist_to_contact(&self, v: V3) -> V3 {
        let p = self.to_contact_frame(V2::new(v.x, v.y));
        V3::new(p.x, p.y, v.z)
    }
}

/// The rotation centre of a twist in the slider frame, `None` for a translation.
pub fn cor(v: &V3) -> Option<V2> {
    if v.z.abs() < 1e-12 {
        None
    } else {
        Some(V2::new(-v.y / v.z, v.x / v.z))
    }
}

/// The unit twist of a rotation about `c` with sense `sign(omega)`.
pub fn twist_about(c: V2, omega: f64) -> V3 {
    V3::new(omega * c.y, -omega * c.x, omega).normalize()
}

/// 2-D cross product (z component).
pub fn cross(a: V2, b: V2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Signed area of a polygon (positive when counter-clockwise).
pub fn signed_area(p: &[V2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| cross(p[i], p[(i + 1) % n])).sum::<f64>() / 2.0
}

/// Area centroid of a simple polygon (the centre of friction of a uniform slider).
pub fn centroid(p: &[V2]) -> V2 {
    let n = p.len();
    let a = signed_area(p);
    if a.abs() < 1e-15 {
        return p.iter().sum::<V2>() / n.max(1) as f64;
    }
    let mut c = V2::zeros();
    for i in 0..n {
        let (u, w) = (p[i], p[(i + 1) % n]);
        c += (u + w) * cross(u, w);
    }
    c / (6.0 * a)
}

/// Convex hull (Andrew's monotone chain), counter-clockwise.
pub fn convex_hull(points: &[V2]) -> Vec<V2> {
    let mut p: Vec<V2> = points.to_vec();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup_by(|a, b| (*a - *b).norm() < 1e-12);
    if p.len() < 3 {
        return p;
    }
    let mut h: Vec<V2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = h.len();
        let iter: Box<dyn Iterator<Item = &V2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while h.len() >= start + 2
                && cross(h[h.len() - 1] - h[h.len() - 2], q - h[h.len() - 2]) <= 0.0
            {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

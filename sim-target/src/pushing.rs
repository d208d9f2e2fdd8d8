//! Quasi-static pushing of a slider by a point (or circular) pusher: the ellipsoidal
//! approximation of the limit surface (Lee & Cutkosky 1991; Lynch, Maekawa & Tanie 1992),
//! which Lynch & Mason (§3, "the motion of a pushed object") take as the support-friction model.
//! Distances and the inside test against the outline come from parry (`parry2d-f64`).
//!
//! The slider's support friction is summarised by its centre of friction (COF) and the limit
//! surface `H(f) = (fx² + fy²)/f_max² + m²/m_max² = 1` in the slider frame at the COF, with
//! `f_max = μ_s·m·g` and `m_max = μ_s·m·g·c`, `c` the mean distance of the support pressure
//! from the COF. A quasi-static slider moves with the twist normal to the limit surface at the
//! applied wrench: `v ∝ ∇H(f)`, i.e. `(vx, vy, ω) ∝ (fx, fy, m/c²)`.
//!
//! At a point contact with Coulomb friction μ_c, the pusher's force lies in the friction cone.
//! The two cone edges map to two contact-point velocities that bound the *motion cone*: a
//! pusher velocity inside it **sticks** (the contact point moves with the pusher; the closed
//! form is [`sticking_twist`]), outside it the contact **slides** and the force is on the cone
//! edge nearer the pusher's velocity, scaled so that the normal velocities match.

use parry2d_f64::math::Vector;
use parry2d_f64::query::PointQuery;
use parry2d_f64::shape::Polyline;
use parry2d_f64::utils::point_in_poly2d;

use crate::robot::{Pose, wrap_angle};

/// A planar twist in the slider frame at the COF: `(vx, vy)` m/s and `omega` rad/s.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Twist {
    /// Velocity of the COF along the slider's x axis.
    pub vx: f64,
    /// Velocity of the COF along the slider's y axis.
    pub vy: f64,
    /// Angular velocity, counter-clockwise.
    pub omega: f64,
}

impl Twist {
    /// Velocity of the body point `p` (slider frame, relative to the COF).
    pub fn point_velocity(&self, p: [f64; 2]) -> [f64; 2] {
        [self.vx - self.omega * p[1], self.vy + self.omega * p[0]]
    }
}

/// How the contact behaved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactMode {
    /// The pusher moves away from the slider (or along it): no force, no motion.
    Separating,
    /// The contact point moves with the pusher.
    Sticking,
    /// The pusher slides along the slider's edge.
    Sliding,
}

/// The slider twist for a sticking point push (Lynch, Maekawa & Tanie 1992): the contact
/// point `p` (slider frame, relative to the COF) moves with the pusher velocity `vp`.
pub fn sticking_twist(c: f64, p: [f64; 2], vp: [f64; 2]) -> Twist {
    let c2 = c * c;
    let (px, py) = (p[0], p[1]);
    let d = c2 + px * px + py * py;
    let vx = ((c2 + px * px) * vp[0] + px * py * vp[1]) / d;
    let vy = (px * py * vp[0] + (c2 + py * py) * vp[1]) / d;
    let omega = (px * vy - py * vx) / c2;
    Twist { vx, vy, omega }
}

/// The slider twist for a force `f` applied at `p` (up to scale): `∇H(f)`.
pub fn twist_for_force(c: f64, p: [f64; 2], f: [f64; 2]) -> Twist {
    let m = p[0] * f[1] - p[1] * f[0];
    Twist {
        vx: f[0],
        vy: f[1],
        omega: m / (c * c),
    }
}

/// 2-D cross product.
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn rotate(v: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// The slider twist for a pusher moving at `vp` (slider frame) that touches it at `p` with
/// inward unit normal `n` (pointing from the pusher into the slider) and friction `mu`.
pub fn point_push(c: f64, p: [f64; 2], n: [f64; 2], mu: f64, vp: [f64; 2]) -> (Twist, ContactMode) {
    let vn = dot(vp, n);
    if vn <= 0.0 {
        return (Twist::default(), ContactMode::Separating);
    }
    let half = mu.max(0.0).atan();
    // Friction cone edges: the normal turned by ±atan μ (left = counter-clockwise).
    let f_left = rotate(n, half);
    let f_right = rotate(n, -half);
    let v_left = twist_for_force(c, p, f_left).point_velocity(p);
    let v_right = twist_for_force(c, p, f_right).point_velocity(p);
    // Inside the motion cone (between v_right and v_left, counter-clockwise)?
    let inside = cross(v_right, vp) >= 0.0 && cross(vp, v_left) >= 0.0;
    if inside {
        return (sticking_twist(c, p, vp), ContactMode::Sticking);
    }
    // Sliding: the force is on the edge nearer vp; scale so the normal velocities agree.
    let (f, v_edge) = if cross(v_left, vp) > 0.0 {
        (f_left, v_left)
    } else {
        (f_right, v_right)
    };
    let k = vn / dot(v_edge, n);
    let t = twist_for_force(c, p, f);
    (
        Twist {
            vx: k * t.vx,
            vy: k * t.vy,
            omega: k * t.omega,
        },
        ContactMode::Sliding,
    )
}

/// The COF and the characteristic length `c` of a support distribution: for a uniform
/// pressure over a polygon, the area centroid and the mean distance from it (integrated on a
/// fine grid); for point supports, the weighted centroid and weighted mean distance.
pub fn friction_centre(support: &SupportShape<'_>) -> ([f64; 2], f64) {
    match support {
        SupportShape::Uniform(outline) => {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for v in outline.iter() {
                for k in 0..2 {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            const N: usize = 120;
            let mut pts = Vec::new();
            for i in 0..N {
                for j in 0..N {
                    let x = lo[0] + (hi[0] - lo[0]) * (i as f64 + 0.5) / N as f64;
                    let y = lo[1] + (hi[1] - lo[1]) * (j as f64 + 0.5) / N as f64;
                    if point_in_polygon([x, y], outline) {
                        pts.push([x, y]);
                    }
                }
            }
            weighted_centre(&pts, None)
        }
        SupportShape::Points(points, weights) => weighted_centre(points, *weights),
    }
}

/// A support distribution, borrowed from a scene object.
pub enum SupportShape<'a> {
    /// Uniform pressure over this outline.
    Uniform(&'a [[f64; 2]]),
    /// Point supports with optional weights.
    Points(&'a [[f64; 2]], Option<&'a [f64]>),
}

fn weighted_centre(pts: &[[f64; 2]], weights: Option<&[f64]>) -> ([f64; 2], f64) {
    let w = |i: usize| weights.and_then(|w| w.get(i).copied()).unwrap_or(1.0);
    let total: f64 = (0..pts.len()).map(w).sum();
    if pts.is_empty() || total <= 0.0 {
        return ([0.0, 0.0], 1e-3);
    }
    let mut cof = [0.0, 0.0];
    for (i, p) in pts.iter().enumerate() {
        cof[0] += w(i) * p[0] / total;
        cof[1] += w(i) * p[1] / total;
    }
    let c: f64 = pts
        .iter()
        .enumerate()
        .map(|(i, p)| w(i) * ((p[0] - cof[0]).powi(2) + (p[1] - cof[1]).powi(2)).sqrt())
        .sum::<f64>()
        / total;
    // A single support point has no moment arm: keep c small but positive.
    (cof, c.max(1e-4))
}

fn parry_vertices(outline: &[[f64; 2]]) -> Vec<Vector> {
    outline.iter().map(|v| Vector::new(v[0], v[1])).collect()
}

/// Whether `p` is inside the simple polygon `outline` (parry's winding-number test).
pub fn point_in_polygon(p: [f64; 2], outline: &[[f64; 2]]) -> bool {
    point_in_poly2d(Vector::new(p[0], p[1]), &parry_vertices(outline))
}

/// Closest point on the polygon's boundary to `p`, and the distance (parry's projection on the
/// closed polyline of the outline; `p` itself at infinite distance for an empty outline).
pub fn closest_boundary_point(p: [f64; 2], outline: &[[f64; 2]]) -> ([f64; 2], f64) {
    let n = outline.len() as u32;
    if n == 0 {
        return (p, f64::INFINITY);
    }
    let indices = (0..n).map(|i| [i, (i + 1) % n]).collect();
    let boundary = Polyline::new(parry_vertices(outline), Some(indices));
    let q = Vector::new(p[0], p[1]);
    let proj = boundary.project_local_point(q, false);
    ([proj.point.x, proj.point.y], (proj.point - q).length())
}

/// A pushable object in the plane: its outline in the object frame, where its COF is, its
/// limit surface's `c`, the pusher friction, and its pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Slider {
    /// Outline, object frame.
    pub outline: Vec<[f64; 2]>,
    /// COF, object frame.
    pub cof: [f64; 2],
    /// Characteristic length of the limit surface, m.
    pub c: f64,
    /// Pusher–slider friction coefficient.
    pub mu: f64,
    /// Pose of the object frame, table frame.
    pub pose: Pose,
}

impl Slider {
    /// A slider from a scene object.
    pub fn from_object(o: &crate::scene::Object) -> Slider {
        let shape = match &o.support {
            crate::scene::Support::Uniform => SupportShape::Uniform(&o.outline),
            crate::scene::Support::Points { points, weights } => {
                SupportShape::Points(points, weights.as_deref())
            }
        };
        let (cof, c) = friction_centre(&shape);
        Slider {
            outline: o.outline.clone(),
            cof,
            c,
            mu: o.pusher_friction,
            pose: o.pose,
        }
    }

    /// A table-frame point in the object frame.
    pub fn to_local(&self, q: [f64; 2]) -> [f64; 2] {
        rotate([q[0] - self.pose.x, q[1] - self.pose.y], -self.pose.theta)
    }

    /// An object-frame point in the table frame.
    pub fn to_table(&self, p: [f64; 2]) -> [f64; 2] {
        let r = rotate(p, self.pose.theta);
        [self.pose.x + r[0], self.pose.y + r[1]]
    }

    /// Gap between a circular pusher (centre `q`, table frame, radius `r`) and the outline;
    /// negative when they overlap (the centre inside counts as overlapping).
    pub fn gap(&self, q: [f64; 2], r: f64) -> f64 {
        let local = self.to_local(q);
        let (_, d) = closest_boundary_point(local, &self.outline);
        if point_in_polygon(local, &self.outline) {
            -d - r
        } else {
            d - r
        }
    }

    /// Move a circular pusher of radius `r` from `from` to `to` (table frame) and let the
    /// slider respond quasi-statically, in sub-steps of at most `max_step` metres. Returns the
    /// contact mode of the last sub-step that touched, if any.
    pub fn push(
        &mut self,
        from: [f64; 2],
        to: [f64; 2],
        r: f64,
        max_step: f64,
    ) -> Option<ContactMode> {
        let d = [to[0] - from[0], to[1] - from[1]];
        let len = dot(d, d).sqrt();
        let n_steps = ((len / max_step.max(1e-6)).ceil() as usize).max(1);
        let mut mode = None;
        let mut q = from;
        for k in 1..=n_steps {
            let f = k as f64 / n_steps as f64;
            let next = [from[0] + f * d[0], from[1] + f * d[1]];
            let step = [next[0] - q[0], next[1] - q[1]];
            q = next;
            // Contact at the new pusher position?
            let local = self.to_local(q);
            let (cp, dist) = closest_boundary_point(local, &self.outline);
            let inside = point_in_polygon(local, &self.outline);
            if !inside && dist > r {
                continue;
            }
            // Inward normal at the contact (from the pusher centre towards the contact point).
            let mut n = [cp[0] - local[0], cp[1] - local[1]];
            if inside {
                n = [-n[0], -n[1]];
            }
            let nl = dot(n, n).sqrt();
            if nl < 1e-15 {
                continue;
            }
            let n = [n[0] / nl, n[1] / nl];
            let vp = rotate(step, -self.pose.theta);
            let p = [cp[0] - self.cof[0], cp[1] - self.cof[1]];
            let (tw, m) = point_push(self.c, p, n, self.mu, vp);
            mode = Some(m);
            self.apply(tw);
            // Remove any residual overlap along the normal (second-order in the step).
            let gap = self.gap(q, r);
            if gap < 0.0 {
                let shift = rotate([n[0] * -gap, n[1] * -gap], self.pose.theta);
                self.pose.x += shift[0];
                self.pose.y += shift[1];
            }
        }
        mode
    }

    /// Apply a twist (slider frame at the COF, integrated over unit time) exactly on SE(2).
    pub fn apply(&mut self, tw: Twist) {
        let dth = tw.omega;
        // Displacement of the COF in the slider frame along the arc.
        let (dx, dy) = if dth.abs() < 1e-12 {
            (tw.vx, tw.vy)
        } else {
            let s = dth.sin() / dth;
            let cm = (1.0 - dth.cos()) / dth;
            (s * tw.vx - cm * tw.vy, cm * tw.vx + s * tw.vy)
        };
        let cof_before = self.to_table(self.cof);
        let disp = rotate([dx, dy], self.pose.theta);
        let theta = self.pose.theta + dth;
        // New pose: the COF moved by disp and the body turned by dth about it.
        let cof_after = [cof_before[0] + disp[0], cof_before[1] + disp[1]];
        let off = rotate(self.cof, theta);
        self.pose = Pose::new(
            cof_after[0] - off[0],
            cof_after[1] - off[1],
            wrap_angle(theta),
        );
    }

    /// Where the COF is on the table.
    pub fn cof_on_table(&self) -> [f64; 2] {
        self.to_table(self.cof)
    }
}

//! Controllability of a pushed slider, Lynch & Mason (1996) §2.3 (Propositions 1, 2, 4),
//! §3.2.2 (Proposition 5, Theorems 2, 3) and §3.3.2 (Theorems 5, 6, 7).
//!
//! Velocity directions are unit twists `(v_x, v_y, ω)` on the velocity sphere; forces are
//! `(f_x, f_y, m)` with the moment about the centre of friction.

use std::f64::consts::PI;

use super::limit_surface::EllipsoidLimitSurface;
use super::{LineContact, MechanicsError, Slider, V2, V3, cross};

const EPS: f64 = 1e-9;

/// Propositions 1 and 2: the pushing control system is small-time accessible, and so
/// controllable in the obstacle-free plane, iff the set holds two directions that are not both
/// translations and not opposite.
pub fn controllable(dirs: &[V3]) -> bool {
    let d: Vec<V3> = dirs
        .iter()
        .filter(|v| v.norm() > EPS)
        .map(|v| v.normalize())
        .collect();
    for i in 0..d.len() {
        for j in i + 1..d.len() {
            let distinct = (d[i] - d[j]).norm() > 1e-7;
            let not_opposite = (d[i] + d[j]).norm() > 1e-7;
            let rotates = d[i].z.abs() > EPS || d[j].z.abs() > EPS;
            if distinct && not_opposite && rotates {
                return true;
            }
        }
    }
    false
}

/// Whether the directions positively span R³ (`0` inside their convex hull; Theorem 1, part 1).
pub fn positively_spans_space(dirs: &[V3]) -> bool {
    let d: Vec<V3> = dirs
        .iter()
        .filter(|v| v.norm() > EPS)
        .map(|v| v.normalize())
        .collect();
    let mut full_rank = false;
    for i in 0..d.len() {
        for j in i + 1..d.len() {
            let n = d[i].cross(&d[j]);
            if n.norm() < 1e-9 {
                continue;
            }
            let n = n.normalize();
            if d.iter().any(|v| n.dot(v).abs() > 1e-9) {
                full_rank = true;
            }
            for s in [1.0, -1.0] {
                if d.iter().all(|v| s * n.dot(v) <= 1e-9) {
                    return false; // a closed half-space holds them all
                }
            }
        }
    }
    full_rank
}

/// Whether 2-D directions (angles) positively span the plane: every gap between consecutive
/// angles is shorter than π.
fn angles_span_circle(mut a: Vec<f64>) -> bool {
    if a.len() < 3 && a.len() != 2 {
        return false;
    }
    a.sort_by(f64::total_cmp);
    let mut max_gap: f64 = 0.0;
    for i in 0..a.len() {
        let next = if i + 1 < a.len() {
            a[i + 1]
        } else {
            a[0] + 2.0 * PI
        };
        max_gap = max_gap.max(next - a[i]);
    }
    max_gap < PI - 1e-9
}

/// Proposition 4: the system is small-time locally controllable iff the directions positively
/// span a great circle of the velocity sphere that is not the `ω = 0` circle (or, Theorem 1,
/// the whole sphere).
pub fn small_time_locally_controllable(dirs: &[V3]) -> bool {
    if positively_spans_space(dirs) {
        return true;
    }
    let d: Vec<V3> = dirs
        .iter()
        .filter(|v| v.norm() > EPS)
        .map(|v| v.normalize())
        .collect();
    for i in 0..d.len() {
        for j in i + 1..d.len() {
            let n = d[i].cross(&d[j]);
            if n.norm() < 1e-9 {
                continue;
            }
            let n = n.normalize();
            if n.x.abs() < 1e-9 && n.y.abs() < 1e-9 {
                continue; // the ω = 0 great circle
            }
            let b1 = d[i];
            let b2 = n.cross(&b1);
            let angles: Vec<f64> = d
                .iter()
                .filter(|v| n.dot(v).abs() < 1e-9)
                .map(|v| v.dot(&b2).atan2(v.dot(&b1)))
                .collect();
            if angles_span_circle(angles) {
                return true;
            }
        }
    }
    false
}

/// Proposition 5: with a bounded support friction distribution the slider is controllable by
/// pushing iff the pusher can apply two force directions, not both through the centre of
/// friction and not opposite. (The limit surface maps them one-to-one to velocity directions
/// with the same properties, so this is Proposition 2 on forces.)
pub fn proposition5(forces: &[V3]) -> bool {
    controllable(forces)
}

/// The wrench `(d, p × d)` of a unit force `d` applied at `p`.
pub fn wrench(p: V2, d: V2) -> V3 {
    V3::new(d.x, d.y, cross(p, d)).normalize()
}

/// Force directions a point pusher can apply at `p` with inward contact normal `n` and friction
/// `mu`: the normal and the two friction-cone edges.
fn point_forces(p: V2, n: V2, mu: f64) -> Vec<V3> {
    let a = mu.atan();
    let rot = |v: V2, t: f64| V2::new(v.x * t.cos() - v.y * t.sin(), v.x * t.sin() + v.y * t.cos());
    let mut f = vec![wrench(p, n)];
    if mu > 0.0 {
        f.push(wrench(p, rot(n, a)));
        f.push(wrench(p, rot(n, -a)));
    }
    f
}

/// A closed curve `Γ` of available point-pushing contacts (§3.2.2), relative to the centre of
/// friction.
#[derive(Debug, Clone, PartialEq)]
pub enum PushBoundary {
    /// A polygon (counter-clockwise).
    Polygon(Vec<V2>),
    /// A circle with this centre and radius.
    Disk {
        /// Centre of the circle relative to the centre of friction.
        centre: V2,
        /// Radius.
        radius: f64,
    },
}

/// The curve of force directions `f̂(Γ)` (sampled): at every point of `Γ` the normal force and
/// the friction-cone edges; at a polygon vertex every normal between the adjacent edge normals.
pub fn boundary_forces(g: &PushBoundary, mu: f64, samples: usize) -> Vec<V3> {
    let samples = samples.max(2);
    let mut out = Vec::new();
    match g {
        PushBoundary::Polygon(v) => {
            let n = v.len();
            for i in 0..n {
                let (a, b) = (v[i], v[(i + 1) % n]);
                let t = (b - a).normalize();
                let nrm = V2::new(-t.y, t.x);
                for k in 1..samples {
                    let p = a + (b - a) * (k as f64 / samples as f64);
                    out.extend(point_forces(p, nrm, mu));
                }
                // Vertex b: normals between this edge's and the next edge's.
                let c = v[(i + 2) % n];
                let t2 = (c - b).normalize();
                let n2 = V2::new(-t2.y, t2.x);
                for k in 0..=4 {
                    let w = k as f64 / 4.0;
                    let nn = (nrm * (1.0 - w) + n2 * w).normalize();
                    out.extend(point_forces(b, nn, mu));
                }
            }
        }
        PushBoundary::Disk { centre, radius } => {
            for k in 0..4 * samples {
                let th = 2.0 * PI * k as f64 / (4 * samples) as f64;
                let u = V2::new(th.cos(), th.sin());
                out.extend(point_forces(centre + u * *radius, -u, mu));
            }
        }
    }
    out
}

/// Theorem 2: a polygonal slider pushed at a point anywhere on edge `edge` (sampled along the
/// edge) is controllable; decided here by Proposition 5 on the forces the edge offers.
pub fn theorem2_edge(slider: &Slider, edge: usize, mu: f64) -> Result<bool, MechanicsError> {
    let (a, b) = slider.edge(edge)?;
    let t = (b - a).normalize();
    let n = V2::new(-t.y, t.x);
    let f: Vec<V3> = (1..8)
        .flat_map(|k| point_forces(a + (b - a) * (k as f64 / 8.0), n, mu))
        .collect();
    Ok(proposition5(&f))
}

/// Theorem 2, vertex case: pushing at vertex `i` (normals between the adjacent edge normals,
/// friction `mu`) is controllable, decided by Proposition 5.
pub fn theorem2_vertex(slider: &Slider, i: usize, mu: f64) -> Result<bool, MechanicsError> {
    let n = slider.n_edges();
    if i >= n {
        return Err(MechanicsError::NoSuchEdge(i, n));
    }
    let (prev, v, next) = (
        slider.vertices[(i + n - 1) % n],
        slider.vertices[i],
        slider.vertices[(i + 1) % n],
    );
    let t1 = (v - prev).normalize();
    let t2 = (next - v).normalize();
    let (n1, n2) = (V2::new(-t1.y, t1.x), V2::new(-t2.y, t2.x));
    let f: Vec<V3> = (0..=4)
        .flat_map(|k| {
            let w = k as f64 / 4.0;
            point_forces(v, (n1 * (1.0 - w) + n2 * w).normalize(), mu)
        })
        .collect();
    Ok(proposition5(&f))
}

/// Theorem 3: small-time local controllability by point-contact pushing anywhere on `Γ`,
/// decided by mapping `f̂(Γ)` through an ellipsoidal limit surface and applying Proposition 4.
/// The paper's verdict: true unless `Γ` is a frictionless disk centred at the centre of friction.
pub fn theorem3(g: &PushBoundary, mu: f64) -> bool {
    let c = match g {
        PushBoundary::Polygon(v) => v.iter().map(|p| p.norm()).fold(0.0, f64::max) * 0.6,
        PushBoundary::Disk { centre, radius } => (centre.norm() + radius) * 0.6,
    };
    let ls = EllipsoidLimitSurface { c: c.max(1e-6) };
    let v: Vec<V3> = boundary_forces(g, mu, 6)
        .iter()
        .map(|f| ls.velocity(f))
        .collect();
    small_time_locally_controllable(&v)
}

/// The open arc `(lo, hi)` (angles in the slider frame, radians) of pure forces — forces through
/// the centre of friction — interior to the composite friction cone of a line contact, if any.
pub fn pure_force_arc(contact: &LineContact, mu: f64) -> Option<(f64, f64)> {
    let p1 = contact.to_contact_frame(contact.a);
    let p2 = contact.to_contact_frame(contact.b);
    let y0 = -p1.y; // distance from the centre of friction to the contact line
    if y0 <= 0.0 {
        return None;
    }
    // A pure force at angle φ from the normal (counter-clockwise) crosses the contact line at
    // x = y0·tan φ: it is inside F iff |φ| < atan μ and x1 < x < x2.
    let (x1, x2) = (p1.x.min(p2.x), p1.x.max(p2.x));
    let lo = (x1 / y0).atan().max(-mu.atan());
    let hi = (x2 / y0).atan().min(mu.atan());
    if hi - lo <= 1e-12 {
        return None;
    }
    let n = contact.normal();
    let base = n.y.atan2(n.x);
    Some((base + lo, base + hi))
}

/// Theorem 5: a line contact whose composite friction cone holds a pure force in its interior
/// makes the slider controllable by the stable pushes found by STABLE.
pub fn theorem5(contact: &LineContact, mu: f64) -> bool {
    pure_force_arc(contact, mu).is_some()
}

/// Theorem 6: some hull edge of the polygon, pushed along its whole length, satisfies
/// Theorem 5.
pub fn theorem6(slider: &Slider, mu: f64) -> Result<bool, MechanicsError> {
    for e in 0..slider.n_edges() {
        if slider.is_hull_edge(e)? && theorem5(&LineContact::full_edge(slider, e)?, mu) {
            return Ok(true);
        }
    }
    Ok(false)
}

/// Theorem 7: the pure forces interior to at least one contact's composite friction cone
/// positively span the plane of pure forces ⇒ small-time locally controllable by STABLE pushes.
pub fn theorem7(contacts: &[LineContact], mu: f64) -> bool {
    let arcs: Vec<(f64, f64)> = contacts
        .iter()
        .filter_map(|c| pure_force_arc(c, mu))
        .collect();
    if arcs.is_empty() {
        return false;
    }
    open_arcs_span_circle(&arcs)
}

/// Whether the union of the open arcs `(lo, hi)` (radians, `0 < hi − lo < 2π`) positively
/// spans the plane: exactly when no closed half-plane holds it, i.e. when every gap the arcs
/// leave on the circle is shorter than π. Decided exactly on the arcs' end points (a sweep
/// around the circle from the first arc's start), not on samples of their interiors.
pub fn open_arcs_span_circle(arcs: &[(f64, f64)]) -> bool {
    let mut a: Vec<(f64, f64)> = arcs
        .iter()
        .filter(|(lo, hi)| hi > lo)
        .map(|&(lo, hi)| (lo.rem_euclid(2.0 * PI), (hi - lo).min(2.0 * PI)))
        .collect();
    if a.is_empty() {
        return false;
    }
    a.sort_by(|x, y| x.0.total_cmp(&y.0));
    let first = a[0].0;
    let mut end = first + a[0].1;
    let mut max_gap: f64 = 0.0;
    for &(lo, len) in &a[1..] {
        max_gap = max_gap.max(lo - end);
        end = end.max(lo + len);
    }
    max_gap = max_gap.max(first + 2.0 * PI - end);
    max_gap < PI
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_translations_are_not_controllable() {
        assert!(!controllable(&[V3::x(), V3::y()]));
        assert!(controllable(&[V3::x(), V3::new(0.0, 1.0, 1.0)]));
        assert!(!controllable(&[
            V3::new(0.0, 1.0, 1.0),
            V3::new(0.0, -1.0, -1.0)
        ]));
    }

    #[test]
    fn one_open_hemisphere_is_not_stlc() {
        // Theorem 1, part 2: all in the open half-space v_y > 0.
        let d = [
            V3::new(0.0, 1.0, 1.0),
            V3::new(0.0, 1.0, -1.0),
            V3::new(1.0, 1.0, 0.0),
            V3::new(-1.0, 1.0, 0.0),
        ];
        assert!(!small_time_locally_controllable(&d));
        // Reversible pair of rotations: a great circle not at ω = 0 (Proposition 4).
        let d = [
            V3::new(1.0, 0.0, 1.0),
            V3::new(-1.0, 0.0, -1.0),
            V3::new(0.0, 1.0, 0.0),
            V3::new(0.0, -1.0, 0.0),
        ];
        assert!(small_time_locally_controllable(&d));
        // Four translations only: the ω = 0 circle, not STLC.
        let d = [V3::x(), -V3::x(), V3::y(), -V3::y()];
        assert!(!small_time_locally_controllable(&d));
    }
}

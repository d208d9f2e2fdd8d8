//! The procedure STABLE of Lynch & Mason (1996), §3.3.1, and the extremal stable pushing
//! directions `V̂_extremal` used by the planner (§4.1).
//!
//! STABLE is drawn in the paper in rotation-centre space. Every region it draws is bounded by a
//! line `û·c = d` and holds rotation centres of one sense; for a twist `v = (v_x, v_y, ω)` with
//! `c = COR(v)`, `û·c ≥ d` with `ω > 0` is the linear inequality `û_y v_x − û_x v_y − d ω ≥ 0`,
//! and `û·c ≤ d` with `ω < 0` is the *same* inequality. So the counter-clockwise region on one
//! side and the clockwise region on the other join, through the translations, into one
//! polyhedral cone `{v : A v ≥ 0}` of velocity space: a convex polygon on the velocity sphere.
//! In the contact frame (line contact on `y = y₀ < 0`, normal `+y`, end points `P₁` left and
//! `P₂` right), with `h_u(v) = u_y v_x − u_x v_y`:
//!
//! 1. friction-cone bands, edges `e_L = (−sin α, cos α)`, `e_R = (sin α, cos α)`, `α = atan μ`,
//!    band limits `m_u = min_x u·x`, `M_u = max_x u·x` over the slider:
//!    `h_{e_L} ≥ M_L ω`, `h_{e_L} ≥ m_L ω`, `h_{e_R} ≤ m_R ω`, `h_{e_R} ≤ M_R ω`;
//! 2. end-point bands (perpendicular bisector at `p/2`, tip line at `r²/p` on the far side),
//!    `û_i = P_i/p_i`: `h_{û₁} ≥ (p₁/2) ω`, `h_{û₁} ≥ −(r²/p₁) ω`, `h_{û₂} ≤ −(r²/p₂) ω`,
//!    `h_{û₂} ≤ (p₂/2) ω`;
//! 3. the intersection of both. Theorem 4's lines (perpendicular to the contact, enclosing the
//!    slider: counter-clockwise centres left of `x_min`, clockwise right of `x_max`) are added
//!    as `v_y + x_min ω ≥ 0`, `v_y + x_max ω ≥ 0`; the paper says they are implied, and the
//!    tests check that they are on the hand-computed cases.
//!
//! The extremal directions are the extreme rays of that cone.

use super::{LineContact, MechanicsError, Slider, V2, V3, cor};

/// Tolerance on a unit constraint row when testing membership.
const TOL: f64 = 1e-9;

/// A convex cone of velocity directions `{v : a_k·v ≥ 0 ∀k}` in the slider frame, with its
/// extreme rays.
#[derive(Debug, Clone, PartialEq)]
pub struct StableSet {
    /// The line contact the set belongs to.
    pub contact: LineContact,
    /// Unit constraint rows `a_k` (slider frame): `v` is in the set iff `a_k·v ≥ 0` for all `k`.
    pub constraints: Vec<V3>,
    /// The extremal directions (unit twists, slider frame), ordered around the polygon.
    pub extremal: Vec<V3>,
}

impl StableSet {
    /// Whether the unit twist `v` is in the set (up to a small tolerance).
    pub fn contains(&self, v: &V3) -> bool {
        let n = v.norm();
        n > 0.0 && self.constraints.iter().all(|a| a.dot(v) / n >= -1e-7)
    }

    /// Whether STABLE found no direction at all.
    pub fn is_empty(&self) -> bool {
        self.extremal.is_empty()
    }

    /// The set intersected with further constraints (rows `a·v ≥ 0`, slider frame).
    pub fn intersect(&self, extra: &[V3]) -> StableSet {
        let mut constraints = self.constraints.clone();
        constraints.extend(
            extra
                .iter()
                .filter(|a| a.norm() > 0.0)
                .map(|a| a.normalize()),
        );
        let extremal = extreme_rays(&constraints);
        StableSet {
            contact: self.contact,
            constraints,
            extremal,
        }
    }

    /// Translation directions among the extremal set.
    pub fn translations(&self) -> Vec<V3> {
        self.extremal
            .iter()
            .copied()
            .filter(|v| v.z.abs() < 1e-9)
            .collect()
    }

    /// Rotation centres of the extremal directions (`None` for translations).
    pub fn extremal_cors(&self) -> Vec<Option<V2>> {
        self.extremal.iter().map(cor).collect()
    }
}

/// The procedure STABLE for a line contact with pusher–slider friction coefficient `mu`.
pub fn stable(
    slider: &Slider,
    contact: &LineContact,
    mu: f64,
) -> Result<StableSet, MechanicsError> {
    if !mu.is_finite() || mu < 0.0 {
        return Err(MechanicsError::BadFriction(mu));
    }
    let verts: Vec<V2> = slider
        .vertices
        .iter()
        .map(|&p| contact.to_contact_frame(p))
        .collect();
    let (mut p1, mut p2) = (
        contact.to_contact_frame(contact.a),
        contact.to_contact_frame(contact.b),
    );
    if p1.x > p2.x {
        std::mem::swap(&mut p1, &mut p2);
    }
    let r2 = slider.radius().powi(2);
    let alpha = mu.atan();
    let (s, c) = alpha.sin_cos();
    let band = |u: V2| {
        let d: Vec<f64> = verts.iter().map(|x| u.dot(x)).collect();
        (
            d.iter().copied().fold(f64::INFINITY, f64::min),
            d.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let (e_l, e_r) = (V2::new(-s, c), V2::new(s, c));
    let (m_l, big_m_l) = band(e_l);
    let (m_r, big_m_r) = band(e_r);
    // h_u(v) = u_y v_x − u_x v_y as a row.
    let h = |u: V2| V3::new(u.y, -u.x, 0.0);
    let (n1, n2) = (p1.norm(), p2.norm());
    if n1 < 1e-12 || n2 < 1e-12 {
        return Err(MechanicsError::CofOutside);
    }
    let (u1, u2) = (p1 / n1, p2 / n2);
    // Theorem 4's lines.
    let xmin = verts.iter().map(|v| v.x).fold(f64::INFINITY, f64::min);
    let xmax = verts.iter().map(|v| v.x).fold(f64::NEG_INFINITY, f64::max);
    let rows = [
        // Step 1: friction-cone bands.
        h(e_l) + V3::new(0.0, 0.0, -big_m_l),
        h(e_l) + V3::new(0.0, 0.0, -m_l),
        -h(e_r) + V3::new(0.0, 0.0, m_r),
        -h(e_r) + V3::new(0.0, 0.0, big_m_r),
        // Step 2: end-point bands (bisector and tip line r²/p).
        h(u1) + V3::new(0.0, 0.0, -n1 / 2.0),
        h(u1) + V3::new(0.0, 0.0, r2 / n1),
        -h(u2) + V3::new(0.0, 0.0, -r2 / n2),
        -h(u2) + V3::new(0.0, 0.0, n2 / 2.0),
        // Theorem 4.
        V3::new(0.0, 1.0, xmin),
        V3::new(0.0, 1.0, xmax),
    ];
    let constraints: Vec<V3> = rows
        .iter()
        .map(|r| contact.twist_to_slider(*r).normalize())
        .collect();
    let extremal = extreme_rays(&constraints);
    Ok(StableSet {
        contact: *contact,
        constraints,
        extremal,
    })
}

/// STABLE for every hull edge of the slider, each pushed along its whole length.
pub fn stable_all_edges(slider: &Slider, mu: f64) -> Result<Vec<StableSet>, MechanicsError> {
    let mut out = Vec::new();
    for e in 0..slider.n_edges() {
        if slider.is_hull_edge(e)? {
            out.push(stable(slider, &LineContact::full_edge(slider, e)?, mu)?);
        }
    }
    Ok(out)
}

/// Extreme rays (unit) of the cone `{v : a_k·v ≥ 0}`, ordered around their mean; empty when
/// the cone is `{0}`.
pub fn extreme_rays(rows: &[V3]) -> Vec<V3> {
    let mut rays: Vec<V3> = Vec::new();
    for i in 0..rows.len() {
        for j in i + 1..rows.len() {
            let d = rows[i].cross(&rows[j]);
            if d.norm() < 1e-10 {
                continue;
            }
            for sgn in [1.0, -1.0] {
                let r = d.normalize() * sgn;
                if rows.iter().all(|a| a.dot(&r) >= -TOL)
                    && !rays.iter().any(|q| (q - r).norm() < 1e-7)
                {
                    rays.push(r);
                }
            }
        }
    }
    // A cone containing a whole line has no extreme rays in this sense; ours are pointed.
    if rays.len() > 2 {
        let m = rays.iter().sum::<V3>();
        if m.norm() > 1e-9 {
            let m = m.normalize();
            let e1 = if m.x.abs() < 0.9 { V3::x() } else { V3::y() };
            let b1 = (e1 - m * m.dot(&e1)).normalize();
            let b2 = m.cross(&b1);
            rays.sort_by(|p, q| {
                let ap = p.dot(&b2).atan2(p.dot(&b1));
                let aq = q.dot(&b2).atan2(q.dot(&b1));
                ap.total_cmp(&aq)
            });
        }
    }
    rays
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Slider {
        let o = [
            V2::new(-1.0, -1.0),
            V2::new(1.0, -1.0),
            V2::new(1.0, 1.0),
            V2::new(-1.0, 1.0),
        ];
        Slider::new(&o, V2::zeros()).unwrap()
    }

    #[test]
    fn extreme_rays_of_octant() {
        let rows = [V3::x(), V3::y(), V3::z()];
        let r = extreme_rays(&rows);
        assert_eq!(r.len(), 3);
        for e in [V3::x(), V3::y(), V3::z()] {
            assert!(r.iter().any(|v| (v - e).norm() < 1e-9));
        }
    }

    #[test]
    fn frictionless_square_gives_single_translation() {
        // μ = 0: e_L = e_R = (0, 1), so h = v_x and step 1 asks v_x ≥ M ω and v_x ≤ m ω with
        // m = −1 < M = 1: only ω = 0, v_x = 0. STABLE finds the single translation along the
        // normal, as §3.3.1 says when F holds a pure force only on its boundary.
        let s = square();
        let set = stable(&s, &LineContact::full_edge(&s, 0).unwrap(), 0.0).unwrap();
        assert_eq!(set.extremal.len(), 1);
        assert!((set.extremal[0] - V3::new(0.0, 1.0, 0.0)).norm() < 1e-9);
    }
}

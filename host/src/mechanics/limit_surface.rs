//! The ellipsoidal approximation of the limit surface (Lynch & Mason 1996, §3.1.1; Lee &
//! Cutkosky; Lynch 1992): a smooth, strictly convex limit surface `fᵀ H f = 1` with
//! `H = diag(1, 1, 1/c²)`, so the velocity direction for a force `f` is the surface normal
//! `v ∝ (f_x, f_y, m/c²)`. It stands for one bounded support friction distribution where a
//! theorem only needs the properties every such distribution shares (a one-to-one,
//! sign-preserving map from force directions to velocity directions).

use super::V3;

/// An ellipsoidal limit surface with characteristic length `c` (for a uniform disk of radius
/// `R`, `c ≈ 0.6 R`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipsoidLimitSurface {
    /// Ratio of the maximum moment to the maximum force, a length.
    pub c: f64,
}

impl EllipsoidLimitSurface {
    /// The unit velocity direction of the slider under force `f = (f_x, f_y, m)`.
    pub fn velocity(&self, f: &V3) -> V3 {
        let v = V3::new(f.x, f.y, f.z / (self.c * self.c));
        if v.norm() > 0.0 { v.normalize() } else { v }
    }

    /// The force direction that produces velocity direction `v` (inverse map).
    pub fn force(&self, v: &V3) -> V3 {
        let f = V3::new(v.x, v.y, v.z * self.c * self.c);
        if f.norm() > 0.0 { f.normalize() } else { f }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pure_force_gives_translation_and_round_trips() {
        let ls = EllipsoidLimitSurface { c: 0.5 };
        let v = ls.velocity(&V3::new(0.0, 1.0, 0.0));
        assert!((v - V3::new(0.0, 1.0, 0.0)).norm() < 1e-12);
        let f = V3::new(0.3, -0.2, 0.7).normalize();
        assert!((ls.force(&ls.velocity(&f)) - f).norm() < 1e-12);
        // A positive moment always gives a counter-clockwise rotation.
        assert!(ls.velocity(&V3::new(1.0, 0.0, 0.01)).z > 0.0);
    }
}

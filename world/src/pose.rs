//! The one planar pose of the project: a rigid transform of SE(2) in the table frame (origin at
//! the table's lower-left corner, x along its width, y along its height, angles
//! counter-clockwise from +x), metres and radians, with its `nalgebra` conversions.

use std::f64::consts::{PI, TAU};

use nalgebra::{Isometry2, Point2, Rotation2, Vector2};
use serde::{Deserialize, Serialize};

/// A pose in the table frame (or in another body's frame): metres and radians.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pose {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Heading, rad, counter-clockwise from +x.
    pub theta: f64,
}

impl Pose {
    /// A pose.
    pub const fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose { x, y, theta }
    }

    /// Position as a vector.
    pub fn position(&self) -> Vector2<f64> {
        Vector2::new(self.x, self.y)
    }

    /// Whether every field is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }

    /// A table-frame vector expressed in this pose's frame (rotation only).
    pub fn vector_to_local(&self, v: Vector2<f64>) -> Vector2<f64> {
        Rotation2::new(-self.theta) * v
    }

    /// A vector of this pose's frame expressed in the table frame (rotation only).
    pub fn vector_to_world(&self, v: Vector2<f64>) -> Vector2<f64> {
        Rotation2::new(self.theta) * v
    }

    /// A table-frame point expressed in this pose's frame.
    pub fn point_to_local(&self, p: Vector2<f64>) -> Vector2<f64> {
        self.vector_to_local(p - self.position())
    }

    /// A point of this pose's frame expressed in the table frame.
    pub fn point_to_world(&self, p: Vector2<f64>) -> Vector2<f64> {
        self.vector_to_world(p) + self.position()
    }

    /// `self ∘ local`: the pose `local` (given in this pose's frame) in the outer frame, its
    /// heading wrapped to (−π, π].
    pub fn compose(&self, local: &Pose) -> Pose {
        let (s, c) = self.theta.sin_cos();
        Pose {
            x: self.x + c * local.x - s * local.y,
            y: self.y + s * local.x + c * local.y,
            theta: wrap_angle(self.theta + local.theta),
        }
    }

    /// The inverse transform (heading wrapped to (−π, π]).
    pub fn inverse(&self) -> Pose {
        let (s, c) = self.theta.sin_cos();
        Pose {
            x: -(c * self.x + s * self.y),
            y: s * self.x - c * self.y,
            theta: wrap_angle(-self.theta),
        }
    }

    /// As an `nalgebra` isometry.
    pub fn isometry(&self) -> Isometry2<f64> {
        Isometry2::new(self.position(), self.theta)
    }

    /// From an `nalgebra` isometry.
    pub fn from_isometry(iso: &Isometry2<f64>) -> Pose {
        Pose::new(iso.translation.x, iso.translation.y, iso.rotation.angle())
    }

    /// A point `[x, y]` of this pose's frame in the outer frame.
    pub fn transform(&self, p: [f64; 2]) -> [f64; 2] {
        let q = self.isometry() * Point2::new(p[0], p[1]);
        [q.x, q.y]
    }
}

/// Wrap an angle to (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_with_inverse_is_identity() {
        let p = Pose::new(0.3, -0.2, 2.5);
        let q = p.compose(&p.inverse());
        assert!(
            q.x.abs() < 1e-12 && q.y.abs() < 1e-12 && q.theta.abs() < 1e-12,
            "{q:?}"
        );
        let back = Pose::from_isometry(&p.isometry());
        assert!((back.x - p.x).abs() < 1e-12 && (back.theta - p.theta).abs() < 1e-12);
    }

    #[test]
    fn points_round_trip_and_wrap() {
        let p = Pose::new(1.0, 2.0, 0.5 * PI);
        let w = p.point_to_world(Vector2::new(1.0, 0.0));
        assert!((w.x - 1.0).abs() < 1e-12 && (w.y - 3.0).abs() < 1e-12);
        let l = p.point_to_local(w);
        assert!((l.x - 1.0).abs() < 1e-12 && l.y.abs() < 1e-12);
        assert_eq!(p.transform([1.0, 0.0])[1], w.y);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
    }
}

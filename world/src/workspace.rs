//! The workspace of a delivery as Lau, Mitani & Igarashi define it (§III-A): the table the
//! robot drives on, the boundary the object must stay inside, the robot's radius and the
//! object's bounding circles (round its marker, and the smallest round its outline);
//! axis-aligned rectangles of the table frame.

use nalgebra::Vector2;

use crate::enclosing_circle::{Circle, enclosing_circle};

/// An axis-aligned rectangle of the table frame, m.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Rect {
    /// Lower-left corner.
    pub min: [f64; 2],
    /// Upper-right corner.
    pub max: [f64; 2],
}

impl Rect {
    /// Whether `p` lies inside (or on) the rectangle.
    pub fn contains(&self, p: Vector2<f64>) -> bool {
        p.x >= self.min[0] && p.x <= self.max[0] && p.y >= self.min[1] && p.y <= self.max[1]
    }
    /// The rectangle shrunk by `d` on every side.
    pub fn inset(&self, d: f64) -> Rect {
        Rect {
            min: [self.min[0] + d, self.min[1] + d],
            max: [self.max[0] - d, self.max[1] - d],
        }
    }
    /// Outward direction from the rectangle to `p` (unit), or `None` when `p` is inside.
    pub fn outward(&self, p: Vector2<f64>) -> Option<Vector2<f64>> {
        let dx = if p.x < self.min[0] {
            p.x - self.min[0]
        } else if p.x > self.max[0] {
            p.x - self.max[0]
        } else {
            0.0
        };
        let dy = if p.y < self.min[1] {
            p.y - self.min[1]
        } else if p.y > self.max[1] {
            p.y - self.max[1]
        } else {
            0.0
        };
        let v = Vector2::new(dx, dy);
        (v.norm() > 0.0).then(|| v / v.norm())
    }
    /// Centre of the rectangle.
    pub fn centre(&self) -> Vector2<f64> {
        Vector2::new(
            (self.min[0] + self.max[0]) / 2.0,
            (self.min[1] + self.max[1]) / 2.0,
        )
    }
}

/// The workspace as the paper's problem definition gives it (§III-A): the boundary the object
/// must stay in, the robot's radius and the radius of the object's bounding circle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Workspace {
    /// The table (the robot's centre can never leave it shrunk by the robot's radius).
    pub table: Rect,
    /// The boundary the object's marker must stay inside.
    pub boundary: Rect,
    /// Robot (bumper) radius, m.
    pub robot_radius: f64,
    /// Radius of the object's bounding circle around its marker, m.
    pub object_radius: f64,
    /// The smallest circle enclosing the object's outline, in the marker's frame (m): what the
    /// outline sweeps through as it turns about the circle's centre, the least such disc.
    pub body: Circle,
}

/// The object's bounds for a workspace: the radius of its outline's bounding circle around
/// the marker at `marker` (both in the object's frame), and the outline's smallest enclosing
/// circle in the marker's frame. No outline: nothing to bound (a zero circle at the marker).
pub fn object_bounds(outline: &[[f64; 2]], marker: [f64; 2]) -> (f64, Circle) {
    let about = outline_about(outline, marker);
    let radius = about.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
    let body = enclosing_circle(&about).unwrap_or(Circle::at_origin(radius));
    (radius, body)
}

/// An outline (object frame) in the frame of its marker at `marker`: what the camera's pose of
/// the marker places on the table.
pub fn outline_about(outline: &[[f64; 2]], marker: [f64; 2]) -> Vec<[f64; 2]> {
    outline
        .iter()
        .map(|v| [v[0] - marker[0], v[1] - marker[1]])
        .collect()
}

impl Workspace {
    /// This workspace seen from the object's smallest enclosing circle: its bounding circle is
    /// that circle, about [`Workspace::body_centre`] rather than the marker. A path for the
    /// object's body (its outline turning freely) is planned in it.
    pub fn body_workspace(&self) -> Workspace {
        Workspace {
            object_radius: self.body.radius,
            body: Circle::at_origin(self.body.radius),
            ..*self
        }
    }

    /// The centre of the object's smallest enclosing circle ([`Workspace::body`]) in the table
    /// frame, for the object's marker at `object`.
    pub fn body_centre(&self, object: &crate::Pose) -> Vector2<f64> {
        object.point_to_world(Vector2::new(self.body.centre[0], self.body.centre[1]))
    }
    /// Where the robot's centre may go: the table shrunk by the robot's radius and 1 cm.
    pub fn reachable(&self) -> Rect {
        self.table.inset(self.robot_radius + 0.01)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Pose;

    /// The L-shape of the Lau presets, marked in its corner: 11.7 cm from the marker to its
    /// furthest vertex, 9.2 cm from the middle of its diagonal to every far corner.
    #[test]
    fn the_l_shape_marked_in_its_corner_has_a_smaller_body_circle() {
        let l = [
            [-0.06, -0.06],
            [0.06, -0.06],
            [0.06, -0.02],
            [-0.02, -0.02],
            [-0.02, 0.08],
            [-0.06, 0.08],
        ];
        let (radius, body) = object_bounds(&l, [-0.04, -0.035]);
        assert!((radius - 0.02_f64.hypot(0.115)).abs() < 1e-12, "{radius}");
        assert!(
            (body.radius - 0.06_f64.hypot(0.07)).abs() < 1e-12,
            "{body:?}"
        );
        assert!((body.centre[0] - 0.04).abs() < 1e-12 && (body.centre[1] - 0.045).abs() < 1e-12);
        let ws = Workspace {
            table: Rect {
                min: [0.0, 0.0],
                max: [1.6, 1.2],
            },
            boundary: Rect {
                min: [0.1, 0.1],
                max: [1.5, 1.1],
            },
            robot_radius: 0.04,
            object_radius: radius,
            body,
        };
        // The marker at (0.5, 0.5), the object turned a quarter: its body's centre is the
        // offset turned, and every vertex lies within the body circle about it.
        let o = Pose::new(0.5, 0.5, std::f64::consts::FRAC_PI_2);
        let c = ws.body_centre(&o);
        assert!(
            (c - Vector2::new(0.5 - 0.045, 0.5 + 0.04)).norm() < 1e-12,
            "{c:?}"
        );
        for v in l {
            let w = o.point_to_world(Vector2::new(v[0] + 0.04, v[1] + 0.035));
            assert!((w - c).norm() <= body.radius + 1e-12);
        }
        let b = ws.body_workspace();
        assert_eq!((b.object_radius, b.body.centre), (body.radius, [0.0, 0.0]));
        // No outline: nothing to bound.
        assert_eq!(object_bounds(&[], [0.0, 0.0]).0, 0.0);
    }
}

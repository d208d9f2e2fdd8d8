//! The workspace of a delivery as Lau, Mitani & Igarashi define it (§III-A): the table the
//! robot drives on, the boundary the object must stay inside, the robot's radius and the radius
//! of the object's bounding circle; axis-aligned rectangles of the table frame.

use nalgebra::Vector2;

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
}

impl Workspace {
    /// Where the robot's centre may go: the table shrunk by the robot's radius and 1 cm.
    pub fn reachable(&self) -> Rect {
        self.table.inset(self.robot_radius + 0.01)
    }
}

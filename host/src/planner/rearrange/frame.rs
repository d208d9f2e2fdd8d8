//! Where the grid of a rearrangement problem lies on the table (Ben-Shahar & Rivlin §V-B): row
//! 0 along the far edge, cell `(x, y)` centred at `((x + ½)·c, (h − y − ½)·c)` metres, table y
//! pointing up. Shared by the scene rasterisation ([`super::scene`]) and the executor
//! ([`crate::exec::rearrange::execute`]), below both.

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector2;

use super::grid::Dir;
use super::problem::Placement;
use crate::strategy::sample::{Pose2, wrap_angle};

/// Where the grid lies on the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridFrame {
    /// Side of a cell, m.
    pub cell: f64,
    /// Grid height in cells (row 0 is at table y = `h · cell`).
    pub h: i32,
}

impl GridFrame {
    /// The centre of cell `(x, y)`, table frame.
    pub fn centre(&self, x: i32, y: i32) -> Vector2<f64> {
        Vector2::new(
            (x as f64 + 0.5) * self.cell,
            (self.h as f64 - y as f64 - 0.5) * self.cell,
        )
    }
    /// The cell containing a table point (may lie outside the grid).
    pub fn cell_of(&self, p: Vector2<f64>) -> (i32, i32) {
        (
            (p.x / self.cell).floor() as i32,
            (self.h as f64 - p.y / self.cell).floor() as i32,
        )
    }
    /// A grid direction as a table unit vector.
    pub fn dir(d: Dir) -> Vector2<f64> {
        match d {
            Dir::E => Vector2::new(1.0, 0.0),
            Dir::S => Vector2::new(0.0, -1.0),
            Dir::W => Vector2::new(-1.0, 0.0),
            Dir::N => Vector2::new(0.0, 1.0),
        }
    }
    /// A grid direction as a heading, rad.
    pub fn heading(d: Dir) -> f64 {
        let v = Self::dir(d);
        v.y.atan2(v.x)
    }
    /// The centre of a `k × k` robot block with its anchor (top-left cell) at `a`.
    pub fn robot_centre(&self, a: (i32, i32), k: i32) -> Vector2<f64> {
        let half = (k - 1) as f64 / 2.0 * self.cell;
        self.centre(a.0, a.1) + Vector2::new(half, -half)
    }
    /// The body pose of a movable placed at `p`.
    pub fn body_pose(&self, p: Placement) -> Pose2 {
        let c = self.centre(p.x, p.y);
        Pose2::new(c.x, c.y, wrap_angle(-(p.o as f64) * FRAC_PI_2))
    }
}

//! Workspaces the executors' unit tests share.

use crate::exec::io::{Rect, Workspace};

/// Lau et al.'s 1.6 × 1.2 m table with its boundary 0.1 m in, a robot of 4 cm radius and
/// a round object of `radius` about its marker.
pub(crate) fn lau_table(radius: f64) -> Workspace {
    Workspace {
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
        body: pushbot_world::enclosing_circle::Circle::at_origin(radius),
    }
}

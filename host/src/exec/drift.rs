//! Whether a push is followed by the special case (Lau, Mitani & Igarashi §III-E, Algorithm 2:
//! the robot re-positions when its last push moved the object away from the goal), with the
//! tighter rules a delivery among obstacles needs
//! ([`crate::exec::deliver_path`]): a push that drifted off its wanted way by more than the
//! re-position angle, and — near a wall — one that drifted towards the wall by more than a
//! much smaller angle.
//!
//! Near a wall the robot cannot stand between the wall and the object, so it cannot push the
//! object back off it: a drift towards the wall that the next push would continue is not
//! corrected later, it becomes a stall. A pure function of the poses before and after the push.

use nalgebra::Vector2;

use crate::exec::delivery_params::DeliveryParams;
use crate::exec::io::Workspace;
use crate::exec::maneuver::angle_of;
use crate::planner::global::clearance;
use crate::strategy::sample::{Pose2, wrap_angle};

/// One push as the special case's trigger sees it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Push {
    /// The object's marker before and after the push.
    pub before: Pose2,
    /// See [`Push::before`].
    pub after: Pose2,
    /// Whether the motion that counts is the enclosing circle's centre's (along a path, which
    /// is planned for it) rather than the marker's.
    pub on_centre: bool,
    /// The way that motion was wanted (unit).
    pub wanted: Vector2<f64>,
    /// The boundary guard's pull on the wanted motion (zero away from the boundary).
    pub bias: Vector2<f64>,
}

/// Whether the special case follows `push`: it did not move the object (the robot lost
/// contact), moved it off its wanted way by more than [`DeliveryParams::reposition_angle`] (at
/// most a quarter turn, the paper's), moved it towards the boundary inside the guard band, or
/// left the object's enclosing circle within [`DeliveryParams::wall_near`] of an obstacle and
/// nearer to it than before while off its way by more than
/// [`DeliveryParams::wall_reposition_angle`].
pub(crate) fn reposition_next(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    p: &DeliveryParams,
    push: &Push,
) -> bool {
    let moved = push.after.position() - push.before.position();
    let went = if push.on_centre {
        ws.body_centre(&push.after) - ws.body_centre(&push.before)
    } else {
        moved
    };
    let off_by = wrap_angle(angle_of(went) - angle_of(push.wanted)).abs();
    moved.norm() < p.moved_epsilon
        || off_by > p.reposition_angle.min(std::f64::consts::FRAC_PI_2)
        || moved.dot(&push.bias) < 0.0
        || (off_by > p.wall_reposition_angle && towards_wall(ws, obstacles, p, push))
}

/// Whether the push left the object's enclosing circle within the wall band of an obstacle
/// and nearer to it than it was.
fn towards_wall(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    p: &DeliveryParams,
    push: &Push,
) -> bool {
    if p.wall_near <= 0.0 || obstacles.is_empty() {
        return false;
    }
    let before = clearance(ws.body_centre(&push.before), obstacles);
    let after = clearance(ws.body_centre(&push.after), obstacles);
    after < ws.body.radius + p.wall_near && after < before
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::test_tables::lau_table;

    /// The object pushed 4 cm up a wall (its face at x = 1.1), 15° off the way wanted.
    fn push(from_x: f64, drift: f64) -> Push {
        let before = Pose2::new(from_x, 0.5, 0.0);
        let went = Vector2::new(drift * 15f64.to_radians().sin(), 15f64.to_radians().cos());
        let after = Pose2::new(from_x + 0.04 * went.x, 0.5 + 0.04 * went.y, 0.0);
        Push {
            before,
            after,
            on_centre: false,
            wanted: Vector2::y(),
            bias: Vector2::zeros(),
        }
    }

    /// 15° is inside the 30° re-position angle: in the open and drifting away from the wall
    /// the pushing goes on; drifting towards the wall within the band it does not.
    #[test]
    fn a_drift_towards_a_near_wall_is_followed_by_the_special_case() {
        let wall = vec![vec![[1.0, 0.4], [1.1, 0.4], [1.1, 1.2], [1.0, 1.2]]];
        let p = DeliveryParams {
            reposition_angle: 30f64.to_radians(),
            wall_near: 0.05,
            wall_reposition_angle: 10f64.to_radians(),
            ..DeliveryParams::default()
        };
        let ws = lau_table(0.09);
        // 12 cm from the wall's face: the circle is 3 cm from it, inside the 5 cm band.
        assert!(reposition_next(&ws, &wall, &p, &push(1.22, -1.0)));
        assert!(!reposition_next(&ws, &wall, &p, &push(1.22, 1.0)));
        // 30 cm from it: outside the band either way.
        assert!(!reposition_next(&ws, &wall, &p, &push(1.4, -1.0)));
        // No wall band (the paper's rule, and a clear table): the drift is let be.
        let off = DeliveryParams {
            wall_near: 0.0,
            ..p
        };
        assert!(!reposition_next(&ws, &wall, &off, &push(1.22, -1.0)));
        assert!(!reposition_next(&ws, &[], &p, &push(1.22, -1.0)));
        // 40° off is past the re-position angle anywhere.
        let mut wide = push(1.4, 1.0);
        let went = Vector2::new(40f64.to_radians().sin(), 40f64.to_radians().cos());
        wide.after = Pose2::new(1.4 + 0.04 * went.x, 0.5 + 0.04 * went.y, 0.0);
        assert!(reposition_next(&ws, &wall, &p, &wide));
    }
}

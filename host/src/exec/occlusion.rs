//! When the robot hides a marker. A body the camera has not seen since the robot stopped may
//! be lost under the robot itself: a thin object's marker overhangs its body (Lau et al.'s wire
//! cutter and snake are narrower than their 5 cm markers), and with the robot standing against
//! it the robot's own marker covers the overhang. Waiting does not help; moving does. Before a
//! body counts as lost, the robot moves [`BACK_OFF`] along its own axis away from where the
//! body was last seen, the camera looks again, and the robot drives back to where it stood (the
//! body did not move meanwhile, and the push the executor is about to make starts there). The
//! last seen position may be from before a push that carried the body along, so when the first
//! way does not show the body the robot tries the other. The simulated robot with the rendered camera
//! (`crate::sim::robot::SimRobot`) and the live one ([`crate::exec::LiveRobot`]) both use what is
//! here, so they behave alike.

use nalgebra::Vector2;

use crate::strategy::sample::Pose2;

/// How far the robot backs away from a body it hides before looking again, m: two of the
/// default 5 cm markers with their quiet zones lie clear of each other once their centres are
/// this much further apart.
pub const BACK_OFF: f64 = 0.08;

/// Speed of those moves, m/s: nothing is pushed on them, so the robot goes faster than it
/// pushes (below the firmware's 0.3 m/s limit).
pub const BACK_OFF_SPEED: f64 = 0.25;

/// How near the robot's marker must have been to where a body's marker was last seen for the
/// robot to hide it, m: two 5 cm markers with their quiet zones overlap up to about 9 cm.
pub const HIDING_REACH: f64 = 0.1;

/// Whether the robot, last seen at `robot`, may itself hide `body`, last seen at `at`: then
/// waiting for the body is no use and the robot moves at once. The robot never hides itself;
/// a body never seen, or a robot never seen, is waited for first.
pub fn robot_may_hide(body: &str, robot: Option<Pose2>, at: Option<Vector2<f64>>) -> bool {
    match (robot, at) {
        (Some(r), Some(a)) => body != "robot" && (a - r.position()).norm() < HIDING_REACH,
        _ => false,
    }
}

/// The two straight moves to try, in order (signed, along the robot's heading at `robot`;
/// negative is backwards): first away from `body`, where the hidden body was last seen —
/// backwards when it was ahead of the robot or beside it, forwards when behind — then the
/// other way.
pub fn back_offs(robot: Pose2, body: Option<Vector2<f64>>) -> [f64; 2] {
    let heading = Vector2::new(robot.theta.cos(), robot.theta.sin());
    let ahead = body.map_or(0.0, |b| heading.dot(&(b - robot.position())));
    if ahead >= -0.01 {
        [-BACK_OFF, BACK_OFF]
    } else {
        [BACK_OFF, -BACK_OFF]
    }
}

/// A body the camera lost: not seen after the robot stopped (waited for, unless the robot may
/// hide it), nor after the robot moved [`BACK_OFF`] away from it either way. Every primitive
/// after it fails with this error, and an evaluation counts the trial as failed
/// ([`crate::exec::deliver::Failure::MarkerLost`]) instead of stopping.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{body} is lost: the camera has not seen its marker since the robot stopped, nor after the \
     robot moved {BACK_OFF} m away from it either way (occluded, out of view, or the marker is \
     gone)"
)]
pub struct BodyLost {
    /// The body's name (`robot`, an object's id).
    pub body: String,
}

/// Whether `e` (or anything it was caused by) is a lost body.
pub fn is_lost(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<BodyLost>())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_robot_backs_away_from_a_body_ahead_or_beside_and_moves_on_from_one_behind() {
        let robot = Pose2::new(0.5, 0.5, std::f64::consts::FRAC_PI_2);
        let away = |body: Vector2<f64>, d: f64| {
            let after = robot.position() + d * Vector2::new(0.0, 1.0);
            (after - body).norm() - (robot.position() - body).norm()
        };
        // Ahead (the robot faces +y), beside, behind: the first move takes it further away.
        for (body, first) in [
            (Vector2::new(0.53, 0.56), -BACK_OFF),
            (Vector2::new(0.56, 0.5), -BACK_OFF),
            (Vector2::new(0.47, 0.44), BACK_OFF),
        ] {
            let moves = back_offs(robot, Some(body));
            assert_eq!(moves, [first, -first], "{body:?}");
            assert!(away(body, moves[0]) > 0.015, "{body:?}");
        }
        // Never seen: backwards first.
        assert_eq!(back_offs(robot, None), [-BACK_OFF, BACK_OFF]);
    }

    #[test]
    fn only_a_body_last_seen_near_the_robot_may_be_hidden_by_it() {
        let robot = Some(Pose2::new(0.5, 0.5, 0.0));
        assert!(robot_may_hide(
            "object",
            robot,
            Some(Vector2::new(0.55, 0.53))
        ));
        assert!(!robot_may_hide(
            "object",
            robot,
            Some(Vector2::new(0.62, 0.5))
        ));
        assert!(!robot_may_hide(
            "robot",
            robot,
            Some(Vector2::new(0.5, 0.5))
        ));
        assert!(!robot_may_hide("object", robot, None));
        assert!(!robot_may_hide(
            "object",
            None,
            Some(Vector2::new(0.5, 0.5))
        ));
    }

    #[test]
    fn a_lost_body_is_found_behind_the_context_it_is_wrapped_in() {
        let lost = BodyLost {
            body: "object".into(),
        };
        let e = anyhow::Error::new(lost.clone()).context("Move did not end");
        assert!(is_lost(&e));
        assert!(e.chain().any(|c| c.to_string().contains("object is lost")));
        assert!(!is_lost(&anyhow::anyhow!("object is lost, says a string")));
    }
}

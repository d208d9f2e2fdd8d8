//! The last leg of a delivery along a path (Lau, Mitani & Igarashi §III-E, Algorithm 2, with
//! this project's rules near the goal among obstacles): where it aims the marker
//! ([`DeliveryParams::goal_wall_offset`]) and which strategy its special case asks
//! ([`DeliveryParams::last_leg_turn_weight`]). Used by [`crate::exec::deliver`].

use nalgebra::Vector2;

use crate::exec::delivery_params::DeliveryParams;
use crate::exec::io::Workspace;
use crate::planner::global::away_from_obstacles;
use crate::strategy::regression::{KernelParams, PushStrategy};

/// The strategy the last leg asks when [`DeliveryParams::last_leg_turn_weight`] is set: the
/// samples keyed on the body's centre `body` with that turn weight; `None` when it is not set.
pub(crate) fn last_leg_strategy(
    strategy: &PushStrategy,
    body: [f64; 2],
    p: &DeliveryParams,
) -> Option<PushStrategy> {
    (p.last_leg_turn_weight > 0.0).then(|| {
        let mut k = strategy.about(body);
        k.set_params(KernelParams {
            turn_weight: p.last_leg_turn_weight,
            ..k.params()
        });
        k
    })
}

/// Where the last leg along a path aims the marker: `goal`, or where the robot has no room
/// between the object at the goal and the nearest obstacle, [`DeliveryParams::goal_wall_offset`]
/// from it away from the obstacle.
pub(crate) fn last_leg_aim(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    goal: Vector2<f64>,
    p: &DeliveryParams,
) -> Vector2<f64> {
    let no_room = ws.body.radius + 2.0 * ws.robot_radius + p.bound_all_margin;
    match away_from_obstacles(goal, obstacles) {
        Some((d, away)) if p.goal_wall_offset > 0.0 && d < no_room => {
            goal + away * p.goal_wall_offset.min(p.success_radius)
        }
        _ => goal,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strategy::sample::Sample;

    /// Beside the zigzag's second wall (its face 15 cm from the goal: no room for the robot
    /// between it and a 7.6 cm object there) the last leg aims 1.1 cm off the goal, away from
    /// the face; 25 cm from it, or with the offset off, at the goal. Never beyond the success
    /// radius.
    #[test]
    fn the_last_leg_aims_away_from_a_wall_the_robot_cannot_stand_at() {
        let ws = crate::exec::test_tables::lau_table(0.076);
        let wall = vec![vec![[1.0, 0.4], [1.1, 0.4], [1.1, 1.2], [1.0, 1.2]]];
        let p = DeliveryParams {
            goal_wall_offset: 0.011,
            ..DeliveryParams::default()
        };
        let aim = last_leg_aim(&ws, &wall, Vector2::new(1.25, 0.6), &p);
        assert!((aim - Vector2::new(1.261, 0.6)).norm() < 1e-12, "{aim}");
        let open = Vector2::new(1.35, 0.6);
        assert_eq!(last_leg_aim(&ws, &wall, open, &p), open);
        let goal = Vector2::new(1.25, 0.6);
        assert_eq!(
            last_leg_aim(&ws, &wall, goal, &DeliveryParams::default()),
            goal
        );
        assert_eq!(last_leg_aim(&ws, &[], goal, &p), goal);
        let far = DeliveryParams {
            goal_wall_offset: 0.5,
            ..p
        };
        let aim = last_leg_aim(&ws, &wall, goal, &far);
        assert!(((aim - goal).norm() - far.success_radius).abs() < 1e-12);
    }

    /// The last leg's strategy: none unless its turn weight is set; with it, the same samples
    /// keyed on the body's centre, and only the turn weight changed.
    #[test]
    fn the_last_leg_asks_the_body_keyed_samples_with_its_turn_weight() {
        let s = Sample {
            p: [-0.08, 0.0],
            r: [0.04, 0.0],
            s: [0.03, 0.01],
            theta: 0.2,
        };
        let strategy = PushStrategy::new([s], KernelParams::default());
        let body = [0.04, 0.035];
        assert!(last_leg_strategy(&strategy, body, &DeliveryParams::default()).is_none());
        let p = DeliveryParams {
            last_leg_turn_weight: 0.06,
            ..DeliveryParams::default()
        };
        let k = last_leg_strategy(&strategy, body, &p).unwrap();
        assert_eq!(
            k.params(),
            KernelParams {
                turn_weight: 0.06,
                ..strategy.params()
            }
        );
        assert_eq!(k.samples(), strategy.about(body).samples());
    }
}

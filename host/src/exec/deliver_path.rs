//! Delivery among obstacles (Lau, Mitani & Igarashi §III-E, last paragraph): the global path
//! ([`crate::planner::global`]) planned from the object's observed position, and Algorithm 2
//! ([`crate::exec::deliver::deliver_learned_among`]) pushing the object towards the path's
//! moving sub-goal, `lookahead` further along the path than the object
//! ([`crate::planner::path_follow`]), until it reaches the goal within the success radius.
//! Near a wall a push that drifted the object towards it is not continued: the robot cannot
//! stand between the wall and the object to push it back, so the special case re-positions at
//! once ([`crate::exec::drift`]). On the last leg, where the marker is pushed to the goal past
//! the path's sub-goals, a general-case push is made only from where the samples have pushed
//! the object the wanted way ([`ObstacleParams::last_leg_trust`]), and where the goal is too
//! near a wall for the robot to stand between them, the marker is aimed a little away from the
//! wall, inside the success radius ([`ObstacleParams::goal_wall_offset`]).
//!
//! A leg that makes no progress along its path for `stall_time` (the object caught on a
//! corner) is a **stall**, never a silent time-out: the robot backs off the object, the path is
//! planned again from the object's measured pose, and the look-ahead shortens (halved at each
//! stall in a row); from the second stall in a row the object is first pushed a little from a
//! side the robot can reach. Each recovery is recorded ([`Recovery`]); after `max_recoveries`
//! the delivery fails as stalled.

use anyhow::Result;
use nalgebra::Vector2;

use crate::exec::deliver::{
    Delivery, DeliveryParams, Failure, Recovery, bound_all_circle, deliver_learned_among,
};
use crate::exec::io::RobotIo;
use crate::exec::maneuver::{Around, outline_on_table};
use crate::exec::reposition::{BoundAll, approach_radius, recorded_pushes};
use crate::planner::detour::shortcut_object_path;
use crate::planner::global::{ObstacleParams, clearance, plan_object_path};
use crate::planner::path_follow::PathFollower;
use crate::strategy::regression::PushStrategy;
use crate::strategy::sample::Sample;

/// How a delivery among obstacles went.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ObstacleDelivery {
    /// The whole delivery (time, steps and trajectory over all legs).
    pub delivery: Delivery,
    /// Where the moving sub-goal was when each leg ended (a leg ends at the goal, a stall or
    /// a failure; one leg per planned path).
    pub subgoals: Vec<[f64; 2]>,
    /// The first global path planned.
    pub path: Vec<[f64; 2]>,
}

/// Deliver the object to `goal` among `obstacles` (table-frame polygons): plan a global path,
/// push along its sub-goals with Algorithm 2, re-planning before every leg.
pub fn deliver_among_obstacles(
    io: &mut dyn RobotIo,
    strategy: &mut PushStrategy,
    goal: Vector2<f64>,
    obstacles: &[Vec<[f64; 2]>],
    params: &DeliveryParams,
    op: &ObstacleParams,
    sink: &mut dyn FnMut(&Sample) -> Result<()>,
) -> Result<ObstacleDelivery> {
    let start = io.time();
    let ws = io.workspace();
    let mut all = Delivery::failed(None, 0.0, f64::NAN);
    let mut subgoals = Vec::new();
    let mut first_path = Vec::new();
    // Look-ahead of the moving sub-goal: halved at each stall in a row (the object is then
    // kept closer to the path), back to the default after progress.
    let mut lookahead = op.lookahead;
    let mut stalls_in_a_row = 0;
    // The path is planned for the object's smallest enclosing circle (its outline swept
    // through every rotation about that circle's centre), not for the circle round its marker:
    // for an object marked off its middle (the L-shape's marker is in its corner, 11.7 cm from
    // its furthest vertex against 9.2 cm) the marker's circle closes a 0.3 m corridor to a
    // 4.6 cm band and still lets the outline touch a wall when the marker is in the middle.
    let body_ws = ws.body_workspace();
    loop {
        let o = ws.body_centre(&io.object_pose());
        let left = params.time_limit - (io.time() - start);
        let Some(path) = plan_object_path(&body_ws, obstacles, o, goal, op) else {
            all.failure = Some(Failure::NoPath);
            break;
        };
        let path = shortcut_object_path(&body_ws, obstacles, &path, op);
        let shown: Vec<[f64; 2]> = path.iter().map(|v| [v.x, v.y]).collect();
        io.show_path(&shown);
        if first_path.is_empty() {
            first_path.clone_from(&shown);
        }
        all.paths.push(shown);
        let Some(mut follow) =
            PathFollower::new(&path, lookahead).map(|f| f.with_end_blend(op.end_blend))
        else {
            all.failure = Some(Failure::NoPath);
            break;
        };
        let leg_params = DeliveryParams {
            time_limit: left,
            stall_time: op.stall_time,
            last_leg_trust: op.last_leg_trust,
            goal_wall_offset: op.goal_wall_offset,
            last_leg_turn_weight: op.last_leg_turn_weight,
            reposition_angle: op.reposition_angle,
            wall_near: op.wall_near,
            wall_reposition_angle: op.wall_reposition_angle,
            ..*params
        };
        let d = deliver_learned_among(
            io,
            strategy,
            goal,
            &leg_params,
            obstacles,
            Some(&mut follow),
            sink,
        )?;
        let failure = d.failure;
        add_leg(&mut all, d);
        let marker = io.object_pose();
        let (o, centre) = (marker.position(), ws.body_centre(&marker));
        let sub = follow.aim(centre).subgoal;
        subgoals.push([sub.x, sub.y]);
        if failure == Some(Failure::Stalled) {
            if all.recoveries.len() >= op.max_recoveries {
                tracing::warn!(
                    "delivery stalled at ({:.3}, {:.3}) after {} recoveries: giving up",
                    o.x,
                    o.y,
                    all.recoveries.len()
                );
                all.failure = Some(Failure::Stalled);
                break;
            }
            stalls_in_a_row += 1;
            lookahead = (op.lookahead / 2f64.powi(stalls_in_a_row)).max(op.subgoal_radius);
            // A second stall in a row: the robot cannot get behind the object for the way the
            // path wants; push it a little from a side it can reach, then plan again.
            // Never further than half the way the marker is from the goal: a stall beside the
            // goal (the marker a few centimetres off it) is nudged, not pushed away.
            let reach = side_step_reach((goal - o).norm());
            let aside = (stalls_in_a_row > 1)
                .then(|| {
                    let bound_all = bound_all_circle(&ws, &marker, params.bound_all_margin, false);
                    side_step(io, obstacles, strategy, sub - centre, reach, op, &bound_all)
                })
                .flatten();
            let action = match aside {
                Some(t) => format!(
                    "back off, push to ({:.3}, {:.3}) from a side the robot can reach, re-plan, look-ahead {lookahead:.3} m",
                    t.x, t.y
                ),
                None => format!("back off and re-plan, look-ahead {lookahead:.3} m"),
            };
            tracing::info!(
                "delivery stalled at ({:.3}, {:.3}) pushing to ({:.3}, {:.3}): {action}",
                o.x,
                o.y,
                sub.x,
                sub.y
            );
            all.recoveries.push(Recovery {
                t: io.time() - start,
                at: [o.x, o.y],
                subgoal: [sub.x, sub.y],
                action,
            });
            back_off(io, op)?;
            if let Some(t) = aside {
                let left = params.time_limit - (io.time() - start);
                let side = DeliveryParams {
                    time_limit: left.min(op.stall_time),
                    success_radius: (op.subgoal_radius / 2.0).min(reach / 2.0),
                    fine_radius: op.subgoal_radius,
                    stall_time: op.stall_time / 2.0,
                    wall_near: op.wall_near,
                    wall_reposition_angle: op.wall_reposition_angle,
                    ..*params
                };
                let d = deliver_learned_among(io, strategy, t, &side, obstacles, None, sink)?;
                add_leg(&mut all, d);
            }
            continue;
        }
        all.failure = failure;
        all.success = failure.is_none();
        break;
    }
    all.time = io.time() - start;
    all.final_distance = (goal - io.object_pose().position()).norm();
    Ok(ObstacleDelivery {
        delivery: all,
        subgoals,
        path: first_path,
    })
}

/// Add one leg's pushes, paths and trajectory to the whole delivery.
fn add_leg(all: &mut Delivery, d: Delivery) {
    all.steps += d.steps;
    all.repositions += d.repositions;
    all.object_path += d.object_path;
    all.robot_path += d.robot_path;
    all.body_path += d.body_path;
    all.trajectory.extend(d.trajectory);
}

/// Back the robot off the object it stalled against: straight back by the object's clearance
/// margin plus a robot radius, where the table leaves room.
fn back_off(io: &mut dyn RobotIo, op: &ObstacleParams) -> Result<()> {
    let ws = io.workspace();
    let r = io.robot_pose();
    let back = ws.robot_radius + op.room_margin;
    let behind = r.position() - back * nalgebra::Vector2::new(r.theta.cos(), r.theta.sin());
    if ws.table.inset(ws.robot_radius + 0.005).contains(behind) {
        io.forward(-back)?;
    }
    Ok(())
}

/// How far a recovery pushes the object aside, m: at most this, and no further than half the
/// way the marker is from the goal, but at least [`MIN_SIDE_STEP`] ([`side_step_reach`]).
const SIDE_STEP: f64 = 0.08;

/// The shortest push aside, m: a few of the fine pushes' steps.
const MIN_SIDE_STEP: f64 = 0.02;

/// How far a recovery pushes the marker aside when it is `to_goal` from the goal, m. Half the
/// way at most: the nudge and the way back to where it stalled are the path it adds, and beside
/// the goal a push as long as the way left took the L-shape past the goal
/// and back, 1.53–1.64× its shortest path in the zigzag's pocket (1.41–1.44× at half).
fn side_step_reach(to_goal: f64) -> f64 {
    SIDE_STEP.min(0.5 * to_goal).max(MIN_SIDE_STEP)
}

/// A recorded push counts for a direction aside when it moved the object within this of it,
/// rad (the sixteen directions are 22.5° apart).
const SIDE_STEP_OFF: f64 = 0.2;

/// Where to push the object's marker when it stalled while wanted along `want`: of sixteen
/// directions, those for which the learned special case (Algorithm 2), or a recorded push that
/// moved the object that way ([`recorded_pushes`]), stands the robot where it fits and can get
/// to from where it is ([`approach_radius`]) and the object's enclosing
/// circle ends no closer to an obstacle than its clearance (or than it is now), the one
/// nearest to `want`.
fn side_step(
    io: &mut dyn RobotIo,
    obstacles: &[Vec<[f64; 2]>],
    strategy: &PushStrategy,
    want: Vector2<f64>,
    reach: f64,
    op: &ObstacleParams,
    bound_all: &BoundAll,
) -> Option<Vector2<f64>> {
    let want = want.try_normalize(1e-9)?;
    let (ws, o, from) = (io.workspace(), io.object_pose(), io.robot_pose().position());
    let ws = &ws;
    let o = &o;
    let here = ws.body_centre(o);
    let keep = clearance(here, obstacles).min(ws.body.radius + op.object_margin);
    let object = outline_on_table(&io.object_outline(), o);
    let keep_clear = Around {
        obstacles,
        object: &object,
    };
    (0..16)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 16.0;
            Vector2::new(a.cos(), a.sin())
        })
        .filter(|d| {
            let t = here + d * reach;
            let local = o.vector_to_local(*d);
            ws.boundary.contains(o.position() + d * reach)
                && clearance(t, obstacles) >= keep
                && strategy
                    .special([local.x, local.y])
                    .into_iter()
                    .chain(
                        recorded_pushes(strategy, [local.x, local.y], SIDE_STEP_OFF).map(|c| c.1),
                    )
                    .any(|rep| approach_radius(ws, &keep_clear, o, from, &rep, bound_all).is_some())
        })
        .max_by(|a, b| a.dot(&want).total_cmp(&b.dot(&want)))
        .map(|d| o.position() + d * reach)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Far from the goal the side step is the full 8 cm; beside it half the way left (a marker
    /// 6 cm off is nudged 3 cm, not carried past the goal), never under 2 cm.
    #[test]
    fn the_side_step_reaches_half_the_way_to_the_goal() {
        assert_eq!(side_step_reach(0.5), SIDE_STEP);
        assert!((side_step_reach(0.06) - 0.03).abs() < 1e-12);
        assert_eq!(side_step_reach(0.01), MIN_SIDE_STEP);
    }
}

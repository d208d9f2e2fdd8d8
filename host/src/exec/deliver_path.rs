//! Delivery among obstacles (Lau, Mitani & Igarashi §III-E, last paragraph): the global path
//! ([`crate::planner::global`]) re-planned from the object's observed position before each leg,
//! and Algorithm 2 ([`crate::strategy::deliver::deliver_learned_among`]) pushing to the path's
//! point `subgoal_spacing` ahead (a sub-goal, reached within `subgoal_radius`), until the last
//! leg reaches the goal within the success radius.
//!
//! A leg that makes no progress towards its sub-goal for `stall_time` (the object caught on a
//! corner, the path looping) is a **stall**, never a silent time-out: the robot backs off the
//! object, the path is planned again from the object's measured pose, and the sub-goals come
//! closer together (halved at each stall in a row). Each recovery is recorded
//! ([`Recovery`]); after `max_recoveries` the delivery fails as stalled.

use anyhow::Result;
use nalgebra::Vector2;

use crate::exec::deliver::{Delivery, DeliveryParams, Failure, Recovery, deliver_learned_among};
use crate::exec::io::RobotIo;
use crate::planner::global::{ObstacleParams, plan_object_path, point_along};
use crate::strategy::regression::PushStrategy;
use crate::strategy::sample::Sample;

/// How a delivery among obstacles went.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ObstacleDelivery {
    /// The whole delivery (time, steps and trajectory over all legs).
    pub delivery: Delivery,
    /// The sub-goals pushed to, in order (the last is the goal when reached).
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
    let mut all = Delivery {
        success: false,
        failure: None,
        time: 0.0,
        steps: 0,
        repositions: 0,
        recoveries: Vec::new(),
        object_path: 0.0,
        robot_path: 0.0,
        final_distance: f64::NAN,
        trajectory: Vec::new(),
    };
    let mut subgoals = Vec::new();
    let mut first_path = Vec::new();
    let mut legs = 0;
    // Sub-goal spacing: halved at each stall in a row, back to the default after progress.
    let mut spacing = op.subgoal_spacing;
    let mut stalls_in_a_row = 0;
    loop {
        let o = io.object_pose().position();
        let left = params.time_limit - (io.time() - start);
        let Some(path) = plan_object_path(&ws, obstacles, o, goal, op) else {
            all.failure = Some(Failure::NoPath);
            break;
        };
        let shown: Vec<[f64; 2]> = path.iter().map(|v| [v.x, v.y]).collect();
        io.show_path(&shown);
        if first_path.is_empty() {
            first_path = shown;
        }
        let length: f64 = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let last = length <= spacing * 1.5;
        let sub = if last {
            goal
        } else {
            point_along(&path, spacing).unwrap_or(goal)
        };
        subgoals.push([sub.x, sub.y]);
        let leg_params = if last {
            DeliveryParams {
                time_limit: left,
                stall_time: op.stall_time,
                ..*params
            }
        } else {
            DeliveryParams {
                time_limit: left,
                success_radius: op.subgoal_radius,
                fine_radius: op.subgoal_radius,
                stall_time: op.stall_time,
                ..*params
            }
        };
        legs += 1;
        let d = deliver_learned_among(io, strategy, sub, &leg_params, obstacles, sink)?;
        all.steps += d.steps;
        all.repositions += d.repositions;
        all.object_path += d.object_path;
        all.robot_path += d.robot_path;
        all.trajectory.extend(d.trajectory);
        if d.failure == Some(Failure::Stalled) {
            let o = io.object_pose().position();
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
            spacing =
                (op.subgoal_spacing / 2f64.powi(stalls_in_a_row)).max(1.5 * op.subgoal_radius);
            let action = format!("back off and re-plan, sub-goals every {spacing:.3} m");
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
            continue;
        }
        if !d.success {
            all.failure = d.failure;
            break;
        }
        spacing = op.subgoal_spacing;
        stalls_in_a_row = 0;
        if last {
            all.success = true;
            break;
        }
        if legs > 200 {
            all.failure = Some(Failure::TimeLimit);
            break;
        }
    }
    all.time = io.time() - start;
    all.final_distance = (goal - io.object_pose().position()).norm();
    Ok(ObstacleDelivery {
        delivery: all,
        subgoals,
        path: first_path,
    })
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

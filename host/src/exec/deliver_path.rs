//! Delivery among obstacles (Lau, Mitani & Igarashi §III-E, last paragraph): the global path
//! ([`crate::planner::global`]) re-planned from the object's observed position before each leg,
//! and Algorithm 2 ([`crate::strategy::deliver::deliver_learned_among`]) pushing to the path's
//! point `subgoal_spacing` ahead (a sub-goal, reached within `subgoal_radius`), until the last
//! leg reaches the goal within the success radius.

use anyhow::Result;
use nalgebra::Vector2;

use crate::exec::deliver::{Delivery, DeliveryParams, Failure, deliver_learned_among};
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
        object_path: 0.0,
        robot_path: 0.0,
        final_distance: f64::NAN,
        trajectory: Vec::new(),
    };
    let mut subgoals = Vec::new();
    let mut first_path = Vec::new();
    let mut legs = 0;
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
        let last = length <= op.subgoal_spacing * 1.5;
        let sub = if last {
            goal
        } else {
            point_along(&path, op.subgoal_spacing).unwrap_or(goal)
        };
        subgoals.push([sub.x, sub.y]);
        let leg_params = if last {
            DeliveryParams {
                time_limit: left,
                ..*params
            }
        } else {
            DeliveryParams {
                time_limit: left,
                success_radius: op.subgoal_radius,
                fine_radius: op.subgoal_radius,
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
        if !d.success {
            all.failure = d.failure;
            break;
        }
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

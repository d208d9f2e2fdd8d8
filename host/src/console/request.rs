//! What the page asks for, read and checked exactly as the CLI checks its arguments: a task
//! with its object, goal and method becomes a [`Task`] only when the goal is on the table, clear
//! of the obstacles and within reach; otherwise the page is told why and nothing moves.

use std::path::Path;

use pushbot_world::Scene;

use crate::task::Task;
use crate::task::goal::GoalPose;

/// A task as the page asks for it.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskRequest {
    /// `deliver`, `rearrange` or `collect`.
    pub task: String,
    /// The object (deliver, collect).
    #[serde(default)]
    pub object: Option<String>,
    /// Its goal (deliver).
    #[serde(default)]
    pub goal: Option<GoalPose>,
    /// `learned` (default) or `dipole` (deliver).
    #[serde(default)]
    pub method: Option<String>,
    /// Goals of the movables (rearrange): id and pose.
    #[serde(default)]
    pub goals: Vec<IdGoal>,
    /// `exact` or `practical` (rearrange).
    #[serde(default)]
    pub mode: Option<String>,
}

/// A movable's goal.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdGoal {
    /// The movable.
    pub id: String,
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// Heading, degrees.
    #[serde(default)]
    pub deg: Option<f64>,
}

/// What a console can run: its table, and where strategies are kept.
pub struct Context<'a> {
    /// The table.
    pub scene: &'a Scene,
    /// The rearrangement problem of the table, when it is one.
    pub rearrange: Option<&'a crate::planner::rearrange::problem::Problem>,
    /// Where strategies are kept (`OBJECT.strategy`).
    pub strategies: &'a Path,
    /// Whether the robot is the built-in target (a missing strategy is collected in simulation).
    pub builtin: bool,
    /// Seed of such a collection.
    pub seed: u64,
}

/// The task `r` asks for, or why not.
pub fn build(r: &TaskRequest, cx: &Context<'_>) -> Result<Task, String> {
    use crate::task::{collect, deliver, rearrange};
    let object = || -> Result<String, String> {
        let id = r
            .object
            .clone()
            .ok_or_else(|| "pick an object first".to_string())?;
        if id.len() > 200 || cx.scene.object(&id).is_none() {
            return Err(format!("the table has no object {id:?}"));
        }
        Ok(id)
    };
    match r.task.as_str() {
        "deliver" => {
            let id = object()?;
            let goal = r
                .goal
                .ok_or_else(|| "place the goal on the table first".to_string())?;
            // The goal is checked before any strategy is loaded or collected.
            deliver::Deliver::new(cx.scene, &id, goal, deliver::Method::Dipole).map_err(|e| e.0)?;
            let method = match r.method.as_deref().unwrap_or("learned") {
                "dipole" => deliver::Method::Dipole,
                "learned" => {
                    let path = cx.strategies.join(format!("{id}.strategy"));
                    deliver::Method::Learned(
                        deliver::load_strategy(cx.scene, &id, &path, cx.builtin, cx.seed)
                            .map_err(|e| e.0)?,
                    )
                }
                m => return Err(format!("unknown method {m:?}: learned or dipole")),
            };
            Ok(Task::Deliver(
                deliver::Deliver::new(cx.scene, &id, goal, method).map_err(|e| e.0)?,
            ))
        }
        "rearrange" => {
            let problem = cx
                .rearrange
                .ok_or_else(|| "this table is not a rearrangement grid".to_string())?;
            let goals: Vec<(String, GoalPose)> = r
                .goals
                .iter()
                .map(|g| {
                    (
                        g.id.clone(),
                        GoalPose {
                            x: g.x,
                            y: g.y,
                            deg: g.deg,
                        },
                    )
                })
                .collect();
            let mode = match r.mode.as_deref() {
                None => None,
                Some("exact") => Some(rearrange::Mode::Exact),
                Some("practical") => Some(rearrange::Mode::Practical),
                Some(m) => return Err(format!("unknown mode {m:?}: exact or practical")),
            };
            Ok(Task::Rearrange(
                rearrange::Rearrange::new(problem.clone(), &goals, mode).map_err(|e| e.0)?,
            ))
        }
        "collect" => {
            let id = object()?;
            let out = cx.strategies.join(format!("{id}.strategy"));
            Ok(Task::Collect(
                collect::Collect::new(
                    cx.scene,
                    &id,
                    out,
                    crate::exec::collect::CollectParams {
                        seed: cx.seed,
                        ..Default::default()
                    },
                )
                .map_err(|e| e.0)?,
            ))
        }
        t => Err(format!("unknown task {t:?}: deliver, rearrange or collect")),
    }
}

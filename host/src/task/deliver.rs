//! Deliver one object to a position the operator chose, among the scene's obstacles: Lau,
//! Mitani & Igarashi's learned strategy along a global path (§III-E, Algorithm 2), or the
//! dipole field they compare it with. Starts from where the camera sees the object.

use anyhow::{Result, anyhow};
use nalgebra::Vector2;

use super::goal::{GoalError, GoalPose, Reach, check_goal};
use super::{Control, EventSink, Failed, Outcome, Session, TaskEvent, drive, marker_truth};
use crate::exec::deliver::{DeliveryParams, deliver_dipole};
use crate::exec::deliver_path::deliver_among_obstacles;
use crate::exec::io::RobotIo;
use crate::planner::global::{ObstacleParams, plan_object_path, scene_obstacles};
use crate::report::StageReport;
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::Sample;

/// How the object is pushed.
#[derive(Debug, Clone)]
pub enum Method {
    /// The learned pushing strategy (its samples).
    Learned(Vec<Sample>),
    /// The dipole field (no learning, no obstacles).
    Dipole,
}

/// A delivery.
#[derive(Debug, Clone)]
pub struct Deliver {
    /// The object's id in the scene.
    pub object: String,
    /// Where its marker should end.
    pub goal: GoalPose,
    /// How it is pushed.
    pub method: Method,
    /// Delivery settings (success radius, time limit …).
    pub params: DeliveryParams,
}

impl Deliver {
    /// A delivery of `object` to `goal` on `scene`'s table, the goal checked first: on the
    /// table, clear of every obstacle, inside the region the robot can push in. A heading is
    /// refused: the strategy delivers to a position.
    pub fn new(
        scene: &pushbot_world::Scene,
        object: &str,
        goal: GoalPose,
        method: Method,
    ) -> Result<Deliver, GoalError> {
        let o = scene.object(object).ok_or_else(|| {
            GoalError(format!(
                "the scene {} has no object {object:?} (it has: {})",
                scene.name,
                scene
                    .objects
                    .iter()
                    .map(|o| o.id.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        if o.marker.is_none() {
            return Err(GoalError(format!(
                "{object} has no marker: the camera cannot follow it"
            )));
        }
        if goal.deg.is_some() {
            return Err(GoalError(
                "a delivery reaches a position (X,Y); for a heading too, push with stable pushes \
                 (`pushbot run stable --goal X,Y,DEG`)"
                    .into(),
            ));
        }
        check_goal(scene, object, &goal, reach(scene, object))?;
        Ok(Deliver {
            object: object.to_string(),
            goal,
            method,
            params: DeliveryParams::default(),
        })
    }

    /// In words.
    pub fn summary(&self) -> String {
        format!(
            "deliver {} to ({:.3}, {:.3}) m with {}",
            self.object,
            self.goal.x,
            self.goal.y,
            match &self.method {
                Method::Learned(s) => format!("the learned strategy ({} samples)", s.len()),
                Method::Dipole => "the dipole field".into(),
            }
        )
    }

    fn goal(&self) -> Vector2<f64> {
        Vector2::new(self.goal.x, self.goal.y)
    }

    /// The object's global path from where the camera sees it.
    pub fn plan(&self, session: &mut Session) -> Result<TaskEvent> {
        session.live.set_object(&self.object)?;
        let ws = session.live.workspace();
        let o = session.live.object_pose();
        if !(o.x.is_finite() && o.y.is_finite()) {
            return Err(anyhow!("the camera does not see {}", self.object));
        }
        let obstacles = scene_obstacles(&session.scene);
        let start = ws.body_centre(&o);
        let path = match self.method {
            Method::Dipole => vec![start, self.goal()],
            Method::Learned(_) => plan_object_path(
                &ws.body_workspace(),
                &obstacles,
                start,
                self.goal(),
                &ObstacleParams::default(),
            )
            .ok_or_else(|| {
                anyhow!(
                    "no path for {} from ({:.3}, {:.3}) to the goal among the obstacles",
                    self.object,
                    o.x,
                    o.y
                )
            })?,
        };
        Ok(TaskEvent::Plan {
            paths: vec![path.iter().map(|v| [v.x, v.y]).collect()],
            note: format!("{}'s path from where the camera sees it", self.object),
        })
    }

    /// Deliver.
    pub fn run(
        &self,
        session: &mut Session,
        control: &Control,
        events: &EventSink,
    ) -> Result<Outcome, Failed> {
        session
            .live
            .set_object(&self.object)
            .map_err(|e| (e, Vec::new()))?;
        if let Ok(plan) = self.plan(session) {
            events(&plan);
        }
        let obstacles = scene_obstacles(&session.scene);
        let goal = self.goal();
        let ids = vec![self.object.clone()];
        let (d, trace) = drive(session, &ids, true, control, events, |io| {
            Ok(match &self.method {
                Method::Learned(samples) => {
                    let mut strategy =
                        PushStrategy::new(samples.iter().copied(), KernelParams::default());
                    let r = deliver_among_obstacles(
                        io,
                        &mut strategy,
                        goal,
                        &obstacles,
                        &self.params,
                        &ObstacleParams::default(),
                        &mut |_| Ok(()),
                    )?;
                    (r.delivery, r.subgoals.len())
                }
                Method::Dipole => (deliver_dipole(io, goal, &self.params)?, 1),
            })
        })?;
        let (d, legs) = d;
        let truth = marker_truth(&session.scene, &self.object, &trace)
            .map(|m| (m[0] - goal.x).hypot(m[1] - goal.y));
        let judged = truth.unwrap_or(d.final_distance);
        let success = judged <= self.params.success_radius;
        let mut rep = StageReport::new(
            "deliver",
            &format!(
                "Deliver {} to ({:.2}, {:.2}) m",
                self.object, goal.x, goal.y
            ),
            match self.method {
                Method::Learned(_) => "Lau, Mitani & Igarashi §III-E (Algorithm 2)",
                Method::Dipole => "the dipole field (Igarashi et al.), Lau et al.'s baseline",
            },
        );
        rep.success = success;
        rep.number("Pushes", d.steps);
        rep.number("Re-positionings", d.repositions);
        rep.number("Legs of the path", legs);
        rep.number(
            "Distance from the goal, camera (mm)",
            round1(d.final_distance * 1e3),
        );
        if let Some(t) = truth {
            rep.number("Distance from the goal, truth (mm)", round1(t * 1e3));
        }
        rep.number(
            "Success radius (mm)",
            round1(self.params.success_radius * 1e3),
        );
        let message = if success {
            format!(
                "{} delivered: {:.1} mm from the goal",
                self.object,
                judged * 1e3
            )
        } else {
            format!(
                "{} not delivered: {:.1} mm from the goal{}",
                self.object,
                judged * 1e3,
                d.failure
                    .as_ref()
                    .map_or(String::new(), |f| format!(" ({f:?})"))
            )
        };
        rep.notes.push(message.clone());
        Ok(Outcome {
            success,
            stopped: None,
            message,
            summary: serde_json::json!({
                "object": self.object,
                "goal": [goal.x, goal.y],
                "pushes": d.steps,
                "repositions": d.repositions,
                "final_distance_m": d.final_distance,
                "truth_distance_m": truth,
                "success_radius_m": self.params.success_radius,
            }),
            report: rep,
            trace,
        })
    }
}

/// What a goal of `object` must keep clear of on `scene`'s table.
pub fn reach(scene: &pushbot_world::Scene, object: &str) -> Reach {
    let o = scene.object(object);
    let marker = o.and_then(|o| o.marker).map_or([0.0, 0.0], |m| [m.x, m.y]);
    let radius = o.map_or(0.0, |o| {
        o.outline
            .iter()
            .map(|v| (v[0] - marker[0]).hypot(v[1] - marker[1]))
            .fold(0.0, f64::max)
    });
    Reach {
        object_radius: radius,
        inset: crate::exec::LiveOptions::default().boundary_inset,
    }
}

/// `x` to one decimal.
pub(crate) fn round1(x: f64) -> f64 {
    (x * 10.0).round() / 10.0
}

/// The samples of the strategy for `object` at `path`. A missing file is collected there first
/// in simulation when `builtin` (the built-in target's world is the simulator's); on a real
/// robot it must be collected on the robot (`pushbot collect --port`).
pub fn load_strategy(
    scene: &pushbot_world::Scene,
    object: &str,
    path: &std::path::Path,
    builtin: bool,
    seed: u64,
) -> Result<Vec<Sample>, GoalError> {
    if path.exists() {
        let f = crate::strategy::store::load(path)
            .map_err(|e| GoalError(format!("the strategy {}: {e}", path.display())))?;
        if f.object != object {
            return Err(GoalError(format!(
                "the strategy {} is for {:?}, not for {object:?}",
                path.display(),
                f.object
            )));
        }
        return Ok(f.samples);
    }
    if !builtin {
        return Err(GoalError(format!(
            "no strategy {}: collect one on the robot first (`pushbot collect --object {object} \
             --port PORT --camera CAMERA --out {}`, or Collect in the console), or push with \
             the dipole field",
            path.display(),
            path.display()
        )));
    }
    collect_in_sim(scene, object, path, seed)
}

#[cfg(feature = "sim")]
fn collect_in_sim(
    scene: &pushbot_world::Scene,
    object: &str,
    path: &std::path::Path,
    seed: u64,
) -> Result<Vec<Sample>, GoalError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| GoalError(format!("creating {}: {e}", dir.display())))?;
    }
    let sim = crate::sim::robot::SimRobotOptions {
        seed,
        ..Default::default()
    };
    let params = crate::exec::collect::CollectParams {
        seed,
        ..Default::default()
    };
    crate::experiments::delivery::collect_or_load(
        scene,
        Some(object),
        path,
        sim,
        &params,
        KernelParams::default(),
        &indicatif::ProgressBar::hidden(),
    )
    .map(|(s, _)| s)
    .map_err(|e| {
        GoalError(format!(
            "collecting a strategy for {object} in simulation: {e:#}"
        ))
    })
}

#[cfg(not(feature = "sim"))]
fn collect_in_sim(
    _: &pushbot_world::Scene,
    object: &str,
    path: &std::path::Path,
    _: u64,
) -> Result<Vec<Sample>, GoalError> {
    Err(GoalError(format!(
        "no strategy {} for {object}, and this build has no simulator to collect one in",
        path.display()
    )))
}

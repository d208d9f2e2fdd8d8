//! Push the slider to a goal pose with stable pushes: Lynch & Mason §4's planner, planned from
//! where the camera sees the slider (not the scene's start) to the scene's goal or the
//! operator's, and driven closed loop inside the stable set
//! ([`crate::exec::stable_feedback`]).

use anyhow::{Result, anyhow};

use super::goal::{GoalError, GoalPose, Reach, check_goal};
use super::{Control, EventSink, Failed, Outcome, Session, TaskEvent, drive};
use crate::exec::stable_feedback::{FeedbackParams, execute_closed_loop};
use crate::exec::stable_replan::plan_clear;
use crate::experiments::stable_trials::StableTask;
use crate::planner::stable::{Plan, Pose, Problem};
use crate::report::StageReport;

/// A stable push.
#[derive(Debug, Clone)]
pub struct Stable {
    /// The planned task of the scene (its problem and the robot's scene).
    pub task: StableTask,
}

impl Stable {
    /// The stable task `task` with its goal moved to `goal` (a heading in degrees, or the
    /// scene's), checked on the table.
    pub fn new(mut task: StableTask, goal: Option<GoalPose>) -> Result<Stable, GoalError> {
        if let Some(g) = goal {
            let scene = task.sim_scene().map_err(|e| GoalError(format!("{e:#}")))?;
            let radius = task
                .problem
                .slider
                .vertices
                .iter()
                .map(|v| v.x.hypot(v.y))
                .fold(0.0, f64::max);
            check_goal(
                &scene,
                "slider",
                &g,
                Reach {
                    object_radius: radius,
                    inset: 0.0,
                },
            )?;
            let theta = g.deg.map_or(task.problem.goal.theta, |d| d.to_radians());
            task.problem.goal = Pose::new(g.x, g.y, theta);
        }
        Ok(Stable { task })
    }

    /// In words.
    pub fn summary(&self) -> String {
        let g = self.task.problem.goal;
        format!(
            "push the slider of {} with stable pushes to ({:.3}, {:.3}) m, {:.0}°",
            self.task.name,
            g.x,
            g.y,
            g.theta.to_degrees()
        )
    }

    /// The problem from where the camera sees the slider, and its plan.
    fn observed(&self, session: &mut Session) -> Result<(Problem, Plan)> {
        let s = crate::exec::io::RobotIo::body_pose(&mut session.live, "slider")
            .ok_or_else(|| anyhow!("the camera does not see the slider"))?;
        let mut p = self.task.problem.clone();
        p.start = Pose::new(s.x, s.y, s.theta);
        p.start_contact = None;
        let plan = plan_clear(&p).filter(|pl| pl.found && !pl.steps.is_empty());
        let Some(plan) = plan else {
            let why = crate::planner::stable::no_plan::why(&p, &crate::planner::stable::plan(&p))
                .map_or_else(String::new, |w| format!(": {w}"));
            return Err(anyhow!(
                "no plan of stable pushes from where the slider is ({:.3}, {:.3}, {:.0}°) to the goal{why}",
                s.x,
                s.y,
                s.theta.to_degrees()
            ));
        };
        Ok((p, plan))
    }

    /// The slider's planned path from where the camera sees it.
    pub fn plan(&self, session: &mut Session) -> Result<TaskEvent> {
        let (_, plan) = self.observed(session)?;
        let mut path = vec![];
        if let Some(s) = plan.steps.first() {
            path.push([s.from.x, s.from.y]);
        }
        path.extend(plan.steps.iter().map(|s| [s.to.x, s.to.y]));
        Ok(TaskEvent::Plan {
            paths: vec![path],
            note: format!(
                "{} stable pushes, cost {}, {} contact changes",
                plan.pushes, plan.cost, plan.contact_changes
            ),
        })
    }

    /// Push.
    pub fn run(
        &self,
        session: &mut Session,
        control: &Control,
        events: &EventSink,
    ) -> Result<Outcome, Failed> {
        let (p, plan) = self.observed(session).map_err(|e| (e, Vec::new()))?;
        if let Ok(ev) = self.plan(session) {
            events(&ev);
        }
        let ids = vec!["slider".to_string()];
        let (run, trace) = drive(session, &ids, false, control, events, |io| {
            execute_closed_loop(&p, &plan, io, &FeedbackParams::default())
        })?;
        if run.replans > 0 {
            events(&TaskEvent::Replan {
                note: format!("{} re-plans from the measured poses", run.replans),
            });
        }
        let end = trace
            .last()
            .and_then(|t| t.truth.as_ref())
            .and_then(|(_, objects)| objects.iter().find(|(id, _)| id == "slider"))
            .map_or(run.end, |(_, q)| Pose::new(q.x, q.y, q.theta));
        let success = p.in_goal(&end);
        let err_mm = (end.x - p.goal.x).hypot(end.y - p.goal.y) * 1e3;
        let mut st = StageReport::new(
            "stable",
            &format!("Stable pushes of the slider ({})", self.task.name),
            "Lynch & Mason §3 (STABLE), §4 (planner), driven closed loop",
        );
        st.success = success;
        st.number("Pushes planned", plan.pushes);
        st.number("Re-plans", run.replans);
        st.number("Contact losses", run.contact_losses);
        st.number(
            "Distance from the goal (mm)",
            super::deliver::round1(err_mm),
        );
        let message = match (&run.failure, success) {
            (_, true) => format!("the slider reached the goal: {err_mm:.1} mm from it"),
            (Some(why), false) => format!("the slider did not reach the goal: {why}"),
            (None, false) => {
                format!("the slider ended {err_mm:.1} mm from the goal, outside its neighbourhood")
            }
        };
        st.notes.push(message.clone());
        Ok(Outcome {
            success,
            stopped: None,
            message,
            summary: serde_json::json!({
                "end": [end.x, end.y, end.theta],
                "goal": [p.goal.x, p.goal.y, p.goal.theta],
                "error_mm": err_mm,
                "replans": run.replans,
                "contact_losses": run.contact_losses,
            }),
            report: st,
            trace,
        })
    }
}

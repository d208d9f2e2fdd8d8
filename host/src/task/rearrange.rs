//! Rearrange the boxes on the table into a goal arrangement, from where the camera sees them:
//! Ben-Shahar & Rivlin's optimal plan (§IV: the cost map over the goal set, restoration from
//! the observed start) or their practical mode for many movables, carried out with
//! re-observation and snapping to the grid (§V-B). The goals are the scene's, or the operator's
//! (`--goal ID=X,Y[,DEG]`, in table metres, snapped to the grid cell they fall in).

use anyhow::{Result, anyhow};

use super::goal::{GoalError, GoalPose, obstacle_name};
use super::{Control, EventSink, Failed, Outcome, Session, TaskEvent, drive};
use crate::exec::rearrange::{ExecOptions, execute, execute_practical, observe};
use crate::planner::rearrange::budget::ExactBudget;
use crate::planner::rearrange::frame::GridFrame;
use crate::planner::rearrange::practical::Options;
use crate::planner::rearrange::problem::{Dir, Model, Placement, Problem};
use crate::planner::rearrange::to_scene::{SceneOptions, scene_for};
use crate::planner::rearrange::{cost_map, restore};
use crate::report::StageReport;

/// Which planner a rearrangement uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// The exact cost map (optimal).
    Exact,
    /// The object-level search over single-object legs (many movables).
    Practical,
}

/// A rearrangement.
#[derive(Debug, Clone)]
pub struct Rearrange {
    /// The grid problem, its goals the operator's.
    pub problem: Problem,
    /// The planner.
    pub mode: Mode,
    /// How the grid lies on the table.
    pub scene_opts: SceneOptions,
}

impl Rearrange {
    /// A rearrangement of `problem` with `goals` (movable name → table pose) in place of its
    /// own; `mode` `None` picks the exact planner when its map fits in memory.
    pub fn new(
        mut problem: Problem,
        goals: &[(String, GoalPose)],
        mode: Option<Mode>,
    ) -> Result<Rearrange, GoalError> {
        let scene_opts = SceneOptions::default();
        let frame = GridFrame {
            cell: scene_opts.cell,
            h: problem.grid.h,
        };
        for (id, g) in goals {
            let Some(i) = problem.movables.iter().position(|m| m.name == *id) else {
                return Err(GoalError(format!(
                    "no movable {id:?} (there are: {})",
                    problem
                        .movables
                        .iter()
                        .map(|m| m.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            };
            let (x, y) = frame.cell_of(nalgebra::Vector2::new(g.x, g.y));
            let o = match g.deg {
                Some(d) => ((-d / 90.0).round() as i64).rem_euclid(4) as u8,
                None => problem.goal_movables[i].map_or(problem.start.movables[i].o, |p| p.o),
            };
            let at = Placement { x, y, o };
            let cells = problem.movables[i].cells_at(o);
            for (cx, cy) in cells.iter().map(|c| (c.0 + x, c.1 + y)) {
                let free = problem.grid.get(cx, cy).map(|c| !c.obstacle);
                match free {
                    None => {
                        return Err(GoalError(format!(
                            "the goal ({:.2}, {:.2}) of {id} puts it off the grid ({} × {} cells of {} m)",
                            g.x, g.y, problem.grid.w, problem.grid.h, scene_opts.cell
                        )));
                    }
                    Some(false) => {
                        let scene = scene_for(&problem, &scene_opts)
                            .map_err(|e| GoalError(format!("{e:#}")))?;
                        let c = frame.centre(cx, cy);
                        let which = scene
                            .obstacles
                            .iter()
                            .enumerate()
                            .find(|(_, o)| {
                                crate::planner::global::polygon_distance(c, &o.outline) <= 0.0
                            })
                            .map_or("an obstacle".to_string(), |(k, o)| {
                                obstacle_name(k, &o.outline)
                            });
                        return Err(GoalError(format!(
                            "the goal ({:.2}, {:.2}) of {id} is inside {which}",
                            g.x, g.y
                        )));
                    }
                    Some(true) => {}
                }
            }
            problem.goal_movables[i] = Some(at);
        }
        let fits = ExactBudget::of(&problem).check();
        let mode = match mode {
            Some(Mode::Exact) => {
                fits.map_err(|e| GoalError(format!("the exact planner: {e}")))?;
                Mode::Exact
            }
            Some(Mode::Practical) => Mode::Practical,
            None if fits.is_ok() => Mode::Exact,
            None => Mode::Practical,
        };
        Model::new(&problem).map_err(|e| GoalError(format!("{e}")))?;
        Ok(Rearrange {
            problem,
            mode,
            scene_opts,
        })
    }

    /// The table scene of the grid problem (the built-in target serves it).
    pub fn scene(&self) -> Result<pushbot_world::Scene> {
        scene_for(&self.problem, &self.scene_opts)
    }

    /// In words.
    pub fn summary(&self) -> String {
        format!(
            "rearrange {} ({} movable{}, {} planner)",
            self.problem.name,
            self.problem.movables.len(),
            if self.problem.movables.len() == 1 {
                ""
            } else {
                "s"
            },
            match self.mode {
                Mode::Exact => "exact",
                Mode::Practical => "practical",
            }
        )
    }

    fn frame(&self) -> GridFrame {
        GridFrame {
            cell: self.scene_opts.cell,
            h: self.problem.grid.h,
        }
    }

    /// Each movable's way from where the camera sees it: the optimal plan's pushes (exact), or
    /// straight to its goal (practical, planned leg by leg as it runs).
    pub fn plan(&self, session: &mut Session) -> Result<TaskEvent> {
        let frame = self.frame();
        let (start, _) = observe(&self.problem, &frame, &mut session.live, (Dir::E, false))?;
        let centre = |p: Placement| {
            let c = frame.body_pose(p);
            [c.x, c.y]
        };
        let mut paths: Vec<Vec<[f64; 2]>> =
            start.movables.iter().map(|p| vec![centre(*p)]).collect();
        match self.mode {
            Mode::Exact => {
                let model = Model::new(&self.problem).map_err(|e| anyhow!("{e}"))?;
                let map = cost_map(&model).map_err(|e| anyhow!("{e}"))?;
                let s = model
                    .pack(&start)
                    .ok_or_else(|| anyhow!("the observed arrangement is not free"))?;
                let plan = restore(&model, &map, s).map_err(|e| anyhow!("{e}"))?;
                for st in &plan.steps {
                    for (i, p) in st.config.movables.iter().enumerate() {
                        let c = centre(*p);
                        if paths[i].last() != Some(&c) {
                            paths[i].push(c);
                        }
                    }
                }
                Ok(TaskEvent::Plan {
                    paths,
                    note: format!(
                        "the optimal plan from the observed arrangement: cost {}, {} moves",
                        plan.cost,
                        plan.steps.len()
                    ),
                })
            }
            Mode::Practical => {
                for (i, g) in self.problem.goal_movables.iter().enumerate() {
                    if let Some(g) = g {
                        paths[i].push(centre(*g));
                    }
                }
                Ok(TaskEvent::Plan {
                    paths,
                    note: "each movable to its goal (the practical mode plans leg by leg)".into(),
                })
            }
        }
    }

    /// Rearrange.
    pub fn run(
        &self,
        session: &mut Session,
        control: &Control,
        events: &EventSink,
    ) -> Result<Outcome, Failed> {
        let ids: Vec<String> = self
            .problem
            .movables
            .iter()
            .map(|m| m.name.clone())
            .collect();
        let plan = self.plan(session).map_err(|e| (e, Vec::new()))?;
        events(&plan);
        let exec = ExecOptions {
            cell: self.scene_opts.cell,
            fill: self.scene_opts.fill,
            ..ExecOptions::default()
        };
        let (rep, trace) = match self.mode {
            Mode::Exact => {
                let model = Model::new(&self.problem).map_err(|e| (anyhow!("{e}"), Vec::new()))?;
                let map = cost_map(&model).map_err(|e| (anyhow!("{e}"), Vec::new()))?;
                drive(session, &ids, false, control, events, |io| {
                    execute(&model, &map, io, &exec)
                })?
            }
            Mode::Practical => {
                let opts = Options::for_problem(&self.problem);
                drive(session, &ids, false, control, events, |io| {
                    execute_practical(&self.problem, opts, io, &exec)
                })?
            }
        };
        for r in &rep.replans {
            events(&TaskEvent::Replan {
                note: format!(
                    "after segment {}: {} off the cell the plan had put {}",
                    r.after_segment,
                    r.moved
                        .iter()
                        .map(|m| m.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                    if r.moved.len() == 1 { "it" } else { "them" }
                ),
            });
        }
        let mut st = StageReport::new(
            "rearrange",
            &format!("Rearrange {}", self.problem.name),
            "Ben-Shahar & Rivlin §IV (cost map, restoration), §V-B",
        );
        st.success = rep.reached;
        st.number("Planned cost", rep.planned_cost);
        st.number("Executed cost", rep.executed_cost);
        st.number("Pushes", rep.pushes);
        st.number("Re-plans", rep.replans.len());
        st.number("Deviations snapped to the grid", rep.deviations);
        let message = if rep.reached {
            format!(
                "the goal arrangement reached in {} pushes (cost {}, planned {})",
                rep.pushes, rep.executed_cost, rep.planned_cost
            )
        } else {
            "the goal arrangement was not reached".to_string()
        };
        st.notes.push(message.clone());
        Ok(Outcome {
            success: rep.reached,
            stopped: None,
            message,
            summary: serde_json::to_value(&rep).unwrap_or_default(),
            report: st,
            trace,
        })
    }
}

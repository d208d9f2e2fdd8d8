//! Evaluation of delivery as in Lau, Mitani & Igarashi §V (Fig. 10–11): trials from each named
//! start position of a scene to its goal, with the learned strategy and the dipole-field
//! baseline side by side, in the in-process simulation.

use anyhow::{Result, anyhow};
use nalgebra::Vector2;
use pushbot_world::Scene;
use rayon::prelude::*;

pub use super::trials::{Method, StartResult, parse_starts, summarise};
use crate::exec::collect::CollectReport;
use crate::exec::deliver::Failure;
use crate::exec::deliver::{Delivery, DeliveryParams, deliver_dipole, deliver_learned};
use crate::exec::deliver_path::deliver_among_obstacles;
use crate::exec::io::RobotIo;
use crate::exec::occlusion;
use crate::planner::global::{ObstacleParams, path_length, scene_obstacles, shortest_object_path};
use crate::sim::robot::{SimRobot, SimRobotOptions};
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::{Pose2, Sample};

/// Everything a batch of trials needs.
#[derive(Debug, Clone)]
pub struct TrialSetup {
    /// The scene (its first goal for the object is the goal).
    pub scene: Scene,
    /// The object's id (the scene's first object when `None`).
    pub object: Option<String>,
    /// Simulated robot settings (the seed is varied per trial from this one).
    pub sim: SimRobotOptions,
    /// Delivery parameters.
    pub delivery: DeliveryParams,
    /// Kernel parameters of the regression.
    pub kernel: KernelParams,
}

impl TrialSetup {
    /// The goal position of the object.
    pub fn goal(&self) -> Result<Vector2<f64>> {
        let id = match &self.object {
            Some(id) => id.clone(),
            None => self
                .scene
                .objects
                .first()
                .map(|o| o.id.clone())
                .ok_or_else(|| anyhow!("scene {} has no object", self.scene.name))?,
        };
        let g = self
            .scene
            .goals
            .iter()
            .find(|g| g.object == id)
            .ok_or_else(|| anyhow!("scene {} has no goal for {id:?}", self.scene.name))?;
        Ok(Vector2::new(g.pose.x, g.pose.y))
    }

    /// A simulated robot for trial `trial` from `start`.
    pub fn robot(&self, start: &str, trial: usize) -> Result<SimRobot> {
        let mut opts = self.sim;
        opts.seed = self
            .sim
            .seed
            .wrapping_mul(1_000_003)
            .wrapping_add(trial as u64 * 131 + u64::from(start.bytes().next().unwrap_or(0)));
        SimRobot::new(
            self.scene.clone(),
            self.object.as_deref(),
            Some(start),
            opts,
        )
    }
}

/// Run `trials` deliveries from `start` with `method`; the learned method starts each trial
/// from `samples` (supplemental samples are used within a trial, not carried to the next) and,
/// in a scene with obstacles, follows a global path through sub-goals. The trials run on
/// every core (each has its own world and seed; the results are in trial order).
pub fn run_start(
    setup: &TrialSetup,
    method: Method,
    samples: &[Sample],
    start: &str,
    trials: usize,
) -> Result<(StartResult, Vec<Delivery>)> {
    let goal = setup.goal()?;
    let runs = (0..trials)
        .into_par_iter()
        .map(|t| run_trial(setup, method, samples, start, t, goal))
        .collect::<Result<Vec<_>>>()?;
    Ok((summarise(start, method, &runs), runs))
}

/// Trial `t` of [`run_start`].
fn run_trial(
    setup: &TrialSetup,
    method: Method,
    samples: &[Sample],
    start: &str,
    t: usize,
    goal: Vector2<f64>,
) -> Result<Delivery> {
    let mut io = setup.robot(start, t)?;
    let (ws, o) = (io.workspace(), io.true_object_pose());
    if !ws.boundary.contains(o.position()) {
        anyhow::bail!(
            "start {start} puts the object's marker at ({:.3}, {:.3}), outside the boundary \
             x {:.3}..{:.3}, y {:.3}..{:.3} (a smaller --boundary-inset or a larger \
             --table-margin brings it inside)",
            o.x,
            o.y,
            ws.boundary.min[0],
            ws.boundary.max[0],
            ws.boundary.min[1],
            ws.boundary.max[1]
        );
    }
    let obstacles = scene_obstacles(&setup.scene);
    // The yardstick is the shortest path of the outline's smallest enclosing circle (the
    // outline turning freely), from where its centre starts to where it ends (the goal is
    // the marker's; for an object marked off its middle the centre ends up to that far
    // from it, either side). Where the end is not clear of the walls for the circle (the
    // object lies against one) the path to the goal stands in.
    let from = ws.body_centre(&o);
    let shortest_to = |to| {
        shortest_object_path(
            &ws.body_workspace(),
            &obstacles,
            from,
            to,
            &ObstacleParams::default(),
        )
        .map(|p| path_length(&p))
    };
    let delivered = match method {
        Method::Learned if !setup.scene.obstacles.is_empty() => {
            let mut strat = PushStrategy::new(samples.iter().copied(), setup.kernel);
            deliver_among_obstacles(
                &mut io,
                &mut strat,
                goal,
                &obstacles,
                &setup.delivery,
                &ObstacleParams::default(),
                &mut |_| Ok(()),
            )
            .map(|d| d.delivery)
        }
        Method::Learned => {
            let mut strat = PushStrategy::new(samples.iter().copied(), setup.kernel);
            deliver_learned(&mut io, &mut strat, goal, &setup.delivery, &mut |_| Ok(()))
        }
        Method::Dipole => deliver_dipole(&mut io, goal, &setup.delivery),
    };
    // A body the camera lost ends this trial, not the evaluation: the trial failed (and
    // whatever the delivery made of the poses it could no longer measure is void).
    let mut d = match delivered {
        Ok(d) if io.lost().is_none() => d,
        Err(e) if io.lost().is_none() && !occlusion::is_lost(&e) => return Err(e),
        _ => {
            if let Some(l) = io.lost() {
                tracing::warn!("start {start}, trial {t}: {l}");
            }
            lost_delivery(&io, goal)
        }
    };
    // The end is the last pose of the track the body's path was measured on (no new look).
    let end = d.trajectory.last().map(|(_, o)| ws.body_centre(o));
    d.shortest_path = match end {
        Some(end) if d.success => shortest_to(end).or_else(|| shortest_to(goal)),
        _ => shortest_to(goal),
    };
    tracing::debug!(
        "start {start}, trial {t}: delivered {}, {:.1} s, body path {:.3} m, shortest {:.3} m, {} recoveries, {} re-positionings, {} camera frames, {} looks again",
        d.success,
        d.time,
        d.body_path,
        d.shortest_path.unwrap_or(f64::NAN),
        d.recoveries.len(),
        d.repositions,
        io.camera_frames(),
        io.relooks()
    );
    Ok(d)
}

/// A trial the camera's loss of a body ended: failed, with the object's true distance from the
/// goal where it stopped (its path is not known: what the camera saw of it is gone with it).
fn lost_delivery(io: &SimRobot, goal: Vector2<f64>) -> Delivery {
    let distance = (io.true_object_pose().position() - goal).norm();
    Delivery::failed(Some(Failure::MarkerLost), io.time(), distance)
}

/// The six objects of Lau et al. (Fig. 6), as preset scenes, in the order of their Fig. 11.
pub const LAU_SCENES: &[&str] = &[
    "lau-irregular",
    "lau-irregular-corner",
    "lau-l-shape",
    "lau-wire-cutter",
    "lau-scissors",
    "lau-snake",
];

/// One scene's evaluation.
#[derive(Debug, serde::Serialize)]
pub struct SceneEval {
    /// The scene's name.
    pub scene: String,
    /// Samples of the strategy used.
    pub samples: usize,
    /// The collection's report, when it collected.
    pub collection: Option<CollectReport>,
    /// One result per start and method.
    pub results: Vec<StartResult>,
}

/// One trial's robot and object poses after every step, labelled "START METHOD".
pub type LabelledRun = (String, Vec<(Pose2, Pose2)>);

/// One cell's results and its first trial's trajectory.
pub type Cell = (StartResult, Option<LabelledRun>);

/// The cells of an earlier run, by start and method ([`evaluate_scene`]).
pub type ResumedCells<'a> = dyn Fn(&str, Method) -> Option<Cell> + Sync + 'a;

/// Called with each cell as it is done, with its trials' deliveries (`None` for a cell
/// resumed, [`evaluate_scene`]).
pub type CellReport<'a> =
    dyn Fn(&StartResult, Option<&LabelledRun>, Option<&[Delivery]>) -> Result<()> + Sync + 'a;

/// Trials of every method from every start of one scene (Lau et al. §V), the cells (start ×
/// method) on all cores: the results in the order start × method, and the first trial's
/// trajectory of each (labelled "START METHOD") for the figure. A cell `resumed` returns (read
/// back from an earlier run, [`super::resume`]) is not run again; every cell, run or resumed,
/// is handed to `report` as it is done (in any order), with its trials if it was run.
pub fn evaluate_scene(
    setup: &TrialSetup,
    methods: &[Method],
    samples: &[Sample],
    starts: &[String],
    trials: usize,
    resumed: &ResumedCells<'_>,
    report: &CellReport<'_>,
) -> Result<(Vec<StartResult>, Vec<LabelledRun>)> {
    let cells: Vec<(String, Method)> = starts
        .iter()
        .flat_map(|s| methods.iter().map(move |m| (s.clone(), *m)))
        .collect();
    evaluate_cells(setup, &cells, samples, trials, resumed, report)
}

/// As [`evaluate_scene`], for the given cells (start × method) only, in their order (one
/// shard's share of a sweep, [`super::shard`]).
pub fn evaluate_cells(
    setup: &TrialSetup,
    cells: &[(String, Method)],
    samples: &[Sample],
    trials: usize,
    resumed: &ResumedCells<'_>,
    report: &CellReport<'_>,
) -> Result<(Vec<StartResult>, Vec<LabelledRun>)> {
    let done = cells
        .par_iter()
        .map(|(s, m)| {
            if let Some((res, first)) = resumed(s, *m) {
                report(&res, first.as_ref(), None)?;
                return Ok((res, first));
            }
            let (res, runs) = run_start(setup, *m, samples, s, trials)?;
            let first = runs
                .first()
                .map(|first| (format!("{s} {m:?}"), first.trajectory.clone()));
            report(&res, first.as_ref(), Some(&runs))?;
            Ok((res, first))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut results = Vec::with_capacity(done.len());
    let mut trajectories = Vec::new();
    for (res, first) in done {
        results.push(res);
        trajectories.extend(first);
    }
    Ok((results, trajectories))
}

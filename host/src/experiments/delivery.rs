//! Delivery experiments in the in-process simulation (feature `sim`): collect a pushing
//! strategy on the clear table or reuse a cached one (Lau et al. Algorithm 1), then deliver the
//! object among the scene's obstacles along the global path (§III-E) — the library entry point
//! of the demo's strategy stage.

use std::path::Path;

use anyhow::{Result, anyhow};
use indicatif::ProgressBar;
use pushbot_world::Scene;

use crate::exec::collect::{CollectParams, CollectReport, collect};
use crate::exec::deliver::DeliveryParams;
use crate::exec::deliver_path::{ObstacleDelivery, deliver_among_obstacles};
use crate::planner::global::{ObstacleParams, scene_goal, scene_obstacles};
use crate::sim::robot::{SimRobot, SimRobotOptions};
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::{Pose2, Sample};
use crate::strategy::store::{self, StrategyWriter};

/// The pushing strategy of `object` in `scene`: loaded from `cache` when that file exists and
/// has samples, otherwise collected there with Algorithm 1 (on the scene's table without its
/// obstacles: the strategy belongs to the object, and the paper collects on a clear table) and
/// written to `cache` sample by sample. Returns the samples and, when it collected, the report.
pub fn collect_or_load(
    scene: &Scene,
    object: Option<&str>,
    cache: &Path,
    sim: SimRobotOptions,
    params: &CollectParams,
    kernel: KernelParams,
    pb: &ProgressBar,
) -> Result<(Vec<Sample>, Option<CollectReport>)> {
    if cache.exists() {
        let file = store::load(cache)?;
        if file.samples.len() >= params.initial.clamp(1, 20) {
            return Ok((file.samples, None));
        }
    }
    let id = object
        .map(str::to_owned)
        .or_else(|| scene.objects.first().map(|o| o.id.clone()))
        .ok_or_else(|| anyhow!("scene {} has no object", scene.name))?;
    let (mut writer, existing) = StrategyWriter::open(cache, &id)?;
    let mut clear = scene.clone();
    clear.obstacles.clear();
    let mut io = SimRobot::new(clear, Some(&id), None, sim)?;
    let mut strategy = PushStrategy::new(existing, kernel);
    let mut sink = |s: &Sample| -> Result<()> {
        writer.append(s)?;
        Ok(())
    };
    let rep = collect(&mut io, &mut strategy, params, &mut sink, pb)?;
    Ok((strategy.samples().to_vec(), Some(rep)))
}

/// What [`collect_and_deliver`] did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SceneDelivery {
    /// Samples of the strategy used.
    pub samples: usize,
    /// The collection's report, when it collected.
    pub collection: Option<CollectReport>,
    /// The delivery.
    pub result: ObstacleDelivery,
    /// The object's start pose (marker), table frame.
    pub start: Pose2,
}

/// Collect (or reuse the cached strategy in `cache`), then deliver the object of `scene` to its
/// goal among the scene's obstacles, in the in-process simulation: the library entry point of
/// the demo. `object`: the object's id (the scene's first when `None`).
// Each argument is a separate, independently defaulted setting of one of the two algorithms.
#[allow(clippy::too_many_arguments)]
pub fn collect_and_deliver(
    scene: &Scene,
    object: Option<&str>,
    cache: &Path,
    sim: SimRobotOptions,
    collect_params: &CollectParams,
    delivery: &DeliveryParams,
    op: &ObstacleParams,
    pb: &ProgressBar,
) -> Result<SceneDelivery> {
    let kernel = KernelParams::default();
    let (samples, collection) =
        collect_or_load(scene, object, cache, sim, collect_params, kernel, pb)?;
    let goal = scene_goal(scene, object)?;
    let mut io = SimRobot::new(scene.clone(), object, None, sim)?;
    let start = io.true_object_pose();
    let mut strategy = PushStrategy::new(samples.iter().copied(), kernel);
    let result = deliver_among_obstacles(
        &mut io,
        &mut strategy,
        goal,
        &scene_obstacles(scene),
        delivery,
        op,
        &mut |_| Ok(()),
    )?;
    Ok(SceneDelivery {
        samples: samples.len(),
        collection,
        result,
        start,
    })
}

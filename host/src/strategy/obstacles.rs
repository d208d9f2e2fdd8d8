//! Delivery among obstacles, as Lau, Mitani & Igarashi handle it (§III-E, last paragraph):
//! "we first compute a global collision-free path with existing planning techniques [LaValle],
//! and then execute the robot to push the object along sub-goals of this path".
//!
//! The global planner is A* (the `pathfinding` crate) on a grid over the boundary, for the
//! object's marker. A cell is free when the object's bounding circle (around its marker) clears
//! every obstacle by a small margin and the marker stays inside the boundary. The robot's room
//! to push is a cost, not a wall: cells where the robot could not circle the object on its
//! bound-all circle (Fig. 3) — closer to an obstacle than the object's radius plus the robot's
//! diameter plus a margin — cost `room_penalty` times as much, so the path keeps that room
//! wherever the free space allows and squeezes through only where it must.
//!
//! Delivery re-plans from the object's current position before each leg and pushes with
//! Algorithm 2 ([`deliver_learned`]) to the path's point `subgoal_spacing` ahead (a sub-goal,
//! reached within `subgoal_radius`), until the last leg reaches the goal within the success
//! radius.

use std::path::Path;

use anyhow::{Result, anyhow};
use indicatif::ProgressBar;
use nalgebra::Vector2;
use pathfinding::prelude::astar;
use pushbot_sim::Scene;

use super::collect::{CollectParams, CollectReport, collect};
use super::deliver::{Delivery, DeliveryParams, Failure, deliver_learned_among};
use super::regression::{KernelParams, PushStrategy};
use super::robot_io::{RobotIo, Workspace};
use super::sample::{Pose2, Sample};
use super::store::{self, StrategyWriter};
use crate::sim::robot::{SimRobot, SimRobotOptions};

/// Parameters of the global path and its sub-goals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleParams {
    /// Grid cell size, m.
    pub cell: f64,
    /// Clearance of the object's bounding circle from obstacles, m.
    pub object_margin: f64,
    /// Extra room beyond the robot's diameter that the robot wants around the object, m.
    pub room_margin: f64,
    /// Cost factor of cells without room for the robot to circle the object.
    pub room_penalty: u32,
    /// Distance along the path to the next sub-goal, m.
    pub subgoal_spacing: f64,
    /// A sub-goal (not the goal) counts as reached within this distance, m.
    pub subgoal_radius: f64,
}

impl Default for ObstacleParams {
    fn default() -> Self {
        ObstacleParams {
            cell: 0.01,
            object_margin: 0.01,
            room_margin: 0.02,
            room_penalty: 4,
            subgoal_spacing: 0.15,
            subgoal_radius: 0.04,
        }
    }
}

/// Distance from `p` to the polygon `poly` (0 inside it).
pub fn polygon_distance(p: Vector2<f64>, poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    if n == 0 {
        return f64::INFINITY;
    }
    let mut inside = false;
    let mut best = f64::INFINITY;
    for i in 0..n {
        let a = Vector2::new(poly[i][0], poly[i][1]);
        let b = Vector2::new(poly[(i + 1) % n][0], poly[(i + 1) % n][1]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
        let ab = b - a;
        let t = if ab.norm_squared() > 0.0 {
            ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        best = best.min((a + t * ab - p).norm());
    }
    if inside { 0.0 } else { best }
}

/// Distance from `p` to the nearest obstacle.
pub fn clearance(p: Vector2<f64>, obstacles: &[Vec<[f64; 2]>]) -> f64 {
    obstacles
        .iter()
        .map(|o| polygon_distance(p, o))
        .fold(f64::INFINITY, f64::min)
}

/// The clearances a path needs: the object's (hard) and the robot's room to push (soft).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearances {
    /// The marker must stay this far from every obstacle, m.
    pub object: f64,
    /// Closer than this, cells cost more, m.
    pub room: f64,
}

impl Clearances {
    /// From the workspace (robot and object radii) and the parameters.
    pub fn new(ws: &Workspace, p: &ObstacleParams) -> Clearances {
        Clearances {
            object: ws.object_radius + p.object_margin,
            room: ws.object_radius + 2.0 * ws.robot_radius + p.room_margin,
        }
    }
}

/// A global path for the object's marker from `start` to `goal` among `obstacles` (table-frame
/// polygons), inside the workspace's boundary; `None` when there is none. The path runs from
/// `start` to `goal` through grid cell centres.
pub fn plan_object_path(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    start: Vector2<f64>,
    goal: Vector2<f64>,
    p: &ObstacleParams,
) -> Option<Vec<Vector2<f64>>> {
    if !(p.cell.is_finite() && p.cell > 1e-4) {
        return None;
    }
    let c = Clearances::new(ws, p);
    let b = ws.boundary;
    let nx = ((b.max[0] - b.min[0]) / p.cell).floor() as i32 + 1;
    let ny = ((b.max[1] - b.min[1]) / p.cell).floor() as i32 + 1;
    if nx <= 0 || ny <= 0 || nx.saturating_mul(ny) > 4_000_000 {
        return None;
    }
    let centre = |(i, j): (i32, i32)| {
        Vector2::new(
            b.min[0] + f64::from(i) * p.cell,
            b.min[1] + f64::from(j) * p.cell,
        )
    };
    let cell_of = |v: Vector2<f64>| {
        (
            (((v.x - b.min[0]) / p.cell).round() as i32).clamp(0, nx - 1),
            (((v.y - b.min[1]) / p.cell).round() as i32).clamp(0, ny - 1),
        )
    };
    // Per-cell step cost factor: 0 = blocked.
    let factor: Vec<u32> = (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|ij| {
            let d = clearance(centre(ij), obstacles);
            if d < c.object {
                0
            } else if d < c.room {
                p.room_penalty.max(1)
            } else {
                1
            }
        })
        .collect();
    let at = |(i, j): (i32, i32)| factor[(j * nx + i) as usize];
    let (s, g) = (cell_of(start), cell_of(goal));
    // The start and goal cells may be in the soft zone, never blocked for the search to begin.
    if at(g) == 0 {
        return None;
    }
    let (cells, _) = astar(
        &s,
        |&(i, j)| {
            let mut v = Vec::with_capacity(8);
            for (di, dj, w) in [
                (1, 0, 10),
                (-1, 0, 10),
                (0, 1, 10),
                (0, -1, 10),
                (1, 1, 14),
                (1, -1, 14),
                (-1, 1, 14),
                (-1, -1, 14),
            ] {
                let n = (i + di, j + dj);
                if n.0 < 0 || n.1 < 0 || n.0 >= nx || n.1 >= ny {
                    continue;
                }
                let f = at(n);
                if f > 0 {
                    v.push((n, w * f));
                }
            }
            v
        },
        |&(i, j)| {
            let (di, dj) = ((i - g.0).abs(), (j - g.1).abs());
            (10 * di.max(dj) + 4 * di.min(dj)) as u32
        },
        |&n| n == g,
    )?;
    let mut path: Vec<Vector2<f64>> = vec![start];
    path.extend(cells.iter().skip(1).map(|&ij| centre(ij)));
    if let Some(last) = path.last_mut() {
        *last = goal;
    }
    Some(path)
}

/// The point `spacing` along `path` from its start (its end when shorter).
pub fn point_along(path: &[Vector2<f64>], spacing: f64) -> Option<Vector2<f64>> {
    let mut left = spacing;
    for w in path.windows(2) {
        let seg = (w[1] - w[0]).norm();
        if seg >= left && seg > 0.0 {
            return Some(w[0] + (w[1] - w[0]) * (left / seg));
        }
        left -= seg;
    }
    path.last().copied()
}

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
        if first_path.is_empty() {
            first_path = path.iter().map(|v| [v.x, v.y]).collect();
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

/// The scene's obstacles as polygons.
pub fn scene_obstacles(scene: &Scene) -> Vec<Vec<[f64; 2]>> {
    scene.obstacles.iter().map(|o| o.outline.clone()).collect()
}

/// The scene's goal position for `object` (the first object when `None`).
pub fn scene_goal(scene: &Scene, object: Option<&str>) -> Result<Vector2<f64>> {
    let id = match object {
        Some(id) => id.to_owned(),
        None => scene
            .objects
            .first()
            .map(|o| o.id.clone())
            .ok_or_else(|| anyhow!("scene {} has no object", scene.name))?,
    };
    let g = scene
        .goals
        .iter()
        .find(|g| g.object == id)
        .ok_or_else(|| anyhow!("scene {} has no goal for {id:?}", scene.name))?;
    Ok(Vector2::new(g.pose.x, g.pose.y))
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::strategy::robot_io::Rect;

    fn ws() -> Workspace {
        Workspace {
            table: Rect {
                min: [-0.2, -0.2],
                max: [1.8, 1.4],
            },
            boundary: Rect {
                min: [0.1, 0.1],
                max: [1.5, 1.1],
            },
            robot_radius: 0.04,
            object_radius: 0.07,
        }
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    }

    #[test]
    fn polygon_distance_matches_hand_cases() {
        let r = rect(0.0, 0.0, 1.0, 1.0);
        assert_eq!(polygon_distance(Vector2::new(0.5, 0.5), &r), 0.0);
        assert!((polygon_distance(Vector2::new(2.0, 0.5), &r) - 1.0).abs() < 1e-12);
        assert!((polygon_distance(Vector2::new(2.0, 2.0), &r) - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_path_goes_around_a_wall_with_the_object_clear_of_it() {
        let ws = ws();
        let p = ObstacleParams::default();
        let wall = vec![rect(0.78, 0.45, 0.88, 1.2)];
        let (s, g) = (Vector2::new(0.45, 0.95), Vector2::new(1.25, 0.6));
        let path = plan_object_path(&ws, &wall, s, g, &p).unwrap();
        assert_eq!(path[0], s);
        assert_eq!(*path.last().unwrap(), g);
        let c = Clearances::new(&ws, &p);
        // Every point (and every point between them) keeps the object clear of the wall.
        for w in path.windows(2) {
            for k in 0..=10 {
                let q = w[0] + (w[1] - w[0]) * (f64::from(k) / 10.0);
                assert!(clearance(q, &wall) >= c.object - 0.01, "{q:?}");
                assert!(ws.boundary.contains(q), "{q:?}");
            }
            assert!((w[1] - w[0]).norm() < 0.02);
        }
        // It passes below the wall's end.
        assert!(
            path.iter()
                .any(|q| q.y < 0.45 - c.object + 0.01 && (q.x - 0.83).abs() < 0.05)
        );
        // Where the gap allows, it keeps the robot's room: at the wall's x it is at least
        // `room` from the wall if the gap to the boundary is wide enough.
        let at_wall = path
            .iter()
            .filter(|q| (q.x - 0.83).abs() < 0.01)
            .map(|q| clearance(*q, &wall))
            .fold(f64::INFINITY, f64::min);
        assert!(at_wall >= c.room - 0.011, "{at_wall} < {}", c.room);
        // Longer than the straight line, not absurdly so.
        let len: f64 = path.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        assert!(len > (g - s).norm() && len < 2.5 * (g - s).norm(), "{len}");
    }

    #[test]
    fn no_path_through_a_closed_wall_and_point_along_walks_the_path() {
        let ws = ws();
        let p = ObstacleParams::default();
        let wall = vec![rect(0.78, 0.0, 0.88, 1.2)];
        assert!(
            plan_object_path(
                &ws,
                &wall,
                Vector2::new(0.45, 0.6),
                Vector2::new(1.25, 0.6),
                &p
            )
            .is_none()
        );
        let path = vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(1.0, 1.0),
        ];
        assert_eq!(point_along(&path, 0.5), Some(Vector2::new(0.5, 0.0)));
        assert_eq!(point_along(&path, 1.5), Some(Vector2::new(1.0, 0.5)));
        assert_eq!(point_along(&path, 5.0), Some(Vector2::new(1.0, 1.0)));
    }
}

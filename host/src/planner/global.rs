//! The global path of the object among obstacles, for delivery as Lau, Mitani & Igarashi
//! describe it (§III-E, last paragraph): "we first compute a global collision-free path with
//! existing planning techniques \[LaValle\], and then execute the robot to push the object along
//! sub-goals of this path". A pure planner: a function of the workspace, the obstacles and the
//! goal; [`crate::exec::deliver_path`] pushes along it.
//!
//! The planner is A* (the `pathfinding` crate) on a grid over the boundary, for a reference
//! point of the object with a bounding circle about it (`Workspace::object_radius`): the
//! delivery plans for the centre of the smallest circle enclosing the outline (the outline
//! swept through every rotation about it, `Workspace::body_workspace`). A cell is free when the
//! bounding circle clears every obstacle by a small margin and the point stays inside the
//! boundary. The robot's room to push is a cost, not a wall: cells where the robot could not circle the object on its bound-all
//! circle (Fig. 3) — closer to an obstacle than the object's radius plus the robot's diameter
//! plus a margin — may cost `room_penalty` times as much, so the path keeps that room wherever
//! the free space allows (off by default, see [`ObstacleParams::room_penalty`]). A move also needs the robot's
//! room *behind* the object for that direction of push (its centre on the far side of the
//! bound-all circle, clear of obstacles and on the table): a move without it costs
//! `behind_penalty` times as much, so an object against a wall is taken along the wall, where
//! the robot can push, and not straight off it, where it cannot stand.

use anyhow::{Result, anyhow};
use nalgebra::Vector2;
use pathfinding::prelude::astar;
use pushbot_world::Scene;

use pushbot_world::workspace::Workspace;

/// Parameters of the global path and its sub-goals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleParams {
    /// Grid cell size, m.
    pub cell: f64,
    /// Clearance of the object's bounding circle from obstacles, m.
    pub object_margin: f64,
    /// Extra room beyond the robot's diameter that the robot wants around the object, m.
    pub room_margin: f64,
    /// Cost factor of cells without room for the robot to circle the object. 1 (no cost) by
    /// default: the special case finds stand points the robot can reach and walks round the
    /// obstacles where a wall cuts the circle, and a path kept wide of every wall was up to
    /// 1.4× the shortest (two staggered walls); 4 keeps it wide.
    pub room_penalty: u32,
    /// Cost factor of moves without room for the robot behind the object (1: not checked).
    pub behind_penalty: u32,
    /// How far along the path beyond the object its moving sub-goal is, m
    /// ([`crate::planner::path_follow`]).
    pub lookahead: f64,
    /// Over this much of the path before its end, m, the moving sub-goal shifts by degrees
    /// from the path's end (planned for the body's centre at the goal) to where the body's
    /// centre is when the marker is at the goal ([`crate::planner::path_follow::PathFollower::shifted`]):
    /// for an object marked off its middle (the L-shape's marker is 6 cm from its body's
    /// centre) the body is not first carried to the goal and then back.
    pub end_blend: f64,
    /// A recovery's push aside counts as done within this distance, m; the shortest
    /// look-ahead.
    pub subgoal_radius: f64,
    /// A push that moves the object off the way to its sub-goal by more than this is followed
    /// by a re-positioning, rad ([`crate::exec::deliver::DeliveryParams::reposition_angle`]).
    pub reposition_angle: f64,
    /// A push that leaves the object's enclosing circle within this of an obstacle, and nearer
    /// to it, is followed by a re-positioning once it drifted by
    /// [`Self::wall_reposition_angle`], m ([`crate::exec::deliver::DeliveryParams::wall_near`]).
    pub wall_near: f64,
    /// The re-position angle of a push towards a near wall, rad.
    pub wall_reposition_angle: f64,
    /// On the last leg, the general case's trust radius, m
    /// ([`crate::exec::deliver::DeliveryParams::last_leg_trust`]). Near the goal a general-case
    /// push from where no sample pushed that way (the robot beside the object after the last
    /// sub-goal) sent the L-shape sideways and back (`results/obstacle-rows/README.md`).
    pub last_leg_trust: f64,
    /// On the last leg, where the robot has no room between the object at the goal and a wall,
    /// the marker is aimed this far from the goal away from the wall, m
    /// ([`crate::exec::deliver::DeliveryParams::goal_wall_offset`]).
    pub goal_wall_offset: f64,
    /// On the last leg, the special case's turn weight, m a radian
    /// ([`crate::exec::deliver::DeliveryParams::last_leg_turn_weight`]).
    pub last_leg_turn_weight: f64,
    /// A leg stalls when the object comes no closer to its sub-goal for this long, s.
    pub stall_time: f64,
    /// Recoveries tried before a delivery is given up as stalled.
    pub max_recoveries: usize,
}

impl Default for ObstacleParams {
    fn default() -> Self {
        ObstacleParams {
            cell: 0.01,
            object_margin: 0.01,
            room_margin: 0.02,
            room_penalty: 1,
            behind_penalty: 8,
            lookahead: 0.12,
            end_blend: 0.15,
            subgoal_radius: 0.04,
            reposition_angle: 30f64.to_radians(),
            wall_near: 0.07,
            wall_reposition_angle: 10f64.to_radians(),
            last_leg_trust: 0.02,
            goal_wall_offset: 0.011,
            last_leg_turn_weight: 0.06,
            stall_time: 60.0,
            max_recoveries: 4,
        }
    }
}

/// Distance from `p` to the polygon `poly` (0 inside it).
pub fn polygon_distance(p: Vector2<f64>, poly: &[[f64; 2]]) -> f64 {
    polygon_nearest(p, poly).map_or(f64::INFINITY, |(d, _)| d)
}

/// Distance from `p` to the polygon `poly` and the polygon's point nearest to it (`p` itself,
/// at distance 0, inside it); `None` for an empty polygon.
fn polygon_nearest(p: Vector2<f64>, poly: &[[f64; 2]]) -> Option<(f64, Vector2<f64>)> {
    let n = poly.len();
    if n == 0 {
        return None;
    }
    let mut inside = false;
    let mut best = (f64::INFINITY, p);
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
        let q = a + t * ab;
        let d = (q - p).norm();
        if d < best.0 {
            best = (d, q);
        }
    }
    Some(if inside { (0.0, p) } else { best })
}

/// The clearance of `p` ([`clearance`]) and the unit direction away from the nearest
/// obstacle's nearest point; `None` without obstacles, or with `p` on or inside one.
pub fn away_from_obstacles(
    p: Vector2<f64>,
    obstacles: &[Vec<[f64; 2]>],
) -> Option<(f64, Vector2<f64>)> {
    let (d, q) = obstacles
        .iter()
        .filter_map(|o| polygon_nearest(p, o))
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    Some((d, (p - q).try_normalize(1e-12)?))
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

/// How far an object that stands too close to an obstacle may be pushed off it to where the
/// path begins, m.
const ESCAPE: f64 = 0.15;

/// A global path for the object's reference point (the centre of `ws.object_radius`'s circle)
/// from `start` to `goal` among `obstacles` (table-frame polygons), inside the workspace's
/// boundary; `None` when there is none. The path runs from `start` to `goal` through grid cell
/// centres.
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
    let pushable = |x: Vector2<f64>, d: Vector2<f64>| pushable(ws, obstacles, p, x, d);
    let (s0, g0) = (cell_of(start), cell_of(goal));
    // A goal on the clearance's edge may round to a blocked cell: the nearest free cell within
    // two cells stands in for it (the path still ends at the goal itself).
    let mut g = None;
    for dj in -2..=2i32 {
        for di in -2..=2i32 {
            let n = (g0.0 + di, g0.1 + dj);
            if n.0 < 0 || n.1 < 0 || n.0 >= nx || n.1 >= ny || at(n) == 0 {
                continue;
            }
            if g.is_none_or(|(_, d)| di * di + dj * dj < d) {
                g = Some((n, di * di + dj * dj));
            }
        }
    }
    let g = g?.0;
    // An object pushed closer to an obstacle than its clearance (it is there, so it fits) leaves
    // by the nearest free cell within ESCAPE of it, straight away from what it is close to.
    let s = if at(s0) > 0 {
        s0
    } else {
        let reach = (ESCAPE / p.cell).ceil() as i32;
        let mut best: Option<((i32, i32), i32)> = None;
        for dj in -reach..=reach {
            for di in -reach..=reach {
                let n = (s0.0 + di, s0.1 + dj);
                let d2 = di * di + dj * dj;
                if n.0 < 0 || n.1 < 0 || n.0 >= nx || n.1 >= ny || d2 > reach * reach {
                    continue;
                }
                let d = Vector2::new(f64::from(di), f64::from(dj));
                let d2 = if pushable(centre(s0), d) { d2 } else { d2 * 16 };
                if at(n) > 0 && best.is_none_or(|(_, b)| d2 < b) {
                    best = Some((n, d2));
                }
            }
        }
        best?.0
    };
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
                    let d = Vector2::new(f64::from(di), f64::from(dj));
                    let f = if pushable(centre((i, j)), d) {
                        f
                    } else {
                        f * p.behind_penalty
                    };
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
    let skip = if s == s0 { 1 } else { 0 };
    path.extend(cells.iter().skip(skip).map(|&ij| centre(ij)));
    if let Some(last) = path.last_mut() {
        *last = goal;
    }
    Some(path)
}

/// Whether the robot can stand behind an object at `x` (its circle of `ws.object_radius`) to
/// push it along `d`: always when `p.behind_penalty` is 1 (not checked).
pub(crate) fn pushable(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    p: &ObstacleParams,
    x: Vector2<f64>,
    d: Vector2<f64>,
) -> bool {
    let behind = ws.object_radius + ws.robot_radius + p.room_margin;
    p.behind_penalty <= 1
        || d.try_normalize(1e-12)
            .is_none_or(|u| robot_fits(ws, obstacles, x - u * behind))
}

/// Whether the robot's centre may stand at `p`: on the table and clear of every obstacle (by
/// its radius and 1 cm).
pub fn robot_fits(ws: &Workspace, obstacles: &[Vec<[f64; 2]>], p: Vector2<f64>) -> bool {
    ws.reachable().contains(p) && clearance(p, obstacles) > ws.robot_radius + 0.01
}

/// Whether the robot's centre may move straight from `a` to `b` ([`robot_fits`] every 5 mm).
pub fn segment_clear(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    a: Vector2<f64>,
    b: Vector2<f64>,
) -> bool {
    along(a, b, |x| robot_fits(ws, obstacles, x))
}

/// Whether `holds` at every point from `a` to `b`, both ends included, 5 mm apart or less.
pub(crate) fn along(
    a: Vector2<f64>,
    b: Vector2<f64>,
    holds: impl Fn(Vector2<f64>) -> bool,
) -> bool {
    let n = ((b - a).norm() / 0.005).ceil().max(1.0) as usize;
    (0..=n).all(|k| holds(a + (b - a) * (k as f64 / n as f64)))
}

/// Whether the object's circle at `p` is inside the boundary and `keep` clear of every
/// obstacle.
pub(crate) fn object_fits(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    keep: f64,
    p: Vector2<f64>,
) -> bool {
    ws.boundary.contains(p) && clearance(p, obstacles) >= keep
}

/// A path for the robot's centre from `start` to `goal` around `obstacles` (the same A* as the
/// object's, for a disc of the robot's radius on the table), shortened to the corners where
/// the straight way is blocked; `None` when there is none.
pub fn plan_robot_path(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    start: Vector2<f64>,
    goal: Vector2<f64>,
) -> Option<Vec<Vector2<f64>>> {
    let disc = Workspace {
        boundary: ws.reachable(),
        object_radius: ws.robot_radius,
        body: pushbot_world::enclosing_circle::Circle::at_origin(ws.robot_radius),
        ..*ws
    };
    let op = ObstacleParams {
        cell: 0.02,
        object_margin: 0.015,
        room_penalty: 1,
        behind_penalty: 1,
        ..ObstacleParams::default()
    };
    let path = plan_object_path(&disc, obstacles, start, goal, &op)?;
    Some(pull_taut(&path, |a, b| segment_clear(ws, obstacles, a, b)))
}

/// The shortest collision-free path of the object's reference point from `start` to `goal`:
/// its bounding circle (`ws.object_radius` round that point; for the object's body, the
/// smallest circle enclosing its outline, [`Workspace::body_workspace`]) clear of every
/// obstacle by `op.object_margin` and the point inside the boundary, with no regard for the
/// robot's room — the yardstick the delivered path is measured against. A* on the grid, then
/// pulled taut (a way point kept only where the straight way from the previous one is
/// blocked). `None` when there is none.
pub fn shortest_object_path(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    start: Vector2<f64>,
    goal: Vector2<f64>,
    op: &ObstacleParams,
) -> Option<Vec<Vector2<f64>>> {
    let free = ObstacleParams {
        room_penalty: 1,
        behind_penalty: 1,
        ..*op
    };
    let path = plan_object_path(ws, obstacles, start, goal, &free)?;
    let keep = ws.object_radius + op.object_margin;
    Some(pull_taut(&path, |a, b| {
        along(a, b, |x| object_fits(ws, obstacles, keep, x))
    }))
}

/// Length of a path, m.
pub fn path_length(path: &[Vector2<f64>]) -> f64 {
    path.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// `path` with a way point kept only where the straight way (`clear`) from the last one kept
/// to the next is blocked; its ends stay.
fn pull_taut(
    path: &[Vector2<f64>],
    clear: impl Fn(Vector2<f64>, Vector2<f64>) -> bool,
) -> Vec<Vector2<f64>> {
    let Some(&first) = path.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut i = 0;
    while i + 1 < path.len() {
        let from = out[out.len() - 1];
        let mut j = i + 1;
        while j + 1 < path.len() && clear(from, path[j + 1]) {
            j += 1;
        }
        out.push(path[j]);
        i = j;
    }
    out
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use pushbot_world::workspace::Rect;

    /// A 1.4 × 1.0 m boundary on a 2.0 × 1.6 m table, a 4 cm robot, a 7 cm object.
    pub(crate) fn ws() -> Workspace {
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
            body: pushbot_world::enclosing_circle::Circle::at_origin(0.07),
        }
    }

    /// The rectangle from (x0, y0) to (x1, y1).
    pub(crate) fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    }

    #[test]
    fn polygon_distance_matches_hand_cases() {
        let r = rect(0.0, 0.0, 1.0, 1.0);
        assert_eq!(polygon_distance(Vector2::new(0.5, 0.5), &r), 0.0);
        assert!((polygon_distance(Vector2::new(2.0, 0.5), &r) - 1.0).abs() < 1e-12);
        assert!((polygon_distance(Vector2::new(2.0, 2.0), &r) - 2f64.sqrt()).abs() < 1e-12);
        // Away from the nearer of two: off a face square to it, off a corner along the diagonal.
        let two = [r.clone(), rect(3.0, 0.0, 4.0, 1.0)];
        let away = |x: f64, y: f64| away_from_obstacles(Vector2::new(x, y), &two);
        let (d, u) = away(1.4, 0.5).unwrap();
        assert!((d - 0.4).abs() < 1e-12 && (u - Vector2::x()).norm() < 1e-12);
        let (d, u) = away(2.7, 0.5).unwrap();
        assert!((d - 0.3).abs() < 1e-12 && (u + Vector2::x()).norm() < 1e-12);
        let (d, u) = away(1.8, 2.0).unwrap();
        let diag = Vector2::new(0.8f64, 1.0);
        assert!((d - diag.norm()).abs() < 1e-12 && (u - diag.normalize()).norm() < 1e-12);
        assert_eq!(d, clearance(Vector2::new(1.8, 2.0), &two));
        assert!(away(0.5, 0.5).is_none() && away_from_obstacles(Vector2::zeros(), &[]).is_none());
    }

    #[test]
    fn the_path_goes_around_a_wall_with_the_object_clear_of_it() {
        let ws = ws();
        // With the room cost on, the path also keeps the robot's room round the wall's end.
        let p = ObstacleParams {
            room_penalty: 4,
            ..ObstacleParams::default()
        };
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
    fn no_path_through_a_closed_wall() {
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
    }

    /// An object left against the wall's face (closer than its clearance): the path leaves
    /// along the wall, where the robot can stand behind it, not straight off the wall, where
    /// it cannot; without the room-behind cost it goes straight off.
    #[test]
    fn an_object_against_a_wall_is_taken_along_it_where_the_robot_can_push() {
        let ws = ws();
        let wall = vec![rect(0.78, 0.55, 0.88, 1.2)];
        let (s, g) = (Vector2::new(0.707, 0.857), Vector2::new(1.25, 0.6));
        let behind = ws.object_radius + ws.robot_radius + ObstacleParams::default().room_margin;
        let first_move = |p: &ObstacleParams| {
            let path = plan_object_path(&ws, &wall, s, g, p).expect("a path");
            assert_eq!(path[0], s);
            let next = path
                .iter()
                .find(|q| (**q - s).norm() > 0.03)
                .copied()
                .unwrap();
            (next - s).normalize()
        };
        // With the room cost on, which alone would take the object straight off the wall.
        let base = ObstacleParams {
            room_penalty: 4,
            ..ObstacleParams::default()
        };
        let d = first_move(&base);
        assert!(d.y < -0.7, "not along the wall: {d:?}");
        let blind = ObstacleParams {
            behind_penalty: 1,
            ..base
        };
        let d = first_move(&blind);
        assert!(d.x < -0.9, "straight off the wall: {d:?}");
        assert!(!robot_fits(&ws, &wall, s - d * behind), "{d:?}");
    }

    /// The robot's own path to the far side of a wall goes round its end, every leg clear.
    #[test]
    fn the_robot_transits_around_a_wall() {
        let ws = ws();
        let wall = vec![rect(0.78, 0.45, 0.88, 1.4)];
        let (a, b) = (Vector2::new(0.5, 0.9), Vector2::new(1.2, 0.9));
        assert!(!segment_clear(&ws, &wall, a, b));
        let path = plan_robot_path(&ws, &wall, a, b).expect("a way round");
        assert_eq!((path[0], *path.last().unwrap()), (a, b));
        assert!(path.len() >= 3 && path.len() < 10, "{path:?}");
        for w in path.windows(2) {
            assert!(segment_clear(&ws, &wall, w[0], w[1]), "{w:?}");
        }
        assert!(path.iter().any(|q| q.y < 0.45), "{path:?}");
    }

    /// On a clear table the shortest path is the straight line; round a wall it is the taut
    /// string past the wall's end (at the object's clearance), shorter than the grid's path
    /// and than the delivery's path (which pays for the robot's room), and no shorter than the
    /// two straight legs through the corner it bends at.
    /// Stand points where the robot only just fits (beside an object's disc, as the special
    /// case asks for them) all get a path from across a wall, ending there: a goal on the
    /// clearance's edge that rounds to a blocked grid cell is stood in for by a free one. Before,
    /// some had none, and the robot drove straight into the wall.
    #[test]
    fn a_goal_on_the_clearance_edge_still_has_a_path() {
        let ws = ws();
        let wall = rect(0.78, 0.55, 0.88, 1.2);
        let centre = Vector2::new(1.3, 0.95);
        // The object, a 12-gon; its robot-clearance edge at 0.055 m (radius + 1.5 cm).
        let inner = 0.1;
        let disc: Vec<[f64; 2]> = (0..12)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::TAU / 12.0;
                [centre.x + inner * a.cos(), centre.y + inner * a.sin()]
            })
            .collect();
        let around = vec![wall, disc];
        let from = Vector2::new(0.5, 0.8);
        let mut planned = 0;
        for k in 0..48 {
            let a = f64::from(k) * std::f64::consts::TAU / 48.0;
            let target = centre + (inner + 0.055) * Vector2::new(a.cos(), a.sin());
            if !robot_fits(&ws, &around, target) {
                continue;
            }
            let path = plan_robot_path(&ws, &around, from, target)
                .unwrap_or_else(|| panic!("no path to {target:?}"));
            assert_eq!(*path.last().unwrap(), target);
            for w in path.windows(2) {
                assert!(segment_clear(&ws, &around[..1], w[0], w[1]), "{w:?}");
            }
            planned += 1;
        }
        assert!(planned >= 40, "{planned}");
    }

    #[test]
    fn the_shortest_path_is_the_taut_string_round_the_wall() {
        let ws = ws();
        let p = ObstacleParams::default();
        let (s, g) = (Vector2::new(0.45, 0.95), Vector2::new(1.25, 0.6));
        let straight = shortest_object_path(&ws, &[], s, g, &p).unwrap();
        assert_eq!(straight, vec![s, g]);
        let wall = vec![rect(0.78, 0.45, 0.88, 1.2)];
        let taut = shortest_object_path(&ws, &wall, s, g, &p).unwrap();
        let grid = plan_object_path(&ws, &wall, s, g, &p).unwrap();
        assert!(taut.len() >= 3 && taut.len() < grid.len() / 4, "{taut:?}");
        let (lt, lg) = (path_length(&taut), path_length(&grid));
        assert!(lt < lg, "{lt} {lg}");
        // Every bend is below the wall's end, by about the object's clearance.
        let keep = ws.object_radius + p.object_margin;
        for v in &taut[1..taut.len() - 1] {
            assert!(v.y < 0.45 && clearance(*v, &wall) >= keep - 1e-9, "{v:?}");
            assert!(clearance(*v, &wall) < keep + 0.03, "{v:?}");
        }
        // No path is shorter than the legs through the wall's lower corners inflated by `keep`.
        let corner = Vector2::new(0.83, 0.45 - keep);
        assert!(
            lt >= (corner - s).norm() + (g - corner).norm() - 0.02,
            "{lt}"
        );
    }
}

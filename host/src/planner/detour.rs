//! Cutting the detours out of the object's global path (Lau, Mitani & Igarashi §III-E: the
//! global path the object is pushed along, [`crate::planner::global`]). The grid planner moves
//! in eight directions and a move without the robot's room behind the object costs more, so a
//! small sideways shift beside a wall can cost as much as a long detour; the object followed
//! such loops. A pure function of the path, the workspace and the obstacles.

use nalgebra::Vector2;
use pushbot_world::workspace::Workspace;

#[cfg(doc)]
use crate::planner::global::plan_object_path;
use crate::planner::global::{Clearances, ObstacleParams, along, object_fits, pushable};

/// A stretch of path at least this many times longer than the straight way between its ends
/// is a detour ([`shortcut_object_path`]); a staircase of grid steps is at most 1.08 times.
const DETOUR: f64 = 2.0;

/// `path` (from [`plan_object_path`]) with its detours cut: from each point kept, straight on
/// to the furthest later point the object can be pushed to in a straight line (its circle
/// clear of every obstacle and the robot's room behind it, [`plan_object_path`]'s rules,
/// every 5 mm of the way) when the path between is `DETOUR` (2) times that or longer.
///
/// The grid's eight directions make a small sideways shift as dear as a long detour where a
/// wall leaves no room behind the object for a push straight sideways: 2 cm to the side
/// beside a wall was planned as 6 cm back and 8 cm up again, and the object followed the
/// loop. A push mostly forward and a little sideways needs no such room. Only detours are
/// cut. Cutting every bend taut carried the object closer past walls' ends; over the 12
/// obstacle rows with 5 strategies it gave 102 recoveries against 63, and 17 trials over
/// 1.3× the shortest path against 11. A start or goal closer to an obstacle than the
/// clearance (the object lies there) keeps its step to its neighbour.
pub fn shortcut_object_path(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    path: &[Vector2<f64>],
    p: &ObstacleParams,
) -> Vec<Vector2<f64>> {
    let keep = Clearances::new(ws, p).object;
    let straight = |a: Vector2<f64>, b: Vector2<f64>| {
        along(a, b, |x| {
            object_fits(ws, obstacles, keep, x) && pushable(ws, obstacles, p, x, b - a)
        })
    };
    let Some(&first) = path.first() else {
        return Vec::new();
    };
    let mut arc = vec![0.0];
    for w in path.windows(2) {
        arc.push(arc[arc.len() - 1] + (w[1] - w[0]).norm());
    }
    let detour = |i: usize, j: usize| arc[j] - arc[i] >= DETOUR * (path[j] - path[i]).norm();
    let mut out = vec![first];
    let mut i = 0;
    while i + 1 < path.len() {
        let j = (i + 2..path.len())
            .rev()
            .find(|&j| detour(i, j) && straight(path[i], path[j]))
            .unwrap_or(i + 1);
        out.push(path[j]);
        i = j;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::global::tests::{rect, ws};
    use crate::planner::global::{clearance, path_length, plan_object_path, robot_fits};

    type Polygon = Vec<[f64; 2]>;

    /// The L-shape's body circle beside the zigzag's second wall, 2 cm left of and 8.5 cm
    /// below its goal (`lau-zigzag-l`, seen from start D after a recovery).
    fn beside_the_wall() -> (Workspace, Vec<Polygon>, Vector2<f64>, Vector2<f64>) {
        let ws = Workspace {
            object_radius: 0.092,
            body: pushbot_world::enclosing_circle::Circle::at_origin(0.092),
            ..ws()
        };
        let wall = vec![rect(1.0, 0.4, 1.1, 1.2)];
        (
            ws,
            wall,
            Vector2::new(1.231, 0.515),
            Vector2::new(1.25, 0.6),
        )
    }

    #[test]
    fn a_small_sideways_shift_beside_a_wall_is_a_straight_push_not_a_loop() {
        let (ws, wall, s, g) = beside_the_wall();
        let p = ObstacleParams::default();
        let grid = plan_object_path(&ws, &wall, s, g, &p).unwrap();
        // The grid's eight directions: 2 cm to the right needs a push straight or diagonally
        // right, with the robot inside the wall, so the grid path goes down below the wall's
        // end and back up.
        let low = grid.iter().map(|q| q.y).fold(f64::INFINITY, f64::min);
        assert!(low < s.y - 0.03, "{grid:?}");
        let cut = shortcut_object_path(&ws, &wall, &grid, &p);
        assert_eq!((cut[0], *cut.last().unwrap()), (s, g));
        let low = cut.iter().map(|q| q.y).fold(f64::INFINITY, f64::min);
        assert!(low > s.y - 0.005, "{cut:?}");
        assert!(path_length(&cut) < 1.1 * (g - s).norm(), "{cut:?}");
        // Every step of it keeps the circle clear and leaves the robot room behind.
        let keep = ws.object_radius + p.object_margin;
        let behind = ws.object_radius + ws.robot_radius + p.room_margin;
        for w in cut.windows(2) {
            let u = (w[1] - w[0]).normalize();
            for k in 0..=20 {
                let q = w[0] + (w[1] - w[0]) * (f64::from(k) / 20.0);
                assert!(clearance(q, &wall) >= keep, "{q:?}");
                assert!(robot_fits(&ws, &wall, q - u * behind), "{q:?}");
            }
        }
    }

    #[test]
    fn a_path_round_a_wall_keeps_its_bends() {
        let ws = ws();
        let p = ObstacleParams::default();
        let wall = vec![rect(0.78, 0.45, 0.88, 1.2)];
        let (s, g) = (Vector2::new(0.45, 0.95), Vector2::new(1.25, 0.6));
        let grid = plan_object_path(&ws, &wall, s, g, &p).unwrap();
        let cut = shortcut_object_path(&ws, &wall, &grid, &p);
        // No stretch of it is a detour, so nothing is cut (the taut string would be 5 points).
        assert_eq!(cut, grid);
    }
}

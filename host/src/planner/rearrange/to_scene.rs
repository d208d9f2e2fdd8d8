//! A grid problem of Ben-Shahar & Rivlin as a table scene (§V-B, the NOMAD-200 experiment's
//! set-up): the grid lies on the table with its row 0 along the far edge ([`GridFrame`]: cell
//! `(x, y)` has its centre at `((x + ½)·c, (h − y − ½)·c)` metres, table y pointing up, so the
//! map reads as the table seen from above). A movable is a body whose frame sits at the centre
//! of its anchor cell and turns with it (orientation `o` quarter turns clockwise is heading
//! `−o·π/2`); [`scene_for`] builds the scene for a grid problem in exactly these terms.

use anyhow::{Result, anyhow, bail};

use super::frame::GridFrame;
use super::problem::Problem;

/// How a grid problem becomes a simulator scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneOptions {
    /// Side of a cell, m.
    pub cell: f64,
    /// Fraction of its cells a movable's body fills (the rest is clearance on every side).
    pub fill: f64,
    /// Mass of one mass unit of the grid problem, kg.
    pub kg_per_mass: f64,
    /// Object–table friction coefficient.
    pub support_friction: f64,
    /// Robot–object friction coefficient.
    pub pusher_friction: f64,
}

impl Default for SceneOptions {
    fn default() -> Self {
        SceneOptions {
            cell: 0.1,
            fill: 0.8,
            kg_per_mass: 0.2,
            support_friction: 0.35,
            pusher_friction: 0.5,
        }
    }
}

/// The body-frame outline of a rectangular movable (cells `(0..w) × (0..h)` from its anchor),
/// shrunk by `margin` on every side; `None` if the shape is not a full rectangle at the anchor.
fn rect_outline(cells: &[(i32, i32)], cell: f64, margin: f64) -> Option<Vec<[f64; 2]>> {
    let (w, h) = (
        cells.iter().map(|c| c.0).max()? + 1,
        cells.iter().map(|c| c.1).max()? + 1,
    );
    let full = cells.iter().all(|&(x, y)| x >= 0 && y >= 0)
        && cells.len() == (w * h) as usize
        && (0..h).all(|y| (0..w).all(|x| cells.contains(&(x, y))));
    if !full {
        return None;
    }
    let (x0, x1) = (-0.5 * cell + margin, (w as f64 - 0.5) * cell - margin);
    // Grid y grows down, table y up.
    let (y0, y1) = (-(h as f64 - 0.5) * cell + margin, 0.5 * cell - margin);
    Some(vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
}

/// A simulator scene for a grid problem: the table is the grid, obstacle cells are square
/// obstacles (merged along rows), rectangular movables are boxes at their start with their
/// goals, the robot starts at the centre of its block facing its start heading. Only
/// rectangular movables can be built.
pub fn scene_for(problem: &Problem, opts: &SceneOptions) -> Result<pushbot_world::Scene> {
    use pushbot_world::scene::{Goal, Marker, Object, Obstacle, RobotSpec, Support, Table};
    let c = opts.cell;
    if !(c.is_finite() && c > 0.0 && opts.fill > 0.0 && opts.fill <= 1.0) {
        bail!("cell must be positive and fill in (0, 1]");
    }
    let g = &problem.grid;
    let frame = GridFrame { cell: c, h: g.h };
    let robot = RobotSpec::default();
    let mut obstacles = Vec::new();
    for y in 0..g.h {
        let mut x = 0;
        while x < g.w {
            if g.get(x, y).is_some_and(|cell| cell.obstacle) {
                let x0 = x;
                while g.get(x, y).is_some_and(|cell| cell.obstacle) {
                    x += 1;
                }
                let (ax, bx) = (x0 as f64 * c, x as f64 * c);
                let (ay, by) = ((g.h - y - 1) as f64 * c, (g.h - y) as f64 * c);
                obstacles.push(Obstacle {
                    outline: vec![[ax, ay], [bx, ay], [bx, by], [ax, by]],
                });
            } else {
                x += 1;
            }
        }
    }
    let margin = (1.0 - opts.fill) / 2.0 * c;
    let mut objects = Vec::new();
    let mut goals = Vec::new();
    for (i, m) in problem.movables.iter().enumerate() {
        let outline = rect_outline(&m.cells, c, margin).ok_or_else(|| {
            anyhow!(
                "movable `{}`: only rectangular movables can be built as simulator boxes",
                m.name
            )
        })?;
        let side = outline[1][0] - outline[0][0];
        let p = problem.start.movables[i];
        let pose = frame.body_pose(p);
        objects.push(Object {
            id: m.name.clone(),
            outline,
            pose: pushbot_world::Pose::new(pose.x, pose.y, pose.theta),
            mass: opts.kg_per_mass * m.mass.max(1) as f64,
            support: Support::Uniform,
            support_friction: opts.support_friction,
            pusher_friction: opts.pusher_friction,
            marker: Some(Marker {
                id: 10 + i as u32,
                x: 0.0,
                y: 0.0,
                size: (0.7 * side).min(0.05),
                z: 0.0,
            }),
        });
        if let Some(gp) = problem.goal_movables[i] {
            let gpose = frame.body_pose(gp);
            goals.push(Goal {
                object: m.name.clone(),
                pose: pushbot_world::Pose::new(gpose.x, gpose.y, gpose.theta),
                tolerance: 0.25 * c,
                angle_tolerance: None,
                marker: None,
            });
        }
    }
    let rc = frame.robot_centre(problem.start.robot, problem.robot.size);
    let scene = pushbot_world::Scene {
        name: problem.name.clone(),
        table: Table {
            width: g.w as f64 * c,
            height: g.h as f64 * c,
        },
        robot: RobotSpec {
            start: pushbot_world::Pose::new(rc.x, rc.y, GridFrame::heading(problem.start.heading)),
            ..robot
        },
        obstacles,
        objects,
        goals,
        positions: Vec::new(),
        camera: pushbot_world::scene::CameraSpec::default(),
        rearrange: Some(super::scene::rearrange_section(
            problem,
            c,
            opts.kg_per_mass,
        )),
        stable: None,
        perturb: None,
    };
    // Round-trip through the checked loader so the scene is one the simulator accepts.
    pushbot_world::Scene::from_toml(&scene.to_toml(), &format!("grid scene {}", problem.name))
        .map_err(|e| anyhow!("{e}"))
}

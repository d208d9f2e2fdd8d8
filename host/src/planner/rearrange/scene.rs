//! The shared scene format (`pushbot_world::Scene`) as a grid pushing problem of Ben-Shahar &
//! Rivlin §II-A: the table, obstacles, objects and goals rasterised to cells of the scene's
//! `[rearrange]` section (`pushbot_world::scene::rearrange`), with its admissibility (§IV-B) and
//! metric (§IV-C).
//!
//! Rasterisation, in the terms of [`GridFrame`] (row 0 along the far edge of the table):
//! - a cell is an obstacle when any of 3 × 3 points spread over it lies in an obstacle polygon;
//!   the optional ASCII `map` adds obstacles, rough cells and cells where no movable may be left;
//! - the robot is a block of `robot_size` cells (default: the fewest that hold its bumper),
//!   anchored where its centre lies (its start, and its goal if `robot_goal` is given);
//! - an object's anchor is the cell under its frame's origin, its orientation its heading in
//!   quarter turns (clockwise = `−π/2`), its shape the cells whose centres its outline covers
//!   (in its own frame), its goal the scene's goal for it (if any).

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector2;
use pushbot_world::Scene;
use pushbot_world::scene::rearrange::{Field, Rearrange, error_at};
use pushbot_world::scene::{SceneError, placed};

use super::frame::GridFrame;
use super::metric::Metric;
use super::problem::{
    Cell, Config, ContactMode, Dir, Grid, MovableSpec, Placement, Problem, RobotSpec, Rules,
    face_modes,
};

/// Is `p` inside the polygon (even–odd rule)?
fn inside(poly: &[[f64; 2]], p: Vector2<f64>) -> bool {
    let mut c = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + n - 1) % n]);
        if (a[1] > p.y) != (b[1] > p.y) && p.x < (b[0] - a[0]) * (p.y - a[1]) / (b[1] - a[1]) + a[0]
        {
            c = !c;
        }
    }
    c
}

/// Quarter turns clockwise of a heading (rad), 0..4.
fn quarter_turns(theta: f64) -> u8 {
    ((-theta / FRAC_PI_2).round() as i64).rem_euclid(4) as u8
}

/// The grid problem of a scene with a `[rearrange]` section; `text` (the scene's TOML, when
/// at hand) lets errors name the line of the field.
pub fn problem_from_scene(
    scene: &Scene,
    text: Option<&str>,
    file: &str,
) -> Result<Problem, SceneError> {
    use Field::{Index, Key};
    let err = |path: &[Field], msg: String| error_at(text, file, path, msg);
    let Some(r) = &scene.rearrange else {
        return Err(err(
            &[],
            "the scene has no [rearrange] section (at least `cell`) for the grid planner".into(),
        ));
    };
    let rr: &Rearrange = r;
    let c = rr.cell;
    let (w, h) = (
        (scene.table.width / c + 1e-6).floor(),
        (scene.table.height / c + 1e-6).floor(),
    );
    if !(c.is_finite() && c > 0.0 && (1.0..=256.0).contains(&w) && (1.0..=256.0).contains(&h)) {
        return Err(err(
            &[Key("rearrange"), Key("cell")],
            format!("{c} m makes a grid of {w} × {h} cells; each side must be 1..=256"),
        ));
    }
    let (w, h) = (w as i32, h as i32);
    let frame = GridFrame { cell: c, h };
    let mut grid = Grid::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let o = frame.centre(x, y);
            let hit = scene.obstacles.iter().any(|ob| {
                (-1..=1).any(|i| {
                    (-1..=1).any(|j| {
                        let p = o + Vector2::new(i as f64, j as f64) * (c / 3.0);
                        inside(&ob.outline, p)
                    })
                })
            });
            grid.at_mut(x, y).obstacle = hit;
        }
    }
    if let Some(map) = &rr.map {
        let at = [Key("rearrange"), Key("map")];
        let rows: Vec<&str> = map
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        if rows.len() != h as usize || rows.iter().any(|r| r.chars().count() != w as usize) {
            return Err(err(
                &at,
                format!("the map must have {h} rows of {w} cells (the table in cells of {c} m)"),
            ));
        }
        for (y, row) in rows.iter().enumerate() {
            for (x, ch) in row.chars().enumerate() {
                let cell = grid.at_mut(x as i32, y as i32);
                match ch {
                    '.' => {}
                    '#' => cell.obstacle = true,
                    ',' => cell.rough = 1,
                    ';' => cell.rough = 2,
                    'x' => cell.no_leave = true,
                    other => {
                        return Err(err(
                            &at,
                            format!(
                                "row {} column {}: unknown cell '{other}' (use . # , ; x)",
                                y + 1,
                                x + 1
                            ),
                        ));
                    }
                }
            }
        }
    }
    let dir = |s: &str, path: &[Field]| -> Result<Dir, SceneError> {
        Dir::parse(s).ok_or_else(|| err(path, format!("'{s}' is not one of N, E, S, W")))
    };
    let radius = scene.robot.bumper_radius;
    let size = match rr.robot_size {
        Some(k) => k as i32,
        None => ((2.0 * radius / c) - 1e-9).ceil().max(1.0) as i32,
    };
    if !(1..=8).contains(&size) {
        return Err(err(
            &[Key("rearrange"), Key("robot_size")],
            format!("a robot of {size} × {size} cells: must be 1..=8"),
        ));
    }
    let start = scene.robot.start;
    let half = (size - 1) as f64 / 2.0 * c;
    // The anchor (top-left cell) of the robot's block with its centre at `p`.
    let anchor = |p: Vector2<f64>| frame.cell_of(Vector2::new(p.x - half, p.y + half));
    let robot_at = anchor(Vector2::new(start.x, start.y));
    let goal_robot = match rr.robot_goal {
        Some([gx, gy]) => {
            let (x, y) = anchor(Vector2::new(gx, gy));
            if !(gx.is_finite() && gy.is_finite()) || grid.get(x, y).is_none() {
                return Err(err(
                    &[Key("rearrange"), Key("robot_goal")],
                    format!("[{gx}, {gy}] m is not on the {w} × {h} grid of the table"),
                ));
            }
            Some((x, y))
        }
        None => None,
    };
    let heading = Dir::from_index(quarter_turns(start.theta) as usize);
    let mut movables = Vec::new();
    let mut starts = Vec::new();
    let mut goals = Vec::new();
    for (i, ob) in scene.objects.iter().enumerate() {
        let at = |k| vec![Key("objects"), Index(i), Key(k)];
        let over = rr.movables.iter().position(|m| m.object == ob.id);
        let mpath = |j: usize, k| vec![Key("rearrange"), Key("movable"), Index(j), Key(k)];
        let spec = over.map(|j| &rr.movables[j]);
        let rotates = spec.is_some_and(|m| m.rotates);
        // The shape: cells whose centres the outline covers, around the frame's origin; a 3-DOF
        // movable's in its own frame (orientation 0), a 2-DOF one's as it lies on the table.
        let turn = if rotates { 0.0 } else { ob.pose.theta };
        let outline = placed(&ob.outline, &pushbot_world::Pose::new(0.0, 0.0, turn));
        let mut cells = Vec::new();
        for dy in -16..=16 {
            for dx in -16..=16 {
                let p = Vector2::new(dx as f64 * c, -dy as f64 * c);
                if inside(&outline, p) {
                    cells.push((dx, dy));
                }
            }
        }
        if !cells.contains(&(0, 0)) {
            return Err(err(
                &at("outline"),
                format!(
                    "object {:?}: its outline must cover its frame's origin (the anchor cell's centre) at a cell of {c} m",
                    ob.id
                ),
            ));
        }
        let mass = match spec.and_then(|m| m.mass) {
            Some(m) => m,
            None => ((ob.mass / rr.kg_per_mass).round() as u32).max(1),
        };
        let mut modes = Vec::new();
        if let (Some(m), Some(j)) = (spec, over) {
            if m.faces.unwrap_or(m.push.is_empty()) {
                modes.extend(face_modes(&cells));
            }
            for (k, p) in m.push.iter().enumerate() {
                let mut path = mpath(j, "push");
                path.extend([Index(k), Key("dir")]);
                modes.push(ContactMode::Translate {
                    point: (p.point[0], p.point[1]),
                    dir: dir(&p.dir, &path)?,
                });
            }
            for (k, q) in m.rotate.iter().enumerate() {
                let mut path = mpath(j, "rotate");
                path.extend([Index(k), Key("dir")]);
                let d = dir(&q.dir, &path)?;
                let turn = match q.turn.as_str() {
                    "cw" => 1,
                    "ccw" => -1,
                    other => {
                        path.pop();
                        path.push(Key("turn"));
                        return Err(err(&path, format!("'{other}' is not cw or ccw")));
                    }
                };
                modes.push(ContactMode::Rotate {
                    point: (q.point[0], q.point[1]),
                    dir: d,
                    turn,
                    shift: (q.shift[0], q.shift[1]),
                });
            }
        } else {
            modes = face_modes(&cells);
        }
        let (x, y) = frame.cell_of(Vector2::new(ob.pose.x, ob.pose.y));
        let o = if rotates {
            quarter_turns(ob.pose.theta)
        } else {
            0
        };
        starts.push(Placement { x, y, o });
        let goal = scene.goals.iter().find(|g| g.object == ob.id).map(|g| {
            let (gx, gy) = frame.cell_of(Vector2::new(g.pose.x, g.pose.y));
            Placement {
                x: gx,
                y: gy,
                o: if rotates {
                    quarter_turns(g.pose.theta)
                } else {
                    0
                },
            }
        });
        goals.push(goal);
        movables.push(MovableSpec {
            name: ob.id.clone(),
            cells,
            mass,
            rotates,
            modes,
        });
    }
    for (j, m) in rr.movables.iter().enumerate() {
        if scene.object(&m.object).is_none() {
            return Err(err(
                &[Key("rearrange"), Key("movable"), Index(j), Key("object")],
                format!("no object {:?} in the scene", m.object),
            ));
        }
    }
    let mut push_dirs = 0u8;
    for ch in rr.rules.push_dirs.chars() {
        let d = dir(
            &ch.to_string(),
            &[Key("rearrange"), Key("rules"), Key("push_dirs")],
        )?;
        push_dirs |= 1 << d as u8;
    }
    let m = &rr.metric;
    Ok(Problem {
        name: scene.name.clone(),
        grid,
        robot: RobotSpec {
            size,
            mass: rr.robot_mass,
        },
        movables,
        rules: Rules {
            push_dirs,
            max_pushed: rr.rules.max_pushed,
            distance_limit: rr.rules.distance_limit,
            strict_contact: rr.rules.strict_contact,
            rotations: rr.rules.rotations,
        },
        metric: Metric {
            rough: m.rough,
            safety: m.safety,
            turn: m.turn,
            mode_change: m.mode_change,
        },
        start: Config {
            robot: robot_at,
            heading,
            pushing: false,
            movables: starts,
        },
        goal_robot,
        goal_movables: goals,
    })
}

/// The `[rearrange]` section that describes a grid problem's settings (rules, metric, masses,
/// contact modes and the cells a polygon cannot say: rough and no-leave cells).
pub fn rearrange_section(p: &Problem, cell: f64, kg_per_mass: f64) -> Rearrange {
    use pushbot_world::scene::rearrange::{Metric as M, Movable, Push, Rotate, Rules as R};
    let special = p.grid.cells.iter().any(|c| c.rough > 0 || c.no_leave);
    let map = special.then(|| {
        let mut s = String::new();
        for y in 0..p.grid.h {
            for x in 0..p.grid.w {
                let c: Cell = p.grid.get(x, y).copied().unwrap_or_default();
                s.push(if c.obstacle {
                    '#'
                } else if c.no_leave {
                    'x'
                } else if c.rough == 1 {
                    ','
                } else if c.rough >= 2 {
                    ';'
                } else {
                    '.'
                });
            }
            s.push('\n');
        }
        s
    });
    let frame = GridFrame { cell, h: p.grid.h };
    Rearrange {
        cell,
        robot_size: Some(p.robot.size as u32),
        robot_mass: p.robot.mass,
        robot_goal: p.goal_robot.map(|g| {
            let c = frame.robot_centre(g, p.robot.size);
            [c.x, c.y]
        }),
        kg_per_mass,
        map,
        rules: R {
            max_pushed: p.rules.max_pushed,
            push_dirs: Dir::ALL
                .iter()
                .filter(|d| p.rules.push_dirs & (1 << **d as u8) != 0)
                .map(|d| d.letter())
                .collect(),
            distance_limit: p.rules.distance_limit,
            strict_contact: p.rules.strict_contact,
            rotations: p.rules.rotations,
        },
        metric: M {
            rough: p.metric.rough,
            safety: p.metric.safety,
            turn: p.metric.turn,
            mode_change: p.metric.mode_change,
        },
        movables: p
            .movables
            .iter()
            .map(|m| {
                let mut push = Vec::new();
                let mut rotate = Vec::new();
                for mode in &m.modes {
                    match *mode {
                        ContactMode::Translate { point, dir } => push.push(Push {
                            point: [point.0, point.1],
                            dir: dir.letter().to_string(),
                        }),
                        ContactMode::Rotate {
                            point,
                            dir,
                            turn,
                            shift,
                        } => rotate.push(Rotate {
                            point: [point.0, point.1],
                            dir: dir.letter().to_string(),
                            turn: if turn > 0 { "cw" } else { "ccw" }.to_string(),
                            shift: [shift.0, shift.1],
                        }),
                    }
                }
                Movable {
                    object: m.name.clone(),
                    mass: Some(m.mass),
                    rotates: m.rotates,
                    faces: Some(false),
                    push,
                    rotate,
                }
            })
            .collect(),
    }
}

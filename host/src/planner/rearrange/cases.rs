//! Rearrangement scenes: a small TOML format, and the test cases of Ben-Shahar & Rivlin §V-A
//! (A1–A4, B1–B2, C1–C2, D1) as presets written in it.
//!
//! ```toml
//! name = "example"
//! # '.' free, '#' obstacle, ',' rough, ';' very rough, 'x' no movable may be left here
//! map = """
//! ......
//! ..##..
//! ......
//! """
//! [robot]
//! at = [0, 0]          # anchor (top-left cell); x grows east, y grows south
//! size = 1             # the robot is a size × size block
//! mass = 1             # weight of its own motion in the mass metric
//! heading = "E"        # last direction, for the turn metric
//! goal = [5, 2]        # optional; the robot may end anywhere by default
//!
//! [[movable]]
//! name = "a"
//! cells = [[0, 0], [1, 0]]   # shape relative to the anchor (default one cell)
//! at = [1, 2]
//! goal = [3, 2]              # optional
//! mass = 1
//! rotates = false            # 3-DOF: takes the four orientations
//! faces = true               # translational contact modes on every face (default when no
//!                            # [[movable.push]] is given)
//! # [[movable.push]]   point = [-1, 0], dir = "E"
//! # [[movable.rotate]] point = [1, 1], dir = "N", turn = "ccw", shift = [0, 0]
//!
//! [rules]                    # admissibility, §IV-B
//! max_pushed = 1             # 1, 2, … or 0 for any number
//! push_dirs = "NESW"
//! distance_limit = 7         # Manhattan, robot anchor to each movable it is not pushing
//! strict_contact = true      # touch movables only through contact modes
//! rotations = true
//!
//! [metric]                   # §IV-C
//! rough = [2, 4]             # passability factors of rough and very rough cells
//! safety = 0
//! turn = 0
//! mode_change = 0
//! ```

use serde::Deserialize;
use toml::Spanned;

use super::metric::Metric;
use super::problem::{
    Cell, Config, ContactMode, Dir, Grid, MovableSpec, Placement, Problem, RobotSpec, Rules,
    face_modes,
};

/// Why a scene could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SceneError(pub String);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    name: Option<String>,
    #[allow(dead_code)]
    description: Option<String>,
    map: Spanned<String>,
    robot: RobotFile,
    #[serde(default, rename = "movable")]
    movables: Vec<MovableFile>,
    #[serde(default)]
    rules: RulesFile,
    #[serde(default)]
    metric: MetricFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotFile {
    at: Spanned<[i32; 2]>,
    #[serde(default = "one_i32")]
    size: i32,
    #[serde(default = "one")]
    mass: u32,
    heading: Option<Spanned<String>>,
    goal: Option<Spanned<[i32; 2]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MovableFile {
    name: Spanned<String>,
    cells: Option<Vec<[i32; 2]>>,
    at: Spanned<[i32; 2]>,
    #[serde(default)]
    orientation: u8,
    goal: Option<Spanned<[i32; 2]>>,
    goal_orientation: Option<u8>,
    #[serde(default = "one")]
    mass: u32,
    #[serde(default)]
    rotates: bool,
    faces: Option<bool>,
    #[serde(default)]
    push: Vec<PushFile>,
    #[serde(default)]
    rotate: Vec<RotateFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PushFile {
    point: [i32; 2],
    dir: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RotateFile {
    point: [i32; 2],
    dir: Spanned<String>,
    turn: Spanned<String>,
    #[serde(default)]
    shift: [i32; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RulesFile {
    #[serde(default = "one_u8")]
    max_pushed: u8,
    push_dirs: Option<Spanned<String>>,
    distance_limit: Option<u32>,
    #[serde(default = "yes")]
    strict_contact: bool,
    #[serde(default = "yes")]
    rotations: bool,
}

impl Default for RulesFile {
    fn default() -> Self {
        RulesFile {
            max_pushed: 1,
            push_dirs: None,
            distance_limit: None,
            strict_contact: true,
            rotations: true,
        }
    }
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct MetricFile {
    rough: Option<[u32; 2]>,
    #[serde(default)]
    safety: u32,
    #[serde(default)]
    turn: u32,
    #[serde(default)]
    mode_change: u32,
}

fn one() -> u32 {
    1
}
fn one_i32() -> i32 {
    1
}
fn one_u8() -> u8 {
    1
}
fn yes() -> bool {
    true
}

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())]
        .bytes()
        .filter(|&b| b == b'\n')
        .count()
        + 1
}

/// Parse a scene from TOML text. Errors name the line and the field.
pub fn parse_scene(text: &str, default_name: &str) -> Result<Problem, SceneError> {
    let f: SceneFile = toml::from_str(text).map_err(|e| SceneError(format!("scene: {e}")))?;
    let err = |span: std::ops::Range<usize>, field: &str, msg: String| -> SceneError {
        SceneError(format!(
            "scene line {}: `{field}`: {msg}",
            line_of(text, span.start)
        ))
    };
    // map
    let map_span = f.map.span();
    let rows: Vec<&str> = f
        .map
        .get_ref()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    if rows.is_empty() {
        return Err(err(map_span, "map", "the map has no rows".into()));
    }
    let w = rows[0].chars().count();
    if w > 256 || rows.len() > 256 {
        return Err(err(
            map_span,
            "map",
            "the map may be at most 256 × 256".into(),
        ));
    }
    let mut grid = Grid::new(w as i32, rows.len() as i32);
    for (y, row) in rows.iter().enumerate() {
        if row.chars().count() != w {
            return Err(err(
                map_span.clone(),
                "map",
                format!(
                    "row {} has {} cells, the first row {w}",
                    y + 1,
                    row.chars().count()
                ),
            ));
        }
        for (x, ch) in row.chars().enumerate() {
            let cell = match ch {
                '.' => Cell::default(),
                '#' => Cell {
                    obstacle: true,
                    ..Cell::default()
                },
                ',' => Cell {
                    rough: 1,
                    ..Cell::default()
                },
                ';' => Cell {
                    rough: 2,
                    ..Cell::default()
                },
                'x' => Cell {
                    no_leave: true,
                    ..Cell::default()
                },
                other => {
                    return Err(err(
                        map_span.clone(),
                        "map",
                        format!(
                            "row {} column {}: unknown cell '{other}' (use . # , ; x)",
                            y + 1,
                            x + 1
                        ),
                    ));
                }
            };
            *grid.at_mut(x as i32, y as i32) = cell;
        }
    }
    let parse_dir = |s: &Spanned<String>, field: &str| -> Result<Dir, SceneError> {
        Dir::parse(s.get_ref()).ok_or_else(|| {
            err(
                s.span(),
                field,
                format!("'{}' is not one of N, E, S, W", s.get_ref()),
            )
        })
    };
    let in_grid = |p: &Spanned<[i32; 2]>, field: &str| -> Result<(i32, i32), SceneError> {
        let [x, y] = *p.get_ref();
        if grid.get(x, y).is_none() {
            return Err(err(
                p.span(),
                field,
                format!("[{x}, {y}] is outside the {}×{} map", grid.w, grid.h),
            ));
        }
        Ok((x, y))
    };
    let robot = RobotSpec {
        size: f.robot.size,
        mass: f.robot.mass,
    };
    let start_robot = in_grid(&f.robot.at, "robot.at")?;
    let heading = match &f.robot.heading {
        Some(h) => parse_dir(h, "robot.heading")?,
        None => Dir::E,
    };
    let goal_robot = match &f.robot.goal {
        Some(g) => Some(in_grid(g, "robot.goal")?),
        None => None,
    };
    let mut movables = Vec::new();
    let mut starts = Vec::new();
    let mut goals = Vec::new();
    for m in &f.movables {
        let name = m.name.get_ref().clone();
        let field = |s: &str| format!("movable `{name}`.{s}");
        let cells: Vec<(i32, i32)> = m
            .cells
            .clone()
            .unwrap_or_else(|| vec![[0, 0]])
            .iter()
            .map(|c| (c[0], c[1]))
            .collect();
        if cells.is_empty() {
            return Err(err(
                m.name.span(),
                &field("cells"),
                "needs at least one cell".into(),
            ));
        }
        if m.orientation > 3 || m.goal_orientation.is_some_and(|o| o > 3) {
            return Err(err(
                m.name.span(),
                &field("orientation"),
                "must be 0..=3".into(),
            ));
        }
        let mut modes = Vec::new();
        if m.faces.unwrap_or(m.push.is_empty()) {
            modes.extend(face_modes(&cells));
        }
        for p in &m.push {
            modes.push(ContactMode::Translate {
                point: (p.point[0], p.point[1]),
                dir: parse_dir(&p.dir, &field("push.dir"))?,
            });
        }
        for r in &m.rotate {
            let turn = match r.turn.get_ref().as_str() {
                "cw" => 1,
                "ccw" => -1,
                other => {
                    return Err(err(
                        r.turn.span(),
                        &field("rotate.turn"),
                        format!("'{other}' is not cw or ccw"),
                    ));
                }
            };
            modes.push(ContactMode::Rotate {
                point: (r.point[0], r.point[1]),
                dir: parse_dir(&r.dir, &field("rotate.dir"))?,
                turn,
                shift: (r.shift[0], r.shift[1]),
            });
        }
        let (x, y) = in_grid(&m.at, &field("at"))?;
        starts.push(Placement {
            x,
            y,
            o: m.orientation,
        });
        goals.push(match &m.goal {
            Some(g) => {
                let (gx, gy) = in_grid(g, &field("goal"))?;
                Some(Placement {
                    x: gx,
                    y: gy,
                    o: m.goal_orientation.unwrap_or(m.orientation),
                })
            }
            None => None,
        });
        movables.push(MovableSpec {
            name,
            cells,
            mass: m.mass,
            rotates: m.rotates,
            modes,
        });
    }
    let mut push_dirs = 0u8;
    match &f.rules.push_dirs {
        Some(s) => {
            for ch in s.get_ref().chars() {
                let d = Dir::parse(&ch.to_string()).ok_or_else(|| {
                    err(
                        s.span(),
                        "rules.push_dirs",
                        format!("'{ch}' is not one of N, E, S, W"),
                    )
                })?;
                push_dirs |= 1 << d as u8;
            }
        }
        None => push_dirs = 0b1111,
    }
    let rules = Rules {
        push_dirs,
        max_pushed: f.rules.max_pushed,
        distance_limit: f.rules.distance_limit,
        strict_contact: f.rules.strict_contact,
        rotations: f.rules.rotations,
    };
    let metric = Metric {
        rough: f.metric.rough.unwrap_or([1, 1]),
        safety: f.metric.safety,
        turn: f.metric.turn,
        mode_change: f.metric.mode_change,
    };
    Ok(Problem {
        name: f.name.unwrap_or_else(|| default_name.to_string()),
        grid,
        robot,
        movables,
        rules,
        metric,
        start: Config {
            robot: start_robot,
            heading,
            pushing: false,
            movables: starts,
        },
        goal_robot,
        goal_movables: goals,
    })
}

/// The presets: (name, what the paper shows, TOML).
pub const CASES: &[(&str, &str, &str)] = &[
    ("A1", "Fig. 9: one box at a time, mass metric", A1),
    ("A2", "Fig. 10: up to two boxes at once", A2),
    (
        "A3",
        "Fig. 11: two at once, a rough region changes the route",
        A3,
    ),
    (
        "A4",
        "Fig. 12: one at a time, distance limit 7: the robot fetches the second box",
        A4,
    ),
    (
        "B1",
        "Fig. 13: exchanging two boxes needs an intermediate placement",
        B1,
    ),
    ("B2", "Fig. 14: a rough region changes the exchange", B2),
    (
        "C1",
        "Fig. 16: a complex movable pushed by a small robot",
        C1,
    ),
    (
        "C2",
        "Fig. 17: the same with a large robot, some pushes no longer fit",
        C2,
    ),
    ("D1", "Fig. 19: rotational pushes in clutter", D1),
];

/// Load a preset by name (case-insensitive), a simulator preset with a `[rearrange]` section,
/// or a scene file by path: the shared scene format (it has a `[table]`; see
/// [`super::scene`]) or this grid format.
pub fn load_scene(name_or_path: &str) -> Result<Problem, SceneError> {
    if let Some((n, _, text)) = CASES
        .iter()
        .find(|(n, _, _)| n.eq_ignore_ascii_case(name_or_path))
    {
        return parse_scene(text, n);
    }
    if pushbot_sim::scene::PRESETS.contains(&name_or_path) {
        let scene =
            pushbot_sim::Scene::preset(name_or_path).map_err(|e| SceneError(e.to_string()))?;
        return super::scene::problem_from_scene(&scene, None, &format!("preset {name_or_path}"))
            .map_err(|e| SceneError(e.to_string()));
    }
    let path = std::path::Path::new(name_or_path);
    let text = std::fs::read_to_string(path).map_err(|e| {
        SceneError(format!(
            "scene `{name_or_path}`: not a preset ({}) and not a readable file: {e}",
            CASES.iter().map(|c| c.0).collect::<Vec<_>>().join(", ")
        ))
    })?;
    let file = path.display().to_string();
    if toml::from_str::<toml::Table>(&text).is_ok_and(|t| t.contains_key("table")) {
        let scene =
            pushbot_sim::Scene::from_toml(&text, &file).map_err(|e| SceneError(e.to_string()))?;
        return super::scene::problem_from_scene(&scene, Some(&text), &file)
            .map_err(|e| SceneError(e.to_string()));
    }
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
    parse_scene(&text, stem).map_err(|e| SceneError(format!("{file}: {}", e.0)))
}

macro_rules! a_map {
    () => {
        r#"map = """
..................
..................
..................
..................
..................
..................
..................
"""
"#
    };
}

macro_rules! case_a {
    ($name:literal, $rules:literal, $metric:literal, $map:expr) => {
        concat!(
            "name = \"",
            $name,
            "\"\n",
            $map,
            r#"
[robot]
at = [0, 3]

[[movable]]
name = "a"
at = [2, 3]
goal = [14, 3]

[[movable]]
name = "b"
at = [4, 3]
goal = [15, 3]

[rules]
"#,
            $rules,
            "\n[metric]\n",
            $metric,
            "\n"
        )
    };
}

const A1: &str = case_a!("A1", "max_pushed = 1", "", a_map!());
const A2: &str = case_a!("A2", "max_pushed = 2", "", a_map!());
const A3: &str = case_a!(
    "A3",
    "max_pushed = 2",
    "rough = [3, 8]",
    r#"map = """
..................
..................
.......;;;;.......
.......;;;;.......
.......;;;;.......
..................
..................
"""
"#
);
const A4: &str = case_a!("A4", "max_pushed = 1\ndistance_limit = 7", "", a_map!());

macro_rules! b_map {
    () => {
        r#"map = """
#########
#.......#
#.......#
#.......#
#.......#
#.......#
#########
"""
"#
    };
}

macro_rules! case_b {
    ($name:literal, $map:expr, $metric:literal) => {
        concat!(
            "name = \"",
            $name,
            "\"\n",
            $map,
            r#"
[robot]
at = [1, 3]

[[movable]]
name = "a"
at = [3, 3]
goal = [5, 3]

[[movable]]
name = "b"
at = [5, 3]
goal = [3, 3]

[metric]
"#,
            $metric,
            "\n"
        )
    };
}

const B1: &str = case_b!("B1", b_map!(), "");
const B2: &str = case_b!(
    "B2",
    r#"map = """
#########
#;;;;;;.#
#;;;;;;.#
#.......#
#.......#
#.......#
#########
"""
"#,
    "rough = [4, 8]"
);

macro_rules! case_c {
    ($name:literal, $size:literal, $at:literal) => {
        concat!(
            "name = \"",
            $name,
            "\"\n",
            r#"# A low ceiling on the left: one free row above the movable's start.
map = """
################
########.......#
#..............#
#..............#
#..............#
#..............#
#..............#
#..............#
################
"""

[robot]
size = "#,
            $size,
            "\nat = ",
            $at,
            r#"

# A U-shaped movable opening north (Fig. 15): pushed south from its notch or the tops of its
# arms, north from under its middle, east or west from the middle of its sides.
[[movable]]
name = "u"
cells = [[0, 0], [2, 0], [0, 1], [1, 1], [2, 1]]
at = [3, 3]
goal = [3, 5]
faces = false
push = [
  { point = [1, 0], dir = "S" },
  { point = [0, -1], dir = "S" },
  { point = [2, -1], dir = "S" },
  { point = [1, 2], dir = "N" },
  { point = [-1, 1], dir = "E" },
  { point = [3, 1], dir = "W" },
]
"#
        )
    };
}

const C1: &str = case_c!("C1", "1", "[12, 2]");
const C2: &str = case_c!("C2", "2", "[12, 1]");

const D1: &str = r#"name = "D1"
# A bar that only slides along its length and turns by pushes at its ends (Fig. 18), among
# clutter: it has to turn to pass the gap in the wall and turn back at its goal.
map = """
.........
.........
.........
####.####
.........
.........
.........
"""

[robot]
at = [0, 0]

[[movable]]
name = "bar"
cells = [[0, 0], [1, 0]]
at = [3, 1]
goal = [5, 5]
rotates = true
faces = false
push = [
  { point = [-1, 0], dir = "E" },
  { point = [2, 0], dir = "W" },
]
rotate = [
  { point = [1, 1], dir = "N", turn = "ccw", shift = [0, 0] },
  { point = [1, -1], dir = "S", turn = "cw", shift = [0, 0] },
  { point = [0, 1], dir = "N", turn = "cw", shift = [1, -1] },
  { point = [0, -1], dir = "S", turn = "ccw", shift = [1, 1] },
]
"#;

//! The optional `[rearrange]` section of a scene: what Ben-Shahar & Rivlin's grid planner
//! (the host's `planner::rearrange`, §II and §IV of "To Push or Not to Push") needs beyond the
//! table itself. Data only: the simulator ignores it, the host rasterises the table, obstacles,
//! objects and goals to a grid of `cell` metres.
//!
//! ```toml
//! [rearrange]
//! cell = 0.1                 # m
//! robot_size = 1             # the robot is a block of cells (default: the smallest that holds it)
//! robot_mass = 1
//! robot_goal = [0.55, 0.25]  # optional: where the robot's centre must end (m, table frame)
//! kg_per_mass = 0.2          # an object of 0.4 kg has mass 2 in the mass metric
//! # Optional: the paper's exact map, row 0 along the far edge (table y = height), one character
//! # per cell: '.' free, '#' obstacle, ',' rough, ';' very rough, 'x' no movable may be left.
//! map = """
//! ....
//! .##.
//! """
//! rules = { max_pushed = 1, push_dirs = "NESW", distance_limit = 7 }
//! metric = { rough = [3, 8], safety = 0, turn = 0, mode_change = 0 }
//!
//! [[rearrange.movable]]      # optional, per object (default: mass from kg, pushes on every face)
//! object = "box-1"
//! mass = 2
//! rotates = false
//! push = [{ point = [-1, 0], dir = "E" }]            # grid cells from the anchor, y down
//! rotate = [{ point = [1, 1], dir = "N", turn = "ccw", shift = [0, 0] }]
//! ```

use serde::{Deserialize, Serialize};

use super::error::{SceneError, Seg, line_col, path_string, span_of};

/// Grid planning settings of a scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rearrange {
    /// Side of a grid cell, m.
    pub cell: f64,
    /// Side of the robot's block, cells (default: the smallest block that holds the bumper).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_size: Option<u32>,
    /// Weight of the robot's own motion in the mass metric.
    #[serde(default = "one")]
    pub robot_mass: u32,
    /// Where the robot must end: its centre, m, table frame, rasterised like its start
    /// (default: anywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_goal: Option<[f64; 2]>,
    /// Kilograms per mass unit of the mass metric.
    #[serde(default = "default_kg")]
    pub kg_per_mass: f64,
    /// The paper's exact map, if any; it adds to what is rasterised from the obstacles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<String>,
    /// Admissibility (§IV-B).
    #[serde(default)]
    pub rules: Rules,
    /// The metric (§IV-C).
    #[serde(default)]
    pub metric: Metric,
    /// Per-object settings.
    #[serde(default, rename = "movable", skip_serializing_if = "Vec::is_empty")]
    pub movables: Vec<Movable>,
}

/// Admissibility options (§IV-B).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Rules {
    /// Most movables pushed by one move (0 = any number).
    pub max_pushed: u8,
    /// Allowed pushing directions, letters of `NESW`.
    pub push_dirs: String,
    /// Manhattan distance limit from the robot to movables it is not pushing, cells.
    pub distance_limit: Option<u32>,
    /// Touch movables only through their contact modes.
    pub strict_contact: bool,
    /// Use rotational contact modes.
    pub rotations: bool,
}

impl Default for Rules {
    fn default() -> Self {
        Rules {
            max_pushed: 1,
            push_dirs: "NESW".into(),
            distance_limit: None,
            strict_contact: true,
            rotations: true,
        }
    }
}

/// Metric weights (§IV-C).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Metric {
    /// Passability factors of rough and very rough cells.
    pub rough: [u32; 2],
    /// Extra cost of pushing a movable next to an obstacle.
    pub safety: u32,
    /// Cost per quarter turn of the robot.
    pub turn: u32,
    /// Cost per contact-mode change.
    pub mode_change: u32,
}

impl Default for Metric {
    fn default() -> Self {
        Metric {
            rough: [1, 1],
            safety: 0,
            turn: 0,
            mode_change: 0,
        }
    }
}

/// Settings of one object as a movable.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Movable {
    /// The object's id.
    pub object: String,
    /// Mass in mass units (default: the object's kg / `kg_per_mass`, at least 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<u32>,
    /// 3-DOF: takes the four orientations.
    #[serde(default)]
    pub rotates: bool,
    /// Translational contact modes on every face (default: when no `push` is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<bool>,
    /// Translational contact modes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub push: Vec<Push>,
    /// Rotational contact modes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rotate: Vec<Rotate>,
}

/// A translational contact mode: the robot's leading face covers `point` and moves in `dir`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Push {
    /// Contact cell relative to the anchor (grid cells, y down).
    pub point: [i32; 2],
    /// `N`, `E`, `S` or `W`.
    pub dir: String,
}

/// A rotational contact mode (Fig. 18).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rotate {
    /// Contact cell relative to the anchor.
    pub point: [i32; 2],
    /// The robot's direction of motion.
    pub dir: String,
    /// `cw` or `ccw`.
    pub turn: String,
    /// New anchor minus old anchor.
    #[serde(default)]
    pub shift: [i32; 2],
}

fn one() -> u32 {
    1
}

fn default_kg() -> f64 {
    0.2
}

/// One step of a field path inside the scene document.
#[derive(Clone, Debug, PartialEq)]
pub enum Field {
    /// A table key.
    Key(&'static str),
    /// An array index.
    Index(usize),
}

/// A [`SceneError`] for a check that failed after parsing, with the field's line and column
/// looked up in the scene's text (when the text is at hand).
pub fn error_at(text: Option<&str>, file: &str, path: &[Field], message: String) -> SceneError {
    let segs: Vec<Seg> = path
        .iter()
        .map(|f| match f {
            Field::Key(k) => Seg::Key(k),
            Field::Index(i) => Seg::Index(*i),
        })
        .collect();
    let (line, column) = match text.and_then(|t| span_of(t, &segs).map(|s| line_col(t, s.start))) {
        Some((l, c)) => (Some(l), Some(c)),
        None => (None, None),
    };
    SceneError {
        file: file.to_owned(),
        line,
        column,
        field: Some(path_string(&segs)),
        message,
    }
}

//! Scenes: the one TOML format, shared by host and sim, that describes a pushing task — the
//! table, static obstacles, the robot, the objects (outline, mass, support distribution,
//! frictions, marker) and the goals — plus built-in presets loadable by name.
//!
//! ```toml
//! name = "example"
//! [table]                      # origin at the lower-left corner, metres
//! width = 1.2
//! height = 0.9
//!
//! [robot]                      # every field optional: the reference robot
//! bumper_radius = 0.04
//! start = { x = 0.2, y = 0.45, theta = 0.0 }   # radians
//!
//! [[obstacles]]                # static polygons, table frame, counter-clockwise or not
//! outline = [[0.5, 0.0], [0.55, 0.0], [0.55, 0.3], [0.5, 0.3]]
//!
//! [[objects]]
//! id = "box"
//! outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]  # object frame
//! pose = { x = 0.6, y = 0.45, theta = 0.0 }   # where the object frame is on the table
//! mass = 0.2                                  # kg
//! support = { kind = "uniform" }              # or { kind = "points", points = [[x, y], …], weights = […] }
//! support_friction = 0.35                     # object–table Coulomb coefficient
//! pusher_friction = 0.5                       # robot–object Coulomb coefficient
//! marker = { id = 3, x = 0.0, y = 0.0, size = 0.05, z = 0.03 }   # tag36h11, object frame; z: height above the table
//!
//! [[goals]]
//! object = "box"
//! pose = { x = 1.0, y = 0.7, theta = 0.0 }
//! tolerance = 0.022                           # m
//!
//! [[positions]]                # optional named poses (e.g. the start positions of a layout)
//! name = "A"
//! pose = { x = 0.3, y = 0.3, theta = 0.0 }
//! ```
//!
//! Errors name the file, the line and column, and the field (`objects[1].mass`): syntax and
//! type errors come from the `toml` crate's spans, and the checks that follow parsing (positive
//! masses, simple polygons, objects on the table, goals naming objects, …) look the field's
//! span up in the document.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::pose::Pose;

pub mod camera;
mod checks;
mod error;
mod sections;
mod validate;
pub use camera::{CameraSpec, InlineIntrinsics, IntrinsicsSpec, Occluder};
pub use error::SceneError;
use error::{Seg, key_before, line_col, path_string, span_of};
pub mod perturb;
pub mod rearrange;
pub mod stable;

/// A whole scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A name for reports.
    #[serde(default)]
    pub name: String,
    /// The table.
    pub table: Table,
    /// The robot.
    #[serde(default)]
    pub robot: RobotSpec,
    /// Static obstacles.
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// Objects to push.
    #[serde(default)]
    pub objects: Vec<Object>,
    /// Where objects should go.
    #[serde(default)]
    pub goals: Vec<Goal>,
    /// Named poses (start positions of a layout, waypoints).
    #[serde(default)]
    pub positions: Vec<NamedPose>,
    /// The overhead camera: image, robot marker, calibration markers.
    #[serde(default)]
    pub camera: CameraSpec,
    /// Grid rearrangement planning settings (see [`rearrange`]); the simulator ignores them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rearrange: Option<rearrange::Rearrange>,
    /// A stable-pushing task for the host's planner (the sim ignores it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stable: Option<stable::Stable>,
    /// How far the simulated world may differ from the model (`--perturb`; see [`perturb`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub perturb: Option<perturb::Perturb>,
}

/// The table: a rectangle with its origin at the lower-left corner; its edges are walls.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Table {
    /// Extent along x, m.
    pub width: f64,
    /// Extent along y, m.
    pub height: f64,
}

/// The robot's build and start. Missing fields are the reference robot's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RobotSpec {
    /// Bumper radius, m.
    pub bumper_radius: f64,
    /// Wheel base, m.
    pub wheel_base: f64,
    /// Wheel radius, m.
    pub wheel_radius: f64,
    /// Encoder counts per wheel revolution.
    pub encoder_cpr: u32,
    /// Motor no-load wheel speed at full duty, rad/s.
    pub no_load_speed: f64,
    /// Motor stall torque at the wheel at full duty, N·m.
    pub stall_torque: f64,
    /// True start pose.
    pub start: Pose,
    /// A flat front bumper plate (`{ width, offset }`, m); none: the round bumper only.
    pub front_plate: Option<crate::body::FrontPlate>,
}

impl Default for RobotSpec {
    /// The reference robot: the firmware's default geometry (`pushbot_firmware::RobotParams`,
    /// as `f32` there) and the simulator's default N20 motor at 6 V (no-load 32 rad/s, stall
    /// torque 0.018 N·m); `pushbot-sim`'s tests check that the two stay equal.
    fn default() -> Self {
        let (supply_v, ke) = (6.0, 6.0 / 32.0);
        let resistance = ke * supply_v / 0.018;
        RobotSpec {
            bumper_radius: f64::from(0.04_f32),
            wheel_base: f64::from(0.07_f32),
            wheel_radius: f64::from(0.016_f32),
            encoder_cpr: 1400,
            no_load_speed: supply_v / ke,
            stall_torque: ke * supply_v / resistance,
            start: Pose::new(0.2, 0.2, 0.0),
            front_plate: None,
        }
    }
}

/// A static obstacle: a polygon in the table frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Vertices, m, in order (either sense); convex or not, but simple.
    pub outline: Vec<[f64; 2]>,
}

/// How an object's weight rests on the table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Support {
    /// Pressure spread uniformly over the outline.
    Uniform,
    /// The weight rests on a few points (object frame), shared by `weights` (default equal).
    Points {
        /// Support points, m, object frame.
        points: Vec<[f64; 2]>,
        /// Relative share of each point (normalised; default all equal).
        #[serde(default)]
        weights: Option<Vec<f64>>,
    },
}

/// A fiducial marker (AprilTag tag36h11) printed on an object or the robot.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Marker {
    /// Tag id.
    pub id: u32,
    /// Centre, object frame, m.
    pub x: f64,
    /// Centre, object frame, m.
    pub y: f64,
    /// Side of the tag's black square, m.
    #[serde(default = "default_marker_size")]
    pub size: f64,
    /// Height of the tag above the table, m (finite, ≥ 0; default 0: on the table).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub z: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn default_marker_size() -> f64 {
    0.05
}

/// An object that can be pushed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Object {
    /// Unique name.
    pub id: String,
    /// Outline in the object frame, m; convex or not, but simple.
    pub outline: Vec<[f64; 2]>,
    /// Pose of the object frame on the table.
    pub pose: Pose,
    /// Mass, kg.
    pub mass: f64,
    /// Support pressure distribution.
    #[serde(default = "default_support")]
    pub support: Support,
    /// Object–table Coulomb friction coefficient.
    pub support_friction: f64,
    /// Robot–object Coulomb friction coefficient.
    pub pusher_friction: f64,
    /// Marker, if any.
    #[serde(default)]
    pub marker: Option<Marker>,
}

fn default_support() -> Support {
    Support::Uniform
}

/// A goal for an object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Goal {
    /// The object's id.
    pub object: String,
    /// Goal pose of the object frame (the heading matters only if `angle_tolerance` is set).
    pub pose: Pose,
    /// Position tolerance, m.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Heading tolerance, rad; absent: position only.
    #[serde(default)]
    pub angle_tolerance: Option<f64>,
    /// Marker drawn at the goal, if any.
    #[serde(default)]
    pub marker: Option<Marker>,
}

fn default_tolerance() -> f64 {
    0.022
}

/// A named pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NamedPose {
    /// Name.
    pub name: String,
    /// Pose, table frame.
    pub pose: Pose,
}

/// Something the loader changed in a scene that it accepted, for `scene check` to say (e.g. a
/// clockwise outline stored counter-clockwise).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Note {
    /// The field, e.g. `obstacles[0].outline`.
    pub field: String,
    /// What was done, e.g. `was clockwise; normalised to counter-clockwise`.
    pub message: String,
}

impl std::fmt::Display for Note {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.field, self.message)
    }
}

impl Scene {
    /// Parse and check a scene; `file` names the source in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Scene, SceneError> {
        Scene::from_toml_noted(text, file).map(|(s, _)| s)
    }

    /// Parse and check a scene, and say what was normalised: outlines are stored
    /// counter-clockwise (a clockwise one is reversed, keeping vertex 0 first; see
    /// [`crate::polygon::normalise_ccw`]).
    pub fn from_toml_noted(text: &str, file: &str) -> Result<(Scene, Vec<Note>), SceneError> {
        let mut scene: Scene = toml::from_str(text).map_err(|e| {
            let (line, column) = match e.span() {
                Some(s) => {
                    let (l, c) = line_col(text, s.start);
                    (Some(l), Some(c))
                }
                None => (None, None),
            };
            SceneError {
                file: file.to_owned(),
                line,
                column,
                field: e.span().and_then(|s| key_before(text, s.start)),
                message: e.message().trim().to_owned(),
            }
        })?;
        // The per-field checks on the scene as written (exact simple-polygon checks on every
        // outline as given), then the normalisation (winding, fine outlines simplified), then
        // the checks that need shapes, on the outlines every consumer will use.
        let checked = scene.check().map(|()| scene.normalise()).and_then(|notes| {
            scene.check_geometry()?;
            Ok(notes)
        });
        let notes = match checked {
            Ok(notes) => notes,
            Err(bad) => {
                let (line, column) = match span_of(text, &bad.path) {
                    Some(s) => {
                        let (l, c) = line_col(text, s.start);
                        (Some(l), Some(c))
                    }
                    None => (None, None),
                };
                return Err(SceneError {
                    file: file.to_owned(),
                    line,
                    column,
                    field: Some(path_string(&bad.path)),
                    message: bad.message,
                });
            }
        };
        if let Some(IntrinsicsSpec::Inline(l)) = &scene.camera.intrinsics {
            scene.camera.lens = Some(l.for_size(scene.camera.width, scene.camera.height));
        }
        Ok((scene, notes))
    }

    /// Read a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        Scene::load_noted(path).map(|(s, _)| s)
    }

    /// Read a scene file, and say what was normalised (see [`Scene::from_toml_noted`]).
    pub fn load_noted(path: &Path) -> Result<(Scene, Vec<Note>), SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            file: file.clone(),
            line: None,
            column: None,
            field: None,
            message: if e.kind() == std::io::ErrorKind::InvalidData {
                "cannot read: not a text (TOML) file".to_owned()
            } else {
                format!("cannot read: {e}")
            },
        })?;
        let (mut scene, notes) = Scene::from_toml_noted(&text, &file)?;
        if let Some(IntrinsicsSpec::File(name)) = scene.camera.intrinsics.clone() {
            let at = |message: String| {
                let span = span_of(&text, &[Seg::Key("camera"), Seg::Key("intrinsics")]);
                let (line, column) = span.map_or((None, None), |s| {
                    let (l, c) = line_col(&text, s.start);
                    (Some(l), Some(c))
                });
                SceneError {
                    file: file.clone(),
                    line,
                    column,
                    field: Some("camera.intrinsics".into()),
                    message,
                }
            };
            let lens_path = path.parent().unwrap_or(Path::new(".")).join(&name);
            let lens =
                crate::lens_file::read_intrinsics(&lens_path).map_err(|e| at(e.to_string()))?;
            if (lens.width, lens.height) != (scene.camera.width, scene.camera.height) {
                return Err(at(format!(
                    "the lens file is for {}×{} frames, the scene's camera is {}×{}",
                    lens.width, lens.height, scene.camera.width, scene.camera.height
                )));
            }
            scene.camera.lens = Some(lens);
        }
        Ok((scene, notes))
    }

    /// A built-in preset by name (see [`PRESETS`]).
    pub fn preset(name: &str) -> Result<Scene, SceneError> {
        match crate::presets::text(name) {
            Some(text) => Scene::from_toml(&text, &format!("preset {name}")),
            None => Err(SceneError {
                file: format!("preset {name}"),
                line: None,
                column: None,
                field: None,
                message: format!("no such preset; the presets are: {}", PRESETS.join(", ")),
            }),
        }
    }

    /// A preset by name, or else a file by path.
    pub fn preset_or_file(name_or_path: &str) -> Result<Scene, SceneError> {
        Scene::preset_or_file_noted(name_or_path).map(|(s, _)| s)
    }

    /// A preset by name, or else a file by path, and what was normalised (see
    /// [`Scene::from_toml_noted`]).
    pub fn preset_or_file_noted(name_or_path: &str) -> Result<(Scene, Vec<Note>), SceneError> {
        let path = Path::new(name_or_path);
        if PRESETS.contains(&name_or_path) {
            Scene::preset(name_or_path).map(|s| (s, Vec::new()))
        } else if !path.exists() {
            Err(SceneError {
                file: name_or_path.to_owned(),
                line: None,
                column: None,
                field: None,
                message: format!(
                    "no such preset or file; the presets are: {}",
                    PRESETS.join(", ")
                ),
            })
        } else if path.is_dir() {
            Err(SceneError {
                file: name_or_path.to_owned(),
                line: None,
                column: None,
                field: None,
                message: "is a directory, not a scene file (TOML)".to_owned(),
            })
        } else {
            Scene::load_noted(path)
        }
    }

    /// The scene as TOML.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }

    /// The object with this id.
    pub fn object(&self, id: &str) -> Option<&Object> {
        self.objects.iter().find(|o| o.id == id)
    }

    /// The calibration markers fixed on the table (table frame).
    pub fn fiducials(&self) -> Vec<Marker> {
        self.camera
            .fiducials_on(self.table.width, self.table.height)
    }

    /// The named pose with this name.
    pub fn position(&self, name: &str) -> Option<Pose> {
        self.positions
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.pose)
    }
}

/// Names of the built-in presets.
pub const PRESETS: &[&str] = crate::presets::NAMES;

/// The outline's vertices placed at `pose` (table frame).
pub fn placed(outline: &[[f64; 2]], pose: &Pose) -> Vec<[f64; 2]> {
    let (s, c) = pose.theta.sin_cos();
    outline
        .iter()
        .map(|v| [pose.x + c * v[0] - s * v[1], pose.y + s * v[0] + c * v[1]])
        .collect()
}

pub use crate::polygon::signed_area;

fn pose_finite(p: &Pose) -> bool {
    p.is_finite()
}

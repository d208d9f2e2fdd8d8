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
//! marker = { id = 3, x = 0.0, y = 0.0, size = 0.05 }   # AprilTag tag36h11, object frame
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

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::robot::Pose;

pub mod camera;
mod checks;
pub use camera::CameraSpec;
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
    pub front_plate: Option<crate::world::FrontPlate>,
}

impl Default for RobotSpec {
    fn default() -> Self {
        let g = pushbot_firmware::RobotParams::default().geometry;
        let m = crate::motor::MotorParams::default();
        RobotSpec {
            bumper_radius: f64::from(g.bumper_radius),
            wheel_base: f64::from(g.wheel_base),
            wheel_radius: f64::from(g.wheel_radius),
            encoder_cpr: g.encoder_cpr,
            no_load_speed: m.no_load_speed(),
            stall_torque: m.stall_torque(),
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

/// Why a scene could not be loaded: where (file, line, column), which field, and what.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// File name (or `preset NAME`).
    pub file: String,
    /// 1-based line, if known.
    pub line: Option<usize>,
    /// 1-based column, if known.
    pub column: Option<usize>,
    /// The field, e.g. `objects[1].mass`, if known.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.column {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": ")?;
        if let Some(field) = &self.field {
            write!(f, "{field}: ")?;
        }
        f.write_str(&self.message)
    }
}

impl std::error::Error for SceneError {}

/// One step of a field path.
#[derive(Clone, Debug, PartialEq)]
enum Seg {
    Key(&'static str),
    Index(usize),
}

fn path_string(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Line and column (1-based) of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// The key of the value that starts at byte `offset` (`mass` in `mass = "heavy"`, `x` in
/// `pose = { x = "a" }`), for parse errors whose span is a value.
fn key_before(text: &str, offset: usize) -> Option<String> {
    let before = text.get(..offset)?;
    let line = before.rsplit('\n').next()?;
    let lhs = line.trim_end().strip_suffix('=')?.trim_end();
    let key: String = lhs
        .chars()
        .rev()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    (!key.is_empty()).then_some(key)
}

/// The span of the value at `path` in the document, or of its nearest existing ancestor.
fn span_of(text: &str, path: &[Seg]) -> Option<std::ops::Range<usize>> {
    use toml::de::{DeTable, DeValue};
    let doc = DeTable::parse(text).ok()?;
    let mut best = None;
    let mut table: Option<&DeTable<'_>> = Some(doc.get_ref());
    let mut value: Option<&toml::Spanned<DeValue<'_>>> = None;
    for seg in path {
        let next = match (seg, table, value) {
            (Seg::Key(k), Some(t), _) => t.get(*k),
            (Seg::Index(i), _, Some(v)) => match v.get_ref() {
                DeValue::Array(a) => a.get(*i),
                _ => None,
            },
            _ => None,
        };
        let Some(v) = next else { break };
        best = Some(v.span());
        value = Some(v);
        table = match v.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => None,
        };
    }
    best
}

/// A check that failed after parsing: the field's path and the message.
struct Invalid {
    path: Vec<Seg>,
    message: String,
}

fn invalid(path: Vec<Seg>, message: impl Into<String>) -> Invalid {
    Invalid {
        path,
        message: message.into(),
    }
}

impl Scene {
    /// Parse and check a scene; `file` names the source in errors.
    pub fn from_toml(text: &str, file: &str) -> Result<Scene, SceneError> {
        let scene: Scene = toml::from_str(text).map_err(|e| {
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
        if let Err(bad) = scene.check() {
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
        Ok(scene)
    }

    /// Read a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
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
        Scene::from_toml(&text, &file)
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
        let path = Path::new(name_or_path);
        if PRESETS.contains(&name_or_path) {
            Scene::preset(name_or_path)
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
            Scene::load(path)
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

    fn check(&self) -> Result<(), Invalid> {
        use Seg::{Index, Key};
        let t = self.table;
        for (k, v) in [("width", t.width), ("height", t.height)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(
                    vec![Key("table"), Key(k)],
                    "must be a positive length",
                ));
            }
        }
        let r = &self.robot;
        for (k, v) in [
            ("bumper_radius", r.bumper_radius),
            ("wheel_base", r.wheel_base),
            ("wheel_radius", r.wheel_radius),
            ("no_load_speed", r.no_load_speed),
            ("stall_torque", r.stall_torque),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(vec![Key("robot"), Key(k)], "must be positive"));
            }
        }
        if r.encoder_cpr == 0 {
            return Err(invalid(
                vec![Key("robot"), Key("encoder_cpr")],
                "must be positive",
            ));
        }
        let s = r.start;
        let rr = r.bumper_radius;
        if !(pose_finite(&s)
            && s.x >= rr
            && s.x <= t.width - rr
            && s.y >= rr
            && s.y <= t.height - rr)
        {
            return Err(invalid(
                vec![Key("robot"), Key("start")],
                format!("the robot (radius {rr} m) must start on the table"),
            ));
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            check_polygon(&o.outline)
                .map_err(|m| invalid(vec![Key("obstacles"), Index(i), Key("outline")], m))?;
        }
        for (i, o) in self.objects.iter().enumerate() {
            let at = |k| vec![Key("objects"), Index(i), Key(k)];
            if o.id.is_empty() {
                return Err(invalid(at("id"), "must not be empty"));
            }
            if self.objects[..i].iter().any(|p| p.id == o.id) {
                return Err(invalid(at("id"), format!("duplicate object id {:?}", o.id)));
            }
            check_polygon(&o.outline).map_err(|m| invalid(at("outline"), m))?;
            if !pose_finite(&o.pose) {
                return Err(invalid(at("pose"), "must be finite"));
            }
            for v in placed(&o.outline, &o.pose) {
                if !(v[0] >= 0.0 && v[0] <= t.width && v[1] >= 0.0 && v[1] <= t.height) {
                    return Err(invalid(at("pose"), "the object must lie on the table"));
                }
            }
            if !(o.mass.is_finite() && o.mass > 0.0) {
                return Err(invalid(at("mass"), "must be positive"));
            }
            for (k, v) in [
                ("support_friction", o.support_friction),
                ("pusher_friction", o.pusher_friction),
            ] {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(invalid(at(k), "must be a friction coefficient ≥ 0"));
                }
            }
            if o.support_friction == 0.0 {
                return Err(invalid(
                    at("support_friction"),
                    "must be positive (a frictionless object never stops)",
                ));
            }
            if let Support::Points { points, weights } = &o.support {
                let sp = vec![Key("objects"), Index(i), Key("support")];
                if points.is_empty() {
                    return Err(invalid(sp, "needs at least one support point"));
                }
                if points.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(invalid(sp, "support points must be finite"));
                }
                if let Some(w) = weights {
                    if w.len() != points.len() {
                        return Err(invalid(sp, "needs one weight per support point"));
                    }
                    if w.iter().any(|x| !(x.is_finite() && *x >= 0.0))
                        || w.iter().sum::<f64>() <= 0.0
                    {
                        return Err(invalid(sp, "weights must be ≥ 0 and not all 0"));
                    }
                }
            }
            if let Some(m) = &o.marker
                && !(m.x.is_finite() && m.y.is_finite() && m.size.is_finite() && m.size > 0.0)
            {
                return Err(invalid(
                    at("marker"),
                    "needs a finite centre and a positive size",
                ));
            }
        }
        for (i, g) in self.goals.iter().enumerate() {
            let at = |k| vec![Key("goals"), Index(i), Key(k)];
            if self.object(&g.object).is_none() {
                return Err(invalid(
                    at("object"),
                    format!("no object {:?} in the scene", g.object),
                ));
            }
            if !(pose_finite(&g.pose)
                && g.pose.x >= 0.0
                && g.pose.x <= t.width
                && g.pose.y >= 0.0
                && g.pose.y <= t.height)
            {
                return Err(invalid(at("pose"), "must be on the table"));
            }
            if !(g.tolerance.is_finite() && g.tolerance > 0.0) {
                return Err(invalid(at("tolerance"), "must be positive"));
            }
            if let Some(a) = g.angle_tolerance
                && !(a.is_finite() && a > 0.0)
            {
                return Err(invalid(at("angle_tolerance"), "must be positive"));
            }
        }
        self.check_markers()?;
        for (i, p) in self.positions.iter().enumerate() {
            if !pose_finite(&p.pose) {
                return Err(invalid(
                    vec![Key("positions"), Index(i), Key("pose")],
                    "must be finite",
                ));
            }
        }
        self.check_geometry()
    }
}

impl Scene {
    /// Every marker is drawable, calibration markers lie on the table, and no tag id is used
    /// twice (the camera could not tell the bodies apart).
    fn check_markers(&self) -> Result<(), Invalid> {
        use Seg::{Index, Key};
        let c = &self.camera;
        if c.width < 64 || c.height < 64 || c.width > 8192 || c.height > 8192 {
            return Err(invalid(
                vec![Key("camera"), Key("width")],
                "the image must be 64..=8192 pixels on each side",
            ));
        }
        if !(c.fps.is_finite() && c.fps > 0.0 && c.fps <= 1000.0) {
            return Err(invalid(
                vec![Key("camera"), Key("fps")],
                "must be a frame rate in (0, 1000]",
            ));
        }
        let drawable =
            |m: &Marker| m.x.is_finite() && m.y.is_finite() && m.size.is_finite() && m.size > 0.0;
        let mut used: Vec<(u32, Vec<Seg>)> = Vec::new();
        let mut add = |id: u32, path: Vec<Seg>| -> Result<(), Invalid> {
            if id >= 587 {
                return Err(invalid(
                    path,
                    format!("tag id {id} is not in tag36h11 (0..=586)"),
                ));
            }
            if let Some((_, first)) = used.iter().find(|(u, _)| *u == id) {
                return Err(invalid(
                    path,
                    format!("tag id {id} is already used by {}", path_string(first)),
                ));
            }
            used.push((id, path));
            Ok(())
        };
        let rm = vec![Key("camera"), Key("robot_marker")];
        if !drawable(&c.robot_marker) {
            return Err(invalid(rm, "needs a finite centre and a positive size"));
        }
        add(c.robot_marker.id, rm)?;
        for (i, o) in self.objects.iter().enumerate() {
            if let Some(m) = &o.marker {
                add(m.id, vec![Key("objects"), Index(i), Key("marker")])?;
            }
        }
        for (i, g) in self.goals.iter().enumerate() {
            if let Some(m) = &g.marker {
                let at = vec![Key("goals"), Index(i), Key("marker")];
                if !drawable(m) {
                    return Err(invalid(at, "needs a finite centre and a positive size"));
                }
                add(m.id, at)?;
            }
        }
        let (w, h) = (self.table.width, self.table.height);
        for (i, m) in self.fiducials().iter().enumerate() {
            let at = vec![Key("camera"), Key("fiducials"), Index(i)];
            let half = m.size / 2.0;
            if !(drawable(m)
                && m.x - half >= 0.0
                && m.x + half <= w
                && m.y - half >= 0.0
                && m.y + half <= h)
            {
                return Err(invalid(at, "a calibration marker must lie on the table"));
            }
            add(m.id, at)?;
        }
        Ok(())
    }
}

/// Names of the built-in presets.
pub const PRESETS: &[&str] = crate::presets::NAMES;

fn pose_finite(p: &Pose) -> bool {
    p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()
}

/// The outline's vertices placed at `pose` (table frame).
pub fn placed(outline: &[[f64; 2]], pose: &Pose) -> Vec<[f64; 2]> {
    let (s, c) = pose.theta.sin_cos();
    outline
        .iter()
        .map(|v| [pose.x + c * v[0] - s * v[1], pose.y + s * v[0] + c * v[1]])
        .collect()
}

/// Signed area (shoelace), positive for counter-clockwise vertices.
pub fn signed_area(outline: &[[f64; 2]]) -> f64 {
    let n = outline.len();
    (0..n)
        .map(|i| {
            let (a, b) = (outline[i], outline[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// A usable polygon: ≥ 3 finite vertices, non-zero area, no zero-length edge, no edge
/// crossing another ([`crate::geometry::check_simple`]).
fn check_polygon(outline: &[[f64; 2]]) -> Result<(), String> {
    crate::geometry::check_simple(outline).map_err(|e| e.to_string())
}

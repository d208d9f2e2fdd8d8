//! The `[camera]` section of a scene: what the overhead camera sees besides the bodies' own
//! markers (Lau et al. §IV: markers on the robot, the object and the goal, seen by a ceiling
//! camera) — the robot's marker, the calibration markers fixed on the table, and the image.
//!
//! ```toml
//! [camera]                     # every field optional
//! width = 960                  # pixels
//! height = 720
//! fps = 30.0                   # frames per second of simulated time
//! robot_marker = { id = 0, x = 0.0, y = 0.0, size = 0.05 }   # robot frame
//! # calibration markers at known table positions (table frame); default: six 5 cm tags,
//! # ids 40–45, 6 cm in from the four corners and the middles of the long edges
//! fiducials = [{ id = 40, x = 0.06, y = 0.06, size = 0.05 }]
//! intrinsics = "camera.yaml"  # lens model (ROS camera_info or OpenCV YAML), relative to the scene file
//! # … or the lens itself, as OpenCV's camera matrix and distortion write it (pixel centres at
//! # integers): intrinsics = { fx = 700.0, fy = 700.0, cx = 479.5, cy = 359.5, k1 = -0.08 }
//! pose = { eye = [0.6, -0.3, 1.0], look_at = [0.6, 0.45, 0.0] }  # default: straight above
//! exposure = 0.033             # seconds the shutter is open: moving markers smear (default 0)
//! # things between the camera and the table (a hand), drawn over everything while shown
//! occluders = [{ outline = [[0.5, 0.3], [0.7, 0.3], [0.7, 0.5]], z = 0.3, from = 2.0, until = 4.0 }]
//! ```
//!
//! A camera with a `pose` but no `intrinsics` is an ideal pinhole with a focal length of 0.73 ×
//! the image width (a 68° horizontal field of view, a typical webcam's).

use serde::{Deserialize, Serialize};

use super::Marker;

/// First id of the default calibration markers.
pub const FIDUCIAL_BASE_ID: u32 = 40;

/// The camera's view of a scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraSpec {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Frames per second of simulated time.
    pub fps: f64,
    /// The marker on top of the robot, robot frame.
    pub robot_marker: Marker,
    /// Calibration markers fixed on the table, table frame; `None`: the default six.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fiducials: Option<Vec<Marker>>,
    /// The lens: a file with the lens model (ROS `camera_info` YAML or OpenCV YAML, path
    /// relative to the scene file; read into [`CameraSpec::lens`] when the scene is loaded from
    /// a file), or its values in the scene.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intrinsics: Option<IntrinsicsSpec>,
    /// The lens read from `intrinsics` ([`crate::lens_file`]), checked against `width` ×
    /// `height`; `None`: an ideal pinhole.
    #[serde(skip)]
    pub lens: Option<crate::lens::Intrinsics>,
    /// Where the camera is; `None`: straight above the table's centre, the table filling the
    /// image (the lens's focal length then sets its height).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pose: Option<crate::camera_pose::CameraPlacement>,
    /// Seconds the shutter is open for each frame: what moves in that time smears.
    pub exposure: f64,
    /// Things between the camera and the table, drawn over everything while shown.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub occluders: Vec<Occluder>,
}

/// Where the scene's lens comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum IntrinsicsSpec {
    /// A ROS `camera_info` or OpenCV `FileStorage` YAML file, relative to the scene file.
    File(String),
    /// The values, as OpenCV writes them.
    Inline(InlineIntrinsics),
}

/// A lens written in the scene, in OpenCV's terms: focal lengths and principal point in pixels
/// with pixel centres at integers (OpenCV's camera matrix), `plumb_bob` coefficients (0 when
/// left out). The image size is the camera's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InlineIntrinsics {
    /// Focal length along x, px.
    pub fx: f64,
    /// Focal length along y, px.
    pub fy: f64,
    /// Principal point x, px (OpenCV: pixel centres at integers).
    pub cx: f64,
    /// Principal point y, px.
    pub cy: f64,
    /// Radial r².
    #[serde(default)]
    pub k1: f64,
    /// Radial r⁴.
    #[serde(default)]
    pub k2: f64,
    /// Tangential.
    #[serde(default)]
    pub p1: f64,
    /// Tangential.
    #[serde(default)]
    pub p2: f64,
    /// Radial r⁶.
    #[serde(default)]
    pub k3: f64,
}

impl InlineIntrinsics {
    /// The lens for `width` × `height` frames (our pixel centres at `i + 0.5`).
    pub fn for_size(&self, width: u32, height: u32) -> crate::lens::Intrinsics {
        crate::lens::Intrinsics {
            width,
            height,
            fx: self.fx,
            fy: self.fy,
            cx: self.cx + 0.5,
            cy: self.cy + 0.5,
            distortion: crate::lens::Distortion {
                k1: self.k1,
                k2: self.k2,
                p1: self.p1,
                p2: self.p2,
                k3: self.k3,
            },
        }
    }
}

/// Something between the camera and the table (a hand, an arm): a dark polygon at a height,
/// shown from `from` until `until` seconds of simulated time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Occluder {
    /// Outline in table metres (x, y), on the plane `z`.
    pub outline: Vec<[f64; 2]>,
    /// Height above the table, metres.
    #[serde(default)]
    pub z: f64,
    /// First moment shown, seconds.
    #[serde(default)]
    pub from: f64,
    /// Last moment shown, seconds (default: for ever).
    #[serde(default = "forever")]
    pub until: f64,
}

fn forever() -> f64 {
    f64::INFINITY
}

impl Occluder {
    /// Whether the occluder is there at `time`.
    pub fn shown_at(&self, time: f64) -> bool {
        (self.from..=self.until).contains(&time)
    }
}

impl Default for CameraSpec {
    fn default() -> Self {
        CameraSpec {
            width: 960,
            height: 720,
            fps: 30.0,
            robot_marker: Marker {
                id: 0,
                x: 0.0,
                y: 0.0,
                size: 0.05,
                z: 0.0,
            },
            fiducials: None,
            intrinsics: None,
            lens: None,
            pose: None,
            exposure: 0.0,
            occluders: Vec::new(),
        }
    }
}

impl CameraSpec {
    /// The lens the camera draws through: the scene's intrinsics, or — for a camera placed by
    /// `pose` without them — an ideal pinhole with a focal length of 0.73 × the image width.
    pub fn optics(&self) -> Option<crate::lens::Intrinsics> {
        self.lens.or_else(|| {
            self.pose.map(|_| {
                crate::lens::Intrinsics::pinhole(
                    self.width,
                    self.height,
                    0.73 * f64::from(self.width),
                )
            })
        })
    }

    /// The calibration markers on a `width × height` m table: the ones given, or six 5 cm tags
    /// (ids 40–45) 6 cm in from the corners and the middles of the long edges.
    pub fn fiducials_on(&self, width: f64, height: f64) -> Vec<Marker> {
        if let Some(f) = &self.fiducials {
            return f.clone();
        }
        let d = 0.06;
        [
            (d, d),
            (width - d, d),
            (width - d, height - d),
            (d, height - d),
            (width / 2.0, d),
            (width / 2.0, height - d),
        ]
        .iter()
        .zip(FIDUCIAL_BASE_ID..)
        .map(|(&(x, y), id)| Marker {
            id,
            x,
            y,
            size: 0.05,
            z: 0.0,
        })
        .collect()
    }
}

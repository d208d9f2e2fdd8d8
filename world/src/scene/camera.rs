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
//! ```

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
    /// A file with the lens model (ROS `camera_info` YAML or OpenCV YAML), path relative to
    /// the scene file; read into [`CameraSpec::lens`] when the scene is loaded from a file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intrinsics: Option<String>,
    /// The lens read from `intrinsics` ([`crate::lens_file`]), checked against `width` ×
    /// `height`; `None`: an ideal pinhole.
    #[serde(skip)]
    pub lens: Option<crate::lens::Intrinsics>,
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
        }
    }
}

impl CameraSpec {
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

//! The shared model of pushbot's table, which the host and the simulated target both stand on:
//!
//! * [`Pose`] — the one planar pose (SE(2), on `nalgebra`);
//! * [`geometry`] — outlines as convex parts and their overlaps, on `parry2d`;
//! * [`enclosing_circle`] — the smallest circle enclosing a point set (Welzl);
//! * [`polygon`] — simple-polygon checks in O(n log n) and winding normalisation;
//! * [`simplify`] — fine outlines simplified within 0.1 mm (Douglas–Peucker, `geo`);
//! * [`board`] — the lens-calibration board: an AprilTag grid and its layout file;
//! * [`body`] — the robot's build (round bumper, front plate, switches);
//! * [`scene`] — the one scene format (TOML), its validation with file:line:col errors, and
//!   [`presets`];
//! * [`camera`] — the camera model and the markers it sees;
//! * [`lens`] — a real camera's intrinsics and `plumb_bob` distortion, [`camera_pose`] — its pose
//!   over the table (any tilt) and the homographies of planes at a height, and
//!   [`lens_file`] — the ROS and OpenCV intrinsics files, read and written;
//! * [`workspace`] — the table and the boundary of a delivery (Lau et al. §III-A).
//!
//! The table frame has its origin at the table's lower-left corner, x along the width, y along
//! the height, angles counter-clockwise from +x. This crate depends on neither the firmware nor
//! the simulator.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod board;
pub mod body;
pub mod camera;
pub mod camera_pose;
pub mod enclosing_circle;
pub mod geometry;
pub mod lens;
pub mod lens_file;
pub mod polygon;
pub mod pose;
pub mod presets;
pub mod scene;
pub mod simplify;
pub mod workspace;

pub use pose::{Pose, wrap_angle};
pub use scene::{Scene, SceneError};

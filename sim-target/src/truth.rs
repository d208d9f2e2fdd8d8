//! The simulated robot's true state ([`Truth`]) and the truth log's lines ([`TruthRecord`]):
//! what the simulation knows and the firmware and host do not. Below both the simulation
//! ([`crate::sim`]) and the live camera that renders it ([`crate::camera::live`]).

use pushbot_protocol::{Faults, Mode};
use serde::Serialize;

use crate::robot::Pose;

/// A snapshot of the simulated robot's true state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Simulated time, s.
    pub t: f64,
    /// True pose in the table frame.
    pub pose: Pose,
    /// Duties the firmware applied `[left, right]`.
    pub duty: [f32; 2],
    /// True wheel speeds `[left, right]`, rad/s.
    pub wheel_speed: [f64; 2],
    /// Bumper switches truly pressed (bits: 0 left, 1 centre, 2 right).
    pub bumper: u8,
    /// What the firmware says it is doing.
    pub mode: Mode,
    /// The firmware's latched faults.
    pub faults: Faults,
    /// The firmware's odometry pose (its own frame, starting at zero).
    pub odometry: pushbot_protocol::Pose,
}

/// One line of the truth log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthRecord {
    /// Simulated time, s.
    pub t: f64,
    /// True x, m (table frame).
    pub x: f64,
    /// True y, m.
    pub y: f64,
    /// True heading, rad.
    pub theta: f64,
    /// Duties `[left, right]`.
    pub duty: [f32; 2],
    /// Bumper switches truly pressed.
    pub bumper: u8,
    /// True object poses `[x, y, theta]` in scene order (absent without objects).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub objects: Vec<[f64; 3]>,
}

impl From<&Truth> for TruthRecord {
    fn from(t: &Truth) -> Self {
        TruthRecord {
            t: t.t,
            x: t.pose.x,
            y: t.pose.y,
            theta: t.pose.theta,
            duty: t.duty,
            bumper: t.bumper,
            objects: Vec::new(),
        }
    }
}

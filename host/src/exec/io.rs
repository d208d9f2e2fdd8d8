//! "The robot and what the camera sees": the primitives and observations every executor is
//! written against — Lau, Mitani & Igarashi's collection (§III-C/D, Algorithm 1) and delivery
//! (§III-E, Algorithm 2), the rearrangement and stable-pushing executors. Its in-process
//! implementation on the simulated robot is `crate::sim::robot::SimRobot`; the one on a robot
//! behind a serial port with a camera is [`crate::exec::live::LiveRobot`].
//!
//! The paper's robot only spins, drives forward and stops (§IV, "Software"); its host sees the
//! robot's and the object's marker poses from a ceiling camera. [`RobotIo`] is exactly that.

use anyhow::Result;
use pushbot_world::Pose;
pub use pushbot_world::workspace::{Rect, Workspace};

/// The robot and the camera, as the executors see them.
pub trait RobotIo {
    /// Spin in place by `angle`, rad (counter-clockwise positive); returns when stopped.
    fn spin(&mut self, angle: f64) -> Result<()>;
    /// Drive straight by `distance`, m (negative: backwards); returns when stopped.
    fn forward(&mut self, distance: f64) -> Result<()>;
    /// Drive at `v` m/s turning at `omega` rad/s for `duration` s (the dipole baseline).
    fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()>;
    /// The robot's pose in the table frame, as the camera sees it.
    fn robot_pose(&mut self) -> Pose;
    /// The object's marker pose in the table frame, as the camera sees it.
    fn object_pose(&mut self) -> Pose;
    /// The pose of the object named `id` in the scene (its body frame, not its marker), in the
    /// table frame, as the camera sees it; `None` when there is no such object or it is not seen.
    fn body_pose(&mut self, id: &str) -> Option<Pose>;
    /// Time since the start, s (simulated time in simulation).
    fn time(&self) -> f64;
    /// The workspace.
    fn workspace(&self) -> Workspace;
    /// The outline of the object being delivered, in its marker's frame, as the scene gives
    /// it; empty when it is not known (the special case then stands the robot where the
    /// regression says, as the paper does).
    fn object_outline(&self) -> Vec<[f64; 2]> {
        Vec::new()
    }
    /// The path the robot is working along (table metres), for views and recordings; a robot
    /// that shows nothing ignores it.
    fn show_path(&mut self, _path: &[[f64; 2]]) {}
}

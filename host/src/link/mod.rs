//! The host end of the serial link to the robot: transport, framing, handshake, heartbeats,
//! acknowledged and retried commands, `Done`s, telemetry, reconnect, and a typed robot API.
//!
//! ```no_run
//! use pushbot::link::{LinkOptions, Robot};
//! let robot = Robot::connect("/dev/ttyACM0", LinkOptions::default())?;
//! let done = robot.move_distance(0.3, 0.1, false)?;
//! println!("{:?} at {:?}", done.outcome, done.pose);
//! # Ok::<(), pushbot::link::LinkError>(())
//! ```

mod error;
mod robot;
mod session;
pub mod transport;

#[cfg(test)]
mod tests;

pub use error::{FAULT_NAMES, FaultNames, LinkError, Refusal};
pub use robot::{
    DoneReport, LinkOptions, Motion, Robot, RobotInfo, command_name, motion_budget_us,
};
pub use session::{LinkStats, RobotEvent};

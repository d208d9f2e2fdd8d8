//! Execution: the host's end of the closed loop (camera → tracking → decision → motion
//! primitive → link → firmware → motors). Each executor runs *look → estimate → plan or correct
//! → act* on a [`RobotIo`](crate::exec::io::RobotIo), with the maneuvers written once
//! in [`maneuver`]:
//!
//! - [`collect`]: Lau et al.'s Algorithm 1 (collecting the pushing strategy);
//! - [`deliver`]: Algorithm 2 (learned delivery) and the dipole-field baseline;
//! - [`deliver_path`]: delivery among obstacles along the global path's sub-goals, and
//!   [`last_leg`] its last stretch to the goal;
//! - [`rearrange`]: Ben-Shahar & Rivlin's plans driven with re-observation and snapping;
//! - [`stable`]: Lynch & Mason's stable pushes on the plated robot, with transits;
//! - [`stable_feedback`]: the same plans driven closed loop: steering inside the stable set,
//!   re-planning from the measured poses, re-acquiring a lost edge;
//! - [`primitive`]: one motion primitive as a task, resumed from the odometry through link
//!   breaks (`pushbot robot move`);
//! - [`live`]: the [`RobotIo`](crate::exec::io::RobotIo) over a real serial link
//!   and a real camera: the same code runs a robot on a table and the simulated target, which
//!   it cannot tell apart.

pub mod collect;
pub mod deliver;
pub mod deliver_path;
pub mod delivery_params;
pub mod drift;
pub mod grabber;
pub mod grid_snap;
pub mod io;
pub mod last_leg;
pub mod live;
pub mod maneuver;
pub mod occlusion;
pub mod odometry_feed;
pub mod plan_source;
pub mod primitive;
pub mod rearrange;
pub mod record;
pub mod reposition;
pub mod stable;
pub mod stable_feedback;
pub mod stable_replan;
pub mod stable_start;
pub mod stall;
#[cfg(test)]
mod test_tables;
pub mod view;

pub use live::{LiveOptions, LiveRobot};

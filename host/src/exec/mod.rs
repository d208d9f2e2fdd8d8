//! Execution on a robot seen by a camera: the host's end of the closed loop
//! (camera → tracking → decision → motion primitive → link → firmware → motors).
//!
//! [`live::LiveRobot`] is the [`RobotIo`](crate::strategy::robot_io::RobotIo) every planner and
//! the learned strategy drive, implemented over a real serial link ([`crate::link`]) and a real
//! camera ([`crate::vision`]): the same code runs a robot on a table and the simulated target
//! (`pushbot-sim`, or the built-in target `crate::sim::SimTarget`), which it cannot tell apart.

pub mod grabber;
pub mod live;
pub mod record;
pub mod view;

pub use live::{LiveOptions, LiveRobot};

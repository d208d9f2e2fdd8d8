//! The simulated pushbot target: the firmware's own core ([`pushbot_firmware::Core`]) running on
//! simulated motors, encoders and bumper switches, in a world of walls, at simulated time.
//!
//! * In process: [`Sim`] — tick it, hand it the host's bytes, take the robot's bytes.
//! * Over a real serial path: [`PtySim`] — runs a [`Sim`] on a background thread, paced against
//!   the wall clock, and serves the robot's serial port on a pseudo-terminal that a host opens
//!   exactly like a real robot's port. The `pushbot-sim` binary is a thin CLI around it.
//!
//! The table frame has its origin at the table's lower-left corner, x along the width, y along
//! the height, angles counter-clockwise from +x (see [`robot`]).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use pushbot_world::{geometry, presets, scene};

pub mod encoder;
pub mod fault_pipe;
pub mod faults;
pub mod motor;
pub mod perturb;
pub mod plug;
pub mod pty;
pub mod pushing;
pub mod quasistatic;
pub mod robot;
pub mod sim;
pub mod terminal;
pub mod truth;
pub mod world;

pub use pty::{Pty, PtySim};
pub use robot::Pose;
pub use scene::{Scene, SceneError};
pub use sim::{Sim, SimOptions, Truth, TruthRecord};
pub use world::{Body, Hardware, World};

pub mod camera;

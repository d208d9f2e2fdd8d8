//! The host end of the serial link to the robot: the sans-IO link client (framing, handshake,
//! sequence numbers, retries, replies, heartbeats, timeouts) and its serial driver (transport,
//! a reader thread). The typed robot API over it is [`crate::robot`].
//!
//! ```no_run
//! use pushbot::link::{Client, ClientOptions, HostTime};
//! use pushbot_protocol::Command;
//! let mut client = Client::new(HostTime::default(), ClientOptions::default());
//! let seq = client.command(HostTime::default(), Command::Stop);
//! while let Some(bytes) = client.poll_transmit(HostTime::default()) {
//!     // write `bytes` to the robot, hand its bytes to `client.handle_bytes`
//! #   let _ = (bytes, seq);
//! }
//! ```

pub mod client;
pub mod driver;
mod error;
pub mod serial;
pub mod transport;

#[cfg(test)]
mod client_tests;
#[cfg(test)]
mod heard_tests;

pub use client::{
    Answer, Client, ClientOptions, Event, Handshake, Heard, HostTime, LinkStats, MotionEnd,
    RobotEvent,
};
pub use driver::Driver;
pub use error::{FAULT_NAMES, FaultNames, LinkError, Refusal};
pub use serial::SerialDriver;

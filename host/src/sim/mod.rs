//! The built-in simulated target (the default cargo feature `sim`): the only part of the host
//! that knows `pushbot-sim`. Everything else talks to a robot through a serial port or a
//! [`crate::link`] driver and sees the table through a camera source, and cannot tell the
//! simulated target from a real one.

pub mod synth;
pub mod target;

pub use target::SimTarget;

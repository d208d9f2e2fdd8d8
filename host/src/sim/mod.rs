//! The built-in simulated target (the default cargo feature `sim`): the only part of the host
//! that knows `pushbot-sim` — the target served on a pty with its camera ([`target`]), the
//! in-process driver of the link client ([`inprocess`]), the in-process robot of the strategy
//! code with its truth-with-noise "camera" or its rendered camera read by the host's vision
//! pipeline ([`robot`], [`camera`]), and rendered camera frames for vision
//! tests and benches ([`synth`]). Everything else talks to a robot through a serial port or a
//! [`crate::link`] driver and sees the table through a camera source, and cannot tell the
//! simulated target from a real one.

pub mod camera;
pub mod inprocess;
pub mod robot;
pub mod synth;
pub mod target;

pub use target::SimTarget;

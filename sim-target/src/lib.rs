//! The simulated pushbot target.
#![forbid(unsafe_code)]

pub mod camera;

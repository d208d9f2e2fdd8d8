//! The simulated pushbot target.
#![forbid(unsafe_code)]

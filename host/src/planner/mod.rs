//! Planners.

pub mod stable;

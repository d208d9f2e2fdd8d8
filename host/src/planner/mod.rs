//! Planners: how the robot moves objects by pushing.

pub mod rearrange;
pub mod stable;

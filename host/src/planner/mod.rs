//! Planners: how the robot moves objects by pushing. Pure functions of a world snapshot and a
//! goal: no I/O, no robot, no clock; [`crate::exec`] drives their plans.
//!
//! - [`rearrange`]: several movables on a grid, optimally (Ben-Shahar & Rivlin).
//! - [`stable`]: stable pushes among obstacles (Lynch & Mason §4).
//! - [`global`]: the object's path among obstacles for delivery (Lau et al. §III-E).
//! - [`detour`]: that path with its detours cut.
//! - [`path_follow`]: following that path with a sub-goal that moves with the object.

pub mod detour;
pub mod global;
pub mod path_follow;
pub mod rearrange;
pub mod stable;

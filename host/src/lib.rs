//! pushbot host: the PC side of the pushing robot.
//!
//! Data flows one way: camera → `vision` → planners (`planner`, `strategy`) → motion
//! primitives → `link` → firmware → motors. See `DESIGN.md` of the project.
#![forbid(unsafe_code)]

pub mod cli;
pub mod console;
pub mod exec;
pub mod experiments;
pub mod link;
pub mod mechanics;
pub mod planner;
pub mod plot;
pub mod recording;
pub mod report;
pub mod robot;
#[cfg(feature = "sim")]
pub mod sim;
pub mod strategy;
pub mod task;
pub mod vision;

//! The pushing problem of Ben-Shahar & Rivlin §II-A on a grid, and its composite configuration
//! space CSS packed into integer indices.
//!
//! A [`Problem`] is what a scene describes: the table grid (static obstacles 𝓘, rough cells,
//! cells where no movable may be left), the robot 𝓡 (a k × k block of cells), the movables
//! 𝓜₁…𝓜ᵣ (any cell shape, a mass, 2-DOF or 3-DOF with 90° turns, and their pushing contact
//! modes, Fig. 15 and 18), the admissibility rules (§IV-B), the metric (§IV-C), a start and a goal.
//!
//! [`Model`] compiles a problem into dense tables: every body's statically valid placements get
//! a local index, and a composite configuration Q = (q_𝓡, q_𝓜₁, …, q_𝓜ᵣ) is packed in mixed
//! radix (robot memory, robot, movable 1, …) into one integer ([`PackedIndex`]: a `u32` while the
//! space has fewer than 2³² configurations, a `u64` past it). Placements that overlap an obstacle
//! never get an index, so the packed space is the product of the bodies' free placements;
//! overlaps between bodies (the C-obstacle CCO) are found with precomputed pairwise bit tables.
//!
//! The parts: `spec` (the description), `tables` (domains and bit tables), `model` (compiling
//! a problem), `packed` (packing and unpacking configurations); the grid itself is in
//! [`super::grid`].

mod model;
mod packed;
mod spec;
mod tables;

pub use super::grid::{Cell, Dir, Grid, rot};
pub use model::Model;
pub use spec::{
    Config, ContactMode, GoalPlacement, MovableSpec, Placement, Problem, ProblemError, RobotSpec,
    Rules, face_modes,
};
pub use tables::{
    Bits, ContactTable, Domain, FastDiv, MAX_MOVABLES, NONE, PackedIndex, RotInstance, State,
};

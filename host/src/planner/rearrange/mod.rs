//! Rearrangement planning of several movables by pushing: Ben-Shahar & Rivlin, "To Push or Not
//! to Push" (§II problem, §IV algorithm, §V test cases).
//!
//! - [`grid`]: the table grid and the four directions, below the problem and the metric;
//! - [`problem`]: the pushing problem of §II-A on a grid, composite configurations packed into
//!   integer indices;
//! - [`admissibility`]: admissible neighbours and origins, §IV-B, computed on the fly;
//! - [`metric`]: the cost metrics of §IV-C (mass, safety, passability, contact-mode changes, turns);
//! - [`costmap`]: the cost mapping phase, §IV-A1 (backward propagation from a goal set), on
//!   every core; its wave front in `wavefront`;
//! - [`budget`]: the memory the exact map needs, known before it is built (§IV-E);
//! - [`practical`]: the practical mode for many movables, an object-level search over exact
//!   single-object legs;
//! - [`restore`](mod@restore): the pushing C-path restoration phase, §IV-A2;
//! - [`cases`]: the test cases A–D of §V-A (scene presets) and reading scenes;
//! - [`scene`]: the shared scene format (`[rearrange]` section) rasterised to a grid problem;
//! - [`svg`]: plans drawn as the paper's step-by-step figures;
//! - [`frame`]: where the grid lies on the table, shared by [`scene`] and [`to_scene`];
//! - [`to_scene`]: a grid problem as a table scene (§V-B); `crate::exec::rearrange` carries
//!   plans out on the robot, closed on the camera.
//!
//! Limits (§IV-E): the map holds one `u16` per packed configuration, so memory grows as
//! (free cells)^(1 + r) — 128 MB for the robot and 2 boxes in a 20 × 20 room, 860 MB for 3 boxes in
//! 12 × 12, and a 4th box or a 3-DOF movable multiplies it again by the cells (and by 4); the
//! wave front adds at most one bit per configuration per bucket (`max_edge + 1` buckets), in
//! 4 KiB pages taken when first written and given back when their bucket is swept (16 MB at
//! its peak for the 2-box room). Time is bounded by cache misses on the cost array: the wave front is scattered,
//! so each bucket is swept in index order (a bit set) and the map is visited in one forward pass
//! per cost, the configurations of one cost split among the cores. Plan costs must stay below
//! 65 535. Packed indices are `u32` below 2³² configurations and `u64` from there on, so any map
//! that fits in memory can be built; [`budget`] sizes a map before it is built and refuses one
//! that would not fit, and the [`practical`] mode takes what the exact map cannot.

pub mod admissibility;
pub mod budget;
pub mod cases;
pub mod costmap;
mod wavefront;

pub mod frame;
pub mod grid;
pub mod metric;
pub mod practical;
pub mod problem;
pub mod restore;
pub mod scene;
pub mod svg;
pub mod to_scene;

pub use admissibility::{MoveKind, Step};
pub use costmap::{
    CostMap, INF, MapError, MapStats, cost_map, cost_map_from, cost_map_with, map_bytes_estimate,
};
pub use metric::Metric;
pub use problem::{
    Config, ContactMode, Dir, Grid, Model, MovableSpec, Placement, Problem, RobotSpec, Rules,
};
pub use restore::{Plan, RestoreError, restore};

/// Map the problem's goal set and restore the plan from its start: (model, map, plan or why not).
pub fn solve(
    problem: &Problem,
) -> Result<(Model, CostMap, Result<Plan, RestoreError>), SolveError> {
    let model = Model::new(problem)?;
    let map = cost_map(&model)?;
    let start = model.pack(&problem.start).ok_or(SolveError::StartNotFree)?;
    let plan = restore(&model, &map, start);
    Ok((model, map, plan))
}

/// Why a problem could not be mapped.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SolveError {
    /// The description is wrong.
    #[error(transparent)]
    Problem(#[from] problem::ProblemError),
    /// The map overflowed.
    #[error(transparent)]
    Map(#[from] MapError),
    /// The start overlaps something.
    #[error("the start configuration is not free")]
    StartNotFree,
}

/// Cost of following a sequence of configurations under a model's admissibility and metric:
/// `None` if some step is not an admissible move there. Used to compare plans across presets.
pub fn replay_cost(model: &Model, start: &Config, configs: &[Config]) -> Option<u32> {
    let mut cur = model.pack(start)?;
    let mut total = 0;
    let mut nb = Vec::new();
    for c in configs {
        model.neighbours(cur, &mut nb);
        let best = nb
            .iter()
            .filter(|s| {
                let u = model.unpack(s.to);
                u.robot == c.robot && u.movables == c.movables
            })
            .min_by_key(|s| s.cost)?;
        total += best.cost;
        cur = best.to;
    }
    Some(total)
}

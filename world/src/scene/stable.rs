//! The optional `[stable]` section of a scene: a stable-pushing task for the host's planner
//! after Lynch & Mason (1996) §4 — which object, its pushing edges, the pusher, the costs and
//! the grid. Data only: the sim ignores it; the host's `planner::stable::presets` reads it.
//!
//! ```toml
//! [stable]
//! object = "slider"            # the pushed object; its goal is the scene's goal for it
//! edges = [0]                  # pushing contacts: edges of the object's outline
//! goal_xy_frac = 0.25          # goal half-width in x, y as a fraction of the object length
//! goal_theta_deg = 2.0
//! pusher = { kind = "diff-drive" }            # arm | omni | car | diff-drive, sizes optional
//! planner = { a = 1, b = 5, c = "inf" }       # costs, step and grid (all optional)
//! ```

use serde::{Deserialize, Serialize};

/// A stable-pushing task.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stable {
    /// Id of the object to push.
    pub object: String,
    /// Edges of the object's outline that may be pushed.
    pub edges: Vec<usize>,
    /// Edge the pusher starts at (default: any, chosen for free).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_edge: Option<usize>,
    /// Goal half-width in x and y as a fraction of the object length.
    pub goal_xy_frac: f64,
    /// Goal half-width in θ, degrees.
    pub goal_theta_deg: f64,
    /// Who pushes.
    pub pusher: StablePusher,
    /// Planner settings.
    #[serde(default)]
    pub planner: StablePlanner,
}

/// The pusher of a stable-pushing task.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StablePusher {
    /// `arm`, `omni`, `car` or `diff-drive`.
    pub kind: String,
    /// Robot width, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    /// Robot depth behind its front, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth: Option<f64>,
    /// Front plate to wheel axle, m (default for `diff-drive`: the robot's front plate offset).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axle_offset: Option<f64>,
    /// Width of the flat front plate, m (default for `diff-drive`: the robot's front plate).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plate_width: Option<f64>,
    /// Car: minimum turning radius, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_turning_radius: Option<f64>,
}

/// A contact-change cost: an integer or `"inf"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum StableCost {
    /// Finite.
    Int(u32),
    /// `"inf"`: contact changes disallowed.
    Word(String),
}

/// Planner settings (all optional; the host's defaults otherwise).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StablePlanner {
    /// Cost per push step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a: Option<u32>,
    /// Cost per control change.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b: Option<u32>,
    /// Cost per contact change.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c: Option<StableCost>,
    /// Step length as a fraction of the object length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_frac: Option<f64>,
    /// Grid cell in x, y as a fraction of the step.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_xy_frac: Option<f64>,
    /// Grid cell in θ, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid_theta_deg: Option<f64>,
    /// MAXCOST.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_cost: Option<u32>,
    /// Node limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_nodes: Option<usize>,
    /// Radius (fraction of the object length) of the refined region around the goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fine_radius_frac: Option<f64>,
    /// Refinement factor near the goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fine_factor: Option<f64>,
}

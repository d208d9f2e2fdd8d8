//! The parameters of a delivery (Lau, Mitani & Igarashi §III-E, §IV–V): the paper's success
//! radius and time limit, its two-level motion, and the project's rules for the boundary, the
//! special case and stalls among obstacles. Used by [`crate::exec::deliver`] and the pieces it
//! is made of ([`crate::exec::drift`], [`crate::exec::stall`]).

use crate::strategy::dipole::DipoleParams;
#[cfg(doc)]
use crate::strategy::regression::PushStrategy;

/// Parameters of delivery.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeliveryParams {
    /// Success: the object's marker within this distance of the goal, m (the paper: 2.2 cm).
    pub success_radius: f64,
    /// Failure when not delivered within this time, s (the paper: 8 minutes).
    pub time_limit: f64,
    /// Coarse push length, m.
    pub coarse_step: f64,
    /// Fine push length, m.
    pub fine_step: f64,
    /// Object–goal distance below which pushes are fine, m.
    pub fine_radius: f64,
    /// Heading error left after a coarse spin that a fine spin corrects, rad.
    pub heading_tolerance: f64,
    /// The object moved if its marker moved at least this far, m.
    pub moved_epsilon: f64,
    /// Extra space of the bound-all circle beyond the robot's and the object's radii, m.
    pub bound_all_margin: f64,
    /// Width of the band inside the boundary where the wanted object motion is pulled inward,
    /// m (0: off, as in the paper).
    pub boundary_guard: f64,
    /// Strength of that pull at the boundary, relative to the unit goal direction.
    pub boundary_pull: f64,
    /// The special case (re-positioning) follows a push whose object motion missed the wanted
    /// motion by more than this, rad. The paper's is a quarter turn (the object moved away
    /// from the goal). Among obstacles it is tighter
    /// ([`crate::planner::global::ObstacleParams::reposition_angle`]): a push that drifts is
    /// not continued, so the object keeps to its path.
    pub reposition_angle: f64,
    /// Among obstacles: a push that leaves the object's enclosing circle within this of an
    /// obstacle, and nearer to it, is followed by the special case once it missed the wanted
    /// motion by [`Self::wall_reposition_angle`] ([`crate::exec::drift`]), m; 0: off (the paper).
    pub wall_near: f64,
    /// The re-position angle for a push towards a near wall, rad.
    pub wall_reposition_angle: f64,
    /// Stall: the object came no closer to the goal by [`Self::stall_progress`] (or half the
    /// way still left to the success radius, if less) for this long, s; 0 turns it off (as in
    /// the paper, and for deliveries on a clear table). Deliveries among obstacles set it
    /// ([`crate::planner::global::ObstacleParams::stall_time`]) and recover.
    pub stall_time: f64,
    /// Progress towards the goal that counts against a stall, m.
    pub stall_progress: f64,
    /// Along a path, on its last leg (the marker pushed to the goal): the general case pushes
    /// only when a sample lies within this of its query in (p, s)
    /// ([`PushStrategy::general_distance`]), m; farther, the special case stands the robot where
    /// the samples show that push. 0: off (the paper, and a clear table). Set by deliveries
    /// among obstacles ([`crate::planner::global::ObstacleParams::last_leg_trust`]).
    pub last_leg_trust: f64,
    /// Along a path, on its last leg: where the robot cannot stand between the object at the
    /// goal and the nearest obstacle (the goal nearer to it than the object's enclosing circle,
    /// the robot's width and [`Self::bound_all_margin`]), the marker is aimed this far from the
    /// goal away from the obstacle, m (at most [`Self::success_radius`]; success is still
    /// measured at the goal). A push that ends short towards the wall then still delivers, and
    /// one that ends short away from it leaves the robot room to correct it; aimed at the goal,
    /// the object stalled beside it against the wall. 0: off (the paper, and a clear table).
    /// Set by deliveries among obstacles
    /// ([`crate::planner::global::ObstacleParams::goal_wall_offset`]).
    pub goal_wall_offset: f64,
    /// Along a path, on its last leg: the special case's turn weight
    /// ([`crate::strategy::regression::KernelParams::turn_weight`]), m a radian; 0 keeps the
    /// strategy's. Near the goal a stand point whose push turned the L-shape about its marker
    /// swung its body back and forth beside the goal. Set by deliveries among obstacles
    /// ([`crate::planner::global::ObstacleParams::last_leg_turn_weight`]).
    pub last_leg_turn_weight: f64,
    /// Dipole baseline: length of one drive step, s.
    pub dipole_step: f64,
    /// Dipole baseline: controller parameters.
    pub dipole: DipoleParams,
}

impl Default for DeliveryParams {
    fn default() -> Self {
        DeliveryParams {
            success_radius: 0.022,
            time_limit: 480.0,
            coarse_step: 0.04,
            fine_step: 0.015,
            fine_radius: 0.1,
            heading_tolerance: 0.05,
            moved_epsilon: 0.003,
            bound_all_margin: 0.02,
            boundary_guard: 0.06,
            boundary_pull: 1.0,
            reposition_angle: std::f64::consts::FRAC_PI_2,
            wall_near: 0.0,
            wall_reposition_angle: std::f64::consts::FRAC_PI_2,
            stall_time: 0.0,
            stall_progress: 0.02,
            last_leg_trust: 0.0,
            goal_wall_offset: 0.0,
            last_leg_turn_weight: 0.0,
            dipole_step: 0.25,
            dipole: DipoleParams::default(),
        }
    }
}

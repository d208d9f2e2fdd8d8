//! The best-first push planner of Lynch & Mason (1996) §4.1–4.2 (after Barraquand & Latombe
//! 1993): OPEN is a 1-D array of FIFO lists indexed by integer cost (§4.2.2), a configuration is
//! expanded only if its grid cell has not been occupied with the same contact (§4.2.3), and the
//! search stops at the goal neighbourhood, at MAXCOST or at the node limit (§4.2.4).
//!
//! Costs: each push step costs `a`; a step whose control (contact and direction) differs from
//! the previous step's costs `b` more; a step on a different contact than the previous step
//! costs `c` more (a contact change is also a control change). For a mobile pusher a
//! contact-changing step is accepted only if a transit path exists (§4.6); that path is found
//! lazily, when the node is taken from OPEN, and kept in the plan. The exact-goal variant of
//! §4.5 backs up along the found path to a configuration from which one stable push reaches the
//! goal exactly.
//!
//! The parts: `steps` (push steps, plans and their cost), `bound` (the A* lower bound), `grid`
//! (the pruning grid), `open` (OPEN), `best_first` (the search loop), `crossing` (the goal test
//! along a step), `finish` (the exact-goal finish) and `brute_force` (an unpruned search for
//! tests).

mod best_first;
mod bound;
mod brute_force;
mod crossing;
mod finish;
mod grid;
mod open;
mod steps;

pub use best_first::{Checks, plan, plan_checked, plan_with};
pub use bound::Heuristic;
pub use brute_force::brute_force_cost;
pub use crossing::{goal_crossing, goal_finish};
pub use finish::exact_goal;
pub(super) use finish::{backed_up, push_steps};
pub use open::Queue;
pub use steps::{
    Plan, SearchEnd, SearchTrace, Step, TREE_EDGES, goal_measure, step_cost, step_twist_of,
    summarise,
};

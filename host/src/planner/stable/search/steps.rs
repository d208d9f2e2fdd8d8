//! A plan of the stable push planner (Lynch & Mason 1996 §4.2.2): its push steps, the transit
//! paths of a mobile pusher, the search statistics, and the integer cost
//! `a·pushes + b·control changes + c·contact changes` the search minimises.

use crate::mechanics::V3;
use crate::planner::stable::transit::TransitPath;
use crate::planner::stable::{Pose, Problem};

/// One push step of a plan.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Step {
    /// Index into the problem's contacts.
    pub contact: usize,
    /// Slider edge of that contact, numbered as the scene gives it ([`ContactModel::label`]).
    ///
    /// [`ContactModel::label`]: crate::planner::stable::ContactModel::label
    pub edge: usize,
    /// Control index within the contact's controls (`usize::MAX` for an exact-goal push).
    pub control: usize,
    /// Configuration before the step.
    pub from: Pose,
    /// Configuration after the step.
    pub to: Pose,
    /// Slider-frame twist integrated over the step.
    pub twist: [f64; 3],
}

/// A plan and the search statistics.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Plan {
    /// Whether a path to the goal neighbourhood was found.
    pub found: bool,
    /// Total cost `a·pushes + b·control changes + c·contact changes`.
    pub cost: u32,
    /// Number of push steps.
    pub pushes: usize,
    /// Number of control changes.
    pub control_changes: usize,
    /// Number of contact changes.
    pub contact_changes: usize,
    /// Configurations expanded.
    pub nodes_expanded: usize,
    /// Planning time (ms).
    pub plan_time_ms: f64,
    /// The push steps.
    pub steps: Vec<Step>,
    /// Transit paths of the pusher, one per contact change.
    pub transits: Vec<TransitPath>,
    /// Whether the plan ends exactly at the goal (§4.5 variant).
    pub exact_goal: bool,
    /// How the search ended and what it saw (for saying why there is no plan).
    #[serde(skip)]
    pub search: SearchTrace,
}

/// How a search ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SearchEnd {
    /// It reached the goal neighbourhood.
    Goal,
    /// It expanded `max_nodes` configurations.
    NodeLimit,
    /// OPEN ran empty: every configuration the grid and the costs let it reach was expanded.
    #[default]
    Exhausted,
    /// It did not start: the goal is cut off from the start ([`crate::planner::stable::reach`]).
    Unreachable,
}

/// Most edges of the explored tree a failed search keeps (for drawing it).
pub const TREE_EDGES: usize = 20_000;

/// What a search saw: how it ended, what it dropped and why, how close it came.
#[derive(Debug, Clone, Default)]
pub struct SearchTrace {
    /// How it ended.
    pub ended: SearchEnd,
    /// Steps dropped because their cost (with the bound) passed `max_cost`.
    pub cut_by_cost: u64,
    /// Steps dropped because they collide.
    pub collided: u64,
    /// Contact changes dropped because the pusher found no transit path to the new contact.
    pub no_transit: u64,
    /// The expanded configuration nearest the goal (by the larger of its distance and angle
    /// over the goal neighbourhood's), and that measure (1 is the neighbourhood's edge).
    pub closest: Option<(Pose, f64)>,
    /// Edges `(parent, child)` of the explored tree, at most [`TREE_EDGES`], when no plan was
    /// found.
    pub tree: Vec<[Pose; 2]>,
}

/// How far `q` is from the goal neighbourhood of `p`: the largest of its offsets in x and y
/// over the neighbourhood's half-width and its angle over the neighbourhood's half-angle (at
/// most 1 inside the neighbourhood, as [`Problem::in_goal`] decides).
pub fn goal_measure(p: &Problem, q: &Pose) -> f64 {
    let d = (q.x - p.goal.x).abs().max((q.y - p.goal.y).abs()) / p.params.goal_xy.max(1e-12);
    let a = crate::planner::stable::angle_diff(q.theta, p.goal.theta).abs()
        / p.params.goal_theta.max(1e-12);
    d.max(a)
}

/// Cost of a step given the previous step's (contact, control).
pub fn step_cost(
    p: &Problem,
    prev: Option<(usize, usize)>,
    contact: usize,
    control: usize,
) -> Option<u32> {
    let mut c = p.params.a;
    // Saturating: costs come from the command line.
    if let Some((pc, pk)) = prev {
        // `pk == usize::MAX`: the pusher waits at its start contact, no control yet; leaving
        // that contact is still a contact (and so a control) change.
        if (pc, pk) != (contact, control) && (pk != usize::MAX || pc != contact) {
            c = c.saturating_add(p.params.b);
        }
        if pc != contact {
            c = c.saturating_add(p.params.c?);
        }
    }
    Some(c)
}

/// Fill in the counts (and recompute the cost) from the steps.
pub fn summarise(p: &Problem, plan: &mut Plan) {
    plan.pushes = plan.steps.len();
    plan.control_changes = 0;
    plan.contact_changes = 0;
    let mut cost = 0u32;
    let mut prev: Option<(usize, usize)> = p.start_contact.map(|c| (c, usize::MAX));
    for s in &plan.steps {
        if let Some((pc, pk)) = prev {
            if (pc, pk) != (s.contact, s.control) && (pk != usize::MAX || pc != s.contact) {
                plan.control_changes += 1;
            }
            if pc != s.contact {
                plan.contact_changes += 1;
            }
        }
        cost = cost.saturating_add(step_cost(p, prev, s.contact, s.control).unwrap_or(0));
        prev = Some((s.contact, s.control));
    }
    plan.cost = cost;
}

/// The slider-frame twist of a step as a vector.
pub fn step_twist_of(s: &Step) -> V3 {
    V3::new(s.twist[0], s.twist[1], s.twist[2])
}

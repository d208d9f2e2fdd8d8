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

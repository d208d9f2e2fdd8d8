//! The exact-goal variant of Lynch & Mason (1996) §4.5: back up along a found plan to a
//! configuration from which one stable push reaches the goal exactly; and the back-up and
//! step splitter shared with the Dubins finish of a wheeled pusher.

use super::steps::{Plan, Step, summarise};
use crate::mechanics::V3;
use crate::planner::stable::transit::transit;
use crate::planner::stable::{Pose, Problem, step_twist};

/// The exact-goal variant of §4.5: back up along `plan` until a configuration from which a
/// single usable push of one contact moves `PS` collision-free exactly onto the goal; the
/// final push is counted as `ceil(length / step)` steps of one control. Only pushers whose
/// usable set has interior on the velocity sphere (arm, omnidirectional) can do this.
pub fn exact_goal(p: &Problem, plan: &Plan) -> Option<Plan> {
    if !plan.found {
        return None;
    }
    for back in (0..=plan.steps.len()).rev() {
        let q = if back == 0 {
            p.start
        } else {
            plan.steps[back - 1].to
        };
        let last_contact = if back == 0 {
            p.start_contact
        } else {
            Some(plan.steps[back - 1].contact)
        };
        let xi = q.twist_to(&p.goal);
        if xi.norm() < 1e-12 {
            continue;
        }
        // Prefer the contact already in use (no transit).
        let mut order: Vec<usize> = (0..p.contacts.len()).collect();
        if let Some(lc) = last_contact {
            order.sort_by_key(|&c| c != lc);
        }
        for ci in order {
            let cm = &p.contacts[ci];
            if !cm.usable.set.contains(&xi) || !cm.body.step_free(&p.world, &q, &xi) {
                continue;
            }
            let change = last_contact.is_some_and(|lc| lc != ci);
            if change && p.params.c.is_none() {
                continue;
            }
            let mut out = backed_up(plan, back);
            if change && p.pusher.is_mobile() {
                match transit(p, &q, last_contact.unwrap_or(ci), ci, 0) {
                    Some(t) => out.transits.push(t),
                    None => continue,
                }
            }
            out.steps
                .extend(push_steps(p, ci, &q, &[(xi, usize::MAX)], &p.goal));
            summarise(p, &mut out);
            out.exact_goal = true;
            return Some(out);
        }
    }
    None
}

/// `plan` backed up to its first `back` steps, with the transit paths of the contact changes
/// among them: where the exact-goal finishes of §4.5 continue from.
pub(in crate::planner::stable) fn backed_up(plan: &Plan, back: usize) -> Plan {
    let mut out = plan.clone();
    out.steps.truncate(back);
    let changes = out
        .steps
        .windows(2)
        .filter(|w| w[0].contact != w[1].contact)
        .count();
    out.transits.truncate(changes);
    out
}

/// The steps of the constant pushes `pushes` (whole slider-frame twists, each with its control
/// index) with contact `ci` from `q`, each push cut into steps of the problem's step length (so
/// the cost counts them as the search counts steps); the last step ends on `goal` exactly.
pub(in crate::planner::stable) fn push_steps(
    p: &Problem,
    ci: usize,
    q: &Pose,
    pushes: &[(V3, usize)],
    goal: &Pose,
) -> Vec<Step> {
    pushes_in_steps(p, ci, q, pushes, goal, 0)
}

/// As [`push_steps`], the last push cut into at least `min_last` steps.
pub(in crate::planner::stable) fn pushes_in_steps(
    p: &Problem,
    ci: usize,
    q: &Pose,
    pushes: &[(V3, usize)],
    goal: &Pose,
    min_last: usize,
) -> Vec<Step> {
    let edge = p.contacts[ci].label;
    let mut out = Vec::new();
    let mut at = *q;
    for (j, &(xi, control)) in pushes.iter().enumerate() {
        let unit = step_twist(&p.slider, &xi, p.params.step);
        let mut n = (xi.norm() / unit.norm()).ceil().max(1.0) as usize;
        if j + 1 == pushes.len() {
            n = n.max(min_last);
        }
        let tw = xi / n as f64;
        for k in 0..n {
            let from = at.integrate(&(xi * (k as f64 / n as f64)));
            let to = if j + 1 == pushes.len() && k + 1 == n {
                *goal
            } else {
                at.integrate(&(xi * ((k + 1) as f64 / n as f64)))
            };
            out.push(Step {
                contact: ci,
                edge,
                control,
                from,
                to,
                twist: [tw.x, tw.y, tw.z],
            });
        }
        at = at.integrate(&xi);
    }
    out
}

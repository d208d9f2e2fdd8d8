//! A brute-force uniform-cost search without grid pruning, for testing the planner's
//! optimality claims (Lynch & Mason 1996 §4.3) on small instances.

use super::crossing::goal_finish;
use super::steps::step_cost;
use crate::planner::stable::{Pose, Problem};

/// Brute-force uniform-cost search over the same step discretisation *without grid pruning*,
/// exploring every control sequence up to `depth` steps; returns the least cost that reaches
/// the goal neighbourhood at a step's end or, as the planner's exact finish, between its ends (no transit checks: for arm pushers). For testing the planner's
/// optimality claims (§4.3) on small instances.
pub fn brute_force_cost(p: &Problem, depth: usize) -> Option<u32> {
    let mut best: Option<u32> = None;
    fn rec(
        p: &Problem,
        q: Pose,
        prev: Option<(usize, usize)>,
        cost: u32,
        depth: usize,
        best: &mut Option<u32>,
    ) {
        if best.is_some_and(|b| cost >= b) {
            return;
        }
        if prev.is_some_and(|(_, k)| k != usize::MAX) && p.in_goal(&q) {
            *best = Some(cost);
            return;
        }
        if depth == 0 {
            return;
        }
        for (ci, cm) in p.contacts.iter().enumerate() {
            for (k, xi) in p.steps_at(ci, &q).iter().enumerate() {
                let Some(dc) = step_cost(p, prev, ci, k) else {
                    continue;
                };
                if cost.saturating_add(dc) > p.params.max_cost {
                    continue;
                }
                // The goal met between the step's ends (the planner's exact finish).
                if let Some(t) = goal_finish(p, &q, xi)
                    && t < 1.0
                    && cm.body.step_free(&p.world, &q, &(xi * t))
                    && best.is_none_or(|b| cost + dc < b)
                {
                    *best = Some(cost + dc);
                }
                if !cm.body.step_free(&p.world, &q, xi) {
                    continue;
                }
                rec(
                    p,
                    q.integrate(xi),
                    Some((ci, k)),
                    cost + dc,
                    depth - 1,
                    best,
                );
            }
        }
    }
    rec(
        p,
        p.start,
        p.start_contact.map(|c| (c, usize::MAX)),
        0,
        depth,
        &mut best,
    );
    best
}

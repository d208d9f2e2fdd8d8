//! Re-planning from measured poses for the closed loop of stable pushing
//! ([`crate::exec::stable_feedback`]): Lynch & Mason's planner (§4.1–4.5) run again from where
//! the camera sees the slider, as its plans assume a known start. Three things the planner
//! alone does not give an executor: plans that keep a margin from the obstacles where they can
//! (the paper's plans graze them, and a closed loop allowed some error off its path then pushes
//! the slider into them), a start on any pushing edge when the plate's own has no plan, and a
//! start the planner accepts when the slider already grazes an obstacle.

use crate::mechanics::V2;
use crate::planner::stable::collision::{Body, Obstacle};
use crate::planner::stable::exact::finish_exactly;
use crate::planner::stable::transit::transit;
use crate::planner::stable::{Plan, Pose, Problem, plan as plan_stable};

/// A plan from the measured slider pose `s`, the plate on contact `ci`: on that contact first
/// (no contact change, [`plan_inner`]); else starting on any pushing edge (the executor
/// transits to it). The planner refuses a start where the slider (with the pusher) touches an
/// obstacle, and a slider the closed loop let graze a wall is such a start: then the same from
/// the nearest free pose within `NUDGE` (the closed loop takes up the difference).
pub fn plan_from(p: &Problem, s: Pose, ci: usize) -> Option<Plan> {
    let kept = with_margin(p, MARGIN);
    let attempt = |q0: Pose| {
        [&kept, p].into_iter().find_map(|base| {
            [Some(ci), None].into_iter().find_map(|sc| {
                let mut q = base.clone();
                q.start = q0;
                q.start_contact = sc;
                plan_inner(&q).filter(|pl| match pl.steps.first() {
                    // A plan on another edge needs a way there from the plate's.
                    Some(st) => st.contact == ci || transit(p, &q0, ci, st.contact, 0).is_some(),
                    None => p.in_goal(&q0),
                })
            })
        })
    };
    if let Some(pl) = attempt(s) {
        return Some(pl);
    }
    let free = |q: &Pose| {
        p.contacts
            .iter()
            .any(|c| c.body.clearance(&p.world, q, NUDGE) > NUDGE_CLEARANCE)
    };
    if free(&s) {
        return None;
    }
    // Nearest first: rings of 2 mm, 16 directions, the heading as measured or ±2°; the first
    // [`NUDGE_TRIES`] free poses are tried.
    let mut tried = 0;
    for k in 1..=(NUDGE / 0.002).round() as usize {
        let r = 0.002 * k as f64;
        for j in 0..16 {
            let a = j as f64 * std::f64::consts::TAU / 16.0;
            for dth in [0.0, 2f64.to_radians(), -(2f64.to_radians())] {
                let q = Pose::new(s.x + r * a.cos(), s.y + r * a.sin(), s.theta + dth);
                if !free(&q) {
                    continue;
                }
                tracing::info!(
                    "stable closed loop: the slider touches an obstacle; planning from {:.1} mm, \
                     {:.0}° away",
                    r * 1e3,
                    dth.to_degrees()
                );
                if let Some(pl) = attempt(q) {
                    return Some(pl);
                }
                tried += 1;
                if tried >= NUDGE_TRIES {
                    return None;
                }
            }
        }
    }
    None
}

/// A plan for `p` ([`plan_inner`]) that keeps [`MARGIN`] from the obstacles where one does,
/// else one that may graze them.
pub fn plan_clear(p: &Problem) -> Option<Plan> {
    plan_inner(&with_margin(p, MARGIN))
        .filter(|pl| !pl.steps.is_empty())
        .or_else(|| plan_inner(p))
}

/// The clearance plans keep from obstacles where they can ([`with_margin`]), m: a plan that
/// grazes a wall is one the closed loop, allowed
/// [`crate::exec::stable_feedback::FeedbackParams::replan_xy`] off its path,
/// pushes the slider into.
pub const MARGIN: f64 = 0.025;

/// `p` with every contact's collision body (slider and pusher) grown by `m` (each convex part
/// offset outward, its corners cut: a polygon between the part grown by `m·cos(π/n)`-ish and
/// by `m`): its plans keep about `m` from every obstacle and wall. Only the collision bodies
/// change (mechanics, costs, goal and transits are `p`'s).
pub fn with_margin(p: &Problem, m: f64) -> Problem {
    let mut q = p.clone();
    let slider_parts: Vec<Vec<V2>> = Obstacle::parts(&p.slider.vertices)
        .map(|ps| ps.into_iter().map(|o| o.vertices).collect())
        .unwrap_or_else(|| vec![p.slider.vertices.clone()]);
    for c in &mut q.contacts {
        let mut parts: Vec<Vec<V2>> = slider_parts.iter().map(|v| grown(v, m)).collect();
        if !c.footprint.is_empty() {
            parts.push(grown(&c.footprint, m));
        }
        c.body = Body::new(&parts);
        c.swept = c.steps.iter().map(|xi| c.body.swept(xi)).collect();
        c.fine_swept = c.fine_steps.iter().map(|xi| c.body.swept(xi)).collect();
    }
    q
}

/// The convex polygon `v` grown by `m`: each vertex replaced by its two neighbouring edges'
/// points moved out along their normals.
fn grown(v: &[V2], m: f64) -> Vec<V2> {
    let ccw = crate::mechanics::signed_area(v) >= 0.0;
    let n = v.len();
    let normal = |i: usize| {
        let d = v[(i + 1) % n] - v[i];
        let out = V2::new(d.y, -d.x);
        let out = if ccw { out } else { -out };
        out / out.norm().max(1e-12)
    };
    let mut out = Vec::with_capacity(2 * n);
    for (i, p) in v.iter().enumerate() {
        let (prev, next) = (normal((i + n - 1) % n), normal(i));
        out.push(p + prev * m);
        out.push(p + next * m);
    }
    out
}

/// How far from the measured pose [`plan_from`] looks for a free start, m.
const NUDGE: f64 = 0.02;
/// How many free poses near it [`plan_from`] plans from before it gives up.
const NUDGE_TRIES: usize = 6;
/// The clearance that start needs, m.
const NUDGE_CLEARANCE: f64 = 0.002;

/// A plan for `p` that ends in the inner part of its goal neighbourhood where one exists
/// (`GOAL_SHRINK`), exactly on the goal where the exact finish (§4.5) exists; `None` when no
/// plan reaches even the whole neighbourhood.
pub fn plan_inner(p: &Problem) -> Option<Plan> {
    for shrink in GOAL_SHRINK {
        let mut q = p.clone();
        q.params.goal_xy *= shrink.0;
        q.params.goal_theta *= shrink.1;
        if shrink.0 < 1.0 {
            // A tighter goal is a preference: a short search, not an exhausted one.
            q.params.max_nodes = q.params.max_nodes.min(INNER_NODES);
        }
        let pl = plan_stable(&q);
        if pl.found {
            return Some(finish_exactly(&q, &pl).unwrap_or(pl));
        }
    }
    None
}

/// Nodes a search for the inner part of the goal may expand before the next, wider goal is
/// tried.
const INNER_NODES: usize = 20_000;

/// The goal neighbourhoods [`plan_inner`] tries, as shares of the task's (x-y, θ): a plan
/// ends anywhere in its neighbourhood, often on its edge, where the camera's noise and the
/// next push's error decide; so a plan aims at the inner part first.
const GOAL_SHRINK: [(f64, f64); 3] = [(0.4, 0.5), (0.7, 0.75), (1.0, 1.0)];

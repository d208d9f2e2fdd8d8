//! The exact finish of a push step (Lynch & Mason 1996 §4.2.4's goal test, made continuous): a
//! step may pass through the goal neighbourhood between its two ends, where a test at the ends
//! of grid-sized steps cannot see it. With `a = 0` (Fig. 17's costs) pushing on costs nothing,
//! so a plan that would end inside the neighbourhood mid-step costs the same as one that ends
//! on a step's end; a search that tests only the ends adds a control change to land there, and
//! loses the optimum. [`goal_crossing`] finds the first instant of a step inside the
//! neighbourhood, to machine precision.

use crate::mechanics::V3;
use crate::planner::stable::{Pose, Problem, angle_diff, cor_of};

/// Bisection steps on a monotone piece (2⁻⁶⁰ of the step).
const BISECT: usize = 60;

/// The least `t ∈ [0, 1]` at which the motion `q.integrate(xi · t)` is in the goal
/// neighbourhood, or `None` if it never is during the step.
pub fn goal_crossing(p: &Problem, q: &Pose, xi: &V3) -> Option<f64> {
    let g = &p.goal;
    let (gxy, gth) = (p.params.goal_xy, p.params.goal_theta);
    // The θ constraint: θ(t) = θ0 + ω t within gth of the goal's heading (mod 2π).
    let d0 = angle_diff(g.theta, q.theta);
    let mut windows: Vec<(f64, f64)> = Vec::new();
    if xi.z.abs() < 1e-12 {
        if d0.abs() <= gth {
            windows.push((0.0, 1.0));
        }
    } else {
        for k in [-1.0, 0.0, 1.0] {
            let c = d0 + k * std::f64::consts::TAU;
            let (a, b) = ((c - gth) / xi.z, (c + gth) / xi.z);
            let (lo, hi) = (a.min(b).max(0.0), a.max(b).min(1.0));
            if lo <= hi {
                windows.push((lo, hi));
            }
        }
        windows.sort_by(|x, y| x.0.total_cmp(&y.0));
    }
    let at = |t: f64| q.integrate(&(xi * t));
    let inside = |t: f64| {
        let r = at(t);
        (r.x - g.x).abs() <= gxy && (r.y - g.y).abs() <= gxy
    };
    // Cut each window where x(t) or y(t) may turn (the motion's heading about its centre
    // crosses a multiple of π/2): on each piece both are monotone, so the set where the piece
    // is inside is one interval, and its start is found by bisection on each bound.
    let turns: Vec<f64> = match cor_of(xi) {
        Some(c) => {
            let centre = q.apply(c);
            let phi0 = (q.y - centre.y).atan2(q.x - centre.x);
            let mut ts = Vec::new();
            for k in -8..=8 {
                let t = (k as f64 * std::f64::consts::FRAC_PI_2 - phi0) / xi.z;
                if t > 0.0 && t < 1.0 {
                    ts.push(t);
                }
            }
            ts
        }
        None => vec![],
    };
    for (lo, hi) in windows {
        let mut cuts = vec![lo];
        cuts.extend(turns.iter().copied().filter(|&t| t > lo && t < hi));
        cuts.push(hi);
        cuts.sort_by(f64::total_cmp);
        for w in cuts.windows(2) {
            if let Some(t) = first_inside(w[0], w[1], &at, &inside, g, gxy) {
                return Some(t);
            }
        }
    }
    None
}

/// On `[a, b]`, where x(t) and y(t) are monotone, the first `t` inside the box about `g`.
fn first_inside(
    a: f64,
    b: f64,
    at: &dyn Fn(f64) -> Pose,
    inside: &dyn Fn(f64) -> bool,
    g: &Pose,
    gxy: f64,
) -> Option<f64> {
    if inside(a) {
        return Some(a);
    }
    // Each of the four bounds holds on a sub-interval ending at a or at b (monotone). The
    // start of the intersection is the latest start over the bounds that hold from b only.
    let bounds: [&dyn Fn(&Pose) -> bool; 4] = [
        &|r| r.x - g.x <= gxy,
        &|r| g.x - r.x <= gxy,
        &|r| r.y - g.y <= gxy,
        &|r| g.y - r.y <= gxy,
    ];
    let mut start = a;
    for holds in bounds {
        let (ha, hb) = (holds(&at(a)), holds(&at(b)));
        match (ha, hb) {
            (true, _) => {}
            (false, false) => return None,
            (false, true) => {
                // First t where it holds: bisect keeping `hi` on the holding side.
                let (mut lo, mut hi) = (a, b);
                for _ in 0..BISECT {
                    let m = 0.5 * (lo + hi);
                    if holds(&at(m)) {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                start = start.max(hi);
            }
        }
    }
    // A bound holding at a but not at b ends inside the piece: check the start is before.
    (start <= b && inside(start)).then_some(start)
}

/// Samples of the rest of a step searched for its deepest point inside the neighbourhood.
const DEPTH_SAMPLES: usize = 32;

/// The largest relative offset from the goal (in x, y or θ, over the neighbourhood's
/// half-width) at which an exact finish may end: it ends in the inner half.
pub const FINISH_DEPTH: f64 = 0.5;

/// Where an exact finish of the step `xi` from `q` ends: from the first instant inside the goal
/// neighbourhood ([`goal_crossing`]) on, the sampled instant deepest inside it (the largest
/// margin to its faces, relative to their half-widths), if that is in the inner half
/// (`FINISH_DEPTH`): a plan that ended on the neighbourhood's boundary would leave it at any
/// execution error (the simulated robot's Fig. 13 ended 0.3° outside one).
pub fn goal_finish(p: &Problem, q: &Pose, xi: &V3) -> Option<f64> {
    let t0 = goal_crossing(p, q, xi)?;
    let g = &p.goal;
    let depth = |t: f64| {
        let r = q.integrate(&(xi * t));
        let dx = (r.x - g.x).abs() / p.params.goal_xy;
        let dy = (r.y - g.y).abs() / p.params.goal_xy;
        let dt = angle_diff(r.theta, g.theta).abs() / p.params.goal_theta;
        dx.max(dy).max(dt)
    };
    let mut best = (depth(t0), t0);
    for k in 1..=DEPTH_SAMPLES {
        let t = t0 + (1.0 - t0) * k as f64 / DEPTH_SAMPLES as f64;
        let d = depth(t);
        if d < best.0 {
            best = (d, t);
        }
    }
    (best.0 <= FINISH_DEPTH && p.in_goal(&q.integrate(&(xi * best.1)))).then_some(best.1)
}

//! Closed-loop stable pushing on the plated robot: the plan of Lynch & Mason §4
//! driven with the camera in the loop. §3's guarantee — the slider stays fixed on the pusher —
//! holds for *every* pusher motion whose rotation centre lies in the stable set of the contact
//! (§3.3, STABLE), not only for the planner's extremal controls. So the robot may steer freely
//! within that set; this executor uses it to follow the planned path:
//!
//! - every control period it observes the slider and derives where the robot's axle would be
//!   if the plate were flush on the planned contact (the *virtual* pose);
//! - it projects that pose onto the planned path and steers with a path-following law
//!   (curvature = the plan's curvature − k_e·lateral error − k_θ·heading error), the
//!   curvature clamped into the stable set's interval of turning curvatures for the contact
//!   ([`stable_curvatures`]);
//! - past a bound (lateral or heading error), or at the end of the path outside the goal, it
//!   re-plans from the measured slider pose (the planner takes milliseconds), and prefers the
//!   plan's exact finish (§4.5) when there is one; re-plans keep a margin from the obstacles
//!   where they can, may start on any pushing edge, and start from a free pose next to a
//!   slider that grazes an obstacle ([`crate::exec::stable_replan`]);
//! - the robot may start anywhere, at any heading: it first drives to the plan's first edge
//!   ([`crate::exec::stable_start`]), or re-plans onto an edge it can reach;
//! - a car's corrections turn no tighter than its turning radius (its pushes are forward only,
//!   as every push here);
//! - when the plate has lost the edge (the slider turned or slid on it beyond a bound), it
//!   backs off and re-acquires the edge with the transit code's approach
//!   ([`crate::exec::stable::approach`]), then re-plans.
//!
//! Planned contact changes are driven as in the open-loop executor
//! ([`crate::exec::stable::drive_transit`]).

use anyhow::{Context, Result, bail};

use crate::exec::io::RobotIo;
use crate::exec::stable::{approach, drive_transit, flush_pose, observe};
use crate::exec::stable_replan::{plan_clear, plan_from};
use crate::exec::stable_start::{go_to_first_contact, on_edge, start_path};
use crate::mechanics::{V2, V3, cross};
use crate::planner::stable::pusher::PusherKind;
use crate::planner::stable::robot::{SPEED, robot_in_slider};
use crate::planner::stable::transit::transit;
use crate::planner::stable::{Plan, Pose, Problem, angle_diff};

/// After the plate lost the edge, the pusher–slider friction the loop plans with is cut by
/// this factor …
const MU_CUT: f64 = 0.8;

/// … down to this share of the nominal one.
const MIN_MU_SHARE: f64 = 0.5;

/// Settings of the closed loop.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FeedbackParams {
    /// Distance pushed per control period, m (one `Velocity` command, then a look).
    pub control_step: f64,
    /// Gain on the lateral error, 1/m² (curvature per metre of error).
    pub k_lateral: f64,
    /// Gain on the heading error, 1/m (curvature per radian).
    pub k_heading: f64,
    /// Share of the stable curvature interval the steering may use (inside the set, not on its
    /// boundary).
    pub stable_margin: f64,
    /// Re-plan when the slider is this far off the planned path, m.
    pub replan_xy: f64,
    /// Re-plan when the slider's heading is this far off the path's, rad.
    pub replan_theta: f64,
    /// The plate has lost the edge when the slider sits this far from flush on it, m (gap or
    /// sideways).
    pub lost_xy: f64,
    /// … or turned this far on it, rad.
    pub lost_theta: f64,
    /// Most re-plans before giving up.
    pub max_replans: usize,
    /// Most contact losses before giving up.
    pub max_losses: usize,
}

impl Default for FeedbackParams {
    fn default() -> Self {
        FeedbackParams {
            control_step: 0.01,
            k_lateral: 100.0,
            k_heading: 20.0,
            stable_margin: 0.9,
            replan_xy: 0.02,
            replan_theta: 5f64.to_radians(),
            lost_xy: 0.012,
            lost_theta: 8f64.to_radians(),
            max_replans: 20,
            max_losses: 4,
        }
    }
}

/// What a closed-loop run did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FeedbackRun {
    /// Whether the camera saw the slider in the goal neighbourhood at the end.
    pub reached: bool,
    /// The slider's last observed pose.
    pub end: Pose,
    /// Re-plans from the measured poses.
    pub replans: usize,
    /// Times the plate lost the edge and re-acquired it.
    pub contact_losses: usize,
    /// Distance pushed, m.
    pub pushed: f64,
    /// Control periods driven.
    pub periods: usize,
    /// Planning time of the re-plans, ms.
    pub replan_ms: f64,
    /// The observed slider positions, one per look (table m): the executed path.
    pub path: Vec<[f64; 2]>,
    /// Why it stopped outside the goal, if it did.
    pub failure: Option<String>,
}

/// The interval `[κ_right, κ_left]` of axle-path curvatures (1/m, left positive) of forward
/// pushes on contact `ci` that lie in its stable set (with the pusher's feasible set): a
/// robot arc of curvature κ is a rotation about a point on its axle line at 1/κ, and the set
/// is convex on the velocity sphere, so the curvatures form an interval about 0 (straight
/// ahead). Found by bisection on the set's membership test.
pub fn stable_curvatures(p: &Problem, ci: usize) -> (f64, f64) {
    let (axle, heading) = robot_in_slider(p, ci);
    let set = &p.contacts[ci].usable.set;
    let twist = |k: f64| {
        // Axle velocity `heading`, angular velocity `k`: the slider-frame twist at its origin.
        let u = heading + V2::new(axle.y, -axle.x) * k;
        V3::new(u.x, u.y, k)
    };
    let edge = |sign: f64| {
        if !set.contains(&twist(0.0)) {
            return 0.0;
        }
        let (mut lo, mut hi) = (0.0, 100.0);
        if set.contains(&twist(sign * hi)) {
            return sign * hi;
        }
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            if set.contains(&twist(sign * mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        sign * lo
    };
    (edge(-1.0), edge(1.0))
}

/// A run of a plan's steps on one contact, as the path of the robot's axle.
struct Segment {
    contact: usize,
    /// Axle positions (table frame) at each configuration.
    pts: Vec<V2>,
    /// Curvature of the axle path of each step.
    kappa: Vec<f64>,
    /// Arc length at each point.
    cum: Vec<f64>,
    /// The robot's heading at the end.
    end_dir: V2,
}

/// The plan's runs of steps with one contact, in order.
fn segments(p: &Problem, plan: &Plan) -> Vec<Segment> {
    let mut out: Vec<Segment> = Vec::new();
    for st in &plan.steps {
        let (axle, heading) = robot_in_slider(p, st.contact);
        let xi = V3::new(st.twist[0], st.twist[1], st.twist[2]);
        let u = V2::new(xi.x - xi.z * axle.y, xi.y + xi.z * axle.x);
        let d = u.dot(&heading);
        let kappa = if d.abs() > 1e-9 { xi.z / d } else { 0.0 };
        if !matches!(out.last(), Some(s) if s.contact == st.contact) {
            out.push(Segment {
                contact: st.contact,
                pts: vec![st.from.apply(axle)],
                kappa: Vec::new(),
                cum: vec![0.0],
                end_dir: st.from.rotate(heading),
            });
        }
        let Some(s) = out.last_mut() else { continue };
        // The step's arc in pieces of at most 5 mm of the axle's path (a finishing step may
        // be a long Dubins arc; its chord is not the path).
        let n = ((d.abs() / 0.005).ceil() as usize).clamp(1, 1000);
        for k in 1..=n {
            let q = st.from.integrate(&(xi * (k as f64 / n as f64)));
            let pt = q.apply(axle);
            let l = s.cum[s.cum.len() - 1] + (pt - s.pts[s.pts.len() - 1]).norm();
            s.pts.push(pt);
            s.kappa.push(kappa);
            s.cum.push(l);
            s.end_dir = q.rotate(heading);
        }
    }
    out
}

/// How tracking one segment ended.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tracked {
    /// At the end of the path.
    Done,
    /// Too far off the path: re-plan.
    OffPath,
    /// The plate lost the edge.
    Lost,
    /// The slider came into the goal neighbourhood with margin before the path ended.
    InGoal,
    /// No transit path leads from the plate's edge to the next segment's from where the
    /// slider is: re-plan.
    NoTransit,
}

/// Whether `q` is inside the goal neighbourhood by a margin for the camera's noise.
fn well_in_goal(p: &Problem, q: &Pose) -> bool {
    (q.x - p.goal.x).abs() <= p.params.goal_xy * 0.7
        && (q.y - p.goal.y).abs() <= p.params.goal_xy * 0.7
        && angle_diff(q.theta, p.goal.theta).abs() <= p.params.goal_theta * 0.5
}

/// Follow segment `seg` with the closed loop until its end, a bound or a lost contact; on the
/// plan's `last` segment also until the slider is well inside the goal.
fn track(
    p: &Problem,
    seg: &Segment,
    io: &mut dyn RobotIo,
    fp: &FeedbackParams,
    run: &mut FeedbackRun,
    last: bool,
) -> Result<Tracked> {
    let ci = seg.contact;
    let (k_right, k_left) = stable_curvatures(p, ci);
    let (k_min, k_max) = (k_right * fp.stable_margin, k_left * fp.stable_margin);
    // A car turns no tighter than its radius (Fig. 14): its plan's pushes do not, nor may the
    // corrections.
    let k_car = match p.pusher.kind {
        PusherKind::Car { min_turning_radius } if min_turning_radius > 0.0 => {
            1.0 / min_turning_radius
        }
        _ => f64::INFINITY,
    };
    let n = seg.pts.len();
    let total = seg.cum[n - 1];
    // Start from the nearest point of the whole path (it may be taken up half-way).
    let (_, s0) = observe(io)?;
    let (c0, _) = flush_pose(p, ci, &s0);
    let mut idx = (0..n - 1)
        .min_by(|a, b| {
            (seg.pts[*a] - c0)
                .norm()
                .total_cmp(&(seg.pts[*b] - c0).norm())
        })
        .unwrap_or(0);
    // Enough periods for the path three times over.
    let limit = ((3.0 * total + 0.2) / fp.control_step) as usize + 20;
    for _ in 0..limit {
        let (r, s) = observe(io)?;
        run.path.push([s.x, s.y]);
        run.end = s;
        let (c, h) = flush_pose(p, ci, &s);
        let rel = V2::new(r.x, r.y) - c;
        let (side, gap) = (cross(h, rel), -rel.dot(&h));
        let dth = angle_diff(r.theta, h.y.atan2(h.x));
        if gap.abs() > fp.lost_xy || side.abs() > fp.lost_xy || dth.abs() > fp.lost_theta {
            tracing::info!(
                "stable closed loop: the plate is off the edge: gap {:.1} mm, sideways {:.1} mm, \
                 turned {:.1}°",
                gap * 1e3,
                side * 1e3,
                dth.to_degrees()
            );
            return Ok(Tracked::Lost);
        }
        if last && well_in_goal(p, &s) {
            return Ok(Tracked::InGoal);
        }
        // Project the virtual axle `c` onto the path, never backwards.
        let (mut best, mut at) = (f64::INFINITY, (idx, 0.0));
        for j in idx..(idx + 16).min(n - 1) {
            let (a, b) = (seg.pts[j], seg.pts[j + 1]);
            let d = b - a;
            let l2 = d.dot(&d).max(1e-18);
            let t = ((c - a).dot(&d) / l2).clamp(0.0, 1.0);
            let dist = (a + d * t - c).norm();
            if dist < best {
                best = dist;
                at = (j, t);
            }
        }
        idx = at.0;
        let (a, b) = (seg.pts[idx], seg.pts[idx + 1]);
        let tangent = if (b - a).norm() > 1e-9 {
            (b - a).normalize()
        } else {
            seg.end_dir
        };
        let sigma = seg.cum[idx] + at.1 * (seg.cum[idx + 1] - seg.cum[idx]);
        let mut remaining = total - sigma;
        if idx == n - 2 && at.1 >= 1.0 {
            // Past the last point: along the final heading.
            remaining = -(c - seg.pts[n - 1]).dot(&seg.end_dir);
        }
        if remaining <= 1e-3 {
            return Ok(Tracked::Done);
        }
        let e = cross(tangent, c - (a + (b - a) * at.1));
        let th_e = angle_diff(h.y.atan2(h.x), tangent.y.atan2(tangent.x));
        if e.abs() > fp.replan_xy || th_e.abs() > fp.replan_theta {
            tracing::info!(
                "stable closed loop: off the path by {:.1} mm, {:.1}° at {:.0} of {:.0} mm",
                e * 1e3,
                th_e.to_degrees(),
                sigma * 1e3,
                total * 1e3
            );
            return Ok(Tracked::OffPath);
        }
        // The plan's own curvature is always allowed (its controls are the extremal stable
        // pushes, on the set's boundary); the corrections stay inside the set.
        let k_ref = seg.kappa[idx];
        let kappa = (k_ref - fp.k_lateral * e - fp.k_heading * th_e.sin())
            .clamp(k_min.min(k_ref), k_max.max(k_ref))
            .clamp(-k_car, k_car);
        let ds = fp.control_step.min(remaining.max(0.002));
        let dur = ds / SPEED;
        io.drive(SPEED, kappa * SPEED, dur)
            .context("a closed-loop push")?;
        run.pushed += ds;
        run.periods += 1;
    }
    Ok(Tracked::OffPath)
}

/// Back off the edge and bring the plate flush on contact `ci` again (the approach of a
/// transit).
fn reacquire(p: &Problem, ci: usize, io: &mut dyn RobotIo) -> Result<()> {
    io.forward(-0.04).context("backing off a lost edge")?;
    approach(p, ci, io).context("re-acquiring the edge")
}

/// A plan from the measured slider pose `s` with the plate on contact `ci` ([`plan_from`]),
/// counted in `run`.
fn replan(p: &Problem, s: Pose, ci: usize, run: &mut FeedbackRun) -> Option<Plan> {
    let t0 = std::time::Instant::now();
    let found = plan_from(p, s, ci);
    run.replan_ms += t0.elapsed().as_secs_f64() * 1e3;
    run.replans += 1;
    found
}

/// Drive `plan` closed loop on `io` (the slider is the object `slider`; the robot starts
/// anywhere free, at any heading: it first drives to the plan's first contact,
/// [`go_to_first_contact`]). Returns what it did; `reached` is the camera's verdict.
pub fn execute_closed_loop(
    p: &Problem,
    plan: &Plan,
    io: &mut dyn RobotIo,
    fp: &FeedbackParams,
) -> Result<FeedbackRun> {
    let Some(first) = plan.steps.first() else {
        bail!("the plan has no step");
    };
    let (_, s0) = observe(io)?;
    let mut run = FeedbackRun {
        reached: false,
        end: s0,
        replans: 0,
        contact_losses: 0,
        pushed: 0.0,
        periods: 0,
        replan_ms: 0.0,
        path: vec![[s0.x, s0.y]],
        failure: None,
    };
    // The robot may start anywhere: when it has no way to the plan's first edge, a plan from
    // the observed pose that starts on an edge it can reach.
    let mut current = plan.clone();
    let (r0, _) = observe(io)?;
    let reachable =
        |c: usize| on_edge(p, c, &r0, &s0) || start_path(p, V2::new(r0.x, r0.y), &s0, c).is_some();
    if !reachable(first.contact) {
        let alt = (0..p.contacts.len())
            .filter(|c| reachable(*c))
            .find_map(|c| {
                let mut q = p.clone();
                q.start = s0;
                q.start_contact = Some(c);
                run.replans += 1;
                plan_clear(&q).filter(|pl| pl.steps.first().is_some_and(|st| st.contact == c))
            });
        match alt {
            Some(pl) => current = pl,
            None => {
                run.failure = Some(
                    "no transit path from the robot's start to an edge with a plan".to_string(),
                );
                return Ok(run);
            }
        }
    }
    let first = current.steps[0].contact;
    if !go_to_first_contact(p, first, io)? {
        run.failure = Some(format!(
            "no transit path from the robot's start to contact {first}"
        ));
        return Ok(run);
    }
    let mut contact = first;
    // The model the loop plans and steers with: the nominal one until the plate slides.
    let mut model = p.clone();
    // Bounds of the current plan: widened once when no plan exists from the measured pose and
    // the current one is followed on.
    let mut relax = 1.0;
    // The segment to go on from, and the one being driven.
    let (mut first_seg, mut at_seg) = (0, 0);
    loop {
        let segs = segments(&model, &current);
        let mut outcome = Tracked::Done;
        let mut transits = current.transits.iter().peekable();
        let mut fpr = *fp;
        fpr.replan_xy *= relax;
        fpr.replan_theta *= relax;
        for (k, seg) in segs.iter().enumerate().skip(first_seg) {
            at_seg = k;
            if seg.contact != contact {
                // The plan's transit path for this change (a re-plan may start with one), or
                // one from the observed pose.
                let planned = transits
                    .next_if(|t| (t.from_contact, t.to_contact) == (contact, seg.contact))
                    .cloned();
                let tr = match planned {
                    Some(t) => t,
                    None => {
                        let (_, s) = observe(io)?;
                        match transit(&model, &s, contact, seg.contact, 0) {
                            Some(t) => t,
                            None => {
                                outcome = Tracked::NoTransit;
                                break;
                            }
                        }
                    }
                };
                drive_transit(&model, &tr, io)
                    .with_context(|| format!("transit {contact} → {}", seg.contact))?;
                contact = seg.contact;
            }
            outcome = track(&model, seg, io, &fpr, &mut run, k + 1 == segs.len())?;
            if outcome != Tracked::Done {
                break;
            }
        }
        if outcome == Tracked::Lost {
            run.contact_losses += 1;
            if run.contact_losses > fp.max_losses {
                run.failure = Some(format!("lost the edge {} times", run.contact_losses));
                break;
            }
            // The slider slid on the plate: the friction between them is lower than the model's
            // (a wrong guess is one of the errors the loop is for). Plan and steer from now on
            // with less of it, so that the stable sets, and the turns they allow, are narrower.
            if model.mu > MIN_MU_SHARE * p.mu
                && let Some(m) = model.with_mu((model.mu * MU_CUT).max(MIN_MU_SHARE * p.mu))
            {
                tracing::info!(
                    "stable closed loop: the edge was lost: planning with pusher friction {:.3} \
                     (was {:.3})",
                    m.mu,
                    model.mu
                );
                model = m;
            }
            reacquire(&model, contact, io)?;
        }
        let (_, s) = observe(io)?;
        run.end = s;
        run.path.push([s.x, s.y]);
        tracing::info!(
            "stable closed loop: {outcome:?} at ({:.3}, {:.3}, {:.2}°), goal ({:.3}, {:.3}, {:.2}°)",
            s.x,
            s.y,
            s.theta.to_degrees(),
            p.goal.x,
            p.goal.y,
            p.goal.theta.to_degrees()
        );
        if well_in_goal(p, &s) && outcome != Tracked::Lost {
            run.reached = true;
            break;
        }
        if run.replans >= fp.max_replans {
            run.reached = p.in_goal(&s);
            if !run.reached {
                run.failure = Some(format!("{} re-plans and not in the goal", run.replans));
            }
            break;
        }
        let next = replan(&model, s, contact, &mut run);
        tracing::info!(
            "stable closed loop: re-plan {}: {:?}",
            run.replans,
            next.as_ref().map(|pl| (pl.steps.len(), pl.exact_goal))
        );
        match next {
            Some(pl) if !pl.steps.is_empty() => {
                current = pl;
                relax = 1.0;
                first_seg = 0;
            }
            Some(_) => {
                run.reached = p.in_goal(&s);
                break;
            }
            None if p.in_goal(&s) => {
                run.reached = true;
                break;
            }
            None if relax == 1.0 && outcome == Tracked::OffPath => {
                // Keep following the plan it left (from where it is, with wider bounds).
                relax = 2.0;
                first_seg = at_seg;
            }
            None => {
                run.failure = Some(format!(
                    "no plan from the measured pose ({:.3}, {:.3}, {:.1}°)",
                    s.x,
                    s.y,
                    s.theta.to_degrees()
                ));
                break;
            }
        }
    }
    Ok(run)
}

//! Collecting the pushing strategy: Lau, Mitani & Igarashi §III-C (initial data collection)
//! and §III-D (experimental evaluation of existing data), Algorithm 1.
//!
//! Initial collection: K times, spin by a random angle and drive forward a random distance,
//! saving each push that moved the object as a sample; `reset_robot` (face the marker and
//! creep forward until the object moves) when a push did not move the object, and
//! `reset_robot_obj_boundary` (around the bound-all circle to the push-point, then push the
//! object back in; Fig. 3) when the object left the boundary. Experimental evaluation: solve
//! random goal queries with the data so far, adding each push as a supplemental sample used at
//! once, until the last `streak` queries all succeeded.
//!
//! Two guards the paper leaves to the person watching the robot: a random push that could carry
//! the object's marker out of the boundary is drawn again ([`safe_spin`]), and when the object
//! ends where the robot cannot get behind it (against the table's edge), `reset_robot_obj_boundary`
//! reports it instead of sliding the object along the edge, and [`bring_inside`] stops the
//! collection with an error that says where the object is, after [`STUCK_RESETS`] tries. The
//! collection ends with the object inside the boundary.
//!
//! Fewer samples than the paper: each push of the initial collection is, by default,
//! the one of [`CollectParams::candidates`] random pushes that, with the contact it leads the
//! robot to, the strategy knows least ([`Selection::Explore`], [`crate::strategy::active`]), and
//! the initial collection ends with a push for each way of moving the object (every 45°) its
//! samples do not cover ([`uncovered`]); the initial collection is short and the evaluation,
//! which stops at the streak, does the rest; and the evaluation keeps only the pushes that teach
//! the strategy something ([`Admission`]). `Selection::Random`, `initial` 300 and
//! `admission: None` are the paper's Algorithm 1.

use anyhow::Result;
use indicatif::ProgressBar;
use nalgebra::Vector2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::exec::deliver::{DeliveryParams, Failure, bound_all_radius, deliver_learned};
use crate::exec::io::RobotIo;
use crate::exec::maneuver::{Around, Drive, Turn, circle_walk, face};
use crate::strategy::active::{Selection, least_known, least_known_ahead};
use crate::strategy::regression::{Admission, KernelParams, PushStrategy};
use crate::strategy::sample::Sample;

/// Parameters of Algorithm 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CollectParams {
    /// K: samples of the initial collection.
    pub initial: usize,
    /// Largest random spin of a push, rad (either way).
    pub spin_max: f64,
    /// Shortest random push, m.
    pub push_min: f64,
    /// Longest random push, m.
    pub push_max: f64,
    /// ε: the object moved if its marker moved at least this far, m.
    pub epsilon: f64,
    /// Evaluation stops after this many straight successful queries (the paper: 10).
    pub streak: usize,
    /// Evaluation gives up after this many queries.
    pub max_queries: usize,
    /// Random goals are at least this far from the object, m.
    pub goal_min_distance: f64,
    /// Delivery parameters of the evaluation's queries (its time limit is over_time_limit()).
    pub delivery: DeliveryParams,
    /// Seed of the random pushes and goals.
    pub seed: u64,
    /// How the initial collection chooses its pushes.
    pub selection: Selection,
    /// Random candidate pushes [`Selection::Uncertain`] and [`Selection::Explore`] choose among.
    pub candidates: usize,
    /// Which pushes of the evaluation are kept as supplemental samples (`None`: all, the paper).
    pub admission: Option<Admission>,
}

/// K of the initial collection by default: measured as the shortest that reaches
/// the streak within 300 samples on every `lau-*` object.
pub const DEFAULT_INITIAL: usize = 100;

impl Default for CollectParams {
    fn default() -> Self {
        CollectParams {
            initial: DEFAULT_INITIAL,
            spin_max: 75f64.to_radians(),
            push_min: 0.02,
            push_max: 0.08,
            epsilon: 0.004,
            streak: 10,
            max_queries: 80,
            goal_min_distance: 0.25,
            // over_time_limit(): the paper's 8 minutes, as in its trials.
            delivery: DeliveryParams::default(),
            seed: 1,
            selection: Selection::Explore,
            candidates: 12,
            admission: Some(Admission::default()),
        }
    }
}

/// What a collection run did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct CollectReport {
    /// Samples from the initial collection.
    pub initial_samples: usize,
    /// Supplemental samples from the evaluation's queries.
    pub supplemental_samples: usize,
    /// [`Selection::Explore`]'s coverage pushes after the initial collection: one for each way
    /// of moving the object (every 45°) no sample covered.
    pub coverage_pushes: usize,
    /// Samples from those pushes (the others found no stand point or did not move the object).
    pub coverage_samples: usize,
    /// Pushes the evaluation's queries made (kept as samples or not).
    pub evaluation_pushes: usize,
    /// Samples in the strategy at the end (including any loaded before).
    pub total_samples: usize,
    /// Pushes of the initial collection that did not move the object (each led to reset_robot).
    pub misses: usize,
    /// Times reset_robot_obj_boundary ran.
    pub boundary_resets: usize,
    /// Goal queries solved or tried.
    pub queries: usize,
    /// Successful queries.
    pub successes: usize,
    /// Failed queries by reason.
    pub failures: std::collections::BTreeMap<String, usize>,
    /// Whether the last `streak` queries all succeeded.
    pub streak_reached: bool,
    /// Simulated (or real) minutes of the initial collection.
    pub initial_minutes: f64,
    /// Minutes of the whole run.
    pub total_minutes: f64,
}

/// `reset_robot()`: spin to face the object's marker and creep forward until the object moves.
/// Returns whether it moved.
pub fn reset_robot(io: &mut dyn RobotIo, epsilon: f64) -> Result<bool> {
    let o0 = io.object_pose();
    let r0 = io.robot_pose();
    let budget = (o0.position() - r0.position()).norm() + 0.15;
    let mut travelled = 0.0;
    let creep = 0.015;
    while travelled < budget {
        let r = io.robot_pose();
        let o = io.object_pose();
        let d = o.position() - r.position();
        face(io, d.y.atan2(d.x), &Turn::two_level(0.05))?;
        io.forward(creep)?;
        travelled += creep;
        if (io.object_pose().position() - o0.position()).norm() >= epsilon {
            return Ok(true);
        }
    }
    Ok(false)
}

/// How far a boundary reset may slide the object along the boundary (across the inward normal)
/// in one round before it stops pushing, m.
pub const SLIDE_LIMIT: f64 = 0.05;

/// `reset_robot_obj_boundary()` (Fig. 3): the object's marker is outside the boundary; move the
/// robot around the bound-all circle to the push-point (where the vector to the object's centre
/// is perpendicular to the boundary, pointing inside) and push the object back in. Returns
/// whether the marker is inside the boundary again.
pub fn reset_robot_obj_boundary(io: &mut dyn RobotIo, margin: f64, epsilon: f64) -> Result<bool> {
    let ws = io.workspace();
    let radius = bound_all_radius(&ws, margin);
    let reach = ws.reachable();
    let target = ws.boundary.inset(0.04);
    for _round in 0..4 {
        let o = io.object_pose();
        let Some(n) = ws.boundary.outward(o.position()) else {
            return Ok(true);
        };
        // The push-point, or the reachable point of the circle nearest to it from which a push
        // still points inward (within 60° of the boundary's inward normal); none: the object
        // lies where the robot cannot get behind it, and pushing from further round would only
        // slide it along the table's edge.
        let base = n.y.atan2(n.x);
        let at = |a: f64| o.position() + radius * Vector2::new(a.cos(), a.sin());
        let Some(push_angle) = (0..=12)
            .flat_map(|k| {
                let d = f64::from(k) * 5f64.to_radians();
                [base + d, base - d]
            })
            .find(|a| reach.contains(at(*a)))
        else {
            tracing::debug!(
                "boundary reset: no push-point behind the object at ({:.3}, {:.3})",
                o.x,
                o.y
            );
            return Ok(false);
        };
        tracing::debug!(
            "boundary reset round {_round}: object at ({:.3}, {:.3}), push from {:.0}° (wanted {:.0}°)",
            o.x,
            o.y,
            push_angle.to_degrees(),
            base.to_degrees()
        );
        circle_walk(
            io,
            o.position(),
            radius,
            radius,
            push_angle,
            &Drive::two_level(0.05),
            &Around::default(),
        )?;
        let o0 = io.object_pose().position();
        // (d) Push towards the object until it is back inside; give up this round when six
        // pushes running did not bring it closer (it slides along the boundary, or is stuck).
        let mut still = 0;
        let start = distance_outside(&target, o.position());
        let inward = -n;
        for _ in 0..30 {
            let o = io.object_pose();
            if target.contains(o.position()) {
                return Ok(true);
            }
            let away = distance_outside(&target, o.position());
            let r = io.robot_pose();
            // Aim at the marker, pulled a little towards the table's centre.
            let aim = o.position() + 0.03 * (ws.boundary.centre() - o.position()).normalize();
            let d = aim - r.position();
            face(io, d.y.atan2(d.x), &Turn::two_level(0.05))?;
            io.forward(0.03)?;
            let at = io.object_pose().position();
            let now = distance_outside(&target, at);
            let moved = at - o0;
            let slid = (moved - moved.dot(&inward) * inward).norm();
            if now > start + 0.02 || slid > SLIDE_LIMIT {
                // Pushed from the side (an off-centre marker, a push-point pulled in from the
                // table's edge), it slides along the edge rather than back in, and further out
                // or into a corner: stop before it is out of the robot's reach.
                break;
            }
            if now > away - epsilon {
                still += 1;
                if still >= 6 {
                    break;
                }
            } else {
                still = 0;
            }
        }
        let o = io.object_pose();
        tracing::debug!(
            "boundary reset round {_round} ended: object at ({:.3}, {:.3}), robot at {:?}",
            o.x,
            o.y,
            io.robot_pose()
        );
        if ws.boundary.contains(o.position()) {
            return Ok(true);
        }
    }
    Ok(ws.boundary.contains(io.object_pose().position()))
}

/// `reset_robot_obj_boundary` tries before [`bring_inside`] gives up: the object is then where
/// the robot cannot push it back (against the table's edge) and needs a hand. A try that finds
/// no push-point costs no motion; one whose pushes turn the object instead of bringing it in
/// (a marker near a corner) is worth repeating from the new pose.
pub const STUCK_RESETS: usize = 5;

/// Push the object back inside the boundary if it is outside (`reset_robot_obj_boundary`, up to
/// [`STUCK_RESETS`] times); returns how many resets ran, or an error that says where the object
/// is stuck.
pub fn bring_inside(io: &mut dyn RobotIo, margin: f64, epsilon: f64) -> Result<usize> {
    for tries in 0..STUCK_RESETS {
        if !outside(io) {
            return Ok(tries);
        }
        if reset_robot_obj_boundary(io, margin, epsilon)? {
            return Ok(tries + 1);
        }
    }
    Err(stuck(io))
}

/// The random spin of an initial-collection push: `first` (already drawn), or, when a push of
/// up to `push_max` along the heading it gives could carry the object's marker out of the
/// boundary, another draw, up to 16 in all; when none is safe, the one whose push ends deepest
/// inside. The object never moves further than the robot drives, so a safe heading keeps it in.
pub fn safe_spin(
    io: &mut dyn RobotIo,
    rng: &mut ChaCha8Rng,
    first: f64,
    params: &CollectParams,
) -> f64 {
    let ws = io.workspace();
    let (r, o) = (io.robot_pose(), io.object_pose().position());
    let end = |a: f64| o + params.push_max * Vector2::new((r.theta + a).cos(), (r.theta + a).sin());
    let mut best = (distance_outside(&ws.boundary, end(first)), first);
    for _ in 1..16 {
        if best.0 <= 0.0 || !best.0.is_finite() {
            break;
        }
        let a = rng.random_range(-params.spin_max..=params.spin_max);
        let d = distance_outside(&ws.boundary, end(a));
        if d < best.0 {
            best = (d, a);
        }
    }
    best.1
}

/// [`Selection::Uncertain`]'s and [`Selection::Explore`]'s push: of `params.candidates` random
/// (spin, length) pairs whose push keeps the object's marker inside the boundary, the one the
/// strategy knows least ([`least_known`], or [`least_known_ahead`] when exploring, in the
/// object's frame); when none is safe, [`safe_spin`]'s.
fn uncertain_push(
    io: &mut dyn RobotIo,
    rng: &mut ChaCha8Rng,
    strategy: &PushStrategy,
    params: &CollectParams,
) -> (f64, f64) {
    let ws = io.workspace();
    let (r, o) = (io.robot_pose(), io.object_pose());
    let p = o.point_to_local(r.position());
    let mut pushes = Vec::new();
    let mut motions = Vec::new();
    for _ in 0..params.candidates.max(1) {
        let a = rng.random_range(-params.spin_max..=params.spin_max);
        let l = rng.random_range(params.push_min..=params.push_max);
        let dir = Vector2::new((r.theta + a).cos(), (r.theta + a).sin());
        if distance_outside(&ws.boundary, o.position() + params.push_max * dir) > 0.0 {
            continue;
        }
        let m = o.vector_to_local(l * dir);
        pushes.push((a, l));
        motions.push([m.x, m.y]);
    }
    let width = strategy.params().kernel_width;
    let pick = match params.selection {
        Selection::Explore => least_known_ahead,
        _ => least_known,
    };
    match pick(strategy.samples(), [p.x, p.y], &motions, width) {
        Some(i) => pushes[i],
        None => {
            let first = rng.random_range(-params.spin_max..=params.spin_max);
            let angle = safe_spin(io, rng, first, params);
            (angle, rng.random_range(params.push_min..=params.push_max))
        }
    }
}

/// A way of moving the object counts as covered by a sample that moved it at least this far
/// within 22.5° of it, m.
pub const COVERED: f64 = 0.01;

/// The object-frame directions of motion, every 45° from the object's +x, that no sample moved
/// the object along (within 22.5°) by at least `min` m: ways the strategy cannot push it.
pub fn uncovered(samples: &[Sample], min: f64) -> Vec<f64> {
    let bin = std::f64::consts::FRAC_PI_4;
    let mut seen = [false; 8];
    for s in samples.iter().filter(|s| s.s_len() >= min) {
        let k = (s.s[1].atan2(s.s[0]) / bin).round().rem_euclid(8.0) as usize;
        seen[k % 8] = true;
    }
    (0..8)
        .filter(|&k| !seen[k])
        .map(|k| k as f64 * bin)
        .collect()
}

/// A push meant to move the object along `dir` (object frame, rad): round the bound-all circle
/// to the side opposite that way, face the marker and push. The sample, or `None` when the
/// robot cannot stand there or the object did not move.
fn coverage_push(
    io: &mut dyn RobotIo,
    dir: f64,
    margin: f64,
    params: &CollectParams,
) -> Result<Option<Sample>> {
    let ws = io.workspace();
    let radius = bound_all_radius(&ws, margin);
    let o = io.object_pose();
    let stand_angle = o.theta + dir + std::f64::consts::PI;
    let stand = o.position() + radius * Vector2::new(stand_angle.cos(), stand_angle.sin());
    if !ws.reachable().contains(stand) {
        return Ok(None);
    }
    circle_walk(
        io,
        o.position(),
        radius,
        radius,
        stand_angle,
        &Drive::two_level(0.05),
        &Around::default(),
    )?;
    // reset_robot's approach (face the marker, creep until the object moves), then a push
    // straight on, as the initial collection's pushes start from a touch.
    if !reset_robot(io, params.epsilon)? {
        return Ok(None);
    }
    let (r0, o0) = (io.robot_pose(), io.object_pose());
    io.forward((params.push_min + params.push_max) / 2.0)?;
    let (r1, o1) = (io.robot_pose(), io.object_pose());
    if (o1.position() - o0.position()).norm() < params.epsilon {
        return Ok(None);
    }
    Ok(Some(Sample::from_push(r0, r1, o0, o1)))
}

/// The error [`collect`] stops with when the object cannot be pushed back inside.
fn stuck(io: &mut dyn RobotIo) -> anyhow::Error {
    let (o, ws) = (io.object_pose(), io.workspace());
    anyhow::anyhow!(
        "the object is stuck outside the boundary at ({:.3}, {:.3}) m, where the robot cannot get \
         behind it to push it back ({STUCK_RESETS} resets failed; boundary x {:.2}..{:.2}, \
         y {:.2}..{:.2}): put it back inside and run again",
        o.x,
        o.y,
        ws.boundary.min[0],
        ws.boundary.max[0],
        ws.boundary.min[1],
        ws.boundary.max[1]
    )
}

/// How far `p` lies outside `r`, m (0 inside).
fn distance_outside(r: &crate::exec::io::Rect, p: Vector2<f64>) -> f64 {
    let dx = (r.min[0] - p.x).max(p.x - r.max[0]).max(0.0);
    let dy = (r.min[1] - p.y).max(p.y - r.max[1]).max(0.0);
    dx.hypot(dy)
}

fn outside(io: &mut dyn RobotIo) -> bool {
    let ws = io.workspace();
    !ws.boundary.contains(io.object_pose().position())
}

/// A random goal inside the boundary at least `min_dist` from the object's marker (the
/// last of 100 draws otherwise), and its distance from the marker.
fn random_goal(io: &mut dyn RobotIo, rng: &mut ChaCha8Rng, min_dist: f64) -> (Vector2<f64>, f64) {
    let ws = io.workspace();
    let area = ws.boundary.inset(0.05);
    let o = io.object_pose().position();
    let mut best = area.centre();
    for _ in 0..100 {
        let g = Vector2::new(
            rng.random_range(area.min[0]..=area.max[0]),
            rng.random_range(area.min[1]..=area.max[1]),
        );
        best = g;
        if (g - o).norm() >= min_dist {
            break;
        }
    }
    (best, (best - o).norm())
}

fn progress(pb: &ProgressBar, strategy: &PushStrategy, rep: &CollectReport, t: f64) {
    pb.set_position(strategy.len() as u64);
    pb.set_message(format!(
        "queries {} ok {} | {:.1} sim min",
        rep.queries,
        rep.successes,
        t / 60.0
    ));
}

/// Run Algorithm 1 on `io`: the initial collection, then the experimental evaluation. Each new
/// sample is added to `strategy` and passed to `sink` (to be stored) as it is made.
///
/// The evaluation's deliveries ask the strategy with the paper's keys, the object's motion
/// alone ([`KernelParams::turn_weight`] 0): they explore, keeping the pushes that turn the
/// object among the supplemental samples, and the streak is judged on the paper's rule. The
/// strategy's own parameters are back when the collection ends, however it ends. (Collecting
/// with the turn weight, collection seeds 1 and 4 of `lau-all`: the snake's seed-4 strategy
/// took 385 samples and delivered 0/10 from starts C and F.)
pub fn collect(
    io: &mut dyn RobotIo,
    strategy: &mut PushStrategy,
    params: &CollectParams,
    sink: &mut dyn FnMut(&Sample) -> Result<()>,
    pb: &ProgressBar,
) -> Result<CollectReport> {
    let own = strategy.params();
    strategy.set_params(KernelParams {
        turn_weight: 0.0,
        ..own
    });
    let rep = algorithm_1(io, strategy, params, sink, pb);
    strategy.set_params(own);
    strategy.set_admission(None);
    rep
}

/// [`collect`] with the strategy's parameters as they are (it leaves the admission rule set).
fn algorithm_1(
    io: &mut dyn RobotIo,
    strategy: &mut PushStrategy,
    params: &CollectParams,
    sink: &mut dyn FnMut(&Sample) -> Result<()>,
    pb: &ProgressBar,
) -> Result<CollectReport> {
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let t0 = io.time();
    let margin = params.delivery.bound_all_margin;
    let mut rep = CollectReport::default();

    // Initial data collection.
    let mut moved_last = false;
    let mut attempts = 0;
    while rep.initial_samples < params.initial && attempts < 8 * params.initial.max(1) {
        attempts += 1;
        if !moved_last {
            reset_robot(io, params.epsilon)?;
        }
        if outside(io) {
            rep.boundary_resets += bring_inside(io, margin, params.epsilon)?;
        }
        // Counters only: asking for a pose here would make a live robot look once more.
        tracing::debug!(
            "initial collection: {} samples, {} misses, {:.0} s",
            rep.initial_samples,
            rep.misses,
            io.time() - t0
        );
        let (angle, length) = match params.selection {
            Selection::Random => {
                let first = rng.random_range(-params.spin_max..=params.spin_max);
                let angle = safe_spin(io, &mut rng, first, params);
                (angle, rng.random_range(params.push_min..=params.push_max))
            }
            Selection::Uncertain | Selection::Explore => {
                uncertain_push(io, &mut rng, strategy, params)
            }
        };
        io.spin(angle)?;
        let (r0, o0) = (io.robot_pose(), io.object_pose());
        io.forward(length)?;
        let (r1, o1) = (io.robot_pose(), io.object_pose());
        moved_last = (o1.position() - o0.position()).norm() >= params.epsilon;
        if moved_last {
            let s = Sample::from_push(r0, r1, o0, o1);
            strategy.add(s);
            sink(&s)?;
            rep.initial_samples += 1;
        } else {
            rep.misses += 1;
        }
        progress(pb, strategy, &rep, io.time() - t0);
    }
    rep.initial_minutes = (io.time() - t0) / 60.0;

    // Exploring: a push for every way of moving the object the samples do not cover yet.
    if params.selection == Selection::Explore {
        for dir in uncovered(strategy.samples(), COVERED) {
            if outside(io) {
                rep.boundary_resets += bring_inside(io, margin, params.epsilon)?;
            }
            rep.coverage_pushes += 1;
            if let Some(s) = coverage_push(io, dir, margin, params)? {
                strategy.add(s);
                sink(&s)?;
                rep.coverage_samples += 1;
            }
            progress(pb, strategy, &rep, io.time() - t0);
        }
        rep.initial_minutes = (io.time() - t0) / 60.0;
    }

    // Experimental evaluation of existing data.
    strategy.set_admission(params.admission);
    let mut streak = 0;
    let mut needs_reset = true;
    while rep.queries < params.max_queries && params.streak > 0 {
        if needs_reset {
            reset_robot(io, params.epsilon)?;
        }
        if outside(io) {
            rep.boundary_resets += bring_inside(io, margin, params.epsilon)?;
        }
        let (goal, distance) = random_goal(io, &mut rng, params.goal_min_distance);
        tracing::debug!(
            "evaluation query {}: goal ({:.3}, {:.3}), {:.0} s",
            rep.queries,
            goal.x,
            goal.y,
            io.time() - t0
        );
        let mut added = 0;
        let d = deliver_learned(io, strategy, goal, &params.delivery, &mut |s| {
            added += 1;
            sink(s)
        })?;
        tracing::debug!(
            "evaluation query {}: delivered {} in {:.1} s, from {:.3} m off the goal, object path \
             {:.3} m",
            rep.queries,
            d.success,
            d.time,
            distance,
            d.object_path
        );
        rep.supplemental_samples += added;
        rep.evaluation_pushes += d.steps;
        rep.queries += 1;
        if d.success {
            rep.successes += 1;
            streak += 1;
        } else {
            streak = 0;
            if let Some(f) = d.failure {
                *rep.failures.entry(format!("{f:?}")).or_insert(0) += 1;
            }
        }
        needs_reset = matches!(d.failure, Some(Failure::TimeLimit));
        progress(pb, strategy, &rep, io.time() - t0);
        if streak >= params.streak {
            rep.streak_reached = true;
            break;
        }
    }
    // Leave the object inside the boundary, ready for a delivery.
    if outside(io) {
        rep.boundary_resets += bring_inside(io, margin, params.epsilon)?;
    }
    rep.total_samples = strategy.len();
    rep.total_minutes = (io.time() - t0) / 60.0;
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_4, FRAC_PI_6, PI};

    fn moved(s: [f64; 2]) -> Sample {
        Sample {
            p: [-0.1, 0.0],
            r: [0.04, 0.0],
            s,
            theta: 0.0,
        }
    }

    #[test]
    fn uncovered_ways_are_those_no_sample_moved_the_object_far_enough() {
        // +x by 1.5 cm and −x by 1.2 cm are covered (−x at −179°, in the bin of 180°); +y only
        // by 5 mm, which is too little; 30° by 2 cm falls in the 45° bin.
        let samples = [
            moved([0.015, 0.0]),
            moved([-0.012, -0.0002]),
            moved([0.0, 0.005]),
            moved([0.02 * FRAC_PI_6.cos(), 0.02 * FRAC_PI_6.sin()]),
        ];
        let left = uncovered(&samples, COVERED);
        let want = [2.0, 3.0, 5.0, 6.0, 7.0].map(|k| k * FRAC_PI_4);
        assert_eq!(left.len(), want.len(), "{left:?}");
        for (a, b) in left.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{left:?}");
        }
        assert!(!left.iter().any(|a| (a - PI).abs() < 1e-9));
        assert_eq!(uncovered(&[], COVERED).len(), 8);
    }
}

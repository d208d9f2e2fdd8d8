//! Object delivery (Lau, Mitani & Igarashi §III-E, Algorithm 2) and the dipole-field baseline
//! (§V, Fig. 10–11), both on a [`RobotIo`].
//!
//! Learned delivery repeats: observe robot and object; if the object's marker is within 2.2 cm
//! of the goal, succeed; if the object leaves the boundary, the robot leaves the table or time
//! runs out, fail. Otherwise ask the pushing strategy: in the *general case* for the push
//! direction r from the robot's current position p and the wanted object motion s (the goal
//! direction scaled by `offset`); in the *special case* — the last push moved the object away
//! from the goal (or did not move it: the robot lost contact) — for both the position p to push
//! from and the direction r, and move there around the object's bound-all circle (Fig. 3, 4b).
//! Motion is two-level (§IV): spins are corrected once at a finer level, and pushes are long
//! (coarse) far from the goal and short (fine) near it. Every push that moved the object is a
//! supplemental sample (§III-D), handed to a sink and usable at once — unless the strategy has an
//! admission rule (a collection's evaluation keeps only informative pushes,
//! [`crate::strategy::regression::Admission`]).

use anyhow::Result;
use nalgebra::Vector2;

pub use crate::exec::delivery_params::DeliveryParams;
use crate::exec::drift::{Push, reposition_next};
use crate::exec::io::{Rect, RobotIo, Workspace};
use crate::exec::last_leg::{last_leg_aim, last_leg_strategy};
use crate::exec::maneuver::{
    Around, Drive, Turn, WAY_POINT_ARRIVE, angle_of, circle_walk, face, go_to, outline_on_table,
};
use crate::exec::reposition::{BoundAll, Stand, Standing, reachable_reposition};
use crate::exec::stall::StallWatch;
use crate::planner::path_follow::PathFollower;
use crate::strategy::dipole::{self, DipoleCommand};
use crate::strategy::regression::PushStrategy;
use crate::strategy::sample::{Pose2, Sample, wrap_angle};

/// Why a delivery failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Failure {
    /// The object's marker left the boundary.
    ObjectLeftBoundary,
    /// The robot reached the table's edge.
    RobotLeftBoundary,
    /// Not delivered within the time limit.
    TimeLimit,
    /// The strategy had no answer (no samples).
    NoStrategy,
    /// Among obstacles: no global path for the object.
    NoPath,
    /// No progress towards the goal for the stall time, after every recovery was tried.
    Stalled,
    /// The camera lost the object (or the robot): not seen after the robot stopped, nor after
    /// it backed away ([`crate::exec::occlusion::BodyLost`]).
    MarkerLost,
}

/// A stall among obstacles and what was done about it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Recovery {
    /// When the stall was detected, s since the delivery started.
    pub t: f64,
    /// Where the object's marker was, table frame, m.
    pub at: [f64; 2],
    /// The sub-goal it was being pushed to.
    pub subgoal: [f64; 2],
    /// What was tried: "back off and re-plan", then with closer sub-goals.
    pub action: String,
}

/// How one delivery went.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Delivery {
    /// Whether the object reached the goal.
    pub success: bool,
    /// Why not, if not.
    pub failure: Option<Failure>,
    /// Time taken, s.
    pub time: f64,
    /// Pushes made (learned) or commands sent (dipole).
    pub steps: usize,
    /// Times the robot re-positioned itself (special case).
    pub repositions: usize,
    /// Stalls detected and the recoveries tried (among obstacles).
    pub recoveries: Vec<Recovery>,
    /// Path length of the object's marker, m.
    pub object_path: f64,
    /// Path length of the robot, m.
    pub robot_path: f64,
    /// Path length of the centre of the object's body (its outline's smallest enclosing
    /// circle), m: the point the shortest path below is for.
    pub body_path: f64,
    /// Length of the shortest collision-free path of the object's body (its smallest
    /// enclosing circle) from where its centre started to where it ended, m, when measured
    /// ([`crate::planner::global::shortest_object_path`]).
    pub shortest_path: Option<f64>,
    /// Final marker–goal distance, m.
    pub final_distance: f64,
    /// The global paths of the object's body planned, one per leg (among obstacles), table
    /// frame, m.
    pub paths: Vec<Vec<[f64; 2]>>,
    /// Robot and object poses after every step (Fig. 8).
    #[serde(skip)]
    pub trajectory: Vec<(Pose2, Pose2)>,
}

impl Delivery {
    /// A delivery that has not (yet) reached the goal: nothing pushed, nothing travelled.
    pub fn failed(failure: Option<Failure>, time: f64, final_distance: f64) -> Delivery {
        Delivery {
            success: false,
            failure,
            time,
            steps: 0,
            repositions: 0,
            recoveries: Vec::new(),
            object_path: 0.0,
            robot_path: 0.0,
            body_path: 0.0,
            shortest_path: None,
            final_distance,
            paths: Vec::new(),
            trajectory: Vec::new(),
        }
    }
}

/// Radius of the bound-all circle (Fig. 3): object bounding radius + robot radius + margin.
pub fn bound_all_radius(ws: &Workspace, margin: f64) -> f64 {
    ws.object_radius + ws.robot_radius + margin
}

/// The bound-all circle (Fig. 3) of the object whose marker is at `o`: about the marker
/// ([`bound_all_radius`]), or with `body` about the outline's smallest enclosing circle (its
/// radius + robot radius + margin).
pub(crate) fn bound_all_circle(ws: &Workspace, o: &Pose2, margin: f64, body: bool) -> BoundAll {
    if body {
        BoundAll {
            centre: ws.body_centre(o),
            radius: ws.body.radius + ws.robot_radius + margin,
        }
    } else {
        BoundAll {
            centre: o.position(),
            radius: bound_all_radius(ws, margin),
        }
    }
}

/// Camera noise dead-band of a measured track, m: a step is counted once the body is this far
/// from the last point counted. Between two looks at a still body the camera's noise (about
/// 1 mm) moves it by 1.8 mm on average, which over hundreds of looks would add metres to a path
/// of one; 5 mm is over three standard deviations of that.
pub const TRACK_DEADBAND: f64 = 0.005;

/// Length of the track of one body of `traj` (robot or object), measured through the camera:
/// the polyline through the points at least [`TRACK_DEADBAND`] apart, and its last point.
fn path_len(traj: &[(Pose2, Pose2)], pick: impl Fn(&(Pose2, Pose2)) -> Vector2<f64>) -> f64 {
    let mut points = traj.iter().map(pick);
    let Some(mut last) = points.next() else {
        return 0.0;
    };
    let mut len = 0.0;
    let mut end = last;
    for p in points {
        end = p;
        if (p - last).norm() >= TRACK_DEADBAND {
            len += (p - last).norm();
            last = p;
        }
    }
    len + (end - last).norm()
}

/// An inward pull on the wanted object motion near the boundary: for each edge of `boundary`
/// closer to the object than `boundary_guard` (and closer to it than to the goal, so a goal by
/// the edge is still reached), the edge's inward normal weighted by how far into the guard band
/// the object is (0 at its inner side, `boundary_pull` at the edge). Not in Lau et al., whose
/// delivery fails as soon as the object crosses the boundary: a strategy of a few hundred pushes
/// drifts sideways by a centimetre or two per push, and an object started beside the boundary
/// then leaves it while heading for the goal.
fn boundary_bias(
    boundary: &Rect,
    o: Vector2<f64>,
    goal: Vector2<f64>,
    p: &DeliveryParams,
) -> Vector2<f64> {
    if p.boundary_guard <= 0.0 {
        return Vector2::zeros();
    }
    let edges = [
        (
            o.x - boundary.min[0],
            goal.x - boundary.min[0],
            Vector2::x(),
        ),
        (
            boundary.max[0] - o.x,
            boundary.max[0] - goal.x,
            -Vector2::x(),
        ),
        (
            o.y - boundary.min[1],
            goal.y - boundary.min[1],
            Vector2::y(),
        ),
        (
            boundary.max[1] - o.y,
            boundary.max[1] - goal.y,
            -Vector2::y(),
        ),
    ];
    edges
        .iter()
        .filter(|(d, g, _)| *d < p.boundary_guard && *g > *d)
        .map(|(d, _, n)| n * p.boundary_pull * (1.0 - d.max(0.0) / p.boundary_guard))
        .sum()
}

/// Distance from `o` to the nearest edge of `boundary` (negative outside), m.
fn edge_distance(boundary: &Rect, o: Vector2<f64>) -> f64 {
    (o.x - boundary.min[0])
        .min(boundary.max[0] - o.x)
        .min(o.y - boundary.min[1])
        .min(boundary.max[1] - o.y)
}

/// The checks every delivery loop makes each step: success or one of the failures.
fn verdict(
    io: &mut dyn RobotIo,
    o: &Pose2,
    r: &Pose2,
    goal: Vector2<f64>,
    start: f64,
    p: &DeliveryParams,
) -> Option<Result<(), Failure>> {
    let ws = io.workspace();
    if (goal - o.position()).norm() < p.success_radius {
        return Some(Ok(()));
    }
    if !ws.boundary.contains(o.position()) {
        return Some(Err(Failure::ObjectLeftBoundary));
    }
    if !ws
        .table
        .inset(ws.robot_radius + 0.002)
        .contains(r.position())
    {
        return Some(Err(Failure::RobotLeftBoundary));
    }
    if io.time() - start > p.time_limit {
        return Some(Err(Failure::TimeLimit));
    }
    None
}

fn finish(
    io: &mut dyn RobotIo,
    start: f64,
    goal: Vector2<f64>,
    outcome: Result<(), Failure>,
    steps: usize,
    repositions: usize,
    trajectory: Vec<(Pose2, Pose2)>,
) -> Delivery {
    let o = io.object_pose();
    let ws = io.workspace();
    Delivery {
        success: outcome.is_ok(),
        failure: outcome.err(),
        time: io.time() - start,
        steps,
        repositions,
        recoveries: Vec::new(),
        object_path: path_len(&trajectory, |t| t.1.position()),
        robot_path: path_len(&trajectory, |t| t.0.position()),
        body_path: path_len(&trajectory, |t| ws.body_centre(&t.1)),
        shortest_path: None,
        final_distance: (goal - o.position()).norm(),
        paths: Vec::new(),
        trajectory,
    }
}

/// Deliver the object to `goal` with the pushing strategy (Algorithm 2). Every push with an
/// object motion of at least `moved_epsilon` is added to `strategy` at once and passed to
/// `sink` (to be stored).
pub fn deliver_learned(
    io: &mut dyn RobotIo,
    strategy: &mut PushStrategy,
    goal: Vector2<f64>,
    p: &DeliveryParams,
    sink: &mut dyn FnMut(&Sample) -> Result<()>,
) -> Result<Delivery> {
    deliver_learned_among(io, strategy, goal, p, &[], None, sink)
}

/// [`deliver_learned`] among `obstacles` (table-frame polygons): the special case stands the
/// robot only where it fits and walks the bound-all circle the way the obstacles leave open.
/// With a `path` (ending at `goal`, planned for the object's enclosing circle) the object is
/// wanted to move its circle's centre towards the path's moving sub-goal
/// ([`PathFollower::aim`]) rather than straight at the goal, the strategy is asked about that
/// centre's motion ([`PushStrategy::about`]), and a stall is measured on the way left along the
/// path. A special-case stand point whose push failed is not stood on again until a push goes
/// the wanted way (`Standing::failed`).
pub fn deliver_learned_among(
    io: &mut dyn RobotIo,
    strategy: &mut PushStrategy,
    goal: Vector2<f64>,
    p: &DeliveryParams,
    obstacles: &[Vec<[f64; 2]>],
    mut path: Option<&mut PathFollower>,
    sink: &mut dyn FnMut(&Sample) -> Result<()>,
) -> Result<Delivery> {
    let start = io.time();
    let ws = io.workspace();
    // The bound-all circle the special case walks: on a clear table the paper's, about the
    // marker (as the strategy was collected); among obstacles about the outline's smallest
    // enclosing circle, which for an object marked off its middle is up to a fifth smaller
    // (the L-shape: 15.2 cm against 17.7 cm) and leaves the walk room in a corridor.
    let circle_of = |o: &Pose2| bound_all_circle(&ws, o, p.bound_all_margin, !obstacles.is_empty());
    let mut traj = Vec::new();
    let (mut steps, mut repositions) = (0, 0);
    let mut special = {
        let (r, o) = (io.robot_pose(), io.object_pose());
        let c = circle_of(&o);
        (r.position() - c.centre).norm() > c.radius
    };
    let mut stall = StallWatch::new(p, start);
    let mut last_leg = false;
    // Along a path the wanted motion is the enclosing circle's centre's, so the strategy is
    // asked for the pushes that moved that point so: the samples keyed on it
    // ([`PushStrategy::about`]). In the last leg too, where the marker is wanted at the goal:
    // the pushes that moved the marker that way include those that did it by turning the
    // object about it (the L-shape's marker is in its corner), which swing the body about
    // near the goal; the body's keys ask for carrying it there. The marker's own keys serve
    // a clear table.
    let body = ws.body.centre;
    let mut about_body = (path.is_some() && body != [0.0, 0.0]).then(|| strategy.about(body));
    // On the last leg, the same samples with the special case's heavier turn weight
    // ([`DeliveryParams::last_leg_turn_weight`]).
    let mut last_keyed: Option<PushStrategy> = None;
    // Among obstacles, the special case's stand points (object frame) whose push failed since
    // the last push that went the wanted way: not tried again while another is reachable.
    let mut failed: Vec<[f64; 2]> = Vec::new();
    // The object's outline (its marker's frame; empty when not known): the special case
    // stands the robot clear of it and walks round it.
    let outline = io.object_outline();
    let goal_aim = last_leg_aim(&ws, obstacles, goal, p);
    loop {
        let (r, o) = (io.robot_pose(), io.object_pose());
        traj.push((r, o));
        if let Some(v) = verdict(io, &o, &r, goal, start, p) {
            return Ok(finish(io, start, goal, v, steps, repositions, traj));
        }
        let dist = (goal - o.position()).norm();
        // Along a path the object's enclosing circle follows it (the path is planned for that
        // circle, [`crate::exec::deliver_path`]) until the moving sub-goal is the goal itself;
        // from there the marker is pushed to the goal, and progress is watched afresh on it.
        let centre = ws.body_centre(&o);
        let (on_centre, aim, left) = match path.as_deref_mut() {
            Some(f) => {
                let a = f.aim(centre);
                if (a.subgoal - goal).norm() > 1e-9 {
                    // Over the path's last stretch its end blends into where the body is
                    // when the marker is at the goal ([`PathFollower::shifted`]).
                    (true, f.shifted(&a, centre - o.position()), a.left)
                } else {
                    if !last_leg {
                        last_leg = true;
                        stall = StallWatch::new(p, io.time());
                        last_keyed = last_leg_strategy(strategy, body, p);
                    }
                    (false, goal_aim, (goal_aim - o.position()).norm())
                }
            }
            None => (false, goal, dist),
        };
        if stall.stalled(left, io.time()) {
            let v = Err(Failure::Stalled);
            return Ok(finish(io, start, goal, v, steps, repositions, traj));
        }
        let to_aim = aim - if on_centre { centre } else { o.position() };
        let to_aim = to_aim.try_normalize(1e-9).unwrap_or_else(|| {
            (goal - o.position())
                .try_normalize(1e-9)
                .unwrap_or_else(Vector2::x)
        });
        let bias = boundary_bias(&ws.boundary, o.position(), goal, p);
        let want_world = to_aim + bias;
        let want = o.vector_to_local(want_world.normalize());
        let want = [want.x, want.y];
        tracing::debug!(
            "delivery step {steps}: object {:.3} m from the goal, {:.1} s, special {special}, \
             robot ({:.3}, {:.3}, {:.2}), object ({:.3}, {:.3}, {:.2})",
            dist,
            io.time() - start,
            r.x,
            r.y,
            r.theta,
            o.x,
            o.y,
            o.theta
        );
        let step = if dist > p.fine_radius {
            p.coarse_step
        } else {
            (0.8 * dist).clamp(0.006, p.fine_step)
        };
        // Within the guard band a push is no longer than 80 % of the way to the boundary: a
        // quasi-static push moves the object no further than the pusher, so one push cannot
        // carry it out before the next look.
        let edge = edge_distance(&ws.boundary, o.position());
        let step = if p.boundary_guard > 0.0 && edge < p.boundary_guard {
            step.min((0.8 * edge).max(0.006))
        } else {
            step
        };
        let keyed: &PushStrategy = last_keyed
            .as_ref()
            .or(about_body.as_ref())
            .unwrap_or(strategy);
        // On the last leg the general case pushes only from where the samples have pushed
        // the object the wanted way; from elsewhere the special case stands the robot there.
        let pl = o.point_to_local(r.position());
        if !special && last_leg && p.last_leg_trust > 0.0 {
            special = keyed
                .general_distance([pl.x, pl.y], want)
                .is_some_and(|d| d > p.last_leg_trust);
        }
        let mut stood = None;
        let dir_world = if special {
            let circle = circle_of(&o);
            let robot = Standing {
                from: r.position(),
                failed: &failed,
                outline: &outline,
            };
            let Some(Stand {
                rep,
                radius,
                reachable,
            }) = reachable_reposition(keyed, &ws, obstacles, &o, robot, want, &circle)
            else {
                return Ok(finish(
                    io,
                    start,
                    goal,
                    Err(Failure::NoStrategy),
                    steps,
                    repositions,
                    traj,
                ));
            };
            // Along a path, no stand point the robot can reach pushes the object the way the
            // path wants: that is a stall now, not after `stall_time` of pushing nothing (the
            // recovery backs off, plans again and pushes the object aside).
            if !reachable && path.is_some() {
                tracing::debug!("no reachable stand point for the path's way: a stall");
                let v = Err(Failure::Stalled);
                return Ok(finish(io, start, goal, v, steps, repositions, traj));
            }
            repositions += 1;
            stood = Some(rep.p);
            let at = o.point_to_world(Vector2::new(rep.p[0], rep.p[1]));
            let rel = at - circle.centre;
            // The walk ends where the robot comes in to the stand point from, which the
            // approach below reaches precisely: one leg is enough there.
            circle_walk(
                io,
                circle.centre,
                radius,
                circle.radius,
                angle_of(rel),
                &Drive::one_leg(WAY_POINT_ARRIVE),
                &Around {
                    obstacles,
                    object: &outline_on_table(&outline, &o),
                },
            )?;
            go_to(io, at, &Drive::two_level(p.heading_tolerance))?;
            o.vector_to_world(Vector2::new(rep.r[0], rep.r[1]))
        } else {
            let Some(rr) = keyed.general([pl.x, pl.y], want) else {
                return Ok(finish(
                    io,
                    start,
                    goal,
                    Err(Failure::NoStrategy),
                    steps,
                    repositions,
                    traj,
                ));
            };
            o.vector_to_world(Vector2::new(rr[0], rr[1]))
        };
        face(
            io,
            angle_of(dir_world),
            &Turn::two_level(p.heading_tolerance),
        )?;
        let (r0, o0) = (io.robot_pose(), io.object_pose());
        if stood.is_some() {
            tracing::debug!(
                "the re-positioning moved the object {:.4} m and turned it {:.3} rad",
                (o0.position() - o.position()).norm(),
                wrap_angle(o0.theta - o.theta)
            );
        }
        io.forward(step)?;
        steps += 1;
        let (r1, o1) = (io.robot_pose(), io.object_pose());
        let sample = Sample::from_push(r0, r1, o0, o1);
        let moved = o1.position() - o0.position();
        // Supplemental sample, used at once (kept only if informative when the strategy has an
        // admission rule: a collection's selective sampling).
        if moved.norm() >= p.moved_epsilon && strategy.offer(sample) {
            sink(&sample)?;
            if let Some(b) = last_keyed.as_mut() {
                b.add(sample.about(body));
            }
            if let Some(b) = about_body.as_mut() {
                b.add(sample.about(body));
            }
        }
        // Special case next when the push went astray ([`reposition_next`]).
        let push = Push {
            before: o0,
            after: o1,
            on_centre,
            wanted: to_aim,
            bias,
        };
        special = reposition_next(&ws, obstacles, p, &push);
        if !special {
            failed.clear();
        } else if let Some(at) = stood {
            failed.push(at);
        }
    }
}

/// Deliver the object to `goal` by following the dipole field (Igarashi et al.), the baseline.
pub fn deliver_dipole(
    io: &mut dyn RobotIo,
    goal: Vector2<f64>,
    p: &DeliveryParams,
) -> Result<Delivery> {
    let start = io.time();
    let mut traj = Vec::new();
    let mut steps = 0;
    loop {
        let (r, o) = (io.robot_pose(), io.object_pose());
        traj.push((r, o));
        if let Some(v) = verdict(io, &o, &r, goal, start, p) {
            return Ok(finish(io, start, goal, v, steps, 0, traj));
        }
        steps += 1;
        match dipole::command(o.position(), r.position(), r.theta, goal, &p.dipole) {
            Some(DipoleCommand::Spin { angle }) => io.spin(angle)?,
            Some(DipoleCommand::Drive { v, omega }) => io.drive(v, omega, p.dipole_step)?,
            // Robot on top of the object's marker: back off a little.
            None => io.forward(-0.02)?,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// A body that moves 1 m in 4 cm pushes, looked at 6 times between pushes (as the special
    /// case's re-positioning does), each look with 1 mm of camera noise: the raw polyline is
    /// far longer than the metre, the dead-banded track is within 2 % of it.
    #[test]
    fn the_track_length_is_not_inflated_by_camera_noise() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let noise = Normal::new(0.0, 0.001).unwrap();
        let mut traj = Vec::new();
        for k in 0..=25 {
            for _ in 0..6 {
                let o = Pose2::new(
                    0.04 * k as f64 + noise.sample(&mut rng),
                    0.5 + noise.sample(&mut rng),
                    0.0,
                );
                traj.push((o, o));
            }
        }
        let raw: f64 = traj
            .windows(2)
            .map(|w| (w[1].1.position() - w[0].1.position()).norm())
            .sum();
        let tracked = path_len(&traj, |t| t.1.position());
        assert!(raw > 1.15, "raw {raw}");
        assert!((tracked - 1.0).abs() < 0.02, "tracked {tracked}");
        // A still body watched 500 times: its noise alone would be most of a metre; tracked,
        // it is no more than a few dead-bands.
        let still: Vec<_> = (0..500)
            .map(|_| {
                let o = Pose2::new(noise.sample(&mut rng), noise.sample(&mut rng), 0.0);
                (o, o)
            })
            .collect();
        let raw_still: f64 = still
            .windows(2)
            .map(|w| (w[1].1.position() - w[0].1.position()).norm())
            .sum();
        let tracked_still = path_len(&still, |t| t.1.position());
        assert!(
            raw_still > 0.5 && tracked_still < 0.05,
            "{raw_still} {tracked_still}"
        );
        assert_eq!(path_len(&[], |t| t.1.position()), 0.0);
    }
}

//! Stable pushes on this project's robot (Lynch & Mason §4, executed as the paper intends: open
//! loop, no sensing during a push): the plan of [`crate::planner::stable::robot`]'s problem
//! (the plated differential-drive robot) driven as one `Velocity` arc per run of steps with
//! one control.
//!
//! Plans may change contact ([`robot_problem_edges`]): between two pushing runs the robot
//! drives the plan's transit path ([`crate::planner::stable::transit`], §4.6's open problem) — straight back off
//! the old edge, along the way points of the path for its turning disk, straight onto the new
//! edge. Transits are closed loop between primitives: each leg is aimed from the observed robot
//! pose, the way points (planned for the slider at the plan's configuration) are re-anchored to
//! the observed slider, and the robot lines up on the new edge's approach line, drives in by
//! the observed distance (its `forward` does not stop on contact: `SimRobot` sends `Move` with
//! `stop_on_contact: false`) and on by a short straight seating push ([`SEAT`]) that turns the
//! slider flush against the plate. The pushes stay open loop.

use anyhow::{Context, Result, anyhow, bail};

use crate::exec::io::RobotIo;
use crate::exec::maneuver::{Drive, Turn, face, go_to};
use crate::mechanics::{V2, cross};
use crate::planner::stable::robot::{SPEED, arcs, robot_in_slider};
#[cfg(doc)]
use crate::planner::stable::robot::{robot_problem_edges, robot_start};
use crate::planner::stable::transit::TransitPath;
use crate::planner::stable::{Plan, Pose, Problem, angle_diff};

/// One executed push: the slider's pose relative to the robot before and after, and how far
/// the slider moved.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PushRecord {
    /// Contact (index into the problem's contacts) pushed on.
    pub contact: usize,
    /// Distance the slider moved, m.
    pub pushed: f64,
    /// How far it moved on the plate, m.
    pub drift: f64,
    /// How far it turned on the plate, rad.
    pub drift_angle: f64,
}

/// Contact changes driven in an execution: pushes on another contact than the push before.
pub fn contact_changes(pushes: &[PushRecord]) -> usize {
    pushes
        .windows(2)
        .filter(|w| w[0].contact != w[1].contact)
        .count()
}

/// The slider pose in the robot frame.
fn relative(robot: Pose, slider: Pose) -> Pose {
    let (s, c) = robot.theta.sin_cos();
    let (dx, dy) = (slider.x - robot.x, slider.y - robot.y);
    Pose::new(
        c * dx + s * dy,
        -s * dx + c * dy,
        slider.theta - robot.theta,
    )
}

/// The observed poses of the robot (axle centre, heading) and the slider.
pub(crate) fn observe(io: &mut dyn RobotIo) -> Result<(Pose, Pose)> {
    let rp = io.robot_pose();
    let sp = io
        .body_pose("slider")
        .ok_or_else(|| anyhow!("the slider is not seen"))?;
    let (r, s) = (
        Pose::new(rp.x, rp.y, rp.theta),
        Pose::new(sp.x, sp.y, sp.theta),
    );
    if ![r.x, r.y, r.theta, s.x, s.y, s.theta]
        .iter()
        .all(|v| v.is_finite())
    {
        bail!("the camera saw no finite pose (robot {r:?}, slider {s:?})");
    }
    Ok((r, s))
}

/// Drive the plan open loop on `io` (the slider is the object `slider`): its pushing arcs, and
/// at each contact change the plan's transit path ([`drive_transit`]). The robot starts flush
/// on the first contact ([`robot_start`]). Observes only between primitives: to report drift
/// and to drive transits. Returns each push and the slider's final pose.
pub fn execute(p: &Problem, plan: &Plan, io: &mut dyn RobotIo) -> Result<(Vec<PushRecord>, Pose)> {
    let mut pushes = Vec::new();
    let mut transits = plan.transits.iter();
    let mut contact = None;
    for (i, arc) in arcs(p, plan).into_iter().enumerate() {
        if let Some(from) = contact
            && from != arc.contact
        {
            let to = arc.contact;
            let tr = transits.next().ok_or_else(|| {
                anyhow!("push {i}: the plan changes contact {from} → {to} without a transit path")
            })?;
            if (tr.from_contact, tr.to_contact) != (from, to) {
                bail!(
                    "push {i}: the plan changes contact {from} → {to} but its next transit path \
                     leads {} → {}",
                    tr.from_contact,
                    tr.to_contact
                );
            }
            drive_transit(p, tr, io)
                .with_context(|| format!("push {i}: transit from contact {from} to {to}"))?;
        }
        contact = Some(arc.contact);
        let (d, phi) = (arc.distance, arc.turn);
        let (r0, s0) = observe(io)?;
        let dur = (d.abs() / SPEED).max(phi.abs() / 0.5).max(0.05);
        io.drive(d / dur, phi / dur, dur)
            .with_context(|| format!("push {i}"))?;
        let (r1, s1) = observe(io)?;
        let (q0, q1) = (relative(r0, s0), relative(r1, s1));
        pushes.push(PushRecord {
            contact: arc.contact,
            pushed: (s1.x - s0.x).hypot(s1.y - s0.y),
            drift: (q1.x - q0.x).hypot(q1.y - q0.y),
            drift_angle: angle_diff(q1.theta, q0.theta).abs(),
        });
    }
    let (_, end) = observe(io)?;
    Ok((pushes, end))
}

/// A way point stop closer than this counts as reached, m.
const WAYPOINT_TOL: f64 = 0.004;
/// Largest sideways offset from the new edge's approach line before the plate goes in, m.
const LINE_TOL: f64 = 0.001;
/// Largest heading error before the plate goes in, rad (0.5°; `spin` ends within about that).
const HEADING_TOL: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// The straight approach stops this far before the edge, m, for a last heading correction.
const CREEP_GAP: f64 = 0.005;
/// Speed of the last approach and the seating push, m/s: the pushing speed.
const CREEP_SPEED: f64 = SPEED;
/// How far the approach pushes straight on past the observed edge, m: the seating push. The
/// robot's heading is only as good as its `spin` (about 0.5°; short `Velocity` turns do not
/// overcome the motors' friction), so the plate first meets the edge at a corner; a straight
/// push with the plate's line contact turns the slider flush against it (in the sim 10 mm
/// leave it flush to 0.03 mm and 0.001°, 3 mm do not), moving it this far along the edge's
/// normal.
pub const SEAT: f64 = 0.01;
/// The plate counts as on the edge when the observed gap is at most this, m.
const FLUSH_TOL: f64 = 0.0003;
/// Tries of each closed-loop correction.
const TRIES: usize = 4;

/// World point `w` in the frame of the slider at `q`.
fn to_slider(q: &Pose, w: V2) -> V2 {
    let (s, c) = q.theta.sin_cos();
    let d = w - V2::new(q.x, q.y);
    V2::new(c * d.x + s * d.y, -s * d.x + c * d.y)
}

/// Where the axle centre is (world) and which way the robot faces when its plate is flush on
/// contact `ci` of the slider at `s`.
pub(crate) fn flush_pose(p: &Problem, ci: usize, s: &Pose) -> (V2, V2) {
    let (axle, heading) = robot_in_slider(p, ci);
    (s.apply(axle), s.rotate(heading))
}

/// Turn the robot to face the world direction `h`: spins, measured between, until within
/// `HEADING_TOL` (or out of tries).
fn face_dir(io: &mut dyn RobotIo, h: V2) -> Result<()> {
    face(io, h.y.atan2(h.x), &Turn::until(HEADING_TOL, TRIES))
}

/// Drive the axle centre to `w` (world): turn to face it, drive straight; again from the
/// observed pose while farther than `tol`.
fn go_to_within(io: &mut dyn RobotIo, w: V2, tol: f64) -> Result<()> {
    go_to(io, w, &Drive::legs(tol, TRIES))
}

/// Drive the transit path `tr` from its first contact to its second, the slider staying
/// where it is: straight back off the old edge by the planned leg, to each way point of the
/// turning disk's path (re-anchored to the observed slider), then onto the new edge
/// ([`approach`]). Every leg is aimed from the observed poses.
pub fn drive_transit(p: &Problem, tr: &TransitPath, io: &mut dyn RobotIo) -> Result<()> {
    if tr.to_contact >= p.contacts.len() || tr.from_contact >= p.contacts.len() {
        bail!(
            "transit {} → {}: the problem has {} contacts",
            tr.from_contact,
            tr.to_contact,
            p.contacts.len()
        );
    }
    if tr.waypoints.len() < 4 {
        bail!(
            "transit {} → {}: {} way points, not a mobile robot's path (contact, stand-off, …, \
             stand-off, contact)",
            tr.from_contact,
            tr.to_contact,
            tr.waypoints.len()
        );
    }
    let (_, s) = observe(io)?;
    // The way points are planned for the slider at `tr.at`: the same points relative to it.
    let pts: Vec<V2> = tr
        .waypoints
        .iter()
        .map(|w| s.apply(to_slider(&tr.at, V2::new(w[0], w[1]))))
        .collect();
    let n = pts.len();
    io.forward(-(pts[1] - pts[0]).norm())
        .context("backing off the edge")?;
    for (k, w) in pts[2..n - 1].iter().enumerate() {
        go_to_within(io, *w, WAYPOINT_TOL).with_context(|| format!("to way point {}", k + 2))?;
    }
    approach(p, tr.to_contact, io).context("onto the new edge")
}

/// From a stand-off in front of contact `ci`'s edge, bring the plate flush onto it: onto the
/// approach line (the axle's path straight in along the edge's normal) within `LINE_TOL`,
/// facing the edge within `HEADING_TOL`, straight in to `CREEP_GAP` before the edge, face
/// it again, and on at the pushing speed by the observed gap plus [`SEAT`], a short straight
/// push that leaves the slider flush on the plate.
pub fn approach(p: &Problem, ci: usize, io: &mut dyn RobotIo) -> Result<()> {
    if ci >= p.contacts.len() {
        bail!(
            "contact {ci}: the problem has {} contacts",
            p.contacts.len()
        );
    }
    // Where the axle should be and the remaining distance to it along the heading.
    let target = |io: &mut dyn RobotIo| -> Result<(Pose, V2, V2)> {
        let (r, s) = observe(io)?;
        let (c, h) = flush_pose(p, ci, &s);
        Ok((r, c, h))
    };
    for _ in 0..TRIES {
        let (r, c, h) = target(io)?;
        let rel = V2::new(r.x, r.y) - c;
        if cross(h, rel).abs() <= LINE_TOL {
            break;
        }
        go_to_within(io, c + h * rel.dot(&h), LINE_TOL / 2.0)?;
    }
    let (_, _, h) = target(io)?;
    face_dir(io, h)?;
    let (r, c, h) = target(io)?;
    let gap = (c - V2::new(r.x, r.y)).dot(&h);
    if gap > CREEP_GAP {
        io.forward(gap - CREEP_GAP)?;
    }
    let (_, _, h) = target(io)?;
    face_dir(io, h)?;
    let (r, c, h) = target(io)?;
    let gap = (c - V2::new(r.x, r.y)).dot(&h);
    io.drive(CREEP_SPEED, 0.0, (gap.max(0.0) + SEAT) / CREEP_SPEED)?;
    for _ in 0..TRIES {
        let (r, c, h) = target(io)?;
        let gap = (c - V2::new(r.x, r.y)).dot(&h);
        if gap <= FLUSH_TOL {
            break;
        }
        io.drive(CREEP_SPEED, 0.0, (gap + FLUSH_TOL) / CREEP_SPEED)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::io::{Rect, Workspace};
    use crate::planner::stable::robot::{robot_problem, robot_problem_edges};
    use crate::planner::stable::search::Step;
    use crate::planner::stable::transit::{point_segment_distance, transit};
    use crate::strategy::sample::Pose2;

    /// A kinematic robot: its primitives move it exactly, or with the given errors (spins
    /// scaled by `spin_gain`, straight moves by `move_gain`, veering `veer` rad per m); the
    /// slider never moves. Records the smallest clearance between the slider and the disk the
    /// robot sweeps while spinning.
    struct Mock {
        r: Pose,
        s: Pose,
        slider: Vec<V2>,
        disk: f64,
        spin_gain: f64,
        move_gain: f64,
        veer: f64,
        spin_clearance: f64,
    }

    impl Mock {
        fn clearance(&self) -> f64 {
            let c = V2::new(self.r.x, self.r.y);
            let w: Vec<V2> = self.slider.iter().map(|v| self.s.apply(*v)).collect();
            (0..w.len())
                .map(|i| point_segment_distance(c, w[i], w[(i + 1) % w.len()]))
                .fold(f64::INFINITY, f64::min)
                - self.disk
        }
    }

    impl RobotIo for Mock {
        fn spin(&mut self, angle: f64) -> Result<()> {
            self.spin_clearance = self.spin_clearance.min(self.clearance());
            self.r.theta += angle * self.spin_gain;
            Ok(())
        }
        fn forward(&mut self, distance: f64) -> Result<()> {
            let d = distance * self.move_gain;
            self.r.x += d * self.r.theta.cos();
            self.r.y += d * self.r.theta.sin();
            self.r.theta += self.veer * d.abs();
            Ok(())
        }
        fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()> {
            let (t0, t1) = (self.r.theta, self.r.theta + omega * duration);
            if omega.abs() < 1e-12 {
                self.r.x += v * duration * t0.cos();
                self.r.y += v * duration * t0.sin();
            } else {
                self.r.x += v / omega * (t1.sin() - t0.sin());
                self.r.y -= v / omega * (t1.cos() - t0.cos());
            }
            self.r.theta = t1;
            Ok(())
        }
        fn robot_pose(&mut self) -> Pose2 {
            Pose2::new(self.r.x, self.r.y, self.r.theta)
        }
        fn object_pose(&mut self) -> Pose2 {
            Pose2::new(self.s.x, self.s.y, self.s.theta)
        }
        fn body_pose(&mut self, id: &str) -> Option<Pose2> {
            (id == "slider").then(|| self.object_pose())
        }
        fn time(&self) -> f64 {
            0.0
        }
        fn workspace(&self) -> Workspace {
            let table = Rect {
                min: [0.0, 0.0],
                max: [1.2, 0.8],
            };
            Workspace {
                table,
                boundary: table,
                robot_radius: 0.04,
                object_radius: 0.12,
                body: pushbot_world::enclosing_circle::Circle::at_origin(0.12),
            }
        }
    }

    fn two_edges() -> Problem {
        robot_problem_edges("fig13", None, &[0, 3], Some(10))
            .unwrap()
            .1
    }

    /// The mock robot flush on contact `ci` of the slider at `q`.
    fn mock_on(p: &Problem, q: Pose, ci: usize, errors: (f64, f64, f64)) -> Mock {
        let (c, h) = flush_pose(p, ci, &q);
        Mock {
            r: Pose::new(c.x, c.y, h.y.atan2(h.x)),
            s: q,
            slider: p.slider.vertices.clone(),
            disk: p.pusher.turning_radius_disk(),
            spin_gain: errors.0,
            move_gain: errors.1,
            veer: errors.2,
            spin_clearance: f64::INFINITY,
        }
    }

    /// Where the robot ended relative to flush on contact `ci`: sideways offset, gap (m) and
    /// heading error (rad).
    fn off_flush(p: &Problem, m: &Mock, ci: usize) -> (f64, f64, f64) {
        let (c, h) = flush_pose(p, ci, &m.s);
        let rel = V2::new(m.r.x, m.r.y) - c;
        (
            cross(h, rel),
            -rel.dot(&h),
            super::angle_diff(m.r.theta, h.y.atan2(h.x)),
        )
    }

    #[test]
    fn robot_problem_edges_builds_two_contacts_and_rejects_bad_input() {
        let p = two_edges();
        assert_eq!(p.contacts.len(), 2);
        assert_eq!(p.params.c, Some(10));
        assert!(p.pusher.is_mobile());
        let (_, one) = robot_problem("fig13", None).unwrap();
        assert_eq!(one.contacts.len(), 1);
        assert_eq!(one.params.c, None);
        assert!(robot_problem_edges("fig13", None, &[], None).is_err());
        assert!(robot_problem_edges("fig13", None, &[0, 17], None).is_err());
        assert!(robot_problem_edges("fig13", Some(f64::NAN), &[0], None).is_err());
        assert!(robot_problem_edges("no-such-preset", None, &[0], None).is_err());
    }

    #[test]
    fn arcs_split_at_a_contact_change() {
        let p = two_edges();
        let step = |contact: usize, control: usize| {
            let xi = p.contacts[contact].steps[control];
            Step {
                contact,
                edge: p.contacts[contact].edge,
                control,
                from: p.start,
                to: p.start.integrate(&xi),
                twist: [xi.x, xi.y, xi.z],
            }
        };
        let plan = Plan {
            found: true,
            cost: 0,
            pushes: 3,
            control_changes: 1,
            contact_changes: 1,
            nodes_expanded: 0,
            plan_time_ms: 0.0,
            steps: vec![step(0, 0), step(0, 0), step(1, 0)],
            transits: vec![],
            exact_goal: false,
            search: Default::default(),
        };
        let a = arcs(&p, &plan);
        assert_eq!(a.len(), 2, "{a:?}");
        assert_eq!((a[0].contact, a[1].contact), (0, 1));
        // Each arc in its own contact's robot frame: pushing forward.
        assert!(a[0].distance > 0.0 && a[1].distance > 0.0, "{a:?}");
        // A plan that changes contact without its transit path is refused, not driven.
        let mut m = mock_on(&p, p.start, 0, (1.0, 1.0, 0.0));
        let err = execute(&p, &plan, &mut m).unwrap_err();
        assert!(
            format!("{err:#}").contains("without a transit path"),
            "{err:#}"
        );
    }

    #[test]
    fn a_transit_ends_with_the_plate_flush_on_the_new_edge() {
        let p = two_edges();
        // In the open on fig13's table.
        let q = Pose::new(0.6, 1.0, 0.0);
        let tr = transit(&p, &q, 0, 1, 0).expect("a transit path");
        // Exact primitives; primitives with errors (spins 3 % long, moves 2 % short, veering
        // 1°/m); and the slider seen 4 mm and 1.5° away from where the transit was planned.
        let moved = Pose::new(q.x + 0.004, q.y - 0.003, q.theta + 1.5f64.to_radians());
        for (errors, seen) in [
            ((1.0, 1.0, 0.0), q),
            ((1.03, 0.98, 1f64.to_radians()), q),
            ((0.97, 1.02, -1f64.to_radians()), moved),
        ] {
            let mut m = mock_on(&p, seen, 0, errors);
            drive_transit(&p, &tr, &mut m).unwrap();
            let (side, gap, dth) = off_flush(&p, &m, 1);
            assert!(
                side.abs() <= LINE_TOL + 1e-4
                    && (-SEAT - 1e-4..=FLUSH_TOL).contains(&gap)
                    && dth.abs() <= HEADING_TOL + 1e-3,
                "errors {errors:?}: {:.2} mm sideways, gap {:.2} mm, {:.3}°",
                side * 1e3,
                gap * 1e3,
                dth.to_degrees()
            );
            assert!(
                m.spin_clearance > -0.003,
                "errors {errors:?}: the turning disk came {:.1} mm into the slider",
                -m.spin_clearance * 1e3
            );
        }
    }

    #[test]
    fn a_transit_that_is_not_a_mobile_robots_path_is_an_error() {
        let p = two_edges();
        let mut m = mock_on(&p, p.start, 0, (1.0, 1.0, 0.0));
        let tr = TransitPath {
            from_contact: 0,
            to_contact: 1,
            at: p.start,
            waypoints: vec![],
            length: 0.0,
        };
        assert!(drive_transit(&p, &tr, &mut m).is_err());
        let tr = TransitPath {
            to_contact: 5,
            ..tr
        };
        assert!(drive_transit(&p, &tr, &mut m).is_err());
        assert!(approach(&p, 7, &mut m).is_err());
    }
}

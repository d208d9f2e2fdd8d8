//! The maneuvers every executor drives, written once: turn to a heading ([`face`]), drive the
//! robot's centre to a point ([`go_to`]; around obstacles, [`transit`]), and walk around an
//! object on a circle ([`circle_walk`],
//! Lau, Mitani & Igarashi Fig. 3). Each measures with the camera ([`RobotIo::robot_pose`]) and
//! acts with primitives (spin, forward); how often it measures and corrects is the caller's
//! [`Turn`] and [`Drive`]: the paper's two-level motion (§IV: a coarse spin corrected once at a
//! finer level), a single open-loop turn, or turns repeated until within a tolerance.

use anyhow::Result;
use nalgebra::Vector2;

use crate::exec::io::{RobotIo, Workspace};
use crate::planner::global::{clearance, plan_robot_path, robot_fits, segment_clear};
use crate::strategy::sample::{Pose2, wrap_angle};

/// How to turn to a heading: up to `tries` spins, each from a fresh measurement, stopping once
/// within `tol` (rad); with `first_always` the first spin is made however small the error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turn {
    /// Heading tolerance, rad.
    pub tol: f64,
    /// Most spins.
    pub tries: usize,
    /// Spin once before looking at the tolerance.
    pub first_always: bool,
}

impl Turn {
    /// One spin by the measured error, no correction.
    pub const ONCE: Turn = Turn {
        tol: 0.0,
        tries: 1,
        first_always: true,
    };

    /// The paper's two levels (§IV): a spin, then one finer spin if still off by more than `tol`.
    pub fn two_level(tol: f64) -> Turn {
        Turn {
            tol,
            tries: 2,
            first_always: true,
        }
    }

    /// Spins until within `tol`, at most `tries`.
    pub fn until(tol: f64, tries: usize) -> Turn {
        Turn {
            tol,
            tries,
            first_always: false,
        }
    }
}

/// How to drive to a point: up to `tries` legs (turn, then straight), each from a fresh
/// measurement, stopping once within `arrive` (m). With `fresh_turn` the turn measures the
/// heading again (otherwise it turns from the leg's measurement); with `remeasure` the leg's
/// length is measured again after the turn (spinning in place shifts the centre a little).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// Arrival tolerance, m.
    pub arrive: f64,
    /// Most legs.
    pub tries: usize,
    /// How each leg turns.
    pub turn: Turn,
    /// The turn measures the heading again.
    pub fresh_turn: bool,
    /// Measure the leg's length again after the turn.
    pub remeasure: bool,
}

impl Drive {
    /// The paper's two-level motion (§IV): two legs, each turning with [`Turn::two_level`];
    /// arrived within 5 mm.
    pub fn two_level(tol: f64) -> Drive {
        Drive {
            arrive: 0.005,
            tries: 2,
            turn: Turn::two_level(tol),
            fresh_turn: true,
            remeasure: false,
        }
    }

    /// One leg: one turn from a fresh measurement, the length measured again after it; already
    /// there within `arrive`.
    pub fn one_leg(arrive: f64) -> Drive {
        Drive {
            arrive,
            tries: 1,
            turn: Turn::ONCE,
            fresh_turn: true,
            remeasure: true,
        }
    }

    /// Legs until within `arrive` (at most `tries`), each a single spin from the leg's own
    /// measurement and a straight drive of the measured distance.
    pub fn legs(arrive: f64, tries: usize) -> Drive {
        Drive {
            arrive,
            tries,
            turn: Turn::ONCE,
            fresh_turn: false,
            remeasure: false,
        }
    }
}

/// The angle of a vector, rad.
pub fn angle_of(v: Vector2<f64>) -> f64 {
    v.y.atan2(v.x)
}

/// Turn to `heading` (rad, table frame) as `turn` says, measuring the robot's pose first.
pub fn face(io: &mut dyn RobotIo, heading: f64, turn: &Turn) -> Result<()> {
    let pose = io.robot_pose();
    face_from(io, heading, turn, pose)
}

/// [`face`] from an already measured `pose` (the first spin uses it; later ones measure).
fn face_from(io: &mut dyn RobotIo, heading: f64, turn: &Turn, mut pose: Pose2) -> Result<()> {
    for i in 0..turn.tries {
        if i > 0 {
            pose = io.robot_pose();
        }
        let e = wrap_angle(heading - pose.theta);
        if !(i == 0 && turn.first_always) && e.abs() <= turn.tol {
            break;
        }
        io.spin(e)?;
    }
    Ok(())
}

/// Drive the robot's centre to `target` (table frame) as `drive` says.
pub fn go_to(io: &mut dyn RobotIo, target: Vector2<f64>, drive: &Drive) -> Result<()> {
    for _ in 0..drive.tries {
        let r = io.robot_pose();
        let d = target - r.position();
        if d.norm() <= drive.arrive {
            break;
        }
        if drive.fresh_turn {
            face(io, angle_of(d), &drive.turn)?;
        } else {
            face_from(io, angle_of(d), &drive.turn, r)?;
        }
        let length = if drive.remeasure {
            (target - io.robot_pose().position()).norm()
        } else {
            d.norm()
        };
        io.forward(length)?;
    }
    Ok(())
}

/// Drive the robot's centre to `target` around `obstacles`: straight when the way is clear,
/// else along a path planned around them ([`plan_robot_path`]); straight when there is none.
pub fn transit(
    io: &mut dyn RobotIo,
    target: Vector2<f64>,
    obstacles: &[Vec<[f64; 2]>],
    drive: &Drive,
) -> Result<()> {
    let ws = io.workspace();
    let here = io.robot_pose().position();
    if obstacles.is_empty() || segment_clear(&ws, obstacles, here, target) {
        return go_to(io, target, drive);
    }
    match plan_robot_path(&ws, obstacles, here, target) {
        Some(path) => {
            tracing::debug!(
                "transit around obstacles: {} way points to ({:.3}, {:.3})",
                path.len() - 1,
                target.x,
                target.y
            );
            for p in &path[1..] {
                go_to(io, *p, drive)?;
            }
            Ok(())
        }
        None => go_to(io, target, drive),
    }
}

/// Move the robot around the circle of radius `radius` about `centre` (Fig. 3 a–c): first to
/// the circle's closest point, then along it in chords of at most 30° to the point at angle
/// `to`, going the way that keeps the robot on the table and off the `obstacles` (points the
/// robot cannot reach are pulled back onto the table). The walk's end is driven to as `end`
/// says; the points on the way, which need no precision (each chord starts from a fresh
/// measurement), with one leg each ([`Drive::one_leg`], within [`WAY_POINT_ARRIVE`]).
/// Where a wall made the end come in closer than the bound-all circle (`radius` < `outer`),
/// the points on the way stay as far out as `outer` where the robot fits there: a walk at the
/// closer radius would sweep through the object. A robot inside the circle backs straight
/// out onto it; where a wall is in that way (it pushed the object along the wall, or from an
/// L's inner corner facing one) it backs along its last push instead and drives a path round
/// the obstacles and the object ([`around_object`], `keep_clear`) to the end.
pub fn circle_walk(
    io: &mut dyn RobotIo,
    centre: Vector2<f64>,
    radius: f64,
    outer: f64,
    to: f64,
    end: &Drive,
    keep_clear: &Around,
) -> Result<()> {
    let obstacles = keep_clear.obstacles;
    let ws = io.workspace();
    let reach = ws.reachable();
    let clamp = |p: Vector2<f64>| {
        Vector2::new(
            p.x.clamp(reach.min[0], reach.max[0]),
            p.y.clamp(reach.min[1], reach.max[1]),
        )
    };
    let at = |a: f64, r: f64| centre + r * Vector2::new(a.cos(), a.sin());
    let on = |a: f64| at(a, radius);
    // As far out as `outer` where the robot fits, in 1 cm steps; else on the circle.
    let wide = |a: f64| {
        let steps = ((outer - radius) / 0.01).ceil().max(0.0) as usize;
        (0..=steps)
            .map(|k| at(a, (outer - 0.01 * k as f64).max(radius)))
            .find(|p| robot_fits(&ws, obstacles, *p))
            .unwrap_or_else(|| on(a))
    };
    let r = io.robot_pose();
    let rel = r.position() - centre;
    let from = if rel.norm() > 1e-9 {
        angle_of(rel)
    } else {
        r.theta + std::f64::consts::PI
    };
    let inside = rel.norm() < radius;
    // An obstacle cuts the circle both ways (a corridor, a wall's end) or stands where the
    // robot would join it: the stand point is reached by a path around the obstacles and the
    // object instead.
    let cut = !obstacles.is_empty() && circle_cut(&ws, obstacles, &on, from, to, inside);
    let way = Drive::one_leg(WAY_POINT_ARRIVE);
    if inside {
        let out = clamp(wide(from));
        // The way straight out, past the first centimetre (a robot that pushed the object
        // along a wall touches the wall).
        let way_out = (out - r.position()).norm();
        let n = (way_out / 0.005).ceil() as usize;
        let free = obstacles.is_empty()
            || (2..=n).all(|k| {
                let t = r.position() + (out - r.position()) * (k as f64 / n as f64);
                robot_fits(&ws, obstacles, t)
            });
        if free {
            // Back straight away from the centre onto the circle.
            face(io, angle_of(-rel), &end.turn)?;
            let back = out - io.robot_pose().position();
            io.forward(-back.norm())?;
        } else {
            // A wall is in the way out: back along the push just made, the way the robot came
            // (the object went ahead of it, nothing else was there), to leave the object's
            // touch before a path round it is driven.
            let behind = r.position() - RETREAT * Vector2::new(r.theta.cos(), r.theta.sin());
            if reach.contains(behind) {
                io.forward(-RETREAT)?;
            }
        }
    }
    let here = if inside {
        io.robot_pose().position()
    } else {
        r.position()
    };
    let around = around_object(&ws, keep_clear, centre, radius, here);
    // A robot a wall kept from backing out onto the circle (it pushed the object along the
    // wall) cannot walk the circle's chords from there: they pass through the object.
    let stuck = inside && (here - centre).norm() < radius - WAY_POINT_ARRIVE;
    if cut || stuck {
        return transit(io, on(to), &around, end);
    }
    if !inside {
        // From afar, around the obstacles and the object itself.
        transit(io, clamp(wide(from)), &around, &way)?;
    }
    let (a, b) = circle_routes(from, to);
    let blocked = |pts: &[f64]| {
        pts.iter()
            .filter(|a| !robot_fits(&ws, obstacles, on(**a)))
            .count()
    };
    let pts = if blocked(&a) <= blocked(&b) { a } else { b };
    let last = pts.len().saturating_sub(1);
    for (k, ang) in pts.into_iter().enumerate() {
        if k == last {
            go_to(io, clamp(on(ang)), end)?;
        } else {
            go_to(io, clamp(wide(ang)), &way)?;
        }
    }
    Ok(())
}

/// How far a robot inside the circle with a wall in its way out backs along its last push
/// before a path round the object is planned, m.
const RETREAT: f64 = 0.025;

/// How near a walk's way points the robot must come, m.
pub const WAY_POINT_ARRIVE: f64 = 0.01;

/// What a walk round the object keeps clear of.
#[derive(Debug, Clone, Copy, Default)]
pub struct Around<'a> {
    /// The obstacles, table-frame polygons.
    pub obstacles: &'a [Vec<[f64; 2]>],
    /// The object's outline in the table frame ([`outline_on_table`]); empty when not known.
    pub object: &'a [[f64; 2]],
}

/// `outline` (the object's frame, [`RobotIo::object_outline`]) placed on the table by the
/// object's pose `o`.
pub fn outline_on_table(outline: &[[f64; 2]], o: &Pose2) -> Vec<[f64; 2]> {
    outline
        .iter()
        .map(|v| {
            let w = o.point_to_world(Vector2::new(v[0], v[1]));
            [w.x, w.y]
        })
        .collect()
}

/// The obstacles of `keep_clear` and, when there are any, the object inside the bound-all
/// circle of `radius` about `centre` as one more: what a path from the robot at `from` to a
/// stand point on the circle must go round. The object is a 12-gon the robot on the circle
/// clears, or — when the robot at `from` is too close to that 12-gon to plan from (it pushed
/// from inside the circle, in an L's inner corner) and the outline is known — the outline
/// itself, so that the way out of the corner goes round the object's arms rather than
/// through them.
pub fn around_object(
    ws: &Workspace,
    keep_clear: &Around,
    centre: Vector2<f64>,
    radius: f64,
    from: Vector2<f64>,
) -> Vec<Vec<[f64; 2]>> {
    let mut around = keep_clear.obstacles.to_vec();
    let inner = radius - ws.robot_radius - 0.015;
    if inner > 0.0 && !keep_clear.obstacles.is_empty() {
        let gon: Vec<[f64; 2]> = (0..12)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 12.0;
                let p = centre + inner * Vector2::new(a.cos(), a.sin());
                [p.x, p.y]
            })
            .collect();
        let trapped = clearance(from, std::slice::from_ref(&gon)) < ws.robot_radius + TRAPPED;
        around.push(if trapped && keep_clear.object.len() >= 3 {
            keep_clear.object.to_vec()
        } else {
            gon
        });
    }
    around
}

/// The robot is too close to the object's 12-gon to plan a path from where it is when its
/// bumper is nearer to it than this, m (the robot path planner's margin and half a cell).
const TRAPPED: f64 = 0.025;

/// The two ways along the circle from angle `from` to `to`, as the angles of chords of at most
/// 30°, the short way first.
fn circle_routes(from: f64, to: f64) -> (Vec<f64>, Vec<f64>) {
    let delta = wrap_angle(to - from);
    let other = if delta >= 0.0 {
        delta - std::f64::consts::TAU
    } else {
        delta + std::f64::consts::TAU
    };
    let route = |d: f64| -> Vec<f64> {
        let n = (d.abs() / 30f64.to_radians()).ceil().max(1.0) as usize;
        (1..=n).map(|i| from + d * i as f64 / n as f64).collect()
    };
    (route(delta), route(other))
}

/// Whether the walk round the circle (`on`) from angle `from` to `to` is cut: the stand point
/// is clear but every way along the circle to it (each chord end checked), or the point where
/// a robot from outside (`inside` false) joins it, is not.
fn circle_cut(
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    on: &dyn Fn(f64) -> Vector2<f64>,
    from: f64,
    to: f64,
    inside: bool,
) -> bool {
    if !robot_fits(ws, obstacles, on(to)) {
        return false;
    }
    let clear = |pts: &[f64]| pts.iter().all(|a| robot_fits(ws, obstacles, on(*a)));
    let (a, b) = circle_routes(from, to);
    let joins = inside || robot_fits(ws, obstacles, on(from));
    !joins || !(clear(&a) || clear(&b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::io::Rect;

    fn ws() -> Workspace {
        Workspace {
            table: Rect {
                min: [-0.25, -0.25],
                max: [1.85, 1.45],
            },
            boundary: Rect {
                min: [0.1, 0.1],
                max: [1.5, 1.1],
            },
            robot_radius: 0.04,
            object_radius: 0.075,
            body: pushbot_world::enclosing_circle::Circle::at_origin(0.075),
        }
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    }

    /// In a 0.3 m corridor the bound-all circle (radius 0.155 m) runs into both walls: from
    /// above the object to below it neither way round is open, and a robot from outside cannot
    /// join the circle inside a wall. On the open table nothing is cut, and a stand point in a
    /// wall is not for the circle walk to decide.
    #[test]
    fn a_corridor_cuts_the_circle_both_ways() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let ws = ws();
        let walls = vec![rect(0.6, 0.0, 0.7, 1.2), rect(1.0, 0.0, 1.1, 1.2)];
        let c = Vector2::new(0.85, 0.5);
        let on = |a: f64| c + 0.155 * Vector2::new(a.cos(), a.sin());
        assert!(circle_cut(&ws, &walls, &on, FRAC_PI_2, -FRAC_PI_2, true));
        // Joining from outside at the left, inside the wall.
        assert!(circle_cut(&ws, &walls, &on, PI, FRAC_PI_2, false));
        // Above to a little to its right: the short way is open.
        assert!(!circle_cut(&ws, &walls, &on, FRAC_PI_2, 1.2, true));
        // The open table.
        assert!(!circle_cut(&ws, &[], &on, FRAC_PI_2, -FRAC_PI_2, true));
        let far = vec![rect(1.3, 0.0, 1.4, 0.2)];
        assert!(!circle_cut(&ws, &far, &on, PI, 0.0, false));
        // A stand point inside the wall.
        assert!(!circle_cut(&ws, &walls, &on, FRAC_PI_2, PI, true));
    }

    /// A robot on the open table that turns and drives 10 % short of what it is asked,
    /// counting its drives.
    struct Short {
        pose: Pose2,
        drives: usize,
        /// Where each drive ended.
        track: Vec<Vector2<f64>>,
    }

    impl RobotIo for Short {
        fn spin(&mut self, angle: f64) -> Result<()> {
            self.pose.theta = wrap_angle(self.pose.theta + 0.9 * angle);
            Ok(())
        }
        fn forward(&mut self, distance: f64) -> Result<()> {
            let (s, c) = self.pose.theta.sin_cos();
            self.pose.x += 0.9 * distance * c;
            self.pose.y += 0.9 * distance * s;
            self.drives += 1;
            self.track.push(self.pose.position());
            Ok(())
        }
        fn drive(&mut self, _: f64, _: f64, _: f64) -> Result<()> {
            anyhow::bail!("not used")
        }
        fn robot_pose(&mut self) -> Pose2 {
            self.pose
        }
        fn object_pose(&mut self) -> Pose2 {
            Pose2::new(C.x, C.y, 0.0)
        }
        fn body_pose(&mut self, _: &str) -> Option<Pose2> {
            None
        }
        fn time(&self) -> f64 {
            0.0
        }
        fn workspace(&self) -> Workspace {
            ws()
        }
    }

    /// The object's centre in the walks below.
    const C: Vector2<f64> = Vector2::new(0.85, 0.5);

    /// A walk from 3 cm outside the 15.5 cm circle about [`C`], from its right half way round
    /// to the left, ending `radius` from `C` (way points out to `outer`), driven by [`Short`];
    /// checks the end is reached within the end's tolerance.
    fn walk_half_round(radius: f64, outer: f64) -> Short {
        let mut io = Short {
            pose: Pose2::new(C.x + 0.185, C.y, std::f64::consts::PI),
            drives: 0,
            track: Vec::new(),
        };
        let end = Drive::two_level(0.05);
        circle_walk(
            &mut io,
            C,
            radius,
            outer,
            std::f64::consts::PI,
            &end,
            &Around::default(),
        )
        .unwrap();
        let target = C - Vector2::new(radius, 0.0);
        let miss = (io.pose.position() - target).norm();
        assert!(miss <= end.arrive, "ended {miss:.4} m from the walk's end");
        io
    }

    /// From 3 cm outside the circle half way round: onto the circle and five way points, each
    /// one turn and one drive (a second leg would correct the 10 % shortfall, about 8 mm,
    /// which a way point does not need), and the end driven to as asked: two legs of the
    /// paper's two levels, ending within 5 mm.
    #[test]
    fn a_walk_drives_each_way_point_once_and_its_end_as_asked() {
        let io = walk_half_round(0.155, 0.155);
        assert_eq!(io.drives, 1 + 5 + 2, "drives");
    }

    /// A walk whose end comes in to 10 cm of the object (a wall cut the bound-all circle of
    /// 15.5 cm there) goes round at 15.5 cm wherever the robot fits, and only its end comes
    /// in: at 10 cm all the way round it would sweep through the object.
    #[test]
    fn a_walk_that_ends_closer_goes_round_at_the_bound_all_circle() {
        let io = walk_half_round(0.10, 0.155);
        // Every drive but the end's two legs ended 15.5 cm out, give or take the 10 %
        // shortfall of a chord.
        let (way, last) = io.track.split_at(io.track.len() - 2);
        assert!(way.len() >= 5, "{:?}", io.track);
        for p in way {
            let d = (p - C).norm();
            assert!(d > 0.14, "a way point {d:.3} m from the object");
        }
        assert!(last.iter().all(|p| (p - C).norm() < 0.12), "{last:?}");
    }

    /// A walk from the inner corner of an L (12 × 14 cm, 4 cm arms, its corner's opening
    /// facing a wall 10 cm away), where the robot has just pushed one arm, to a stand point
    /// on the far side; driven by [`Short`]. Returns the closest the robot's centre came to the
    /// L's outline after its first 5 mm; the walk knows the outline when `known`.
    fn walk_out_of_an_l(known: bool) -> f64 {
        let l = [
            [-0.02, -0.025],
            [0.10, -0.025],
            [0.10, 0.015],
            [0.02, 0.015],
            [0.02, 0.115],
            [-0.02, 0.115],
        ];
        let o = Pose2::new(1.296, 0.684, 2.26);
        let outline = outline_on_table(&l, &o);
        let wall = vec![rect(1.0, 0.4, 1.1, 1.2)];
        let start = Pose2::new(1.201, 0.684, -1.76);
        let mut io = Short {
            pose: start,
            drives: 0,
            track: Vec::new(),
        };
        let centre = Vector2::new(1.236, 0.687);
        let keep_clear = Around {
            obstacles: &wall,
            object: if known { &outline } else { &[] },
        };
        let end = Drive::two_level(0.05);
        circle_walk(&mut io, centre, 0.152, 0.152, 0.51, &end, &keep_clear).unwrap();
        let mut closest = f64::INFINITY;
        let mut at = start.position();
        for next in io.track {
            let n = ((next - at).norm() / 0.002).ceil().max(1.0) as usize;
            for k in 0..=n {
                let p = at + (next - at) * (k as f64 / n as f64);
                if (p - start.position()).norm() > 0.005 {
                    closest = closest.min(crate::planner::global::polygon_distance(p, &outline));
                }
            }
            at = next;
        }
        closest
    }

    /// Out of an L's inner corner with a wall in the way straight out: the robot backs along
    /// the push it made and drives round the outline itself, never closer to it than its
    /// 4 cm radius. Round the bound-all circle's 12-gon instead (the outline not known) it
    /// has no path from inside the 12-gon and its way out runs more than 5 mm into an arm.
    #[test]
    fn a_walk_out_of_an_inner_corner_goes_round_the_outline() {
        let clear = walk_out_of_an_l(true);
        assert!(clear >= 0.04 - 1e-3, "came {clear:.4} m from the outline");
        let blind = walk_out_of_an_l(false);
        assert!(blind < 0.035, "without the outline: {blind:.4} m");
    }
}

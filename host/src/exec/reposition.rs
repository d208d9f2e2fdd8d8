//! Where the special case of Algorithm 2 (Lau, Mitani & Igarashi §III-E, Fig. 4b) stands the
//! robot when there are obstacles (the end of §III-E): the learned re-positioning for the
//! wanted direction, moved only as far as walls make it. The approach comes in closer than the
//! bound-all circle (Fig. 3) where a wall cuts that circle, and only when no approach works is
//! the wanted direction turned or a single recorded push (a sample, §III-B) stood in for the
//! regression. [`crate::exec::deliver::deliver_learned_among`] walks the robot there. On any
//! table, a stand point the regression averaged into the object itself (pushes from both
//! flanks of a thin or concave object) is moved back out along its push (`stand_clear`).

use nalgebra::Vector2;

use crate::exec::io::Workspace;
use crate::exec::maneuver::{Around, around_object, outline_on_table};
use crate::planner::global::{plan_robot_path, polygon_distance, robot_fits, segment_clear};
use crate::strategy::regression::{PushStrategy, Reposition};
use crate::strategy::sample::{Pose2, wrap_angle};
use std::f64::consts::FRAC_PI_2;

/// The bound-all circle (Fig. 3) the special case walks the robot round the object on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundAll {
    /// Centre, table frame.
    pub centre: Vector2<f64>,
    /// Radius, m.
    pub radius: f64,
}

/// Where the robot is when the special case stands it somewhere, and the stand points
/// (object frame) from which a push of this delivery moved the object neither far enough
/// nor the wanted way since it last did: they are not tried again while others are reachable.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Standing<'a> {
    /// The robot's position, table frame.
    pub from: Vector2<f64>,
    /// Stand points that failed, object frame.
    pub failed: &'a [[f64; 2]],
    /// The object's outline in its marker's frame ([`crate::exec::io::RobotIo::object_outline`];
    /// empty when not known): a stand point inside it is moved out (`stand_clear`).
    pub outline: &'a [[f64; 2]],
}

/// A candidate stand point closer than this to one that failed counts as that one, m.
const FAILED_STAND_RADIUS: f64 = 0.015;

/// Wanted directions tried, in order, when the robot cannot stand where the special case puts
/// it: the direction to the goal, then turned either way by up to 90°.
const SPECIAL_TURNS_DEG: [f64; 13] = [
    0.0, 15.0, -15.0, 30.0, -30.0, 45.0, -45.0, 60.0, -60.0, 75.0, -75.0, 90.0, -90.0,
];

/// The special case's re-positioning (Algorithm 2) for an object at `o` wanted to move along
/// `want` (object frame), where the robot can stand and get to, with the radius of the circle
/// about the object it comes in from: the stand point and its approach point must be clear of
/// the table's edge and of `obstacles`, and a path must lead from the robot at `from` to the
/// approach point around the obstacles and the object. The approach point lies on the
/// bound-all circle where that is clear; where a wall cuts the circle there (a corridor), it
/// comes in closer, down to [`APPROACH_GAP`] outside the stand point. When no approach works,
/// or the stand point already failed ([`Standing::failed`]), the candidates are the
/// regression's answers for the wanted direction turned either way ([`SPECIAL_TURNS_DEG`])
/// and the recorded pushes that moved the object within 90° of it, nearest direction first;
/// the first that works wins, else the untouched one. On a clear table every stand point can
/// be reached, so it is the paper's re-positioning except that a stand point whose push failed
/// is not stood on again while another is fresh: the paper's stands the robot where it failed
/// again and again, and a snake turned about a point beside the goal, walked round after every
/// push, orbits the goal 4 cm from it until the time runs out (4 of 50 from Fig. 10's E with
/// the rendered camera).
pub(crate) fn reachable_reposition(
    strategy: &PushStrategy,
    ws: &Workspace,
    obstacles: &[Vec<[f64; 2]>],
    o: &Pose2,
    robot: Standing,
    want: [f64; 2],
    bound_all: &BoundAll,
) -> Option<Stand> {
    let clear = |rep| stand_clear(rep, robot.outline, ws.robot_radius);
    let first = clear(strategy.special(want)?);
    let stand = |rep, radius| Stand {
        rep,
        radius,
        reachable: true,
    };
    let object = outline_on_table(robot.outline, o);
    let keep_clear = Around {
        obstacles,
        object: &object,
    };
    // On a clear table every stand point is reached from the bound-all circle.
    let approach_radius = |rep: &Reposition| {
        if obstacles.is_empty() {
            Some(bound_all.radius)
        } else {
            approach_radius(ws, &keep_clear, o, robot.from, rep, bound_all)
        }
    };
    let fresh = |rep: &Reposition| {
        robot
            .failed
            .iter()
            .all(|f| (f[0] - rep.p[0]).hypot(f[1] - rep.p[1]) > FAILED_STAND_RADIUS)
    };
    if fresh(&first)
        && let Some(radius) = approach_radius(&first)
    {
        return Some(stand(first, radius));
    }
    // The regression's answer for a turned direction, or one recorded push: the regression
    // averages the stand points of pushes that moved the object alike, and when those came
    // from different sides (an L turned about its corner, or pushed along) the average can
    // stand where none of them did, inside a wall. Each candidate is ranked by how far off
    // the wanted direction its motion is; the first the robot can reach wins.
    let turned = SPECIAL_TURNS_DEG[1..].iter().filter_map(|deg| {
        let (s, c) = deg.to_radians().sin_cos();
        let rep = strategy.special([c * want[0] - s * want[1], s * want[0] + c * want[1]])?;
        Some((deg.abs().to_radians(), clear(rep)))
    });
    let mut candidates: Vec<(f64, Reposition)> = turned
        .chain(recorded_pushes(strategy, want, FRAC_PI_2))
        .collect();
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    candidates
        .into_iter()
        .filter(|(_, rep)| fresh(rep))
        .find_map(|(_, rep)| approach_radius(&rep).map(|radius| stand(rep, radius)))
        .or_else(|| {
            tracing::debug!("special case: no reachable stand point within 90 degrees");
            Some(Stand {
                rep: first,
                radius: bound_all.radius,
                reachable: obstacles.is_empty(),
            })
        })
}

/// A stand point counts as clear of the outline when the robot's bumper overlaps it by no
/// more than this, m: the recorded stand points are in contact, give or take the camera.
const STAND_OVERLAP: f64 = 0.003;

/// How far outside the outline a stand point that was inside it is moved, m.
const STAND_GAP: f64 = 0.004;

/// Furthest a stand point is moved back out of the outline, m.
const STAND_BACK_MAX: f64 = 0.25;

/// `rep` with its stand point clear of the object: the regression (Algorithm 2) averages the
/// stand points of pushes that moved the object alike, and when they came from different sides
/// of a concave or thin object (an L's two arms, a snake's two flanks) the average can lie
/// inside the object, where driving to it would knock the object away before the push. Such a
/// stand point is moved back against the push, along −r, to where the robot's bumper (of
/// `robot_radius`) first clears `outline` (object frame) by [`STAND_GAP`]: where a robot
/// pushing along r from further back would touch the object. Unchanged when it is clear, when
/// the outline is not known, or when no point within [`STAND_BACK_MAX`] clears it.
pub(crate) fn stand_clear(rep: Reposition, outline: &[[f64; 2]], robot_radius: f64) -> Reposition {
    let p = Vector2::new(rep.p[0], rep.p[1]);
    if outline.len() < 3 || polygon_distance(p, outline) >= robot_radius - STAND_OVERLAP {
        return rep;
    }
    let Some(back) = Vector2::new(-rep.r[0], -rep.r[1]).try_normalize(1e-9) else {
        return rep;
    };
    let steps = (STAND_BACK_MAX / 0.002) as usize;
    (1..=steps)
        .map(|k| p + back * (0.002 * k as f64))
        .find(|q| polygon_distance(*q, outline) >= robot_radius + STAND_GAP)
        .map_or(rep, |q| Reposition {
            p: [q.x, q.y],
            ..rep
        })
}

/// The special case's answer ([`reachable_reposition`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Stand {
    /// Where to stand and how to push, object frame.
    pub rep: Reposition,
    /// Radius of the circle about the bound-all circle's centre the robot comes in from, m.
    pub radius: f64,
    /// Whether the robot can stand there and get to it; `false` only among obstacles, when
    /// no candidate within 90° of the wanted direction is reachable (the untouched answer).
    pub reachable: bool,
}

/// The recorded pushes (samples) that moved the object within `max_off` of `want` (object
/// frame) and at least [`SINGLE_PUSH_LEAST`] of the mean distance, with how far off they
/// moved it, rad.
pub(crate) fn recorded_pushes(
    strategy: &PushStrategy,
    want: [f64; 2],
    max_off: f64,
) -> impl Iterator<Item = (f64, Reposition)> + '_ {
    let want_angle = want[1].atan2(want[0]);
    let least = SINGLE_PUSH_LEAST * strategy.offset();
    strategy.samples().iter().filter_map(move |s| {
        let off = wrap_angle(s.s[1].atan2(s.s[0]) - want_angle).abs();
        (s.s_len() >= least && off <= max_off).then_some((off, Reposition { p: s.p, r: s.r }))
    })
}

/// The radius of the circle about the bound-all circle's centre from which the robot, now at
/// `from`, comes in to push as `rep` says: the bound-all circle where its point is clear, else
/// closer in 1 cm steps down to [`APPROACH_GAP`] outside the stand point; `None` when the
/// stand point does not fit or no approach point on that line does with a path to it round
/// the obstacles and the object ([`around_object`]).
pub(crate) fn approach_radius(
    ws: &Workspace,
    keep_clear: &Around,
    o: &Pose2,
    from: Vector2<f64>,
    rep: &Reposition,
    circle: &BoundAll,
) -> Option<f64> {
    let (centre, bound_all) = (circle.centre, circle.radius);
    let obstacles = keep_clear.obstacles;
    let at = o.point_to_world(Vector2::new(rep.p[0], rep.p[1]));
    let rel = at - centre;
    if !robot_fits(ws, obstacles, at) {
        return None;
    }
    let Some(u) = rel.try_normalize(1e-9) else {
        return Some(bound_all);
    };
    let closest = (rel.norm() + APPROACH_GAP).min(bound_all);
    let steps = ((bound_all - closest) / 0.01).ceil().max(0.0) as usize;
    (0..=steps)
        .map(|k| (bound_all - 0.01 * k as f64).max(closest))
        .find(|&radius| {
            let approach = centre + radius * u;
            let around = around_object(ws, keep_clear, centre, radius, from);
            robot_fits(ws, obstacles, approach)
                && (segment_clear(ws, &around, from, approach)
                    || plan_robot_path(ws, &around, from, approach).is_some())
        })
}

/// A recorded push stands in for the regression only when it moved the object at least this
/// fraction of the samples' mean displacement ([`PushStrategy::offset`]).
const SINGLE_PUSH_LEAST: f64 = 0.5;

/// The closest the special case's approach comes to the object: this far outside the stand
/// point, m.
const APPROACH_GAP: f64 = 0.03;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::deliver::bound_all_radius;
    use crate::exec::maneuver::angle_of;
    use crate::exec::test_tables::lau_table;
    use crate::strategy::sample::Sample;

    /// A disc-like strategy: pushing from angle a (8 cm out) moves the object towards a + π.
    fn disc_strategy() -> PushStrategy {
        let samples = (0..720).map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 720.0;
            let push = 0.01 + 0.04 * ((k * 7) % 13) as f64 / 13.0;
            Sample {
                p: [0.08 * a.cos(), 0.08 * a.sin()],
                r: [-push * a.cos(), -push * a.sin()],
                s: [-0.8 * push * a.cos(), -0.8 * push * a.sin()],
                theta: 0.0,
            }
        });
        PushStrategy::new(
            samples,
            crate::strategy::regression::KernelParams::default(),
        )
    }

    /// A bar 14 cm long and 2.4 cm thin (a snake's width), pushed along its length from either
    /// flank alike: the regression averages the two stand points to one inside the bar. With
    /// the outline known the robot stands at the bar's end instead, back along the push, its
    /// bumper clear of the bar; without it, the average is kept as the paper has it.
    #[test]
    fn a_stand_point_averaged_into_the_object_is_moved_back_out_along_the_push() {
        let bar = [
            [-0.07, -0.012],
            [0.07, -0.012],
            [0.07, 0.012],
            [-0.07, 0.012],
        ];
        let samples = [1.0, -1.0].into_iter().flat_map(|side| {
            [0.025, 0.03, 0.035].map(|push| Sample {
                p: [-0.02, side * 0.052],
                r: [push, -side * 0.01],
                s: [0.6 * push, 0.0],
                theta: 0.0,
            })
        });
        let strategy = PushStrategy::new(
            samples,
            crate::strategy::regression::KernelParams::default(),
        );
        let ws = lau_table(0.075);
        let o = Pose2::new(0.8, 0.6, 0.3);
        let circle = BoundAll {
            centre: o.position(),
            radius: bound_all_radius(&ws, 0.02),
        };
        let from = Vector2::new(0.5, 0.3);
        let stand = |outline: &[[f64; 2]]| {
            let robot = Standing {
                from,
                failed: &[],
                outline,
            };
            reachable_reposition(&strategy, &ws, &[], &o, robot, [1.0, 0.0], &circle)
                .expect("a re-positioning")
                .rep
        };
        let inside = stand(&[]);
        let p = Vector2::new(inside.p[0], inside.p[1]);
        assert!(polygon_distance(p, &bar) < 0.005, "the average: {inside:?}");
        let out = stand(&bar);
        let q = Vector2::new(out.p[0], out.p[1]);
        let clear = polygon_distance(q, &bar);
        assert!(
            (ws.robot_radius + STAND_GAP..ws.robot_radius + STAND_GAP + 0.003).contains(&clear),
            "{clear} from the bar: {out:?}"
        );
        // Moved straight back against the push, which is kept.
        let back = (q - p).normalize();
        let push = Vector2::new(out.r[0], out.r[1]).normalize();
        assert!(back.dot(&push) < -0.999, "{inside:?} -> {out:?}");
        assert_eq!(out.r, inside.r);
        // A stand point already clear is left where it is.
        let aside = Reposition {
            p: [0.0, 0.06],
            r: [0.0, -0.03],
        };
        assert_eq!(stand_clear(aside, &bar, ws.robot_radius), aside);
    }

    /// An object at the bottom of a 0.3 m corridor (walls at x 0.6–0.7 and 1.0–1.1), to be
    /// pushed right. Its stand point, 8 cm to its left, fits; the bound-all circle's point
    /// there is inside the left wall. The robot comes in closer, from within the corridor,
    /// and pushes the way wanted, not a direction turned away from it.
    #[test]
    fn in_a_corridor_the_approach_comes_closer_than_the_bound_all_circle() {
        let ws = lau_table(0.117);
        let walls = vec![
            vec![[0.6, 0.0], [0.7, 0.0], [0.7, 0.8], [0.6, 0.8]],
            vec![[1.0, 0.4], [1.1, 0.4], [1.1, 1.2], [1.0, 1.2]],
        ];
        let strategy = disc_strategy();
        let o = Pose2::new(0.88, 0.3, 0.0);
        let bound_all = bound_all_radius(&ws, 0.02);
        let circle = BoundAll {
            centre: o.position(),
            radius: bound_all,
        };
        let from = Vector2::new(0.85, 0.6);
        let at = |from| Standing {
            from,
            failed: &[],
            outline: &[],
        };
        let Stand { rep, radius, .. } =
            reachable_reposition(&strategy, &ws, &walls, &o, at(from), [1.0, 0.0], &circle)
                .expect("a re-positioning");
        let stand = Vector2::new(rep.p[0], rep.p[1]);
        let push = Vector2::new(rep.r[0], rep.r[1]);
        assert!(
            angle_of(-stand).abs() < 10f64.to_radians()
                && angle_of(push).abs() < 10f64.to_radians(),
            "stands at {stand:?}, pushes {push:?}"
        );
        assert!(radius < bound_all - 0.02, "approach radius {radius}");
        let approach = o.position() + radius * stand.normalize();
        assert!(robot_fits(&ws, &walls, approach), "{approach:?}");
        assert!(!robot_fits(
            &ws,
            &walls,
            o.position() + bound_all * stand.normalize()
        ));
        // On an open table the approach stays on the bound-all circle.
        let open = [vec![[0.0, 1.15], [0.05, 1.15], [0.05, 1.2]]];
        let Stand { radius, .. } =
            reachable_reposition(&strategy, &ws, &open, &o, at(from), [1.0, 0.0], &circle)
                .expect("a re-positioning");
        assert_eq!(radius, bound_all);
    }

    /// Pushes from the object's left, at heights −3…3 cm, that moved it right and fanned out
    /// over ±80° (each direction three times), and three from below (the point returned) that
    /// moved it 55° from the right.
    fn from_left_and_below() -> (PushStrategy, [f64; 2]) {
        let mut samples = Vec::new();
        // From the left, at heights −3…3 cm: the object goes right and turns, so its motion
        // fans out over ±80°; each direction is pushed three times.
        for k in -8..=8 {
            let phi = (k as f64 * 10.0).to_radians();
            for push in [0.03, 0.035, 0.04] {
                samples.push(Sample {
                    p: [-0.08, -0.03 * k as f64 / 8.0],
                    r: [push, 0.0],
                    s: [0.8 * push * phi.cos(), 0.8 * push * phi.sin()],
                    theta: 0.0,
                });
            }
        }
        // From below, pushing up: three pushes that moved it 55° from the right, a little
        // further than the pushes from the left moved it.
        let below = [0.0, -0.08];
        let phi = 55f64.to_radians();
        for push in [0.05, 0.055, 0.06] {
            samples.push(Sample {
                p: below,
                r: [0.0, push],
                s: [0.8 * push * phi.cos(), 0.8 * push * phi.sin()],
                theta: 0.0,
            });
        }
        let strategy = PushStrategy::new(
            samples,
            crate::strategy::regression::KernelParams::default(),
        );
        (strategy, below)
    }

    /// On a clear table the paper's answer is stood on, until its push failed: then another
    /// answer is, reached from the bound-all circle (the snake's orbit round the goal).
    #[test]
    fn on_a_clear_table_a_failed_stand_point_is_not_stood_on_again() {
        let ws = lau_table(0.06);
        let o = Pose2::new(0.76, 0.5, 0.0);
        let (strategy, _) = from_left_and_below();
        let circle = BoundAll {
            centre: o.position(),
            radius: 0.06 + 0.08 + 0.02,
        };
        let first = strategy.special([1.0, 0.0]).expect("an answer");
        let stand_with = |failed: &[[f64; 2]]| {
            let robot = Standing {
                from: Vector2::new(1.2, 0.2),
                failed,
                outline: &[],
            };
            reachable_reposition(&strategy, &ws, &[], &o, robot, [1.0, 0.0], &circle)
                .expect("a re-positioning")
        };
        let stand = stand_with(&[]);
        assert_eq!(stand.rep, first);
        assert!(
            stand.reachable && stand.radius == circle.radius,
            "{stand:?}"
        );
        let stand = stand_with(&[first.p]);
        let moved = (stand.rep.p[0] - first.p[0]).hypot(stand.rep.p[1] - first.p[1]);
        assert!(
            moved > FAILED_STAND_RADIUS,
            "stood again where it failed: {stand:?}"
        );
        assert!(
            stand.reachable && stand.radius == circle.radius,
            "{stand:?}"
        );
    }

    /// An object pressed against a wall on its left, wanted to the right. Every push the
    /// strategy knows that moves it rightwards stands the robot on its left, in the wall, but
    /// for three pushes from below that turned it and moved it up and to the right. The
    /// regression (its k nearest pushes are always from the left) stands the robot in the wall
    /// for every turned direction; the re-positioning stands it where one of the pushes from
    /// below did. Once that stand point failed it is not offered again.
    #[test]
    fn against_a_wall_a_recorded_push_from_a_side_the_robot_can_reach_is_used() {
        let ws = lau_table(0.06);
        let walls = vec![vec![[0.6, 0.0], [0.7, 0.0], [0.7, 1.2], [0.6, 1.2]]];
        let o = Pose2::new(0.76, 0.5, 0.0);
        let (strategy, below) = from_left_and_below();
        let circle = BoundAll {
            centre: o.position(),
            radius: 0.06 + 0.08 + 0.02,
        };
        let from = Vector2::new(1.2, 0.2);
        let stands_in_a_wall = |rep: &Reposition| {
            !robot_fits(
                &ws,
                &walls,
                o.point_to_world(Vector2::new(rep.p[0], rep.p[1])),
            )
        };
        // The regression alone leaves the robot nowhere to stand.
        for deg in SPECIAL_TURNS_DEG {
            let (s, c) = deg.to_radians().sin_cos();
            let rep = strategy.special([c, s]).expect("an answer");
            assert!(stands_in_a_wall(&rep), "turned {deg}°: {rep:?}");
        }
        let robot = Standing {
            from,
            failed: &[],
            outline: &[],
        };
        let stand = reachable_reposition(&strategy, &ws, &walls, &o, robot, [1.0, 0.0], &circle)
            .expect("a re-positioning");
        assert_eq!(stand.rep.p, below, "{stand:?}");
        assert!(stand.reachable && !stands_in_a_wall(&stand.rep));
        // Once the stand point below failed, nothing reachable is left: the untouched answer,
        // marked as not reachable.
        let robot = Standing {
            from,
            failed: &[below],
            outline: &[],
        };
        let stand = reachable_reposition(&strategy, &ws, &walls, &o, robot, [1.0, 0.0], &circle)
            .expect("a re-positioning");
        assert!(!stand.reachable, "{stand:?}");
        assert_eq!(Some(stand.rep), strategy.special([1.0, 0.0]));
    }
}

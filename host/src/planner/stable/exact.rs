//! The exact-goal variant of Lynch & Mason (1996) §4.5 — back up along the plan, then push
//! exactly onto the goal — for every pusher, wheeled ones included.
//!
//! The paper finishes with *one* stable push. That needs a usable set with interior on the
//! velocity sphere (the arm, the omnidirectional robot): a single push is a constant twist, and
//! hitting a goal `(x, y, θ)` exactly takes all three of its components. A car or a
//! differential drive pushes about rotation centres on its axle line only, forward, at least
//! the extremal stable radius away on either side (Fig. 14) — and while the slider stays fixed
//! to the pusher, the slider's pose and the robot's pose determine each other. Reaching the
//! goal exactly is then the shortest path of a forward-only car of that minimum turning radius
//! between two robot poses: a *Dubins path*, three pushes (turn, straight, turn, or three
//! turns), computed by the `dubins_paths` crate. The finish is kept when each of its pushes
//! is in the contact's usable set and free of collision along its whole length.
//!
//! [`finish_exactly`] tries the paper's single push first ([`search::exact_goal`]), then the
//! Dubins finish.

use dubins_paths::SegmentType;
use dubins_paths::f64::{DubinsPath, PosRot};

use super::pusher::PusherKind;
use super::search::{self, Plan, backed_up, push_steps, summarise};
use super::{Pose, Problem};
use crate::mechanics::{V2, V3};

/// Control index of an exact-goal push turning left (not one of the contact's controls).
pub const EXACT_LEFT: usize = usize::MAX - 1;
/// Control index of an exact-goal push turning right.
pub const EXACT_RIGHT: usize = usize::MAX - 2;
/// Control index of an exact-goal straight push, when straight ahead is not a control.
pub const EXACT_STRAIGHT: usize = usize::MAX - 3;

/// One push of a finish: its whole slider-frame twist and its control index.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Push {
    xi: V3,
    control: usize,
}

/// A wheeled pusher on one contact, in the slider frame: its axle centre `a`, forward `n`,
/// left `l`, and the tightest turning radius its stable set allows on either side.
#[derive(Debug, Clone, Copy)]
struct Axle {
    a: V2,
    n: V2,
    l: V2,
    rho: f64,
}

impl Axle {
    /// The axle of contact `ci`; `None` for a pusher without one (arm, omnidirectional).
    fn of(p: &Problem, ci: usize) -> Option<Axle> {
        let cm = &p.contacts[ci];
        if !matches!(
            p.pusher.kind,
            PusherKind::Car { .. } | PusherKind::DiffDrive
        ) {
            return None;
        }
        let pl = &cm.placement;
        let a = pl.to_slider(V2::new(0.0, -p.pusher.axle_offset));
        let n = pl.normal;
        // The extremal rotation centres are the tightest stable turns.
        let rho = cm
            .usable
            .controls
            .iter()
            .filter_map(super::cor_of)
            .map(|c| (c - a).norm())
            .fold(0.0, f64::max)
            * (1.0 + 1e-6);
        (rho > 0.0).then_some(Axle {
            a,
            n,
            l: V2::new(-n.y, n.x),
            rho,
        })
    }

    /// The twist of a turn of the axle centre through `phi` (left if positive) at radius `rho`.
    fn turn(&self, phi: f64) -> V3 {
        let c = self.a + self.l * (self.rho * phi.signum());
        V3::new(phi * c.y, -phi * c.x, phi)
    }
}

/// The exact finishes with contact `ci` from `q` onto `goal`: the Dubins words of the robot's
/// axle centre at the largest extremal turning radius of the contact, each turned into pushes
/// (slider-frame twists), shortest first. Only those whose every push is usable and
/// collision-free. Empty for a pusher without an axle (arm, omnidirectional).
fn dubins_finishes(p: &Problem, ci: usize, q: &Pose, goal: &Pose) -> Vec<Vec<Push>> {
    let cm = &p.contacts[ci];
    let Some(axle) = Axle::of(p, ci) else {
        return Vec::new();
    };
    let Axle { a, n, rho, .. } = axle;
    let robot = |q: &Pose| {
        let at = q.apply(a);
        let h = q.rotate(n);
        PosRot::from_floats(at.x, at.y, h.y.atan2(h.x))
    };
    let straight_control = cm
        .usable
        .controls
        .iter()
        .position(|c| c.z.abs() < 1e-12 && (V2::new(c.x, c.y).normalize() - n).norm() < 1e-9)
        .unwrap_or(EXACT_STRAIGHT);
    let (r0, r1) = (robot(q), robot(goal));
    let mut words: Vec<DubinsPath> = dubins_paths::PathType::ALL
        .iter()
        .filter_map(|&t| DubinsPath::new(r0, r1, rho, t).ok())
        .collect();
    words.sort_by(|x, y| x.length().total_cmp(&y.length()));
    words
        .into_iter()
        .filter_map(|w| {
            let mut pushes = Vec::new();
            for (i, kind) in w.path_type.to_segment_types().into_iter().enumerate() {
                let len = w.segment_length(i);
                if len < 1e-9 {
                    continue;
                }
                let push = match kind {
                    SegmentType::S => Push {
                        xi: V3::new(n.x, n.y, 0.0) * len,
                        control: straight_control,
                    },
                    SegmentType::L => Push {
                        xi: axle.turn(len / rho),
                        control: EXACT_LEFT,
                    },
                    SegmentType::R => Push {
                        xi: axle.turn(-len / rho),
                        control: EXACT_RIGHT,
                    },
                };
                pushes.push(push);
            }
            let mut at = *q;
            for push in &pushes {
                if !cm.usable.set.contains(&push.xi) || !cm.body.step_free(&p.world, &at, &push.xi)
                {
                    return None;
                }
                at = at.integrate(&push.xi);
            }
            Some(pushes)
        })
        .collect()
}

/// The exact-goal finish of §4.5 for a wheeled pusher (see the module doc): back up along
/// `plan` until a configuration from which a Dubins path of pushes with the contact in use ends
/// collision-free exactly on the goal; of the finishes from the first such configuration, the
/// cheapest. Without contact changes: the finish keeps the contact the plan was using there.
pub fn dubins_goal(p: &Problem, plan: &Plan) -> Option<Plan> {
    if !plan.found {
        return None;
    }
    for back in (0..=plan.steps.len()).rev() {
        let (q, ci) = if back == 0 {
            (
                p.start,
                p.start_contact.or(plan.steps.first().map(|s| s.contact))?,
            )
        } else {
            let s = &plan.steps[back - 1];
            (s.to, s.contact)
        };
        let best = dubins_finishes(p, ci, &q, &p.goal)
            .into_iter()
            .map(|pushes| {
                let mut out = backed_up(plan, back);
                let pushes: Vec<(V3, usize)> = pushes.iter().map(|u| (u.xi, u.control)).collect();
                out.steps.extend(push_steps(p, ci, &q, &pushes, &p.goal));
                summarise(p, &mut out);
                out.exact_goal = true;
                out
            })
            .min_by_key(|o| o.cost);
        if best.is_some() {
            return best;
        }
    }
    None
}

/// Back up along `plan` and finish exactly on the goal (§4.5): with one stable push where the
/// pusher can ([`search::exact_goal`]), else with the Dubins pushes of a wheeled pusher
/// ([`dubins_goal`]). `None` when neither exists from any configuration of the plan.
pub fn finish_exactly(p: &Problem, plan: &Plan) -> Option<Plan> {
    search::exact_goal(p, plan).or_else(|| dubins_goal(p, plan))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::stable::robot::robot_problem;
    use crate::planner::stable::{angle_diff, plan};

    #[test]
    fn dubins_finishes_land_exactly_on_the_goal_with_usable_pushes() {
        let (_, p) = robot_problem("fig15", Some(10.0)).unwrap();
        let cm = &p.contacts[0];
        let g = p.goal;
        // Poses around the goal: beside it, behind it, turned either way.
        let mut found = 0;
        for (dx, dy, dth) in [(-0.5, 0.1, 0.3), (-0.6, -0.1, -0.3), (-0.4, 0.0, 0.0)] {
            let q = Pose::new(g.x + dx, g.y + dy, g.theta + dth);
            for pushes in dubins_finishes(&p, 0, &q, &g) {
                found += 1;
                let mut end = q;
                for push in &pushes {
                    assert!(cm.usable.set.contains(&push.xi));
                    end = end.integrate(&push.xi);
                }
                assert!(
                    (end.x - g.x).hypot(end.y - g.y) < 1e-6
                        && angle_diff(end.theta, g.theta).abs() < 1e-6,
                    "{end:?} vs {g:?}"
                );
            }
        }
        assert!(found >= 3, "{found} finishes");
    }

    #[test]
    fn fig15_for_the_robot_ends_exactly_on_the_goal_after_backing_up_along_the_plan() {
        let (_, p) = robot_problem("fig15", Some(2.0)).unwrap();
        let pl = plan(&p);
        assert!(pl.found);
        let done = finish_exactly(&p, &pl).expect("an exact finish");
        assert!(done.exact_goal);
        assert_eq!(done.steps.last().unwrap().to, p.goal);
        assert!(done.steps.iter().any(|s| s.control >= EXACT_STRAIGHT));
        // Every step follows from the previous one, is usable and collision-free, and the
        // twists integrate onto the goal itself.
        let mut at = p.start;
        for s in &done.steps {
            let d = (s.from.x - at.x).hypot(s.from.y - at.y);
            assert!(d < 1e-6, "gap {d}");
            let xi = V3::new(s.twist[0], s.twist[1], s.twist[2]);
            let cm = &p.contacts[s.contact];
            assert!(cm.usable.set.contains(&xi));
            assert!(cm.body.step_free(&p.world, &s.from, &xi));
            at = s.from.integrate(&xi);
        }
        assert!((at.x - p.goal.x).hypot(at.y - p.goal.y) < 1e-6);
        assert!(angle_diff(at.theta, p.goal.theta).abs() < 1e-6);
    }
}

//! Shared by the stable-planner test files: the slider of Fig. 12 and an independent
//! validator of plans.

#![allow(dead_code)]

use pushbot::mechanics::stable::stable;
use pushbot::mechanics::{V2, V3, cor};
use pushbot::planner::stable::pusher::PusherKind;
use pushbot::planner::stable::search::Plan;
use pushbot::planner::stable::{Problem, angle_diff};

/// The slider of Fig. 12 (a 20 × 14 cm box with one corner cut), its object frame at its area
/// centroid (the centre of friction of a uniform support).
pub const SLIDER: &str = "[[-0.09691358024691357, -0.06790123456790124], [0.10308641975308644, -0.06790123456790124], [0.10308641975308644, 0.03209876543209876], [0.05308641975308642, 0.07209876543209877], [-0.09691358024691357, 0.07209876543209877]]";

/// Separating-axis overlap test of two convex polygons (closed: touching overlaps).
fn overlap(a: &[V2], b: &[V2]) -> bool {
    for poly in [a, b] {
        let n = poly.len();
        for i in 0..n {
            let e = poly[(i + 1) % n] - poly[i];
            let ax = V2::new(-e.y, e.x);
            let pa = a.iter().map(|p| ax.dot(p));
            let pb = b.iter().map(|p| ax.dot(p));
            let (amin, amax) = (
                pa.clone().fold(f64::INFINITY, f64::min),
                pa.fold(f64::NEG_INFINITY, f64::max),
            );
            let (bmin, bmax) = (
                pb.clone().fold(f64::INFINITY, f64::min),
                pb.fold(f64::NEG_INFINITY, f64::max),
            );
            if amax < bmin || bmax < amin {
                return false;
            }
        }
    }
    true
}

pub fn hull(p: &[V2]) -> Vec<V2> {
    pushbot::mechanics::convex_hull(p)
}

/// An independent check of a plan against its problem: continuity, every step a constant push
/// inside the freshly computed STABLE set of its edge and inside the pusher's kinematics,
/// pusher + slider collision-free at 50 poses along every step, the end in the goal
/// neighbourhood, and the cost equal to the a/b/c sum recomputed from the steps.
pub fn validate(p: &Problem, plan: &Plan) {
    assert!(plan.found);
    assert!(!plan.steps.is_empty());
    let mut q = p.start;
    let mut prev: Option<(usize, V3)> = None;
    let mut cost = 0u32;
    let (mut cc, mut ctl) = (0usize, 0usize);
    if let Some(sc) = p.start_contact {
        prev = Some((p.contacts[sc].label, V3::zeros()));
    }
    let slider_convex = hull(&p.slider.vertices);
    for (i, s) in plan.steps.iter().enumerate() {
        assert!(
            (s.from.x - q.x).abs() < 1e-9
                && (s.from.y - q.y).abs() < 1e-9
                && angle_diff(s.from.theta, q.theta).abs() < 1e-9,
            "step {i} not continuous"
        );
        // The step's own motion, from its end poses alone.
        let xi = s.from.twist_to(&s.to);
        let dir = xi.normalize();
        let cm = &p.contacts[s.contact];
        assert_eq!(cm.label, s.edge);
        let st = stable(&p.slider, &cm.placement.contact, p.mu).unwrap();
        assert!(
            st.constraints.iter().all(|a| a.dot(&dir) >= -1e-6),
            "step {i} not stable: {dir:?}"
        );
        // Pusher kinematics: wheeled robots rotate about a point on their axle (in front of
        // the turning radius for a car), forward.
        let pl = &cm.placement;
        match &p.pusher.kind {
            PusherKind::Car { .. } | PusherKind::DiffDrive if dir.z.abs() > 1e-9 => {
                let c = cor(&dir).unwrap();
                let cc_ = pl.contact.to_contact_frame(c);
                assert!(
                    (cc_.y - (pl.y0 - p.pusher.axle_offset)).abs() < 1e-6,
                    "step {i}: COR off the axle"
                );
                if let PusherKind::Car { min_turning_radius } = &p.pusher.kind {
                    assert!(
                        (cc_.x - pl.offset).abs() >= min_turning_radius - 1e-6,
                        "step {i}: too tight"
                    );
                }
            }
            PusherKind::Car { .. } | PusherKind::DiffDrive => {
                let t = pl.contact.twist_to_contact(dir);
                assert!(
                    t.x.abs() < 1e-6 && t.y > 0.0,
                    "step {i}: wheeled robot translating sideways"
                );
            }
            _ => {}
        }
        // Collision along the step.
        for k in 0..=50 {
            let qt = s.from.integrate(&(xi * (k as f64 / 50.0)));
            let mut parts = vec![
                slider_convex
                    .iter()
                    .map(|v| qt.apply(*v))
                    .collect::<Vec<_>>(),
            ];
            if !cm.footprint.is_empty() {
                parts.push(hull(&cm.footprint).iter().map(|v| qt.apply(*v)).collect());
            }
            for part in &parts {
                for v in part {
                    assert!(
                        v.x > 0.0 && v.y > 0.0 && v.x < p.world.table.0 && v.y < p.world.table.1,
                        "step {i} leaves the table"
                    );
                }
                for o in &p.world.obstacles[p.world.n_walls..] {
                    assert!(
                        !overlap(part, &o.vertices),
                        "step {i} at t={k}/50 hits an obstacle"
                    );
                }
            }
        }
        // Cost: a per step, b per control change (contact or direction), c per contact change.
        cost += p.params.a;
        if let Some((pe, pd)) = prev {
            let changed_contact = pe != s.edge;
            if changed_contact || (pd.norm() > 0.0 && (pd - dir).norm() > 1e-6) {
                cost += p.params.b;
                ctl += 1;
            }
            if changed_contact {
                cost += p.params.c.expect("contact change with c = inf");
                cc += 1;
            }
        }
        prev = Some((s.edge, dir));
        q = s.to;
    }
    assert!(
        p.in_goal(&q) || plan.exact_goal,
        "plan ends outside the goal neighbourhood"
    );
    if plan.exact_goal {
        assert!((q.x - p.goal.x).abs() < 1e-9 && (q.y - p.goal.y).abs() < 1e-9);
    }
    assert_eq!(plan.cost, cost, "cost");
    assert_eq!(plan.contact_changes, cc);
    assert_eq!(plan.control_changes, ctl);
    // A mobile pusher has a transit path for every contact change, starting at the contact it
    // leaves and clear of the slider.
    if p.pusher.is_mobile() {
        assert_eq!(plan.transits.len(), cc);
    }
}

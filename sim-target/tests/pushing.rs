//! Quasi-static pushing with the ellipsoidal limit surface: validation against the papers'
//! rules and closed forms.

use proptest::prelude::*;
use pushbot_sim::Pose;
use pushbot_sim::pushing::{
    ContactMode, Slider, SupportShape, friction_centre, point_push, sticking_twist, twist_for_force,
};

fn square(side: f64) -> Vec<[f64; 2]> {
    let h = side / 2.0;
    vec![[-h, -h], [h, -h], [h, h], [-h, h]]
}

fn slider(mu: f64) -> Slider {
    let outline = square(0.1);
    let (cof, c) = friction_centre(&SupportShape::Uniform(&outline));
    Slider {
        outline,
        cof,
        c,
        mu,
        pose: Pose::new(0.5, 0.5, 0.0),
    }
}

/// The mean distance from the centre of a uniform square of side a is
/// a·(√2 + ln(1 + √2))/6 (closed form).
#[test]
fn limit_surface_length_of_a_square() {
    let (cof, c) = friction_centre(&SupportShape::Uniform(&square(0.1)));
    let exact = 0.1 * (2f64.sqrt() + (1.0 + 2f64.sqrt()).ln()) / 6.0;
    assert!(cof[0].abs() < 1e-9 && cof[1].abs() < 1e-9);
    assert!((c - exact).abs() / exact < 2e-3, "{c} vs {exact}");
    // Point supports: weighted centroid and weighted mean distance.
    let pts = [[0.0, 0.0], [0.3, 0.0]];
    let (cof, c) = friction_centre(&SupportShape::Points(&pts, Some(&[2.0, 1.0])));
    assert!((cof[0] - 0.1).abs() < 1e-12 && cof[1] == 0.0);
    assert!((c - (2.0 * 0.1 + 0.2) / 3.0).abs() < 1e-12);
}

/// A push through the centre of friction translates without rotating.
#[test]
fn centre_push_translates() {
    let mut s = slider(0.5);
    let r = 0.04;
    // Pusher starts 1 cm short of the left face, pushes 10 cm along +x through the COF.
    let from = [0.5 - 0.05 - r - 0.01, 0.5];
    let to = [from[0] + 0.1, 0.5];
    let mode = s.push(from, to, r, 0.001);
    assert_eq!(mode, Some(ContactMode::Sticking));
    assert!(s.pose.theta.abs() < 1e-9, "rotated {}", s.pose.theta);
    assert!((s.pose.y - 0.5).abs() < 1e-9);
    assert!((s.pose.x - 0.59).abs() < 1.5e-3, "x {}", s.pose.x);
    assert!(s.gap(to, r) >= -1e-9);
}

/// Mason's voting theorem: the slider turns the way at least two of the three rays (the two
/// friction-cone edges and the pushing direction) turn about the COF.
#[test]
fn off_centre_push_rotates_by_mason_rule() {
    let c = 0.04;
    let mut checked = 0;
    for i in 0..40 {
        for j in 0..24 {
            for mu in [0.1, 0.5, 1.0] {
                // Contact on the left face of a 0.1 m square, normal +x.
                let py = -0.045 + 0.09 * i as f64 / 39.0;
                let p = [-0.05, py];
                let n = [1.0, 0.0];
                let a = -1.4 + 2.8 * j as f64 / 23.0;
                let vp = [a.cos(), a.sin()];
                let (tw, mode) = point_push(c, p, n, mu, vp);
                assert_ne!(mode, ContactMode::Separating);
                let half = f64::atan(mu);
                let moment = |d: [f64; 2]| (p[0] * d[1] - p[1] * d[0]).signum();
                let votes = moment([half.cos(), half.sin()])
                    + moment([half.cos(), -half.sin()])
                    + moment(vp);
                if votes == 0.0 || tw.omega.abs() < 1e-12 {
                    continue;
                }
                assert_eq!(
                    tw.omega.signum(),
                    votes.signum(),
                    "p {p:?} vp {vp:?} mu {mu}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 2000, "{checked}");
}

/// A sticking push matches the ellipsoid model's closed form; checked against a brute-force
/// search over the friction cone for the force whose contact velocity points along the push.
#[test]
fn sticking_push_matches_closed_form() {
    let c = 0.035;
    let p = [-0.05, 0.02];
    let n = [1.0, 0.0];
    let mu = 0.6;
    let vp = [1.0, 0.15];
    let (tw, mode) = point_push(c, p, n, mu, vp);
    assert_eq!(mode, ContactMode::Sticking);
    assert_eq!(tw, sticking_twist(c, p, vp));
    // Brute force: the force angle in the cone whose contact velocity is parallel to vp.
    let half = f64::atan(mu);
    let mut best = (f64::INFINITY, 0.0);
    for k in 0..=200_000 {
        let a = -half + 2.0 * half * k as f64 / 200_000.0;
        let t = twist_for_force(c, p, [a.cos(), a.sin()]);
        let v = t.point_velocity(p);
        let err = (v[0] * vp[1] - v[1] * vp[0]).abs() / (v[0].hypot(v[1]) * vp[0].hypot(vp[1]));
        if err < best.0 {
            best = (err, a);
        }
    }
    let t = twist_for_force(c, p, [best.1.cos(), best.1.sin()]);
    let v = t.point_velocity(p);
    let scale = vp[0] / v[0];
    assert!(
        (t.vx * scale - tw.vx).abs() < 1e-4,
        "{t:?}·{scale} vs {tw:?}"
    );
    assert!((t.vy * scale - tw.vy).abs() < 1e-4);
    assert!((t.omega * scale - tw.omega).abs() < 1e-2);
    // And the contact point indeed moves with the pusher.
    let vc = tw.point_velocity(p);
    assert!((vc[0] - vp[0]).abs() < 1e-12 && (vc[1] - vp[1]).abs() < 1e-12);
}

/// Outside the motion cone the contact slides: normal velocities agree, tangential ones not.
#[test]
fn steep_push_slides() {
    let c = 0.035;
    let p = [-0.05, 0.0];
    let n = [1.0, 0.0];
    let vp = [0.2, 1.0];
    let (tw, mode) = point_push(c, p, n, 0.2, vp);
    assert_eq!(mode, ContactMode::Sliding);
    let vc = tw.point_velocity(p);
    assert!((vc[0] - vp[0]).abs() < 1e-12, "normal {vc:?} vs {vp:?}");
    assert!(vc[1] < vp[1] - 0.1, "slides: {vc:?}");
    // The force is on the cone edge: f ∝ (1, 0.2); the COF moves along it.
    assert!((tw.vy / tw.vx - 0.2).abs() < 1e-12);
}

/// An object the pusher does not touch, or moves away from, never moves.
#[test]
fn unpushed_object_never_moves() {
    let mut s = slider(0.5);
    let before = s.pose;
    let r = 0.04;
    // Passing by 1 mm clear of the top face.
    assert_eq!(
        s.push([0.3, 0.5 + 0.05 + r + 0.001], [0.7, 0.591], r, 0.001),
        None
    );
    // Touching, but pulling away.
    let mode = s.push([0.5 - 0.05 - r, 0.5], [0.3, 0.5], r, 0.001);
    assert!(
        matches!(mode, None | Some(ContactMode::Separating)),
        "{mode:?}"
    );
    assert_eq!(s.pose, before);
}

proptest! {
    /// Whatever the push, the pusher never ends inside the slider and the slider only moves
    /// when touched.
    #[test]
    fn never_interpenetrates(y in 0.42f64..0.58, ang in -1.2f64..1.2, len in 0.0f64..0.2, mu in 0.0f64..1.0) {
        let mut s = slider(mu);
        let r = 0.04;
        let from = [0.5 - 0.05 - r - 0.005, y];
        let to = [from[0] + len * ang.cos(), from[1] + len * ang.sin()];
        let mode = s.push(from, to, r, 0.0005);
        prop_assert!(s.gap(to, r) >= -1e-9);
        if mode.is_none() {
            prop_assert_eq!(s.pose, Pose::new(0.5, 0.5, 0.0));
        }
    }
}

/// parry's boundary projection and inside test against the closed form for a square, and
/// against dense sampling of the boundary of a non-convex outline.
#[test]
fn boundary_distance_and_inside_test() {
    use pushbot_sim::pushing::{closest_boundary_point, point_in_polygon};
    let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let (q, d) = closest_boundary_point([0.3, 0.2], &sq);
    assert!((d - 0.2).abs() < 1e-12 && (q[0] - 0.3).abs() < 1e-12 && q[1].abs() < 1e-12);
    let (_, d) = closest_boundary_point([2.0, 2.0], &sq);
    assert!((d - 2f64.sqrt()).abs() < 1e-12);
    assert!(point_in_polygon([0.5, 0.5], &sq) && !point_in_polygon([1.5, 0.5], &sq));
    let l = [
        [0.0, 0.0],
        [2.0, 0.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];
    for p in [[1.5, 1.5], [0.5, 0.5], [1.2, 0.9], [-0.5, 3.0], [1.0, 1.0]] {
        let mut best = f64::INFINITY;
        for k in 0..l.len() {
            let (a, b) = (l[k], l[(k + 1) % l.len()]);
            for s in 0..=2000 {
                let t = f64::from(s) / 2000.0;
                let x = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
                best = best.min((x[0] - p[0]).hypot(x[1] - p[1]));
            }
        }
        let (_, d) = closest_boundary_point(p, &l);
        assert!(d <= best + 1e-12 && best - d < 1e-3, "{p:?}: {d} vs {best}");
    }
    assert!(!point_in_polygon([1.5, 1.5], &l) && point_in_polygon([1.2, 0.9], &l));
}

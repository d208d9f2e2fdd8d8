//! The stable-pushing planner (Lynch & Mason 1996 §4) on the five presets, each plan checked
//! step by step by an independent validator; the bucketed OPEN list against a binary heap; and
//! the planner's optimality claim (§4.3) against an exhaustive search on small instances. Scenes
//! written inline use the shared scene format with a `[stable]` section.

/// The slider of Fig. 12 (a 20 × 14 cm box with one corner cut), its object frame at its area
/// centroid (the centre of friction of a uniform support).
const SLIDER: &str = "[[-0.09691358024691357, -0.06790123456790124], [0.10308641975308644, -0.06790123456790124], [0.10308641975308644, 0.03209876543209876], [0.05308641975308642, 0.07209876543209877], [-0.09691358024691357, 0.07209876543209877]]";

use pushbot::mechanics::stable::stable;
use pushbot::mechanics::{V2, V3, cor};
use pushbot::planner::stable::presets::{CostOverride, PRESETS, load_scene, scene_from_toml};
use pushbot::planner::stable::pusher::PusherKind;
use pushbot::planner::stable::search::{Heuristic, Plan, brute_force_cost, exact_goal, step_cost};
use pushbot::planner::stable::{Pose, Problem, Queue, angle_diff, plan, plan_with};

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

fn hull(p: &[V2]) -> Vec<V2> {
    pushbot::mechanics::convex_hull(p)
}

/// An independent check of a plan against its problem: continuity, every step a constant push
/// inside the freshly computed STABLE set of its edge and inside the pusher's kinematics,
/// pusher + slider collision-free at 50 poses along every step, the end in the goal
/// neighbourhood, and the cost equal to the a/b/c sum recomputed from the steps.
fn validate(p: &Problem, plan: &Plan) {
    assert!(plan.found);
    assert!(!plan.steps.is_empty());
    let mut q = p.start;
    let mut prev: Option<(usize, V3)> = None;
    let mut cost = 0u32;
    let (mut cc, mut ctl) = (0usize, 0usize);
    if let Some(sc) = p.start_contact {
        prev = Some((p.contacts[sc].edge, V3::zeros()));
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
        assert_eq!(cm.edge, s.edge);
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

#[test]
fn planner_finds_valid_plans_on_all_presets() {
    for name in PRESETS {
        let scene = load_scene(name).unwrap();
        let p = scene.problem(CostOverride::default()).unwrap();
        let plan = plan(&p);
        assert!(
            plan.found,
            "{name}: no plan ({} nodes)",
            plan.nodes_expanded
        );
        validate(&p, &plan);
        if name == "fig16" || name == "fig17" || name == "fig18" {
            assert!(
                plan.contact_changes >= 1,
                "{name}: the task needs both edges"
            );
        }
    }
}

#[test]
fn bucket_queue_matches_binary_heap() {
    for name in ["fig13", "fig17"] {
        let p = load_scene(name)
            .unwrap()
            .problem(CostOverride::default())
            .unwrap();
        let a = plan_with(&p, Queue::Buckets);
        let b = plan_with(&p, Queue::Heap);
        assert_eq!(a.found, b.found);
        assert_eq!(a.cost, b.cost, "{name}");
    }
}

#[test]
fn exact_goal_variant_ends_on_the_goal() {
    // §4.5: back up, then one stable push exactly onto the goal (omnidirectional robot, arm).
    for name in ["fig13", "fig18"] {
        let p = load_scene(name)
            .unwrap()
            .problem(CostOverride::default())
            .unwrap();
        let pl = plan(&p);
        let e = exact_goal(&p, &pl).expect("a pusher with a 2-D stable set can finish exactly");
        validate(&p, &e);
    }
}

/// Distance from a point to a convex polygon (0 inside).
fn dist_to_convex(p: V2, poly: &[V2]) -> f64 {
    let n = poly.len();
    let inside = (0..n).all(|i| {
        let e = poly[(i + 1) % n] - poly[i];
        e.x * (p.y - poly[i].y) - e.y * (p.x - poly[i].x) >= 0.0
    });
    if inside {
        return 0.0;
    }
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let d = b - a;
            let t = ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            (a + d * t - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// §4.6 (beyond the paper): a differential-drive robot with a flat front plate must go around
/// the slider to push it back; the plan holds that transit path, which keeps the robot's
/// turning disk clear of the obstacles and the slider between its two straight legs.
#[test]
fn mobile_pusher_contact_change_has_a_free_transit_path() {
    let text = format!(
        r#"name = "dd"
[table]
width = 1.6
height = 1.2
[[obstacles]]
outline = [[0.9, 0.0], [1.1, 0.0], [1.1, 0.5], [0.9, 0.5]]
[[objects]]
id = "slider"
outline = {SLIDER}
pose = {{ x = 0.5, y = 0.4, theta = 0.0 }}
mass = 0.1
support_friction = 0.3
pusher_friction = 0.5
[[goals]]
object = "slider"
pose = {{ x = 0.5, y = 0.3, theta = 0.0 }}
[stable]
object = "slider"
edges = [0, 3]
start_edge = 0
goal_xy_frac = 0.1
goal_theta_deg = 2.0
pusher = {{ kind = "diff-drive", width = 0.12, depth = 0.1, axle_offset = 0.05, plate_width = 0.2 }}
planner = {{ a = 1, b = 1, c = 5, step_frac = 0.3, grid_xy_frac = 1.0, grid_theta_deg = 6.0, fine_radius_frac = 1.0, fine_factor = 3.0 }}
"#
    );
    let p = scene_from_toml(&text, "dd.toml")
        .unwrap()
        .problem(CostOverride::default())
        .unwrap();
    let pl = plan(&p);
    assert!(pl.found);
    validate(&p, &pl);
    assert!(pl.contact_changes >= 1 && !pl.transits.is_empty());
    let r = p.pusher.turning_radius_disk();
    for t in &pl.transits {
        let w: Vec<V2> = t.waypoints.iter().map(|q| V2::new(q[0], q[1])).collect();
        assert!(w.len() >= 4);
        let slider: Vec<V2> = hull(&p.slider.vertices)
            .iter()
            .map(|v| t.at.apply(*v))
            .collect();
        let len: f64 = w.windows(2).map(|s| (s[1] - s[0]).norm()).sum();
        assert!((len - t.length).abs() < 1e-9);
        // The middle part (stand-off to stand-off) is driven as the turning disk.
        for seg in w[1..w.len() - 1].windows(2) {
            for k in 0..=20 {
                let c = seg[0] + (seg[1] - seg[0]) * (k as f64 / 20.0);
                assert!(
                    dist_to_convex(c, &slider) >= r - 1e-6,
                    "transit disk hits the slider at {c:?}"
                );
                for o in &p.world.obstacles[p.world.n_walls..] {
                    assert!(
                        dist_to_convex(c, &o.vertices) >= r - 1e-6,
                        "transit disk hits an obstacle"
                    );
                }
                assert!(c.x >= r - 1e-9 && c.y >= r - 1e-9);
            }
        }
    }
    // With a wall of obstacles enclosing the slider's far side, no transit exists and the plan
    // must avoid the contact change.
    let walled = text.replace(
        "[[objects]]",
        "[[obstacles]]\noutline = [[0.0, 0.56], [1.6, 0.56], [1.6, 0.6], [0.0, 0.6]]\n[[objects]]",
    );
    let p = scene_from_toml(&walled, "walled.toml")
        .unwrap()
        .problem(CostOverride::default())
        .unwrap();
    let pl = plan(&p);
    if pl.found {
        validate(&p, &pl);
        for t in &pl.transits {
            assert!(t.waypoints.iter().all(|q| q[1] < 0.56));
        }
    }
}

/// A small open table, slider pushed by an arm on two opposite edges, starting at edge 0.
fn small(goal: [f64; 3], a: u32, b: u32, c: u32) -> Problem {
    let text = format!(
        r#"name = "small"
[table]
width = 1.0
height = 1.0
[[objects]]
id = "s"
outline = {SLIDER}
pose = {{ x = 0.5, y = 0.5, theta = 0.0 }}
mass = 0.1
support_friction = 0.3
pusher_friction = 0.5
[[goals]]
object = "s"
pose = {{ x = {}, y = {}, theta = {} }}
[stable]
object = "s"
edges = [0, 3]
start_edge = 0
goal_xy_frac = 0.1
goal_theta_deg = 3.0
pusher = {{ kind = "arm" }}
planner = {{ a = {a}, b = {b}, c = {c}, step_frac = 0.2, grid_xy_frac = 0.5, grid_theta_deg = 2.0, max_cost = 200, max_nodes = 300000 }}
"#,
        goal[0],
        goal[1],
        goal[2].to_radians()
    );
    scene_from_toml(&text, "small.toml")
        .unwrap()
        .problem(CostOverride::default())
        .unwrap()
}

/// §4.3 claims optimality only for the cost "number of contact changes": then the planner finds
/// the minimum number of contact changes of any feasible path. Checked against an exhaustive
/// search of all control sequences up to 4 steps. For other costs the grid pruning can lose the
/// optimum, so only "never better than the true optimum" is asserted, and the plan is valid.
#[test]
fn optimality_against_exhaustive_search() {
    let goals = [
        [0.5, 0.45, 0.0],
        [0.5, 0.56, 0.0],
        [0.47, 0.45, 5.0],
        [0.55, 0.5, -10.0],
    ];
    let (mut compared, mut equal) = (0, 0);
    for g in goals {
        let p = small(g, 0, 0, 1);
        let pl = plan(&p);
        let bf = brute_force_cost(&p, 4);
        assert!(pl.found, "goal {g:?}");
        // The planner's minimum is over paths of any length, the exhaustive one over ≤ 4 steps.
        if let Some(bf) = bf {
            assert!(
                pl.cost <= bf,
                "goal {g:?}: {} contact changes, exhaustive search {bf}",
                pl.cost
            );
            compared += 1;
            if pl.pushes <= 4 {
                assert_eq!(pl.cost, bf, "goal {g:?}");
                equal += 1;
            }
        }
        validate(&p, &pl);
        let p = small(g, 1, 1, 2);
        let pl = plan(&p);
        if let Some(bf) = brute_force_cost(&p, 4) {
            assert!(
                pl.found && pl.cost >= bf,
                "goal {g:?}: planner {} beats the optimum {bf}",
                pl.cost
            );
            validate(&p, &pl);
        }
    }
    assert!(
        compared >= 3 && equal >= 1,
        "the exhaustive search must reach most goals ({compared}, {equal})"
    );
}

#[test]
fn malformed_scenes_are_clear_errors() {
    let e = scene_from_toml("name = \"x\"\n[table]\nwidth = [1.0\n", "x.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.toml:3:") || e.contains("x.toml:4:"), "{e}");
    let text = format!(
        r#"name = "x"
[table]
width = 1.0
height = 1.0
[[objects]]
id = "s"
outline = {SLIDER}
pose = {{ x = 0.5, y = 0.5, theta = 0.0 }}
mass = 0.1
support_friction = 0.3
pusher_friction = -0.5
[[goals]]
object = "s"
pose = {{ x = 0.5, y = 0.3, theta = 0.0 }}
[stable]
object = "s"
edges = [0]
goal_xy_frac = 0.1
goal_theta_deg = 3.0
pusher = {{ kind = "arm" }}
"#
    );
    let fmt = |t: &str| format!("{:#}", scene_from_toml(t, "x.toml").unwrap_err());
    let e = fmt(&text);
    assert!(
        e.contains("x.toml:11") && e.contains("pusher_friction"),
        "{e}"
    );
    let good = text.replace("pusher_friction = -0.5", "pusher_friction = 0.5");
    assert!(scene_from_toml(&good, "x.toml").is_ok());
    let e = fmt(&good.replace("object = \"s\"\nedges", "object = \"t\"\nedges"));
    assert!(e.contains("stable.object"), "{e}");
    let e = fmt(&good.replace("kind = \"arm\"", "kind = \"tank\""));
    assert!(
        e.contains("stable.pusher.kind") && e.contains("tank"),
        "{e}"
    );
    let e = fmt(&good.replace("edges = [0]", "edges = []"));
    assert!(e.contains("stable.edges"), "{e}");
    let e = fmt(&good.replace("goal_xy_frac", "bogus = 1\ngoal_xy_frac"));
    assert!(e.contains("bogus"), "{e}");
    let e = fmt(good.split("[stable]").next().unwrap());
    assert!(e.contains("[stable]"), "{e}");
    // The old stable-only format (`table = [w, h]`, [task], [pusher]) is refused by name.
    let e = fmt("name = \"x\"\ntable = [1.0, 1.0]\nmu = 0.5\n");
    assert!(
        e.contains("x.toml") && e.contains("no [table] section"),
        "{e}"
    );
    assert!(load_scene("no-such-preset-or-file").is_err());
}

#[test]
fn start_in_collision_is_rejected() {
    // The slider clear of the obstacle, but the robot behind its only pushing edge inside it.
    let text = r#"name = "x"
[table]
width = 1.0
height = 1.0
[[obstacles]]
outline = [[0.4, 0.3], [0.6, 0.3], [0.6, 0.44], [0.4, 0.44]]
[[objects]]
id = "s"
outline = [[-0.1, -0.05], [0.1, -0.05], [0.1, 0.05], [-0.1, 0.05]]
pose = { x = 0.5, y = 0.5, theta = 0.0 }
mass = 0.1
support_friction = 0.3
pusher_friction = 0.5
[[goals]]
object = "s"
pose = { x = 0.5, y = 0.8, theta = 0.0 }
[stable]
object = "s"
edges = [0]
goal_xy_frac = 0.1
goal_theta_deg = 3.0
pusher = { kind = "omni", width = 0.2, depth = 0.12 }
"#;
    let e = scene_from_toml(text, "x.toml")
        .unwrap()
        .problem(CostOverride::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("collide") && e.contains("start"), "{e}");
    // Moved clear, the same scene plans.
    let clear = text.replace("0.3]", "0.1]").replace("0.44]", "0.2]");
    let p = scene_from_toml(&clear, "x.toml")
        .unwrap()
        .problem(CostOverride::default())
        .unwrap();
    let _ = Pose::new(0.0, 0.0, 0.0);
    assert!(plan(&p).found);
}

/// The A* bound never exceeds the number of steps a found plan still takes (admissibility),
/// from every configuration along the plan, on every preset.
#[test]
fn heuristic_is_a_lower_bound_along_found_plans() {
    for name in PRESETS {
        let p = load_scene(name)
            .unwrap()
            .problem(CostOverride::default())
            .unwrap();
        let pl = plan(&p);
        assert!(pl.found, "{name}");
        let h = Heuristic::new(&p);
        let n = pl.steps.len();
        for (i, s) in pl.steps.iter().enumerate() {
            let b = h.steps(&s.from);
            assert!(
                b as usize <= n - i,
                "{name}: step {i}: bound {b} > {}",
                n - i
            );
        }
        // And it is not trivial: from the start it needs a good part of the plan's steps.
        let b0 = h.steps(&p.start) as usize;
        assert!(b0 >= 3 && b0 <= n, "{name}: bound {b0} of {n} steps");
        // The whole bound, with its control-change term, never exceeds the cost the plan
        // still pays after each step.
        let mut rest = pl.cost;
        let mut prev = p.start_contact.map(|c| (c, usize::MAX));
        for (i, s) in pl.steps.iter().enumerate() {
            rest -= step_cost(&p, prev, s.contact, s.control).unwrap();
            prev = Some((s.contact, s.control));
            let turn = h.turns(&s.to, s.to.theta.sin_cos(), s.contact, s.control);
            let bound = h.cost(h.steps(&s.to)) + if turn { p.params.b } else { 0 };
            assert!(
                bound <= rest,
                "{name}: after step {i}: bound {bound} > the {rest} still paid"
            );
        }
        assert_eq!(rest, 0, "{name}: the plan's cost is the sum of its steps'");
    }
}

/// The control-change term of the bound (`Heuristic::turns`) claims only curves that miss the
/// goal neighbourhood: following a control it says misses, sampled finely over a whole turn
/// (or 3 m of translation), never enters it; for configurations backed up along a control
/// from inside the neighbourhood, whose curve does enter, it never says miss.
#[test]
fn control_change_bound_only_claims_curves_that_miss_the_goal() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    for name in ["fig13", "fig15", "fig16"] {
        let p = load_scene(name)
            .unwrap()
            .problem(CostOverride::default())
            .unwrap();
        let h = Heuristic::new(&p);
        let (gx, gt) = (p.params.goal_xy, p.params.goal_theta);
        let (mut misses, mut entering) = (0, 0);
        for i in 0..600 {
            let ci = rng.random_range(0..p.contacts.len());
            let k = rng.random_range(0..p.contacts[ci].steps.len());
            let xi = p.contacts[ci].steps[k];
            // Length of the curve in step units: a whole turn, or 3 m.
            let span = if xi.z.abs() > 1e-12 {
                2.0 * std::f64::consts::PI / xi.z.abs()
            } else {
                3.0 / xi.x.hypot(xi.y)
            };
            let q = if i % 2 == 0 {
                Pose::new(
                    p.goal.x + rng.random_range(-0.4..0.4),
                    p.goal.y + rng.random_range(-0.4..0.4),
                    p.goal.theta + rng.random_range(-1.5..1.5),
                )
            } else {
                // From a pose inside the neighbourhood, back along the control.
                let inside = Pose::new(
                    p.goal.x + rng.random_range(-gx..gx) * 0.99,
                    p.goal.y + rng.random_range(-gx..gx) * 0.99,
                    p.goal.theta + rng.random_range(-gt..gt) * 0.99,
                );
                assert!(p.in_goal(&inside));
                inside.integrate(&(xi * -rng.random_range(0.0..span.min(20.0))))
            };
            let turn = h.turns(&q, q.theta.sin_cos(), ci, k);
            let n = 20_000;
            let enters =
                (0..=n).any(|j| p.in_goal(&q.integrate(&(xi * (span * j as f64 / n as f64)))));
            if i % 2 == 1 {
                assert!(
                    !turn,
                    "{name}: q {q:?} control {ci}/{k} enters the goal, bound says miss"
                );
                entering += 1;
            }
            if turn {
                assert!(
                    !enters,
                    "{name}: q {q:?} control {ci}/{k}: said miss, but enters"
                );
                misses += 1;
            }
        }
        assert!(
            misses > 100 && entering > 100,
            "{name}: {misses} misses, {entering} entering"
        );
    }
}

/// The precomputed swept-shape test gives the same answer as conservative advancement, for
/// steps of every control from configurations scattered over the table (many near obstacles).
#[test]
fn swept_shape_test_agrees_with_conservative_advancement() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for name in ["fig13", "fig16", "fig18"] {
        let p = load_scene(name)
            .unwrap()
            .problem(CostOverride::default())
            .unwrap();
        let (w, h) = p.world.table;
        let (mut free, mut blocked) = (0, 0);
        for _ in 0..1500 {
            let q = Pose::new(
                rng.random_range(0.0..w),
                rng.random_range(0.0..h),
                rng.random_range(-3.2..3.2),
            );
            for cm in &p.contacts {
                if !cm.body.free_at(&p.world, &q) {
                    continue;
                }
                for (k, xi) in cm.steps.iter().enumerate() {
                    let a = cm.body.step_free(&p.world, &q, xi);
                    let b = cm.body.step_free_swept(&p.world, &q, xi, &cm.swept[k]);
                    assert_eq!(a, b, "{name}: q {q:?} control {k}");
                    if a { free += 1 } else { blocked += 1 }
                }
                for (k, xi) in cm.fine_steps.iter().enumerate() {
                    let a = cm.body.step_free(&p.world, &q, xi);
                    let b = cm.body.step_free_swept(&p.world, &q, xi, &cm.fine_swept[k]);
                    assert_eq!(a, b, "{name}: q {q:?} fine control {k}");
                }
            }
        }
        assert!(
            free > 100 && blocked > 50,
            "{name}: {free} free, {blocked} blocked"
        );
    }
}

/// A scene file in the shared format, written out from a preset's planner description, gives
/// the same problem as the preset: same plan cost and pushes.
#[test]
fn shared_format_scene_plans_like_the_preset() {
    let preset = load_scene("fig15").unwrap();
    let raw: Vec<V2> = preset.objects[0]
        .polygon
        .iter()
        .map(|p| V2::new(p[0], p[1]))
        .collect();
    let c = pushbot::mechanics::centroid(&raw);
    let outline: Vec<[f64; 2]> = raw.iter().map(|p| [p.x - c.x, p.y - c.y]).collect();
    let (s, g) = (preset.task.start, preset.task.goal);
    let mut text = format!(
        "name = \"fig15-shared\"\n[table]\nwidth = {}\nheight = {}\n",
        preset.table[0], preset.table[1]
    );
    for o in &preset.obstacles {
        text += &format!("[[obstacles]]\noutline = {:?}\n", o.polygon);
    }
    text += &format!(
        "[[objects]]\nid = \"slider\"\noutline = {outline:?}\npose = {{ x = {}, y = {}, theta = {} }}\nmass = 0.1\nsupport_friction = 0.3\npusher_friction = {}\n\
         [[goals]]\nobject = \"slider\"\npose = {{ x = {}, y = {}, theta = {} }}\n\
         [stable]\nobject = \"slider\"\nedges = [0]\ngoal_xy_frac = {}\ngoal_theta_deg = {}\n\
         pusher = {{ kind = \"car\", width = 0.2, depth = 0.18, axle_offset = 0.15, min_turning_radius = 0.3 }}\n\
         planner = {{ a = 1, b = 5, c = \"inf\", step_frac = 0.3, grid_xy_frac = 1.0, grid_theta_deg = 6.0, fine_radius_frac = 1.0, fine_factor = 3.0, max_cost = 3000, max_nodes = 300000 }}\n",
        s[0],
        s[1],
        s[2].to_radians(),
        preset.mu,
        g[0],
        g[1],
        g[2].to_radians(),
        preset.task.goal_xy_frac,
        preset.task.goal_theta_deg,
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fig15-shared.toml");
    std::fs::write(&path, &text).unwrap();
    let shared = load_scene(path.to_str().unwrap()).unwrap();
    let a = plan(&preset.problem(CostOverride::default()).unwrap());
    let b = plan(&shared.problem(CostOverride::default()).unwrap());
    assert!(a.found && b.found);
    assert_eq!((a.cost, a.pushes), (b.cost, b.pushes));
    // A field error in the [stable] section names the file and the line.
    std::fs::write(&path, text.replace("edges = [0]", "edges = \"zero\"")).unwrap();
    let e = format!("{:#}", load_scene(path.to_str().unwrap()).unwrap_err());
    let line = text.lines().position(|l| l.starts_with("edges")).unwrap() + 1;
    assert!(e.contains(&format!("fig15-shared.toml:{line}:")), "{e}");
}

//! The stable-pushing planner (Lynch & Mason 1996 §4) on the five presets, each plan checked
//! step by step by an independent validator; the bucketed OPEN list against a binary heap; and
//! the planner's optimality claim (§4.3) against an exhaustive search on small instances. Scenes
//! written inline use the shared scene format with a `[stable]` section.
//!
//! The A* bound, the optimality check against exhaustive search and the swept-shape test are
//! in `stable_search.rs`.

use pushbot::mechanics::V2;
use pushbot::planner::stable::presets::{CostOverride, PRESETS, load_scene, scene_from_toml};
use pushbot::planner::stable::search::exact_goal;
use pushbot::planner::stable::{Pose, Queue, plan, plan_with};

mod stable_common;

use stable_common::{SLIDER, hull, validate};

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

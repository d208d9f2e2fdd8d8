//! Every "no plan" of the stable-push planner carries a reason, and the reason holds in the
//! scene: on 100 seeded random scenes of each pusher kind, each reason is checked by an
//! independent test of what it claims (the obstacles it names do cut the start off, or overlap
//! the slider at the goal, or block every push from the start; the budget it names was spent,
//! and raising it changes the search; the empty table it says has no plan has none). A scene
//! cut in two on purpose names the obstacle that cuts it, in the text, in `--json` and with
//! the explored tree drawn by `--svg`.

use pushbot::planner::stable::collision::Body;
use pushbot::planner::stable::no_plan::{NoPlan, why, without_obstacles};
use pushbot::planner::stable::random_scene::{RandomPusher, random_scene};
use pushbot::planner::stable::reach::unreachable;
use pushbot::planner::stable::search::goal_measure;
use pushbot::planner::stable::{Problem, plan};

/// Scenes per pusher kind.
const SCENES: u64 = 100;

/// Check `reason` against the scene of `p`; the failures, if any.
fn check(p: &Problem, reason: &NoPlan, nodes: usize) -> Result<(), String> {
    let named = |names: &[String]| -> Vec<usize> {
        (0..p.world.obstacles.len())
            .filter(|&i| names.contains(&p.world.names[i]))
            .collect()
    };
    match reason {
        NoPlan::Unreachable(u) => {
            if u.names.is_empty() {
                return Err("names no obstacle".into());
            }
            // The named obstacles alone (with the walls) still cut the start off.
            let mut q = p.clone();
            q.world = p
                .world
                .only(|i| i < p.world.n_walls || u.blockers.contains(&i));
            if unreachable(&q).is_none() {
                return Err(format!("{:?} alone do not cut the start off", u.names));
            }
        }
        NoPlan::GoalBlocked { blockers } => {
            if blockers.is_empty() {
                return Err("names no obstacle".into());
            }
            // Each named obstacle (some part of it) overlaps the slider at the goal.
            let slider = Body::new(std::slice::from_ref(&p.slider.vertices));
            for name in blockers {
                let overlaps = named(std::slice::from_ref(name))
                    .iter()
                    .any(|&k| !slider.free_at(&p.world.only(|j| j == k), &p.goal));
                if !overlaps {
                    return Err(format!("{name} does not overlap the slider at the goal"));
                }
            }
        }
        NoPlan::StartBlocked { contacts } => {
            for (edge, names) in contacts {
                if names.is_empty() {
                    return Err(format!("edge {edge}: names no obstacle"));
                }
                let ci = p
                    .contacts
                    .iter()
                    .position(|c| c.label == *edge)
                    .ok_or(format!("no contact on edge {edge}"))?;
                let cm = &p.contacts[ci];
                let free = cm.body.free_at(&p.world, &p.start)
                    && p.steps_at(ci, &p.start)
                        .iter()
                        .any(|xi| cm.body.step_free(&p.world, &p.start, xi));
                if free {
                    return Err(format!("edge {edge}: a push from the start is free"));
                }
            }
        }
        NoPlan::NodeLimit { nodes: n, .. } => {
            if *n != p.params.max_nodes || nodes != p.params.max_nodes {
                return Err(format!(
                    "{n} / {nodes} nodes, budget {}",
                    p.params.max_nodes
                ));
            }
        }
        NoPlan::CostLimit { max_cost, .. } => {
            let mut q = p.clone();
            q.params.max_cost = max_cost.saturating_mul(10);
            let more = plan(&q);
            if !more.found && more.nodes_expanded <= nodes {
                return Err("raising max_cost changes nothing".into());
            }
        }
        NoPlan::TurnsTooWide { .. } => {
            if plan(&without_obstacles(p)).found {
                return Err("the empty table has a plan".into());
            }
        }
        NoPlan::Exhausted {
            nodes: n, closest, ..
        } => {
            if *n >= p.params.max_nodes {
                return Err("exhausted at the node budget".into());
            }
            let c = closest.ok_or("no closest approach")?;
            if goal_measure(p, &c.pose) <= 1.0 {
                return Err("the closest approach is in the goal neighbourhood".into());
            }
            if !plan(&without_obstacles(p)).found {
                return Err("the empty table has no plan either: a turning limit".into());
            }
        }
    }
    Ok(())
}

#[test]
fn every_random_no_plan_has_a_reason_that_holds() {
    let mut failures = Vec::new();
    for kind in RandomPusher::ALL {
        let (mut none, mut kinds) = (0, std::collections::BTreeMap::<String, usize>::new());
        for seed in 0..SCENES {
            let rs = random_scene(seed, kind).expect("a random scene");
            let p = rs.problem().expect("its problem");
            let pl = plan(&p);
            let reason = why(&p, &pl);
            if pl.found {
                if reason.is_some() {
                    failures.push(format!("{}: a plan and a reason", rs.name()));
                }
                continue;
            }
            none += 1;
            let Some(reason) = reason else {
                failures.push(format!("{}: no plan and no reason", rs.name()));
                continue;
            };
            let name = format!("{reason:?}");
            *kinds
                .entry(name.split([' ', '(', '{']).next().unwrap_or("").to_string())
                .or_default() += 1;
            if let Err(e) = check(&p, &reason, pl.nodes_expanded) {
                failures.push(format!("{}: {reason}: {e}", rs.name()));
            }
        }
        eprintln!(
            "{}: {none} of {SCENES} without a plan: {kinds:?}",
            kind.name()
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A table cut in two by a wall of an obstacle, the slider on one side, its goal on the other.
const CUT_IN_TWO: &str = r#"
name = "cut-in-two"
[table]
width = 1.2
height = 0.9
[robot]
start = { x = 0.1, y = 0.1, theta = 0.0 }
[[obstacles]]
outline = [[0.3, 0.5], [0.4, 0.5], [0.4, 0.6], [0.3, 0.6]]
[[obstacles]]
outline = [[0.58, 0.0], [0.62, 0.0], [0.62, 0.9], [0.58, 0.9]]
[[objects]]
id = "box"
outline = [[-0.06, -0.04], [0.06, -0.04], [0.06, 0.04], [-0.06, 0.04]]
pose = { x = 0.3, y = 0.3, theta = 0.0 }
mass = 0.1
support_friction = 0.3
pusher_friction = 0.5
[[goals]]
object = "box"
pose = { x = 0.9, y = 0.45, theta = 0.0 }
[stable]
object = "box"
edges = [0, 1, 2, 3]
goal_xy_frac = 0.25
goal_theta_deg = 5.0
pusher = { kind = "omni", width = 0.1, depth = 0.08 }
planner = { a = 1, b = 5, c = 10, step_frac = 0.3, grid_xy_frac = 0.5, grid_theta_deg = 6.0, max_cost = 3000, max_nodes = 100000 }
"#;

fn pushbot(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args(args)
        .output()
        .expect("run pushbot")
}

#[test]
fn a_scene_cut_in_two_names_the_obstacle_that_cuts_it() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let scene = dir.path().join("cut.toml");
    std::fs::write(&scene, CUT_IN_TWO).expect("write the scene");
    let svg = dir.path().join("cut.svg");
    let (scene, svg_s) = (scene.to_str().unwrap(), svg.to_str().unwrap());
    let out = pushbot(&["plan", "stable", "--scene", scene, "--svg", svg_s]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{text}");
    assert!(text.contains("unreachable"), "{text}");
    assert!(text.contains("obstacles[1]"), "{text}");
    let json = pushbot(&["--json", "plan", "stable", "--scene", scene]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).expect("JSON");
    let reason = v["no_plan_reason"].as_str().expect("a reason");
    assert!(reason.contains("obstacles[1]"), "{reason}");
    // Unreachable is decided before the search: there is no tree; a budget of 20 nodes on a
    // scene that has a plan leaves one, and says which option raises the budget.
    let budget = pushbot(&[
        "plan",
        "stable",
        "--scene",
        "fig13",
        "--max-nodes",
        "20",
        "--svg",
        svg_s,
    ]);
    let text = String::from_utf8_lossy(&budget.stdout);
    assert_eq!(budget.status.code(), Some(1), "{text}");
    assert!(text.contains("--max-nodes"), "{text}");
    let drawn = std::fs::read_to_string(&svg).expect("the drawing");
    let tree = drawn
        .split("id=\"explored\"")
        .nth(1)
        .expect("the explored tree is drawn");
    let lines = tree
        .split("</g>")
        .next()
        .unwrap_or("")
        .matches("<line")
        .count();
    assert!(lines >= 19, "{lines} edges of the explored tree drawn");
}

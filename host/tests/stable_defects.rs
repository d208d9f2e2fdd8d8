//! The stable planner's known defects (D1–D8), one test each: every test failed
//! before its fix. Scenes are written inline in the shared scene format with a `[stable]`
//! section.

use pushbot::mechanics::controllability::theorem7;
use pushbot::mechanics::{LineContact, V2};
use pushbot::planner::stable::presets::{CostOverride, scene_from_toml};
use pushbot::planner::stable::{Problem, plan};

mod stable_common;

use stable_common::{SLIDER, validate};

/// A scene on a `w × h` table with the given obstacles (TOML `[[obstacles]]` blocks), the
/// slider `outline` at `start`, its goal `goal` and the `[stable]` line `stable`.
fn scene(
    w: f64,
    h: f64,
    obstacles: &str,
    outline: &str,
    start: [f64; 3],
    goal: [f64; 3],
    stable: &str,
) -> String {
    format!(
        r#"name = "defect"
[table]
width = {w}
height = {h}
{obstacles}
[[objects]]
id = "s"
outline = {outline}
pose = {{ x = {}, y = {}, theta = {} }}
mass = 0.1
support_friction = 0.3
pusher_friction = 0.5
[[goals]]
object = "s"
pose = {{ x = {}, y = {}, theta = {} }}
[stable]
object = "s"
goal_xy_frac = 0.25
goal_theta_deg = 3.0
{stable}
"#,
        start[0], start[1], start[2], goal[0], goal[1], goal[2]
    )
}

fn problem(text: &str) -> anyhow::Result<Problem> {
    scene_from_toml(text, "defect.toml")?.problem(CostOverride::default())
}

/// The Fig. 12 slider's vertices as given (counter-clockwise).
fn slider_vertices() -> Vec<[f64; 2]> {
    serde_json::from_str(SLIDER).unwrap()
}

/// D1: a clockwise outline is stored counter-clockwise, but the plan names the edges as the
/// user numbered them: `edges = [0]` on the clockwise outline `[v0, v4, v3, v2, v1]` pushes the
/// edge from v0 to v4 (the slider's left side), and every step says edge 0.
#[test]
fn d1_clockwise_outline_keeps_the_users_edge_numbers() {
    let v = slider_vertices();
    let cw = [v[0], v[4], v[3], v[2], v[1]];
    let text = scene(
        1.2,
        1.0,
        "",
        &format!("{cw:?}"),
        [0.3, 0.5, 0.0],
        [0.6, 0.5, 0.0],
        "edges = [0]\npusher = { kind = \"arm\" }\nplanner = { a = 1, b = 5, c = \"inf\" }",
    );
    let p = problem(&text).unwrap();
    let pl = plan(&p);
    assert!(pl.found);
    validate(&p, &pl);
    assert!(
        pl.steps.iter().all(|s| s.edge == 0),
        "steps name edges {:?}, the user's edge was 0",
        pl.steps.iter().map(|s| s.edge).collect::<Vec<_>>()
    );
    // The contact lies on the user's edge 0: from v0 to v4, x = −0.0969 (object frame = centre
    // of friction frame up to the centroid shift, which is 0 here: the outline is centred).
    let c = &p.contacts[0].placement.contact;
    for q in [c.a, c.b] {
        assert!((q.x - v[0][0]).abs() < 1e-6, "contact at {q:?}");
    }
}

/// A U-shaped obstacle open to the left: its bay (x 0.5–0.8, y 0.35–0.65) holds the goal.
const U_OBSTACLE: &str = "[[obstacles]]\noutline = [[0.45, 0.3], [0.85, 0.3], [0.85, 0.7], [0.45, 0.7], [0.45, 0.65], [0.8, 0.65], [0.8, 0.35], [0.45, 0.35]]";

/// D2: a non-convex obstacle is kept exact: the slider is pushed into the bay of a U.
#[test]
fn d2_slider_is_pushed_into_the_bay_of_a_u() {
    let text = scene(
        1.2,
        1.0,
        U_OBSTACLE,
        SLIDER,
        [0.2, 0.5, 0.0],
        [0.66, 0.5, 0.0],
        "edges = [4]\npusher = { kind = \"arm\" }\nplanner = { a = 1, b = 5, c = \"inf\" }",
    );
    let p = problem(&text).unwrap();
    let pl = plan(&p);
    assert!(pl.found, "no plan into the U's bay");
    validate(&p, &pl);
}

/// D3: a differential drive on a robot with a round bumper (no `[robot] front_plate`, no
/// `plate_width`) is refused with a clear error, not planned as a plate; with a plate it plans.
#[test]
fn d3_round_bumper_is_refused() {
    let text = scene(
        1.2,
        1.0,
        "",
        SLIDER,
        [0.3, 0.5, 0.0],
        [0.6, 0.5, 0.0],
        "edges = [4]\npusher = { kind = \"diff-drive\" }\nplanner = { a = 1, b = 5, c = \"inf\" }",
    );
    let e = format!("{:#}", problem(&text).unwrap_err());
    assert!(
        e.contains("round bumper") && e.contains("front_plate"),
        "error: {e}"
    );
    let plated = text.replace(
        "[[objects]]",
        "[robot]\nstart = { x = 1.0, y = 0.15, theta = 0.0 }\nfront_plate = { width = 0.12, offset = 0.06 }\n[[objects]]",
    );
    assert!(problem(&plated).is_ok());
}

/// D4: the robot's problem for a scene honours its `[stable]` section: edges, start edge,
/// contact-change cost, goal tolerances and the robot's own plate.
#[test]
fn d4_robot_problem_honours_the_scene_stable_section() {
    use pushbot::planner::stable::robot::robot_problem_scene;
    let text = scene(
        1.2,
        1.0,
        "[robot]\nstart = { x = 1.0, y = 0.15, theta = 0.0 }\nfront_plate = { width = 0.1, offset = 0.05 }",
        SLIDER,
        [0.3, 0.5, 0.0],
        [0.6, 0.5, 0.0],
        "edges = [4, 1]\nstart_edge = 1\npusher = { kind = \"omni\", width = 0.2, depth = 0.12 }\nplanner = { a = 1, b = 5, c = 7 }",
    )
    .replace("goal_theta_deg = 3.0", "goal_theta_deg = 5.0");
    let dir = std::env::temp_dir().join(format!("stable-d4-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("d4.toml");
    std::fs::write(&file, &text).unwrap();
    let (_, p) = robot_problem_scene(file.to_str().unwrap()).unwrap();
    let edges: Vec<usize> = p.contacts.iter().map(|c| c.edge).collect();
    assert_eq!(edges, vec![4, 1]);
    assert_eq!(p.start_contact, Some(1));
    assert_eq!(p.params.c, Some(7));
    assert!((p.params.goal_theta - 5f64.to_radians()).abs() < 1e-12);
    // The pusher is the robot: a differential drive with the scene's plate.
    assert!(matches!(
        p.pusher.kind,
        pushbot::planner::stable::pusher::PusherKind::DiffDrive
    ));
    assert_eq!(p.pusher.plate_width, Some(0.1));
    assert!((p.pusher.axle_offset - 0.05).abs() < 1e-12);
    std::fs::remove_dir_all(&dir).ok();
}

/// D5: Theorem 7 is decided exactly. Two line contacts whose open arcs of pure forces (width
/// `w` each) sit `π + δ` apart leave a largest gap of `π + |δ| − w`: they positively span the
/// plane iff `|δ| < w`. A test on 64 samples per arc misses spans with `|δ|` within `w/32`
/// of `w`.
#[test]
fn d5_theorem7_is_exact_at_the_boundary() {
    let h = 0.1f64; // contact half-length at distance 1 from the centre of friction
    let w = 2.0 * h.atan();
    let rot = |p: V2, a: f64| V2::new(a.cos() * p.x - a.sin() * p.y, a.sin() * p.x + a.cos() * p.y);
    let pair = |delta: f64| {
        // Below the centre of friction, pushing up (+y); above it, rotated by δ, pushing down.
        let c1 = LineContact {
            edge: 0,
            a: V2::new(-h, -1.0),
            b: V2::new(h, -1.0),
        };
        let c2 = LineContact {
            edge: 1,
            a: rot(V2::new(h, 1.0), delta),
            b: rot(V2::new(-h, 1.0), delta),
        };
        [c1, c2]
    };
    for f in [0.0, 0.5, 0.98, 0.99, 0.999] {
        assert!(theorem7(&pair(f * w), 1.0), "δ = {f}·w spans");
        assert!(theorem7(&pair(-f * w), 1.0), "δ = −{f}·w spans");
    }
    for f in [1.0, 1.001, 1.02, 1.5] {
        assert!(!theorem7(&pair(f * w), 1.0), "δ = {f}·w leaves a gap ≥ π");
    }
}

/// D8: a goal walled in by obstacles is found unreachable before the search, with a reason.
#[test]
fn d8_walled_in_goal_is_refused_before_the_search() {
    // A pen of four bars around (0.9, 0.5), 0.36 × 0.36 inside: room for the slider, no way in.
    let pen = "[[obstacles]]\noutline = [[0.68, 0.28], [1.12, 0.28], [1.12, 0.32], [0.68, 0.32]]\n\
               [[obstacles]]\noutline = [[0.68, 0.68], [1.12, 0.68], [1.12, 0.72], [0.68, 0.72]]\n\
               [[obstacles]]\noutline = [[0.68, 0.32], [0.72, 0.32], [0.72, 0.68], [0.68, 0.68]]\n\
               [[obstacles]]\noutline = [[1.08, 0.32], [1.12, 0.32], [1.12, 0.68], [1.08, 0.68]]";
    let text = scene(
        1.4,
        1.0,
        pen,
        SLIDER,
        [0.25, 0.5, 0.0],
        [0.9, 0.5, 0.0],
        "edges = [4, 1]\npusher = { kind = \"arm\" }\nplanner = { a = 1, b = 5, c = 3, max_nodes = 400000 }",
    );
    let p = problem(&text).unwrap();
    let pl = plan(&p);
    assert!(!pl.found);
    assert_eq!(pl.nodes_expanded, 0, "the search ran");
    let why = pushbot::planner::stable::reach::unreachable(&p)
        .map(|u| u.to_string())
        .unwrap_or_default();
    assert!(why.contains("unreachable"), "reason: {why:?}");
    // Open the pen's left bar: the same goal is reachable and planned.
    let open = text.replace(
        "[[obstacles]]\noutline = [[0.68, 0.32], [0.72, 0.32], [0.72, 0.68], [0.68, 0.68]]\n",
        "",
    );
    assert_ne!(open, text);
    let p = problem(&open).unwrap();
    assert!(pushbot::planner::stable::reach::unreachable(&p).is_none());
    let pl = plan(&p);
    assert!(pl.found);
    validate(&p, &pl);
}

/// D7: the goal is tested along each step, not only at its ends. With `a = 0, b = 1` (Fig.
/// 17's kind of costs) and the pusher starting on edge 0, a goal 2.5 steps along one control's
/// curve is reached by that one control: cost 0, the optimum. A search that tests only step
/// ends steps over the small goal neighbourhood and pays control changes to land in it.
#[test]
fn d7_goal_between_step_ends_keeps_the_optimum() {
    let text = scene(
        1.0,
        1.0,
        "",
        SLIDER,
        [0.5, 0.3, 0.0],
        [0.5, 0.6, 0.0],
        "edges = [0, 3]\nstart_edge = 0\npusher = { kind = \"arm\" }\nplanner = { a = 0, b = 1, c = 10, step_frac = 0.2, grid_xy_frac = 0.5, grid_theta_deg = 2.0, max_cost = 40, max_nodes = 200000 }",
    );
    let mut p = problem(&text).unwrap();
    let ci = p.start_contact.unwrap();
    for k in 0..p.contacts[ci].steps.len() {
        let xi = p.contacts[ci].steps[k];
        p.goal = p.start.integrate(&(xi * 2.5));
        p.params.goal_xy = 0.002;
        p.params.goal_theta = 0.3f64.to_radians();
        // The step ends before and after are outside the neighbourhood.
        assert!(!p.in_goal(&p.start.integrate(&(xi * 2.0))));
        assert!(!p.in_goal(&p.start.integrate(&(xi * 3.0))));
        let pl = plan(&p);
        assert!(pl.found, "control {k}: no plan");
        validate(&p, &pl);
        assert_eq!(pl.cost, 0, "control {k}: cost {} > the optimum 0", pl.cost);
    }
}

/// D6: on a concave slider a plate on a hull edge touches what of the slider lies on that
/// edge's line, not just the edge: a U's two prong tops. The line contact is the true one,
/// between the outermost points the plate covers (§3.3: a line contact is two point contacts
/// at its ends). A plate too narrow to reach across the notch keeps to its own prong.
#[test]
fn d6_concave_slider_contact_is_the_true_contact() {
    use pushbot::mechanics::{Slider, centroid};
    use pushbot::planner::stable::pusher::{Pusher, PusherKind};
    let u: Vec<V2> = [
        [0.0, 0.0],
        [0.2, 0.0],
        [0.2, 0.15],
        [0.14, 0.15],
        [0.14, 0.1],
        [0.06, 0.1],
        [0.06, 0.15],
        [0.0, 0.15],
    ]
    .iter()
    .map(|p| V2::new(p[0], p[1]))
    .collect();
    let cof = centroid(&u);
    let slider = Slider::new(&u, cof).unwrap();
    // Edge 2: the right prong's top, (0.2, 0.15) → (0.14, 0.15).
    let wide = Pusher::boxed(PusherKind::Omni, 0.3, 0.1, 0.05, Some(0.3));
    let c = wide.placement(&slider, 2).unwrap().contact;
    let xs = [c.a.x + cof.x, c.b.x + cof.x];
    let (lo, hi) = (xs[0].min(xs[1]), xs[0].max(xs[1]));
    assert!(
        lo.abs() < 1e-9 && (hi - 0.2).abs() < 1e-9,
        "contact from x = {lo} to {hi}, the prongs span 0 to 0.2"
    );
    assert!((c.a.y + cof.y - 0.15).abs() < 1e-9 && (c.b.y + cof.y - 0.15).abs() < 1e-9);
    let narrow = Pusher::boxed(PusherKind::Omni, 0.04, 0.1, 0.05, Some(0.04));
    let c = narrow.placement(&slider, 2).unwrap().contact;
    for p in [c.a, c.b] {
        let x = p.x + cof.x;
        assert!(
            (0.14 - 1e-9..=0.2 + 1e-9).contains(&x),
            "narrow plate at x = {x}"
        );
    }
}

/// A file in the old stable-only format is named as such; a scene with a typo gets the
/// parser's own message, not the old format's.
#[test]
fn the_old_format_is_told_apart_from_a_scene_that_does_not_parse() {
    let old = "table = [1.0, 1.0]\n[task]\nstart = [0.1, 0.1, 0.0]\n";
    let e = scene_from_toml(old, "old.toml").unwrap_err().to_string();
    assert!(e.contains("old.toml") && e.contains("no [table]"), "{e}");
    let good = scene(
        1.2,
        1.0,
        "",
        SLIDER,
        [0.3, 0.5, 0.0],
        [0.9, 0.5, 0.0],
        "edges = [0]\npusher = { kind = \"arm\" }",
    );
    scene_from_toml(&good, "good.toml").unwrap();
    let typo = good.replace("goal_xy_frac", "goal_xy_frak");
    let e = scene_from_toml(&typo, "typo.toml").unwrap_err().to_string();
    assert!(
        !e.contains("no [table]") && e.contains("goal_xy_frak"),
        "{e}"
    );
}

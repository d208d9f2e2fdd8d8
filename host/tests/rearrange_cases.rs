//! The test cases of Ben-Shahar & Rivlin §V-A as scene presets (`bsr-a1` … `bsr-d1`, by their
//! paper names A1 … D1): each test checks what the paper's figure shows, by comparing plans and
//! re-costing them under the other presets' rules; the optimal costs are checked against a
//! brute-force search, and scenes written inline use the shared scene format.

use pushbot::planner::rearrange::cases::{CASES, load_scene, problem_from_toml};
use pushbot::planner::rearrange::{
    Config, Dir, Model, MoveKind, Plan, Problem, RestoreError, cost_map, cost_map_with,
    replay_cost, restore, solve,
};

fn plan_of(name: &str) -> (Problem, Model, Plan) {
    let p = load_scene(name).unwrap();
    let (model, _map, plan) = solve(&p).unwrap();
    (p, model, plan.unwrap_or_else(|e| panic!("{name}: {e}")))
}

fn configs(plan: &Plan) -> Vec<Config> {
    plan.steps.iter().map(|s| s.config.clone()).collect()
}

/// The movables pushed, stage by stage, with repeats of the same movable merged.
fn push_runs(plan: &Plan) -> Vec<u64> {
    let mut runs: Vec<u64> = Vec::new();
    for s in &plan.steps {
        if let MoveKind::Push { pushed } = s.step.kind
            && runs.last() != Some(&pushed)
        {
            runs.push(pushed);
        }
    }
    runs
}

/// Does any pushed movable arrive on a rough cell of problem `p`?
fn pushes_through_rough(p: &Problem, plan: &Plan) -> bool {
    plan.steps.iter().any(|s| match s.step.kind {
        MoveKind::Push { pushed } => (0..p.movables.len()).any(|i| {
            let pl = s.config.movables[i];
            pushed & (1 << i) != 0
                && p.movables[i]
                    .cells_at(pl.o)
                    .iter()
                    .any(|&(x, y)| p.grid.get(pl.x + x, pl.y + y).is_some_and(|c| c.rough > 0))
        }),
        _ => false,
    })
}

fn ends_at_goals(p: &Problem, plan: &Plan) -> bool {
    let last = plan.steps.last().map(|s| &s.config).unwrap_or(&plan.start);
    last.movables
        .iter()
        .zip(&p.goal_movables)
        .all(|(m, g)| g.is_none_or(|g| g == *m))
}

#[test]
fn a1_one_box_at_a_time_a2_two_at_once_is_cheaper() {
    let (p1, _, a1) = plan_of("A1");
    let (p2, _, a2) = plan_of("A2");
    assert!(ends_at_goals(&p1, &a1) && ends_at_goals(&p2, &a2));
    let double = |pl: &Plan| {
        pl.steps
            .iter()
            .any(|s| matches!(s.step.kind, MoveKind::Push { pushed } if pushed.count_ones() == 2))
    };
    assert!(!double(&a1), "A1 may push only one box at a time");
    assert!(double(&a2), "A2 should push both boxes together (Fig. 10)");
    assert!(
        a2.cost < a1.cost,
        "A2 {} should beat A1 {}",
        a2.cost,
        a1.cost
    );
}

#[test]
fn a3_passability_changes_the_route() {
    let (p3, m3, a3) = plan_of("A3");
    let (_, _, a2) = plan_of("A2");
    assert!(ends_at_goals(&p3, &a3));
    assert!(
        pushes_through_rough(&p3, &a2),
        "A2's route crosses A3's rough region"
    );
    assert!(
        !pushes_through_rough(&p3, &a3),
        "A3 should push around the rough region (Fig. 11)"
    );
    let a2_under_a3 =
        replay_cost(&m3, &a2.start, &configs(&a2)).expect("A2's plan is admissible in A3");
    assert!(
        a2_under_a3 > a3.cost,
        "A2's route costs {a2_under_a3} under A3's metric, A3's {}",
        a3.cost
    );
}

#[test]
fn a4_distance_limit_makes_the_robot_fetch_the_second_box() {
    let (p4, _, a4) = plan_of("A4");
    let (_, _, a1) = plan_of("A1");
    assert!(ends_at_goals(&p4, &a4));
    let limit = p4.rules.distance_limit.unwrap() as i32;
    for s in &a4.steps {
        let pushed = match s.step.kind {
            MoveKind::Push { pushed } => pushed,
            _ => 0,
        };
        for (i, m) in s.config.movables.iter().enumerate() {
            if pushed & (1 << i) == 0 {
                let d = (m.x - s.config.robot.0).abs() + (m.y - s.config.robot.1).abs();
                assert!(d <= limit, "robot {d} from a box it is not pushing");
            }
        }
    }
    assert_eq!(
        push_runs(&a1).len(),
        2,
        "without a limit each box is pushed in one go"
    );
    assert!(
        push_runs(&a4).len() >= 3,
        "with the limit the robot alternates between the boxes (Fig. 12)"
    );
    assert!(a4.cost >= a1.cost);
}

#[test]
fn b1_exchange_needs_an_intermediate_placement() {
    let (p, _, b1) = plan_of("B1");
    assert!(ends_at_goals(&p, &b1));
    let row = p.start.movables[0].y;
    assert!(
        b1.steps
            .iter()
            .any(|s| s.config.movables.iter().any(|m| m.y != row)),
        "one box must leave the line the two share (Fig. 13)"
    );
}

#[test]
fn b2_rough_region_changes_the_exchange() {
    let (_, _, b1) = plan_of("B1");
    let (p2, m2, b2) = plan_of("B2");
    assert!(ends_at_goals(&p2, &b2));
    assert!(
        pushes_through_rough(&p2, &b1),
        "B1 uses the region that B2 makes rough"
    );
    assert!(
        !pushes_through_rough(&p2, &b2),
        "B2 avoids the rough region (Fig. 14)"
    );
    let b1_under_b2 =
        replay_cost(&m2, &b1.start, &configs(&b1)).expect("B1's plan is admissible in B2");
    assert!(b1_under_b2 > b2.cost);
}

#[test]
fn c1_small_robot_uses_pushes_the_large_c2_cannot() {
    let (p1, _, c1) = plan_of("C1");
    let (p2, m2, c2) = plan_of("C2");
    assert!(ends_at_goals(&p1, &c1) && ends_at_goals(&p2, &c2));
    assert!(c1.cost < c2.cost, "C1 {} vs C2 {}", c1.cost, c2.cost);
    // C1 pushes the movable south where it starts ...
    let start_u = p1.start.movables[0];
    let mut before = p1.start.clone();
    let mut c1_south_at_start = false;
    for s in &c1.steps {
        if s.step.kind != MoveKind::Transit && s.step.dir == Dir::S && before.movables[0] == start_u
        {
            c1_south_at_start = true;
        }
        before = s.config.clone();
    }
    assert!(
        c1_south_at_start,
        "the small robot pushes south from the start (Fig. 16)"
    );
    // ... which no placement of the large robot can do (Fig. 17).
    let mut nb = Vec::new();
    for r in 0..m2.robot.len() {
        let rp = m2.robot.place[r as usize];
        let c = Config {
            robot: (rp.x, rp.y),
            heading: Dir::E,
            pushing: false,
            movables: vec![start_u],
        };
        if let Some(idx) = m2.pack(&c) {
            m2.neighbours(idx, &mut nb);
            assert!(!nb.iter().any(|s| s.step_is_push() && s.dir == Dir::S));
        }
    }
    let first_push = c2
        .steps
        .iter()
        .find(|s| s.step.kind != MoveKind::Transit)
        .unwrap();
    assert_ne!(
        first_push.step.dir,
        Dir::S,
        "the large robot must first move the movable elsewhere"
    );
}

trait IsPush {
    fn step_is_push(&self) -> bool;
}
impl IsPush for pushbot::planner::rearrange::Step {
    fn step_is_push(&self) -> bool {
        self.kind != MoveKind::Transit
    }
}

#[test]
fn d1_rotational_pushes_in_clutter() {
    let (p, _, d1) = plan_of("D1");
    assert!(ends_at_goals(&p, &d1));
    assert!(
        d1.steps
            .iter()
            .any(|s| matches!(s.step.kind, MoveKind::Rotate { .. }))
    );
    let mut no_rot = p.clone();
    no_rot.rules.rotations = false;
    let (_, _, plan) = solve(&no_rot).unwrap();
    assert_eq!(
        plan.unwrap_err(),
        RestoreError::NoPushingPath,
        "without rotations D1 has no solution (§V-A)"
    );
}

#[test]
fn the_map_is_reused_for_new_starts() {
    let p = load_scene("B1").unwrap();
    let model = Model::new(&p).unwrap();
    let map = cost_map(&model).unwrap();
    let mut solved = 0;
    for idx in (0..model.n_states).step_by(97) {
        match restore(&model, &map, idx) {
            Ok(plan) => {
                solved += 1;
                assert_eq!(Some(plan.cost), map.get(idx));
                assert_eq!(
                    replay_cost(&model, &plan.start, &configs(&plan)),
                    Some(plan.cost)
                );
            }
            Err(e) => assert!(map.get(idx).is_none(), "{e}"),
        }
    }
    assert!(solved > 10);
}

/// Past 2³² configurations the map is built with `u64` indices; on the paper's cases (2 and 3
/// movables, with and without robot memory, 3-DOF in D1) forcing them gives the same map.
#[test]
fn wide_indices_give_the_same_map() {
    for (name, _, _) in CASES {
        let (_, model, _) = plan_of(name);
        assert!(!model.wide(), "{name}");
        let goals = model.goal_states();
        let narrow = cost_map_with::<u32>(&model, &goals).unwrap();
        let wide = cost_map_with::<u64>(&model, &goals).unwrap();
        assert_eq!(
            narrow.stats.states_mapped, wide.stats.states_mapped,
            "{name}"
        );
        assert!(narrow.stats.states_mapped > 100, "{name}");
        assert!(narrow.cost == wide.cost, "{name}: the maps differ");
        let mut o32 = Vec::new();
        let mut o64 = Vec::new();
        for idx in (0..model.n_states).step_by(31) {
            if !model.valid(&model.decode(idx)) {
                continue;
            }
            model.origins(idx as u32, &mut o32);
            model.origins(idx, &mut o64);
            let o32: Vec<(u64, u32)> = o32.iter().map(|&(q, c)| (q as u64, c)).collect();
            assert_eq!(o32, o64, "{name}: origins of {idx}");
        }
    }
}

#[test]
fn every_preset_parses_and_has_a_plan() {
    for (name, preset, _) in CASES {
        let (p, _, plan) = plan_of(name);
        assert!(ends_at_goals(&p, &plan), "{name}");
        // The paper's name and the preset's are the same scene.
        let q = load_scene(preset).unwrap();
        assert_eq!((q.grid, q.start, q.movables), (p.grid, p.start, p.movables));
        assert!(
            load_scene(&name.to_lowercase()).is_ok(),
            "{name} in lower case"
        );
    }
}

/// Dijkstra over the problem's own configuration graph (the model's neighbours, forward from
/// the start) to the cheapest configuration in the goal set: the cost map's optimum found
/// independently of the backward propagation and restoration.
fn brute_force_cost(model: &Model, start: &Config) -> Option<u32> {
    use std::cmp::Reverse;
    use std::collections::{BinaryHeap, HashMap};
    let p = &model.problem;
    let s = model.pack(start)?;
    let mut dist: HashMap<u64, u32> = HashMap::from([(s, 0)]);
    let mut heap = BinaryHeap::from([Reverse((0u32, s))]);
    let mut nb = Vec::new();
    while let Some(Reverse((d, idx))) = heap.pop() {
        if dist.get(&idx).is_some_and(|&e| e < d) {
            continue;
        }
        let c = model.unpack(idx);
        let at_goal = c
            .movables
            .iter()
            .zip(&p.goal_movables)
            .all(|(m, g)| g.is_none_or(|g| g == *m))
            && p.goal_robot.is_none_or(|g| g == c.robot);
        if at_goal {
            return Some(d);
        }
        model.neighbours(idx, &mut nb);
        for st in nb.drain(..) {
            let nd = d + st.cost;
            if dist.get(&st.to).is_none_or(|&e| nd < e) {
                dist.insert(st.to, nd);
                heap.push(Reverse((nd, st.to)));
            }
        }
    }
    None
}

#[test]
fn optimal_costs_match_a_brute_force_search() {
    for (name, _, _) in CASES {
        let (p, model, plan) = plan_of(name);
        assert_eq!(
            brute_force_cost(&model, &p.start),
            Some(plan.cost),
            "{name}: the planner's optimum against Dijkstra"
        );
    }
}

/// A shared-format scene of `w` × `h` cells of 0.1 m with the robot's centre and one box at
/// cells (grid y down), and a `[rearrange]` section ending in `extra`.
fn grid_scene(
    w: i32,
    h: i32,
    robot: (i32, i32),
    at: (i32, i32),
    goal: (i32, i32),
    extra: &str,
) -> String {
    let c = |(x, y): (i32, i32)| ((x as f64 + 0.5) * 0.1, (h as f64 - y as f64 - 0.5) * 0.1);
    let (r, a, g) = (c(robot), c(at), c(goal));
    format!(
        "name = \"t\"\n[table]\nwidth = {}\nheight = {}\n[robot]\nstart = {{ x = {}, y = {}, theta = 0.0 }}\n\
         [[objects]]\nid = \"a\"\noutline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]\n\
         pose = {{ x = {}, y = {}, theta = 0.0 }}\nmass = 0.2\nsupport_friction = 0.35\npusher_friction = 0.5\n\
         [[goals]]\nobject = \"a\"\npose = {{ x = {}, y = {}, theta = 0.0 }}\n\
         [rearrange]\ncell = 0.1\n{extra}",
        w as f64 / 10.0,
        h as f64 / 10.0,
        r.0,
        r.1,
        a.0,
        a.1,
        g.0,
        g.1
    )
}

#[test]
fn the_rearrange_section_sets_the_robot_goal_and_the_map() {
    // A 5 × 3 room; the robot must also end in the bottom-right corner.
    let base = grid_scene(5, 3, (0, 1), (1, 1), (3, 1), "");
    let p = problem_from_toml(&base, "t.toml").unwrap();
    assert_eq!(p.goal_robot, None);
    let (_, _, free) = solve(&p).unwrap();
    let free = free.unwrap();
    let text = base.clone() + "robot_goal = [0.45, 0.05]\n";
    let p = problem_from_toml(&text, "t.toml").unwrap();
    assert_eq!(p.goal_robot, Some((4, 2)));
    let (model, _, plan) = solve(&p).unwrap();
    let plan = plan.unwrap();
    assert_eq!(plan.steps.last().unwrap().config.robot, (4, 2));
    assert!(plan.cost > free.cost, "{} vs {}", plan.cost, free.cost);
    assert_eq!(brute_force_cost(&model, &p.start), Some(plan.cost));
    // Rough, very rough and no-leave cells, and a map obstacle.
    let text = base + "map = \"\"\"\n.,;x.\n.....\n...#.\n\"\"\"\n";
    let p = problem_from_toml(&text, "t.toml").unwrap();
    let g = |x, y| *p.grid.get(x, y).unwrap();
    assert_eq!(
        (g(1, 0).rough, g(2, 0).rough, g(3, 0).no_leave),
        (1, 2, true)
    );
    assert!(g(3, 2).obstacle && !g(4, 2).obstacle && g(0, 0).rough == 0);
}

#[test]
fn malformed_scenes_name_file_line_and_field() {
    let base = grid_scene(3, 2, (0, 0), (1, 1), (2, 1), "");
    // A contact mode with a bad direction: the line of the field.
    let text = format!(
        "{base}[[rearrange.movable]]\nobject = \"a\"\npush = [{{ point = [0, 1], dir = \"Q\" }}]\n"
    );
    let line = text.lines().position(|l| l.starts_with("push = ")).unwrap() + 1;
    let e = problem_from_toml(&text, "t.toml").unwrap_err().0;
    assert!(
        e.contains(&format!("t.toml:{line}")) && e.contains("rearrange.movable[0].push[0].dir"),
        "{e}"
    );
    // An unknown cell in the map.
    let e = problem_from_toml(&format!("{base}map = \"\"\"\n...\n.?.\n\"\"\"\n"), "t.toml")
        .unwrap_err()
        .0;
    assert!(
        e.contains("rearrange.map") && e.contains("row 2 column 2"),
        "{e}"
    );
    // A map of the wrong size.
    let e = problem_from_toml(
        &format!("{base}map = \"\"\"\n....\n....\n\"\"\"\n"),
        "t.toml",
    )
    .unwrap_err()
    .0;
    assert!(
        e.contains("rearrange.map") && e.contains("2 rows of 3 cells"),
        "{e}"
    );
    // A robot goal off the grid.
    let e = problem_from_toml(&format!("{base}robot_goal = [0.5, 0.05]\n"), "t.toml")
        .unwrap_err()
        .0;
    assert!(e.contains("rearrange.robot_goal"), "{e}");
    // A misspelt rule: the line and the key.
    let text = format!("{base}rules = {{ max_pushd = 2 }}\n");
    let line = text.lines().count();
    let e = problem_from_toml(&text, "t.toml").unwrap_err().0;
    assert!(
        e.contains(&format!("t.toml:{line}")) && e.contains("max_pushd"),
        "{e}"
    );
    // A movable setting for an object that is not there.
    let e = problem_from_toml(
        &format!("{base}[[rearrange.movable]]\nobject = \"nope\"\n"),
        "t.toml",
    )
    .unwrap_err()
    .0;
    assert!(
        e.contains("rearrange.movable[0].object") && e.contains("nope"),
        "{e}"
    );
    // The old grid format (no [table]) is refused by name.
    let e = problem_from_toml(
        "map = \"\"\"\n...\n\"\"\"\n[robot]\nat = [0, 0]\n",
        "old.toml",
    )
    .unwrap_err()
    .0;
    assert!(e.contains("old.toml") && e.contains("no [table]"), "{e}");
}

fn pushbot(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn cli_plan_rearrange_exit_codes_and_json() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("d1.svg");
    let (code, out, _) = pushbot(&[
        "plan",
        "rearrange",
        "--scene",
        "D1",
        "--json",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["found"], true);
    for key in [
        "cost",
        "steps",
        "pushes",
        "states_mapped",
        "map_ms",
        "restore_ms",
        "peak_kib",
        "plan",
    ] {
        assert!(!j[key].is_null(), "{key} missing in {out}");
    }
    assert_eq!(
        j["plan"].as_array().unwrap().len() as u64,
        j["steps"].as_u64().unwrap()
    );
    assert!(std::fs::read_to_string(&svg).unwrap().starts_with("<svg"));
    // a box in a corner cannot be pushed out: no pushing path, exit 1
    let stuck = dir.path().join("stuck.toml");
    std::fs::write(&stuck, grid_scene(4, 2, (3, 1), (0, 0), (2, 1), "")).unwrap();
    let (code, out, _) = pushbot(&[
        "plan",
        "rearrange",
        "--scene",
        stuck.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("\"found\":false"));
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "map = 3\n").unwrap();
    let (code, _, err) = pushbot(&["plan", "rearrange", "--scene", bad.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("bad.toml") && err.contains("[table]"), "{err}");
    std::fs::write(
        &bad,
        grid_scene(4, 2, (3, 1), (0, 0), (2, 1), "").replace("cell = 0.1", "cell = 3"),
    )
    .unwrap();
    let (code, _, err) = pushbot(&["plan", "rearrange", "--scene", bad.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("bad.toml") && err.contains("cell"), "{err}");
    let (code, _, _) = pushbot(&["plan", "rearrange", "--scene", "no-such-scene"]);
    assert_eq!(code, 2);
}

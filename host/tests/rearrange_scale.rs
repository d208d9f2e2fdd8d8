//! The exact planner's size known before it runs (Ben-Shahar & Rivlin §IV-E) and the choice of
//! the practical mode beyond it, through the library and through `pushbot plan rearrange`.

use pushbot::experiments::rearrange_bench::{bench_problem, warehouse_problem};
use pushbot::planner::rearrange::budget::{ExactBudget, TooLarge, human};
use pushbot::planner::rearrange::cases::load_scene;
use pushbot::planner::rearrange::practical::{Action, Options, plan_practical};
use pushbot::planner::rearrange::to_scene::{SceneOptions, scene_for};
use pushbot::planner::rearrange::{Model, cost_map, map_bytes_estimate, replay_cost};

#[test]
fn the_memory_estimate_is_what_the_map_takes() {
    for p in [
        load_scene("A1").unwrap(),
        load_scene("B2").unwrap(),
        bench_problem(9, 2),
        bench_problem(9, 3),
    ] {
        let model = Model::new(&p).unwrap();
        let map = cost_map(&model).unwrap();
        assert_eq!(Model::configurations(&p), model.n_states, "{}", p.name);
        let est = map_bytes_estimate(model.n_states, model.max_edge);
        // A bound: the cost array exactly, and the wave front as if it filled every page.
        let cost_bytes = 2 * model.n_states;
        assert!(
            est >= map.stats.map_bytes
                && map.stats.map_bytes >= cost_bytes
                && est <= 2 * cost_bytes,
            "{}: estimate {est}, map {}",
            p.name,
            map.stats.map_bytes
        );
        assert!(ExactBudget::of(&p).check().is_ok());
    }
}

#[test]
fn too_large_maps_are_refused_naming_the_memory_and_the_practical_mode() {
    // 10¹⁰ configurations: past a u32 index, so u64 indices; refused or not by memory alone.
    let mut four = ExactBudget::of(&bench_problem(10, 4));
    assert_eq!(four.configurations, 10_000_000_000);
    let need = four.bytes;
    assert!(need > 20_000_000_000 && need < 30_000_000_000, "{need}");
    four.available = Some(16 << 30);
    let e = four.check().unwrap_err();
    assert!(matches!(e, TooLarge::Memory { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains(&human(need)) && msg.contains("16.0 GiB") && msg.contains("--mode practical"),
        "{msg}"
    );
    four.available = Some(64 << 30);
    assert_eq!(four.check(), Ok(()));
    assert!(Model::new(&bench_problem(10, 4)).unwrap().wide());
    let twelve = ExactBudget::of(&warehouse_problem(12));
    let msg = twelve.check().unwrap_err().to_string();
    assert!(
        msg.contains("12 movables") && msg.contains("--mode practical"),
        "{msg}"
    );
    assert!(twelve.configurations_f64 > 1e30);
}

#[test]
fn the_warehouse_is_planned_legally_move_by_move() {
    let p = warehouse_problem(12);
    let plan = plan_practical(&p, &Options::for_problem(&p)).unwrap();
    assert!(!plan.optimal);
    // Every move: the robot steps one cell; only a pushed movable moves, one cell the same way,
    // never onto a wall or another movable; the plan's cost is the sum of its moves'.
    let mut prev = p.start.clone();
    for m in &plan.moves {
        let (dx, dy) = m.dir.delta();
        let c = &m.config;
        assert_eq!(c.robot, (prev.robot.0 + dx, prev.robot.1 + dy));
        for (i, (a, b)) in prev.movables.iter().zip(&c.movables).enumerate() {
            if m.action == Action::Push(i) {
                assert_eq!((b.x, b.y), (a.x + dx, a.y + dy));
            } else {
                assert_eq!(a, b);
            }
            assert!(p.grid.free(b.x, b.y));
            assert_ne!((b.x, b.y), c.robot);
        }
        let mut cells: Vec<(i32, i32)> = c.movables.iter().map(|q| (q.x, q.y)).collect();
        cells.sort();
        cells.dedup();
        assert_eq!(cells.len(), c.movables.len());
        prev = c.clone();
    }
    for (m, g) in prev.movables.iter().zip(&p.goal_movables) {
        assert_eq!(Some(*m), *g);
    }
    assert_eq!(plan.cost, plan.moves.iter().map(|m| m.cost).sum::<u32>());
}

#[test]
fn practical_plans_of_the_paper_cases_are_legal_and_no_cheaper_than_the_optimum() {
    for case in ["A1", "A2", "A3", "A4", "B1", "B2", "C1", "C2", "D1"] {
        let p = load_scene(case).unwrap();
        let model = Model::new(&p).unwrap();
        let map = cost_map(&model).unwrap();
        let opt = map.get(model.pack(&p.start).unwrap()).unwrap();
        let plan = plan_practical(&p, &Options::for_problem(&p)).unwrap();
        let configs: Vec<_> = plan.moves.iter().map(|m| m.config.clone()).collect();
        // Legal under the full problem's rules (A4's distance limit included), at its cost.
        assert_eq!(
            replay_cost(&model, &p.start, &configs),
            Some(plan.cost),
            "{case}"
        );
        let end = configs.last().unwrap();
        for (m, g) in end.movables.iter().zip(&p.goal_movables) {
            assert!(g.is_none_or(|g| g == *m), "{case}");
        }
        assert!(plan.cost >= opt, "{case}: {} < {opt}", plan.cost);
    }
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
fn cli_refuses_the_exact_mode_and_picks_the_practical_one_for_many_movables() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("five.toml");
    let scene = scene_for(&warehouse_problem(5), &SceneOptions::default()).unwrap();
    std::fs::write(&file, scene.to_toml()).unwrap();
    let f = file.to_str().unwrap();
    let (code, _, err) = pushbot(&["plan", "rearrange", "--scene", f, "--mode", "exact"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("5 movables") && err.contains("--mode practical"),
        "{err}"
    );
    let svg = dir.path().join("five.svg");
    let svg_arg = svg.to_str().unwrap();
    let (code, out, err) = pushbot(&[
        "plan",
        "rearrange",
        "--scene",
        f,
        "--json",
        "--svg",
        svg_arg,
    ]);
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["mode"], "practical");
    // The figure: one panel per transit and the pushes after it, every movable drawn.
    let kinds: Vec<&str> = j["plan"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["kind"].as_str().unwrap())
        .collect();
    let stages = (0..kinds.len())
        .filter(|&i| {
            let ends_pushes =
                kinds[i] != "transit" && kinds.get(i + 1).is_none_or(|k| *k == "transit");
            ends_pushes || i + 1 == kinds.len()
        })
        .count();
    let drawing = std::fs::read_to_string(&svg).unwrap();
    assert!(stages >= 5, "{kinds:?}");
    assert_eq!(
        drawing.matches(" pushes</text>").count(),
        stages,
        "{drawing}"
    );
    for i in 0..5 {
        assert!(drawing.contains(&format!(">b{i}</text>")), "b{i} not drawn");
    }
    assert_eq!(j["optimal"], false);
    for key in ["cost", "steps", "pushes", "plan"] {
        assert!(!j[key].is_null(), "{key} missing in {out}");
    }
    assert_eq!(
        j["plan"].as_array().unwrap().len() as u64,
        j["steps"].as_u64().unwrap()
    );
    // The exact planner prints its memory before it starts.
    let (code, out, err) = pushbot(&["plan", "rearrange", "--scene", "A1", "--json"]);
    assert_eq!(code, 0);
    assert!(
        err.contains("exact cost map") && err.contains("MiB"),
        "{err}"
    );
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (j["mode"].as_str(), j["optimal"].as_bool()),
        (Some("exact"), Some(true))
    );
}

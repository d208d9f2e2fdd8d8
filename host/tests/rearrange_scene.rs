//! The shared scene format with a `[rearrange]` section as a grid pushing problem: the paper's
//! cases written out as simulator scenes (boxes, polygons, goals) come back as the same grid
//! problem, and errors name the file, the line and the field.

use pushbot::planner::rearrange::cases::load_scene;
use pushbot::planner::rearrange::to_scene::{SceneOptions, scene_for};
use pushbot::planner::rearrange::{Model, solve};

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> String {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn cases_written_as_shared_scenes_rasterise_back_to_the_same_problem() {
    let dir = tempfile::tempdir().unwrap();
    for case in ["A1", "A3", "A4", "B1", "B2", "C2", "D1"] {
        let p = load_scene(case).unwrap();
        let scene = match scene_for(&p, &SceneOptions::default()) {
            Ok(s) => s,
            // Only rectangular movables become simulator boxes.
            Err(e) => {
                assert!(case.starts_with('C'), "{case}: {e}");
                continue;
            }
        };
        let path = write(&dir, &format!("{case}.toml"), &scene.to_toml());
        let back = load_scene(&path).unwrap_or_else(|e| panic!("{case}: {e}"));
        assert_eq!(back.grid, p.grid, "{case}: grid");
        assert_eq!(back.start, p.start, "{case}: start");
        assert_eq!(back.goal_movables, p.goal_movables, "{case}: goals");
        assert_eq!(back.movables, p.movables, "{case}: movables");
        assert_eq!(back.rules, p.rules, "{case}: rules");
        assert_eq!(back.metric, p.metric, "{case}: metric");
        assert_eq!(back.robot, p.robot, "{case}: robot");
        // And so the same optimal plan cost.
        let (_, _, a) = solve(&p).unwrap();
        let (_, _, b) = solve(&back).unwrap();
        assert_eq!(a.unwrap().cost, b.unwrap().cost, "{case}");
    }
}

#[test]
fn a_hand_written_scene_rasterises_obstacles_objects_and_goals() {
    let dir = tempfile::tempdir().unwrap();
    // A 1.0 × 0.5 table in cells of 0.1 m: a wall at x = 0.5 with a door in the middle row.
    let text = r#"
name = "door"
[table]
width = 1.0
height = 0.5
[robot]
start = { x = 0.15, y = 0.25, theta = 0.0 }
[[obstacles]]
outline = [[0.5, 0.0], [0.6, 0.0], [0.6, 0.2], [0.5, 0.2]]
[[obstacles]]
outline = [[0.5, 0.3], [0.6, 0.3], [0.6, 0.5], [0.5, 0.5]]
[[objects]]
id = "box"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.35, y = 0.25, theta = 0.0 }
mass = 0.4
support_friction = 0.35
pusher_friction = 0.5
[[goals]]
object = "box"
pose = { x = 0.75, y = 0.25, theta = 0.0 }
[rearrange]
cell = 0.1
"#;
    let p = load_scene(&write(&dir, "door.toml", text)).unwrap();
    assert_eq!((p.grid.w, p.grid.h), (10, 5));
    for y in 0..5 {
        assert_eq!(
            p.grid.get(5, y).unwrap().obstacle,
            y != 2,
            "wall cell (5, {y})"
        );
        assert!(!p.grid.get(4, y).unwrap().obstacle && !p.grid.get(6, y).unwrap().obstacle);
    }
    assert_eq!(p.start.robot, (1, 2));
    assert_eq!(p.movables[0].cells, vec![(0, 0)]);
    assert_eq!(p.movables[0].mass, 2);
    assert_eq!((p.start.movables[0].x, p.start.movables[0].y), (3, 2));
    let g = p.goal_movables[0].unwrap();
    assert_eq!((g.x, g.y), (7, 2));
    // Through the door: 4 pushes east, the robot starting right behind the box.
    let model = Model::new(&p).unwrap();
    let (_, _, plan) = solve(&model.problem).unwrap();
    let plan = plan.unwrap();
    assert_eq!(plan.pushes(), 4);
    assert_eq!(plan.cost, 2 * 4 + 4 + 1);
}

#[test]
fn errors_name_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let text = r#"name = "bad"
[table]
width = 0.5
height = 0.5
[[objects]]
id = "box"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.35, y = 0.25, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5
[rearrange]
cell = 0.1
[[rearrange.movable]]
object = "box"
push = [{ point = [-1, 0], dir = "Q" }]
"#;
    let path = write(&dir, "bad.toml", text);
    let e = load_scene(&path).unwrap_err().to_string();
    assert!(e.contains("bad.toml:16"), "{e}");
    assert!(e.contains("rearrange.movable[0].push[0].dir"), "{e}");
    let no_section = text.split("[rearrange]").next().unwrap();
    let e = load_scene(&write(&dir, "none.toml", no_section))
        .unwrap_err()
        .to_string();
    assert!(e.contains("[rearrange]"), "{e}");
}

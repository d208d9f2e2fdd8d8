//! `pushbot scene check` on the scene checks: what it normalised (a clockwise outline) is
//! said in text and JSON; a goal inside an obstacle and a bad `[stable]` value exit 2 naming
//! the file, line, column and field; a 100 000-vertex circle is a simple polygon.

use pushbot_tests::{Run, run_bin};

const BASE: &str = r#"name = "t"
[table]
width = 1.2
height = 0.9

[robot]
start = { x = 0.2, y = 0.45, theta = 0.0 }

[[obstacles]]
outline = [[0.8, 0.0], [0.9, 0.0], [0.9, 0.3], [0.8, 0.3]]

[[obstacles]]
outline = [[0.8, 0.5], [0.9, 0.5], [0.9, 0.8], [0.8, 0.8]]

[[objects]]
id = "box"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.5, y = 0.45, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5

[[goals]]
object = "box"
pose = { x = 1.0, y = 0.4, theta = 0.0 }
"#;

fn check(dir: &tempfile::TempDir, name: &str, text: &str, json: bool) -> (String, Run) {
    let p = dir.path().join(name);
    std::fs::write(&p, text).expect("write the scene");
    let p = p.display().to_string();
    let mut args = vec!["scene", "check", "--scene", p.as_str()];
    if json {
        args.push("--json");
    }
    let r = run_bin("pushbot", &args);
    (p, r)
}

fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).expect("needle");
    text[..at].matches('\n').count() + 1
}

#[test]
fn a_clockwise_obstacle_is_accepted_and_the_note_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let text = BASE.replace(
        "[[0.8, 0.5], [0.9, 0.5], [0.9, 0.8], [0.8, 0.8]]",
        "[[0.8, 0.5], [0.8, 0.8], [0.9, 0.8], [0.9, 0.5]]",
    );
    let (_, r) = check(&dir, "cw.toml", &text, false);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(
        r.stdout
            .contains("note: obstacles[1].outline was clockwise; normalised to counter-clockwise"),
        "{r:?}"
    );
    let (_, r) = check(&dir, "cw.toml", &text, true);
    assert_eq!(r.code, Some(0), "{r:?}");
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    assert_eq!(
        v["notes"],
        serde_json::json!(["obstacles[1].outline was clockwise; normalised to counter-clockwise"]),
        "{v}"
    );
    // Counter-clockwise: no note.
    let (_, r) = check(&dir, "ccw.toml", BASE, false);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(!r.stdout.contains("note:"), "{r:?}");
}

#[test]
fn a_goal_inside_an_obstacle_exits_2_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let text = BASE.replace(
        "pose = { x = 1.0, y = 0.4, theta = 0.0 }",
        "pose = { x = 0.85, y = 0.6, theta = 0.0 }",
    );
    let (p, r) = check(&dir, "goal.toml", &text, false);
    assert_eq!(r.code, Some(2), "{r:?}");
    let all = format!("{}{}", r.stdout, r.stderr);
    let at = format!("{p}:{}:", line_of(&text, "pose = { x = 0.85"));
    assert!(all.contains(&at), "{all}");
    assert!(
        all.contains(
            "goals[0].pose: goals[0] (object \"box\"): the goal pose puts the object inside obstacles[1]"
        ),
        "{all}"
    );
}

#[test]
fn a_bad_stable_value_exits_2_with_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{BASE}\n[stable]\nobject = \"box\"\nedges = [0]\ngoal_xy_frac = 0.25\n\
         goal_theta_deg = 2.0\npusher = {{ kind = \"tank\" }}\n"
    );
    let (p, r) = check(&dir, "stable.toml", &text, false);
    assert_eq!(r.code, Some(2), "{r:?}");
    let all = format!("{}{}", r.stdout, r.stderr);
    let at = format!("{p}:{}:", line_of(&text, "pusher ="));
    assert!(all.contains(&at), "{all}");
    assert!(all.contains("stable.pusher.kind"), "{all}");
}

#[test]
fn a_100000_vertex_circle_obstacle_is_simple() {
    let dir = tempfile::tempdir().unwrap();
    let n = 100_000;
    let pts: Vec<String> = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            format!("[{}, {}]", 0.7 + 0.4 * a.cos(), 0.45 + 0.4 * a.sin())
        })
        .collect();
    let text = format!(
        "[table]\nwidth = 1.2\nheight = 0.9\n[robot]\nstart = {{ x = 0.1, y = 0.1, theta = 0.0 }}\n\
         [[obstacles]]\noutline = [{}]\n",
        pts.join(", ")
    );
    let (_, r) = check(&dir, "circle.toml", &text, false);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(r.stdout.contains("ok"), "{r:?}");
}

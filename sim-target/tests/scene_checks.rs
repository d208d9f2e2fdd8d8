//! The scene loader's geometric checks: each refusal names the file, the line and the field.

use pushbot_sim::{Scene, SceneError};

const GOOD: &str = r#"name = "t"
[table]
width = 1.2
height = 0.9

[robot]
start = { x = 0.2, y = 0.45, theta = 0.0 }

[[obstacles]]
outline = [[0.8, 0.0], [0.9, 0.0], [0.9, 0.3], [0.8, 0.3]]

[[objects]]
id = "a"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.5, y = 0.45, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5

[[objects]]
id = "b"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.6, y = 0.6, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5

[[goals]]
object = "a"
pose = { x = 1.0, y = 0.7, theta = 0.0 }
"#;

fn refused(text: &str) -> SceneError {
    Scene::from_toml(text, "checks.toml").expect_err("should be refused")
}

/// The 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).expect("needle in text");
    text[..at].matches('\n').count() + 1
}

/// `text` with the `nth` (0-based) occurrence of `from` replaced.
fn replace_nth(text: &str, from: &str, to: &str, nth: usize) -> String {
    let at = text.match_indices(from).nth(nth).expect("occurrence").0;
    format!("{}{}{}", &text[..at], to, &text[at + from.len()..])
}

fn assert_at(e: &SceneError, field: &str, line: usize, words: &str) {
    assert_eq!(e.file, "checks.toml");
    assert_eq!(e.field.as_deref(), Some(field), "{e}");
    assert_eq!(e.line, Some(line), "{e}");
    assert!(e.message.contains(words), "{e}");
    assert!(
        e.to_string().starts_with(&format!("checks.toml:{line}:")),
        "{e}"
    );
}

#[test]
fn the_good_scene_loads() {
    Scene::from_toml(GOOD, "checks.toml").expect("valid");
}

#[test]
fn object_overlapping_an_obstacle() {
    let text = GOOD.replace("x = 0.6, y = 0.6", "x = 0.78, y = 0.2");
    let e = refused(&text);
    assert_at(
        &e,
        "objects[1].pose",
        line_of(&text, "x = 0.78"),
        "obstacles[0]",
    );
    // Touching the obstacle is fine.
    let ok = GOOD.replace("x = 0.6, y = 0.6", "x = 0.76, y = 0.2");
    Scene::from_toml(&ok, "checks.toml").expect("touching is allowed");
}

#[test]
fn objects_overlapping_each_other() {
    let text = GOOD.replace("x = 0.6, y = 0.6", "x = 0.55, y = 0.5");
    let e = refused(&text);
    assert_at(
        &e,
        "objects[1].pose",
        line_of(&text, "x = 0.55"),
        "objects[0]",
    );
    // Rotated 45°, a square reaches further: 0.04·√2 + 0.04 > 0.095.
    let text = GOOD.replace(
        "x = 0.6, y = 0.6, theta = 0.0",
        "x = 0.595, y = 0.45, theta = 0.785398",
    );
    let e = refused(&text);
    assert_at(&e, "objects[1].pose", line_of(&text, "x = 0.595"), "\"a\"");
}

#[test]
fn objects_goals_and_robot_off_the_table() {
    let text = GOOD.replace("x = 0.6, y = 0.6", "x = 1.18, y = 0.6");
    assert_at(
        &refused(&text),
        "objects[1].pose",
        line_of(&text, "x = 1.18"),
        "table",
    );
    let text = GOOD.replace("x = 1.0, y = 0.7", "x = 1.3, y = 0.7");
    assert_at(
        &refused(&text),
        "goals[0].pose",
        line_of(&text, "x = 1.3"),
        "table",
    );
    let text = GOOD.replace("x = 0.2, y = 0.45", "x = 0.03, y = 0.45");
    assert_at(
        &refused(&text),
        "robot.start",
        line_of(&text, "x = 0.03"),
        "table",
    );
    // The front plate sticks out ahead: the round bumper fits, the plate does not.
    let text = GOOD
        .replace(
            "x = 0.2, y = 0.45, theta = 0.0",
            "x = 1.15, y = 0.2, theta = 0.0",
        )
        .replace(
            "[robot]\n",
            "[robot]\nfront_plate = { width = 0.12, offset = 0.06 }\n",
        );
    assert_at(
        &refused(&text),
        "robot.start",
        line_of(&text, "x = 1.15"),
        "front plate",
    );
    Scene::from_toml(
        &text.replace("front_plate = { width = 0.12, offset = 0.06 }\n", ""),
        "ok",
    )
    .expect("without the plate the robot fits");
}

#[test]
fn robot_starting_in_an_obstacle_or_an_object() {
    let text = GOOD.replace("x = 0.2, y = 0.45", "x = 0.83, y = 0.33");
    assert_at(
        &refused(&text),
        "robot.start",
        line_of(&text, "x = 0.83"),
        "obstacles[0]",
    );
    let ok = GOOD.replace("x = 0.2, y = 0.45", "x = 0.83, y = 0.35");
    Scene::from_toml(&ok, "checks.toml").expect("5 cm above the obstacle is clear");
    let text = GOOD.replace("x = 0.2, y = 0.45", "x = 0.45, y = 0.45");
    assert_at(
        &refused(&text),
        "objects[0].pose",
        line_of(&text, "x = 0.5,"),
        "robot",
    );
}

#[test]
fn bad_front_plate() {
    let text = GOOD.replace(
        "[robot]\n",
        "[robot]\nfront_plate = { width = -0.1, offset = 0.06 }\n",
    );
    assert_at(
        &refused(&text),
        "robot.front_plate",
        line_of(&text, "front_plate"),
        "width",
    );
}

#[test]
fn self_intersecting_polygons() {
    let bow = "[[-0.04, -0.04], [0.04, 0.04], [0.04, -0.04], [-0.04, 0.04]]";
    let square = "[[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]";
    let text = replace_nth(GOOD, square, bow, 1);
    let e = refused(&text);
    assert_at(&e, "objects[1].outline", line_of(&text, bow), "not simple");
    let text = GOOD.replace(
        "[[0.8, 0.0], [0.9, 0.0], [0.9, 0.3], [0.8, 0.3]]",
        "[[0.8, 0.0], [0.9, 0.0], [0.8, 0.3], [0.9, 0.3]]",
    );
    assert_at(
        &refused(&text),
        "obstacles[0].outline",
        line_of(&text, "[[0.8, 0.0]"),
        "not simple",
    );
    // An edge folding back onto the previous one.
    let spike = "[[-0.04, -0.04], [0.04, -0.04], [0.08, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]";
    let text = replace_nth(GOOD, square, spike, 0);
    assert_at(
        &refused(&text),
        "objects[0].outline",
        line_of(&text, spike),
        "not simple",
    );
}

#[test]
fn degenerate_polygons() {
    let square = "[[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]";
    for (bad, words) in [
        ("[[0.0, 0.0], [0.01, 0.0], [0.02, 0.0]]", "degenerate"),
        ("[[0.0, 0.0], [0.04, 0.0]]", "at least 3"),
        (
            "[[-0.04, -0.04], [0.04, -0.04], [0.04, -0.04], [0.04, 0.04]]",
            "degenerate",
        ),
    ] {
        let text = replace_nth(GOOD, square, bad, 0);
        assert_at(
            &refused(&text),
            "objects[0].outline",
            line_of(&text, bad),
            words,
        );
    }
}

//! Scene files: every preset loads and round-trips; errors name the file, line and field.

use pushbot_sim::scene::{PRESETS, Support, signed_area};
use pushbot_sim::{Scene, SceneError};

const GOOD: &str = r#"name = "t"
[table]
width = 1.2
height = 0.9

[[objects]]
id = "box"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.6, y = 0.45, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5

[[goals]]
object = "box"
pose = { x = 1.0, y = 0.7, theta = 0.0 }
"#;

fn err(text: &str) -> SceneError {
    Scene::from_toml(text, "bad.toml").expect_err("should be refused")
}

/// The 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).expect("needle in text");
    text[..at].matches('\n').count() + 1
}

#[test]
fn good_scene_loads_with_defaults() {
    let s = Scene::from_toml(GOOD, "good.toml").expect("valid");
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.objects[0].support, Support::Uniform);
    assert_eq!(s.goals[0].tolerance, 0.022);
    assert_eq!(s.robot, pushbot_sim::scene::RobotSpec::default());
    assert!((signed_area(&s.objects[0].outline) - 0.0064).abs() < 1e-12);
}

#[test]
fn every_preset_loads_and_round_trips() {
    assert!(PRESETS.len() >= 12);
    for name in PRESETS {
        let s = Scene::preset(name).unwrap_or_else(|e| panic!("{e}"));
        let again = Scene::from_toml(&s.to_toml(), name).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s, again, "{name}");
    }
    // The Lau layout: six objects, each with start positions A–F and one goal.
    for name in PRESETS.iter().filter(|n| n.starts_with("lau-")) {
        let s = Scene::preset(name).expect("preset");
        assert_eq!(s.objects.len(), 1);
        assert_eq!(s.goals.len(), 1);
        for p in ["A", "B", "C", "D", "E", "F"] {
            assert!(s.position(p).is_some(), "{name} lacks {p}");
        }
        assert_eq!(
            s.position("A").map(|p| (p.x, p.y)),
            Some((s.objects[0].pose.x, s.objects[0].pose.y))
        );
    }
    assert!(
        Scene::preset("nope")
            .unwrap_err()
            .to_string()
            .contains("lau-snake")
    );
}

#[test]
fn semantic_errors_name_line_and_field() {
    let text = GOOD.replace("mass = 0.2", "mass = -0.2");
    let e = err(&text);
    assert_eq!(e.field.as_deref(), Some("objects[0].mass"));
    assert_eq!(e.line, Some(line_of(&text, "mass = -0.2")));
    assert_eq!(e.file, "bad.toml");
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("bad.toml:{}:", line_of(&text, "mass ="))),
        "{shown}"
    );

    let text = GOOD.replace("object = \"box\"", "object = \"crate\"");
    let e = err(&text);
    assert_eq!(e.field.as_deref(), Some("goals[0].object"));
    assert_eq!(e.line, Some(line_of(&text, "object = \"crate\"")));

    // A bow-tie is not a simple polygon.
    let text = GOOD.replace(
        "[[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]",
        "[[-0.04, -0.04], [0.04, 0.04], [0.04, -0.04], [-0.04, 0.04]]",
    );
    let e = err(&text);
    assert_eq!(e.field.as_deref(), Some("objects[0].outline"));
    assert!(e.message.contains("not simple"), "{e}");
    assert_eq!(e.line, Some(line_of(&text, "outline")));

    // Off the table.
    let text = GOOD.replace("x = 0.6, y = 0.45", "x = 1.19, y = 0.45");
    let e = err(&text);
    assert_eq!(e.field.as_deref(), Some("objects[0].pose"));

    let text = GOOD.replace("width = 1.2", "width = 0.0");
    assert_eq!(err(&text).field.as_deref(), Some("table.width"));
    assert_eq!(err(&text).line, Some(3));
}

#[test]
fn parse_errors_name_line_and_field() {
    // A misspelt field: the message names it, the span its line.
    let text = GOOD.replace("mass = 0.2", "mas = 0.2");
    let e = err(&text);
    assert!(e.message.contains("mas"), "{e}");
    assert!(e.line.is_some(), "{e}");
    // A missing field.
    let text = GOOD.replace("pusher_friction = 0.5\n", "");
    let e = err(&text);
    assert!(e.message.contains("pusher_friction"), "{e}");
    // A wrong type points at the value's line.
    let text = GOOD.replace("mass = 0.2", "mass = \"heavy\"");
    let e = err(&text);
    assert_eq!(e.line, Some(line_of(&text, "mass =")), "{e}");
    // Plain syntax.
    let e = err("[table\nwidth = 1");
    assert_eq!(e.line, Some(1), "{e}");
    // A missing file names the file.
    let e = Scene::load(std::path::Path::new("/nonexistent/scene.toml")).unwrap_err();
    assert!(
        e.to_string().starts_with("/nonexistent/scene.toml: "),
        "{e}"
    );
}

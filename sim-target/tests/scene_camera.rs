//! The scene's `[camera]` section: defaults, and errors for markers the camera could not tell
//! apart or draw, naming the file, line and field.

use pushbot_sim::Scene;

const BASE: &str = r#"name = "t"
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
marker = { id = 3, x = 0.0, y = 0.0, size = 0.05 }
"#;

fn line_of(text: &str, needle: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.contains(needle))
        .expect("needle in text")
}

#[test]
fn default_camera_has_six_fiducials_inside_the_table() {
    let s = Scene::from_toml(BASE, "t.toml").expect("loads");
    let f = s.fiducials();
    assert_eq!(f.len(), 6);
    let ids: std::collections::BTreeSet<u32> = f.iter().map(|m| m.id).collect();
    assert_eq!(ids.len(), 6, "distinct ids");
    assert!(
        f.iter()
            .all(|m| m.x > 0.0 && m.x < 1.2 && m.y > 0.0 && m.y < 0.9)
    );
    assert_eq!((s.camera.width, s.camera.height), (960, 720));
}

#[test]
fn a_tag_id_used_twice_is_refused_with_its_line() {
    let text = format!("{BASE}\n[camera]\nrobot_marker = {{ id = 3, x = 0.0, y = 0.0 }}\n");
    let e = Scene::from_toml(&text, "t.toml").expect_err("id 3 twice");
    assert_eq!(e.field.as_deref(), Some("objects[0].marker"));
    assert!(e.message.contains("camera.robot_marker"), "{e}");
    assert_eq!(e.line, Some(line_of(&text, "marker = { id = 3")));
}

#[test]
fn a_fiducial_off_the_table_is_refused() {
    let text =
        format!("{BASE}\n[camera]\nfiducials = [{{ id = 40, x = 1.19, y = 0.1, size = 0.05 }}]\n");
    let e = Scene::from_toml(&text, "t.toml").expect_err("off the table");
    assert_eq!(e.field.as_deref(), Some("camera.fiducials[0]"));
    assert_eq!(e.line, Some(line_of(&text, "fiducials")));
    assert!(e.to_string().starts_with("t.toml:"), "{e}");
}

#[test]
fn an_unknown_camera_field_is_refused() {
    let text = format!("{BASE}\n[camera]\nresolution = 3\n");
    let e = Scene::from_toml(&text, "t.toml").expect_err("unknown field");
    assert!(e.message.contains("resolution"), "{e}");
    assert_eq!(e.line, Some(line_of(&text, "resolution")));
}

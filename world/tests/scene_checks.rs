//! The scene checks: clockwise outlines normalised (and said so), goals and starts
//! inside obstacles or off the table refused, the planners' sections checked with their field
//! paths, marker heights, the camera's intrinsics file.

use pushbot_world::Scene;
use pushbot_world::polygon::signed_area;

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
marker = { id = 3, x = 0.0, y = 0.0, size = 0.05 }

[[goals]]
object = "box"
pose = { x = 1.0, y = 0.4, theta = 0.0 }
"#;

fn line_of(text: &str, needle: &str) -> usize {
    let at = text.find(needle).expect("needle");
    text[..at].matches('\n').count() + 1
}

fn refused(text: &str, field: &str, line_needle: &str, words: &[&str]) {
    let e = Scene::from_toml(text, "t.toml").expect_err("should be refused");
    assert_eq!(e.field.as_deref(), Some(field), "{e}");
    assert_eq!(e.line, Some(line_of(text, line_needle)), "{e}");
    for w in words {
        assert!(e.to_string().contains(w), "{e} lacks {w}");
    }
}

#[test]
fn the_base_loads_without_notes() {
    let (_, notes) = Scene::from_toml_noted(BASE, "t.toml").expect("valid");
    assert!(notes.is_empty(), "{notes:?}");
}

#[test]
fn clockwise_outlines_are_stored_counter_clockwise_with_a_note() {
    let text = BASE
        .replace(
            "[[0.8, 0.5], [0.9, 0.5], [0.9, 0.8], [0.8, 0.8]]",
            "[[0.8, 0.5], [0.8, 0.8], [0.9, 0.8], [0.9, 0.5]]",
        )
        .replace(
            "[[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]",
            "[[-0.04, -0.04], [-0.04, 0.04], [0.04, 0.04], [0.04, -0.04]]",
        );
    let (s, notes) = Scene::from_toml_noted(&text, "t.toml").expect("clockwise is accepted");
    assert!(signed_area(&s.obstacles[1].outline) > 0.0);
    assert!(signed_area(&s.objects[0].outline) > 0.0);
    assert_eq!(
        s.objects[0].outline[0],
        [-0.04, -0.04],
        "vertex 0 stays first"
    );
    let said: Vec<String> = notes.iter().map(|n| n.to_string()).collect();
    assert_eq!(
        said,
        [
            "obstacles[1].outline was clockwise; normalised to counter-clockwise",
            "objects[0].outline was clockwise; normalised to counter-clockwise",
        ]
    );
    // The same shape.
    let ccw = Scene::from_toml(BASE, "t.toml").unwrap();
    assert_eq!(
        signed_area(&s.obstacles[1].outline),
        signed_area(&ccw.obstacles[1].outline)
    );
}

#[test]
fn a_goal_inside_an_obstacle_or_off_the_table_is_refused() {
    let text = BASE.replace(
        "pose = { x = 1.0, y = 0.4, theta = 0.0 }",
        "pose = { x = 0.85, y = 0.6, theta = 0.0 }",
    );
    refused(
        &text,
        "goals[0].pose",
        "pose = { x = 0.85",
        &[
            "t.toml:",
            "goals[0] (object \"box\")",
            "inside obstacles[1]",
        ],
    );
    // Its centre on the table, its outline not.
    let text = BASE.replace(
        "pose = { x = 1.0, y = 0.4, theta = 0.0 }",
        "pose = { x = 1.18, y = 0.4, theta = 0.0 }",
    );
    refused(
        &text,
        "goals[0].pose",
        "pose = { x = 1.18",
        &["off the table"],
    );
}

#[test]
fn a_named_position_inside_an_obstacle_is_refused() {
    let text = format!(
        "{BASE}\n[[positions]]\nname = \"A\"\npose = {{ x = 0.86, y = 0.1, theta = 0.0 }}\n"
    );
    refused(
        &text,
        "positions[0].pose",
        "pose = { x = 0.86",
        &["positions[0] (\"A\")", "inside obstacles[0]"],
    );
}

#[test]
fn the_robot_starting_inside_an_obstacle_is_refused() {
    let text = BASE.replace(
        "start = { x = 0.2, y = 0.45, theta = 0.0 }",
        "start = { x = 0.85, y = 0.65, theta = 0.0 }",
    );
    refused(&text, "robot.start", "start =", &["obstacles[1]"]);
}

#[test]
fn marker_heights_and_the_intrinsics_file() {
    let text = BASE.replace("size = 0.05 }", "size = 0.05, z = 0.03 }");
    let s = Scene::from_toml(&text, "t.toml").expect("a height");
    assert_eq!(s.objects[0].marker.unwrap().z, 0.03);
    assert_eq!(
        Scene::from_toml(BASE, "t.toml").unwrap().objects[0]
            .marker
            .unwrap()
            .z,
        0.0
    );
    let text = BASE.replace("size = 0.05 }", "size = 0.05, z = -0.01 }");
    refused(&text, "objects[0].marker", "marker =", &["z (its height"]);
    let text = format!("{BASE}\n[camera]\nintrinsics = \"cam.yaml\"\n");
    let s = Scene::from_toml(&text, "t.toml").expect("intrinsics");
    assert_eq!(
        s.camera.intrinsics,
        Some(pushbot_world::scene::IntrinsicsSpec::File(
            "cam.yaml".into()
        ))
    );
    let again = Scene::from_toml(&s.to_toml(), "t.toml").unwrap();
    assert_eq!(again, s);
    let text = format!("{BASE}\n[camera]\nlens = {{ k1 = 0.1 }}\n");
    let e = Scene::from_toml(&text, "t.toml").expect_err("unknown field");
    assert!(e.to_string().contains("lens"), "{e}");
}

#[test]
fn marker_ids_stay_unique() {
    let text = format!("{BASE}\n[camera]\nrobot_marker = {{ id = 3, x = 0.0, y = 0.0 }}\n");
    let e = Scene::from_toml(&text, "t.toml").expect_err("id 3 twice");
    assert!(e.to_string().contains("tag id 3 is already used"), "{e}");
}

fn with(section: &str) -> String {
    format!("{BASE}\n{section}\n")
}

#[test]
fn rearrange_values_are_checked_with_their_paths() {
    Scene::from_toml(&with("[rearrange]\ncell = 0.1"), "t.toml").expect("valid");
    let cases: &[(&str, &str, &str, &str)] = &[
        (
            "[rearrange]\ncell = 0.0001",
            "rearrange.cell",
            "cell =",
            "each side must be 1..=256",
        ),
        (
            "[rearrange]\ncell = 0.1\nrobot_size = 9",
            "rearrange.robot_size",
            "robot_size",
            "1..=8",
        ),
        (
            "[rearrange]\ncell = 0.1\nkg_per_mass = 0",
            "rearrange.kg_per_mass",
            "kg_per_mass",
            "positive",
        ),
        (
            "[rearrange]\ncell = 0.1\nrobot_goal = [5.0, 0.1]",
            "rearrange.robot_goal",
            "robot_goal",
            "not on the table",
        ),
        (
            "[rearrange]\ncell = 0.3\nmap = \"\"\"\n....\n.#..\n..?.\n\"\"\"",
            "rearrange.map",
            "map =",
            "unknown cell '?'",
        ),
        (
            "[rearrange]\ncell = 0.3\nmap = \"\"\"\n...\n\"\"\"",
            "rearrange.map",
            "map =",
            "3 rows of 4 cells",
        ),
        (
            "[rearrange]\ncell = 0.1\nrules = { push_dirs = \"NQ\" }",
            "rearrange.rules.push_dirs",
            "push_dirs",
            "'Q'",
        ),
        (
            "[rearrange]\ncell = 0.1\nmetric = { rough = [0, 2] }",
            "rearrange.metric.rough",
            "rough",
            "≥ 1",
        ),
        (
            "[rearrange]\ncell = 0.1\n[[rearrange.movable]]\nobject = \"nope\"",
            "rearrange.movable[0].object",
            "object = \"nope\"",
            "no object \"nope\"",
        ),
        (
            "[rearrange]\ncell = 0.1\n[[rearrange.movable]]\nobject = \"box\"\npush = [{ point = [0, 0], dir = \"up\" }]",
            "rearrange.movable[0].push[0].dir",
            "dir = \"up\"",
            "'up'",
        ),
        (
            "[rearrange]\ncell = 0.1\n[[rearrange.movable]]\nobject = \"box\"\nrotate = [{ point = [0, 0], dir = \"N\", turn = \"left\" }]",
            "rearrange.movable[0].rotate[0].turn",
            "turn = \"left\"",
            "cw or ccw",
        ),
    ];
    for (section, field, needle, words) in cases {
        refused(&with(section), field, needle, &[words]);
    }
}

const STABLE: &str = "[stable]\nobject = \"box\"\nedges = [0]\ngoal_xy_frac = 0.25\ngoal_theta_deg = 2.0\npusher = { kind = \"diff-drive\" }";

#[test]
fn stable_values_are_checked_with_their_paths() {
    Scene::from_toml(&with(STABLE), "t.toml").expect("valid");
    let cases: &[(&str, &str, &str, &str, &str)] = &[
        (
            "object = \"box\"",
            "object = \"nope\"",
            "stable.object",
            "object = \"nope\"",
            "no object",
        ),
        (
            "edges = [0]",
            "edges = [4]",
            "stable.edges",
            "edges =",
            "edges 0..=3",
        ),
        (
            "edges = [0]",
            "edges = []",
            "stable.edges",
            "edges =",
            "at least one",
        ),
        (
            "edges = [0]",
            "edges = [0]\nstart_edge = 2",
            "stable.start_edge",
            "start_edge",
            "not in stable.edges",
        ),
        (
            "goal_xy_frac = 0.25",
            "goal_xy_frac = 0",
            "stable.goal_xy_frac",
            "goal_xy_frac",
            "> 0",
        ),
        (
            "\"diff-drive\" }",
            "\"tank\" }",
            "stable.pusher.kind",
            "pusher =",
            "got \"tank\"",
        ),
        (
            "\"diff-drive\" }",
            "\"car\" }",
            "stable.pusher.min_turning_radius",
            "pusher =",
            "required for a car",
        ),
        (
            "\"diff-drive\" }",
            "\"arm\", width = -1 }",
            "stable.pusher.width",
            "width = -1",
            "≥ 0",
        ),
        (
            "\"diff-drive\" }",
            "\"arm\" }\nplanner = { c = \"lots\" }",
            "stable.planner.c",
            "c = \"lots\"",
            "\"inf\"",
        ),
        (
            "\"diff-drive\" }",
            "\"arm\" }\nplanner = { step_frac = 0 }",
            "stable.planner.step_frac",
            "step_frac",
            "> 0",
        ),
        (
            "\"diff-drive\" }",
            "\"arm\" }\nplanner = { max_cost = 2000000 }",
            "stable.planner.max_cost",
            "max_cost",
            "at most",
        ),
    ];
    for (from, to, field, needle, words) in cases {
        refused(&with(&STABLE.replace(from, to)), field, needle, &[words]);
    }
    // No goal for the stable object.
    let text = with(STABLE).replace(
        "[[goals]]\nobject = \"box\"\npose = { x = 1.0, y = 0.4, theta = 0.0 }\n",
        "",
    );
    refused(
        &text,
        "stable.object",
        "object = \"box\"\nedges",
        &["no goal"],
    );
}

#[test]
fn a_clockwise_stable_object_keeps_its_pushing_edge() {
    // Edge 0 of the clockwise square is its left side, (−0.04, −0.04) → (−0.04, 0.04).
    let text = with(&STABLE.replace("edges = [0]", "edges = [0]\nstart_edge = 0")).replace(
        "[[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]",
        "[[-0.04, -0.04], [-0.04, 0.04], [0.04, 0.04], [0.04, -0.04]]",
    );
    let (s, notes) = Scene::from_toml_noted(&text, "t.toml").expect("valid");
    let st = s.stable.as_ref().unwrap();
    assert_eq!(st.edges, [3]);
    assert_eq!(st.start_edge, Some(3));
    let o = &s.objects[0].outline;
    assert_eq!(
        (o[3], o[0]),
        ([-0.04, 0.04], [-0.04, -0.04]),
        "the same side"
    );
    assert!(
        notes[0].message.contains("stable.edges renumbered"),
        "{notes:?}"
    );
}

/// The scene's `camera.intrinsics` is read relative to the scene file into `camera.lens`; a
/// missing file, a broken one or one for another image size is refused at the key's line.
#[test]
fn the_lens_file_is_read_with_the_scene_and_checked() {
    use pushbot_world::lens::{Distortion, Intrinsics};
    use pushbot_world::lens_file::{LensFormat, write_intrinsics};
    let dir = tempfile::tempdir().expect("tempdir");
    let lens = Intrinsics {
        width: 960,
        height: 720,
        fx: 700.0,
        fy: 700.0,
        cx: 480.0,
        cy: 360.0,
        distortion: Distortion {
            k1: -0.08,
            ..Distortion::NONE
        },
    };
    std::fs::create_dir_all(dir.path().join("cams")).unwrap();
    std::fs::write(
        dir.path().join("cams/webcam.yaml"),
        write_intrinsics(&lens, LensFormat::OpenCv, "webcam"),
    )
    .unwrap();
    let scene_with = |intrinsics: &str| {
        let text = format!("{BASE}\n[camera]\nintrinsics = \"{intrinsics}\"\n");
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, &text).unwrap();
        (Scene::load(&path), text)
    };
    let (ok, _) = scene_with("cams/webcam.yaml");
    assert_eq!(ok.expect("loads").camera.lens, Some(lens));
    let (missing, text) = scene_with("cams/none.yaml");
    let e = missing.expect_err("refused").to_string();
    let line = line_of(&text, "intrinsics =");
    assert!(e.contains(&format!("scene.toml:{line}:")), "{e}");
    assert!(
        e.contains("camera.intrinsics") && e.contains("none.yaml"),
        "{e}"
    );
    std::fs::write(
        dir.path().join("cams/small.yaml"),
        write_intrinsics(
            &Intrinsics {
                width: 640,
                height: 480,
                cx: 320.0,
                cy: 240.0,
                ..lens
            },
            LensFormat::Ros,
            "small",
        ),
    )
    .unwrap();
    let (small, _) = scene_with("cams/small.yaml");
    let e = small.expect_err("refused").to_string();
    assert!(e.contains("640×480") && e.contains("960×720"), "{e}");
    std::fs::write(dir.path().join("cams/bad.yaml"), "camera_matrix: [\n").unwrap();
    let (bad, _) = scene_with("cams/bad.yaml");
    assert!(bad.is_err());
}

/// A lens written in the scene itself (OpenCV's numbers: pixel centres at integers) becomes the
/// camera's lens for its image size; a camera's pose, exposure and occluders are checked with
/// their paths.
#[test]
fn an_inline_lens_a_pose_an_exposure_and_occluders_are_read_and_checked() {
    let with = |camera: &str| Scene::from_toml(&format!("{BASE}\n[camera]\n{camera}\n"), "s.toml");
    let s = with("intrinsics = { fx = 700.0, fy = 702.0, cx = 479.5, cy = 359.5, k1 = -0.08 }")
        .expect("an inline lens");
    let lens = s.camera.lens.expect("the lens");
    assert_eq!(
        (lens.width, lens.height, lens.cx, lens.cy),
        (960, 720, 480.0, 360.0)
    );
    assert_eq!(
        (lens.fy, lens.distortion.k1, lens.distortion.k2),
        (702.0, -0.08, 0.0)
    );
    let e = with("intrinsics = { fx = -700.0, fy = 700.0, cx = 479.5, cy = 359.5 }")
        .expect_err("a negative focal length")
        .to_string();
    assert!(
        e.contains("camera.intrinsics") && e.contains("positive"),
        "{e}"
    );
    let e = with("intrinsics = { fx = 700.0, fy = 700.0, cx = 479.5, cy = 359.5, k9 = 1.0 }")
        .expect_err("an unknown coefficient")
        .to_string();
    assert!(e.contains("intrinsics"), "{e}");

    let s = with("pose = { eye = [0.6, -0.3, 1.0], look_at = [0.6, 0.45, 0.0] }\nexposure = 0.02")
        .expect("a placed camera");
    assert!(s.camera.pose.is_some() && s.camera.exposure == 0.02);
    assert_eq!(s.camera.optics().map(|l| l.fx), Some(0.73 * 960.0));
    let e = with("pose = { eye = [0.6, -0.3, 1.0], look_at = [0.6, 0.45, 2.0] }")
        .expect_err("looking up")
        .to_string();
    assert!(e.contains("camera.pose") && e.contains("look down"), "{e}");
    let e = with("exposure = 0.5")
        .expect_err("longer than a frame")
        .to_string();
    assert!(e.contains("camera.exposure"), "{e}");
    let e = with("occluders = [{ outline = [[0.1, 0.1], [0.3, 0.1], [0.3, 0.3]], z = -0.1 }]")
        .expect_err("below the table")
        .to_string();
    assert!(e.contains("camera.occluders[0].z"), "{e}");
    let ok = with(
        "occluders = [{ outline = [[0.1, 0.1], [0.3, 0.1], [0.3, 0.3]], z = 0.3, from = 1.0 }]",
    )
    .expect("a hand from 1 s on");
    let hand = &ok.camera.occluders[0];
    assert!(!hand.shown_at(0.5) && hand.shown_at(1.0) && hand.shown_at(1e9));
}

//! Bad input: the real `pushbot` and `pushbot-sim` binaries on malformed
//! scenes, strategy files, calibrations, devices and arguments. Each must exit with code 2,
//! not panic, and say what is wrong and where (file, line and field; the flag; the device).
//!
//! Every malformed scene is a one-line change of a scene that checks clean
//! ([`good_scene_checks_clean`]), so each case fails for the reason it is about.
//!
//! This file holds the malformed scenes; strategy files, calibrations, devices, numbers and
//! arguments are in `bad_input_args.rs`.

use pushbot_tests::run_bin;

mod bad_input_common;

use bad_input_common::{Files, GOOD, assert_bad_input, check_scene, edit, line_of, pushbot};

// ---- scenes -------------------------------------------------------------------------------

#[test]
fn good_scene_checks_clean() {
    let f = Files::new();
    let p = f.write("good.toml", GOOD);
    let r = check_scene(&p);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(r.stdout.contains("objects [box]"), "{r:?}");
}

#[test]
fn scene_missing_field() {
    let f = Files::new();
    let text = edit("mass =", "");
    let p = f.write("missing.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "[[objects]]"));
    assert_bad_input(&check_scene(&p), &[&at, "missing field `mass`"]);
}

#[test]
fn scene_missing_table() {
    let f = Files::new();
    let p = f.write("empty.toml", "");
    assert_bad_input(&check_scene(&p), &[&p, "missing field `table`"]);
}

#[test]
fn scene_wrong_type() {
    let f = Files::new();
    let text = edit("mass =", "mass = \"heavy\"");
    let p = f.write("type.toml", &text);
    let at = format!("{p}:{}:8: mass:", line_of(&text, "mass ="));
    assert_bad_input(&check_scene(&p), &[&at, "invalid type", "expected f64"]);
}

#[test]
fn scene_wrong_type_inside_an_inline_table() {
    let f = Files::new();
    let text = edit(
        "pose = { x = 0.8",
        "pose = { x = \"left\", y = 0.45, theta = 0.0 }",
    );
    let p = f.write("inline.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "pose = { x = \"left\""));
    assert_bad_input(&check_scene(&p), &[&at, "x: invalid type"]);
}

#[test]
fn scene_unknown_field() {
    let f = Files::new();
    let text = edit("mass =", "mass = 0.2\ncolour = \"red\"");
    let p = f.write("unknown.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "colour"));
    assert_bad_input(&check_scene(&p), &[&at, "unknown field `colour`", "`mass`"]);
}

#[test]
fn scene_syntax_error() {
    let f = Files::new();
    let text = edit("height =", "height = [0.9");
    let p = f.write("syntax.toml", &text);
    // The parser notices at the next token, the `[[obstacles]]` header.
    let at = format!("{p}:{}:", line_of(&text, "[[obstacles]]"));
    assert_bad_input(&check_scene(&p), &[&at, "expected"]);
}

#[test]
fn scene_self_intersecting_polygon() {
    let f = Files::new();
    // A bow-tie: edges 0 and 2 cross.
    let text = edit(
        "outline = [[-0.04",
        "outline = [[-0.04, -0.04], [0.04, 0.04], [0.04, -0.04], [-0.04, 0.04]]",
    );
    let p = f.write("bowtie.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "outline = [[-0.04"));
    assert_bad_input(&check_scene(&p), &[&at, "objects[0].outline", "not simple"]);
}

#[test]
fn scene_obstacle_with_two_vertices() {
    let f = Files::new();
    let text = edit("outline = [[0.5", "outline = [[0.5, 0.0], [0.55, 0.0]]");
    let p = f.write("line.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "outline = [[0.5"));
    assert_bad_input(
        &check_scene(&p),
        &[&at, "obstacles[0].outline", "at least 3"],
    );
}

#[test]
fn scene_goal_outside_the_table() {
    let f = Files::new();
    let text = edit(
        "pose = { x = 1.0",
        "pose = { x = 1.5, y = 0.7, theta = 0.0 }",
    );
    let p = f.write("goal.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "pose = { x = 1.5"));
    assert_bad_input(&check_scene(&p), &[&at, "goals[0].pose", "on the table"]);
}

#[test]
fn scene_object_outside_the_table() {
    let f = Files::new();
    let text = edit(
        "pose = { x = 0.8",
        "pose = { x = 1.19, y = 0.45, theta = 0.0 }",
    );
    let p = f.write("object.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "pose = { x = 1.19"));
    assert_bad_input(&check_scene(&p), &[&at, "objects[0].pose", "on the table"]);
}

#[test]
fn scene_object_overlapping_an_obstacle() {
    let f = Files::new();
    // The box's centre on the obstacle's edge.
    let text = edit(
        "pose = { x = 0.8",
        "pose = { x = 0.5, y = 0.15, theta = 0.0 }",
    );
    let p = f.write("overlap.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "pose = { x = 0.5"));
    assert_bad_input(
        &check_scene(&p),
        &[&at, "objects[0].pose", "overlaps obstacles[0]"],
    );
}

#[test]
fn scene_duplicate_object_ids() {
    let f = Files::new();
    let second = r#"[[objects]]
id = "box"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 1.0, y = 0.2, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5

[[goals]]"#;
    let text = edit("[[goals]]", second);
    let p = f.write("dup.toml", &text);
    // The second object's id line.
    let id_line = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("id = "))
        .nth(1)
        .expect("two ids")
        .0
        + 1;
    assert_bad_input(
        &check_scene(&p),
        &[
            &format!("{p}:{id_line}:"),
            "objects[1].id",
            "duplicate object id \"box\"",
        ],
    );
}

#[test]
fn scene_duplicate_marker_id() {
    let f = Files::new();
    let text = edit(
        "pose = { x = 1.0",
        "pose = { x = 1.0, y = 0.7, theta = 0.0 }\nmarker = { id = 3, x = 0.0, y = 0.0 }",
    );
    let p = f.write("marker.toml", &text);
    let r = check_scene(&p);
    assert_bad_input(
        &r,
        &[
            "goals[0].marker",
            "tag id 3 is already used by objects[0].marker",
        ],
    );
    // The line is the goal's marker, the second `marker =` line.
    let goal_marker = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("marker ="))
        .nth(1)
        .expect("two markers")
        .0
        + 1;
    assert!(r.stderr.contains(&format!("{p}:{goal_marker}:")), "{r:?}");
}

#[test]
fn scene_negative_and_nan_values() {
    let f = Files::new();
    let text = edit("mass =", "mass = -0.2");
    let p = f.write("negative.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "mass ="));
    assert_bad_input(
        &check_scene(&p),
        &[&at, "objects[0].mass", "must be positive"],
    );
    let text = edit("support_friction =", "support_friction = nan");
    let p = f.write("nan.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "support_friction"));
    assert_bad_input(&check_scene(&p), &[&at, "objects[0].support_friction"]);
}

#[test]
fn scene_goal_for_a_missing_object() {
    let f = Files::new();
    let text = edit("object = \"box\"", "object = \"ball\"");
    let p = f.write("goalobj.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "object = \"ball\""));
    assert_bad_input(
        &check_scene(&p),
        &[&at, "goals[0].object", "no object \"ball\""],
    );
}

#[test]
fn scene_unknown_preset() {
    let r = check_scene("lau-irreguler");
    assert_bad_input(
        &r,
        &["lau-irreguler", "no such preset or file", "lau-irregular"],
    );
}

#[test]
fn scene_directory_and_binary_file() {
    let f = Files::new();
    let dir = f.0.path().to_str().expect("UTF-8").to_owned();
    assert_bad_input(&check_scene(&dir), &[&dir, "is a directory"]);
    let bin = f.write("scene.toml", [0u8, 159, 146, 150, 255, 0, 1, 2]);
    assert_bad_input(&check_scene(&bin), &[&bin, "not a text (TOML) file"]);
}

#[test]
fn bad_scene_through_every_command_that_takes_one() {
    let f = Files::new();
    let text = edit("mass =", "mass = -1.0");
    let p = f.write("cmds.toml", &text);
    let at = format!("{p}:{}:", line_of(&text, "mass ="));
    let needles = [at.as_str(), "objects[0].mass"];
    // The scene is read before any device is opened or anything is run.
    for args in [
        vec!["eval", "delivery", "--scene", &p, "--trials", "1"],
        vec!["robot", "info", "--scene", &p],
        vec!["track", "--camera", "/dev/video99", "--scene", &p],
        vec!["calibrate", "--camera", "/dev/video99", "--scene", &p],
        vec!["collect", "--object", "box", "--scene", &p],
    ] {
        let r = pushbot(&args);
        assert_bad_input(&r, &needles);
    }
    let r = run_bin("pushbot-sim", &["--scene", &p]);
    assert_bad_input(&r, &needles);
}

#[test]
fn planner_scenes_that_are_missing_or_not_files() {
    let f = Files::new();
    let dir = f.0.path().to_str().expect("UTF-8").to_owned();
    let missing = f.path("nowhere.toml");
    let missing = missing.to_str().expect("UTF-8");
    for cmd in [
        &["plan", "rearrange"][..],
        &["plan", "stable"],
        &["mechanics"],
    ] {
        for scene in [dir.as_str(), missing, "no-such-preset"] {
            let mut args = cmd.to_vec();
            args.extend(["--scene", scene]);
            assert_bad_input(&pushbot(&args), &[scene]);
        }
    }
}

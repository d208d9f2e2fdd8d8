//! Bad input (issue 9, item 3): the real `pushbot` and `pushbot-sim` binaries on malformed
//! scenes, strategy files, calibrations, devices and arguments. Each must exit with code 2,
//! not panic, and say what is wrong and where (file, line and field; the flag; the device).
//!
//! Every malformed scene is a one-line change of a scene that checks clean
//! ([`good_scene_checks_clean`]), so each case fails for the reason it is about.

use std::path::{Path, PathBuf};

use pushbot_tests::{Run, run_bin};

/// A scene in the shared format that passes every check.
const GOOD: &str = r#"name = "bad-input-base"
[table]
width = 1.2
height = 0.9

[[obstacles]]
outline = [[0.5, 0.0], [0.55, 0.0], [0.55, 0.3], [0.5, 0.3]]

[[objects]]
id = "box"
outline = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
pose = { x = 0.8, y = 0.45, theta = 0.0 }
mass = 0.2
support_friction = 0.35
pusher_friction = 0.5
marker = { id = 3, x = 0.0, y = 0.0 }

[[goals]]
object = "box"
pose = { x = 1.0, y = 0.7, theta = 0.0 }
"#;

/// A temporary folder for the files of one test.
struct Files(tempfile::TempDir);

impl Files {
    fn new() -> Files {
        Files(tempfile::tempdir().expect("a temporary folder"))
    }

    /// Write `text` to `name` in the folder; its path as a string.
    fn write(&self, name: &str, text: impl AsRef<[u8]>) -> String {
        let p = self.0.path().join(name);
        std::fs::write(&p, text).expect("write a test file");
        p.to_str().expect("a UTF-8 temporary path").to_owned()
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }
}

/// `GOOD` with the line starting with `from` replaced by `to` (which may be several lines).
fn edit(from: &str, to: &str) -> String {
    let mut found = false;
    let out: Vec<String> = GOOD
        .lines()
        .map(|l| {
            if !found && l.starts_with(from) {
                found = true;
                to.to_owned()
            } else {
                l.to_owned()
            }
        })
        .collect();
    assert!(found, "no line starting with {from:?} in the base scene");
    out.join("\n") + "\n"
}

/// 1-based number of the first line of `text` that starts with `start`.
fn line_of(text: &str, start: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(start))
        .expect("the line is there")
        + 1
}

/// The run exited 2 without a panic, and stderr holds every one of `needles`.
#[track_caller]
fn assert_bad_input(r: &Run, needles: &[&str]) {
    assert!(!r.stderr.contains("panicked"), "panicked:\n{}", r.stderr);
    assert_eq!(r.code, Some(2), "exit code; stderr:\n{}", r.stderr);
    for n in needles {
        assert!(r.stderr.contains(n), "stderr lacks {n:?}:\n{}", r.stderr);
    }
}

fn pushbot(args: &[&str]) -> Run {
    run_bin("pushbot", args)
}

fn check_scene(path: &str) -> Run {
    pushbot(&["scene", "check", "--scene", path])
}

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

// ---- strategy files ------------------------------------------------------------------------

/// `pushbot eval delivery` of the learned method with the strategy file `path`: the file is
/// read before any trial runs.
fn eval_with_strategy(path: &str) -> Run {
    pushbot(&[
        "eval",
        "delivery",
        "--scene",
        "lau-irregular",
        "--method",
        "learned",
        "--start",
        "A",
        "--trials",
        "1",
        "--strategy",
        path,
    ])
}

const STRATEGY_HEAD: &str =
    "pushbot-strategy 1\nobject irregular\ncolumns p_x p_y r_x r_y s_x s_y theta\n";

#[test]
fn strategy_truncated() {
    let f = Files::new();
    let p = f.write("cut.strategy", "pushbot-strategy 1\nobject irregular\n");
    assert_bad_input(
        &eval_with_strategy(&p),
        &[&format!("{p}:3:"), "missing columns line"],
    );
    let p = f.write("empty.strategy", "");
    assert_bad_input(&eval_with_strategy(&p), &[&format!("{p}:1:"), "empty"]);
    // A sample cut short (with its newline: not a crash mid-write).
    let p = f.write(
        "short.strategy",
        format!("{STRATEGY_HEAD}0.01 0.02 0.03 0.04 0.05 0.06 0.07\n0.01 0.02 0.03\n"),
    );
    assert_bad_input(
        &eval_with_strategy(&p),
        &[&format!("{p}:5:"), "missing r_y"],
    );
}

#[test]
fn strategy_bad_header() {
    let f = Files::new();
    let p = f.write("header.strategy", "p_x,p_y,r_x\n0.1,0.2,0.3\n");
    assert_bad_input(
        &eval_with_strategy(&p),
        &[&format!("{p}:1:"), "not a pushing strategy file"],
    );
}

#[test]
fn strategy_wrong_version() {
    let f = Files::new();
    let p = f.write(
        "v9.strategy",
        STRATEGY_HEAD.replace("pushbot-strategy 1", "pushbot-strategy 9"),
    );
    assert_bad_input(
        &eval_with_strategy(&p),
        &[&format!("{p}:1:"), "format version 9", "reads version 1"],
    );
}

#[test]
fn strategy_value_not_a_number() {
    let f = Files::new();
    let p = f.write(
        "nan.strategy",
        format!("{STRATEGY_HEAD}0.01 0.02 NaN 0.04 0.05 0.06 0.07\n"),
    );
    assert_bad_input(
        &eval_with_strategy(&p),
        &[&format!("{p}:4:"), "r_x is `NaN`, not a finite number"],
    );
}

#[test]
fn strategy_file_that_is_missing_or_a_directory() {
    let f = Files::new();
    let missing = f.path("none.strategy");
    let missing = missing.to_str().expect("UTF-8");
    assert_bad_input(&eval_with_strategy(missing), &[missing, "No such file"]);
    let dir = f.0.path().to_str().expect("UTF-8");
    assert_bad_input(&eval_with_strategy(dir), &[dir]);
}

#[test]
fn collect_refuses_to_append_to_a_damaged_strategy() {
    let f = Files::new();
    let p = f.write("damaged.strategy", "pushbot-strategy 2\n");
    let r = pushbot(&["collect", "--object", "irregular", "--out", &p]);
    assert_bad_input(&r, &[&format!("{p}:1:"), "format version 2"]);
    // Nothing was appended.
    assert_eq!(
        std::fs::read_to_string(&p).expect("read back"),
        "pushbot-strategy 2\n"
    );
}

// ---- calibration ---------------------------------------------------------------------------

/// A folder with one (unread) image file, so the folder source opens.
fn image_folder(f: &Files) -> String {
    std::fs::create_dir(f.path("frames")).expect("make the folder");
    f.write(
        "frames/frame-000000.png",
        b"not read before the calibration",
    );
    f.path("frames").to_str().expect("UTF-8").to_owned()
}

#[test]
fn calibration_malformed() {
    let f = Files::new();
    let frames = image_folder(&f);
    for (name, text, needle) in [
        ("garbage.json", "{ this is not json", "not a calibration"),
        ("empty.json", "{}", "not a calibration"),
        ("list.json", "[1, 2, 3]", "not a calibration"),
    ] {
        let cal = f.write(name, text);
        let r = pushbot(&["track", "--camera", &frames, "--calibration", &cal]);
        assert_bad_input(&r, &[&cal, needle]);
    }
    let missing = f.path("missing.json");
    let missing = missing.to_str().expect("UTF-8");
    let r = pushbot(&["track", "--camera", &frames, "--calibration", missing]);
    assert_bad_input(&r, &[missing, "cannot read"]);
}

// ---- serial ports --------------------------------------------------------------------------

#[test]
fn serial_port_that_does_not_exist() {
    let r = pushbot(&["robot", "info", "--port", "/dev/ttyPUSHBOT99"]);
    assert_bad_input(&r, &["no serial port at /dev/ttyPUSHBOT99"]);
}

#[test]
fn serial_port_that_is_not_a_tty() {
    let f = Files::new();
    let file = f.write("port", "");
    let dir = f.0.path().to_str().expect("UTF-8").to_owned();
    for (port, why) in [
        ("/dev/null", "not a terminal device"),
        (file.as_str(), "a regular file"),
        (dir.as_str(), "a directory"),
    ] {
        let r = pushbot(&["robot", "info", "--port", port]);
        assert_bad_input(&r, &[&format!("{port} is not a serial port"), why]);
    }
}

// ---- cameras -------------------------------------------------------------------------------

#[test]
fn camera_device_that_does_not_exist() {
    let r = pushbot(&["track", "--camera", "/dev/video99"]);
    assert_bad_input(&r, &["camera device /dev/video99 does not exist"]);
    let r = pushbot(&["calibrate", "--camera", "v4l2:/dev/video98"]);
    assert_bad_input(&r, &["/dev/video98 does not exist"]);
}

#[test]
fn sim_camera_that_is_not_there() {
    let r = pushbot(&["track", "--camera", "sim:127.0.0.1:1"]);
    assert_bad_input(&r, &["cannot connect to the sim camera at 127.0.0.1:1"]);
}

#[test]
fn camera_folder_missing_empty_or_a_file() {
    let f = Files::new();
    let missing = f.path("no-frames");
    let missing = missing.to_str().expect("UTF-8");
    assert_bad_input(
        &pushbot(&["track", "--camera", missing]),
        &[missing, "does not exist"],
    );
    std::fs::create_dir(f.path("empty")).expect("make the folder");
    let empty = f.path("empty");
    let empty = empty.to_str().expect("UTF-8");
    assert_bad_input(
        &pushbot(&["calibrate", "--camera", empty]),
        &[empty, "has no .png or .jpg files"],
    );
    let file = f.write("frame.png", "x");
    assert_bad_input(
        &pushbot(&["track", "--camera", &file]),
        &[&file, "is not a directory"],
    );
}

// ---- numbers -------------------------------------------------------------------------------

#[test]
fn out_of_range_numbers() {
    for (args, needle) in [
        (
            &["robot", "move", "--distance", "0.1", "--speed", "-0.1"][..],
            "--speed",
        ),
        (&["robot", "move", "--distance", "NaN"], "--distance"),
        (&["robot", "move", "--distance", "inf"], "--distance"),
        (&["robot", "spin", "--angle", "90", "--rate", "0"], "--rate"),
        (&["robot", "--sim-speed=-2", "info"], "--sim-speed"),
        (
            &[
                "eval",
                "delivery",
                "--scene",
                "lau-irregular",
                "--time-limit=-5",
            ],
            "--time-limit",
        ),
        (&["bench", "knn", "--samples", "0"], "samples"),
        (
            &["track", "--camera", "/dev/video99", "--frames", "0"],
            "--frames",
        ),
    ] {
        assert_bad_input(&pushbot(args), &[needle]);
    }
}

#[test]
fn numbers_that_do_not_parse() {
    for (args, needle) in [
        (&["--seed", "abc", "robot", "info"][..], "'--seed"),
        (&["robot", "move", "--distance", "ten"], "'--distance"),
        (&["bench", "knn", "--samples", "1e3"], "1e3"),
    ] {
        assert_bad_input(&pushbot(args), &[needle, "invalid value"]);
    }
}

// ---- arguments -----------------------------------------------------------------------------

#[test]
fn unknown_subcommand_and_flag() {
    assert_bad_input(
        &pushbot(&["frobnicate"]),
        &["unrecognized subcommand 'frobnicate'"],
    );
    assert_bad_input(
        &pushbot(&["robot", "info", "--bogus"]),
        &["unexpected argument '--bogus'"],
    );
    assert_bad_input(&pushbot(&["plan", "rearrange"]), &["--scene"]);
    assert_bad_input(
        &pushbot(&[
            "robot",
            "info",
            "--port",
            "/dev/null",
            "--scene",
            "three-boxes",
        ]),
        &["cannot be used with"],
    );
}

#[test]
fn json_errors_on_stdout() {
    // A check of ours.
    let r = pushbot(&["--json", "robot", "move", "--distance", "nan"]);
    assert_bad_input(&r, &["--distance"]);
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    assert_eq!(v["error"]["kind"], "bad_input", "{v}");
    assert_eq!(v["error"]["exit_code"], 2, "{v}");
    assert!(
        v["error"]["message"]
            .as_str()
            .is_some_and(|m| m.contains("--distance")),
        "{v}"
    );
    // A scene error keeps its place in the message.
    let f = Files::new();
    let text = edit("mass =", "mass = 0");
    let p = f.write("json.toml", &text);
    let r = pushbot(&["scene", "check", "--scene", &p, "--json"]);
    assert_bad_input(&r, &["objects[0].mass"]);
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    let at = format!("{p}:{}:", line_of(&text, "mass ="));
    assert!(
        v["error"]["message"]
            .as_str()
            .is_some_and(|m| m.contains(&at)),
        "{v}"
    );
    // The parser's own errors.
    let r = pushbot(&["--json", "robot", "info", "--bogus"]);
    assert_bad_input(&r, &["--bogus"]);
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    assert_eq!(v["error"]["exit_code"], 2, "{v}");
    assert!(
        v["error"]["message"]
            .as_str()
            .is_some_and(|m| m.contains("--bogus")),
        "{v}"
    );
}

// ---- pushbot-sim ---------------------------------------------------------------------------

#[test]
fn sim_binary_bad_input() {
    let f = Files::new();
    let csv = f.write("pusher.csv", "t,x,y,theta\n0,0.1,0.1,0\n1,0.2\n");
    for (args, needle) in [
        (&["--speed=-1"][..], "speed"),
        (&["--speed", "NaN"], "speed"),
        (&["--start", "5", "5", "0"], "start pose"),
        (&["--faults", "--fault-drop", "2"], "--fault-drop"),
        (&["--scene", "no-such-preset"], "no such preset or file"),
        (&["--bogus"], "--bogus"),
        (&["bench", "--seconds", "0"], "--seconds"),
        (
            &[
                "replay",
                "--scene",
                "three-boxes",
                "--object",
                "box-1",
                "--pusher",
                &csv,
            ],
            ":3: expected 4 numbers",
        ),
    ] {
        let r = run_bin("pushbot-sim", args);
        assert_bad_input(&r, &[needle]);
    }
}

/// The test's own helper gives the path it was asked for.
#[test]
fn binaries_are_found() {
    for name in ["pushbot", "pushbot-sim"] {
        let p = pushbot_tests::bin(name);
        assert!(Path::new(&p).is_file(), "{}", p.display());
    }
}

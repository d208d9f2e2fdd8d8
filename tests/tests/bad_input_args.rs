//! Bad input, continued from `bad_input.rs`: the real `pushbot` and
//! `pushbot-sim` binaries on malformed strategy files, calibrations, serial ports, cameras,
//! numbers and arguments. Each must exit with code 2, not panic, and say what is wrong and where
//! (file, line and field; the flag; the device).

use std::path::Path;

use pushbot_tests::{Run, run_bin};

mod bad_input_common;

use bad_input_common::{Files, assert_bad_input, edit, line_of, pushbot};

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

// ---- lens files ----------------------------------------------------------------------------

/// `--intrinsics` that is missing, not YAML of either format, or not a plumb_bob lens: exit 2,
/// naming the file and what is wrong, before anything runs.
#[test]
fn intrinsics_files_that_do_not_make_a_lens() {
    let f = Files::new();
    let broken = f.write("broken.yaml", "camera_matrix: [\n");
    let fisheye = f.write(
        "fisheye.yaml",
        "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  \
         data: [600, 0, 320, 0, 600, 240, 0, 0, 1]\ndistortion_model: equidistant\n\
         distortion_coefficients:\n  rows: 1\n  cols: 4\n  data: [0.1, 0, 0, 0]\n",
    );
    let missing = f.path("missing.yaml");
    let missing = missing.to_str().expect("UTF-8").to_owned();
    for (file, needle) in [
        (broken.as_str(), "not a ROS camera_info or OpenCV"),
        (fisheye.as_str(), "only plumb_bob"),
        (missing.as_str(), "No such file"),
    ] {
        let r = pushbot(&["--intrinsics", file, "demo", "--stages", "stable"]);
        assert_bad_input(&r, &[file, needle]);
    }
}

/// A disturbance that does not parse, or names no object of any stage, is refused before
/// anything runs; so is one for `pushbot-sim`'s scene.
#[test]
fn disturbances_that_are_malformed_or_name_no_object() {
    let r = pushbot(&["demo", "--stages", "rearrange", "--disturb", "25:b:0"]);
    assert_bad_input(&r, &["--disturb", "AT:OBJECT:DX:DY"]);
    let r = pushbot(&["demo", "--stages", "rearrange", "--disturb", "x:b:0:0.1"]);
    assert_bad_input(&r, &["--disturb", "not a number"]);
    let r = pushbot(&["demo", "--stages", "rearrange", "--disturb", "25:zz:0:0.1"]);
    assert_bad_input(&r, &["--disturb", "\"zz\"", "a, b"]);
    let r = run_bin(
        "pushbot-sim",
        &["--scene", "bsr-a1", "--no-stdin", "--disturb", "5:zz:0:0.1"],
    );
    assert_bad_input(&r, &["--disturb", "\"zz\""]);
}

//! Shared by the bad-input test files: a scene that checks clean, temporary files, one-line
//! edits of the scene, and the check that a run was refused as bad input.

#![allow(dead_code)]

use std::path::PathBuf;

use pushbot_tests::{Run, run_bin};

/// A scene in the shared format that passes every check.
pub const GOOD: &str = r#"name = "bad-input-base"
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
pub struct Files(pub tempfile::TempDir);

impl Files {
    pub fn new() -> Files {
        Files(tempfile::tempdir().expect("a temporary folder"))
    }

    /// Write `text` to `name` in the folder; its path as a string.
    pub fn write(&self, name: &str, text: impl AsRef<[u8]>) -> String {
        let p = self.0.path().join(name);
        std::fs::write(&p, text).expect("write a test file");
        p.to_str().expect("a UTF-8 temporary path").to_owned()
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }
}

/// `GOOD` with the line starting with `from` replaced by `to` (which may be several lines).
pub fn edit(from: &str, to: &str) -> String {
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
pub fn line_of(text: &str, start: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(start))
        .expect("the line is there")
        + 1
}

/// The run exited 2 without a panic, and stderr holds every one of `needles`.
#[track_caller]
pub fn assert_bad_input(r: &Run, needles: &[&str]) {
    assert!(!r.stderr.contains("panicked"), "panicked:\n{}", r.stderr);
    assert_eq!(r.code, Some(2), "exit code; stderr:\n{}", r.stderr);
    for n in needles {
        assert!(r.stderr.contains(n), "stderr lacks {n:?}:\n{}", r.stderr);
    }
}

pub fn pushbot(args: &[&str]) -> Run {
    run_bin("pushbot", args)
}

pub fn check_scene(path: &str) -> Run {
    pushbot(&["scene", "check", "--scene", path])
}

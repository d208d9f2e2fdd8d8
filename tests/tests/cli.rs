//! HIL: the `pushbot robot …` command line against a simulated robot on a pty given with
//! `--port`, judged by ground truth, and its exit-code classes.

use clap::Parser;
use pushbot::cli::{Cli, CliError, Status, run};
use pushbot_tests::{dist, sim_at};

fn cli(args: &[&str]) -> Result<Status, CliError> {
    let mut argv = vec!["pushbot"];
    argv.extend_from_slice(args);
    run(Cli::try_parse_from(argv).expect("arguments parse"))
}

#[test]
fn robot_move_and_spin_over_a_given_port() {
    let sim = sim_at(11, 0.4, 0.45, 0.0);
    let port = sim.serial_path().to_string();
    let start = sim.truth().pose;
    let st = cli(&["robot", "move", "--distance", "0.2", "--port", &port]).unwrap();
    assert_eq!(st, Status::Success);
    let moved = dist(&start, &sim.truth().pose);
    assert!((moved - 0.2).abs() < 0.01, "moved {moved} m");
    // Negative angles parse; degrees on the command line.
    let before = sim.truth().pose.theta;
    let st = cli(&["--json", "robot", "spin", "--angle", "-45", "--port", &port]).unwrap();
    assert_eq!(st, Status::Success);
    let turned = pushbot_tests::angle_diff(sim.truth().pose.theta, before).to_degrees();
    assert!((turned + 45.0).abs() < 3.0, "turned {turned}°");
    let st = cli(&["robot", "estop", "--port", &port]).unwrap();
    assert_eq!(st, Status::Success);
    // Faulted: motion refused (exit 1), clear-faults releases it.
    let err = cli(&["robot", "move", "--distance", "0.1", "--port", &port]).unwrap_err();
    assert!(matches!(err, CliError::Failed(_)), "{err}");
    assert!(err.to_string().contains("EMERGENCY_STOP"), "{err}");
    assert_eq!(
        cli(&["robot", "clear-faults", "--port", &port]).unwrap(),
        Status::Success
    );
    assert_eq!(
        cli(&["robot", "move", "--distance", "0.05", "--port", &port]).unwrap(),
        Status::Success
    );
}

#[test]
fn bad_ports_and_values_are_bad_input() {
    for port in ["/nonexistent/ttyX", "/dev/null"] {
        let err = cli(&["robot", "info", "--port", port]).unwrap_err();
        assert!(matches!(err, CliError::BadInput(_)), "{port}: {err}");
        assert!(err.to_string().contains(port), "{err}");
    }
    let err = cli(&["robot", "move", "--distance", "inf"]).unwrap_err();
    assert!(matches!(err, CliError::BadInput(_)), "{err}");
    // Beyond the robot's limits: refused by the (built-in simulated) robot, still bad input.
    let err = cli(&["robot", "move", "--distance", "0.1", "--speed", "5"]).unwrap_err();
    assert!(matches!(err, CliError::BadInput(_)), "{err}");
}

/// Every command's path below `pushbot` (`[]` is `pushbot` itself), from the real command tree.
fn command_paths() -> Vec<Vec<String>> {
    fn walk(cmd: &clap::Command, path: Vec<String>, out: &mut Vec<Vec<String>>) {
        for sub in cmd.get_subcommands() {
            if sub.get_name() == "help" {
                continue;
            }
            let mut p = path.clone();
            p.push(sub.get_name().to_owned());
            walk(sub, p, out);
        }
        out.push(path);
    }
    let mut out = Vec::new();
    walk(&pushbot::cli::command(), Vec::new(), &mut out);
    out
}

#[test]
fn every_command_help_ends_with_an_example_of_itself() {
    let paths = command_paths();
    assert!(paths.len() > 20, "{paths:?}");
    for path in paths {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let r = pushbot_tests::run_bin("pushbot", &args);
        assert_eq!(r.code, Some(0), "{args:?}: {r:?}");
        let (_, example) = r
            .stdout
            .split_once("\nExample:\n")
            .or_else(|| r.stdout.split_once("\nExamples:\n"))
            .unwrap_or_else(|| {
                panic!("`pushbot {}` has no example:\n{}", path.join(" "), r.stdout)
            });
        let first = example.lines().next().unwrap_or_default().trim();
        let want = ["pushbot".to_owned()]
            .into_iter()
            .chain(path.iter().cloned())
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            first.starts_with(&want),
            "the example of `{want}` is `{first}`"
        );
    }
}

#[test]
fn every_example_parses_and_names_a_command() {
    let paths: Vec<String> = command_paths().iter().map(|p| p.join(" ")).collect();
    for (path, text) in pushbot::cli::EXAMPLES {
        assert!(paths.contains(&path.to_string()), "no command `{path}`");
        for line in text.lines() {
            let argv: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(argv.first(), Some(&"pushbot"), "{line}");
            let parsed = pushbot::cli::command().try_get_matches_from(&argv);
            assert!(
                parsed.is_ok(),
                "`{line}` does not parse: {:?}",
                parsed.err()
            );
        }
    }
}

#[test]
fn the_documented_global_flags_are_everywhere() {
    // --json, --seed and -v on every command; --scene wherever a world is simulated or planned.
    for path in command_paths() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let help = pushbot::cli::command()
            .try_get_matches_from(["pushbot"].into_iter().chain(args.iter().copied()))
            .unwrap_err()
            .render()
            .to_string();
        for flag in ["--json", "--seed", "--verbose"] {
            assert!(
                help.contains(flag),
                "`pushbot {}` lacks {flag}",
                path.join(" ")
            );
        }
    }
}

/// Run `pushbot args` with its standard output a pipe whose reader has already gone.
fn into_closed_pipe(args: &[&str]) -> std::process::Output {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    std::process::Command::new(pushbot_tests::bin("pushbot"))
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start pushbot")
        .wait_with_output()
        .expect("wait for pushbot")
}

#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    use std::os::unix::process::ExitStatusExt;
    for args in [
        &["scene", "list"][..],
        &["plan", "rearrange", "--scene", "A1"],
        &["--help"],
        &["robot", "move", "--help"],
    ] {
        let out = into_closed_pipe(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        // Killed by SIGPIPE, like any Unix filter (not the panic's exit code 101).
        assert_eq!(out.status.signal(), Some(13), "{args:?}: {:?}", out.status);
    }
}

#[test]
fn piped_into_head_gives_one_line_and_no_noise() {
    let bin = pushbot_tests::bin("pushbot");
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("'{}' scene list | head -1", bin.display()))
        .output()
        .expect("run sh");
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).lines().count(),
        1,
        "{out:?}"
    );
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn logs_go_to_stderr_at_the_level_of_v() {
    // Quiet by default: only the result, on stdout.
    let r = pushbot_tests::run_bin("pushbot", &["--json", "robot", "info", "--seed", "3"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(!r.stderr.contains("built-in simulated robot"), "{r:?}");
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    assert_eq!(v["simulated"], true, "{v}");
    // -v: info logs on stderr, stdout still one JSON object; --scene picks the sim's world.
    let r = pushbot_tests::run_bin(
        "pushbot",
        &["-v", "robot", "info", "--json", "--scene", "three-boxes"],
    );
    assert_eq!(r.code, Some(0), "{r:?}");
    assert!(r.stderr.contains("INFO"), "{r:?}");
    assert!(
        r.stderr.contains("built-in simulated robot on /dev/pts/"),
        "{r:?}"
    );
    let v: serde_json::Value = serde_json::from_str(r.stdout.trim()).expect("one JSON object");
    assert_eq!(v["command"], "info", "{v}");
}

#[test]
fn exit_codes_are_in_the_top_level_help() {
    let r = pushbot_tests::run_bin("pushbot", &["--help"]);
    assert_eq!(r.code, Some(0), "{r:?}");
    for needle in ["Exit status: 0 success", "1 the task failed", "2 bad input"] {
        assert!(r.stdout.contains(needle), "{needle}: {}", r.stdout);
    }
}

#[test]
fn exact_goal_finishes_a_car_plan_and_says_clearly_when_nothing_finishes() {
    let run = |scene: &str| {
        std::process::Command::new(pushbot_tests::bin("pushbot"))
            .args(["--json", "plan", "stable", "--scene", scene, "--exact-goal"])
            .output()
            .expect("run pushbot")
    };
    // Fig. 15's car-like pusher has no single exact push (its pushes turn about its rear
    // axle only); the Dubins finish of its tightest stable turns ends on the goal.
    let out = run("fig15");
    assert!(out.status.success(), "{out:?}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["found"], true, "{v}");
    assert_eq!(v["exact_goal"], true, "{v}");
    // Fig. 16's slot with the goal moved 5 mm into the right-hand obstacle: such a goal is
    // refused when the scene is read, naming the goal, the obstacle and where the
    // goal is written — before any planning, with or without --exact-goal.
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("fig16-wall.toml");
    std::fs::write(&scene, FIG16_GOAL_IN_WALL).expect("write scene");
    for exact in [true, false] {
        let mut cmd = std::process::Command::new(pushbot_tests::bin("pushbot"));
        cmd.args(["--json", "plan", "stable", "--scene"])
            .arg(&scene);
        if exact {
            cmd.arg("--exact-goal");
        }
        let out = cmd.output().expect("run pushbot");
        assert_eq!(out.status.code(), Some(2), "{out:?}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
        assert!(
            v["error"]["message"]
                .as_str()
                .is_some_and(|m| m.contains("fig16-wall.toml:")
                    && m.contains("goals[0]")
                    && m.contains("inside obstacles[1]")),
            "{v}"
        );
    }
}

/// Fig. 16's scene with the goal 11.2 cm right of the slot's centre: at the goal's heading
/// (90°) the slider's right side is at x = 0.855, 5 mm inside the obstacle that starts at 0.85.
const FIG16_GOAL_IN_WALL: &str = r#"name = "fig16-goal-in-wall"
[table]
width = 1.2
height = 0.8
[robot]
start = { x = 0.8, y = 0.2, theta = 1.5708 }
[[obstacles]]
outline = [[0.0, 0.45], [0.5, 0.45], [0.5, 0.8], [0.0, 0.8]]
[[obstacles]]
outline = [[0.85, 0.45], [1.2, 0.45], [1.2, 0.8], [0.85, 0.8]]
[[objects]]
id = "slider"
outline = [[-0.09691358024691357, -0.06790123456790124], [0.10308641975308644, -0.06790123456790124], [0.10308641975308644, 0.03209876543209876], [0.05308641975308642, 0.07209876543209877], [-0.09691358024691357, 0.07209876543209877]]
pose = { x = 0.25, y = 0.2, theta = 0.0 }
mass = 0.1
support_friction = 0.3
pusher_friction = 0.5
[[goals]]
object = "slider"
pose = { x = 0.787, y = 0.62, theta = 1.5707963267948966 }
[stable]
object = "slider"
edges = [0, 3]
goal_xy_frac = 0.1
goal_theta_deg = 2.0
pusher = { kind = "arm" }
planner = { a = 1, b = 5, c = 0, step_frac = 0.3, grid_xy_frac = 1.0, grid_theta_deg = 6.0, fine_radius_frac = 0.65, fine_factor = 3.0, max_cost = 3000, max_nodes = 300000 }
"#;

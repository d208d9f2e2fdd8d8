//! `pushbot run deliver|rearrange` on the built-in target, as a user types them: each task
//! starts from where the camera sees the table, ends in a folder with its recording, report,
//! log and summary, and a goal it cannot reach is refused before anything moves (exit 2).

use pushbot_tests::run_bin;
use serde_json::Value;

fn json_of(stdout: &str) -> Value {
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON in {stdout:?}"));
    serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"))
}

#[test]
fn run_deliver_reaches_the_goal_and_leaves_its_folder() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("deliver");
    let strategy = dir.path().join("irregular.strategy");
    let r = run_bin(
        "pushbot",
        &[
            "--json",
            "run",
            "deliver",
            "--object",
            "irregular",
            "--scene",
            "lau-irregular",
            "--goal",
            "1.0,0.6",
            "--strategy",
            strategy.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    let j = json_of(&r.stdout);
    assert_eq!(j["success"], true, "{j}");
    let d = j["result"]["final_distance_m"].as_f64().expect("distance");
    let radius = j["result"]["success_radius_m"].as_f64().expect("radius");
    assert!(d <= radius, "{d} m from the goal");
    for f in ["run.mcap", "report.html", "run.log", "summary.json"] {
        assert!(out.join(f).is_file(), "the folder has no {f}");
    }
    // The summary is the JSON printed; the log has the task's events.
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["success"], true);
    let log = std::fs::read_to_string(out.join("run.log")).unwrap();
    assert!(log.contains("plan") && log.contains("done"), "{log}");
    // The strategy it collected first is kept for the next run.
    assert!(strategy.is_file());
}

#[test]
fn run_rearrange_reaches_the_goal_arrangement_of_a1() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("rearrange");
    let r = run_bin(
        "pushbot",
        &[
            "--json",
            "run",
            "rearrange",
            "--scene",
            "a1",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    let j = json_of(&r.stdout);
    assert_eq!(j["success"], true, "{j}");
    for f in ["run.mcap", "report.html", "summary.json"] {
        assert!(out.join(f).is_file(), "the folder has no {f}");
    }
}

#[test]
fn a_goal_inside_an_obstacle_is_refused_with_exit_2_naming_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("never");
    let r = run_bin(
        "pushbot",
        &[
            "run",
            "deliver",
            "--object",
            "object",
            "--scene",
            "lau-obstacles",
            "--goal",
            "0.83,0.9",
            "--method",
            "dipole",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(r.code, Some(2), "{}\n{}", r.stdout, r.stderr);
    assert!(r.stderr.contains("obstacle 1"), "{}", r.stderr);
    assert!(!out.join("run.mcap").exists(), "it recorded a run");
    // Off the table, and a goal that does not parse: the same class.
    for goal in ["2.5,0.6", "1.0;0.6"] {
        let r = run_bin(
            "pushbot",
            &[
                "run",
                "deliver",
                "--object",
                "irregular",
                "--scene",
                "lau-irregular",
                "--goal",
                goal,
                "--method",
                "dipole",
            ],
        );
        assert_eq!(r.code, Some(2), "--goal {goal}: {}", r.stderr);
        assert!(r.stderr.contains("goal"), "--goal {goal}: {}", r.stderr);
    }
}

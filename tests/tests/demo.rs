//! `pushbot demo` end to end on the built-in simulated target: a stage runs through the serial
//! port and the camera and the report folder has what it promises.

use clap::Parser;
use pushbot::cli::{Cli, CliError, Status, run};

#[test]
fn the_stable_stage_runs_and_writes_the_report() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("report");
    let out_s = out.to_str().expect("utf-8");
    let argv = [
        "pushbot", "demo", "--out", out_s, "--stages", "stable", "--speed", "5", "--view",
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("runs");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("summary.json")).expect("summary.json"),
    )
    .expect("summary is JSON");
    assert_eq!(st, Status::Success, "{summary:#}");
    assert_eq!(summary["success"], true);
    let stage = &summary["stages"][0];
    assert_eq!(stage["id"], "stable");
    assert!(stage["numbers"]["pushed_m"].as_f64().expect("pushed") > 0.3);
    // Closed loop: it counts its re-plans, and the plan figure draws the executed
    // path (green) over the planned one.
    assert!(stage["numbers"]["replans"].as_u64().is_some(), "{stage:#}");
    let plan_svg = std::fs::read_to_string(out.join("stable-plan.svg")).expect("stable-plan.svg");
    assert!(
        plan_svg.contains("#0a4"),
        "no executed path in stable-plan.svg"
    );
    let page = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    for f in ["stable-plan.svg", "stable-run.svg"] {
        assert!(out.join(f).exists(), "{f} missing");
        assert!(page.contains(f), "report.html does not show {f}");
    }
    assert!(out.join("demo.log").exists());
    // The run is recorded by default (see host/tests/recording.rs for what it holds).
    assert!(out.join("run.mcap").metadata().expect("run.mcap").len() > 0);
    // The live view was kept: the last camera frame and its overlay.
    assert!(out.join("live/camera.png").exists());
    let overlay = std::fs::read_to_string(out.join("live/overlay.svg")).expect("overlay");
    assert!(
        overlay.contains("slider"),
        "the overlay names the tracked slider"
    );
}

#[test]
fn an_unknown_stage_or_scene_is_bad_input() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().to_str().expect("utf-8");
    for extra in [
        ["--stages", "juggle"],
        ["--scene", "strategy=no-such-preset"],
        ["--scene", "wrong"],
    ] {
        let mut argv = vec!["pushbot", "demo", "--out", out];
        argv.extend(extra);
        match run(Cli::try_parse_from(&argv).expect("arguments parse")) {
            Err(CliError::BadInput(e)) => {
                let msg = format!("{e:#}");
                assert!(
                    msg.contains(extra[1].split('=').next_back().unwrap_or("")),
                    "{msg}"
                );
            }
            other => panic!("{argv:?}: {other:?}, not bad input"),
        }
    }
}

#[test]
fn the_rearrangement_reaches_its_goal_through_link_cuts() {
    // A 1 s cut every 5 s of robot time, the robot's watchdog at 1 s: cuts stop the
    // robot mid-push or while it stands; each is recovered and the stage still ends at its goal.
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("report");
    let out_s = out.to_str().expect("utf-8");
    let argv = [
        "pushbot",
        "demo",
        "--out",
        out_s,
        "--stages",
        "rearrange",
        "--speed",
        "5",
        "--faults",
        "--fault-cut-every",
        "5",
        "--fault-cut-for",
        "1",
        "--fault-drop",
        "0",
        "--fault-corrupt",
        "0",
        "--fault-delay-ms",
        "0",
    ];
    let st = run(Cli::try_parse_from(argv).expect("arguments parse")).expect("runs");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("summary.json")).expect("summary.json"),
    )
    .expect("summary is JSON");
    assert_eq!(st, Status::Success, "{summary:#}");
    let stage = &summary["stages"][0];
    let recoveries = stage["numbers"]["link_recoveries"]
        .as_u64()
        .expect("counted");
    let mission = stage["mission_s"].as_f64().expect("mission time");
    eprintln!("{recoveries} recoveries in {mission:.1} s of mission time");
    assert!(recoveries >= 1, "{summary:#}");
    let notes = stage["notes"].as_array().expect("notes");
    let logged = notes
        .iter()
        .filter(|n| n.as_str().is_some_and(|s| s.starts_with("link recovered")))
        .count();
    assert_eq!(
        logged as u64, recoveries,
        "every recovery is logged: {notes:?}"
    );
}

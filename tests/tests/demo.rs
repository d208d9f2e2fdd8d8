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

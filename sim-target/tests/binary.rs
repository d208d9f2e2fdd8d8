//! The real `pushbot-sim` binary: first JSON line, a handshake over its pty, exit on stdin EOF.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command as Process, Stdio};
use std::time::{Duration, Instant};

use pushbot_protocol::{
    Command, FrameDecoder, HostFrame, MAX_FRAME, PROTOCOL_VERSION, RobotMsg, encode_frame,
};

#[test]
fn binary_serves_the_robot_on_a_pty() {
    let log = std::env::temp_dir().join(format!("pushbot-sim-truth-{}.jsonl", std::process::id()));
    let mut child = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args(["--seed", "4", "--speed", "5", "--truth-log"])
        .arg(&log)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start pushbot-sim");
    let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
    let mut first = String::new();
    stdout.read_line(&mut first).expect("first line");
    let info: serde_json::Value = serde_json::from_str(&first).expect("first line is JSON");
    assert_eq!(info["seed"], 4);
    assert_eq!(info["speed"], 5.0);
    assert_eq!(info["table"], serde_json::json!([1.2, 0.9]));
    let path = info["serial"].as_str().expect("serial path");

    let mut port = serialport::new(path, 115_200)
        .timeout(Duration::from_millis(50))
        .open()
        .expect("open the pty like a serial port");
    let mut buf = [0u8; MAX_FRAME];
    let hello = HostFrame {
        seq: 1,
        cmd: Command::Hello {
            protocol: PROTOCOL_VERSION,
        },
    };
    let n = encode_frame(&hello, &mut buf).expect("frame");
    port.write_all(&buf[..n]).expect("write hello");

    let mut dec = FrameDecoder::new();
    let mut reply = None;
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut rx = [0u8; 256];
    while reply.is_none() && Instant::now() < deadline {
        match port.read(&mut rx) {
            Ok(n) => dec.feed::<RobotMsg>(&rx[..n], |m| {
                if let Ok(RobotMsg::HelloReply(r)) = m {
                    reply = Some(r);
                }
            }),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => panic!("reading the pty: {e}"),
        }
    }
    let reply = reply.expect("a HelloReply within 10 s");
    assert!(reply.accepted);
    assert_eq!(reply.protocol, PROTOCOL_VERSION);
    drop(port);
    // Let it run: 0.5 s of wall time is 2.5 s of simulated time at speed 5.
    std::thread::sleep(Duration::from_millis(500));

    // Closing stdin ends the process, cleanly.
    drop(child.stdin.take());
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("pushbot-sim did not exit after stdin closed");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(status.success(), "{status}");
    let mut rest = String::new();
    stdout.read_to_string(&mut rest).expect("stdout");

    // The truth log: JSON lines at 100 Hz of simulated time from t = 0.
    let text = std::fs::read_to_string(&log).expect("truth log");
    let _ = std::fs::remove_file(&log);
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("JSON line"))
        .collect();
    assert!(lines.len() > 150, "{} lines", lines.len());
    assert_eq!(lines[0]["t"], 0.0);
    assert_eq!(lines[0]["x"], 0.6);
    let dt = lines[1]["t"].as_f64().unwrap() - lines[0]["t"].as_f64().unwrap();
    assert!((dt - 0.01).abs() < 1e-9, "{dt}");
}

/// Bad arguments are refused with a message, not a panic.
#[test]
fn binary_refuses_bad_arguments() {
    for args in [
        &["--speed", "-1"][..],
        &["--table", "0.01", "0.9"],
        &["--start", "5", "5", "0"],
    ] {
        let out = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
            .args(args)
            .stdin(Stdio::null())
            .output()
            .expect("run");
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("pushbot-sim:"), "{args:?}: {err}");
        assert!(out.stdout.is_empty());
        let _ = std::io::stderr().flush();
    }
}

/// `--json`: an error is one JSON object on stdout naming what is wrong, with exit code 2 for
/// bad input; `-v` is accepted everywhere.
#[test]
fn binary_prints_errors_as_json() {
    let out = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args(["-v", "--json", "--scene", "no-such-scene"])
        .stdin(Stdio::null())
        .output()
        .expect("run");
    assert_eq!(out.status.code(), Some(2));
    let text = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(text.trim()).expect("one JSON object");
    assert_eq!(v["error"]["kind"], "bad_input");
    assert_eq!(v["error"]["exit_code"], 2);
    let msg = v["error"]["message"].as_str().expect("message");
    assert!(
        msg.contains("no-such-scene") && msg.contains("lau-irregular"),
        "{msg}"
    );
}

/// `replay`: a straight pusher path through the slider's centre translates it; the output is
/// one JSON object with a row per CSV sample.
#[test]
fn replay_prints_the_object_trajectory() {
    let csv = std::env::temp_dir().join(format!("pushbot-replay-{}.csv", std::process::id()));
    // lynch-mason-fig12: the slider (8 cm × 12 cm) at (0.25, 0.2); bumper radius 0.04 m.
    let mut text = String::from("t,x,y,theta\n");
    for k in 0..=100 {
        let x = 0.12 + 0.002 * f64::from(k);
        text += &format!("{},{x},0.2,0\n", f64::from(k) * 0.02);
    }
    std::fs::write(&csv, text).unwrap();
    let out = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args([
            "replay",
            "--scene",
            "lynch-mason-fig12",
            "--object",
            "slider",
            "--json",
            "--pusher",
        ])
        .arg(&csv)
        .output()
        .expect("run replay");
    let _ = std::fs::remove_file(&csv);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let rows = doc["trajectory"].as_array().expect("trajectory");
    assert_eq!(rows.len(), 101);
    assert_eq!(rows[0]["contact"], "none");
    let last = &rows[100];
    // Pusher ends at 0.32: its front at 0.36, so the slider's back face (x − 0.04) is there.
    assert!((last["x"].as_f64().unwrap() - 0.40).abs() < 2e-3, "{last}");
    assert!(last["theta"].as_f64().unwrap().abs() < 1e-9);
    assert_eq!(last["contact"], "sticking");

    // Errors name the problem: an unknown object, a bad CSV line.
    let out = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args([
            "replay",
            "--scene",
            "lynch-mason-fig12",
            "--object",
            "nope",
            "--pusher",
            "/dev/null",
        ])
        .output()
        .expect("run");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("slider"));
}

/// `--scene PRESET`: the first line names the scene and its objects.
#[test]
fn binary_runs_a_scene() {
    let mut child = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args(["--scene", "lau-l-shape", "--speed", "10"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start");
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let info: serde_json::Value = serde_json::from_str(&first).expect("JSON");
    assert_eq!(info["scene"], "lau-l-shape");
    assert_eq!(info["objects"], serde_json::json!(["object"]));
    assert_eq!(info["table"], serde_json::json!([1.6, 1.2]));
    drop(child.stdin.take());
    let deadline = Instant::now() + Duration::from_secs(10);
    while child.try_wait().unwrap().is_none() {
        assert!(Instant::now() < deadline, "did not exit");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn link_path_follows_the_pty_through_an_unplug() {
    let dir = tempfile::tempdir().expect("tempdir");
    let link = dir.path().join("ttyPUSHBOT0");
    let mut child = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args([
            "--speed",
            "5",
            "--no-camera",
            "--unplug-at",
            "1",
            "--unplug-for",
            "1",
        ])
        .arg("--link")
        .arg(&link)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("start pushbot-sim");
    let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
    let mut first = String::new();
    stdout.read_line(&mut first).expect("first line");
    let info: serde_json::Value = serde_json::from_str(&first).expect("first line is JSON");
    assert_eq!(
        info["serial"].as_str(),
        link.to_str(),
        "hosts open the link"
    );
    let first_target = std::fs::read_link(&link).expect("a symlink to the pty");
    // Within a few seconds of wall time (1 s of robot time is 0.2 s at 5×) the path vanishes…
    let wait = |want: bool| {
        let deadline = Instant::now() + Duration::from_secs(10);
        while std::fs::symlink_metadata(&link).is_ok() != want {
            assert!(
                Instant::now() < deadline,
                "link present = {want} never came"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    };
    wait(false);
    // …and comes back, naming a pty that exists.
    wait(true);
    let second = std::fs::read_link(&link).expect("back");
    assert!(second.exists(), "{second:?} (was {first_target:?})");
    drop(child.stdin.take());
    let status = child.wait().expect("exit");
    assert!(status.success());
    assert!(std::fs::symlink_metadata(&link).is_err(), "removed at exit");
}

#[test]
fn unplugging_without_a_link_is_refused() {
    let out = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
        .args(["--no-camera", "--unplug-at", "1"])
        .stdin(Stdio::null())
        .output()
        .expect("run pushbot-sim");
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--link"), "{err}");
}

/// The global flags (`--seed`, `--json`, `-v`) go before or after a subcommand, as for
/// `pushbot`, and mean the same; the simulator's own flags are refused with a subcommand.
#[test]
fn global_flags_before_or_after_the_subcommand() {
    let run = |args: &[&str]| {
        Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
            .args(args)
            .stdin(Stdio::null())
            .output()
            .expect("run")
    };
    let before = run(&["--seed", "3", "--json", "bench", "--seconds", "1"]);
    let after = run(&["bench", "--seed", "3", "--json", "--seconds", "1"]);
    for out in [&before, &after] {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let pose = |out: &std::process::Output| {
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
        v["final_pose"].clone()
    };
    assert_eq!(pose(&before), pose(&after));
    let stray = run(&["--speed", "3", "bench", "--seconds", "1"]);
    assert_eq!(stray.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&stray.stderr).contains("--speed"));
}

/// Every `--help` ends with an example that names the binary.
#[test]
fn every_help_has_an_example() {
    for args in [
        &["--help"][..],
        &["bench", "--help"],
        &["replay", "--help"],
        &["presets", "--help"],
    ] {
        let out = Process::new(env!("CARGO_BIN_EXE_pushbot-sim"))
            .args(args)
            .output()
            .expect("run");
        let text = String::from_utf8_lossy(&out.stdout);
        let (_, ex) = text
            .split_once("\nExample:\n")
            .or_else(|| text.split_once("\nExamples:\n"))
            .unwrap_or_else(|| panic!("{args:?}: no example in {text}"));
        assert!(ex.trim_start().starts_with("pushbot-sim"), "{args:?}: {ex}");
    }
}

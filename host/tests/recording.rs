//! Recordings end to end: `pushbot demo` (its stable stage, on the built-in simulated target)
//! writes `run.mcap` in Foxglove's schemas; `pushbot replay` tracks its frames again to the
//! same poses and writes a report; a file cut anywhere is read up to its last whole chunk, and
//! bad files are refused with a clear error, never a panic.

use std::path::Path;
use std::process::Command;

use pushbot::recording::reader;
use pushbot::recording::writer::topics;

fn pushbot(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args(args)
        .output()
        .expect("run pushbot")
}

fn demo(dir: &Path) -> std::path::PathBuf {
    demo_with(dir, &[])
}

fn demo_with(dir: &Path, before: &[&str]) -> std::path::PathBuf {
    let mut args = before.to_vec();
    args.extend([
        "demo",
        "--stages",
        "stable",
        "--out",
        dir.to_str().expect("utf-8"),
        "--json",
    ]);
    let out = pushbot(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir.join("run.mcap")
}

#[test]
fn demo_records_and_replay_reproduces_the_tracked_poses() {
    let dir = tempfile::tempdir().expect("tmp");
    let file = demo(dir.path());
    let rec = reader::read(&file).expect("readable");
    assert_eq!(rec.cut, None, "a finished recording is whole");
    for (topic, schema) in [
        (topics::IMAGE, "foxglove.CompressedImage"),
        (topics::CALIBRATION, "foxglove.CameraCalibration"),
        (topics::ANNOTATIONS, "foxglove.ImageAnnotations"),
        (topics::TF, "foxglove.FrameTransforms"),
        (topics::SCENE, "foxglove.SceneUpdate"),
        (topics::EXECUTED, "foxglove.SceneUpdate"),
        (topics::LOG, "foxglove.Log"),
        (topics::TELEMETRY, "pushbot.Telemetry"),
        (topics::TRACKED, "pushbot.TrackedPoses"),
    ] {
        let msgs: Vec<_> = rec.on(topic).collect();
        assert!(!msgs.is_empty(), "no message on {topic}");
        assert!(msgs.iter().all(|m| m.schema == schema), "{topic}");
    }
    // Robot time, and never backwards within a channel.
    let tele: Vec<u64> = rec.on(topics::TELEMETRY).map(|m| m.log_time).collect();
    assert!(tele.windows(2).all(|w| w[1] >= w[0]));
    let first = &rec.on(topics::TELEMETRY).next().expect("telemetry").value;
    assert!(first["time_us"].as_u64().is_some());
    // Every image is a PNG.
    for m in rec.on(topics::IMAGE) {
        let png = pushbot::recording::foxglove::image_data(&m.value).expect("data");
        assert!(png.starts_with(b"\x89PNG"), "not a PNG");
        assert_eq!(m.value["format"], "png");
    }

    let out = pushbot(&["replay", file.to_str().expect("utf-8"), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let frames = rec.on(topics::TRACKED).count();
    assert_eq!(v["frames"].as_u64(), Some(frames as u64));
    let diff = v["max_diff_m"].as_f64().expect("max_diff_m");
    assert!(diff <= 1e-4, "replayed poses differ by {diff} m");
    assert_eq!(v["agree"], true);
    // The replay's last poses are the live run's last tracked poses.
    let last = rec.on(topics::TRACKED).last().expect("tracked");
    for b in last.value["bodies"].as_array().expect("bodies") {
        if b["seen"] != true || b["rejected"] == true {
            continue;
        }
        let name = b["body"].as_str().expect("name");
        let r = &v["sessions"][0]["last"][name];
        for k in ["x", "y"] {
            let (a, c) = (b[k].as_f64().expect("live"), r[k].as_f64().expect("replay"));
            assert!((a - c).abs() <= 1e-4, "{name}.{k}: live {a}, replay {c}");
        }
    }
    let page = v["report"].as_str().expect("report");
    let html = std::fs::read_to_string(page).expect("report.html");
    assert!(html.contains("<figure"), "the replay report has figures");
    // The live report as recorded: the stage's numbers and the very same figures.
    assert!(
        html.contains("Pushed along"),
        "the stage's numbers are in the replay report"
    );
    for f in ["stable-plan.svg", "stable-run.svg"] {
        let live = std::fs::read_to_string(dir.path().join(f)).expect("live figure");
        let again = std::fs::read_to_string(dir.path().join("replay").join(f)).expect(f);
        assert_eq!(live, again, "{f} differs in the replay report");
    }
    // The run drawn from the recording is the live report's figure, but for its title.
    let live = std::fs::read_to_string(dir.path().join("stable-run.svg")).expect("live figure");
    let again = std::fs::read_to_string(dir.path().join("replay/session-1-run.svg"))
        .expect("replayed figure");
    assert_eq!(
        live.replace("stable pushes executed closed loop (truth)", "T"),
        again.replace("fig15 as recorded", "T")
    );
}

#[test]
fn a_cut_recording_reads_up_to_its_last_whole_chunk() {
    let dir = tempfile::tempdir().expect("tmp");
    let file = demo(dir.path());
    let bytes = std::fs::read(&file).expect("read");
    let whole = reader::read_bytes(&bytes).expect("whole");
    let images = whole.on(topics::IMAGE).count();
    assert!(images >= 2);
    let mut longest = 0;
    for frac in [0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.95, 0.999] {
        let n = (bytes.len() as f64 * frac) as usize;
        let cut = reader::read_bytes(&bytes[..n]).expect("a cut file reads");
        assert!(cut.cut.is_some(), "a file cut at {n} bytes says so");
        // What it reads is what the whole file holds, in order.
        assert!(cut.messages.len() <= whole.messages.len());
        assert_eq!(cut.messages[..], whole.messages[..cut.messages.len()]);
        assert!(
            cut.messages.len() >= longest,
            "more file, no fewer messages"
        );
        longest = cut.messages.len();
    }
    // Near the end, every camera look but the last is there (a look ends a chunk).
    let near_end = reader::read_bytes(&bytes[..bytes.len() * 999 / 1000]).expect("cut");
    assert!(near_end.on(topics::IMAGE).count() >= images - 1);
    // And it replays.
    let cut_file = dir.path().join("cut.mcap");
    std::fs::write(&cut_file, &bytes[..bytes.len() * 3 / 4]).expect("write");
    let out = pushbot(&["replay", cut_file.to_str().expect("utf-8"), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(out.status.code(), Some(0), "{v}");
    assert!(v["cut"].is_string(), "{v}");
}

#[test]
fn bad_recordings_are_refused_clearly() {
    let dir = tempfile::tempdir().expect("tmp");
    let missing = dir.path().join("missing.mcap");
    let text = dir.path().join("text.mcap");
    std::fs::write(&text, "not a recording\n").expect("write");
    let empty = dir.path().join("empty.mcap");
    std::fs::write(&empty, "").expect("write");
    for (f, says) in [
        (&missing, "missing.mcap"),
        (&text, "not an MCAP file"),
        (&empty, "not an MCAP file"),
    ] {
        let out = pushbot(&["replay", f.to_str().expect("utf-8")]);
        assert_eq!(out.status.code(), Some(2), "{}", f.display());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // Garbage after the magic: an error or a cut file, never a panic.
    let mut junk = b"\x89MCAP0\r\n".to_vec();
    junk.extend((0..4000u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8));
    let r = reader::read_bytes(&junk);
    assert!(r.is_err() || r.as_ref().is_ok_and(|c| c.cut.is_some()));
}

/// Through a distorting lens (`--intrinsics`, a webcam's k1 = −0.08): the stage still reaches
/// its goal, the recording publishes the lens as the camera's calibration and keeps it for
/// replay, which tracks the frames again through it to the same poses.
#[test]
fn a_run_through_a_lens_is_recorded_with_it_and_replays_the_same() {
    use pushbot_world::lens::{Distortion, Intrinsics};
    use pushbot_world::lens_file::{LensFormat, write_intrinsics};
    let dir = tempfile::tempdir().expect("tmp");
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
    let yaml = dir.path().join("webcam.yaml");
    std::fs::write(&yaml, write_intrinsics(&lens, LensFormat::OpenCv, "webcam")).expect("write");
    let out = dir.path().join("out");
    let file = demo_with(&out, &["--intrinsics", yaml.to_str().expect("utf-8")]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).expect("summary"))
            .expect("json");
    assert_eq!(summary["success"], true, "{summary:#}");
    let rec = reader::read(&file).expect("readable");
    let cal = rec.on(topics::CALIBRATION).next().expect("calibration");
    assert_eq!(cal.value["D"][0].as_f64(), Some(-0.08));
    assert_eq!(cal.value["K"][0].as_f64(), Some(700.0));
    let out = pushbot(&["replay", file.to_str().expect("utf-8"), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    let diff = v["max_diff_m"].as_f64().expect("max_diff_m");
    assert!(
        diff <= 1e-4,
        "replayed through the lens, poses differ by {diff} m"
    );
}

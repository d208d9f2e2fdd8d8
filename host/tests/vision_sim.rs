//! Vision against the simulated camera's ground truth: detection, calibration and pose accuracy
//! on a few hundred rendered 960×720 frames with noise and mild blur; frame sources; CLI.

use pushbot::sim::synth::{self, DetectionScore, PoseScore, SynthParams, quantile};
use pushbot::vision::apriltag::{AprilTagC, AprilTagCConfig};
use pushbot::vision::detect::{Detector, Region};
use pushbot::vision::folder::FolderSource;
#[cfg(feature = "kornia")]
use pushbot::vision::kornia::{KorniaConfig, KorniaDetector};
use pushbot::vision::layout::MarkerLayout;
use pushbot::vision::simsocket::SimSocketSource;
use pushbot::vision::source::{FrameSource, SourceError, open_source};
use pushbot::vision::tracking::TrackerParams;
use pushbot::vision::{Pipeline, RoiParams, measure};
use pushbot_sim::camera::CameraFrame;
use pushbot_sim::camera::server::CameraServer;

/// The pipeline's accuracy: on 300 rendered frames, body position error median ≤ 1.5 mm and 99th
/// percentile ≤ 4 mm, heading median ≤ 0.5°, ≥ 99.5 % of fully visible markers found, no
/// wrong ids. The camera is calibrated from the first frames' calibration markers, as
/// `pushbot calibrate` does.
#[test]
fn accuracy_on_rendered_frames() {
    let layout = MarkerLayout::default_table();
    let frames = synth::frames(&layout, 300, 42, &SynthParams::default()).unwrap();
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let dets: Vec<_> = frames
        .iter()
        .map(|f| det.detect(&f.frame).unwrap())
        .collect();
    let cal = synth::calibrate(&dets[..5], &layout, [960, 720]).unwrap();
    assert!(cal.rms_px < 0.2, "calibration RMS {} px", cal.rms_px);
    let mut score = DetectionScore::default();
    let mut poses = PoseScore::default();
    for (d, f) in dets.iter().zip(&frames) {
        score.add(d, &f.markers);
        poses.add(&measure(d, &cal, &layout), &f.bodies);
    }
    let (med, p99) = (quantile(&poses.pos_mm, 0.5), quantile(&poses.pos_mm, 0.99));
    let hmed = quantile(&poses.heading_deg, 0.5);
    eprintln!(
        "found {}/{} wrong {} corner rms {:.3} px bias {:?}; position median {med:.3} mm p99 {p99:.3} mm; heading median {hmed:.3}° p99 {:.3}°",
        score.found,
        score.visible,
        score.wrong_ids,
        score.corner_rms(),
        score.corner_bias,
        quantile(&poses.heading_deg, 0.99)
    );
    assert_eq!(
        score.visible,
        300 * 10,
        "every marker is drawn fully visible"
    );
    assert!(
        score.rate() >= 0.995,
        "found {}/{}",
        score.found,
        score.visible
    );
    assert_eq!(score.wrong_ids, 0);
    assert!(med <= 1.5, "position median {med} mm");
    assert!(p99 <= 4.0, "position p99 {p99} mm");
    assert!(hmed <= 0.5, "heading median {hmed}°");
}

/// The kornia candidate reads the same frames with the same corner convention and pixel
/// centres, at its defaults and at `threshold_split = 0.5` (a wrong corner order would show as
/// a 90° heading error or a corner error of tens of pixels, a half-pixel shift as a bias).
#[cfg(feature = "kornia")]
#[test]
fn kornia_candidate_agrees_on_corners() {
    let layout = MarkerLayout::default_table();
    let frames = synth::frames(&layout, 10, 7, &SynthParams::default()).unwrap();
    for threshold_split in [None, Some(0.5)] {
        let mut det = KorniaDetector::new(
            &layout.families(),
            &KorniaConfig {
                threshold_split,
                downscale: None,
            },
        )
        .unwrap();
        let mut score = DetectionScore::default();
        for f in &frames {
            score.add(&det.detect(&f.frame).unwrap(), &f.markers);
        }
        eprintln!(
            "kornia {threshold_split:?}: found {}/{}, corner rms {:.3} px, bias {:?}",
            score.found,
            score.visible,
            score.corner_rms(),
            score.corner_bias
        );
        assert!(
            score.rate() > 0.95,
            "found {}/{}",
            score.found,
            score.visible
        );
        assert!(
            score.corner_rms() < 0.4,
            "corner rms {}",
            score.corner_rms()
        );
        let [bx, by] = score.corner_bias;
        assert!(bx.abs() < 0.1 && by.abs() < 0.1, "corner bias {bx} {by}");
        assert_eq!(score.wrong_ids, 0);
    }
}

/// The chosen pipeline (the C detector, default regions of interest and tracker) over 960×720
/// frames, calibrated from the markers detected in `first`, as `pushbot calibrate` does.
fn calibrated_pipeline(layout: &MarkerLayout, first: &[synth::SynthFrame]) -> Pipeline {
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let seen: Vec<_> = first
        .iter()
        .map(|f| det.detect(&f.frame).unwrap())
        .collect();
    let cal = synth::calibrate(&seen, layout, [960, 720]).unwrap();
    Pipeline::new(Box::new(det), layout.clone(), cal, TrackerParams::default())
}

/// The chosen pipeline (C AprilTag in tracker-guided regions of interest, whole frames every
/// 15 frames while a body is not tracked, or when one is missed) meets the accuracy of `accuracy_on_rendered_frames` on a rendered video where the
/// bodies move, and it does search regions rather than whole frames most of the time.
#[test]
fn regions_of_interest_keep_accuracy_on_video() {
    let layout = MarkerLayout::default_table();
    let frames = synth::moving_frames(&layout, 300, 11, &SynthParams::default()).unwrap();
    let mut pipe = calibrated_pipeline(&layout, &frames[..5]);
    let mut poses = PoseScore::default();
    let mut score = DetectionScore::default();
    let (mut full, mut bodies) = (0, 0);
    for f in &frames {
        let r = pipe.process(&f.frame).unwrap();
        full += usize::from(r.full_frame);
        bodies += f.bodies.len();
        poses.add(&r.measurements, &f.bodies);
        // Wrong ids anywhere; corners of every marker it reports.
        score.add(&r.detections, &f.markers);
        for t in &r.tracked {
            assert!(t.seen && !t.rejected, "frame {}: {t:?}", f.frame.seq);
        }
    }
    let (med, p99) = (quantile(&poses.pos_mm, 0.5), quantile(&poses.pos_mm, 0.99));
    let hmed = quantile(&poses.heading_deg, 0.5);
    eprintln!(
        "whole frames {full}/300, bodies missed {}/{bodies}, wrong {}, corner rms {:.3} px; position median {med:.3} mm p99 {p99:.3} mm; heading median {hmed:.3}°",
        poses.missed,
        score.wrong_ids,
        score.corner_rms()
    );
    assert!(
        (poses.missed as f64) <= 0.005 * bodies as f64,
        "missed {}/{bodies}",
        poses.missed
    );
    assert_eq!(score.wrong_ids, 0);
    assert!(med <= 1.5, "position median {med} mm");
    assert!(p99 <= 4.0, "position p99 {p99} mm");
    assert!(hmed <= 0.5, "heading median {hmed}°");
    // 300 frames: every body is tracked from the first whole frame on, so the scheduled whole
    // frames do not come, and no miss forces one on this video.
    assert!(full <= 3, "whole frames {full}/300");
}

/// A camera read only now and then (every 8th frame of the video: 0.27 s apart, as the
/// in-process robot looks between its moves) still searches regions rather than whole frames:
/// each is centred on the last sighting and reaches as far as a marker can go in the gap
/// ([`RoiParams::max_speed`]). Nothing is missed and the poses keep that accuracy.
#[test]
fn regions_of_interest_reach_across_long_gaps() {
    let layout = MarkerLayout::default_table();
    let frames = synth::moving_frames(&layout, 360, 12, &SynthParams::default()).unwrap();
    let mut pipe = calibrated_pipeline(&layout, &frames[..3]);
    let mut poses = PoseScore::default();
    let mut score = DetectionScore::default();
    let (mut full, mut looks, mut bodies) = (0, 0, 0);
    for f in frames.iter().step_by(8) {
        let r = pipe.process(&f.frame).unwrap();
        full += usize::from(r.full_frame);
        looks += 1;
        bodies += f.bodies.len();
        poses.add(&r.measurements, &f.bodies);
        score.add(&r.detections, &f.markers);
    }
    let (med, p99) = (quantile(&poses.pos_mm, 0.5), quantile(&poses.pos_mm, 0.99));
    eprintln!(
        "whole frames {full}/{looks}, bodies missed {}/{bodies}, wrong {}; position median {med:.3} mm p99 {p99:.3} mm",
        poses.missed, score.wrong_ids
    );
    assert_eq!(poses.missed, 0);
    assert_eq!(score.wrong_ids, 0);
    assert!(med <= 1.5, "position median {med} mm");
    assert!(p99 <= 4.0, "position p99 {p99} mm");
    // The first look is a whole frame; while every body is tracked the rest are regions.
    assert!(full <= 3, "whole frames {full}/{looks}");
}

/// When bodies jump between frames (still frames of random poses), every region misses and
/// the pipeline falls back to the whole frame at once: nothing is lost.
#[test]
fn regions_of_interest_fall_back_to_whole_frames() {
    let layout = MarkerLayout::default_table();
    let frames = synth::frames(&layout, 20, 5, &SynthParams::default()).unwrap();
    let mut pipe = calibrated_pipeline(&layout, &frames[..3]).with_roi(RoiParams::default());
    let mut poses = PoseScore::default();
    for f in &frames {
        let r = pipe.process(&f.frame).unwrap();
        assert!(r.full_frame, "frame {} searched only regions", f.frame.seq);
        poses.add(&r.measurements, &f.bodies);
    }
    assert_eq!(poses.missed, 0);
}

/// A region's detections are the whole frame's, in the frame's coordinates: the same markers
/// with the same corners (to within the sub-pixel refinement's noise); the C detector's own
/// region path gives exactly what the trait's default (copy the region out) gives.
#[test]
fn region_detection_matches_whole_frame() {
    let layout = MarkerLayout::default_table();
    let frames = synth::frames(&layout, 5, 9, &SynthParams::default()).unwrap();
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let mut checked = 0;
    for f in &frames {
        let whole = det.detect(&f.frame).unwrap();
        for w in &whole {
            // Odd offsets too: the decimated grid then differs from the whole frame's.
            let r = Region::square_around(w.centre, 97, 960, 720);
            assert!(r.fits(960, 720));
            let own = det.detect_region(&f.frame, r).unwrap();
            let crop = r.crop(&f.frame).unwrap();
            let copied: Vec<_> = det
                .detect(&crop)
                .unwrap()
                .into_iter()
                .map(|d| d.shifted(r.x as f64, r.y as f64))
                .collect();
            // The C detector's own region path and the copy-out default see the same pixels.
            assert_eq!(own, copied);
            let d = own
                .iter()
                .find(|d| d.id == w.id)
                .unwrap_or_else(|| panic!("marker {} not found in {r:?}", w.id));
            // A wrong offset would be whole pixels; the decimation grid's phase moves corners
            // by a few tenths at most.
            for (a, b) in d.corners.iter().zip(&w.corners) {
                let e = (a[0] - b[0]).hypot(a[1] - b[1]);
                assert!(e < 0.6, "marker {} corner off by {e} px", w.id);
            }
            checked += 1;
        }
    }
    assert!(checked >= 40, "checked {checked}");
    // Regions outside the frame are an error, not a panic.
    let f = &frames[0].frame;
    let bad = Region {
        x: 900,
        y: 0,
        width: 100,
        height: 10,
    };
    assert!(det.detect_region(f, bad).is_err());
    assert!(bad.crop(f).is_err());
}

/// Squares stay inside the frame and keep their size.
#[test]
fn region_squares_stay_inside() {
    for (c, want) in [
        ([0.0, 0.0], (0, 0)),
        ([480.0, 360.0], (432, 312)),
        ([959.9, 719.9], (864, 624)),
        ([-50.0, 1e9], (0, 624)),
        ([f64::NAN, f64::INFINITY], (0, 624)),
    ] {
        let r = Region::square_around(c, 96, 960, 720);
        assert_eq!(
            (r.x, r.y, r.width, r.height),
            (want.0, want.1, 96, 96),
            "{c:?}"
        );
        assert!(r.fits(960, 720));
    }
    let r = Region::square_around([5.0, 5.0], 96, 40, 30);
    assert_eq!((r.x, r.y, r.width, r.height), (0, 0, 40, 30));
}

fn rendered(n: usize) -> Vec<CameraFrame> {
    let layout = MarkerLayout::default_table();
    let frames = synth::frames(&layout, n, 3, &SynthParams::default()).unwrap();
    frames
        .into_iter()
        .map(|f| CameraFrame {
            seq: f.frame.seq,
            time: 10.0 + f.frame.time,
            width: f.frame.width,
            height: f.frame.height,
            pixels: f.frame.pixels,
            truth: f.markers,
        })
        .collect()
}

#[test]
fn folder_source_reads_rendered_pngs() {
    let dir = tempfile::tempdir().unwrap();
    let frames = rendered(3);
    for f in &frames {
        f.write_png(dir.path()).unwrap();
    }
    let mut src = FolderSource::open(dir.path(), 30.0).unwrap();
    for f in &frames {
        let got = src.next_frame().unwrap().unwrap();
        assert_eq!((got.width, got.height), (960, 720));
        assert_eq!(got.pixels, f.pixels, "PNG round trip is lossless");
        assert!((got.time - f.time).abs() < 1e-12, "time from the sidecar");
    }
    assert!(src.next_frame().unwrap().is_none());
    let empty = tempfile::tempdir().unwrap();
    assert!(matches!(
        FolderSource::open(empty.path(), 30.0),
        Err(SourceError::BadSource(_))
    ));
}

#[test]
fn sim_socket_source_receives_frames() {
    let server = CameraServer::bind("127.0.0.1:0").unwrap();
    let mut src = SimSocketSource::connect(&server.local_addr().to_string()).unwrap();
    for _ in 0..400 {
        if server.clients() == 1 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let frames = rendered(2);
    for f in &frames {
        assert_eq!(server.publish(f), 1);
    }
    for f in &frames {
        let got = src.next_frame().unwrap().unwrap();
        assert_eq!((got.seq, got.pixels.len()), (f.seq, 960 * 720));
        assert!((got.time - f.time).abs() < 1e-12);
        assert_eq!(got.pixels, f.pixels);
        assert_eq!(src.last_truth.len(), f.truth.len());
    }
    drop(server);
}

#[test]
fn missing_v4l2_device_is_a_clear_bad_input() {
    let err = open_source("/dev/video-pushbot-missing", 30.0)
        .err()
        .expect("no such device");
    match err {
        SourceError::BadSource(msg) => assert!(msg.contains("does not exist"), "{msg}"),
        other => panic!("expected BadSource, got {other:?}"),
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args(["track", "--camera", "/dev/video-pushbot-missing", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
}

/// `pushbot calibrate` then `pushbot track --json` on a folder of rendered frames.
#[test]
fn cli_calibrate_and_track_on_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let frames = rendered(4);
    for f in &frames {
        f.write_png(dir.path()).unwrap();
    }
    let cal = dir.path().join("cal.json");
    let bin = env!("CARGO_BIN_EXE_pushbot");
    let cam = dir.path().to_str().unwrap();
    // The frames show the test layout, not the scene format's default markers: say so.
    let other = tempfile::tempdir().unwrap();
    let layout = other.path().join("layout.json");
    std::fs::write(
        &layout,
        serde_json::to_string(&MarkerLayout::default_table()).unwrap(),
    )
    .unwrap();
    let layout = layout.to_str().unwrap();
    let out = std::process::Command::new(bin)
        .args([
            "calibrate",
            "--camera",
            cam,
            "--layout",
            layout,
            "--out",
            cal.to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["rms_px"].as_f64().unwrap() < 0.2);
    let out = std::process::Command::new(bin)
        .args([
            "track",
            "--camera",
            cam,
            "--layout",
            layout,
            "--calibration",
            cal.to_str().unwrap(),
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 4);
    let truth = synth::frames(
        &MarkerLayout::default_table(),
        4,
        3,
        &SynthParams::default(),
    )
    .unwrap();
    for (l, f) in lines.iter().zip(&truth) {
        assert!((l["time"].as_f64().unwrap() - 10.0 - f.frame.time).abs() < 1e-9);
        let robot = l["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["id"] == "robot")
            .unwrap();
        let (name, pose) = &f.bodies[0];
        assert_eq!(name, "robot");
        // Each frame places the robot anew: the first frame is exact, later ones are followed
        // or (after the filter's gate rejects a jump) reported as unseen; check the first.
        if l["seq"] == 0 {
            assert_eq!(robot["seen"], true);
            assert!((robot["x"].as_f64().unwrap() - pose.x).abs() < 0.003);
            assert!((robot["y"].as_f64().unwrap() - pose.y).abs() < 0.003);
        }
    }
    // A missing calibration file is bad input.
    let out = std::process::Command::new(bin)
        .args([
            "track",
            "--camera",
            cam,
            "--calibration",
            "/nonexistent/cal.json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}

/// A truncated image among the frames (a camera that wrote half a file) is skipped and
/// counted: `track` goes on with the next frame, and says how many it skipped.
#[test]
fn a_truncated_frame_is_skipped_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    for f in &rendered(4) {
        f.write_png(dir.path()).unwrap();
    }
    let bin = env!("CARGO_BIN_EXE_pushbot");
    let other = tempfile::tempdir().unwrap();
    let layout = other.path().join("layout.json");
    std::fs::write(
        &layout,
        serde_json::to_string(&MarkerLayout::default_table()).unwrap(),
    )
    .unwrap();
    let cal = other.path().join("cal.json");
    let (cam, layout) = (dir.path().to_str().unwrap(), layout.to_str().unwrap());
    let out = std::process::Command::new(bin)
        .args(["calibrate", "--camera", cam, "--layout", layout])
        .args(["--out", cal.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Cut the third frame's file short.
    let third = dir.path().join("frame-000002.png");
    let bytes = std::fs::read(&third).unwrap();
    std::fs::write(&third, &bytes[..bytes.len() / 3]).unwrap();
    let out = std::process::Command::new(bin)
        .args(["track", "--camera", cam, "--layout", layout, "--json"])
        .args(["--calibration", cal.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let seqs: Vec<u64> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["seq"]
                .as_u64()
                .unwrap()
        })
        .collect();
    assert_eq!(
        seqs,
        vec![0, 1, 3],
        "the bad frame is skipped, the others tracked"
    );
    assert!(stderr.contains("1 bad frame"), "{stderr}");
}

/// Without `--scene` or `--layout`, `pushbot calibrate` looks for the markers the README and
/// the scene format name: calibration tags 40–45 on the bare 1.2 m × 0.9 m table.
#[test]
fn calibrate_defaults_to_the_scene_formats_markers() {
    let scene = pushbot_world::Scene::preset("empty").unwrap();
    let layout = MarkerLayout::from_scene(&scene);
    let mut ids: Vec<u32> = layout.calibration.iter().map(|m| m.id).collect();
    ids.sort_unstable();
    assert_eq!(ids, vec![40, 41, 42, 43, 44, 45]);
    let dir = tempfile::tempdir().unwrap();
    for f in synth::frames(&layout, 2, 3, &SynthParams::default()).unwrap() {
        let cf = CameraFrame {
            seq: f.frame.seq,
            time: f.frame.time,
            width: f.frame.width,
            height: f.frame.height,
            pixels: f.frame.pixels,
            truth: f.markers,
        };
        cf.write_png(dir.path()).unwrap();
    }
    let cal = dir.path().join("cal.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
        .args([
            "calibrate",
            "--camera",
            dir.path().to_str().unwrap(),
            "--frames",
            "2",
        ])
        .args(["--out", cal.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["markers"], serde_json::json!([40, 41, 42, 43, 44, 45]));
}

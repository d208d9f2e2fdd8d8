//! A camera with a real lens: frames rendered through OpenCV's `plumb_bob` distortion
//! (k1 = −0.08, f = 700 px — a typical webcam). With the true intrinsics the detected corners
//! are undistorted before calibration and measurement, and bodies are placed as well as by an
//! ideal camera; without them the same frames put bodies millimetres off.
#![cfg(feature = "sim")]

use pushbot::sim::synth::{self, PoseScore, SynthParams, quantile};
use pushbot::vision::apriltag::{AprilTagC, AprilTagCConfig};
use pushbot::vision::detect::Detector;
use pushbot::vision::layout::MarkerLayout;
use pushbot::vision::measure;
use pushbot::vision::undistort::undistort_detections;
use pushbot_world::lens::{Distortion, Intrinsics};

fn webcam() -> Intrinsics {
    Intrinsics {
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
    }
}

#[test]
fn with_the_true_intrinsics_a_distorted_camera_measures_as_an_ideal_one() {
    let layout = MarkerLayout::default_table();
    let params = SynthParams {
        lens: Some(webcam()),
        ..SynthParams::default()
    };
    let frames = synth::frames(&layout, 60, 43, &params).unwrap();
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let raw: Vec<_> = frames
        .iter()
        .map(|f| det.detect(&f.frame).unwrap())
        .collect();
    let fixed: Vec<_> = raw
        .iter()
        .map(|d| undistort_detections(d, &webcam()))
        .collect();
    let mut scores = Vec::new();
    for dets in [&raw, &fixed] {
        let cal = synth::calibrate(&dets[..5], &layout, [960, 720]).unwrap();
        let mut poses = PoseScore::default();
        for (d, f) in dets.iter().zip(&frames) {
            poses.add(&measure(d, &cal, &layout), &f.bodies);
        }
        let (med, worst) = (quantile(&poses.pos_mm, 0.5), quantile(&poses.pos_mm, 1.0));
        eprintln!(
            "calibration rms {:.3} px; position median {med:.3} mm, worst {worst:.3} mm over {} poses",
            cal.rms_px,
            poses.pos_mm.len()
        );
        scores.push((med, worst, poses.pos_mm.len()));
    }
    let (raw_med, _, _) = scores[0];
    let (med, worst, n) = scores[1];
    assert!(n >= 60 * 4, "bodies were measured: {n}");
    assert!(med <= 0.5, "median {med} mm with the intrinsics");
    assert!(worst <= 2.0, "worst {worst} mm with the intrinsics");
    assert!(
        raw_med > 2.0 * med.max(0.1),
        "the lens matters: {raw_med} mm without"
    );
}

/// A measurement that puts a body off the table is dropped before the tracker (a smeared or
/// half-seen marker read wrong), counted, and the body is never given that pose.
#[test]
fn poses_off_the_table_are_dropped_and_counted() {
    use pushbot::vision::Pipeline;
    use pushbot::vision::tracking::TrackerParams;
    let layout = MarkerLayout::default_table();
    let frames = synth::frames(&layout, 3, 44, &SynthParams::default()).unwrap();
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let dets: Vec<_> = frames
        .iter()
        .map(|f| det.detect(&f.frame).unwrap())
        .collect();
    let cal = synth::calibrate(&dets, &layout, [960, 720]).unwrap();
    // The same markers, but a table that ends 10 cm from the origin: every body is off it.
    let mut small = layout.clone();
    small.table = [0.1, 0.1];
    for (l, want_off) in [(layout.clone(), false), (small, true)] {
        let detector =
            Box::new(AprilTagC::new(&l.families(), &AprilTagCConfig::default()).unwrap());
        let mut p = Pipeline::new(detector, l, cal.clone(), TrackerParams::default());
        // A frame of another size than the calibration's: refused, not measured.
        let small = pushbot::vision::frame::Frame {
            seq: 0,
            time: 0.0,
            width: 640,
            height: 480,
            pixels: vec![128; 640 * 480],
        };
        let e = p.process(&small).expect_err("another size").to_string();
        assert!(e.contains("640×480") && e.contains("960×720"), "{e}");
        let r = p.process(&frames[0].frame).unwrap();
        if want_off {
            assert!(r.off_table >= 4, "{}", r.off_table);
            assert!(r.measurements.is_empty() && r.tracked.is_empty());
        } else {
            assert_eq!(r.off_table, 0);
            assert!(r.tracked.len() >= 4 && r.tracked.iter().all(|t| !t.lost));
        }
    }
}

/// The command line through a lens: `pushbot --intrinsics FILE calibrate` keeps the lens in the
/// calibration it saves, `track` with that calibration measures through it (the robot where it
/// is); `track --intrinsics` with a calibration made without the lens is refused (exit 2), and so
/// is a lens made for another image size.
#[test]
fn calibrate_and_track_through_a_lens_on_the_command_line() {
    use pushbot_world::lens_file::{LensFormat, write_intrinsics};
    let dir = tempfile::tempdir().unwrap();
    let frames_dir = dir.path().join("frames");
    std::fs::create_dir_all(&frames_dir).unwrap();
    let layout = MarkerLayout::default_table();
    let params = SynthParams {
        lens: Some(webcam()),
        ..SynthParams::default()
    };
    let frames = synth::frames(&layout, 3, 45, &params).unwrap();
    for f in &frames {
        pushbot_sim::camera::CameraFrame {
            seq: f.frame.seq,
            time: f.frame.time,
            width: f.frame.width,
            height: f.frame.height,
            pixels: f.frame.pixels.clone(),
            truth: f.markers.clone(),
        }
        .write_png(&frames_dir)
        .unwrap();
    }
    let lay = dir.path().join("layout.json");
    std::fs::write(&lay, serde_json::to_string(&layout).unwrap()).unwrap();
    let yaml = dir.path().join("webcam.yaml");
    std::fs::write(
        &yaml,
        write_intrinsics(&webcam(), LensFormat::Ros, "webcam"),
    )
    .unwrap();
    let small = dir.path().join("small.yaml");
    let other = Intrinsics {
        width: 640,
        height: 480,
        cx: 320.0,
        cy: 240.0,
        ..webcam()
    };
    std::fs::write(&small, write_intrinsics(&other, LensFormat::Ros, "small")).unwrap();
    let (cam, lay) = (frames_dir.to_str().unwrap(), lay.to_str().unwrap());
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_pushbot"))
            .args(args)
            .output()
            .unwrap()
    };
    let cal = dir.path().join("cal.json");
    let (cal_s, yaml_s) = (cal.to_str().unwrap(), yaml.to_str().unwrap());
    let out = run(&[
        "--intrinsics",
        yaml_s,
        "calibrate",
        "--camera",
        cam,
        "--layout",
        lay,
        "--out",
        cal_s,
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&cal).unwrap()).unwrap();
    assert_eq!(saved["lens"]["distortion"]["k1"].as_f64(), Some(-0.08));
    assert!(saved["rms_px"].as_f64().unwrap() < 0.2, "{saved}");
    let out = run(&[
        "track",
        "--camera",
        cam,
        "--layout",
        lay,
        "--calibration",
        cal_s,
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let first: serde_json::Value = serde_json::from_str(
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .next()
            .unwrap(),
    )
    .unwrap();
    let robot = first["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["id"] == "robot")
        .unwrap()
        .clone();
    let (name, pose) = &frames[0].bodies[0];
    assert_eq!(name, "robot");
    let off = (robot["x"].as_f64().unwrap() - pose.x).hypot(robot["y"].as_f64().unwrap() - pose.y);
    assert!(
        off < 0.001,
        "the robot is {} mm off through the lens",
        off * 1e3
    );
    // A calibration without the lens, used with it: refused.
    let plain = dir.path().join("plain.json");
    let out = run(&[
        "calibrate",
        "--camera",
        cam,
        "--layout",
        lay,
        "--out",
        plain.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let out = run(&[
        "--intrinsics",
        yaml_s,
        "track",
        "--camera",
        cam,
        "--layout",
        lay,
        "--calibration",
        plain.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("calibrate again"));
    // A lens for 640×480 frames on 960×720 ones: refused, saying both sizes.
    let out = run(&[
        "--intrinsics",
        small.to_str().unwrap(),
        "calibrate",
        "--camera",
        cam,
        "--layout",
        lay,
        "--out",
        dir.path().join("x.json").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("640×480") && err.contains("960×720"), "{err}");
}

/// Markers at their true heights: the robot's marker 6 cm and the objects' 3 cm above
/// the table, seen through the lens in perspective. With the heights in the layout (the scene
/// markers' `z`) and the lens known, the calibration knows the camera's centre and each marker
/// is placed where its rays meet its own plane; with the heights left out, the same frames put
/// bodies centimetres off.
#[test]
fn raised_markers_are_placed_on_their_own_plane() {
    let mut layout = MarkerLayout::default_table();
    for b in &mut layout.bodies {
        b.height = if b.body == "robot" { 0.06 } else { 0.03 };
    }
    let params = SynthParams {
        lens: Some(webcam()),
        ..SynthParams::default()
    };
    let frames = synth::frames(&layout, 40, 46, &params).unwrap();
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let raw: Vec<_> = frames
        .iter()
        .map(|f| det.detect(&f.frame).unwrap())
        .collect();
    let cal = pushbot::vision::calibration::Calibration::fit_through(
        &raw[..5],
        &layout,
        [960, 720],
        Some(&webcam()),
    )
    .unwrap();
    let c = cal
        .camera_centre
        .expect("the lens gives the camera's centre");
    eprintln!("camera centre {c:?}");
    let mut flat = layout.clone();
    for b in &mut flat.bodies {
        b.height = 0.0;
    }
    let mut medians = Vec::new();
    for l in [&layout, &flat] {
        let mut poses = PoseScore::default();
        for (d, f) in raw.iter().zip(&frames) {
            let fixed = undistort_detections(d, &webcam());
            poses.add(&measure(&fixed, &cal, l), &f.bodies);
        }
        let med = quantile(&poses.pos_mm, 0.5);
        eprintln!(
            "position median {med:.3} mm, worst {:.3} mm over {}",
            quantile(&poses.pos_mm, 1.0),
            poses.pos_mm.len()
        );
        assert!(
            poses.pos_mm.len() >= 40 * 3,
            "bodies measured: {}",
            poses.pos_mm.len()
        );
        medians.push(med);
    }
    assert!(
        medians[0] <= 0.5,
        "median {} mm with the heights",
        medians[0]
    );
    assert!(
        medians[1] > 5.0,
        "the heights matter: {} mm without",
        medians[1]
    );
}

//! A camera with a real lens (issue 20): frames rendered through OpenCV's `plumb_bob` distortion
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

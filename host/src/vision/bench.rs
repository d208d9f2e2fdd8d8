//! `pushbot bench vision`: milliseconds per 960×720 frame for the chosen pipeline (C AprilTag
//! detection + table poses + tracking) and, in the same run on the same rendered frames, for the
//! reference C detector alone and for the pure-Rust `kornia-apriltag` candidate (at its defaults
//! and with `threshold_split = 0.5`; built with `--features kornia`), each on one core; with
//! detection rate, wrong ids and corner error against the renderer's ground truth.

use std::time::Instant;

use serde::Serialize;

use super::apriltag::{AprilTagC, AprilTagCConfig};
use super::detect::{Detection, Detector};
#[cfg(feature = "kornia")]
use super::kornia::{KorniaConfig, KorniaDetector};
use super::layout::MarkerLayout;
use super::synth::{self, DetectionScore, PoseScore, SynthParams, quantile};
use super::tracking::TrackerParams;
use super::{Pipeline, measure};

/// One detector's figures.
#[derive(Debug, Clone, Serialize)]
pub struct DetectorFigures {
    /// Name and settings.
    pub name: String,
    /// Mean milliseconds per frame.
    pub ms_mean: f64,
    /// Median milliseconds per frame.
    pub ms_median: f64,
    /// Fraction of fully visible markers found.
    pub detection_rate: f64,
    /// Detections with an id not in the frame at that place.
    pub wrong_ids: usize,
    /// RMS corner error, pixels.
    pub corner_rms_px: f64,
    /// Mean corner error vector, pixels.
    pub corner_bias_px: [f64; 2],
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct VisionBench {
    /// Frames measured.
    pub frames: usize,
    /// Frame size.
    pub size: [u32; 2],
    /// The chosen pipeline: C AprilTag + poses + Kalman tracking.
    pub pipeline: String,
    /// Mean milliseconds per frame of the chosen pipeline.
    pub pipeline_ms_mean: f64,
    /// Median milliseconds per frame of the chosen pipeline.
    pub pipeline_ms_median: f64,
    /// Body position error median / 99th percentile, millimetres (per-frame measurements).
    pub position_mm: [f64; 2],
    /// Body heading error median / 99th percentile, degrees.
    pub heading_deg: [f64; 2],
    /// Calibration RMS reprojection error, pixels.
    pub calibration_rms_px: f64,
    /// Every detector measured.
    pub detectors: Vec<DetectorFigures>,
}

fn time_detector(
    d: &mut dyn Detector,
    name: String,
    frames: &[synth::SynthFrame],
) -> Result<(DetectorFigures, Vec<Vec<Detection>>), String> {
    let mut ms = Vec::with_capacity(frames.len());
    let mut score = DetectionScore::default();
    let mut all = Vec::with_capacity(frames.len());
    for f in frames {
        let t0 = Instant::now();
        let dets = d.detect(&f.frame).map_err(|e| e.to_string())?;
        ms.push(t0.elapsed().as_secs_f64() * 1e3);
        score.add(&dets, &f.markers);
        all.push(dets);
    }
    let fig = DetectorFigures {
        name,
        ms_mean: ms.iter().sum::<f64>() / ms.len().max(1) as f64,
        ms_median: quantile(&ms, 0.5),
        detection_rate: score.rate(),
        wrong_ids: score.wrong_ids,
        corner_rms_px: score.corner_rms(),
        corner_bias_px: score.corner_bias,
    };
    Ok((fig, all))
}

/// Render `n` frames and measure everything on them.
pub fn run(n: usize, seed: u64) -> Result<VisionBench, String> {
    let layout = MarkerLayout::default_table();
    let params = SynthParams::default();
    let frames = synth::frames(&layout, n.max(1), seed, &params)?;
    let families = layout.families();
    let mut detectors = Vec::new();

    let mut c =
        AprilTagC::new(&families, &AprilTagCConfig::default()).map_err(|e| e.to_string())?;
    let (fig, c_dets) = time_detector(
        &mut c,
        "apriltag-c (reference, quad_decimate 2)".into(),
        &frames,
    )?;
    detectors.push(fig);
    #[cfg(feature = "kornia")]
    for (name, cfg) in [
        ("kornia-apriltag (defaults)", KorniaConfig::default()),
        (
            "kornia-apriltag (threshold_split 0.5)",
            KorniaConfig {
                threshold_split: Some(0.5),
                downscale: None,
            },
        ),
    ] {
        let mut k = KorniaDetector::new(&families, &cfg).map_err(|e| e.to_string())?;
        detectors.push(time_detector(&mut k, name.into(), &frames)?.0);
    }

    let cal = synth::calibrate(&c_dets[..c_dets.len().min(5)], &layout, params.size)?;
    let mut poses = PoseScore::default();
    for (dets, f) in c_dets.iter().zip(&frames) {
        poses.add(&measure(dets, &cal, &layout), &f.bodies);
    }
    let mut pipeline = Pipeline::new(
        Box::new(
            AprilTagC::new(&families, &AprilTagCConfig::default()).map_err(|e| e.to_string())?,
        ),
        layout.clone(),
        cal.clone(),
        TrackerParams::default(),
    );
    let mut ms = Vec::with_capacity(frames.len());
    for f in &frames {
        let t0 = Instant::now();
        pipeline.process(&f.frame).map_err(|e| e.to_string())?;
        ms.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    Ok(VisionBench {
        frames: frames.len(),
        size: params.size,
        pipeline: "apriltag-c + homography poses + Kalman tracking".into(),
        pipeline_ms_mean: ms.iter().sum::<f64>() / ms.len().max(1) as f64,
        pipeline_ms_median: quantile(&ms, 0.5),
        position_mm: [quantile(&poses.pos_mm, 0.5), quantile(&poses.pos_mm, 0.99)],
        heading_deg: [
            quantile(&poses.heading_deg, 0.5),
            quantile(&poses.heading_deg, 0.99),
        ],
        calibration_rms_px: cal.rms_px,
        detectors,
    })
}

//! `pushbot bench vision`: milliseconds per 960×720 frame, on one core, of the chosen pipeline
//! (C AprilTag at the chosen settings, [`AprilTagCConfig::default`], in tracker-guided regions of
//! interest + table poses + Kalman tracking, [`super::RoiParams`]) and, in the same run on the
//! same rendered frames, of the same pipeline searching every whole frame, of the reference C
//! detector alone ([`AprilTagCConfig::reference`]) and at the chosen settings, and of the pure-Rust
//! `kornia-apriltag` candidate (at its defaults and with `threshold_split = 0.5`; built with
//! `--features kornia`); with detection rate, wrong ids and corner error against the renderer's
//! ground truth. The frames are a video ([`synth::moving_frames`]): bodies move at a pushing
//! robot's pace, so regions of interest can follow them. The same video is then rendered through
//! a real lens and the chosen pipeline measures through it (the lens model on: only the detected
//! corners are undistorted), beside the reference C detector on those frames.
//!
//! Time is the process's CPU time (`CLOCK_PROCESS_CPUTIME_ID`; one thread works at a time, so
//! it is one core's work whatever else the machine runs); wall-clock time is reported beside it.

use std::time::Instant;

use serde::Serialize;

use super::apriltag::{AprilTagC, AprilTagCConfig};
use super::detect::Detector;
#[cfg(feature = "kornia")]
use super::kornia::{KorniaConfig, KorniaDetector};
use super::layout::MarkerLayout;
use super::tracking::TrackerParams;
use super::{Pipeline, RoiParams};
use crate::sim::synth::{self, DetectionScore, PoseScore, SynthParams, quantile};

/// This process's CPU time, milliseconds: every thread's, so a detector that works on a
/// one-thread pool (kornia) is counted while the caller waits.
pub fn cpu_ms() -> f64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::ProcessCPUTime);
    t.tv_sec as f64 * 1e3 + t.tv_nsec as f64 * 1e-6
}

/// Times of one run, milliseconds per frame.
#[derive(Debug, Clone, Serialize)]
pub struct Times {
    /// Mean CPU time per frame (one core's work).
    pub ms_mean: f64,
    /// Median CPU time per frame.
    pub ms_median: f64,
    /// Slowest frame's CPU time.
    pub ms_max: f64,
    /// Mean wall-clock time per frame (includes waiting for a busy machine).
    pub wall_ms_mean: f64,
}

#[derive(Default)]
struct Clock {
    cpu: Vec<f64>,
    wall: Vec<f64>,
}

impl Clock {
    fn time<T>(&mut self, f: impl FnOnce() -> T) -> T {
        let (c0, w0) = (cpu_ms(), Instant::now());
        let out = f();
        self.cpu.push(cpu_ms() - c0);
        self.wall.push(w0.elapsed().as_secs_f64() * 1e3);
        out
    }

    fn times(&self) -> Times {
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        Times {
            ms_mean: mean(&self.cpu),
            ms_median: quantile(&self.cpu, 0.5),
            ms_max: self.cpu.iter().copied().fold(0.0, f64::max),
            wall_ms_mean: mean(&self.wall),
        }
    }
}

/// One detector's figures (whole frames).
#[derive(Debug, Clone, Serialize)]
pub struct DetectorFigures {
    /// Name and settings.
    pub name: String,
    /// Milliseconds per frame.
    pub time: Times,
    /// Fraction of fully visible markers found.
    pub detection_rate: f64,
    /// Detections with an id not in the frame at that place.
    pub wrong_ids: usize,
    /// RMS corner error, pixels.
    pub corner_rms_px: f64,
    /// Mean corner error vector, pixels.
    pub corner_bias_px: [f64; 2],
}

/// One pipeline's figures: detection, poses and tracking per frame.
#[derive(Debug, Clone, Serialize)]
pub struct PipelineFigures {
    /// What it is.
    pub name: String,
    /// Milliseconds per frame, the whole pipeline.
    pub time: Times,
    /// Fraction of frames whose whole image was searched.
    pub full_frame_fraction: f64,
    /// Fraction of (frame, body) pairs whose body was measured.
    pub bodies_found: f64,
    /// Wrong ids among the detections it made.
    pub wrong_ids: usize,
    /// RMS corner error of the markers it found, pixels.
    pub corner_rms_px: f64,
    /// Body position error median / 99th percentile, millimetres (per-frame measurements).
    pub position_mm: [f64; 2],
    /// Body heading error median / 99th percentile, degrees.
    pub heading_deg: [f64; 2],
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct VisionBench {
    /// Frames measured.
    pub frames: usize,
    /// Frame size.
    pub size: [u32; 2],
    /// How time is measured.
    pub clock: String,
    /// Calibration RMS reprojection error, pixels.
    pub calibration_rms_px: f64,
    /// The chosen pipeline (the default of `track`, `calibrate` and the live executor) and
    /// the same pipeline searching every whole frame.
    pub pipelines: Vec<PipelineFigures>,
    /// Every detector measured on whole frames: the reference C detector first, then the C
    /// detector at the chosen settings, then the kornia candidates (with `--features kornia`).
    pub detectors: Vec<DetectorFigures>,
    /// The same video seen through a real lens, the pipeline measuring through it.
    pub lens: LensFigures,
}

/// The figures through a lens: the chosen pipeline with the lens model on (corners undistorted,
/// [`super::undistort`]) beside the reference C detector, on the same distorted frames.
#[derive(Debug, Clone, Serialize)]
pub struct LensFigures {
    /// The lens the frames were rendered through.
    pub intrinsics: pushbot_world::lens::Intrinsics,
    /// Calibration RMS reprojection error through the lens, pixels.
    pub calibration_rms_px: f64,
    /// The chosen pipeline, measuring through the lens.
    pub pipelines: Vec<PipelineFigures>,
    /// The reference C detector on the same frames.
    pub detectors: Vec<DetectorFigures>,
}

/// A typical webcam's lens for 960×720 frames (f = 700 px, k1 = −0.08), the bench's default.
pub fn webcam_lens() -> pushbot_world::lens::Intrinsics {
    pushbot_world::lens::Intrinsics {
        distortion: pushbot_world::lens::Distortion {
            k1: -0.08,
            ..pushbot_world::lens::Distortion::NONE
        },
        ..pushbot_world::lens::Intrinsics::pinhole(960, 720, 700.0)
    }
}

/// A detector being measured.
struct DetectorRun {
    name: String,
    detector: Box<dyn Detector>,
    clock: Clock,
    score: DetectionScore,
}

impl DetectorRun {
    fn new(name: String, detector: Box<dyn Detector>) -> DetectorRun {
        DetectorRun {
            name,
            detector,
            clock: Clock::default(),
            score: DetectionScore::default(),
        }
    }

    fn frame(&mut self, f: &synth::SynthFrame) -> Result<(), String> {
        let d = &mut self.detector;
        let dets = self
            .clock
            .time(|| d.detect(&f.frame))
            .map_err(|e| e.to_string())?;
        self.score.add(&dets, &f.markers);
        Ok(())
    }

    fn figures(&self) -> DetectorFigures {
        DetectorFigures {
            name: self.name.clone(),
            time: self.clock.times(),
            detection_rate: self.score.rate(),
            wrong_ids: self.score.wrong_ids,
            corner_rms_px: self.score.corner_rms(),
            corner_bias_px: self.score.corner_bias,
        }
    }
}

/// A pipeline being measured.
struct PipelineRun {
    name: String,
    pipeline: Pipeline,
    clock: Clock,
    poses: PoseScore,
    score: DetectionScore,
    full: usize,
    found: usize,
    bodies: usize,
}

impl PipelineRun {
    fn new(name: String, pipeline: Pipeline) -> PipelineRun {
        PipelineRun {
            name,
            pipeline,
            clock: Clock::default(),
            poses: PoseScore::default(),
            score: DetectionScore::default(),
            full: 0,
            found: 0,
            bodies: 0,
        }
    }

    fn frame(&mut self, f: &synth::SynthFrame) -> Result<(), String> {
        let p = &mut self.pipeline;
        let r = self
            .clock
            .time(|| p.process(&f.frame))
            .map_err(|e| e.to_string())?;
        self.full += usize::from(r.full_frame);
        self.poses.add(&r.measurements, &f.bodies);
        self.bodies += f.bodies.len();
        self.found += f
            .bodies
            .iter()
            .filter(|(b, _)| r.measurements.iter().any(|m| &m.body == b))
            .count();
        // Wrong ids among all it reported; corner errors of the markers it found (regions
        // find only some of the markers drawn, so its rate is not scored here).
        self.score.add(&r.detections, &f.markers);
        Ok(())
    }

    fn figures(&self, frames: usize) -> PipelineFigures {
        let q = |v: &[f64]| [quantile(v, 0.5), quantile(v, 0.99)];
        PipelineFigures {
            name: self.name.clone(),
            time: self.clock.times(),
            full_frame_fraction: self.full as f64 / frames.max(1) as f64,
            bodies_found: self.found as f64 / self.bodies.max(1) as f64,
            wrong_ids: self.score.wrong_ids,
            corner_rms_px: self.score.corner_rms(),
            position_mm: q(&self.poses.pos_mm),
            heading_deg: q(&self.poses.heading_deg),
        }
    }
}

/// Render `n` video frames and measure everything on them; then the same through `lens` (a
/// webcam's when `None`), which must be made for 960×720 frames.
pub fn run(
    n: usize,
    seed: u64,
    lens: Option<pushbot_world::lens::Intrinsics>,
) -> Result<VisionBench, String> {
    let layout = MarkerLayout::default_table();
    let params = SynthParams::default();
    let lens = lens.unwrap_or_else(webcam_lens);
    if [lens.width, lens.height] != params.size {
        return Err(format!(
            "the lens is for {}×{} frames, the bench renders {}×{}",
            lens.width, lens.height, params.size[0], params.size[1]
        ));
    }
    let (rms, pipelines, detectors) = measure_set(&layout, n, seed, params, None)?;
    let lensed = SynthParams {
        lens: Some(lens),
        ..params
    };
    let (lens_rms, lens_pipelines, lens_detectors) =
        measure_set(&layout, n, seed, lensed, Some(lens))?;
    Ok(VisionBench {
        frames: n.max(1),
        size: params.size,
        clock: "process CPU time (one thread at work: one core); wall_ms_mean is wall-clock".into(),
        calibration_rms_px: rms,
        pipelines,
        detectors,
        lens: LensFigures {
            intrinsics: lens,
            calibration_rms_px: lens_rms,
            // Only the chosen pipeline and the reference detector: the comparison asked for.
            pipelines: lens_pipelines.into_iter().take(1).collect(),
            detectors: lens_detectors.into_iter().take(1).collect(),
        },
    })
}

/// The figures of one set of frames: calibration RMS, pipelines, detectors.
type SetFigures = (f64, Vec<PipelineFigures>, Vec<DetectorFigures>);

/// Render `n` video frames with `params` and measure every pipeline and detector on them; the
/// calibration and the pipelines measure through `lens`.
fn measure_set(
    layout: &MarkerLayout,
    n: usize,
    seed: u64,
    params: SynthParams,
    lens: Option<pushbot_world::lens::Intrinsics>,
) -> Result<SetFigures, String> {
    let frames = synth::moving_frames(layout, n.max(1), seed, &params)?;
    let families = layout.families();
    let (c_cfg, r_cfg) = (AprilTagCConfig::default(), AprilTagCConfig::reference());
    let c_with = |cfg: &AprilTagCConfig| -> Result<Box<dyn Detector>, String> {
        Ok(Box::new(
            AprilTagC::new(&families, cfg).map_err(|e| e.to_string())?,
        ))
    };
    let c = || c_with(&c_cfg);

    // Calibrate as `pushbot calibrate` does, from the first frames (not timed).
    let mut det = c()?;
    let first = frames
        .iter()
        .take(5)
        .map(|f| det.detect_fine(&f.frame).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let cal =
        super::calibration::Calibration::fit_through(&first, layout, params.size, lens.as_ref())
            .map_err(|e| e.to_string())?;
    #[cfg_attr(not(feature = "kornia"), allow(unused_mut))]
    let mut detectors = vec![
        DetectorRun::new(
            format!(
                "apriltag-c (reference, quad_decimate {}, quad_sigma {})",
                r_cfg.decimate, r_cfg.sigma
            ),
            c_with(&r_cfg)?,
        ),
        DetectorRun::new(
            format!(
                "apriltag-c (chosen, quad_decimate {}, quad_sigma {})",
                c_cfg.decimate, c_cfg.sigma
            ),
            c()?,
        ),
    ];
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
        let k = KorniaDetector::new(&families, &cfg).map_err(|e| e.to_string())?;
        detectors.push(DetectorRun::new(name.into(), Box::new(k)));
    }
    let mut pipelines = Vec::new();
    for (name, roi) in [
        (
            "chosen: apriltag-c (quad_sigma 1) in tracker-guided regions of interest + poses + Kalman tracking",
            RoiParams::default(),
        ),
        (
            "apriltag-c (quad_sigma 1) on every whole frame + poses + Kalman tracking",
            RoiParams::full_frames(),
        ),
    ] {
        let pipe = Pipeline::new(c()?, layout.clone(), cal.clone(), TrackerParams::default())
            .with_roi(roi);
        pipelines.push(PipelineRun::new(name.into(), pipe));
    }
    // Interleaved frame by frame, so every candidate sees the machine in the same state.
    for f in &frames {
        for p in &mut pipelines {
            p.frame(f)?;
        }
        for d in &mut detectors {
            d.frame(f)?;
        }
    }
    Ok((
        cal.rms_px,
        pipelines.iter().map(|p| p.figures(frames.len())).collect(),
        detectors.iter().map(DetectorRun::figures).collect(),
    ))
}

//! `pushbot calibrate`, `pushbot track`, `pushbot bench vision`: the overhead camera's
//! calibration, live tracking and speed.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, Subcommand};

use super::{CliError, CliResult, Global, Status};
use crate::vision::calibration::{Calibration, calibration_markers};
use crate::vision::detect::{DetectorKind, make_detector};
use crate::vision::layout::MarkerLayout;
use crate::vision::source::{Frame, FrameSource, SourceError, open_source};
use crate::vision::tracking::TrackerParams;
use crate::vision::{Pipeline, RoiParams, TrackLine};

/// Where frames come from and what is on the table.
#[derive(Args, Debug, Clone)]
pub struct CameraArgs {
    /// Frame source: /dev/videoN (V4L2), sim:HOST:PORT (the sim camera), or a folder of images.
    /// (Required; an `Option` only so that `calibrate lens|board` parse without it.)
    #[arg(long, required = true)]
    pub camera: Option<String>,
    /// The scene on the table (preset name or TOML file): its calibration markers and the
    /// markers on the robot, the objects and the goals.
    #[arg(long, value_name = "PRESET|FILE", conflicts_with = "layout")]
    pub scene: Option<String>,
    /// A stand-alone marker layout instead of a scene (TOML or JSON: table, calibration
    /// markers, body markers); default: the markers the scene format names on its bare
    /// 1.2 × 0.9 m table (the `empty` preset): calibration tags 40–45 6 cm in from the corners
    /// and the middles of the long edges, the robot's tag 0.
    #[arg(long)]
    pub layout: Option<PathBuf>,
    /// Frame rate assumed for image folders without time sidecars.
    #[arg(long, default_value_t = 30.0, help_heading = super::ADVANCED)]
    pub fps: f64,
    /// Marker detector.
    #[arg(long, value_enum, default_value = "apriltag-c", help_heading = super::ADVANCED)]
    pub detector: DetectorKind,
}

/// `pushbot calibrate`.
#[derive(Args, Debug, Clone)]
pub struct CalibrateArgs {
    /// Source and layout.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Frames to collect detections from.
    #[arg(long, default_value_t = 5)]
    pub frames: usize,
    /// Where to save the calibration (JSON).
    #[arg(long, default_value = "calibration.json")]
    pub out: PathBuf,
}

/// `pushbot track`.
#[derive(Args, Debug, Clone)]
pub struct TrackArgs {
    /// Source and layout.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// A saved calibration; without one, the first frames showing four calibration markers
    /// calibrate the camera.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// Stop after this many frames (default: until the source ends).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Search every whole frame for markers instead of regions around the tracked markers
    /// (without it, whole frames come every 15 frames while a body is not tracked, and
    /// whenever a body is missed).
    #[arg(long, help_heading = super::ADVANCED)]
    pub whole_frames: bool,
    /// Record the frames, detections and tracked poses into this MCAP file (Foxglove schemas;
    /// `pushbot replay FILE` tracks them again).
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// The robot's serial port: its telemetry's wheel odometry becomes the tracker's control
    /// input, so a fast spin or a smeared marker is predicted from the wheels (nothing is sent
    /// but the link's own keep-alive; drive the robot from elsewhere).
    #[arg(long)]
    pub port: Option<String>,
}

/// `pushbot bench …`.
#[derive(Subcommand, Debug, Clone)]
pub enum BenchCommand {
    /// Milliseconds per 960×720 frame: the chosen vision pipeline, the reference C detector and
    /// the kornia candidate, on the same rendered video frames, one core (thread CPU time); then
    /// the pipeline with the lens model on beside the C library, on the same video seen through a
    /// lens (`--intrinsics FILE`, or a webcam's: f = 700 px, k1 = −0.08).
    Vision {
        /// Frames to render and measure.
        #[arg(long, default_value_t = 100)]
        frames: usize,
    },
}

fn layout(args: &CameraArgs) -> Result<MarkerLayout, CliError> {
    if let Some(scene) = &args.scene {
        let scene = pushbot_world::Scene::preset_or_file(scene)
            .map_err(|e| CliError::bad_input(e.to_string()))?;
        return Ok(MarkerLayout::from_scene(&scene));
    }
    match &args.layout {
        Some(p) => MarkerLayout::load(p).map_err(CliError::bad_input),
        None => pushbot_world::Scene::preset("empty")
            .map(|s| MarkerLayout::from_scene(&s))
            .map_err(|e| CliError::Failed(anyhow::anyhow!("the empty preset: {e}"))),
    }
}

fn source(args: &CameraArgs) -> Result<Box<dyn FrameSource>, CliError> {
    let Some(camera) = &args.camera else {
        return Err(CliError::bad_input("--camera is required"));
    };
    open_source(camera, args.fps).map_err(|e| match e {
        SourceError::BadSource(m) => CliError::bad_input(m),
        SourceError::Read(m) | SourceError::BadFrame(m) => CliError::Failed(anyhow::anyhow!(m)),
    })
}

fn read_err(e: SourceError) -> CliError {
    CliError::Failed(anyhow::anyhow!("{e}"))
}

/// The source's next usable frame: a bad one (corrupt, truncated) is skipped with a warning
/// and counted in `skipped`.
fn next_good(src: &mut dyn FrameSource, skipped: &mut u64) -> Result<Option<Frame>, CliError> {
    loop {
        match src.next_frame() {
            Err(SourceError::BadFrame(e)) => {
                *skipped += 1;
                tracing::warn!("a bad frame skipped: {e}");
            }
            r => return r.map_err(read_err),
        }
    }
}

/// Collect up to `n` frames' detections and fit a calibration (the inner error: the frames do
/// not allow one, a failed task rather than bad input).
fn calibrate_from(
    src: &mut dyn FrameSource,
    args: &CameraArgs,
    lay: &MarkerLayout,
    n: usize,
    lens: Option<&pushbot_world::lens::Intrinsics>,
) -> Result<Result<Calibration, String>, CliError> {
    let mut det =
        make_detector(args.detector, &lay.families()).map_err(|e| CliError::Failed(e.into()))?;
    let mut all = Vec::new();
    let mut size = [0, 0];
    let mut skipped = 0;
    while all.len() < n.max(1) {
        let Some(frame) = next_good(src, &mut skipped)? else {
            break;
        };
        size = [frame.width, frame.height];
        all.push(
            calibration_markers(det.as_mut(), &frame, lay)
                .map_err(|e| CliError::Failed(e.into()))?,
        );
    }
    if all.is_empty() {
        return Err(CliError::bad_input(format!(
            "{} gave no frames to calibrate from",
            src.describe()
        )));
    }
    match Calibration::fit_through(&all, lay, size, lens) {
        Err(e @ crate::vision::calibration::CalibrationError::Lens(_)) => {
            Err(CliError::bad_input(format!("--intrinsics: {e}")))
        }
        r => Ok(r.map_err(|e| e.to_string())),
    }
}

/// `pushbot calibrate`.
pub fn calibrate(g: &Global, args: CalibrateArgs) -> CliResult {
    let lay = layout(&args.camera)?;
    if args.frames == 0 {
        return Err(CliError::bad_input("--frames must be at least 1"));
    }
    let mut src = source(&args.camera)?;
    let lens = g.lens()?;
    let cal = match calibrate_from(src.as_mut(), &args.camera, &lay, args.frames, lens.as_ref())? {
        Ok(c) => c,
        Err(msg) => return Ok(super::task_failed(g, &msg)),
    };
    cal.save(&args.out)
        .map_err(|e| CliError::Failed(e.into()))?;
    if g.json {
        let v = serde_json::json!({"calibration": args.out, "rms_px": cal.rms_px, "max_px": cal.max_px,
            "mm_per_px": cal.mm_per_px, "markers": cal.markers, "points": cal.points});
        println!("{v}");
    } else {
        println!(
            "calibrated from markers {:?} ({} points): reprojection RMS {:.3} px, max {:.3} px ({:.2} mm/px); saved {}",
            cal.markers,
            cal.points,
            cal.rms_px,
            cal.max_px,
            cal.mm_per_px,
            args.out.display()
        );
    }
    Ok(Status::Success)
}

/// `pushbot track`.
pub fn track(g: &Global, args: TrackArgs) -> CliResult {
    let lay = layout(&args.camera)?;
    // Files are checked before the camera is opened.
    let saved = match &args.calibration {
        Some(p) => Some(Calibration::load(p).map_err(CliError::bad_input)?),
        None => None,
    };
    if args.frames == Some(0) {
        return Err(CliError::bad_input("--frames must be at least 1"));
    }
    let lens = g.lens()?;
    if let (Some(c), Some(_)) = (&saved, &lens)
        && c.lens != lens
    {
        return Err(CliError::bad_input(format!(
            "--calibration was made {} --intrinsics: calibrate again with it",
            if c.lens.is_some() {
                "through another lens than"
            } else {
                "without"
            }
        )));
    }
    let mut src = source(&args.camera)?;
    let cal = match saved {
        Some(c) => c,
        None => match calibrate_from(src.as_mut(), &args.camera, &lay, 1, lens.as_ref())? {
            Ok(c) => c,
            Err(msg) => return Ok(super::task_failed(g, &msg)),
        },
    };
    let det = make_detector(args.camera.detector, &lay.families())
        .map_err(|e| CliError::Failed(e.into()))?;
    let roi = if args.whole_frames {
        RoiParams::full_frames()
    } else {
        RoiParams::default()
    };
    let recording = match &args.record {
        Some(path) => {
            let mut rec = crate::recording::Recording::create(path).map_err(CliError::BadInput)?;
            let scene = match &args.camera.scene {
                Some(s) => Some(
                    pushbot_world::Scene::preset_or_file(s)
                        .map_err(|e| CliError::bad_input(e.to_string()))?,
                ),
                None => None,
            };
            let info = crate::recording::writer::SessionInfo {
                label: "track",
                scene: scene.as_ref(),
                layout: &lay,
                calibration: &cal,
                tracker: TrackerParams::default(),
                detector: args.camera.detector,
                whole_frames: args.whole_frames,
            };
            rec.begin_session(&info, 0)?;
            Some(rec)
        }
        None => None,
    };
    let mut recording = recording;
    let mut pipe = Pipeline::new(det, lay, cal, TrackerParams::default()).with_roi(roi);
    // The robot's odometry, if its port is given: the simulated target's camera shares its clock.
    let odometry = match &args.port {
        Some(port) => {
            let robot = crate::robot::Robot::connect(port, g.link_options()?)
                .map_err(|e| CliError::bad_input(format!("--port: {e}")))?;
            let same_clock = args
                .camera
                .camera
                .as_deref()
                .is_some_and(|c| c.starts_with("sim:"));
            let feed =
                crate::exec::odometry_feed::OdometryFeed::new(&robot, same_clock.then_some(0.0));
            Some((robot, feed))
        }
        None => None,
    };
    let mut odometry = odometry;
    let mut out = std::io::stdout().lock();
    let mut count = 0;
    let mut skipped = 0;
    while args.frames.is_none_or(|n| count < n) {
        let Some(frame) = next_good(src.as_mut(), &mut skipped)? else {
            break;
        };
        if let Some((robot, feed)) = odometry.as_mut() {
            feed.feed(robot, &mut pipe, frame.time);
        }
        let r = pipe
            .process(&frame)
            .map_err(|e| CliError::Failed(e.into()))?;
        if let Some(rec) = recording.as_mut() {
            // No robot here: the camera's clock is the time line.
            let us = (frame.time.max(0.0) * 1e6) as u64;
            rec.frame(us, &frame, &r, pipe.calibration(), None)?;
        }
        let line = TrackLine::from(&r);
        let text = if g.json {
            serde_json::to_string(&line).map_err(|e| CliError::Failed(e.into()))?
        } else {
            let bodies: Vec<String> = line
                .bodies
                .iter()
                .map(|b| match (b.x, b.y, b.theta) {
                    (Some(x), Some(y), Some(theta)) => format!(
                        "{} ({x:.4}, {y:.4}, {:.1}°){}",
                        b.id,
                        theta.to_degrees(),
                        if b.seen { "" } else { " unseen" }
                    ),
                    _ => format!("{} lost", b.id),
                })
                .collect();
            format!("t={:.3}s {}", line.time, bodies.join("  "))
        };
        if writeln!(out, "{text}").is_err() {
            break;
        }
        count += 1;
    }
    if let Some(rec) = recording {
        rec.finish()?;
    }
    if skipped > 0 {
        eprintln!("{skipped} bad frame(s) skipped (corrupt or truncated images)");
    }
    Ok(Status::Success)
}

/// `pushbot bench vision` needs the simulated camera's frames.
#[cfg(not(feature = "sim"))]
pub fn bench(_g: &Global, _cmd: BenchCommand) -> CliResult {
    Err(super::no_simulated_target())
}

/// `pushbot bench vision`.
#[cfg(feature = "sim")]
pub fn bench(g: &Global, cmd: BenchCommand) -> CliResult {
    match cmd {
        BenchCommand::Vision { frames } => {
            let lens = g.lens()?;
            if let Some(l) = &lens
                && [l.width, l.height] != [960, 720]
            {
                return Err(CliError::bad_input(format!(
                    "--intrinsics: the lens is for {}×{} frames, the bench renders 960×720",
                    l.width, l.height
                )));
            }
            let r = crate::vision::bench::run(frames, g.seed, lens)
                .map_err(|e| CliError::Failed(anyhow::anyhow!(e)))?;
            if g.json {
                println!(
                    "{}",
                    serde_json::to_string(&r).map_err(|e| CliError::Failed(e.into()))?
                );
            } else {
                println!(
                    "{} video frames {}x{}; {}; calibration RMS {:.3} px",
                    r.frames, r.size[0], r.size[1], r.clock, r.calibration_rms_px
                );
                for p in &r.pipelines {
                    println!(
                        "pipeline {}\n  {:.2} ms/frame mean (median {:.2}, max {:.2}; wall {:.2}), whole frames {:.1}%, bodies found {:.2}%, wrong ids {}, corner RMS {:.3} px, position error median {:.3} mm p99 {:.3} mm, heading median {:.3}° p99 {:.3}°",
                        p.name,
                        p.time.ms_mean,
                        p.time.ms_median,
                        p.time.ms_max,
                        p.time.wall_ms_mean,
                        100.0 * p.full_frame_fraction,
                        100.0 * p.bodies_found,
                        p.wrong_ids,
                        p.corner_rms_px,
                        p.position_mm[0],
                        p.position_mm[1],
                        p.heading_deg[0],
                        p.heading_deg[1]
                    );
                }
                for d in &r.detectors {
                    println!(
                        "detector {:<40} {:7.2} ms/frame (median {:.2}; wall {:.2})  found {:.2}%  wrong ids {}  corner RMS {:.3} px  bias ({:+.3}, {:+.3})",
                        d.name,
                        d.time.ms_mean,
                        d.time.ms_median,
                        d.time.wall_ms_mean,
                        100.0 * d.detection_rate,
                        d.wrong_ids,
                        d.corner_rms_px,
                        d.corner_bias_px[0],
                        d.corner_bias_px[1]
                    );
                }
                let l = &r.lens;
                let d = &l.intrinsics.distortion;
                println!(
                    "through a lens (f {:.0} px, k1 {}, k2 {}, p1 {}, p2 {}, k3 {}); calibration RMS {:.3} px",
                    l.intrinsics.fx, d.k1, d.k2, d.p1, d.p2, d.k3, l.calibration_rms_px
                );
                for p in &l.pipelines {
                    println!(
                        "  pipeline {}, lens model on: {:.2} ms/frame mean (median {:.2}), bodies found {:.2}%, position error median {:.3} mm p99 {:.3} mm",
                        p.name,
                        p.time.ms_mean,
                        p.time.ms_median,
                        100.0 * p.bodies_found,
                        p.position_mm[0],
                        p.position_mm[1]
                    );
                }
                for d in &l.detectors {
                    println!(
                        "  detector {}: {:.2} ms/frame (median {:.2}), found {:.2}%",
                        d.name,
                        d.time.ms_mean,
                        d.time.ms_median,
                        100.0 * d.detection_rate
                    );
                }
            }
            Ok(Status::Success)
        }
    }
}

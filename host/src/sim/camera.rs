//! The in-process robot's camera in the loop: every look renders the simulated world as the
//! served target's camera does (the scene's lens and camera placement, markers at their
//! heights, blur, noise and exposure; `sim-target/src/camera/`) and reads the frame with the
//! host's own vision pipeline — marker detection, undistortion, the calibration fitted from
//! the first frames, the tracker — exactly as [`crate::exec::LiveRobot`] reads a real camera.
//! It runs in simulated time, with no pty and no socket between, so evaluations of hundreds of
//! trials can have the camera in the loop (`--camera rendered`).

use std::collections::HashMap;

use anyhow::{Context, Result, anyhow};
use pushbot_world::Scene;

use super::inprocess::SimRef;
use super::target::SceneCamera;
use crate::vision::Pipeline;
use crate::vision::calibration::Calibration;
use crate::vision::detect::{DetectorKind, make_detector};
use crate::vision::layout::{MarkerLayout, Pose};
use crate::vision::source::Frame;
use crate::vision::tracking::TrackerParams;

/// Frames the calibration is fitted through (as [`crate::exec::LiveRobot`] does).
const CALIBRATION_FRAMES: usize = 3;

/// Most frames one look waits for a body it has not seen since the robot stopped, as the live
/// robot does (`reacquire_frames`), before the robot moves to look for it
/// ([`crate::exec::occlusion`]).
pub const REACQUIRE_FRAMES: usize = 30;

/// The rendered camera over one simulated world and the host pipeline reading it.
pub struct RenderedCamera {
    camera: SceneCamera,
    pipeline: Pipeline,
    period: f64,
    seq: u64,
    /// Latest tracked pose of each body (the world's coordinates) and its frame time.
    poses: HashMap<String, (Pose, f64)>,
    frames: u64,
}

impl std::fmt::Debug for RenderedCamera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RenderedCamera")
            .field("frames", &self.frames)
            .field("pipeline", &self.pipeline)
            .finish()
    }
}

impl RenderedCamera {
    /// The camera of `scene` (the simulated world's own scene), its noise from `seed`,
    /// calibrated from frames of the world as `sim` holds it now.
    pub fn new(scene: &Scene, seed: u64, sim: &SimRef<'_>) -> Result<RenderedCamera> {
        let mut camera = SceneCamera::new(scene.clone(), seed ^ 0x00CA_3E4A)
            .map_err(|e| anyhow!("setting up the rendered camera: {e}"))?;
        let period = camera.camera().period();
        let layout = MarkerLayout::from_scene(scene);
        let kind = DetectorKind::ApriltagC;
        let mut det = make_detector(kind, &layout.families())?;
        let mut seen = Vec::with_capacity(CALIBRATION_FRAMES);
        let mut size = [0, 0];
        let mut seq = 0;
        for k in 0..CALIBRATION_FRAMES {
            let frame = render(&mut camera, sim, seq, k as f64 * period)?;
            seq += 1;
            size = [frame.width, frame.height];
            seen.push(det.detect_fine(&frame)?);
        }
        let lens = scene.camera.optics();
        let calibration = Calibration::fit_through(&seen, &layout, size, lens.as_ref())
            .context("calibrating the rendered camera")?;
        let params = TrackerParams {
            // The host looks only between primitives: a body that moved since the last look
            // is a jump, not an outlier (as the live robot's tracker).
            restart_after: 1,
            ..TrackerParams::default()
        };
        let pipeline = Pipeline::new(
            make_detector(kind, &layout.families())?,
            layout,
            calibration,
            params,
        );
        Ok(RenderedCamera {
            camera,
            pipeline,
            period,
            seq,
            poses: HashMap::new(),
            frames: 0,
        })
    }

    /// Seconds between two frames.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Frames read so far (calibration not counted).
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Render the world as `sim` holds it and read the frame; true when `want` (every body
    /// when empty) was seen in it.
    pub fn look(&mut self, sim: &SimRef<'_>, want: &[&str]) -> Result<bool> {
        let time = sim.now_us() as f64 * 1e-6;
        let frame = render(&mut self.camera, sim, self.seq, time)?;
        self.seq += 1;
        let r = self.pipeline.process(&frame)?;
        self.frames += 1;
        let mut seen = Vec::new();
        for t in r.tracked.iter().filter(|t| t.seen && !t.rejected) {
            self.poses.insert(t.body.clone(), (t.pose, t.time));
            seen.push(t.body.as_str());
        }
        Ok(want.iter().all(|w| seen.contains(w)))
    }

    /// The latest tracked pose of `body` and the time of its frame.
    pub fn pose(&self, body: &str) -> Option<(Pose, f64)> {
        self.poses.get(body).copied()
    }
}

/// One frame of the world as `sim` holds it, stamped `time`.
fn render(camera: &mut SceneCamera, sim: &SimRef<'_>, seq: u64, time: f64) -> Result<Frame> {
    let robot = sim.truth().pose;
    let objects = sim.object_poses();
    let f = camera
        .capture(time, &robot, &objects)
        .map_err(|e| anyhow!("rendering a camera frame: {e}"))?;
    Ok(Frame {
        seq,
        time: f.time,
        width: f.width,
        height: f.height,
        pixels: f.pixels,
    })
}

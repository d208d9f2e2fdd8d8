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
use super::target::{SceneCamera, Window};
use crate::vision::calibration::{Calibration, calibration_markers};
use crate::vision::detect::{DetectorKind, make_detector};
use crate::vision::layout::wrap_angle;
use crate::vision::layout::{MarkerLayout, Pose};
use crate::vision::source::Frame;
use crate::vision::tracking::TrackerParams;
use crate::vision::{MotionBound, Pipeline};

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
    /// The frames' size, pixels.
    size: (u32, u32),
    /// The robot's odometry (its own frame) at the last look, and the look's time.
    odometry: Option<(f64, pushbot_protocol::Pose)>,
    /// The farthest point of the robot's edge (its bumper, its plate) from its centre, metres.
    edge_radius: f64,
    /// How far the robot's marker is from its centre, metres.
    marker_radius: f64,
}

/// Odometry's error and the tracker's margin in a motion bound, metres.
const BOUND_SLACK_M: f64 = 0.01;

/// The robot's travel by the camera over its travel by odometry, at most (wheel slip).
const ROBOT_SLIP: f64 = 1.25;

/// The robot's body in the marker layout ([`MarkerLayout::from_scene`]).
const ROBOT: &str = "robot";

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
            let frame = render(&mut camera, sim, seq, k as f64 * period, None)?;
            seq += 1;
            size = [frame.width, frame.height];
            seen.push(calibration_markers(det.as_mut(), &frame, &layout)?);
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
        // The calibration's detector reads the frames from here on (building one costs its
        // families' decode tables).
        let pipeline = Pipeline::new(det, layout, calibration, params);
        let plate = scene.robot.front_plate.iter().flat_map(|p| p.outline());
        let edge_radius = plate
            .map(|c| c[0].hypot(c[1]))
            .fold(scene.robot.bumper_radius, f64::max);
        let marker = &scene.camera.robot_marker;
        let marker_radius = marker.x.hypot(marker.y);
        Ok(RenderedCamera {
            camera,
            pipeline,
            period,
            seq,
            poses: HashMap::new(),
            frames: 0,
            size: (size[0], size[1]),
            odometry: None,
            marker_radius,
            edge_radius,
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
    ///
    /// Between whole-frame searches the sensor is read out only in the regions the tracker
    /// will search ([`Pipeline::plan`]); when they miss a body the pipeline cannot take as
    /// covered ([`Pipeline::process_regions`]), the same image is read out whole (fresh noise)
    /// and searched whole, as the pipeline does a camera's full frame.
    pub fn look(&mut self, sim: &SimRef<'_>, want: &[&str]) -> Result<bool> {
        let time = sim.now_us() as f64 * 1e-6;
        let (width, height) = self.size;
        // Nothing but the robot moves things here, and only where its edge touches them:
        // what moved since the last look moved no farther than twice that edge's travel by
        // the robot's odometry (a pushed object that turns about its contact); a turn moves
        // the edge by the turn times its farthest point from the robot's centre.
        let odometry = sim.truth().odometry;
        if let Some((since, before)) = self.odometry.replace((time, odometry)) {
            let moved = f64::from(odometry.x - before.x).hypot(f64::from(odometry.y - before.y));
            let turned = wrap_angle(f64::from(odometry.theta - before.theta)).abs();
            let metres = 2.0 * (moved + turned * self.edge_radius) + BOUND_SLACK_M;
            self.pipeline.bound_motion(MotionBound { since, metres });
            // The robot's own marker went only as far as the robot, give or take its wheels'
            // slip: a tighter region than the bound of everything it may have pushed.
            let metres = ROBOT_SLIP * (moved + turned * self.marker_radius) + BOUND_SLACK_M;
            self.pipeline
                .bound_body_motion(ROBOT, MotionBound { since, metres });
        }
        let planned = self.pipeline.plan(time, width, height);
        let within = planned.as_ref().map(|rs| {
            rs.iter()
                .map(|r| Window {
                    x0: r.x as usize,
                    y0: r.y as usize,
                    x1: (r.x + r.width) as usize,
                    y1: (r.y + r.height) as usize,
                })
                .collect::<Vec<_>>()
        });
        let frame = render(&mut self.camera, sim, self.seq, time, within.as_deref())?;
        self.seq += 1;
        let partial = match &planned {
            Some(regions) => self.pipeline.process_regions(&frame, regions)?,
            None => Some(self.pipeline.process_whole(&frame)?),
        };
        let r = match partial {
            Some(r) => r,
            None => {
                let frame = render(&mut self.camera, sim, self.seq, time, None)?;
                self.seq += 1;
                self.pipeline.process_whole(&frame)?
            }
        };
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

/// One frame of the world as `sim` holds it, stamped `time`; read out only `within` these
/// windows when given.
fn render(
    camera: &mut SceneCamera,
    sim: &SimRef<'_>,
    seq: u64,
    time: f64,
    within: Option<&[Window]>,
) -> Result<Frame> {
    let robot = sim.truth().pose;
    let objects = sim.object_poses();
    let f = match within {
        Some(w) => camera.capture_within(time, &robot, &objects, w),
        None => camera.capture(time, &robot, &objects),
    }
    .map_err(|e| anyhow!("rendering a camera frame: {e}"))?;
    Ok(Frame {
        seq,
        time: f.time,
        width: f.width,
        height: f.height,
        pixels: f.pixels,
    })
}

//! The robot on the table as the strategy and the planners see it
//! ([`RobotIo`]), over a real serial link and a real overhead camera.
//!
//! Every primitive is a firmware command sent through [`crate::robot::Robot`] and waited for to
//! its `Done`; every pose is what the camera shows *after* the primitive ended: fresh frames
//! through marker detection, the calibration homography and the Kalman tracker
//! ([`crate::vision::Pipeline`]). The host acts in steps (observe → decide → primitive → observe,
//! DESIGN.md "Time"), so it never waits on the wall clock for the robot to move, and the same
//! code runs against the simulated target at any speed.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, RwLock, RwLockReadGuard};
use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};
use nalgebra::Vector2;
use pushbot_protocol::Outcome;
use pushbot_world::Scene;

use super::grabber::FrameGrabber;
use super::occlusion;

mod look;
pub mod watch;
use crate::exec::io::{Rect, RobotIo, Workspace};
use crate::link::LinkError;
use crate::robot::{LinkOptions, Recovery, Robot, link_broke};
use crate::strategy::sample::Pose2;
use crate::vision::Pipeline;
use crate::vision::calibration::{Calibration, calibration_markers};
use crate::vision::detect::{DetectorKind, make_detector};
use crate::vision::layout::MarkerLayout;
use crate::vision::tracking::TrackerParams;
use pushbot_world::workspace::{object_bounds, outline_about};
pub use watch::{Stopper, Watch};

/// Settings of a [`LiveRobot`].
#[derive(Debug, Clone, PartialEq)]
pub struct LiveOptions {
    /// Drive speed, m/s.
    pub speed: f64,
    /// Spin rate, rad/s.
    pub spin_rate: f64,
    /// How far inside the table the object's boundary lies, m (Lau et al. §III-A).
    pub boundary_inset: f64,
    /// The object [`RobotIo::object_pose`] reports (default: the scene's first object with a
    /// marker).
    pub object: Option<String>,
    /// Marker detector.
    pub detector: DetectorKind,
    /// A saved calibration; without one, the first frames calibrate the camera from the
    /// scene's calibration markers.
    pub calibration: Option<Calibration>,
    /// Frames processed per look after a primitive.
    pub frames_per_look: usize,
    /// Longest wait for a frame, wall time.
    pub frame_timeout: Duration,
    /// Frame rate assumed for image folders.
    pub fps: f64,
    /// The robot's link watchdog, ms of robot time: the robot stops this long after the host
    /// goes quiet. Longer than the firmware's 200 ms default so a host busy with vision does
    /// not stop the robot mid-push; against a simulated target running N times faster than
    /// real time, multiply it by N (the host's threads get N times less wall time per robot
    /// second).
    pub watchdog_ms: u16,
    /// Keep a live view (camera image, detections, tracked poses) in this folder
    /// ([`super::view`]).
    pub view_dir: Option<std::path::PathBuf>,
    /// The serial link's settings (`reconnect_timeout`: how long to wait for a port that went
    /// away).
    pub link: LinkOptions,
    /// Recover from a broken link ([`Robot::recover`]) and go on from the measured pose; off
    /// (`--no-recover`), a broken link ends the task with an error.
    pub recover: bool,
    /// The camera's lens (`--intrinsics FILE`); `None`: the scene's `camera.intrinsics`, if
    /// any, else an ideal pinhole.
    pub lens: Option<pushbot_world::lens::Intrinsics>,
    /// Record every look, the robot's telemetry and events into this MCAP recording.
    pub recording: Option<crate::recording::RecordingHandle>,
    /// Frames to wait for the robot or the object to be seen again when a look did not see it
    /// (a hand over the table, a smeared marker), before the task stops with "lost".
    pub reacquire_frames: usize,
    /// Speed of the robot's moves away from a body it hides and back ([`occlusion`]), m/s:
    /// nothing is pushed on them, so faster than `speed` (within the firmware's limit).
    pub look_again_speed: f64,
}

impl Default for LiveOptions {
    fn default() -> Self {
        LiveOptions {
            speed: 0.12,
            spin_rate: 3.0,
            boundary_inset: 0.2,
            object: None,
            detector: DetectorKind::ApriltagC,
            calibration: None,
            frames_per_look: 1,
            frame_timeout: Duration::from_secs(10),
            fps: 30.0,
            watchdog_ms: 1000,
            view_dir: None,
            link: LinkOptions::default(),
            recover: true,
            lens: None,
            recording: None,
            reacquire_frames: 150,
            look_again_speed: occlusion::BACK_OFF_SPEED,
        }
    }
}

/// A robot on a serial port, seen by a camera.
pub struct LiveRobot {
    /// The link; behind a lock that only a recovery of the link takes for writing, so a
    /// [`Stopper`] reaches the robot while a primitive runs.
    robot: Arc<RwLock<Robot>>,
    grabber: Arc<FrameGrabber>,
    /// What every look saw, for a view that shows it ([`LiveRobot::watch`]).
    watch: Option<Arc<Mutex<Watch>>>,
    /// The scene, for choosing another object ([`LiveRobot::set_object`]).
    scene: Scene,
    tracker_params: TrackerParams,
    pipeline: Pipeline,
    opts: LiveOptions,
    /// The object [`RobotIo::object_pose`] reports, if the scene has one.
    object: Option<String>,
    marker: [f64; 2],
    /// The object's outline in its marker's frame.
    outline: Vec<[f64; 2]>,
    workspace: Workspace,
    /// Latest pose of each body (`robot`, object ids, `goal:<id>`) and the frame time it is for.
    poses: HashMap<String, (Pose2, f64)>,
    /// Whether `poses` were looked at since the last primitive.
    fresh: bool,
    /// Time of the first frame of the latest look: a pose older than it was not seen then.
    look_from: f64,
    /// Why the camera stopped, once it has: the next primitive fails with it.
    camera_error: Option<String>,
    /// The look-again rule's state: relooks, the body lost ([`occlusion::Sight`]).
    sight: occlusion::Sight,
    t0_us: u64,
    /// Wall instant and robot clock (s) when the robot last went idle (end of a primitive).
    idle_since: (std::time::Instant, f64),
    /// Mission time minus the robot's clock, s: the host's idle periods counted at wall-clock
    /// rate instead of the robot's (see [`RobotIo::time`] below).
    host_adjust: f64,
    frames_seen: u64,
    view: Option<super::view::LiveView>,
    /// Recoveries since the last motion that ran to its end.
    recoveries_in_a_row: usize,
    recording: Option<crate::recording::live::LiveRecording>,
}

impl std::fmt::Debug for LiveRobot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveRobot")
            .field("port", &self.robot().path())
            .field("camera", &self.grabber.describe())
            .field("object", &self.object)
            .finish()
    }
}

impl LiveRobot {
    /// Connect to the robot on `port` and the camera `camera` (as `--camera` spells it) over
    /// the table of `scene`; calibrate unless `opts` brings a calibration; look once.
    pub fn connect(port: &str, camera: &str, scene: &Scene, opts: LiveOptions) -> Result<Self> {
        for (what, v) in [
            ("speed", opts.speed),
            ("look-again speed", opts.look_again_speed),
        ] {
            if !(v.is_finite() && v > 0.0) {
                bail!("the {what} must be a positive number of m/s, not {v}");
            }
        }
        let object = match &opts.object {
            Some(id) => Some(
                scene
                    .object(id)
                    .ok_or_else(|| anyhow!("scene {} has no object {id:?}", scene.name))?,
            ),
            None => scene
                .objects
                .iter()
                .find(|o| o.marker.is_some())
                .or(scene.objects.first()),
        };
        let (marker, outline, workspace) = object_frame(scene, object, opts.boundary_inset);
        let robot = Robot::connect(port, opts.link.clone())
            .with_context(|| format!("connecting to the robot on {port}"))?;
        robot
            .configure(pushbot_protocol::ConfigUpdate {
                watchdog_ms: Some(opts.watchdog_ms),
                ..Default::default()
            })
            .context("configuring the robot's link watchdog")?;
        let t0_us = robot.telemetry().map_or(0, |t| t.time_us);
        let grabber = Arc::new(
            FrameGrabber::open(camera, opts.fps)
                .with_context(|| format!("opening the camera {camera}"))?,
        );
        let layout = MarkerLayout::from_scene(scene);
        let families = layout.families();
        let lens = opts.lens.or(scene.camera.optics());
        let calibration = match &opts.calibration {
            Some(c) if lens.is_some() && c.lens != lens => bail!(
                "the saved calibration was made {} the camera's lens: calibrate again with it",
                if c.lens.is_some() {
                    "through another lens than"
                } else {
                    "without"
                }
            ),
            Some(c) => c.clone(),
            None => calibrate(&grabber, &layout, opts.detector, opts.frame_timeout, lens)?,
        };
        let detector = make_detector(opts.detector, &families)?;
        let params = TrackerParams {
            // The host looks only between primitives: a body that moved since the last look
            // is a jump, not an outlier — restart its filter at once.
            restart_after: 1,
            ..TrackerParams::default()
        };
        let recording = opts.recording.as_ref().map(|h| {
            let info = crate::recording::writer::SessionInfo {
                label: &scene.name,
                scene: Some(scene),
                layout: &layout,
                calibration: &calibration,
                tracker: params,
                detector: opts.detector,
                whole_frames: false,
            };
            crate::recording::live::LiveRecording::start(h, &robot, &info)
        });
        let pipeline = Pipeline::new(detector, layout, calibration, params);
        let view = match &opts.view_dir {
            Some(d) => Some(super::view::LiveView::create(d)?),
            None => None,
        };
        let mut live = LiveRobot {
            robot: Arc::new(RwLock::new(robot)),
            grabber,
            watch: None,
            scene: scene.clone(),
            tracker_params: params,
            pipeline,
            object: object.map(|o| o.id.clone()),
            marker,
            outline,
            workspace,
            poses: HashMap::new(),
            fresh: false,
            look_from: f64::NEG_INFINITY,
            camera_error: None,
            sight: occlusion::Sight::new(
                scene.robot.front_plate.is_none(),
                [scene.camera.robot_marker.x, scene.camera.robot_marker.y],
            ),
            t0_us,
            idle_since: (std::time::Instant::now(), 0.0),
            host_adjust: 0.0,
            frames_seen: 0,
            view,
            recoveries_in_a_row: 0,
            recording,
            opts,
        };
        live.look()?;
        live.wait_for("robot")?;
        if !live.poses.contains_key("robot") {
            bail!(
                "the camera does not see the robot's marker (tag {}) in {} frames",
                scene.camera.robot_marker.id,
                live.opts.reacquire_frames + 1
            );
        }
        Ok(live)
    }

    /// The link to the robot.
    pub fn link(&self) -> RwLockReadGuard<'_, Robot> {
        self.robot()
    }

    fn robot(&self) -> RwLockReadGuard<'_, Robot> {
        self.robot
            .read()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// A handle that stops the robot from another thread, at once, while a primitive runs.
    pub fn stopper(&self) -> Stopper {
        Stopper::new(Arc::clone(&self.robot))
    }

    /// The camera, shared: a view may read its newest frames while tasks run.
    pub fn grabber(&self) -> Arc<FrameGrabber> {
        Arc::clone(&self.grabber)
    }

    /// What every look sees from now on (the camera frame's detections drawn over it, the
    /// tracked poses), kept in the returned cell.
    pub fn watch(&mut self) -> Arc<Mutex<Watch>> {
        Arc::clone(self.watch.get_or_insert_with(Arc::default))
    }

    /// Report `id`'s pose as [`RobotIo::object_pose`] from now on (the object a task pushes).
    pub fn set_object(&mut self, id: &str) -> Result<()> {
        let object = self
            .scene
            .object(id)
            .ok_or_else(|| anyhow!("scene {} has no object {id:?}", self.scene.name))?;
        let (marker, outline, workspace) =
            object_frame(&self.scene, Some(object), self.opts.boundary_inset);
        (self.marker, self.outline, self.workspace) = (marker, outline, workspace);
        self.object = Some(id.to_owned());
        self.fresh = false;
        Ok(())
    }

    /// The recording every look goes into, if any.
    pub fn recording_handle(&self) -> Option<crate::recording::RecordingHandle> {
        self.opts.recording.clone()
    }

    /// The scene this robot's table is.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Start recording into `recording` (a new session in it), or stop with `None`.
    pub fn record_into(&mut self, recording: Option<crate::recording::RecordingHandle>) {
        self.opts.recording = recording.clone();
        self.recording = recording.map(|h| {
            let info = crate::recording::writer::SessionInfo {
                label: &self.scene.name,
                scene: Some(&self.scene),
                layout: self.pipeline.layout(),
                calibration: self.pipeline.calibration(),
                tracker: self.tracker_params,
                detector: self.opts.detector,
                whole_frames: false,
            };
            crate::recording::live::LiveRecording::start(&h, &self.robot(), &info)
        });
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &Calibration {
        self.pipeline.calibration()
    }

    /// The live view, if one is kept: set its `plan` to draw a path.
    pub fn view_mut(&mut self) -> Option<&mut super::view::LiveView> {
        self.view.as_mut()
    }

    /// Every recovery of the link so far, in order.
    pub fn recoveries(&self) -> Vec<Recovery> {
        self.robot().recoveries()
    }

    /// Frames processed so far.
    pub fn frames_seen(&self) -> u64 {
        self.frames_seen
    }

    /// Times a body the camera did not see was seen again after the robot backed away.
    pub fn relooks(&self) -> usize {
        self.sight.relooks
    }

    /// The latest pose of a tracked body (`robot`, an object id or `goal:<object id>`), with
    /// the time of the frame it is from; looks first if a primitive ran since the last look.
    pub fn tracked(&mut self, body: &str) -> Option<(Pose2, f64)> {
        self.look_if_stale();
        self.poses.get(body).copied()
    }

    /// The robot's clock since connecting, s (from its latest telemetry).
    pub fn robot_clock(&self) -> f64 {
        self.robot()
            .telemetry()
            .map_or(0.0, |t| t.time_us.saturating_sub(self.t0_us) as f64 * 1e-6)
    }

    /// Run one motion to its end; a fault it ended in (a stall against something that does not
    /// move) is cleared and the motion counts as ended, as the strategy expects. A broken link
    /// is recovered ([`Robot::recover`]) and the motion counts as ended too: the executor looks
    /// again and goes on from where the robot really is.
    fn motion(&mut self, what: Motion, run: impl Fn(&Robot) -> Result<Outcome>) -> Result<()> {
        if let Some(l) = &self.sight.lost {
            return Err(l.clone().into());
        }
        if let Some(e) = &self.camera_error {
            bail!("the camera stopped: {e}");
        }
        self.fresh = false;
        self.sight.since.motion(what == Motion::Spin);
        let (wall, t0) = (std::time::Instant::now(), self.robot_clock());
        let (idle_wall, idle_robot) = self.idle_since;
        self.host_adjust += idle_wall.elapsed().as_secs_f64() - (t0 - idle_robot);
        let out = self.run_motion(what, run);
        let t1 = self.robot_clock();
        self.idle_since = (std::time::Instant::now(), t1);
        tracing::debug!(
            "{what}: {:.0} ms wall, {:.2} s robot time",
            wall.elapsed().as_secs_f64() * 1e3,
            t1 - t0
        );
        out
    }

    fn run_motion(&mut self, what: Motion, run: impl Fn(&Robot) -> Result<Outcome>) -> Result<()> {
        // A refused command never started: clear the faults and send it again, a few times (a
        // loaded host can let the link watchdog fire again between the clear and the retry).
        const ATTEMPTS: usize = 4;
        for attempt in 0..ATTEMPTS {
            let outcome = run(&self.robot());
            match outcome {
                Ok(Outcome::Fault(f)) if f.contains(pushbot_protocol::Faults::EMERGENCY_STOP) => {
                    bail!(
                        "{what} on {}: the robot was emergency-stopped",
                        self.robot().path()
                    );
                }
                Ok(Outcome::Fault(f)) if f.contains(pushbot_protocol::Faults::LINK_LOST) => {
                    let cause = format!(
                        "{what} on {} was cut short: the robot's link watchdog fired ({})",
                        self.robot().path(),
                        crate::link::FaultNames(f)
                    );
                    return self.recover_link(what, cause);
                }
                Ok(Outcome::Fault(f)) => {
                    tracing::debug!("{what} ended in fault {}", crate::link::FaultNames(f));
                    self.clear_faults()?;
                    self.recoveries_in_a_row = 0;
                    return Ok(());
                }
                Ok(_) => {
                    self.recoveries_in_a_row = 0;
                    return Ok(());
                }
                Err(e) if attempt + 1 < ATTEMPTS && faulted_refusal(&e) == Some(LINK_ONLY) => {
                    // The link broke while the robot stood (its watchdog fired between two
                    // primitives): recover, then send the refused motion again — it never ran.
                    let cause = format!("{what} on {}: {e:#}", self.robot().path());
                    self.recover_link(what, cause)?;
                }
                Err(e) if attempt + 1 < ATTEMPTS && faulted_refusal(&e).is_some() => {
                    tracing::debug!("{what} refused ({e:#}); clearing the faults and retrying");
                    self.clear_faults()?;
                }
                Err(e) if e.downcast_ref::<LinkError>().is_some_and(link_broke) => {
                    let cause = format!("{what} on {}: {e:#}", self.robot().path());
                    return self.recover_link(what, cause);
                }
                Err(e) => return Err(e.context(format!("{what} on {}", self.robot().path()))),
            }
        }
        bail!("the robot stayed faulted")
    }

    /// The link broke during `what`: recover it, or say why not.
    fn recover_link(&mut self, what: Motion, cause: String) -> Result<()> {
        /// Recoveries in a row (no motion ending in between) before giving up.
        const MOST_IN_A_ROW: usize = 5;
        if !self.opts.recover {
            bail!("{cause} (recovery is off: --no-recover)");
        }
        if self.recoveries_in_a_row >= MOST_IN_A_ROW {
            bail!("{cause}; the link broke {MOST_IN_A_ROW} times in a row: giving up");
        }
        self.recoveries_in_a_row += 1;
        let seq = self.robot().last_seq();
        self.robot
            .write()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .recover(&cause, Some((seq, what.command())))
            .with_context(|| format!("recovering the link after: {cause}"))?;
        // A robot that restarted counts its odometry from zero again.
        self.pipeline.forget_odometry("robot");
        Ok(())
    }

    fn clear_faults(&mut self) -> Result<()> {
        // A fault clears only once its cause has been quiet for a while (robot time).
        for _ in 0..50 {
            let robot = self.robot();
            if robot.clear_faults()?.is_empty() {
                return Ok(());
            }
            let after = robot.telemetry().map(|t| t.time_us + 100_000);
            let _ = robot.wait_telemetry(after);
        }
        bail!("the robot's faults would not clear")
    }
}

/// Where the object's marker is in its body frame, its outline about the marker, and the
/// workspace it is pushed in (the table inset by `inset`).
fn object_frame(
    scene: &Scene,
    object: Option<&pushbot_world::scene::Object>,
    inset: f64,
) -> ([f64; 2], Vec<[f64; 2]>, Workspace) {
    let marker = object
        .and_then(|o| o.marker)
        .map_or([0.0, 0.0], |m| [m.x, m.y]);
    let outline = object.map_or(&[][..], |o| &o.outline);
    let (object_radius, body) = object_bounds(outline, marker);
    let outline = outline_about(outline, marker);
    let table = Rect {
        min: [0.0, 0.0],
        max: [scene.table.width, scene.table.height],
    };
    let workspace = Workspace {
        table,
        boundary: table.inset(inset),
        robot_radius: scene.robot.bumper_radius,
        object_radius,
        body,
    };
    (marker, outline, workspace)
}

/// Only the link's own fault.
const LINK_ONLY: pushbot_protocol::Faults = pushbot_protocol::Faults::LINK_LOST;

/// The faults a refusal names, when `e` is a refusal for latched faults.
fn faulted_refusal(e: &anyhow::Error) -> Option<pushbot_protocol::Faults> {
    match e.downcast_ref::<LinkError>() {
        Some(LinkError::Refused {
            reason: crate::link::Refusal(pushbot_protocol::NackReason::Faulted(f)),
            ..
        }) => Some(*f),
        _ => None,
    }
}

/// Fit the camera's calibration from a few frames of the scene's calibration markers (their
/// corners undistorted first when the camera has a `lens`, which must fit the frames).
fn calibrate(
    grabber: &FrameGrabber,
    layout: &MarkerLayout,
    kind: DetectorKind,
    timeout: Duration,
    lens: Option<pushbot_world::lens::Intrinsics>,
) -> Result<Calibration> {
    let mut det = make_detector(kind, &layout.families())?;
    let mut frames = Vec::new();
    let mut size = [0, 0];
    let mut after = grabber.count();
    for _ in 0..3 {
        let (n, frame) = grabber.next_after(after, timeout)?;
        after = n;
        size = [frame.width, frame.height];
        frames.push(calibration_markers(det.as_mut(), &frame, layout)?);
    }
    Calibration::fit_through(&frames, layout, size, lens.as_ref()).context("calibrating the camera")
}

/// The kinds of motion the live robot is sent: a spin on the spot, a straight move, a velocity
/// command for a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Motion {
    Spin,
    Move,
    Velocity,
}

impl Motion {
    /// The protocol command's name, as [`Robot::recover`] reports it.
    fn command(self) -> &'static str {
        match self {
            Motion::Spin => "Spin",
            Motion::Move => "Move",
            Motion::Velocity => "Velocity",
        }
    }
}

impl std::fmt::Display for Motion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Motion::Spin => "spin",
            Motion::Move => "move",
            Motion::Velocity => "velocity",
        })
    }
}

impl RobotIo for LiveRobot {
    fn spin(&mut self, angle: f64) -> Result<()> {
        let angle = crate::strategy::sample::wrap_angle(angle);
        if !angle.is_finite() || angle.abs() < 1e-3 {
            return Ok(());
        }
        let rate = self.opts.spin_rate as f32;
        self.motion(Motion::Spin, |r| Ok(r.spin(angle as f32, rate)?.outcome))
    }

    fn forward(&mut self, distance: f64) -> Result<()> {
        if !distance.is_finite() || distance.abs() < 5e-4 {
            return Ok(());
        }
        let speed = self.opts.speed as f32;
        let d = distance.clamp(-2.0, 2.0) as f32;
        self.motion(Motion::Move, |r| {
            Ok(r.move_distance(d, speed, false)?.outcome)
        })
    }

    fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()> {
        let ms = (duration * 1e3).clamp(1.0, 60_000.0) as u64;
        let (v, omega) = (v.clamp(-0.3, 0.3) as f32, omega.clamp(-4.0, 4.0) as f32);
        self.motion(Motion::Velocity, |r| {
            let m = r.velocity(v, omega, Duration::from_millis(ms))?;
            Ok(r.wait(&m)?.outcome)
        })
    }

    fn robot_pose(&mut self) -> Pose2 {
        self.pose_of("robot")
    }

    fn object_pose(&mut self) -> Pose2 {
        let Some(id) = self.object.clone() else {
            return Pose2::new(f64::NAN, f64::NAN, f64::NAN);
        };
        let body = self.pose_of(&id);
        let m = body.point_to_world(Vector2::new(self.marker[0], self.marker[1]));
        Pose2::new(m.x, m.y, body.theta)
    }

    fn body_pose(&mut self, id: &str) -> Option<Pose2> {
        self.look_if_stale();
        self.poses.get(id).map(|(p, _)| *p)
    }

    /// Mission time: the robot's clock while it runs primitives, wall-clock time while it waits
    /// for the host (looking, planning). On hardware the two clocks run together and this is
    /// the robot's clock; on a simulated target running N× faster than real time, the host's
    /// work would otherwise count N times over and a delivery would run out of time because the
    /// simulation is fast, not because the robot was slow.
    fn time(&self) -> f64 {
        let (idle_wall, idle_robot) = self.idle_since;
        idle_robot + self.host_adjust + idle_wall.elapsed().as_secs_f64()
    }

    fn workspace(&self) -> Workspace {
        self.workspace
    }

    fn object_outline(&self) -> Vec<[f64; 2]> {
        self.outline.clone()
    }

    fn show_path(&mut self, path: &[[f64; 2]]) {
        if let Some(v) = self.view.as_mut() {
            v.plan = path.to_vec();
        }
    }
}

//! The in-process robot of the strategy code: a [`Robot`] over the [`InProcess`] driver, so
//! the simulated firmware is spoken to through the one link client, byte for byte as over a
//! serial port, stepping simulated time until each primitive's `Done`; its "camera" reads the
//! simulator's true poses with optional seeded noise (about 1 mm and 0.5°).

use std::time::Duration;

use anyhow::{Context, Result, anyhow, bail};
use nalgebra::Vector2;
use pushbot_protocol::{Command, ConfigUpdate, NackReason, Outcome};
use pushbot_world::Scene;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::camera::{REACQUIRE_FRAMES, RenderedCamera};
use super::inprocess::{InProcess, SimRef};
use crate::exec::io::{Rect, RobotIo, Workspace};
use crate::exec::occlusion::{self, BodyLost, Looking};
use crate::link::{LinkError, Refusal};
use crate::robot::{LinkOptions, Robot};
use crate::strategy::sample::{Pose2, wrap_angle};
use pushbot_world::workspace::{object_bounds, outline_about};

/// Settings of the in-process robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimRobotOptions {
    /// Seed of the simulation and the camera noise.
    pub seed: u64,
    /// Camera position noise (standard deviation), m; 0 for exact poses.
    pub position_noise: f64,
    /// Camera heading noise (standard deviation), rad.
    pub heading_noise: f64,
    /// Drive speed, m/s.
    pub speed: f64,
    /// Spin rate, rad/s.
    pub spin_rate: f64,
    /// How far inside the scene's table the object's boundary lies, m. The default, 0.1 m,
    /// leaves every start position of the Lau presets at least 9 cm inside the boundary (at
    /// 0.2 m the L-shape's marker at start E lay outside it before the first push).
    pub boundary_inset: f64,
    /// Extra table the simulated world gets beyond the scene's table on every side, m, so the
    /// robot can get behind an object that left the boundary (the paper's table was larger
    /// than its boundary). With the default 0.25 m, an object that overshoots the boundary by
    /// a push still leaves the robot room to get behind it; with less, a thin object (the
    /// snake) pushed against the wall could not be pushed back. Observations stay in the
    /// scene's coordinates.
    pub table_margin: f64,
    /// What the robot sees the table with: the simulator's truth with the noise above, or the
    /// rendered camera read by the host's vision pipeline ([`super::camera`]).
    pub camera: SimCamera,
}

/// The in-process robot's camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SimCamera {
    /// The simulator's true poses with seeded Gaussian noise (`position_noise`,
    /// `heading_noise`): fast, for long evaluations.
    #[default]
    Truth,
    /// Frames rendered from the simulated world (lens, marker heights, blur, noise) and read by
    /// the host's detector, calibration and tracker: the camera in the loop.
    Rendered,
}

impl Default for SimRobotOptions {
    fn default() -> Self {
        SimRobotOptions {
            seed: 1,
            position_noise: 0.001,
            heading_noise: 0.5f64.to_radians(),
            speed: 0.12,
            spin_rate: 3.0,
            boundary_inset: 0.1,
            table_margin: 0.25,
            camera: SimCamera::Truth,
        }
    }
}

/// The simulated robot, in process, spoken to through the firmware protocol.
pub struct SimRobot {
    robot: Robot<InProcess>,
    opts: SimRobotOptions,
    rng: ChaCha8Rng,
    object: usize,
    /// The object's id (what the camera calls it).
    object_id: String,
    marker: [f64; 2],
    /// The object's outline in its marker's frame.
    outline: Vec<[f64; 2]>,
    workspace: Workspace,
    margin: f64,
    /// The rendered camera, with [`SimCamera::Rendered`].
    camera: Option<RenderedCamera>,
    /// Whether the rendered camera looked since the last motion.
    fresh: bool,
    /// Simulated time of the latest look.
    look_from: f64,
    /// Why the camera stopped: the next motion fails with it, as on the live robot.
    camera_error: Option<String>,
    /// The look-again rule's state: relooks, the body lost ([`occlusion::Sight`]).
    sight: occlusion::Sight,
}

/// What a body never seen measures.
const NAN_POSE: Pose2 = Pose2 {
    x: f64::NAN,
    y: f64::NAN,
    theta: f64::NAN,
};

/// Longest the simulated robot may stay silent (a primitive that never ends: telemetry is off),
/// s of simulated time.
const PRIMITIVE_LIMIT_S: u64 = 60;
/// The robot's link watchdog in process, ms of simulated time.
const WATCHDOG_MS: u16 = 5000;

impl SimRobot {
    /// A simulated robot in `scene`, pushing object `object_id` (the first object when `None`),
    /// which is placed at the scene's named position `start` when given.
    pub fn new(
        scene: Scene,
        object_id: Option<&str>,
        start: Option<&str>,
        opts: SimRobotOptions,
    ) -> Result<SimRobot> {
        SimRobot::perturbed(scene, object_id, start, opts, None)
    }

    /// As [`SimRobot::new`], in the perturbed world `perturb`
    /// (`sim-target/src/perturb.rs`): the simulated world runs its start error, frictions, centre of
    /// friction and wheel slip; the camera noise stays `opts`'s.
    pub fn perturbed(
        mut scene: Scene,
        object_id: Option<&str>,
        start: Option<&str>,
        opts: SimRobotOptions,
        perturb: Option<crate::sim::target::Perturbation>,
    ) -> Result<SimRobot> {
        let object = match object_id {
            Some(id) => scene
                .objects
                .iter()
                .position(|o| o.id == id)
                .ok_or_else(|| anyhow!("scene {} has no object {id:?}", scene.name))?,
            None if scene.objects.is_empty() => bail!("scene {} has no object", scene.name),
            None => 0,
        };
        if let Some(name) = start {
            let pose = scene
                .position(name)
                .ok_or_else(|| anyhow!("scene {} has no start position {name:?}", scene.name))?;
            scene.objects[object].pose = pose;
        }
        let obj = &scene.objects[object];
        let object_id = obj.id.clone();
        // A round robot (no front plate) presses on nothing as it turns on the spot.
        let scene_round = scene.robot.front_plate.is_none();
        let robot_marker = [scene.camera.robot_marker.x, scene.camera.robot_marker.y];
        let marker = obj.marker.map_or([0.0, 0.0], |m| [m.x, m.y]);
        let (object_radius, body) = object_bounds(&obj.outline, marker);
        let outline = outline_about(&obj.outline, marker);
        let scene_table = Rect {
            min: [0.0, 0.0],
            max: [scene.table.width, scene.table.height],
        };
        let m = opts.table_margin;
        if !(m.is_finite() && (0.0..=1.0).contains(&m)) {
            bail!("table margin must be 0..=1 m, not {m}");
        }
        let table = Rect {
            min: [-m, -m],
            max: [scene_table.max[0] + m, scene_table.max[1] + m],
        };
        let workspace = Workspace {
            table,
            boundary: scene_table.inset(opts.boundary_inset),
            robot_radius: scene.robot.bumper_radius,
            object_radius,
            body,
        };
        if workspace.boundary.min[0] >= workspace.boundary.max[0]
            || workspace.boundary.min[1] >= workspace.boundary.max[1]
        {
            bail!(
                "boundary inset {} m leaves nothing of the table",
                opts.boundary_inset
            );
        }
        shift_scene(&mut scene, m);
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        rng.set_stream(7);
        let link = LinkOptions {
            dead_link_timeout: Duration::from_secs(PRIMITIVE_LIMIT_S),
            ..LinkOptions::default()
        };
        let camera_scene = (opts.camera == SimCamera::Rendered).then(|| scene.clone());
        let driver = InProcess::start_perturbed(scene, opts.seed, perturb, link.client_options(1))?;
        let robot = Robot::over(driver, link)
            .map_err(|e| anyhow!("the simulated robot refused the session: {e}"))?;
        let cfg = ConfigUpdate {
            watchdog_ms: Some(WATCHDOG_MS),
            telemetry_hz: Some(0),
            ..ConfigUpdate::default()
        };
        robot
            .configure(cfg)
            .map_err(|e| anyhow!("the simulated robot refused the configuration: {e}"))?;
        let camera = match camera_scene {
            Some(scene) => Some(RenderedCamera::new(
                &scene,
                opts.seed,
                &robot.driver().sim(),
            )?),
            None => None,
        };
        Ok(SimRobot {
            robot,
            opts,
            rng,
            object,
            object_id,
            marker,
            outline,
            workspace,
            margin: m,
            camera,
            fresh: false,
            look_from: f64::NEG_INFINITY,
            camera_error: None,
            sight: occlusion::Sight::new(scene_round, robot_marker),
        })
    }

    /// The simulator (for true poses, figures and tests).
    pub fn sim(&self) -> SimRef<'_> {
        self.robot.driver().sim()
    }

    /// The robot interface the primitives go through.
    pub fn robot(&self) -> &Robot<InProcess> {
        &self.robot
    }

    /// The object's true marker pose (no camera noise).
    pub fn true_object_pose(&self) -> Pose2 {
        let poses = self.sim().object_poses();
        let p = poses
            .get(self.object)
            .map_or(Pose2::new(f64::NAN, f64::NAN, f64::NAN), |(_, p)| *p);
        let o = Pose2::new(p.x - self.margin, p.y - self.margin, p.theta);
        let m = o.point_to_world(Vector2::new(self.marker[0], self.marker[1]));
        Pose2::new(m.x, m.y, p.theta)
    }

    /// The robot's true pose.
    pub fn true_robot_pose(&self) -> Pose2 {
        let p = self.sim().truth().pose;
        Pose2::new(p.x - self.margin, p.y - self.margin, p.theta)
    }

    /// Run one motion command to its `Done`; a latched fault (a stall against something that
    /// does not move) is cleared and the motion counts as ended.
    fn motion(&mut self, cmd: Command) -> Result<()> {
        if let Some(l) = &self.sight.lost {
            return Err(l.clone().into());
        }
        if let Some(e) = &self.camera_error {
            bail!("{e}");
        }
        self.fresh = false;
        self.sight.since.motion(matches!(cmd, Command::Spin { .. }));
        for attempt in 0..2 {
            let started = match self.robot.start(cmd) {
                Ok(m) => m,
                Err(LinkError::Refused {
                    reason: Refusal(NackReason::Faulted(_)),
                    ..
                }) if attempt == 0 => {
                    self.clear_faults()?;
                    continue;
                }
                Err(e) => bail!("the robot refused {cmd:?}: {e}"),
            };
            let done = self
                .robot
                .wait(&started)
                .map_err(|e| anyhow!("{cmd:?} did not end: {e}"))?;
            if let Outcome::Fault(_) = done.outcome {
                self.clear_faults()?;
            }
            return Ok(());
        }
        bail!("the robot stayed faulted")
    }

    fn clear_faults(&mut self) -> Result<()> {
        // Faults clear only once their cause has been quiet for a while.
        for _ in 0..20 {
            self.robot.driver().run_for(0.1);
            match self.robot.request(Command::ClearFaults) {
                Ok(_) | Err(LinkError::Refused { .. }) => {}
                Err(e) => return Err(e).context("clearing faults"),
            }
            if self.sim().truth().faults.is_empty() {
                return Ok(());
            }
        }
        bail!("faults {:?} would not clear", self.sim().truth().faults)
    }

    /// What the rendered camera makes of `body` now (the scene's coordinates). The first
    /// query after a motion looks once, and makes sure of the robot and the object: one not in
    /// the look is waited for, one more frame at a time up to [`REACQUIRE_FRAMES`] (the robot
    /// stands still meanwhile; not when the robot may hide it itself); still unseen, the robot
    /// moves away from it, looks and comes back ([`occlusion`]); still unseen, it is lost
    /// ([`BodyLost`]) and the next motion fails. Every pose reported is from after any such
    /// move. `None` without the rendered camera or for a body never seen.
    fn seen(&mut self, body: &str) -> Option<Pose2> {
        self.camera.as_ref()?;
        if !self.fresh && self.camera_error.is_none() && self.sight.lost.is_none() {
            self.look_all();
            self.make_sure_of("robot");
            let object = self.object_id.clone();
            self.make_sure_of(&object);
        }
        if self.stale(body) {
            // Another body (a goal, another object), asked for by name.
            self.make_sure_of(body);
        }
        let (p, _) = self.camera.as_ref()?.pose(body)?;
        Some(Pose2::new(p.x - self.margin, p.y - self.margin, p.theta))
    }

    /// One look at every body, now.
    fn look_all(&mut self) {
        if let Err(e) = Looker(self).look() {
            self.camera_error = Some(format!("{e:#}"));
        }
        self.fresh = true;
    }

    /// Whether the camera has not seen `body` since the latest look began.
    fn stale(&self, body: &str) -> bool {
        self.camera
            .as_ref()
            .is_none_or(|c| c.pose(body).is_none_or(|(_, t)| t < self.look_from))
    }

    /// Wait for `body`; unseen, back away, look again and come back ([`occlusion`]); still
    /// unseen, it is lost.
    fn make_sure_of(&mut self, body: &str) {
        if self.sight.lost.is_some() || self.camera_error.is_some() || self.camera.is_none() {
            return;
        }
        match occlusion::make_sure_of(&mut Looker(self), body) {
            Ok(sure) => self.sight.record(sure),
            Err(e) => self.camera_error = Some(format!("looking for {body}: {e:#}")),
        }
    }

    /// The body the rendered camera lost, if it has.
    pub fn lost(&self) -> Option<&BodyLost> {
        self.sight.lost.as_ref()
    }

    /// Times a body the camera did not see was seen again after the robot backed away.
    pub fn relooks(&self) -> usize {
        self.sight.relooks
    }

    /// Frames the rendered camera has read (0 without it).
    pub fn camera_frames(&self) -> u64 {
        self.camera.as_ref().map_or(0, RenderedCamera::frames)
    }

    fn noisy(&mut self, p: Pose2) -> Pose2 {
        if self.opts.position_noise <= 0.0 && self.opts.heading_noise <= 0.0 {
            return p;
        }
        let (a, b, c): (f64, f64, f64) = (
            StandardNormal.sample(&mut self.rng),
            StandardNormal.sample(&mut self.rng),
            StandardNormal.sample(&mut self.rng),
        );
        Pose2::new(
            p.x + self.opts.position_noise * a,
            p.y + self.opts.position_noise * b,
            wrap_angle(p.theta + self.opts.heading_noise * c),
        )
    }
}

/// The simulated robot as [`occlusion`] sees it: looks with the rendered camera, waits in
/// simulated time, and moves at [`occlusion::BACK_OFF_SPEED`].
struct Looker<'a>(&'a mut SimRobot);

impl occlusion::Looking for Looker<'_> {
    fn last_seen(&self, body: &str) -> Option<Pose2> {
        let (p, _) = self.0.camera.as_ref()?.pose(body)?;
        Some(Pose2::new(p.x, p.y, p.theta))
    }

    fn seen_since_look(&self, body: &str) -> bool {
        !self.0.stale(body)
    }

    fn look(&mut self) -> Result<f64> {
        let driver = self.0.robot.driver();
        let cam = self.0.camera.as_mut().context("no rendered camera")?;
        let t = driver.sim().now_us() as f64 * 1e-6;
        cam.look(&driver.sim(), &[]).context("camera")?;
        self.0.look_from = t;
        self.0.fresh = true;
        Ok(t)
    }

    fn look_from(&mut self, t: f64) {
        self.0.look_from = t;
    }

    /// Frame by frame up to [`REACQUIRE_FRAMES`], the simulation running between them.
    fn wait_for(&mut self, body: &str, frames: Option<usize>) -> Result<bool> {
        if !self.0.stale(body) {
            return Ok(true);
        }
        let driver = self.0.robot.driver();
        let cam = self.0.camera.as_mut().context("no rendered camera")?;
        for _ in 0..frames.unwrap_or(REACQUIRE_FRAMES) {
            driver.run_for(cam.period());
            if cam.look(&driver.sim(), &[body]).context("camera")? {
                return Ok(true);
            }
        }
        Ok(false)
    }

    fn sight(&mut self) -> &mut occlusion::Sight {
        &mut self.0.sight
    }

    fn straight(&mut self, d: f64) -> Result<()> {
        self.0.motion(Command::Move {
            distance: d as f32,
            speed: occlusion::BACK_OFF_SPEED as f32,
            stop_on_contact: false,
        })
    }
}

/// Grow the scene's table by `m` on every side, moving everything on it along.
fn shift_scene(scene: &mut Scene, m: f64) {
    scene.table.width += 2.0 * m;
    scene.table.height += 2.0 * m;
    let mv = |p: &mut Pose2| {
        p.x += m;
        p.y += m;
    };
    mv(&mut scene.robot.start);
    scene.objects.iter_mut().for_each(|o| mv(&mut o.pose));
    scene.goals.iter_mut().for_each(|g| mv(&mut g.pose));
    scene.positions.iter_mut().for_each(|p| mv(&mut p.pose));
    for o in &mut scene.obstacles {
        for v in &mut o.outline {
            v[0] += m;
            v[1] += m;
        }
    }
    // What the camera sees at fixed places on the table moves along too (the default
    // calibration markers follow the grown table's corners by themselves).
    let camera = &mut scene.camera;
    for f in camera.fiducials.iter_mut().flatten() {
        f.x += m;
        f.y += m;
    }
    for o in &mut camera.occluders {
        for v in &mut o.outline {
            v[0] += m;
            v[1] += m;
        }
    }
    if let Some(p) = &mut camera.pose {
        for v in [&mut p.eye, &mut p.look_at] {
            v[0] += m;
            v[1] += m;
        }
    }
}

impl RobotIo for SimRobot {
    fn spin(&mut self, angle: f64) -> Result<()> {
        let angle = wrap_angle(angle);
        if !angle.is_finite() || angle.abs() < 1e-3 {
            return Ok(());
        }
        self.motion(Command::Spin {
            angle: angle as f32,
            rate: self.opts.spin_rate as f32,
        })
    }

    fn forward(&mut self, distance: f64) -> Result<()> {
        if !distance.is_finite() || distance.abs() < 5e-4 {
            return Ok(());
        }
        self.motion(Command::Move {
            distance: distance.clamp(-2.0, 2.0) as f32,
            speed: self.opts.speed as f32,
            stop_on_contact: false,
        })
    }

    fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()> {
        let ms = (duration * 1e3).clamp(1.0, 60_000.0) as u16;
        self.motion(Command::Velocity {
            v: v.clamp(-0.3, 0.3) as f32,
            omega: omega.clamp(-4.0, 4.0) as f32,
            timeout_ms: ms,
        })
    }

    fn robot_pose(&mut self) -> Pose2 {
        if self.camera.is_some() {
            return self.seen("robot").unwrap_or(NAN_POSE);
        }
        let p = self.true_robot_pose();
        self.noisy(p)
    }

    fn object_pose(&mut self) -> Pose2 {
        if self.camera.is_some() {
            let id = self.object_id.clone();
            let Some(body) = self.seen(&id) else {
                return NAN_POSE;
            };
            let m = body.point_to_world(Vector2::new(self.marker[0], self.marker[1]));
            return Pose2::new(m.x, m.y, body.theta);
        }
        let p = self.true_object_pose();
        self.noisy(p)
    }

    fn body_pose(&mut self, id: &str) -> Option<Pose2> {
        if self.camera.is_some() {
            return self.seen(id);
        }
        let (_, p) = self
            .sim()
            .object_poses()
            .into_iter()
            .find(|(o, _)| o == id)?;
        let p = Pose2::new(p.x - self.margin, p.y - self.margin, p.theta);
        Some(self.noisy(p))
    }

    fn time(&self) -> f64 {
        self.sim().now_us() as f64 * 1e-6
    }

    fn workspace(&self) -> Workspace {
        self.workspace
    }

    fn object_outline(&self) -> Vec<[f64; 2]> {
        self.outline.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitives_move_the_simulated_robot_through_the_protocol() {
        let scene = Scene::preset("lau-irregular").unwrap();
        let mut r = SimRobot::new(
            scene,
            None,
            Some("C"),
            SimRobotOptions {
                position_noise: 0.0,
                heading_noise: 0.0,
                ..SimRobotOptions::default()
            },
        )
        .unwrap();
        let a = r.robot_pose();
        r.spin(std::f64::consts::FRAC_PI_2).unwrap();
        r.forward(0.1).unwrap();
        let b = r.robot_pose();
        assert!((wrap_angle(b.theta - a.theta) - std::f64::consts::FRAC_PI_2).abs() < 0.05);
        assert!(
            (b.y - a.y - 0.1).abs() < 0.01 && (b.x - a.x).abs() < 0.01,
            "{a:?} {b:?}"
        );
        // Object C is at (0.45, 0.25), marker at the origin of the outline.
        let o = r.object_pose();
        assert!((o.x - 0.45).abs() < 1e-9 && (o.y - 0.25).abs() < 1e-9);
        assert!(r.time() > 1.0);
    }

    #[test]
    fn the_rendered_camera_sees_what_the_simulator_holds() {
        let scene = Scene::preset("lau-irregular").unwrap();
        let opts = SimRobotOptions {
            camera: SimCamera::Rendered,
            ..SimRobotOptions::default()
        };
        let mut r = SimRobot::new(scene, None, Some("C"), opts).unwrap();
        for step in 0..3 {
            let (seen, truth) = (r.robot_pose(), r.true_robot_pose());
            let err = (seen.x - truth.x).hypot(seen.y - truth.y);
            assert!(
                err < 0.005,
                "step {step}: robot seen {seen:?}, truly {truth:?}"
            );
            assert!(wrap_angle(seen.theta - truth.theta).abs() < 2f64.to_radians());
            let (seen, truth) = (r.object_pose(), r.true_object_pose());
            let err = (seen.x - truth.x).hypot(seen.y - truth.y);
            assert!(
                err < 0.005,
                "step {step}: object seen {seen:?}, truly {truth:?}"
            );
            // The same stop is one look: asking again reads no new frame.
            let frames = r.camera_frames();
            r.robot_pose();
            assert_eq!(r.camera_frames(), frames);
            r.spin(0.6).unwrap();
            r.forward(0.08).unwrap();
        }
        assert!(r.camera_frames() >= 3);
    }
}

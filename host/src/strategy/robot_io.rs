//! "The robot and what the camera sees": the few primitives and observations that the pushing
//! strategy's collection (Lau, Mitani & Igarashi §III-C/D, Algorithm 1) and delivery (§III-E,
//! Algorithm 2) are written against, and an in-process implementation on the simulated robot.
//!
//! The paper's robot only spins, drives forward and stops (§IV, "Software"); its host sees the
//! robot's and the object's marker poses from a ceiling camera. [`RobotIo`] is exactly that.
//! [`SimRobot`] drives a [`pushbot_sim::Sim`] through the firmware's real protocol end: it
//! encodes [`HostFrame`]s into the simulated firmware and decodes its [`RobotMsg`]s, stepping
//! simulated time until each primitive's `Done`; its "camera" reads the simulator's true poses
//! with optional seeded noise (about 1 mm and 0.5°).

use anyhow::{Context, Result, anyhow, bail};
use nalgebra::Vector2;
use pushbot_protocol::{
    Command, ConfigUpdate, FrameDecoder, HostFrame, MAX_FRAME, NackReason, Outcome,
    PROTOCOL_VERSION, RobotMsg, encode_frame,
};
use pushbot_sim::{Scene, Sim, SimOptions};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr_free::gaussian;

use super::sample::Pose2;

/// An axis-aligned rectangle of the table frame, m.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Rect {
    /// Lower-left corner.
    pub min: [f64; 2],
    /// Upper-right corner.
    pub max: [f64; 2],
}

impl Rect {
    /// Whether `p` lies inside (or on) the rectangle.
    pub fn contains(&self, p: Vector2<f64>) -> bool {
        p.x >= self.min[0] && p.x <= self.max[0] && p.y >= self.min[1] && p.y <= self.max[1]
    }
    /// The rectangle shrunk by `d` on every side.
    pub fn inset(&self, d: f64) -> Rect {
        Rect {
            min: [self.min[0] + d, self.min[1] + d],
            max: [self.max[0] - d, self.max[1] - d],
        }
    }
    /// Outward direction from the rectangle to `p` (unit), or `None` when `p` is inside.
    pub fn outward(&self, p: Vector2<f64>) -> Option<Vector2<f64>> {
        let dx = if p.x < self.min[0] {
            p.x - self.min[0]
        } else if p.x > self.max[0] {
            p.x - self.max[0]
        } else {
            0.0
        };
        let dy = if p.y < self.min[1] {
            p.y - self.min[1]
        } else if p.y > self.max[1] {
            p.y - self.max[1]
        } else {
            0.0
        };
        let v = Vector2::new(dx, dy);
        (v.norm() > 0.0).then(|| v / v.norm())
    }
    /// Centre of the rectangle.
    pub fn centre(&self) -> Vector2<f64> {
        Vector2::new(
            (self.min[0] + self.max[0]) / 2.0,
            (self.min[1] + self.max[1]) / 2.0,
        )
    }
}

/// The workspace as the paper's problem definition gives it (§III-A): the boundary the object
/// must stay in, the robot's radius and the radius of the object's bounding circle.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Workspace {
    /// The table (the robot's centre can never leave it shrunk by the robot's radius).
    pub table: Rect,
    /// The boundary the object's marker must stay inside.
    pub boundary: Rect,
    /// Robot (bumper) radius, m.
    pub robot_radius: f64,
    /// Radius of the object's bounding circle around its marker, m.
    pub object_radius: f64,
}

impl Workspace {
    /// Where the robot's centre may go: the table shrunk by the robot's radius and 1 cm.
    pub fn reachable(&self) -> Rect {
        self.table.inset(self.robot_radius + 0.01)
    }
}

/// The robot and the camera, as the strategy code sees them.
pub trait RobotIo {
    /// Spin in place by `angle`, rad (counter-clockwise positive); returns when stopped.
    fn spin(&mut self, angle: f64) -> Result<()>;
    /// Drive straight by `distance`, m (negative: backwards); returns when stopped.
    fn forward(&mut self, distance: f64) -> Result<()>;
    /// Drive at `v` m/s turning at `omega` rad/s for `duration` s (the dipole baseline).
    fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()>;
    /// The robot's pose in the table frame, as the camera sees it.
    fn robot_pose(&mut self) -> Pose2;
    /// The object's marker pose in the table frame, as the camera sees it.
    fn object_pose(&mut self) -> Pose2;
    /// The pose of the object named `id` in the scene (its body frame, not its marker), in the
    /// table frame, as the camera sees it; `None` when there is no such object or it is not seen.
    fn body_pose(&mut self, id: &str) -> Option<Pose2>;
    /// Time since the start, s (simulated time in simulation).
    fn time(&self) -> f64;
    /// The workspace.
    fn workspace(&self) -> Workspace;
}

/// Tiny Gaussian sampler (Box–Muller), so no extra distribution crate is needed.
mod rand_distr_free {
    use rand::Rng;
    /// A standard normal draw.
    pub fn gaussian(rng: &mut impl Rng) -> f64 {
        let u1: f64 = rng.random_range(f64::EPSILON..1.0);
        let u2: f64 = rng.random_range(0.0..1.0);
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

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
        }
    }
}

/// The simulated robot, in process, spoken to through the firmware protocol.
pub struct SimRobot {
    sim: Sim,
    opts: SimRobotOptions,
    rng: ChaCha8Rng,
    seq: u16,
    decoder: FrameDecoder,
    rx: Vec<u8>,
    object: usize,
    marker: [f64; 2],
    workspace: Workspace,
    last_heartbeat_us: u64,
    margin: f64,
}

/// Longest a primitive may take before it counts as lost, s of simulated time.
const PRIMITIVE_LIMIT_S: f64 = 60.0;
/// Heartbeat period, µs of simulated time (the watchdog is configured to 5 s).
const HEARTBEAT_US: u64 = 1_000_000;

impl SimRobot {
    /// A simulated robot in `scene`, pushing object `object_id` (the first object when `None`),
    /// which is placed at the scene's named position `start` when given.
    pub fn new(
        mut scene: Scene,
        object_id: Option<&str>,
        start: Option<&str>,
        opts: SimRobotOptions,
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
        let marker = obj.marker.map_or([0.0, 0.0], |m| [m.x, m.y]);
        let object_radius = obj
            .outline
            .iter()
            .map(|v| (v[0] - marker[0]).hypot(v[1] - marker[1]))
            .fold(0.0, f64::max);
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
        let sim = Sim::new(&SimOptions {
            seed: opts.seed,
            speed: 0.0,
            scene: Some(scene),
            ..SimOptions::default()
        })?;
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        rng.set_stream(7);
        let mut robot = SimRobot {
            sim,
            opts,
            rng,
            seq: 0,
            decoder: FrameDecoder::new(),
            rx: Vec::new(),
            object,
            marker,
            workspace,
            last_heartbeat_us: 0,
            margin: m,
        };
        robot.handshake()?;
        Ok(robot)
    }

    /// The simulator (for true poses, figures and tests).
    pub fn sim(&self) -> &Sim {
        &self.sim
    }

    /// The object's true marker pose (no camera noise).
    pub fn true_object_pose(&self) -> Pose2 {
        let poses = self.sim.object_poses();
        let p = poses.get(self.object).map_or(
            pushbot_sim::Pose::new(f64::NAN, f64::NAN, f64::NAN),
            |(_, p)| *p,
        );
        let o = Pose2::new(p.x - self.margin, p.y - self.margin, p.theta);
        let m = o.point_to_world(Vector2::new(self.marker[0], self.marker[1]));
        Pose2::new(m.x, m.y, p.theta)
    }

    /// The robot's true pose.
    pub fn true_robot_pose(&self) -> Pose2 {
        let p = self.sim.truth().pose;
        Pose2::new(p.x - self.margin, p.y - self.margin, p.theta)
    }

    fn handshake(&mut self) -> Result<()> {
        let hello = self.request(Command::Hello {
            protocol: PROTOCOL_VERSION,
        })?;
        match hello {
            RobotMsg::HelloReply(r) if r.accepted => {}
            other => bail!("the simulated robot refused the session: {other:?}"),
        }
        let cfg = ConfigUpdate {
            watchdog_ms: Some(5000),
            telemetry_hz: Some(0),
            ..ConfigUpdate::default()
        };
        match self.request(Command::Configure(cfg))? {
            RobotMsg::Ack { .. } => Ok(()),
            other => bail!("the simulated robot refused the configuration: {other:?}"),
        }
    }

    fn send(&mut self, cmd: Command) -> Result<u16> {
        self.seq = self.seq.wrapping_add(1);
        let mut buf = [0u8; MAX_FRAME];
        let n = encode_frame(&HostFrame { seq: self.seq, cmd }, &mut buf)
            .map_err(|e| anyhow!("cannot frame {cmd:?}: {e:?}"))?;
        self.sim.receive(&buf[..n]);
        Ok(self.seq)
    }

    /// Tick until a message matching `want` arrives, feeding heartbeats.
    fn wait_for(
        &mut self,
        max_s: f64,
        mut want: impl FnMut(&RobotMsg) -> bool,
    ) -> Option<RobotMsg> {
        let end = self.sim.now_us() + (max_s * 1e6) as u64;
        while self.sim.now_us() < end {
            if self.sim.now_us() >= self.last_heartbeat_us + HEARTBEAT_US {
                self.last_heartbeat_us = self.sim.now_us();
                // A heartbeat is not acknowledged and has no sequence of its own to track.
                let mut buf = [0u8; MAX_FRAME];
                if let Ok(n) = encode_frame(
                    &HostFrame {
                        seq: self.seq,
                        cmd: Command::Heartbeat,
                    },
                    &mut buf,
                ) {
                    self.sim.receive(&buf[..n]);
                }
            }
            self.sim.tick();
            self.rx.clear();
            self.sim.transmit(&mut self.rx);
            let mut found = None;
            let rx = std::mem::take(&mut self.rx);
            self.decoder.feed::<RobotMsg>(&rx, |m| {
                if let Ok(m) = m
                    && found.is_none()
                    && want(&m)
                {
                    found = Some(m);
                }
            });
            self.rx = rx;
            if found.is_some() {
                return found;
            }
        }
        None
    }

    /// Send a command and wait for its answer (Ack, Nack or HelloReply).
    fn request(&mut self, cmd: Command) -> Result<RobotMsg> {
        let seq = self.send(cmd)?;
        self.wait_for(1.0, |m| match m {
            RobotMsg::Ack { seq: s } | RobotMsg::Nack { seq: s, .. } => *s == seq,
            RobotMsg::HelloReply(_) => true,
            _ => false,
        })
        .ok_or_else(|| anyhow!("no answer to {cmd:?}"))
    }

    /// Run one motion command to its `Done`; a latched fault (a stall against something that
    /// does not move) is cleared and the motion counts as ended.
    fn motion(&mut self, cmd: Command) -> Result<()> {
        for attempt in 0..2 {
            let seq = self.send(cmd)?;
            let msg = self
                .wait_for(PRIMITIVE_LIMIT_S, |m| match m {
                    RobotMsg::Nack { seq: s, .. } => *s == seq,
                    RobotMsg::Done(d) => d.seq == seq,
                    _ => false,
                })
                .ok_or_else(|| anyhow!("{cmd:?} did not end within {PRIMITIVE_LIMIT_S} s"))?;
            match msg {
                RobotMsg::Done(d) => {
                    if let Outcome::Fault(_) = d.outcome {
                        self.clear_faults()?;
                    }
                    return Ok(());
                }
                RobotMsg::Nack {
                    reason: NackReason::Faulted(_),
                    ..
                } if attempt == 0 => self.clear_faults()?,
                other => bail!("the robot refused {cmd:?}: {other:?}"),
            }
        }
        bail!("the robot stayed faulted")
    }

    fn clear_faults(&mut self) -> Result<()> {
        // Faults clear only once their cause has been quiet for a while.
        for _ in 0..20 {
            self.sim.run_for(0.1);
            self.request(Command::ClearFaults)
                .context("clearing faults")?;
            if self.sim.truth().faults.is_empty() {
                return Ok(());
            }
        }
        bail!("faults {:?} would not clear", self.sim.truth().faults)
    }

    fn noisy(&mut self, p: Pose2) -> Pose2 {
        if self.opts.position_noise <= 0.0 && self.opts.heading_noise <= 0.0 {
            return p;
        }
        let (a, b, c) = (
            gaussian(&mut self.rng),
            gaussian(&mut self.rng),
            gaussian(&mut self.rng),
        );
        Pose2::new(
            p.x + self.opts.position_noise * a,
            p.y + self.opts.position_noise * b,
            super::sample::wrap_angle(p.theta + self.opts.heading_noise * c),
        )
    }
}

/// Grow the scene's table by `m` on every side, moving everything on it along.
fn shift_scene(scene: &mut Scene, m: f64) {
    scene.table.width += 2.0 * m;
    scene.table.height += 2.0 * m;
    let mv = |p: &mut pushbot_sim::Pose| {
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
}

impl RobotIo for SimRobot {
    fn spin(&mut self, angle: f64) -> Result<()> {
        let angle = super::sample::wrap_angle(angle);
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
        let p = self.true_robot_pose();
        self.noisy(p)
    }

    fn object_pose(&mut self) -> Pose2 {
        let p = self.true_object_pose();
        self.noisy(p)
    }

    fn body_pose(&mut self, id: &str) -> Option<Pose2> {
        let (_, p) = self.sim.object_poses().into_iter().find(|(o, _)| o == id)?;
        let p = Pose2::new(p.x - self.margin, p.y - self.margin, p.theta);
        Some(self.noisy(p))
    }

    fn time(&self) -> f64 {
        self.sim.now_us() as f64 * 1e-6
    }

    fn workspace(&self) -> Workspace {
        self.workspace
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
        assert!(
            (super::super::sample::wrap_angle(b.theta - a.theta) - std::f64::consts::FRAC_PI_2)
                .abs()
                < 0.05
        );
        assert!(
            (b.y - a.y - 0.1).abs() < 0.01 && (b.x - a.x).abs() < 0.01,
            "{a:?} {b:?}"
        );
        // Object C is at (0.45, 0.25), marker at the origin of the outline.
        let o = r.object_pose();
        assert!((o.x - 0.45).abs() < 1e-9 && (o.y - 0.25).abs() < 1e-9);
        assert!(r.time() > 1.0);
    }
}

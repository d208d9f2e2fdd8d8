//! The simulated robot: the firmware's own [`Core`] on simulated encoders, bumper switches and
//! motors in a [`World`], stepped at a fixed rate in simulated time.
//!
//! One [`Sim::tick`] is one firmware control period (1 ms for the reference robot): the sensors
//! are read from the world at time `t`, the core computes the duties, and the world then moves
//! for one period under those duties (a zero-order hold, as a PWM peripheral does), optionally in
//! several physics sub-steps. Everything random is drawn from the seed, so a run is a function
//! of the seed, the options and the bytes received at each tick.

use std::collections::BTreeMap;
use std::path::PathBuf;

use anyhow::{Result, bail};
use pushbot_firmware::{Core, Inputs, RobotParams};
use pushbot_protocol::{Command, Faults, FrameDecoder, HostFrame};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::encoder::Encoder;
use crate::faults::LinkFaults;
use crate::robot::{BumperSwitches, Pose};
use crate::scene::Scene;
use crate::world::{Hardware, World};

pub use crate::truth::{Truth, TruthRecord};

/// Everything that sets up a simulated robot.
#[derive(Clone, Debug)]
pub struct SimOptions {
    /// Seed of every random draw (motor spread, slip, encoder glitches, switch bounce).
    pub seed: u64,
    /// Pacing of simulated time against the wall clock when served on a pty: 1 = real time,
    /// 20 = twenty times faster, 0 = as fast as the machine goes (unpaced). Ignored in process.
    pub speed: f64,
    /// Where to write the truth log (JSON lines, see [`TruthRecord`]), if anywhere.
    pub truth_log: Option<PathBuf>,
    /// Rate of the truth log, Hz of simulated time.
    pub truth_hz: f64,
    /// The robot's true start pose in the table frame (its odometry starts at zero regardless).
    pub start: Pose,
    /// Table width (along x) and height (along y), m. The table frame has its origin at the
    /// table's lower-left corner; the walls are its four edges.
    pub table: (f64, f64),
    /// The robot the firmware is built for (geometry, limits, gains).
    pub robot: RobotParams,
    /// The physical model's constants and noise.
    pub hardware: Hardware,
    /// Physics sub-steps per firmware tick.
    pub substeps: u32,
    /// A scene: when set, its table, obstacles, objects, robot build and robot start replace
    /// `table`, `start` and the geometry and motor of `robot`/`hardware`.
    pub scene: Option<Scene>,
    /// Link faults injected between the pty and the firmware ([`crate::PtySim`] only).
    pub faults: Option<LinkFaults>,
    /// Run the overhead camera beside the served robot ([`crate::PtySim`] only).
    pub camera: Option<crate::camera::live::LiveCameraOptions>,
    /// Keep a symlink at this path to the served pty ([`crate::PtySim`] only), as udev keeps
    /// `/dev/serial/by-id/…`: hosts open it, and it outlives unplugs.
    pub link: Option<PathBuf>,
    /// Unplugs of the served port ([`crate::PtySim`] only; needs `link`).
    pub unplugs: Vec<crate::plug::Unplug>,
    /// Objects moved by hand at given times ([`Disturbance`]).
    pub disturbances: Vec<Disturbance>,
    /// A perturbed world ([`crate::perturb`]): applied to `scene` (its object's start, friction
    /// and centre of friction) and to the hardware (wheel slip). Needs `scene`.
    pub perturb: Option<crate::perturb::Perturbation>,
}

/// An object moved by hand mid-run: at `at_s` seconds of simulated time `object` is
/// lifted and put down `by` (dx, dy in metres, dθ in radians, table frame) from where it is.
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    /// When, s of simulated time.
    pub at_s: f64,
    /// Which object (its scene id).
    pub object: String,
    /// How far: dx, dy (m), dθ (rad).
    pub by: [f64; 3],
}

impl std::str::FromStr for Disturbance {
    type Err = String;

    /// `AT:OBJECT:DX:DY[:DTHETA_DEG]`, e.g. `40:box1:0.1:0` (seconds, metres, degrees).
    fn from_str(s: &str) -> Result<Disturbance, String> {
        let parts: Vec<&str> = s.split(':').collect();
        if !(4..=5).contains(&parts.len()) || parts[1].is_empty() {
            return Err(format!(
                "{s:?}: a disturbance is AT:OBJECT:DX:DY[:DTHETA_DEG], e.g. 40:box1:0.1:0"
            ));
        }
        let num = |k: usize, what: &str| -> Result<f64, String> {
            parts
                .get(k)
                .map_or(Ok(0.0), |v| v.parse::<f64>())
                .map_err(|_| format!("{s:?}: {what} {:?} is not a number", parts[k]))
                .and_then(|v| {
                    v.is_finite()
                        .then_some(v)
                        .ok_or_else(|| format!("{s:?}: {what} must be finite"))
                })
        };
        let at_s = num(0, "the time")?;
        if at_s < 0.0 {
            return Err(format!("{s:?}: the time must not be negative"));
        }
        Ok(Disturbance {
            at_s,
            object: parts[1].to_string(),
            by: [num(2, "dx")?, num(3, "dy")?, num(4, "dθ")?.to_radians()],
        })
    }
}

impl Default for SimOptions {
    /// Seed 0, real time, a 1.2 m × 0.9 m table, the reference robot at its centre facing +x.
    fn default() -> Self {
        SimOptions {
            seed: 0,
            speed: 1.0,
            truth_log: None,
            truth_hz: 100.0,
            start: Pose::new(0.6, 0.45, 0.0),
            table: (1.2, 0.9),
            robot: RobotParams::default(),
            hardware: Hardware::default(),
            substeps: 1,
            scene: None,
            faults: None,
            camera: None,
            link: None,
            unplugs: Vec::new(),
            disturbances: Vec::new(),
            perturb: None,
        }
    }
}

impl SimOptions {
    /// The scene these options describe: `scene` itself, or an empty table of `table` with the
    /// reference robot at `start`.
    pub fn effective_scene(&self) -> Scene {
        match &self.scene {
            Some(s) => s.clone(),
            None => Scene {
                name: "table".into(),
                table: crate::scene::Table {
                    width: self.table.0,
                    height: self.table.1,
                },
                robot: crate::scene::RobotSpec {
                    start: self.start,
                    ..crate::scene::RobotSpec::default()
                },
                obstacles: Vec::new(),
                objects: Vec::new(),
                goals: Vec::new(),
                positions: Vec::new(),
                camera: crate::scene::CameraSpec::default(),
                rearrange: None,
                stable: None,
                perturb: None,
            },
        }
    }
}

/// The firmware core running on the simulated hardware, in process, at simulated time.
pub struct Sim {
    core: Core,
    world: World,
    encoders: [Encoder; 2],
    switches: BumperSwitches,
    rng: ChaCha8Rng,
    now_us: u64,
    tick_us: u32,
    substeps: u32,
    duty: [f32; 2],
    tx: [u8; 512],
    /// The simulator's own view of the host's frames: which `Hello` opened the session.
    shadow: FrameDecoder,
    session_hello: Option<u16>,
    starts: BTreeMap<u16, u32>,
    starts_since_boot: BTreeMap<u16, u32>,
    watchdog_trips: u64,
    /// Disturbances still to come, soonest last.
    disturbances: Vec<Disturbance>,
}

impl Sim {
    /// A robot at rest at `opts.start`; its firmware has just booted (robot time 0).
    pub fn new(opts: &SimOptions) -> Result<Self> {
        if opts.substeps == 0 || opts.substeps > 1000 {
            bail!("substeps must be 1..=1000, not {}", opts.substeps);
        }
        let (robot, mut hardware) = built_for(opts);
        let body = crate::world::body_from_geometry(&robot.geometry);
        let mut scene = opts.scene.clone();
        if let Some(p) = &opts.perturb {
            let Some(s) = scene.as_mut() else {
                bail!("a perturbed world needs a scene");
            };
            p.apply(s)?;
            hardware.wheel_slip = p.wheel_slip;
        }
        // The world's and the sensors' noise come from separate streams of the one seed.
        let world = match &scene {
            Some(scene) => World::from_scene(scene, body, hardware, opts.seed)?,
            None => World::new(opts.table, opts.start, body, hardware, opts.seed)?,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
        rng.set_stream(1);
        let cpr = robot.geometry.encoder_cpr;
        if cpr == 0 {
            bail!("encoder resolution must be positive");
        }
        let jitter = hardware.encoder_jitter;
        let encoders = [
            Encoder::new(cpr, jitter, rng.random_range(-1_000_000..=1_000_000)),
            Encoder::new(cpr, jitter, rng.random_range(-1_000_000..=1_000_000)),
        ];
        let core = Core::new(robot);
        let tick_us = core.tick_period_us().max(1);
        Ok(Sim {
            core,
            world,
            encoders,
            switches: BumperSwitches::new(hardware.bounce_us),
            rng,
            now_us: 0,
            tick_us,
            substeps: opts.substeps,
            duty: [0.0; 2],
            tx: [0; 512],
            shadow: FrameDecoder::new(),
            session_hello: None,
            starts: BTreeMap::new(),
            starts_since_boot: BTreeMap::new(),
            watchdog_trips: 0,
            disturbances: {
                let mut d = opts.disturbances.clone();
                d.sort_by(|a, b| b.at_s.total_cmp(&a.at_s));
                d
            },
        })
    }

    /// Simulated (robot) time, µs.
    pub fn now_us(&self) -> u64 {
        self.now_us
    }

    /// Length of one tick, µs.
    pub fn tick_us(&self) -> u32 {
        self.tick_us
    }

    /// Hand bytes from the host to the firmware, at the current simulated time. Every motion
    /// primitive the core starts is counted by its sequence number ([`Sim::starts`]).
    pub fn receive(&mut self, bytes: &[u8]) {
        for &b in bytes {
            let hello = match self.shadow.push::<HostFrame>(b) {
                Some(Ok(HostFrame {
                    seq,
                    cmd: Command::Hello { .. },
                })) => Some(seq),
                _ => None,
            };
            let before = self.core.active();
            self.core.receive(self.now_us, &[b]);
            if let Some(seq) = hello
                && self.core.has_session()
                && self.session_hello != Some(seq)
            {
                // A new session (not a retried `Hello`): its numbers start afresh.
                self.session_hello = Some(seq);
                self.starts.clear();
            }
            let after = self.core.active();
            if let Some(seq) = after
                && after != before
            {
                *self.starts.entry(seq).or_insert(0) += 1;
                *self.starts_since_boot.entry(seq).or_insert(0) += 1;
            }
        }
    }

    /// How many times the core started a motion primitive, by sequence number, in the current
    /// session (the simulator's own count: a primitive executed twice counts 2).
    pub fn starts(&self) -> &BTreeMap<u16, u32> {
        &self.starts
    }

    /// As [`Sim::starts`], over every session since boot: for a host whose numbering goes on
    /// across sessions (a recovered link), a number started twice here was executed twice.
    pub fn starts_since_boot(&self) -> &BTreeMap<u16, u32> {
        &self.starts_since_boot
    }

    /// How many times the link watchdog latched `LINK_LOST` since boot.
    pub fn watchdog_trips(&self) -> u64 {
        self.watchdog_trips
    }

    /// One firmware control period: read the sensors, step the core, move the world.
    pub fn tick(&mut self) {
        let angles = self.world.wheel_angles();
        let inputs = Inputs {
            encoder: [
                self.encoders[0].read(angles[0], &mut self.rng),
                self.encoders[1].read(angles[1], &mut self.rng),
            ],
            bumper: self
                .switches
                .read(self.now_us, self.world.pressed(), &mut self.rng),
        };
        let lost = self.core.faults().contains(Faults::LINK_LOST);
        let out = self.core.step(self.now_us, &inputs);
        if !lost && self.core.faults().contains(Faults::LINK_LOST) {
            self.watchdog_trips += 1;
        }
        self.duty = out.duty;
        let dt = f64::from(self.tick_us) * 1e-6 / f64::from(self.substeps);
        for _ in 0..self.substeps {
            self.world.step(self.duty, dt);
        }
        self.now_us += u64::from(self.tick_us);
        while self
            .disturbances
            .last()
            .is_some_and(|d| d.at_s * 1e6 <= self.now_us as f64)
        {
            if let Some(d) = self.disturbances.pop() {
                if self.world.shift_object(&d.object, d.by) {
                    tracing::info!(
                        "disturbance at {:.2} s: {} moved by ({:+.3}, {:+.3}) m, {:+.1}°",
                        d.at_s,
                        d.object,
                        d.by[0],
                        d.by[1],
                        d.by[2].to_degrees()
                    );
                } else {
                    tracing::warn!("disturbance at {:.2} s: no object {:?}", d.at_s, d.object);
                }
            }
        }
    }

    /// Run whole ticks until at least `seconds` more of simulated time have passed.
    pub fn run_for(&mut self, seconds: f64) {
        let end = self.now_us + (seconds.max(0.0) * 1e6) as u64;
        while self.now_us < end {
            self.tick();
        }
    }

    /// Append the bytes the firmware wants to send to `out`.
    pub fn transmit(&mut self, out: &mut Vec<u8>) {
        // Bounded, in case a core never reports an empty queue.
        for _ in 0..1024 {
            let n = self.core.transmit(&mut self.tx);
            if n == 0 {
                break;
            }
            out.extend_from_slice(&self.tx[..n.min(self.tx.len())]);
        }
    }

    /// The true state now.
    pub fn truth(&self) -> Truth {
        Truth {
            t: self.now_us as f64 / 1e6,
            pose: self.world.pose(),
            duty: self.duty,
            wheel_speed: self.world.wheel_speeds(),
            bumper: self.world.pressed(),
            mode: self.core.mode(),
            faults: self.core.faults(),
            odometry: self.core.pose(),
        }
    }

    /// The objects' true poses, in scene order, with their ids.
    pub fn object_poses(&self) -> Vec<(String, Pose)> {
        self.world
            .objects()
            .iter()
            .map(|(id, s)| (id.clone(), s.pose))
            .collect()
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The firmware core.
    pub fn core(&self) -> &Core {
        &self.core
    }
}

/// The firmware parameters and hardware the options describe (a scene's robot spec wins).
pub fn built_for(opts: &SimOptions) -> (RobotParams, Hardware) {
    let mut robot = opts.robot;
    let mut hw = opts.hardware;
    if let Some(scene) = &opts.scene {
        let r = &scene.robot;
        robot.geometry.bumper_radius = r.bumper_radius as f32;
        robot.geometry.wheel_base = r.wheel_base as f32;
        robot.geometry.wheel_radius = r.wheel_radius as f32;
        robot.geometry.encoder_cpr = r.encoder_cpr;
        robot.gains.kff = (1.0 / r.no_load_speed) as f32;
        hw.motor.ke = hw.motor.supply_v / r.no_load_speed;
        hw.motor.resistance_ohm = hw.motor.ke * hw.motor.supply_v / r.stall_torque;
    }
    (robot, hw)
}

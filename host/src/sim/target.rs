//! The built-in simulated target: the simulated robot (running the firmware's own code) served
//! on a real pseudo-terminal, with its overhead camera on a local socket — what `pushbot demo`,
//! `pushbot robot` without `--port` and the hardware-in-the-loop tests connect to exactly as to
//! a robot and a camera.

use anyhow::{Context, Result};
use pushbot_sim::camera::live::LiveCameraOptions;
use pushbot_sim::{PtySim, SimOptions};
use pushbot_world::Scene;

pub use pushbot_sim::camera::SceneCamera;
pub use pushbot_sim::camera::render::Window;
pub use pushbot_sim::faults::{FaultArgs, LinkFaults};
pub use pushbot_sim::perturb::Perturbation;
pub use pushbot_sim::sim::Disturbance;

/// A simulated robot and camera serving one scene.
pub struct SimTarget {
    sim: PtySim,
    camera: Option<String>,
}

impl std::fmt::Debug for SimTarget {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SimTarget")
            .field("port", &self.sim.serial_path())
            .field("camera", &self.camera)
            .finish()
    }
}

impl SimTarget {
    /// Serve `scene` with every random draw from `seed`, simulated time running `speed` times
    /// faster than the wall clock; camera frames are also written to `frames_dir` if given, and
    /// `faults` (if any) are injected on the serial link, both ways.
    pub fn start(
        scene: &Scene,
        seed: u64,
        speed: f64,
        frames_dir: Option<std::path::PathBuf>,
        faults: Option<LinkFaults>,
    ) -> Result<SimTarget> {
        SimTarget::start_with(scene, seed, speed, frames_dir, faults, Vec::new())
    }

    /// As [`SimTarget::start`], with objects moved by hand mid-run (`disturbances`).
    pub fn start_with(
        scene: &Scene,
        seed: u64,
        speed: f64,
        frames_dir: Option<std::path::PathBuf>,
        faults: Option<LinkFaults>,
        disturbances: Vec<Disturbance>,
    ) -> Result<SimTarget> {
        let sim = PtySim::start(SimOptions {
            seed,
            speed,
            faults,
            disturbances,
            scene: Some(scene.clone()),
            camera: Some(LiveCameraOptions {
                frames_dir,
                ..LiveCameraOptions::default()
            }),
            ..SimOptions::default()
        })
        .context("starting the built-in simulated target")?;
        let camera = match sim.camera_addr() {
            Some(a) => Some(format!("sim:{a}")),
            None => anyhow::bail!("the simulated target started without its camera"),
        };
        Ok(SimTarget { sim, camera })
    }

    /// Serve `scene` as [`SimTarget::start`] does (no frames kept, no link faults), in the
    /// perturbed world `perturb` ([`pushbot_sim::perturb`]).
    pub fn start_perturbed(
        scene: &Scene,
        seed: u64,
        speed: f64,
        perturb: Option<pushbot_sim::perturb::Perturbation>,
    ) -> Result<SimTarget> {
        let sim = PtySim::start(SimOptions {
            seed,
            speed,
            perturb,
            scene: Some(scene.clone()),
            camera: Some(LiveCameraOptions::default()),
            ..SimOptions::default()
        })
        .context("starting the built-in simulated target")?;
        let camera = match sim.camera_addr() {
            Some(a) => Some(format!("sim:{a}")),
            None => anyhow::bail!("the simulated target started without its camera"),
        };
        Ok(SimTarget { sim, camera })
    }

    /// Serve only the robot's serial port (no camera): the scene's robot and world, or the
    /// default empty table when `scene` is `None` (`pushbot robot …` without `--port`).
    pub fn start_robot(scene: Option<&Scene>, seed: u64, speed: f64) -> Result<SimTarget> {
        let sim = PtySim::start(SimOptions {
            seed,
            speed,
            scene: scene.cloned(),
            ..SimOptions::default()
        })
        .context("starting the built-in simulated robot")?;
        Ok(SimTarget { sim, camera: None })
    }

    /// The robot's serial port (a pty path): `--port`.
    pub fn port(&self) -> &str {
        self.sim.serial_path()
    }

    /// The camera, as `--camera` spells it (`sim:127.0.0.1:PORT`); empty when the target was
    /// started without one ([`SimTarget::start_robot`]).
    pub fn camera(&self) -> &str {
        self.camera.as_deref().unwrap_or("")
    }

    /// The simulator, for ground truth in tests and reports.
    pub fn sim(&self) -> &PtySim {
        &self.sim
    }

    /// Stop the simulation; returns the error that stopped it, if any.
    pub fn shutdown(self) -> Result<()> {
        self.sim.shutdown()
    }
}

impl crate::task::session::Target for SimTarget {
    fn truth(&self) -> Option<crate::task::session::Truth> {
        let t = self.sim.truth();
        Some(crate::task::session::Truth {
            t: t.t,
            robot: [t.pose.x, t.pose.y, t.pose.theta],
            wheel_speed: t.wheel_speed,
            objects: self
                .sim
                .objects()
                .into_iter()
                .map(|(id, p)| (id, [p.x, p.y, p.theta]))
                .collect(),
        })
    }

    fn port(&self) -> String {
        self.sim.serial_path().to_string()
    }

    fn camera(&self) -> String {
        self.camera.clone().unwrap_or_default()
    }
}

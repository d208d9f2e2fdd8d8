//! The robot on its table, as tasks run on it: a [`LiveRobot`] (the serial link and the
//! overhead camera, on a real robot or the built-in simulated target alike) and, on the
//! built-in target, the simulator's truth to judge a run by. One session runs many tasks one
//! after the other (the console), or one (`pushbot run`).

use std::sync::Arc;

use anyhow::Result;
use pushbot_world::Scene;

use crate::exec::{LiveOptions, LiveRobot};

/// What the simulator knows of its world at one instant (only the built-in target has it).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Truth {
    /// Robot time, s.
    pub t: f64,
    /// The robot's true pose: x, y (m), heading (rad).
    pub robot: [f64; 3],
    /// The wheels' true speeds (left, right), rad/s.
    pub wheel_speed: [f64; 2],
    /// Every object's true body pose.
    pub objects: Vec<(String, [f64; 3])>,
}

/// What a session runs on besides the link and the camera: the built-in simulated target
/// (which knows the truth), or nothing for a real robot.
pub trait Target: Send + Sync {
    /// The truth now, where there is one.
    fn truth(&self) -> Option<Truth>;
    /// The serial port to connect to.
    fn port(&self) -> String;
    /// The camera, as `--camera` spells it.
    fn camera(&self) -> String;
}

/// Where the robot is: a real one (its port and camera) or the built-in simulated target.
#[derive(Debug, Clone, PartialEq)]
pub enum Where {
    /// A robot on a serial port, seen by a camera.
    Real {
        /// The serial port.
        port: String,
        /// The camera (`/dev/videoN`, a folder, `sim:HOST:PORT`).
        camera: String,
    },
    /// The built-in simulated target serving the scene.
    Builtin {
        /// Simulated seconds per wall second.
        speed: f64,
        /// Seed of the simulated world.
        seed: u64,
    },
}

/// A robot on a table, connected.
pub struct Session {
    /// The robot and the camera.
    pub live: LiveRobot,
    /// The scene of the table.
    pub scene: Scene,
    target: Option<Arc<dyn Target>>,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("live", &self.live)
            .field("builtin", &self.target.is_some())
            .finish()
    }
}

impl Session {
    /// Connect to the robot `at` over the table of `scene`.
    pub fn open(scene: &Scene, at: &Where, opts: LiveOptions) -> Result<Session> {
        match at {
            Where::Real { port, camera } => Ok(Session {
                live: LiveRobot::connect(port, camera, scene, opts)?,
                scene: scene.clone(),
                target: None,
            }),
            Where::Builtin { speed, seed } => Session::builtin(scene, *speed, *seed, opts),
        }
    }

    #[cfg(feature = "sim")]
    fn builtin(scene: &Scene, speed: f64, seed: u64, opts: LiveOptions) -> Result<Session> {
        let mut seen = scene.clone();
        if opts.lens.is_some() {
            seen.camera.lens = opts.lens;
        }
        let target: Arc<dyn Target> = Arc::new(crate::sim::SimTarget::start_with(
            &seen,
            seed,
            speed,
            None,
            None,
            Vec::new(),
        )?);
        let live = LiveRobot::connect(&target.port(), &target.camera(), scene, opts)?;
        Ok(Session {
            live,
            scene: scene.clone(),
            target: Some(target),
        })
    }

    #[cfg(not(feature = "sim"))]
    fn builtin(_: &Scene, _: f64, _: u64, _: LiveOptions) -> Result<Session> {
        anyhow::bail!(
            "this build of pushbot has no simulated target (built without the `sim` feature): \
             give --port PATH and --camera SRC for a real robot"
        )
    }

    /// The built-in target, when the session runs on it.
    pub fn target(&self) -> Option<Arc<dyn Target>> {
        self.target.clone()
    }

    /// The simulator's truth now (the built-in target only).
    pub fn truth(&self) -> Option<Truth> {
        self.target.as_ref().and_then(|t| t.truth())
    }

    /// Whether this is the built-in simulated target.
    pub fn builtin_target(&self) -> bool {
        self.target.is_some()
    }
}

/// The watchdog a task's robot is given: the robot's own second on a real robot, longer on a
/// simulated target running `speed` times faster than real time (the host's threads get less
/// wall time per robot second).
pub fn watchdog_ms(at: &Where) -> u16 {
    match at {
        Where::Real { .. } => 1000,
        Where::Builtin { speed, .. } => (1000.0 * speed.max(1.0)).min(5000.0) as u16,
    }
}

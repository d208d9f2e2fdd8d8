//! `pushbot console`: the operator's page in the browser ([`crate::console`]), on the built-in
//! simulated target or, with `--port`/`--camera`, a real robot.

use std::path::PathBuf;

use clap::Args;

use super::run::{RobotArgs, live_options, where_of};
use super::{CliError, CliResult, Global, Status};

/// `pushbot console`.
#[derive(Args, Debug, Clone)]
pub struct ConsoleArgs {
    /// The table: a preset or a scene file; a rearrangement case (A1 … D1) offers the
    /// rearrangement too.
    #[arg(long, default_value = "lau-obstacles")]
    pub scene: String,
    /// A real robot's serial port (with --camera); without it, the built-in simulated target.
    #[arg(long, requires = "camera")]
    pub port: Option<String>,
    /// The overhead camera (/dev/videoN, a folder of frames, sim:HOST:PORT), with --port.
    #[arg(long, requires = "port")]
    pub camera: Option<String>,
    /// Where to listen. Other machines can reach a non-loopback address; every request needs
    /// the token printed at start either way.
    #[arg(long, default_value = "127.0.0.1:7878", value_name = "ADDR")]
    pub listen: std::net::SocketAddr,
    /// The console's folder: a folder per run under runs/, strategies under strategies/.
    #[arg(long, default_value = "pushbot-console", value_name = "DIR")]
    pub dir: PathBuf,
    /// The built-in target's simulated seconds per wall second.
    #[arg(long = "sim-speed", default_value_t = 1.0, help_heading = "Simulation")]
    pub sim_speed: f64,
}

/// Run `pushbot console`.
pub fn run(g: &Global, a: &ConsoleArgs) -> CliResult {
    let (scene, rearrange) = match crate::planner::rearrange::cases::load_scene(&a.scene) {
        Ok(problem) => {
            let s = crate::planner::rearrange::to_scene::scene_for(
                &problem,
                &crate::planner::rearrange::to_scene::SceneOptions::default(),
            )
            .map_err(CliError::BadInput)?;
            (s, Some(problem))
        }
        Err(_) => (
            pushbot_world::Scene::preset_or_file(&a.scene)
                .map_err(|e| CliError::bad_input(format!("--scene {}: {e}", a.scene)))?,
            None,
        ),
    };
    let robot = RobotArgs {
        port: a.port.clone(),
        camera: a.camera.clone(),
        out: None,
        sim_speed: a.sim_speed,
    };
    let at = where_of(g, &robot)?;
    let live = live_options(g, &at)?;
    crate::console::serve(crate::console::ConsoleOptions {
        listen: a.listen,
        scene,
        rearrange,
        at,
        live,
        dir: a.dir.clone(),
        seed: g.seed,
        token: std::env::var("PUSHBOT_CONSOLE_TOKEN")
            .ok()
            .filter(|t| !t.is_empty()),
    })
    .map_err(CliError::Failed)?;
    Ok(Status::Success)
}

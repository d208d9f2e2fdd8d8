//! `pushbot demo`: the whole system in one command. It starts the built-in simulated target
//! (the firmware's own code on a simulated robot, a real pty for its serial port, a camera
//! socket) — or takes `--port`/`--camera` of a real robot — connects exactly as to hardware, and
//! runs three stages, each with a progress bar:
//!
//! 1. **strategy** (Lau, Mitani & Igarashi): collect a pushing strategy for an irregular object
//!    (or reuse the cached one), then deliver the object to its goal among obstacles;
//! 2. **rearrange** (Ben-Shahar & Rivlin): plan an optimal rearrangement of two boxes (cost map
//!    and restoration) and execute it, re-observing and snapping to the grid;
//! 3. **stable** (Lynch & Mason): plan stable pushes of the slider among obstacles and drive
//!    them closed loop.
//!
//! It writes a report folder (`report.html`, `summary.json`, figures, `demo.log`) and prints its
//! path. The pipeline is `crate::experiments::demo` (with the simulator); this module parses
//! and prints.

use std::path::PathBuf;
#[cfg(feature = "sim")]
use std::time::Instant;

use clap::Args;
use pushbot_world::Scene;

#[cfg(feature = "sim")]
use super::Status;
use super::{CliError, CliResult, Global};

/// The stages, in the order they run.
pub const STAGES: [&str; 3] = ["strategy", "rearrange", "stable"];

/// `pushbot demo`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "Examples:\n  pushbot demo\n  pushbot demo --out /tmp/demo --png --stages strategy,stable\n  pushbot demo --scene strategy=lau-snake\n  pushbot demo --stages stable --foxglove 127.0.0.1:8765\n  pushbot demo --stages strategy --faults --fault-cut-every 5 --fault-cut-for 1\n  pushbot demo --stages rearrange --disturb 40:b:0:0.1\n  pushbot demo --port /dev/ttyACM0 --camera /dev/video0 --scene strategy=my-table.toml --reconnect 10 --intrinsics camera.yaml"
)]
pub struct DemoArgs {
    /// Folder for the report (created; files in it are replaced).
    #[arg(long, default_value = "pushbot-demo")]
    pub out: PathBuf,
    /// Stages to run, comma-separated: strategy, rearrange, stable.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "strategy,rearrange,stable"
    )]
    pub stages: Vec<String>,
    /// A stage's scene, `STAGE=PRESET|FILE` (repeatable); defaults: strategy=lau-obstacles,
    /// rearrange=A1 (two boxes), stable=fig15.
    #[arg(long = "scene", value_name = "STAGE=SCENE")]
    pub scenes: Vec<String>,
    /// The robot's serial port: run on a real robot (needs --camera) instead of the built-in
    /// simulated target.
    #[arg(long, requires = "camera")]
    pub port: Option<String>,
    /// The overhead camera (/dev/videoN, a folder, sim:HOST:PORT), with --port.
    #[arg(long, requires = "port")]
    pub camera: Option<String>,
    /// Simulated seconds per wall second of the built-in target.
    #[arg(long = "sim-speed", alias = "speed", default_value_t = 8.0, help_heading = super::ADVANCED)]
    pub speed: f64,
    /// Also render every figure as PNG.
    #[arg(long)]
    pub png: bool,
    /// Where collected pushing strategies are cached (default: OUT/cache).
    #[arg(long, help_heading = super::ADVANCED)]
    pub cache: Option<PathBuf>,
    /// Keep a live view while it runs: open OUT/live/live.html in a browser (the camera image
    /// with detected markers, tracked poses and the current path, refreshed after every look).
    #[arg(long)]
    pub view: bool,
    /// Move a box by hand mid-run on the built-in simulated target (repeatable):
    /// `AT:OBJECT:DX:DY[:DTHETA_DEG]`, e.g. `--disturb 40:b:0:0.1` moves box `b` 10 cm at 40 s
    /// of simulated time; the executor re-plans from where it is, and the report lists it.
    #[cfg(feature = "sim")]
    #[arg(long, value_name = "AT:OBJECT:DX:DY", help_heading = super::ADVANCED)]
    pub disturb: Vec<crate::sim::target::Disturbance>,
    /// Record the run into this MCAP file (default OUT/run.mcap): camera, detections, tracked
    /// poses, scene, paths, telemetry, logs, in Foxglove's schemas (open it in Foxglove, or
    /// `pushbot replay FILE`).
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// Do not record the run.
    #[arg(long, conflicts_with = "record")]
    pub no_record: bool,
    /// Serve the recording's channels live over the Foxglove WebSocket protocol while the run
    /// goes (open Foxglove, "Open connection", ws://ADDR); ADDR defaults to 127.0.0.1:8765.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765", conflicts_with = "no_record")]
    pub foxglove: Option<String>,
    /// Link faults between the host and the built-in simulated target (as `pushbot-sim`
    /// takes them), e.g. `--faults --fault-cut-every 5 --fault-cut-for 1`; last, as their
    /// heading holds for what follows.
    #[cfg(feature = "sim")]
    #[command(flatten, next_help_heading = "Fault injection")]
    pub faults: crate::sim::target::FaultArgs,
}

/// The scene a stage runs on: `--scene STAGE=…` or the default.
fn scene_arg<'a>(args: &'a DemoArgs, stage: &str, default: &'a str) -> Result<&'a str, CliError> {
    for s in &args.scenes {
        let Some((k, v)) = s.split_once('=') else {
            return Err(CliError::bad_input(format!(
                "--scene {s:?}: expected STAGE=SCENE, e.g. strategy=lau-snake"
            )));
        };
        if !STAGES.contains(&k) {
            return Err(CliError::bad_input(format!(
                "--scene {s:?}: unknown stage {k:?}; the stages are {}",
                STAGES.join(", ")
            )));
        }
        if k == stage {
            return Ok(v);
        }
    }
    Ok(default)
}

fn load_scene(name: &str) -> Result<Scene, CliError> {
    Scene::preset_or_file(name).map_err(|e| CliError::bad_input(e.to_string()))
}

/// Run `pushbot demo`.
pub fn run(g: &Global, args: DemoArgs) -> CliResult {
    for s in &args.stages {
        if !STAGES.contains(&s.as_str()) {
            return Err(CliError::bad_input(format!(
                "--stages: unknown stage {s:?}; the stages are {}",
                STAGES.join(", ")
            )));
        }
    }
    if !(args.speed.is_finite() && args.speed > 0.0 && args.speed <= 50.0) {
        return Err(CliError::bad_input(format!(
            "--sim-speed must be in (0, 50], not {}",
            args.speed
        )));
    }
    // Check every scene before running anything.
    let strategy_scene = load_scene(scene_arg(&args, "strategy", "lau-obstacles")?)?;
    let rearrange_case = scene_arg(&args, "rearrange", "A1")?.to_string();
    let rearrange_problem = crate::planner::rearrange::cases::load_scene(&rearrange_case)
        .map_err(|e| CliError::bad_input(e.to_string()))?;
    let stable_name = scene_arg(&args, "stable", "fig15")?.to_string();
    crate::planner::stable::presets::load_scene(&stable_name)
        .map_err(|e| CliError::bad_input(format!("{e:#}")))?;

    if let (Some(port), Some(camera)) = (&args.port, &args.camera) {
        drop(crate::link::transport::open(port).map_err(|e| CliError::bad_input(format!("{e}")))?);
        crate::exec::grabber::FrameGrabber::open(camera, 30.0)
            .map_err(|e| CliError::bad_input(format!("--camera {camera}: {e}")))?;
    }
    run_stages(
        g,
        &args,
        strategy_scene,
        (rearrange_case, rearrange_problem),
        stable_name,
    )
}

/// Run the checked stages and print the outcome.
#[cfg(feature = "sim")]
fn run_stages(
    g: &Global,
    args: &DemoArgs,
    strategy_scene: Scene,
    rearrange: (String, crate::planner::rearrange::Problem),
    stable_name: String,
) -> CliResult {
    use crate::experiments::demo::{DemoOptions, run};
    let faults = args.faults.link_faults().map_err(CliError::bad_input)?;
    if faults.is_some() && args.port.is_some() {
        return Err(CliError::bad_input(
            "--faults injects faults on the built-in simulated target's link, not with --port",
        ));
    }
    let movables: Vec<&str> = strategy_scene
        .objects
        .iter()
        .map(|o| o.id.as_str())
        .chain(rearrange.1.movables.iter().map(|m| m.name.as_str()))
        .collect();
    if let Some(d) = args
        .disturb
        .iter()
        .find(|d| !movables.contains(&d.object.as_str()))
    {
        return Err(CliError::bad_input(format!(
            "--disturb: no stage has an object {:?} (the objects are {})",
            d.object,
            movables.join(", ")
        )));
    }
    if !args.disturb.is_empty() && args.port.is_some() {
        return Err(CliError::bad_input(
            "--disturb moves boxes on the built-in simulated target, not with --port",
        ));
    }
    let opts = DemoOptions {
        out: args.out.clone(),
        stages: args.stages.clone(),
        strategy_scene,
        rearrange,
        stable_name,
        robot: args.port.clone().zip(args.camera.clone()),
        speed: args.speed,
        seed: g.seed,
        png: args.png,
        cache: args.cache.clone(),
        view: args.view,
        quiet: g.json,
        faults,
        disturb: args.disturb.clone(),
        link: g.link_options()?,
        recover: !g.no_recover,
        lens: g.lens()?,
        foxglove: args.foxglove.clone(),
        record: (!args.no_record).then(|| {
            args.record
                .clone()
                .unwrap_or_else(|| args.out.join("run.mcap"))
        }),
    };
    let t0 = Instant::now();
    if let Some(addr) = args.foxglove.as_ref().filter(|_| !g.json) {
        println!("Foxglove live view: open a connection to ws://{addr}");
    }
    if args.view && !g.json {
        println!(
            "live view: open {} in a browser",
            args.out.join("live").join("live.html").display()
        );
    }
    let (report, page) = run(&opts).map_err(CliError::Failed)?;
    let ok = report.success();
    if g.json {
        let v = serde_json::json!({
            "report": page,
            "success": ok,
            "wall_s": t0.elapsed().as_secs_f64(),
            "stages": report.stages(),
            "recording": opts.record,
        });
        println!("{v}");
    } else {
        for s in report.stages() {
            println!(
                "{:10} {:8} {:6.1} s",
                s.id,
                if s.success { "reached" } else { "FAILED" },
                s.wall_s
            );
        }
        println!("report: {}", page.display());
        if let Some(r) = &opts.record {
            println!("recording: {}", r.display());
        }
    }
    Ok(if ok {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// Without the `sim` feature the demo's strategy stage (collected in the simulation) cannot
/// run: say so.
#[cfg(not(feature = "sim"))]
fn run_stages(
    _g: &Global,
    _args: &DemoArgs,
    _strategy_scene: Scene,
    _rearrange: (String, crate::planner::rearrange::Problem),
    _stable_name: String,
) -> CliResult {
    Err(super::no_simulated_target())
}

//! `pushbot run deliver|rearrange|stable` and `pushbot collect --port`: one task
//! ([`crate::task`]) on the robot — the built-in simulated target, or a real robot with
//! `--port`/`--camera` — from the table as the camera sees it, into a run folder (`run.mcap`,
//! `report.html`, `run.log`, `summary.json`). A goal off the table, inside an obstacle or out of
//! the robot's reach is refused before anything moves (exit 2).

use std::path::PathBuf;

use clap::{Args, Subcommand};

use super::{CliError, CliResult, Global, Status};
use crate::exec::LiveOptions;
use crate::task::folder::RunFolder;
use crate::task::goal::{GoalError, parse_goal, parse_id_goal};
use crate::task::{Control, EventSink, Session, Task, TaskEvent, Where};

/// `pushbot run`: one task on the robot.
#[derive(Subcommand, Debug)]
pub enum RunCommand {
    /// Deliver an object to a position with the learned strategy (or the dipole field), among
    /// the scene's obstacles.
    Deliver(DeliverArgs),
    /// Rearrange the boxes into the goal arrangement, from where they are.
    Rearrange(RearrangeArgs),
    /// Push the slider with stable pushes to its goal pose, closed loop.
    Stable(StableArgs),
}

/// Where the task runs and where its folder goes.
#[derive(Args, Debug, Clone)]
pub struct RobotArgs {
    /// A real robot's serial port (with --camera); without it, the built-in simulated target.
    #[arg(long, requires = "camera")]
    pub port: Option<String>,
    /// The overhead camera (/dev/videoN, a folder of frames, sim:HOST:PORT), with --port.
    #[arg(long, requires = "port")]
    pub camera: Option<String>,
    /// The run's folder (default: runs/TASK-YYYYMMDD-HHMMSS).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The built-in target's simulated seconds per wall second.
    #[arg(long = "sim-speed", default_value_t = 4.0, help_heading = "Simulation")]
    pub sim_speed: f64,
}

/// `pushbot run deliver`.
#[derive(Args, Debug, Clone)]
pub struct DeliverArgs {
    /// The object to deliver (its id in the scene).
    #[arg(long)]
    pub object: String,
    /// Where its marker should end: X,Y in metres on the table.
    #[arg(long, value_name = "X,Y")]
    pub goal: String,
    /// The table: a preset or a scene file (default: lau-OBJECT).
    #[arg(long)]
    pub scene: Option<String>,
    /// The pushing strategy (from `pushbot collect`; default OBJECT.strategy). On the built-in
    /// target a missing file is collected first, in simulation.
    #[arg(long, value_name = "FILE")]
    pub strategy: Option<PathBuf>,
    /// `learned` (the strategy) or `dipole` (the dipole field, no strategy needed).
    #[arg(long, value_enum, default_value_t = DeliverMethod::Learned)]
    pub method: DeliverMethod,
    #[command(flatten)]
    pub robot: RobotArgs,
}

/// How `run deliver` pushes.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeliverMethod {
    /// The learned pushing strategy (Lau et al. Algorithm 2).
    Learned,
    /// The dipole field (Igarashi et al.), the paper's baseline.
    Dipole,
}

/// `pushbot run rearrange`.
#[derive(Args, Debug, Clone)]
pub struct RearrangeArgs {
    /// A case (A1 … D1), a preset with a `[rearrange]` section, or a scene file.
    #[arg(long)]
    pub scene: String,
    /// A movable's goal in place of the scene's: ID=X,Y or ID=X,Y,DEG (metres; the grid cell it
    /// falls in). Repeat for several.
    #[arg(long, value_name = "ID=X,Y")]
    pub goal: Vec<String>,
    /// The planner: `exact` (optimal) or `practical` (many movables); default: exact when its
    /// map fits in memory.
    #[arg(long, value_enum)]
    pub mode: Option<RearrangeMode>,
    #[command(flatten)]
    pub robot: RobotArgs,
}

/// `--mode` of `run rearrange`.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum RearrangeMode {
    /// The exact cost map (optimal).
    Exact,
    /// The practical mode (many movables).
    Practical,
}

/// `pushbot run stable`.
#[derive(Args, Debug, Clone)]
pub struct StableArgs {
    /// A preset (fig13 … fig18, robot scale) or a scene file with a `[stable]` section whose
    /// pusher is a `diff-drive`.
    #[arg(long)]
    pub scene: String,
    /// The slider's goal in place of the scene's: X,Y or X,Y,DEG (metres, degrees).
    #[arg(long, value_name = "X,Y[,DEG]")]
    pub goal: Option<String>,
    #[command(flatten)]
    pub robot: RobotArgs,
}

/// The scene's id of the object the operator names: its id, or one of Lau et al.'s objects by
/// name on its own preset (`--object irregular` on `lau-irregular`).
pub fn object_id(scene: &pushbot_world::Scene, name: &str) -> String {
    if scene.object(name).is_some() {
        return name.to_string();
    }
    match scene.objects.first() {
        Some(o) if scene.name == format!("lau-{name}") => o.id.clone(),
        _ => name.to_string(),
    }
}

fn bad(e: GoalError) -> CliError {
    CliError::bad_input(e)
}

/// Run `pushbot run …`.
pub fn run(g: &Global, cmd: RunCommand) -> CliResult {
    match cmd {
        RunCommand::Deliver(a) => deliver(g, &a),
        RunCommand::Rearrange(a) => rearrange(g, &a),
        RunCommand::Stable(a) => stable(g, &a),
    }
}

fn deliver(g: &Global, a: &DeliverArgs) -> CliResult {
    use crate::task::deliver::{Deliver, Method};
    let name = a
        .scene
        .clone()
        .unwrap_or_else(|| format!("lau-{}", a.object));
    let scene = pushbot_world::Scene::preset_or_file(&name)
        .map_err(|e| CliError::bad_input(format!("--scene {name}: {e}")))?;
    let goal = parse_goal(&a.goal).map_err(bad)?;
    let object = object_id(&scene, &a.object);
    // The goal first: nothing is loaded or collected for a goal that cannot be reached.
    Deliver::new(&scene, &object, goal, Method::Dipole).map_err(bad)?;
    let method = match a.method {
        DeliverMethod::Dipole => Method::Dipole,
        DeliverMethod::Learned => {
            let path = a
                .strategy
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}.strategy", a.object)));
            Method::Learned(strategy_samples(g, &scene, &object, &path, &a.robot)?)
        }
    };
    let task = Deliver::new(&scene, &object, goal, method).map_err(bad)?;
    run_task(g, &scene, Task::Deliver(task), &a.robot)
}

/// The samples of the strategy at `path` ([`crate::task::deliver::load_strategy`]).
fn strategy_samples(
    g: &Global,
    scene: &pushbot_world::Scene,
    object: &str,
    path: &std::path::Path,
    robot: &RobotArgs,
) -> Result<Vec<crate::strategy::sample::Sample>, CliError> {
    if !path.exists() && robot.port.is_none() && !g.json {
        eprintln!(
            "no strategy {}: collecting one for {object} in simulation first",
            path.display()
        );
    }
    crate::task::deliver::load_strategy(scene, object, path, robot.port.is_none(), g.seed)
        .map_err(bad)
}

fn rearrange(g: &Global, a: &RearrangeArgs) -> CliResult {
    use crate::task::rearrange::{Mode, Rearrange};
    let problem = crate::planner::rearrange::cases::load_scene(&a.scene)
        .map_err(|e| CliError::bad_input(format!("--scene {}: {e}", a.scene)))?;
    let goals = a
        .goal
        .iter()
        .map(|s| parse_id_goal(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(bad)?;
    let mode = a.mode.map(|m| match m {
        RearrangeMode::Exact => Mode::Exact,
        RearrangeMode::Practical => Mode::Practical,
    });
    let task = Rearrange::new(problem, &goals, mode).map_err(bad)?;
    let scene = task.scene().map_err(CliError::BadInput)?;
    run_task(g, &scene, Task::Rearrange(task), &a.robot)
}

#[cfg(feature = "sim")]
fn stable(g: &Global, a: &StableArgs) -> CliResult {
    use crate::experiments::stable_trials::StableTask;
    let st = StableTask::load(&a.scene).map_err(|e| CliError::bad_input(format!("{e:#}")))?;
    let goal = a.goal.as_deref().map(parse_goal).transpose().map_err(bad)?;
    let task = crate::task::stable::Stable::new(st, goal).map_err(bad)?;
    let scene = task.task.sim_scene().map_err(CliError::BadInput)?;
    run_task(g, &scene, Task::Stable(Box::new(task)), &a.robot)
}

#[cfg(not(feature = "sim"))]
fn stable(_: &Global, _: &StableArgs) -> CliResult {
    Err(super::no_simulated_target())
}

/// Where `robot` says the task runs.
pub fn where_of(g: &Global, robot: &RobotArgs) -> Result<Where, CliError> {
    match (&robot.port, &robot.camera) {
        (Some(port), Some(camera)) => Ok(Where::Real {
            port: port.clone(),
            camera: camera.clone(),
        }),
        _ => {
            if !(robot.sim_speed.is_finite() && robot.sim_speed > 0.0 && robot.sim_speed <= 50.0) {
                return Err(CliError::bad_input(format!(
                    "--sim-speed must be in (0, 50], not {}",
                    robot.sim_speed
                )));
            }
            #[cfg(not(feature = "sim"))]
            {
                let _ = g;
                Err(super::no_simulated_target())
            }
            #[cfg(feature = "sim")]
            Ok(Where::Builtin {
                speed: robot.sim_speed,
                seed: g.seed,
            })
        }
    }
}

/// The settings of a task's robot these flags ask for.
pub fn live_options(g: &Global, at: &Where) -> Result<LiveOptions, CliError> {
    Ok(LiveOptions {
        watchdog_ms: crate::task::session::watchdog_ms(at),
        link: g.link_options()?,
        recover: !g.no_recover,
        lens: g.lens()?,
        ..LiveOptions::default()
    })
}

/// Run `task` on the robot `robot` says, over `scene`'s table, into its folder; prints the
/// events (text on stderr, or the summary as JSON).
pub fn run_task(
    g: &Global,
    scene: &pushbot_world::Scene,
    task: Task,
    robot: &RobotArgs,
) -> CliResult {
    let at = where_of(g, robot)?;
    let opts = live_options(g, &at)?;
    if let Where::Real { port, camera } = &at {
        drop(crate::link::transport::open(port).map_err(|e| CliError::bad_input(format!("{e}")))?);
        crate::exec::grabber::FrameGrabber::open(camera, 30.0)
            .map_err(|e| CliError::bad_input(format!("--camera {camera}: {e}")))?;
    }
    let dir = robot
        .out
        .clone()
        .unwrap_or_else(|| crate::task::folder::default_folder(task.name()));
    let folder = std::sync::Arc::new(RunFolder::create(&dir).map_err(CliError::BadInput)?);
    let mut session = Session::open(scene, &at, opts).map_err(CliError::Failed)?;
    session.live.record_into(Some(folder.recording()));
    let quiet = g.json;
    let log = std::sync::Arc::clone(&folder);
    let events: EventSink = std::sync::Arc::new(move |e: &TaskEvent| {
        log.event(e);
        if !quiet {
            print_event(e);
        }
    });
    let outcome = task.run(&mut session, &Control::new(), &events);
    session.live.record_into(None);
    drop(events);
    let folder = std::sync::Arc::try_unwrap(folder)
        .map_err(|_| CliError::Failed(anyhow::anyhow!("the run folder is still in use")))?;
    let summary = folder
        .finish(scene, task.name(), &outcome)
        .map_err(CliError::Failed)?;
    if g.json {
        println!("{}", serde_json::to_string(&summary).unwrap_or_default());
    } else {
        println!(
            "{}: {}\nfolder: {} (report.html, run.mcap, run.log, summary.json)",
            if outcome.success { "done" } else { "FAILED" },
            outcome.message,
            dir.display()
        );
    }
    Ok(if outcome.success {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// One event as a line on stderr (looks and primitives are left to the log).
fn print_event(e: &TaskEvent) {
    let line = match e {
        TaskEvent::Started { summary, .. } => format!("started: {summary}"),
        TaskEvent::Plan { note, .. } => format!("plan: {note}"),
        TaskEvent::Replan { note } => format!("re-plan: {note}"),
        TaskEvent::Recovery { count } => format!("link recovered ({count} so far)"),
        TaskEvent::Stall { note } => format!("stall: {note}"),
        TaskEvent::Lost { note } => format!("lost: {note}"),
        TaskEvent::Progress { note, samples, .. } => match samples {
            Some(n) => format!("{n} samples {note}"),
            None => note.clone(),
        },
        TaskEvent::Paused => "paused".into(),
        TaskEvent::Resumed => "resumed".into(),
        TaskEvent::Done { success, message } => {
            format!("{}: {message}", if *success { "done" } else { "failed" })
        }
        TaskEvent::Look { .. } | TaskEvent::Primitive { .. } => return,
    };
    eprintln!("{line}");
}

/// `pushbot collect --port P --camera C`: Algorithm 1 on the robot, into `--out` (resumed when it
/// has samples already).
pub fn collect_on_robot(g: &Global, a: &super::strategy_args::CollectArgs) -> CliResult {
    use crate::exec::collect::CollectParams;
    let name = a
        .scene
        .clone()
        .unwrap_or_else(|| format!("lau-{}", a.object));
    let scene = pushbot_world::Scene::preset_or_file(&name)
        .map_err(|e| CliError::bad_input(format!("--scene {name}: {e}")))?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.strategy", a.object)));
    let params = a.active.apply(CollectParams {
        initial: a.initial,
        streak: a.streak,
        max_queries: a.max_queries,
        seed: g.seed,
        ..CollectParams::default()
    })?;
    let object = object_id(&scene, &a.object);
    let task = crate::task::collect::Collect::new(&scene, &object, out, params).map_err(bad)?;
    let robot = RobotArgs {
        port: a.port.clone(),
        camera: a.camera.clone(),
        out: a.run_dir.clone(),
        sim_speed: 1.0,
    };
    run_task(g, &scene, Task::Collect(task), &robot)
}

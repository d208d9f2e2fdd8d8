//! The `pushbot` command line: `pushbot <noun> <verb>`, the same global flags everywhere.
//!
//! Exit codes: 0 success, 1 the task failed (goal not reached, no plan exists, the robot
//! faulted, the link died), 2 bad input (arguments, scene files, ports that are not serial).
//! Errors go to stderr as `error: …`; with `--json` they are also printed on stdout as one
//! JSON object `{"error": {"kind": "bad_input" | "failed", "message": …, "exit_code": …}}`.
//! Every command's `--help` ends with an example ([`EXAMPLES`]).

use std::process::ExitCode;

use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};

pub mod bench_eval;
pub mod console;
#[cfg(feature = "sim")]
mod data_need;
pub mod demo;
#[cfg(feature = "sim")]
mod eval_merge;
pub mod lens;
pub mod link_bench;
pub mod rearrange;
pub mod replay;
pub mod robot;
pub mod run;
pub mod scene;
pub mod stable;
pub mod stable_run;
pub mod strategy;
pub mod strategy_args;
#[cfg(feature = "sim")]
mod strategy_sim;
pub mod vision;

/// `--sim-camera`: what the simulated robot sees the table with.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimCameraArg {
    /// The simulator's poses with Gaussian noise.
    Truth,
    /// Rendered frames read by the host's vision pipeline.
    Rendered,
}

/// Flags every command takes.
#[derive(Args, Debug, Clone)]
pub struct Global {
    /// Print one JSON object (or JSON lines for streams) instead of text.
    #[arg(long, global = true, help_heading = GLOBAL)]
    pub json: bool,
    /// Seed for everything random (simulation noise, sampling).
    #[arg(long, global = true, help_heading = GLOBAL, default_value_t = 1)]
    pub seed: u64,
    /// More log output (-v info, -vv debug, -vvv trace). Logs go to stderr.
    #[arg(short, long, global = true, help_heading = GLOBAL, action = clap::ArgAction::Count)]
    pub verbose: u8,
    /// When the robot's serial port goes away (a USB re-enumeration), wait this many seconds of
    /// wall time for it to come back and go on; without it, a vanished port is an error at once.
    #[arg(long, global = true, help_heading = GLOBAL, value_name = "SECONDS")]
    pub reconnect: Option<f64>,
    /// Do not recover a broken link (a cut, a vanished port): end the task with an error
    /// instead of reconnecting, clearing the link's fault and going on from the measured pose.
    #[arg(long, global = true, help_heading = GLOBAL)]
    pub no_recover: bool,
    /// The camera's lens: a ROS `camera_info` or OpenCV `FileStorage` YAML file (intrinsics and
    /// `plumb_bob` distortion), for commands that use a camera; overrides the scene's
    /// `camera.intrinsics`.
    #[arg(long, global = true, help_heading = GLOBAL, value_name = "FILE")]
    pub intrinsics: Option<std::path::PathBuf>,
}

impl Global {
    /// The lens `--intrinsics` names, read and checked.
    pub fn lens(&self) -> Result<Option<pushbot_world::lens::Intrinsics>, CliError> {
        match &self.intrinsics {
            Some(p) => pushbot_world::lens_file::read_intrinsics(p)
                .map(Some)
                .map_err(|e| CliError::bad_input(format!("--intrinsics: {e}"))),
            None => Ok(None),
        }
    }

    /// The serial link's settings these flags ask for.
    pub fn link_options(&self) -> Result<crate::robot::LinkOptions, CliError> {
        let mut o = crate::robot::LinkOptions::default();
        if let Some(s) = self.reconnect {
            if !(s.is_finite() && (0.0..=86_400.0).contains(&s)) {
                return Err(CliError::bad_input(format!(
                    "--reconnect must be a number of seconds in 0..=86400, not {s}"
                )));
            }
            o.reconnect_timeout = std::time::Duration::from_secs_f64(s);
        }
        Ok(o)
    }
}

/// pushbot: a small differential-drive robot that rearranges and delivers objects by pushing.
/// `pushbot --version`: the crate's version and the git revision it was built from
/// (`host/build.rs`; `unknown` outside a git checkout).
pub const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (",
    env!("PUSHBOT_GIT_REVISION"),
    ")"
);

/// The heading under which a command's research and tuning options stand in its `--help`,
/// after the options a user needs.
pub const ADVANCED: &str = "Advanced options";

/// The heading of an evaluation's options for running on the robot rather than in simulation.
pub const ROBOT: &str = "On the robot";

/// The heading of the options every command takes.
pub const GLOBAL: &str = "Global options";

#[derive(Parser, Debug)]
#[command(name = "pushbot", version = VERSION, about, long_about = None)]
pub struct Cli {
    #[command(flatten)]
    pub global: Global,
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// The whole system in one command: the built-in simulated target (or --port/--camera),
    /// a learned delivery, a rearrangement and a stable push, and a report folder.
    Demo(demo::DemoArgs),
    /// The operator's page in the browser: the camera, the table, goals by clicking, plan,
    /// run, pause, stop and an emergency stop.
    Console(console::ConsoleArgs),
    /// Talk to the robot: info, move, spin, stop, estop, clear-faults.
    Robot(robot::RobotArgs),
    /// Pushing mechanics of an object: STABLE per edge, controllability (Lynch & Mason §3).
    Mechanics(stable::MechanicsArgs),
    /// Plan a task without running it.
    #[command(subcommand)]
    Plan(PlanCommand),
    /// Collect a pushing strategy for an object (Lau et al. Algorithm 1): on the robot with
    /// --port/--camera, else in simulation.
    Collect(strategy_args::CollectArgs),
    /// Evaluate: `eval delivery` (Lau et al. Fig. 11, learned vs dipole).
    Eval(strategy_args::EvalArgs),
    /// Run one task on the robot (simulated or real).
    #[command(subcommand)]
    Run(run::RunCommand),
    /// Calibrate the overhead camera from markers at known table positions; `calibrate lens`
    /// finds the lens's intrinsics and distortion from frames of a printed board
    /// (`calibrate board` writes it).
    Calibrate(lens::CalibrateCommand),
    /// Track the robot, objects and goals with the overhead camera (one line per frame).
    Track(vision::TrackArgs),
    /// Re-run tracking from a recording (`--record`, the demo's run.mcap) and write its report.
    Replay(replay::ReplayArgs),
    /// Measure planners and pipelines; prints numbers.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Scene files: check one (`scene check`), list the built-in presets (`scene list`).
    #[command(subcommand)]
    Scene(scene::SceneCommand),
}

/// `pushbot plan …`.
#[derive(Subcommand, Debug)]
pub enum PlanCommand {
    /// Rearrange movables by pushing, optimally (Ben-Shahar & Rivlin).
    Rearrange(rearrange::PlanArgs),
    /// Stable pushing among obstacles (Lynch & Mason §4).
    Stable(stable::PlanStableArgs),
}

/// `pushbot bench …`.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// The rearrangement planner on large rooms: the exact cost map on every core (time, states/s,
    /// cores busy, peak memory) and the practical mode (its cost over the optimum).
    Rearrange(rearrange::BenchArgs),
    /// Plan time of the stable-pushing presets next to the paper's.
    Stable(stable::BenchStableArgs),
    /// Commands through a faulty wire to the built-in simulated target: what completed, what
    /// the robot executed twice, watchdog trips, retries, latency.
    Link(link_bench::BenchLinkArgs),
    /// The delivery evaluation (Lau et al. Fig. 11) with the truth camera and with the rendered
    /// one: trials per second of wall time and the simulation's real-time factor.
    Eval(bench_eval::BenchEvalArgs),
    #[command(flatten)]
    Vision(vision::BenchCommand),
    #[command(flatten)]
    Strategy(strategy_args::BenchCmd),
}

/// How a command that ran to its end went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// It did what was asked: exit 0.
    Success,
    /// It ran but the task failed (no plan, goal not reached, fault): exit 1.
    TaskFailed,
}

/// Why a command could not do its work.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The input was wrong (arguments, files, devices): exit 2.
    #[error("{0:#}")]
    BadInput(anyhow::Error),
    /// Something failed while working (link lost, I/O): exit 1.
    #[error("{0:#}")]
    Failed(#[from] anyhow::Error),
}

impl CliError {
    /// A bad-input error with a message.
    pub fn bad_input(msg: impl std::fmt::Display) -> Self {
        CliError::BadInput(anyhow::anyhow!("{msg}"))
    }
}

/// The error of a command that needs the built-in simulated target in a build without it
/// (`--no-default-features`): exit 2, naming what to give instead.
#[cfg(not(feature = "sim"))]
pub fn no_simulated_target() -> CliError {
    CliError::bad_input(
        "this build of pushbot has no simulated target (built without the `sim` feature): \
         give --port PATH (and --camera SRC) for a real robot",
    )
}

/// What every command's `run` returns.
pub type CliResult = Result<Status, CliError>;

/// An example for every command, by its path below `pushbot` (`""` is `pushbot` itself):
/// shown at the end of its `--help`. Each line is a whole command line that parses.
pub const EXAMPLES: &[(&str, &str)] = &[
    (
        "",
        "pushbot robot info\n  pushbot plan rearrange --scene A1 --svg a1.svg",
    ),
    (
        "robot",
        "pushbot robot info --port /dev/ttyACM0\n  pushbot robot move --distance 0.2 --scene three-boxes",
    ),
    (
        "robot info",
        "pushbot robot info --port /dev/ttyACM0 --json",
    ),
    (
        "robot move",
        "pushbot robot move --distance -0.1 --speed 0.05 --port /dev/ttyACM0",
    ),
    ("robot spin", "pushbot robot spin --angle -90 --rate 45"),
    ("robot stop", "pushbot robot stop --port /dev/ttyACM0"),
    ("robot estop", "pushbot robot estop --port /dev/ttyACM0"),
    (
        "robot clear-faults",
        "pushbot robot clear-faults --port /dev/ttyACM0",
    ),
    ("mechanics", "pushbot mechanics --scene fig13 --json"),
    ("plan", "pushbot plan stable --scene fig16 --svg fig16.svg"),
    (
        "plan rearrange",
        "pushbot plan rearrange --scene A1 --svg a1.svg",
    ),
    (
        "plan stable",
        "pushbot plan stable --scene fig15 --exact-goal --svg fig15.svg",
    ),
    (
        "collect",
        "pushbot collect --object irregular --out irregular.strategy --seed 3",
    ),
    (
        "eval",
        "pushbot eval delivery --scene lau-irregular --start A,C --trials 5",
    ),
    (
        "eval delivery",
        "pushbot eval delivery --scene lau-irregular --strategy irregular.strategy --trials 5",
    ),
    (
        "calibrate",
        "pushbot calibrate --camera /dev/video0 --scene lau-irregular --out calibration.json",
    ),
    (
        "calibrate lens",
        "pushbot calibrate lens --frames board-frames/ --layout board.toml --out lens.yaml",
    ),
    ("calibrate board", "pushbot calibrate board --out board.svg"),
    (
        "track",
        "pushbot track --camera sim:127.0.0.1:5600 --scene lau-irregular --frames 100 --json",
    ),
    ("replay", "pushbot replay pushbot-demo/run.mcap --json"),
    ("bench", "pushbot bench stable --repeat 3"),
    ("bench rearrange", "pushbot bench rearrange --quick"),
    ("bench stable", "pushbot bench stable --repeat 3 --json"),
    (
        "bench link",
        "pushbot bench link --commands 10000 --corrupt 0.01 --frame-loss 0.05 --duplicate 0.01",
    ),
    ("bench vision", "pushbot bench vision --frames 50"),
    (
        "bench knn",
        "pushbot bench knn --samples 10000 --queries 500",
    ),
    (
        "eval stable",
        "pushbot eval stable --scene fig15 --trials 20 --perturb --seed 1 --json",
    ),
    (
        "run",
        "pushbot run deliver --object irregular --goal 1.0,0.6",
    ),
    (
        "run deliver",
        "pushbot run deliver --object irregular --goal 1.0,0.6 --port /dev/ttyACM0 --camera /dev/video0",
    ),
    (
        "run rearrange",
        "pushbot run rearrange --scene A1 --goal box1=0.35,0.45 --mode exact",
    ),
    (
        "run stable",
        "pushbot run stable --scene fig15 --goal 0.6,0.5,90",
    ),
    (
        "console",
        "pushbot console --scene lau-obstacles\n  pushbot console --port /dev/ttyACM0 --camera /dev/video0 --scene my-table.toml",
    ),
    ("scene", "pushbot scene check --scene my-table.toml"),
    (
        "scene check",
        "pushbot scene check --scene my-table.toml --json",
    ),
    ("scene list", "pushbot scene list"),
];

/// The exit codes, as `pushbot --help` states them.
const EXIT_CODES: &str = "\n\nExit status: 0 success; 1 the task failed (no plan exists, goal not \
     reached, the robot faulted, the link died); 2 bad input (arguments, files, devices).\n\
     Logs go to stderr (-v info, -vv debug, -vvv trace, or PUSHBOT_LOG=<filter>).";

/// Report a task that ran but failed with `message` (exit code 1 follows): `error: …` on
/// stderr, and with `--json` the same error object on stdout as [`main`] prints.
pub fn task_failed(g: &Global, message: &str) -> Status {
    eprintln!("error: {message}");
    if g.json {
        print_json_error("failed", message, 1);
    }
    Status::TaskFailed
}

fn with_examples(mut cmd: clap::Command, path: &str) -> clap::Command {
    if let Some((_, ex)) = EXAMPLES.iter().find(|(p, _)| *p == path) {
        let mut help = format!("Example:\n  {ex}");
        if path.is_empty() {
            help.push_str(EXIT_CODES);
        }
        cmd = cmd.after_help(help);
    }
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|c| c.get_name().to_owned())
        .collect();
    for name in names {
        let sub_path = if path.is_empty() {
            name.clone()
        } else {
            format!("{path} {name}")
        };
        cmd = cmd.mut_subcommand(&name, |c| with_examples(c, &sub_path));
    }
    cmd
}

/// The `pushbot` command line as clap sees it, with [`EXAMPLES`] in each command's help.
pub fn command() -> clap::Command {
    with_examples(Cli::command(), "")
}

/// Parse arguments, run, map the result to an exit code.
pub fn main() -> ExitCode {
    let json = std::env::args_os().any(|a| a == "--json");
    let cli = match command()
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m))
    {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version are "errors" that print to stdout and exit 0.
            if json && e.use_stderr() {
                let text = e.render().to_string();
                let first = text.lines().next().unwrap_or_default();
                print_json_error("bad_input", first.trim_start_matches("error: "), 2);
            }
            e.exit()
        }
    };
    init_logging(cli.global.verbose);
    let json = cli.global.json;
    let result = run(cli);
    let (kind, e, code) = match result {
        Ok(Status::Success) => return ExitCode::SUCCESS,
        Ok(Status::TaskFailed) => return ExitCode::from(1),
        Err(CliError::Failed(e)) => ("failed", e, 1),
        Err(CliError::BadInput(e)) => ("bad_input", e, 2),
    };
    eprintln!("error: {e:#}");
    if json {
        print_json_error(kind, &format!("{e:#}"), code);
    }
    ExitCode::from(code)
}

fn print_json_error(kind: &str, message: &str, code: u8) {
    let v = serde_json::json!({"error": {"kind": kind, "message": message, "exit_code": code}});
    println!("{v}");
}

fn init_logging(verbose: u8) {
    // The firmware's own log (when the built-in simulated target runs it in this process) is the
    // robot's business: its stalls and timeouts reach the host as faults over the link anyway.
    let level = match verbose {
        0 => "warn,pushbot_firmware=error",
        1 => "info,pushbot_firmware=warn",
        2 => "debug",
        _ => "trace",
    };
    let filter = tracing_subscriber::EnvFilter::try_from_env("PUSHBOT_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(level));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> CliResult {
    let Cli { global, command } = cli;
    match command {
        Command::Demo(args) => demo::run(&global, args),
        Command::Console(a) => console::run(&global, &a),
        Command::Robot(args) => robot::run(&global, args),
        Command::Mechanics(a) => stable::run_mechanics(&global, &a),
        Command::Plan(PlanCommand::Rearrange(args)) => rearrange::plan(&global, args),
        Command::Plan(PlanCommand::Stable(a)) => stable::run_plan(&global, &a),
        Command::Bench(BenchCommand::Rearrange(args)) => rearrange::bench(&global, args),
        Command::Bench(BenchCommand::Stable(a)) => stable::run_bench(&global, &a),
        Command::Bench(BenchCommand::Link(a)) => link_bench::run(&global, &a),
        Command::Bench(BenchCommand::Eval(a)) => bench_eval::run(&global, &a),
        Command::Calibrate(a) => lens::run(&global, a),
        Command::Track(a) => vision::track(&global, a),
        Command::Replay(a) => replay::run(&global, a),
        Command::Bench(BenchCommand::Vision(b)) => vision::bench(&global, b),
        Command::Bench(BenchCommand::Strategy(cmd)) => {
            strategy::run_bench(&global, strategy_args::BenchArgs { cmd })
        }
        Command::Collect(args) => strategy::run_collect(&global, args),
        Command::Eval(strategy_args::EvalArgs {
            cmd: strategy_args::EvalCmd::Stable(a),
        }) => stable_run::eval(&global, &a),
        Command::Eval(args) => strategy::run_eval(&global, args),
        Command::Run(cmd) => run::run(&global, cmd),
        Command::Scene(cmd) => scene::run(&global, cmd),
    }
}

/// A progress bar on stderr for `len` steps (hidden with `--json` and off a terminal).
pub fn progress_bar(global: &Global, len: u64) -> indicatif::ProgressBar {
    if global.json || !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::with_draw_target(
        Some(len),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{elapsed_precise} samples {pos} {wide_bar} {msg}")
    {
        pb.set_style(style);
    }
    pb
}

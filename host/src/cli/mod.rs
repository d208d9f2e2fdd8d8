//! The `pushbot` command line: `pushbot <noun> <verb>`, the same global flags everywhere.
//!
//! Exit codes: 0 success, 1 the task failed (goal not reached, no plan exists, the robot
//! faulted, the link died), 2 bad input (arguments, scene files, ports that are not serial).

use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

pub mod demo;
pub mod rearrange;
pub mod robot;
pub mod stable;
pub mod strategy;
pub mod vision;

/// Flags every command takes.
#[derive(Args, Debug, Clone)]
pub struct Global {
    /// Print one JSON object (or JSON lines for streams) instead of text.
    #[arg(long, global = true)]
    pub json: bool,
    /// Seed for everything random (simulation noise, sampling).
    #[arg(long, global = true, default_value_t = 1)]
    pub seed: u64,
    /// More log output (-v info, -vv debug, -vvv trace). Logs go to stderr.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    pub verbose: u8,
}

/// pushbot: a small differential-drive robot that rearranges and delivers objects by pushing.
#[derive(Parser, Debug)]
#[command(name = "pushbot", version, about, long_about = None)]
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
    /// Talk to the robot: info, move, spin, stop, estop, clear-faults.
    Robot(robot::RobotArgs),
    /// Pushing mechanics of an object: STABLE per edge, controllability (Lynch & Mason §3).
    Mechanics(stable::MechanicsArgs),
    /// Plan a task without running it.
    #[command(subcommand)]
    Plan(PlanCommand),
    /// Collect a pushing strategy for an object (Lau et al. Algorithm 1), in simulation.
    Collect(strategy::CollectArgs),
    /// Evaluate: `eval delivery` (Lau et al. Fig. 11, learned vs dipole).
    Eval(strategy::EvalArgs),
    /// Calibrate the overhead camera from markers at known table positions.
    Calibrate(vision::CalibrateArgs),
    /// Track the robot, objects and goals with the overhead camera (one line per frame).
    Track(vision::TrackArgs),
    /// Measure planners and pipelines; prints numbers.
    #[command(subcommand)]
    Bench(BenchCommand),
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
    /// Cost-map building of the rearrangement planner on large rooms.
    Rearrange(rearrange::BenchArgs),
    /// Plan time of the stable-pushing presets next to the paper's.
    Stable(stable::BenchStableArgs),
    #[command(flatten)]
    Vision(vision::BenchCommand),
    #[command(flatten)]
    Strategy(strategy::BenchCmd),
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

/// What every command's `run` returns.
pub type CliResult = Result<Status, CliError>;

/// Parse arguments, run, map the result to an exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    init_logging(cli.global.verbose);
    let result = run(cli);
    match result {
        Ok(Status::Success) => ExitCode::SUCCESS,
        Ok(Status::TaskFailed) => ExitCode::from(1),
        Err(CliError::Failed(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
        Err(CliError::BadInput(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn init_logging(verbose: u8) {
    let level = match verbose {
        0 => "warn",
        1 => "info",
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
        Command::Robot(args) => robot::run(&global, args),
        Command::Mechanics(a) => stable::run_mechanics(&global, &a),
        Command::Plan(PlanCommand::Rearrange(args)) => rearrange::plan(&global, args),
        Command::Plan(PlanCommand::Stable(a)) => stable::run_plan(&global, &a),
        Command::Bench(BenchCommand::Rearrange(args)) => rearrange::bench(&global, args),
        Command::Bench(BenchCommand::Stable(a)) => stable::run_bench(&global, &a),
        Command::Calibrate(a) => vision::calibrate(&global, a),
        Command::Track(a) => vision::track(&global, a),
        Command::Bench(BenchCommand::Vision(b)) => vision::bench(&global, b),
        Command::Bench(BenchCommand::Strategy(cmd)) => {
            strategy::run_bench(&global, strategy::BenchArgs { cmd })
        }
        Command::Collect(args) => strategy::run_collect(&global, args),
        Command::Eval(args) => strategy::run_eval(&global, args),
    }
}

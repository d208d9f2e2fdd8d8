//! `pushbot bench eval`: arguments and printing of the delivery evaluation's speed with each
//! simulated camera (`crate::experiments::eval_bench`, which needs the built-in simulated
//! target).

use std::path::PathBuf;

use clap::Args;

use super::strategy_args::MethodArg;
use super::{CliError, CliResult, Global};
use crate::experiments::trials::parse_starts;

/// `pushbot bench eval`.
#[derive(Args, Debug, Clone)]
#[command(
    after_help = "Example:\n  pushbot bench eval --scene lau-snake --start A,B --trials 2 \
                        --strategy-dir results/fig11-rendered/strategies --json"
)]
pub struct BenchEvalArgs {
    /// Scene preset or file of the trials.
    #[arg(long, default_value = "lau-irregular")]
    pub scene: String,
    /// Start positions: A..F, A,C or B.
    #[arg(long, default_value = "A..F")]
    pub start: String,
    /// Trials per start position and method.
    #[arg(long, default_value_t = 1)]
    pub trials: usize,
    /// Method(s).
    #[arg(long, value_enum, default_value_t = MethodArg::Both)]
    pub method: MethodArg,
    /// Pushing strategy file of the scene's object.
    #[arg(long, conflicts_with = "strategy_dir")]
    pub strategy: Option<PathBuf>,
    /// Directory of cached strategies `<scene>.strategy` (as `eval delivery`'s): loaded when
    /// present, otherwise collected there first (not timed). Without it or `--strategy`, one
    /// is collected first into a temporary file.
    #[arg(long)]
    pub strategy_dir: Option<PathBuf>,
    /// Time limit of one trial, s of simulated time.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 480.0)]
    pub time_limit: f64,
}

impl BenchEvalArgs {
    fn check(&self) -> Result<Vec<String>, CliError> {
        if self.trials == 0 {
            return Err(CliError::bad_input("--trials must be at least 1"));
        }
        if !(self.time_limit.is_finite() && self.time_limit > 0.0) {
            return Err(CliError::bad_input("--time-limit must be a positive time"));
        }
        parse_starts(&self.start).map_err(CliError::bad_input)
    }
}

/// Run `pushbot bench eval`.
#[cfg(feature = "sim")]
pub fn run(g: &Global, a: &BenchEvalArgs) -> CliResult {
    use super::Status;
    use super::strategy_args::scene_with_starts;
    use crate::exec::collect::CollectParams;
    use crate::exec::deliver::DeliveryParams;
    use crate::experiments::delivery::collect_or_load;
    use crate::experiments::eval_bench::bench;
    use crate::experiments::strategy_eval::{Method, TrialSetup};
    use crate::sim::robot::SimRobotOptions;
    use crate::strategy::regression::KernelParams;

    let starts = a.check()?;
    let scene = scene_with_starts(&a.scene, &starts)?;
    let setup = TrialSetup {
        scene,
        object: None,
        sim: SimRobotOptions {
            seed: g.seed,
            ..SimRobotOptions::default()
        },
        delivery: DeliveryParams {
            time_limit: a.time_limit,
            ..DeliveryParams::default()
        },
        kernel: KernelParams::default(),
    };
    setup.goal().map_err(CliError::BadInput)?;
    let methods = a.method.methods();
    let samples = if !methods.contains(&Method::Learned) {
        Vec::new()
    } else if let Some(path) = &a.strategy {
        crate::strategy::store::load(path)
            .map_err(|e| CliError::bad_input(e.to_string()))?
            .samples
    } else {
        let name = a.scene.replace(['/', '.'], "_");
        let (file, temporary) = match &a.strategy_dir {
            Some(dir) => {
                std::fs::create_dir_all(dir).map_err(|e| {
                    CliError::bad_input(format!("cannot create {}: {e}", dir.display()))
                })?;
                (dir.join(format!("{name}.strategy")), false)
            }
            None => (
                std::env::temp_dir().join(format!(
                    "pushbot-bench-eval-{}-{name}.strategy",
                    std::process::id()
                )),
                true,
            ),
        };
        let params = CollectParams {
            seed: g.seed,
            ..CollectParams::default()
        };
        let pb = super::progress_bar(g, params.initial as u64);
        let got = collect_or_load(
            &setup.scene,
            None,
            &file,
            setup.sim,
            &params,
            setup.kernel,
            &pb,
        );
        pb.finish_and_clear();
        if temporary {
            let _ = std::fs::remove_file(&file);
        }
        got.map_err(CliError::Failed)?.0
    };
    let r = bench(&setup, &methods, &samples, &starts, a.trials).map_err(CliError::Failed)?;
    if g.json {
        let line = serde_json::to_string(&r).map_err(|e| CliError::Failed(e.into()))?;
        println!("{line}");
        return Ok(Status::Success);
    }
    println!(
        "{} trials of {} (starts {}, {} a cell), on {} cores",
        r.truth.trials,
        r.scene,
        starts.join(","),
        r.trials_per_cell,
        r.truth.threads
    );
    println!("| camera   | trials/s | real-time factor | wall s | simulated s | delivered |");
    println!("|----------|---------:|-----------------:|-------:|------------:|----------:|");
    for c in [&r.truth, &r.rendered] {
        let delivered = format!("{} / {}", c.successes, c.trials);
        println!(
            "| {:<8} | {:>8.3} | {:>15.0}× | {:>6.1} | {:>11.1} | {delivered:>9} |",
            c.camera, c.trials_per_s, c.realtime_factor, c.wall_s, c.sim_s
        );
    }
    Ok(Status::Success)
}

/// Run `pushbot bench eval` (this build has no simulated target).
#[cfg(not(feature = "sim"))]
pub fn run(_g: &Global, a: &BenchEvalArgs) -> CliResult {
    a.check()?;
    Err(super::no_simulated_target())
}

//! `pushbot collect`, `pushbot eval delivery` and `pushbot bench knn`: the learned pushing
//! strategy of Lau, Mitani & Igarashi (collection, Algorithm 1; delivery, Algorithm 2) and the
//! dipole-field baseline, run in the in-process simulation.

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pushbot_world::Scene;
use serde_json::json;

use super::{CliError, CliResult, Global, Status};
use crate::exec::collect::{CollectParams, bring_inside, collect};
use crate::exec::deliver::{DeliveryParams, deliver_dipole, deliver_learned};
use crate::exec::deliver_path::deliver_among_obstacles;
use crate::exec::{LiveOptions, LiveRobot};
use crate::experiments::trials::{Method, summarise};
use crate::planner::global::{ObstacleParams, scene_goal, scene_obstacles};
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::Sample;
use crate::strategy::store;

/// Settings shared by collection and evaluation.
#[derive(Args, Debug, Clone)]
pub struct SimArgs {
    /// Camera position noise (standard deviation), mm.
    #[arg(long, default_value_t = 1.0)]
    pub noise_mm: f64,
    /// Camera heading noise (standard deviation), degrees.
    #[arg(long, default_value_t = 0.5)]
    pub noise_deg: f64,
    /// How far inside the table edge the object's boundary lies, m [default: 0.1 in simulation,
    /// whose table gets --table-margin of extra room; 0.2 with --hil, where the table is the
    /// real one and the robot needs room to get behind an object at the boundary]
    #[arg(long)]
    pub boundary_inset: Option<f64>,
    /// Extra simulated table beyond the scene's on every side (room for the robot), m.
    #[arg(long, default_value_t = 0.25)]
    pub table_margin: f64,
    /// Kernel width K_w of the regression, m (the paper: 8 px ≈ 1.8 cm).
    #[arg(long, default_value_t = 0.018)]
    pub kernel_width: f64,
    /// Neighbours k of the regression.
    #[arg(long, default_value_t = 5)]
    pub k: usize,
}

impl SimArgs {
    pub(super) fn kernel(&self) -> Result<KernelParams, CliError> {
        if !(self.kernel_width.is_finite() && self.kernel_width > 0.0) || self.k == 0 {
            return Err(CliError::bad_input(
                "the kernel width must be positive and k at least 1",
            ));
        }
        Ok(KernelParams {
            k: self.k,
            kernel_width: self.kernel_width,
        })
    }
}

/// `pushbot collect`: collect a pushing strategy (Algorithm 1) in the simulation.
#[derive(Args, Debug)]
pub struct CollectArgs {
    /// The object: one of Lau et al.'s six (irregular, irregular-corner, l-shape, wire-cutter,
    /// scissors, snake; scene `lau-<object>`), or an object id of `--scene`.
    #[arg(long)]
    pub object: String,
    /// Scene preset or file (default: `lau-<object>`).
    #[arg(long)]
    pub scene: Option<String>,
    /// Strategy file to append to (default: `<object>.strategy`); an existing file is resumed.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// K: samples of the initial collection.
    #[arg(long, default_value_t = 300)]
    pub initial: usize,
    /// Stop the evaluation after this many straight successful queries.
    #[arg(long, default_value_t = 10)]
    pub streak: usize,
    /// Give up the evaluation after this many queries.
    #[arg(long, default_value_t = 80)]
    pub max_queries: usize,
    /// Write the strategy as an SVG (Fig. 7 style).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    #[command(flatten)]
    pub sim: SimArgs,
}

/// `pushbot eval`: evaluations.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// What to evaluate.
    #[command(subcommand)]
    pub cmd: EvalCmd,
}

/// The evaluations.
#[derive(Subcommand, Debug)]
pub enum EvalCmd {
    /// Deliver the object from named start positions to the goal (Lau et al. Fig. 10–11).
    Delivery(DeliveryArgs),
}

/// Which delivery methods to run.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodArg {
    /// The learned pushing strategy.
    Learned,
    /// The dipole-field baseline.
    Dipole,
    /// Both, side by side.
    Both,
}

/// `pushbot eval delivery`.
#[derive(Args, Debug)]
pub struct DeliveryArgs {
    /// Learned delivery's boundary guard: the band inside the boundary where the wanted object
    /// motion is pulled inward and pushes are shortened, m; 0 is the paper's delivery, which
    /// only fails once the object crosses the boundary [default: 0.06]
    #[arg(long)]
    pub boundary_guard: Option<f64>,
    /// Scene preset or file (e.g. lau-irregular), several separated by commas, or `lau-all`
    /// for the six objects of Lau et al.; scenes with obstacles are delivered along a global
    /// path (learned method).
    #[arg(long)]
    pub scene: String,
    /// Object id in the scene (default: the first).
    #[arg(long)]
    pub object: Option<String>,
    /// Method(s).
    #[arg(long, value_enum, default_value_t = MethodArg::Both)]
    pub method: MethodArg,
    /// Start positions: A..F, A,C or B.
    #[arg(long, default_value = "A..F")]
    pub start: String,
    /// Trials per start position and method.
    #[arg(long, default_value_t = 10)]
    pub trials: usize,
    /// Pushing strategy file (one scene); without it or `--strategy-dir` one is collected in
    /// the simulation first.
    #[arg(long)]
    pub strategy: Option<PathBuf>,
    /// Directory of cached strategies `<scene>.strategy`: loaded when present, otherwise
    /// collected (Algorithm 1, initial + evaluation) and written there.
    #[arg(long)]
    pub strategy_dir: Option<PathBuf>,
    /// K of the collection when no strategy file is given.
    #[arg(long, default_value_t = 300)]
    pub initial: usize,
    /// Time limit of one trial, s of simulated time (the paper: 8 minutes).
    #[arg(long, default_value_t = 480.0)]
    pub time_limit: f64,
    /// Run on the robot through the serial port and the camera (`--port`, `--camera`): collect
    /// (unless `--strategy`) and deliver the one live object from where it is to the goal,
    /// `--trials` times, with one `--method`.
    #[arg(long)]
    pub hil: bool,
    /// With `--hil`: the robot's serial port.
    #[arg(long)]
    pub port: Option<String>,
    /// With `--hil`: the camera (a device, an image folder, a video, or `sim:HOST:PORT`).
    #[arg(long)]
    pub camera: Option<String>,
    /// With `--hil`: the robot's link watchdog, ms of robot time.
    #[arg(long, default_value_t = 1000)]
    pub watchdog_ms: u16,
    /// Collection's evaluation stops after this many straight successful queries (0: initial
    /// collection only).
    #[arg(long, default_value_t = 10)]
    pub streak: usize,
    /// Write the first trial's trajectories of every start (Fig. 8 style) as an SVG.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    #[command(flatten)]
    pub sim: SimArgs,
}

/// `pushbot bench`: benchmarks.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Which benchmark.
    #[command(subcommand)]
    pub cmd: BenchCmd,
}

/// The benchmarks of this module.
#[derive(Subcommand, Debug)]
pub enum BenchCmd {
    /// k-NN regression query time at a strategy size.
    Knn {
        /// Samples in the strategy.
        #[arg(long, default_value_t = 100_000)]
        samples: usize,
        /// Queries timed.
        #[arg(long, default_value_t = 2_000)]
        queries: usize,
    },
}

pub(super) fn progress_bar(global: &Global, len: u64) -> ProgressBar {
    if global.json || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) =
        ProgressStyle::with_template("{elapsed_precise} samples {pos} {wide_bar} {msg}")
    {
        pb.set_style(style);
    }
    pb
}

/// Run `pushbot eval`.
pub fn run_eval(global: &Global, a: EvalArgs) -> CliResult {
    let EvalCmd::Delivery(a) = a.cmd;
    if !(a.time_limit.is_finite() && a.time_limit > 0.0) {
        return Err(CliError::bad_input("--time-limit must be positive"));
    }
    if a.hil {
        let scene =
            Scene::preset_or_file(&a.scene).map_err(|e| CliError::bad_input(e.to_string()))?;
        return run_hil(global, &a, &scene);
    }
    eval_in_sim(global, a)
}

/// `pushbot eval delivery` in the in-process simulation.
#[cfg(feature = "sim")]
fn eval_in_sim(global: &Global, a: DeliveryArgs) -> CliResult {
    super::strategy_sim::eval_in_sim(global, a)
}

/// Without the `sim` feature only `--hil` evaluates.
#[cfg(not(feature = "sim"))]
fn eval_in_sim(_global: &Global, _a: DeliveryArgs) -> CliResult {
    Err(super::no_simulated_target())
}

/// Run `pushbot collect`.
#[cfg(feature = "sim")]
pub fn run_collect(global: &Global, a: CollectArgs) -> CliResult {
    super::strategy_sim::run_collect(global, a)
}

/// Without the `sim` feature there is nothing to collect in.
#[cfg(not(feature = "sim"))]
pub fn run_collect(_global: &Global, _a: CollectArgs) -> CliResult {
    Err(super::no_simulated_target())
}

impl DeliveryArgs {
    /// The delivery parameters these arguments set (time limit, boundary guard).
    pub(super) fn delivery_params(&self) -> Result<DeliveryParams, CliError> {
        let d = DeliveryParams::default();
        let boundary_guard = self.boundary_guard.unwrap_or(d.boundary_guard);
        if !(boundary_guard.is_finite() && boundary_guard >= 0.0) {
            return Err(CliError::bad_input(
                "--boundary-guard must be finite and not negative",
            ));
        }
        Ok(DeliveryParams {
            time_limit: self.time_limit,
            boundary_guard,
            ..d
        })
    }
}

/// `eval delivery --hil`: collect (or load) and deliver through the serial port and the camera.
/// The live object cannot be put back at a start position, so each trial delivers it from
/// wherever it is to the scene's goal, with one method.
fn run_hil(global: &Global, a: &DeliveryArgs, scene: &Scene) -> CliResult {
    let (Some(port), Some(camera)) = (a.port.as_deref(), a.camera.as_deref()) else {
        return Err(CliError::bad_input("--hil needs --port and --camera"));
    };
    let method = match a.method {
        MethodArg::Learned => Method::Learned,
        MethodArg::Dipole => Method::Dipole,
        MethodArg::Both => {
            return Err(CliError::bad_input(
                "--hil runs one method on the one live object: --method learned or dipole",
            ));
        }
    };
    let boundary_inset = a
        .sim
        .boundary_inset
        .unwrap_or(LiveOptions::default().boundary_inset);
    if !(boundary_inset.is_finite() && boundary_inset >= 0.0) {
        return Err(CliError::bad_input(
            "the boundary inset must be finite and not negative",
        ));
    }
    let opts = LiveOptions {
        boundary_inset,
        object: a.object.clone(),
        watchdog_ms: a.watchdog_ms,
        ..LiveOptions::default()
    };
    let mut io = LiveRobot::connect(port, camera, scene, opts).map_err(CliError::Failed)?;
    let goal = scene_goal(scene, a.object.as_deref()).map_err(CliError::BadInput)?;
    let kernel = a.sim.kernel()?;
    let delivery = a.delivery_params()?;
    let mut collection = None;
    let samples: Vec<Sample> = match (method, &a.strategy) {
        (Method::Dipole, _) => Vec::new(),
        (Method::Learned, Some(path)) => {
            store::load(path)
                .map_err(|e| CliError::bad_input(e.to_string()))?
                .samples
        }
        (Method::Learned, None) => {
            let params = CollectParams {
                initial: a.initial,
                streak: a.streak,
                seed: global.seed,
                ..CollectParams::default()
            };
            let mut strategy = PushStrategy::new(Vec::new(), kernel);
            let pb = progress_bar(global, params.initial as u64);
            let rep = collect(&mut io, &mut strategy, &params, &mut |_| Ok(()), &pb)?;
            pb.finish_and_clear();
            collection = Some(rep);
            strategy.samples().to_vec()
        }
    };
    let mut runs = Vec::new();
    for _ in 0..a.trials {
        // A trial starts with the object inside the boundary (Lau et al. §III-A): push it back
        // if the collection or the last trial left it outside.
        bring_inside(
            &mut io,
            delivery.bound_all_margin,
            CollectParams::default().epsilon,
        )?;
        let d = match method {
            Method::Learned => {
                let mut strat = PushStrategy::new(samples.iter().copied(), kernel);
                if scene.obstacles.is_empty() {
                    deliver_learned(&mut io, &mut strat, goal, &delivery, &mut |_| Ok(()))?
                } else {
                    deliver_among_obstacles(
                        &mut io,
                        &mut strat,
                        goal,
                        &scene_obstacles(scene),
                        &delivery,
                        &ObstacleParams::default(),
                        &mut |_| Ok(()),
                    )?
                    .delivery
                }
            }
            Method::Dipole => deliver_dipole(&mut io, goal, &delivery)?,
        };
        runs.push(d);
    }
    let res = summarise("live", method, &runs);
    if global.json {
        println!(
            "{}",
            json!({
                "hil": true,
                "trials": a.trials,
                "scenes": [{
                    "scene": scene.name,
                    "samples": samples.len(),
                    "collection": collection,
                    "results": [res],
                }],
            })
        );
    } else {
        println!(
            "{} live {:?}: {:.0} % of {} | samples {} | final distance {}",
            scene.name,
            method,
            res.success_rate,
            res.trials,
            samples.len(),
            runs.last()
                .map_or("-".into(), |d| format!("{:.3} m", d.final_distance)),
        );
    }
    Ok(if res.success_rate >= 95.0 {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// Run `pushbot bench`.
pub fn run_bench(global: &Global, a: BenchArgs) -> CliResult {
    let BenchCmd::Knn { samples, queries } = a.cmd;
    if samples == 0 || queries == 0 {
        return Err(CliError::bad_input("samples and queries must be positive"));
    }
    let r = crate::strategy::bench::run(samples, queries, global.seed);
    if global.json {
        println!("{}", json!(r));
    } else {
        println!(
            "{} samples: build {:.1} ms, general {:.2} µs, special {:.2} µs, linear {:.1} µs \
             per query",
            r.samples, r.build_ms, r.general_us, r.special_us, r.linear_us
        );
    }
    Ok(Status::Success)
}

//! `pushbot collect`, `pushbot eval delivery` and `pushbot bench knn`: the learned pushing
//! strategy of Lau, Mitani & Igarashi (collection, Algorithm 1; delivery, Algorithm 2) and the
//! dipole-field baseline, run in the in-process simulation.

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pushbot_sim::Scene;
use serde_json::json;

use super::{CliError, CliResult, Global, Status};
use crate::exec::{LiveOptions, LiveRobot};
use crate::sim::robot::{SimRobot, SimRobotOptions};
use crate::strategy::collect::{CollectParams, CollectReport, bring_inside, collect};
use crate::strategy::deliver::{DeliveryParams, deliver_dipole, deliver_learned};
use crate::strategy::eval::{Method, StartResult, TrialSetup, parse_starts, run_start, summarise};
use crate::strategy::figures;
use crate::strategy::obstacles;
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::Sample;
use crate::strategy::store::{self, StrategyWriter};

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
    fn options(&self, seed: u64) -> Result<SimRobotOptions, CliError> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        let boundary_inset = self.boundary_inset.unwrap_or(0.1);
        if !ok(self.noise_mm) || !ok(self.noise_deg) || !ok(boundary_inset) {
            return Err(CliError::bad_input(
                "noise and boundary inset must be finite and not negative",
            ));
        }
        Ok(SimRobotOptions {
            seed,
            position_noise: self.noise_mm * 1e-3,
            heading_noise: self.noise_deg.to_radians(),
            boundary_inset,
            table_margin: self.table_margin,
            ..SimRobotOptions::default()
        })
    }

    fn kernel(&self) -> Result<KernelParams, CliError> {
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

fn progress_bar(global: &Global, len: u64) -> ProgressBar {
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

fn scene_for(object: &str, scene: Option<&str>) -> Result<(Scene, Option<String>), CliError> {
    let (name, id) = match scene {
        Some(s) => (s.to_owned(), Some(object.to_owned())),
        None => (format!("lau-{object}"), None),
    };
    let scene = Scene::preset_or_file(&name).map_err(|e| CliError::bad_input(e.to_string()))?;
    Ok((scene, id))
}

/// Collect in the simulation into `writer`'s file, starting from `existing` samples.
fn collect_in_sim(
    global: &Global,
    scene: Scene,
    object: Option<&str>,
    sim: &SimArgs,
    params: &CollectParams,
    existing: Vec<Sample>,
    writer: Option<&mut StrategyWriter>,
) -> Result<(PushStrategy, CollectReport), CliError> {
    let mut io = SimRobot::new(scene, object, None, sim.options(global.seed)?)
        .map_err(CliError::BadInput)?;
    let mut strategy = PushStrategy::new(existing, sim.kernel()?);
    let pb = progress_bar(global, params.initial as u64);
    let mut w = writer;
    let mut sink = |s: &Sample| -> anyhow::Result<()> {
        if let Some(w) = w.as_deref_mut() {
            w.append(s)?;
        }
        Ok(())
    };
    let rep = collect(&mut io, &mut strategy, params, &mut sink, &pb)?;
    pb.finish_and_clear();
    Ok((strategy, rep))
}

/// Run `pushbot collect`.
pub fn run_collect(global: &Global, a: CollectArgs) -> CliResult {
    let (scene, id) = scene_for(&a.object, a.scene.as_deref())?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.strategy", a.object)));
    let (mut writer, existing) =
        StrategyWriter::open(&out, &a.object).map_err(|e| CliError::bad_input(e.to_string()))?;
    let had = existing.len();
    let params = CollectParams {
        initial: a.initial,
        streak: a.streak,
        max_queries: a.max_queries,
        seed: global.seed,
        ..CollectParams::default()
    };
    let outline = object_outline(&scene, id.as_deref());
    let (strategy, rep) = collect_in_sim(
        global,
        scene,
        id.as_deref(),
        &a.sim,
        &params,
        existing,
        Some(&mut writer),
    )?;
    if let Some(svg) = &a.svg {
        std::fs::write(svg, figures::strategy_svg(strategy.samples(), &outline))
            .map_err(|e| CliError::Failed(anyhow::anyhow!("writing {}: {e}", svg.display())))?;
    }
    if global.json {
        println!(
            "{}",
            json!({"object": a.object, "file": out, "samples_before": had, "report": rep})
        );
    } else {
        println!(
            "{}: {} samples ({} initial, {} supplemental, {} before) in {:.1} simulated min \
             ({:.1} initial); queries {} ok {}; {} straight successes {}",
            a.object,
            rep.total_samples,
            rep.initial_samples,
            rep.supplemental_samples,
            had,
            rep.total_minutes,
            rep.initial_minutes,
            rep.queries,
            rep.successes,
            a.streak,
            if rep.streak_reached {
                "reached"
            } else {
                "NOT reached"
            },
        );
        println!("written to {}", out.display());
    }
    Ok(if rep.streak_reached || a.streak == 0 {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// The object's outline relative to its marker (for figures).
fn object_outline(scene: &Scene, id: Option<&str>) -> Vec<[f64; 2]> {
    let obj = match id {
        Some(id) => scene.object(id),
        None => scene.objects.first(),
    };
    obj.map(|o| {
        let m = o.marker.map_or([0.0, 0.0], |m| [m.x, m.y]);
        o.outline
            .iter()
            .map(|v| [v[0] - m[0], v[1] - m[1]])
            .collect()
    })
    .unwrap_or_default()
}

/// The six objects of Lau et al. (Fig. 6), as preset scenes, in the order of their Fig. 11.
pub const LAU_SCENES: &[&str] = &[
    "lau-irregular",
    "lau-irregular-corner",
    "lau-l-shape",
    "lau-wire-cutter",
    "lau-scissors",
    "lau-snake",
];

/// One scene's evaluation.
#[derive(Debug, serde::Serialize)]
struct SceneEval {
    scene: String,
    samples: usize,
    collection: Option<CollectReport>,
    results: Vec<StartResult>,
}

/// The table of Lau et al. Fig. 11: success % per start (rows) and scene × method (columns).
fn fig11_table(evals: &[SceneEval], starts: &[String], methods: &[Method]) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    let short = |s: &str| s.strip_prefix("lau-").unwrap_or(s).to_owned();
    let name = |m: &Method| match m {
        Method::Learned => "ours",
        Method::Dipole => "dipole",
    };
    let _ = write!(t, "{:<6}", "start");
    for e in evals {
        let w = 9 * methods.len();
        let _ = write!(t, "| {:<w$}", short(&e.scene));
    }
    t.push('\n');
    let _ = write!(t, "{:<6}", "");
    for _ in evals {
        t.push_str("| ");
        for m in methods {
            let _ = write!(t, "{:<9}", name(m));
        }
    }
    t.push('\n');
    for s in starts {
        let _ = write!(t, "{s:<6}");
        for e in evals {
            t.push_str("| ");
            for m in methods {
                let cell = e
                    .results
                    .iter()
                    .find(|r| &r.start == s && r.method == *m)
                    .map_or("-".to_owned(), |r| format!("{:.0}", r.success_rate));
                let _ = write!(t, "{cell:<9}");
            }
        }
        t.push('\n');
    }
    t
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
    let starts = parse_starts(&a.start).map_err(CliError::bad_input)?;
    let names: Vec<String> = if a.scene.trim() == "lau-all" {
        LAU_SCENES.iter().map(|s| (*s).to_owned()).collect()
    } else {
        a.scene
            .split(',')
            .map(|s| s.trim().to_owned())
            .filter(|s| !s.is_empty())
            .collect()
    };
    if names.is_empty() {
        return Err(CliError::bad_input("no scene given"));
    }
    if names.len() > 1 && a.strategy.is_some() {
        return Err(CliError::bad_input(
            "--strategy is one file for one scene; use --strategy-dir with several scenes",
        ));
    }
    let mut scenes = Vec::new();
    for n in &names {
        let scene = Scene::preset_or_file(n).map_err(|e| CliError::bad_input(e.to_string()))?;
        for s in &starts {
            if scene.position(s).is_none() {
                return Err(CliError::bad_input(format!(
                    "scene {} has no start position {s}",
                    scene.name
                )));
            }
        }
        scenes.push(scene);
    }
    let methods: Vec<Method> = match a.method {
        MethodArg::Learned => vec![Method::Learned],
        MethodArg::Dipole => vec![Method::Dipole],
        MethodArg::Both => vec![Method::Dipole, Method::Learned],
    };
    let mut evals = Vec::new();
    let mut trajectories = Vec::new();
    for (name, scene) in names.iter().zip(&scenes) {
        let setup = TrialSetup {
            scene: scene.clone(),
            object: a.object.clone(),
            sim: a.sim.options(global.seed)?,
            delivery: a.delivery_params()?,
            kernel: a.sim.kernel()?,
        };
        setup.goal().map_err(CliError::BadInput)?;
        // The strategy: from a file, from the cache directory (collected there when missing),
        // or collected here first.
        let params = CollectParams {
            initial: a.initial,
            streak: a.streak,
            seed: global.seed,
            ..CollectParams::default()
        };
        let mut collection = None;
        let samples: Vec<Sample> = if !methods.contains(&Method::Learned) {
            Vec::new()
        } else if let Some(path) = &a.strategy {
            store::load(path)
                .map_err(|e| CliError::bad_input(e.to_string()))?
                .samples
        } else if let Some(dir) = &a.strategy_dir {
            std::fs::create_dir_all(dir).map_err(|e| {
                CliError::bad_input(format!("cannot create {}: {e}", dir.display()))
            })?;
            let file = dir.join(format!("{}.strategy", name.replace(['/', '.'], "_")));
            let pb = progress_bar(global, params.initial as u64);
            let (samples, rep) = obstacles::collect_or_load(
                scene,
                a.object.as_deref(),
                &file,
                setup.sim,
                &params,
                setup.kernel,
                &pb,
            )
            .map_err(CliError::Failed)?;
            pb.finish_and_clear();
            collection = rep;
            samples
        } else {
            let mut clear = scene.clone();
            clear.obstacles.clear();
            let (strat, rep) = collect_in_sim(
                global,
                clear,
                a.object.as_deref(),
                &a.sim,
                &params,
                Vec::new(),
                None,
            )?;
            collection = Some(rep);
            strat.samples().to_vec()
        };
        let mut results: Vec<StartResult> = Vec::new();
        for s in &starts {
            for &m in &methods {
                let (res, runs) = run_start(&setup, m, &samples, s, a.trials)?;
                if let Some(first) = runs.into_iter().next()
                    && names.len() == 1
                {
                    trajectories.push((format!("{s} {m:?}"), first.trajectory));
                }
                if !global.json {
                    println!(
                        "{} {} {:>7}: {:>5.1} % of {} | time {} | object path {} | failures {:?}",
                        scene.name,
                        res.start,
                        format!("{m:?}"),
                        res.success_rate,
                        res.trials,
                        res.mean_time_s.map_or("-".into(), |t| format!("{t:.1} s")),
                        res.mean_object_path_m
                            .map_or("-".into(), |t| format!("{t:.2} m")),
                        res.failures,
                    );
                }
                results.push(res);
            }
        }
        evals.push(SceneEval {
            scene: scene.name.clone(),
            samples: samples.len(),
            collection,
            results,
        });
    }
    if let Some(svg) = &a.svg {
        if let [scene] = scenes.as_slice() {
            let goal =
                obstacles::scene_goal(scene, a.object.as_deref()).map_err(CliError::BadInput)?;
            let text = figures::trajectories_svg(&trajectories, scene, goal);
            std::fs::write(svg, text)
                .map_err(|e| CliError::Failed(anyhow::anyhow!("writing {}: {e}", svg.display())))?;
        } else {
            return Err(CliError::bad_input("--svg draws one scene's trajectories"));
        }
    }
    let learned_ok = evals
        .iter()
        .flat_map(|e| &e.results)
        .filter(|r| r.method == Method::Learned)
        .all(|r| r.success_rate >= 95.0);
    if global.json {
        println!(
            "{}",
            json!({
                "trials": a.trials,
                "starts": starts,
                "scenes": evals,
            })
        );
    } else {
        println!("\nSuccess % of {} trials (Lau et al. Fig. 11):", a.trials);
        print!("{}", fig11_table(&evals, &starts, &methods));
    }
    Ok(if learned_ok {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

impl DeliveryArgs {
    /// The delivery parameters these arguments set (time limit, boundary guard).
    fn delivery_params(&self) -> Result<DeliveryParams, CliError> {
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
    let goal = obstacles::scene_goal(scene, a.object.as_deref()).map_err(CliError::BadInput)?;
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
                    obstacles::deliver_among_obstacles(
                        &mut io,
                        &mut strat,
                        goal,
                        &obstacles::scene_obstacles(scene),
                        &delivery,
                        &obstacles::ObstacleParams::default(),
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

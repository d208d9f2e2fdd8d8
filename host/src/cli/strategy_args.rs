//! The arguments of `pushbot collect`, `pushbot eval delivery` and `pushbot bench knn` (the
//! learned pushing strategy of Lau, Mitani & Igarashi), shared by the commands that run on a
//! robot ([`super::strategy`]) and those that run in the simulation (`strategy_sim`).

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};

use super::CliError;
use crate::exec::collect::{CollectParams, DEFAULT_INITIAL};
use crate::exec::deliver::DeliveryParams;
use crate::strategy::active::Selection;
use crate::strategy::regression::{Admission, KernelParams};

/// Settings shared by collection and evaluation.
#[derive(Args, Debug, Clone)]
pub struct SimArgs {
    /// Camera position noise (standard deviation), mm.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 1.0)]
    pub noise_mm: f64,
    /// Camera heading noise (standard deviation), degrees.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 0.5)]
    pub noise_deg: f64,
    /// How far inside the table edge the object's boundary lies, m [default: 0.1 in simulation,
    /// whose table gets --table-margin of extra room; 0.2 with --hil, where the table is the
    /// real one and the robot needs room to get behind an object at the boundary]
    #[arg(long, help_heading = super::ADVANCED)]
    pub boundary_inset: Option<f64>,
    /// Extra simulated table beyond the scene's on every side (room for the robot), m.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 0.25)]
    pub table_margin: f64,
    /// Kernel width K_w of the regression, m (the paper: 8 px ≈ 1.8 cm).
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 0.018)]
    pub kernel_width: f64,
    /// Neighbours k of the regression.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 5)]
    pub k: usize,
    /// How much the special case (re-positioning) prefers pushes that turn the object little:
    /// metres of object motion a radian of turn weighs (0: the paper's motion alone).
    #[arg(long, help_heading = super::ADVANCED, default_value_t = crate::strategy::regression::TURN_WEIGHT)]
    pub turn_weight: f64,
    /// What the simulated robot sees the table with: `truth` (the simulator's poses with the
    /// noise above; fast) or `rendered` (frames rendered from the simulated world — lens,
    /// markers at their heights, blur, noise — read by the host's detector, calibration and
    /// tracker: the camera in the loop). `--figure 11` defaults to `rendered`.
    #[arg(long, help_heading = super::ADVANCED, value_enum)]
    pub sim_camera: Option<super::SimCameraArg>,
}

impl SimArgs {
    pub fn kernel(&self) -> Result<KernelParams, CliError> {
        if !(self.kernel_width.is_finite() && self.kernel_width > 0.0) || self.k == 0 {
            return Err(CliError::bad_input(
                "the kernel width must be positive and k at least 1",
            ));
        }
        if !(self.turn_weight.is_finite() && self.turn_weight >= 0.0) {
            return Err(CliError::bad_input("the turn weight must be a number ≥ 0"));
        }
        Ok(KernelParams {
            k: self.k,
            kernel_width: self.kernel_width,
            turn_weight: self.turn_weight,
        })
    }
}

/// How the initial collection chooses its pushes.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum SelectionArg {
    /// A random spin and push length (the paper).
    Random,
    /// Of several random pushes, the one the strategy knows least.
    Uncertain,
    /// Of several random pushes, the one that, with the contact it leads the robot to, the
    /// strategy knows least; then a push for each way of moving the object no sample covers.
    Explore,
}

/// Which pushes of the collection's evaluation become samples.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeepArg {
    /// Every push (the paper).
    All,
    /// Only pushes into a region the strategy has not seen, or whose outcome it mispredicted.
    Informative,
}

/// How the collection chooses and keeps its pushes (fewer samples to learn than the paper).
#[derive(Args, Debug, Clone)]
pub struct ActiveArgs {
    /// How the initial collection chooses its pushes.
    #[arg(long, help_heading = super::ADVANCED, value_enum, default_value_t = SelectionArg::Explore)]
    pub selection: SelectionArg,
    /// Which pushes of the collection's evaluation are kept as samples.
    #[arg(long, help_heading = super::ADVANCED, value_enum, default_value_t = KeepArg::Informative)]
    pub keep: KeepArg,
    /// With `--keep informative`: a push whose (p, s) lies farther than this from every sample
    /// is new, m [default: 0.01]
    #[arg(long, help_heading = super::ADVANCED)]
    pub novel_distance: Option<f64>,
    /// With `--keep informative`: a push whose robot motion differs by more than this from the
    /// strategy's answer at its (p, s) is a surprise, degrees [default: 20]
    #[arg(long, help_heading = super::ADVANCED)]
    pub surprise_deg: Option<f64>,
}

impl ActiveArgs {
    /// `params` with this selection and admission; an error for a negative or non-finite
    /// threshold.
    pub fn apply(&self, params: CollectParams) -> Result<CollectParams, CliError> {
        let ok = |v: Option<f64>| v.is_none_or(|v| v.is_finite() && v >= 0.0);
        if !ok(self.novel_distance) || !ok(self.surprise_deg) {
            return Err(CliError::bad_input(
                "--novel-distance and --surprise-deg must be finite and not negative",
            ));
        }
        Ok(CollectParams {
            selection: match self.selection {
                SelectionArg::Random => Selection::Random,
                SelectionArg::Uncertain => Selection::Uncertain,
                SelectionArg::Explore => Selection::Explore,
            },
            admission: match self.keep {
                KeepArg::All => None,
                KeepArg::Informative => {
                    let d = Admission::default();
                    Some(Admission {
                        novel_distance: self.novel_distance.unwrap_or(d.novel_distance),
                        surprise: self.surprise_deg.map_or(d.surprise, f64::to_radians),
                    })
                }
            },
            ..params
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
    /// K: samples of the initial collection (the paper's collection: 300 with `--selection
    /// random --keep all`).
    #[arg(long, help_heading = super::ADVANCED, default_value_t = DEFAULT_INITIAL)]
    pub initial: usize,
    /// Stop the evaluation after this many straight successful queries.
    #[arg(long, default_value_t = 10)]
    pub streak: usize,
    /// Give up the evaluation after this many queries.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 80)]
    pub max_queries: usize,
    /// Write the strategy as an SVG (Fig. 7 style).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Collect on a real robot on this serial port (with --camera), seen by the camera; a
    /// stopped collection goes on from the samples already in --out.
    #[arg(long, requires = "camera")]
    pub port: Option<String>,
    /// The overhead camera (/dev/videoN, a folder of frames, sim:HOST:PORT), with --port.
    #[arg(long, requires = "port")]
    pub camera: Option<String>,
    /// The run's folder with --port (default: runs/collect-YYYYMMDD-HHMMSS).
    #[arg(long = "run-dir", value_name = "DIR", requires = "port")]
    pub run_dir: Option<PathBuf>,
    #[command(flatten)]
    pub active: ActiveArgs,
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
    Delivery(Box<DeliveryArgs>),
    /// Stable pushes (Lynch & Mason §4) closed or open loop in perturbed worlds.
    Stable(super::stable_run::StableEvalArgs),
    /// Join the files of a sweep's shards (`eval delivery` or `eval stable` with `--shard K/N
    /// --resume FILE`) into the one table (and figure), as the sweep run whole prints them.
    #[command(
        after_help = "Example:\n  pushbot eval merge fig11-1.jsonl fig11-2.jsonl fig11-3.jsonl --svg fig11.svg"
    )]
    Merge(MergeArgs),
}

/// `pushbot eval merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shards' files, one per shard (in any order).
    #[arg(required = true, value_name = "FILE.jsonl")]
    pub files: Vec<PathBuf>,
    /// Where to draw the figure (default: `fig11.svg` for a `--figure 11` sweep; none for
    /// others, whose one scene's trajectories it draws when given).
    #[arg(long)]
    pub svg: Option<PathBuf>,
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

#[cfg(feature = "sim")]
impl MethodArg {
    /// The methods it names, the baseline first.
    pub fn methods(self) -> Vec<crate::experiments::strategy_eval::Method> {
        use crate::experiments::strategy_eval::Method;
        match self {
            MethodArg::Learned => vec![Method::Learned],
            MethodArg::Dipole => vec![Method::Dipole],
            MethodArg::Both => vec![Method::Dipole, Method::Learned],
        }
    }
}

/// Scene `name` (a preset or a file), refused unless it has every start position of `starts`.
#[cfg(feature = "sim")]
pub fn scene_with_starts(name: &str, starts: &[String]) -> Result<pushbot_world::Scene, CliError> {
    let scene = pushbot_world::Scene::preset_or_file(name)
        .map_err(|e| CliError::bad_input(e.to_string()))?;
    if let Some(s) = starts.iter().find(|s| scene.position(s).is_none()) {
        return Err(CliError::bad_input(format!(
            "scene {} has no start position {s}",
            scene.name
        )));
    }
    Ok(scene)
}

/// `pushbot eval delivery`.
#[derive(Args, Debug)]
pub struct DeliveryArgs {
    /// Learned delivery's boundary guard: the band inside the boundary where the wanted object
    /// motion is pulled inward and pushes are shortened, m; 0 is the paper's delivery, which
    /// only fails once the object crosses the boundary [default: 0.06]
    #[arg(long, help_heading = super::ADVANCED)]
    pub boundary_guard: Option<f64>,
    /// Scene preset or file (e.g. lau-irregular), several separated by commas, or `lau-all`
    /// for the six objects of Lau et al.; scenes with obstacles are delivered along a global
    /// path (learned method).
    #[arg(long, required_unless_present = "figure")]
    pub scene: Option<String>,
    /// Run one of Lau et al.'s evaluations whole and draw it. `11` is Fig. 11 — the six
    /// objects × starts A–F, learned and dipole side by side, `--trials` each, on all cores,
    /// with the rendered camera in the loop (unless `--sim-camera truth`); it prints the table
    /// and writes the figure to `--svg` (default `fig11.svg`). `7` is the data-need curve
    /// (success of `--trials` deliveries per start after every `--every` samples, while
    /// collecting the paper's way and the active way; table printed, SVG to `--svg` [default:
    /// data-need.svg]).
    #[arg(long, value_name = "N")]
    pub figure: Option<u8>,
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
    #[arg(long, help_heading = super::ADVANCED, default_value_t = DEFAULT_INITIAL)]
    pub initial: usize,
    /// Time limit of one trial, s of simulated time (the paper: 8 minutes).
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 480.0)]
    pub time_limit: f64,
    /// Run on the robot through the serial port and the camera (`--port`, `--camera`): collect
    /// (unless `--strategy`) and deliver the one live object from where it is to the goal,
    /// `--trials` times, with one `--method`.
    #[arg(long, help_heading = super::ROBOT)]
    pub hil: bool,
    /// With `--hil`: the robot's serial port.
    #[arg(long, help_heading = super::ROBOT)]
    pub port: Option<String>,
    /// With `--hil`: the camera (a device, an image folder, a video, or `sim:HOST:PORT`).
    #[arg(long, help_heading = super::ROBOT)]
    pub camera: Option<String>,
    /// With `--hil`: the robot's link watchdog, ms of robot time.
    #[arg(long, help_heading = super::ROBOT, default_value_t = 1000)]
    pub watchdog_ms: u16,
    /// With `--hil`: record the run (camera, detections, tracked poses, telemetry) into this
    /// MCAP file, in Foxglove's schemas (`pushbot replay FILE` tracks it again).
    #[arg(long, help_heading = super::ROBOT, value_name = "FILE.mcap", requires = "hil")]
    pub record: Option<PathBuf>,
    /// Collection's evaluation stops after this many straight successful queries (0: initial
    /// collection only).
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 10)]
    pub streak: usize,
    /// Write the first trial's trajectories of every start (Fig. 8 style) as an SVG, and a PNG
    /// of it beside; with `--figure`, the figure.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// With `--figure 7`: samples between the curve's points.
    #[arg(long, help_heading = super::ADVANCED, default_value_t = 25)]
    pub every: usize,
    /// Keep every finished cell (scene × start × method) in this JSON-lines file as it is
    /// done; run again with the same file (the same --trials, --seed, camera and strategies;
    /// starts, methods or scenes may be added) and the cells already in it are not run again.
    /// For evaluations of hours: an interruption loses only the cells that were running. Example: `pushbot eval delivery --figure 11 --trials
    /// 50 --strategy-dir strategies --resume fig11-cells.jsonl`
    #[arg(long, help_heading = super::ADVANCED, value_name = "FILE.jsonl", conflicts_with = "hil")]
    pub resume: Option<PathBuf>,
    /// Run only the K-th of N shares of the sweep's cells (dealt the same way on every
    /// machine), into its own --resume file; `pushbot eval merge` joins the N files into the
    /// one table and figure. Example: `pushbot eval delivery --figure 11 --trials 50
    /// --strategy-dir strategies --shard 2/3 --resume fig11-2.jsonl`
    #[arg(long, help_heading = super::ADVANCED, value_name = "K/N", requires = "resume")]
    pub shard: Option<crate::experiments::shard::Shard>,
    /// Write every trial run into this folder: `SCENE-START-METHOD-TRIAL.json` (how it went,
    /// the robot's and the object's pose after every step) and an SVG drawing of it (tracks,
    /// the object's outline along the way, the stalls recovered). Example: `pushbot eval
    /// delivery --scene lau-zigzag-l --method learned --trials 20 --trace-dir traces`
    #[arg(long, help_heading = super::ADVANCED, value_name = "DIR", conflicts_with = "hil")]
    pub trace_dir: Option<PathBuf>,
    #[command(flatten)]
    pub active: ActiveArgs,
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

impl DeliveryArgs {
    /// The collection's parameters these arguments set (K, streak, the active collection's
    /// options), seeded by `seed`.
    pub fn collect_params(&self, seed: u64) -> Result<CollectParams, CliError> {
        self.active.apply(CollectParams {
            initial: self.initial,
            streak: self.streak,
            seed,
            ..CollectParams::default()
        })
    }

    /// The delivery parameters these arguments set (time limit, boundary guard).
    pub fn delivery_params(&self) -> Result<DeliveryParams, CliError> {
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

//! `pushbot eval stable`: Lynch & Mason's stable pushes (§4) planned
//! for the plated robot and driven closed loop ([`crate::exec::stable_feedback`]) —
//! or open loop, as the paper drives them, with `--open-loop` — on the in-process simulated
//! robot, perturbed with `--perturb` (the scene's `[perturb]` ranges, seeded by `--seed` and
//! the trial number); through a serial port and a camera with `--hil` (the built-in target on
//! a pty with its rendered camera) or `--port`/`--camera` (a real robot). `eval stable --random
//! N` runs the random scenes of `planner::stable::random_scene` (diff-drive or car) instead of
//! one scene.

use clap::Args;

use super::{CliError, CliResult, Global};

/// The arguments `run stable` and `eval stable` share.
#[derive(Args, Debug, Clone)]
pub struct StableRunArgs {
    /// A preset (fig13, fig15, fig16, fig17, fig18: its robot-scale version, the robot's plate
    /// pushing on edge 0) or a scene file with a `[stable]` section whose pusher is a
    /// `diff-drive`. (`eval stable` takes --random instead.)
    #[arg(long)]
    pub scene: Option<String>,
    /// Perturb the simulated world: start pose, frictions, centre of friction, wheel slip and
    /// camera noise drawn from the scene's `[perturb]` ranges (defaults: ±5°, ±10 mm, ±30 %,
    /// 5 mm, ±0.5 %, 1 mm and 0.5°), seeded by --seed and the trial number. The planner keeps
    /// the nominal model.
    #[arg(long)]
    pub perturb: bool,
    /// Drive the plan open loop (as the paper does), for comparison.
    #[arg(long)]
    pub open_loop: bool,
    /// The trial number (`run stable`) or the first one (`eval stable`): with --seed, it picks
    /// the perturbed world.
    #[arg(long, default_value_t = 1)]
    pub trial: u64,
    /// Through a serial port and the camera: the built-in simulated target on a pty with its
    /// rendered camera (AprilTag detection and tracking in the loop), one trial at a time.
    #[arg(long)]
    pub hil: bool,
    /// A real robot's serial port (with --camera); the perturbation does not apply there.
    #[arg(long, requires = "camera")]
    pub port: Option<String>,
    /// The overhead camera (/dev/videoN, a folder, sim:HOST:PORT), with --port.
    #[arg(long, requires = "port")]
    pub camera: Option<String>,
    /// With --hil: simulated seconds per wall second.
    #[arg(long = "sim-speed", default_value_t = 8.0)]
    pub speed: f64,
    /// Write each trial's drawing (the plan, and the slider's executed path over it) into this
    /// folder as `trial-N.svg`.
    #[arg(long)]
    pub svg: Option<std::path::PathBuf>,
    /// In process (without --hil): what the simulated robot sees the table with — `truth` (the
    /// simulator's poses with the perturbation's camera noise; the default) or `rendered`
    /// (frames rendered from the simulated world and read by the host's detector, calibration
    /// and tracker: the camera in the loop, in simulated time).
    #[arg(long, value_enum)]
    pub sim_camera: Option<super::SimCameraArg>,
}

/// `pushbot eval stable`.
#[derive(Args, Debug, Clone)]
pub struct StableEvalArgs {
    #[command(flatten)]
    pub run: StableRunArgs,
    /// Number of trials (trials --trial … --trial + N − 1).
    #[arg(long, default_value_t = 20)]
    pub trials: u64,
    /// Instead of --scene: N random scenes (`planner::stable::random_scene`, seeds --trial …
    /// --trial + N − 1), each planned with the nominal model and run once (its trial number is
    /// its seed), the robot starting at a free pose of any heading.
    #[arg(long, conflicts_with = "scene")]
    pub random: Option<u64>,
    /// The random scenes' pusher: diff-drive (the simulated robot itself) or car (mapped onto
    /// it: its rear axle on the robot's wheel axle; forward-only pushes no tighter than its
    /// turning radius).
    #[arg(long, default_value = "diff-drive", requires = "random")]
    pub pusher: String,
    /// Keep every finished trial in this JSON-lines file as it is done; run again with the same
    /// file (and the same arguments) and the trials in it are not run again.
    #[arg(long, help_heading = super::ADVANCED, value_name = "FILE.jsonl", conflicts_with_all = ["hil", "port"])]
    pub resume: Option<std::path::PathBuf>,
    /// Run only the K-th of N shares of the trials, into its own --resume file; `pushbot eval
    /// merge` joins the N files. Example: `pushbot eval stable --scene fig15 --perturb
    /// --trials 300 --shard 1/3 --resume fig15-1.jsonl`
    #[arg(long, help_heading = super::ADVANCED, value_name = "K/N", requires = "resume")]
    pub shard: Option<crate::experiments::shard::Shard>,
}

impl StableEvalArgs {
    /// The key of this run's trials (`scene` or random scenes of `pusher`, `count` of them).
    #[cfg(feature = "sim")]
    fn key(
        &self,
        g: &Global,
        scene: Option<String>,
        pusher: Option<String>,
        count: u64,
    ) -> crate::experiments::stable_sweep::StableKey {
        let r = &self.run;
        let camera = match r.sim_camera {
            Some(super::SimCameraArg::Rendered) => "rendered",
            _ => "truth",
        };
        let mut key = crate::experiments::stable_sweep::StableKey::new(
            scene,
            pusher,
            !r.open_loop,
            r.perturb,
            g.seed,
            r.trial,
            count,
            camera,
        );
        key.shard = self.shard;
        key
    }

    /// The `--resume` file, opened for `key`.
    #[cfg(feature = "sim")]
    fn open(
        &self,
        key: &crate::experiments::stable_sweep::StableKey,
    ) -> Result<Option<crate::experiments::stable_sweep::StableFile>, CliError> {
        let Some(path) = &self.resume else {
            return Ok(None);
        };
        let f = crate::experiments::stable_sweep::StableFile::open(path, key)
            .map_err(|e| CliError::bad_input(format!("{e:#}")))?;
        if !f.is_empty() {
            eprintln!(
                "{}: {} trials done in an earlier run, not run again",
                path.display(),
                f.len()
            );
        }
        Ok(Some(f))
    }
}

impl StableRunArgs {
    /// The in-process robot's camera.
    #[cfg(feature = "sim")]
    fn sim_camera(&self) -> crate::sim::robot::SimCamera {
        match self.sim_camera {
            Some(super::SimCameraArg::Rendered) => crate::sim::robot::SimCamera::Rendered,
            Some(super::SimCameraArg::Truth) | None => crate::sim::robot::SimCamera::Truth,
        }
    }

    fn check(&self) -> Result<(), CliError> {
        if self.sim_camera.is_some() && (self.hil || self.port.is_some()) {
            return Err(CliError::bad_input(
                "--sim-camera is the in-process robot's camera; --hil and --port use a real \
                 camera stream",
            ));
        }
        if !(self.speed.is_finite() && self.speed > 0.0 && self.speed <= 50.0) {
            return Err(CliError::bad_input(format!(
                "--sim-speed must be in (0, 50], not {}",
                self.speed
            )));
        }
        if self.hil && self.port.is_some() {
            return Err(CliError::bad_input(
                "--hil runs the built-in simulated target; --port a real robot: give one",
            ));
        }
        if self.perturb && self.port.is_some() {
            return Err(CliError::bad_input(
                "--perturb perturbs the simulated world, not a real robot's (with --port)",
            ));
        }
        Ok(())
    }
}

/// Run `pushbot eval stable`.
pub fn eval(g: &Global, a: &StableEvalArgs) -> CliResult {
    if !(1..=10_000).contains(&a.trials) {
        return Err(CliError::bad_input(format!(
            "--trials must be 1..=10000, not {}",
            a.trials
        )));
    }
    if let Some(n) = a.random {
        if !(1..=10_000).contains(&n) {
            return Err(CliError::bad_input(format!(
                "--random must be 1..=10000, not {n}"
            )));
        }
        return eval_random(g, a, n);
    }
    eval_or_run(g, a, false)
}

#[cfg(feature = "sim")]
fn eval_or_run(g: &Global, a: &StableEvalArgs, single: bool) -> CliResult {
    use crate::experiments::stable_sweep::TrialRecord;
    use crate::experiments::stable_trials::{StableTask, StableTrial, run_trial, run_trial_live};
    use rayon::prelude::*;
    let r = &a.run;
    r.check()?;
    let Some(name) = &r.scene else {
        return Err(CliError::bad_input(
            "give --scene (a preset or a scene file), or --random N with `eval stable`",
        ));
    };
    let task = StableTask::load(name).map_err(|e| CliError::bad_input(format!("{e:#}")))?;
    if let (Some(port), Some(camera)) = (&r.port, &r.camera) {
        drop(crate::link::transport::open(port).map_err(|e| CliError::bad_input(format!("{e}")))?);
        crate::exec::grabber::FrameGrabber::open(camera, 30.0)
            .map_err(|e| CliError::bad_input(format!("--camera {camera}: {e}")))?;
    }
    let key = a.key(g, Some(name.clone()), None, a.trials);
    let file = a.open(&key)?;
    let trials = key.mine();
    let pb = super::progress_bar(g, trials.len() as u64);
    pb.set_message(format!(
        "{} {} loop{}",
        name,
        if r.open_loop { "open" } else { "closed" },
        if r.perturb { ", perturbed" } else { "" }
    ));
    let one = |t: u64| -> anyhow::Result<StableTrial> {
        if let Some(run) = file
            .as_ref()
            .and_then(|f| f.get(t))
            .and_then(|d| d.run.clone())
        {
            pb.inc(1);
            return Ok(run);
        }
        let pert = task.perturbation(g.seed, t, r.perturb);
        let out = if r.hil || r.port.is_some() {
            let robot = r.port.as_deref().zip(r.camera.as_deref());
            run_trial_live(&task, t, g.seed, pert, !r.open_loop, robot, r.speed)
        } else {
            run_trial(&task, t, g.seed, pert, !r.open_loop, r.sim_camera())
        };
        if let (Some(f), Ok(run)) = (&file, &out) {
            f.record(&TrialRecord {
                trial: t,
                run: Some(run.clone()),
            })?;
        }
        pb.inc(1);
        out
    };
    let results: Vec<anyhow::Result<StableTrial>> = if r.hil || r.port.is_some() {
        trials.iter().map(|t| one(*t)).collect()
    } else {
        trials.par_iter().map(|t| one(*t)).collect()
    };
    pb.finish_and_clear();
    let mut rows = Vec::new();
    for (t, res) in trials.iter().zip(results) {
        rows.push(res.map_err(|e| CliError::Failed(e.context(format!("trial {t}"))))?);
    }
    if let Some(dir) = &r.svg {
        write_svgs(dir, &task, &rows)?;
    }
    show_named(g, &key, &task, &rows, single)
}

/// The end of an evaluation of one scene (run whole, a shard's share, or the shards merged):
/// the table or `--json`; `run` (`single`) fails when the goal was missed.
#[cfg(feature = "sim")]
pub(super) fn show_named(
    g: &Global,
    key: &crate::experiments::stable_sweep::StableKey,
    task: &crate::experiments::stable_trials::StableTask,
    rows: &[crate::experiments::stable_trials::StableTrial],
    single: bool,
) -> CliResult {
    use serde_json::json;

    use super::Status;
    use crate::experiments::stable_trials::StableTrial;
    let name = key.scene.as_deref().unwrap_or_default();
    let (open_loop, perturb) = (!key.closed_loop, key.perturbed);
    let reached = rows.iter().filter(|t| t.reached).count();
    let n = rows.len();
    let mean = |f: &dyn Fn(&StableTrial) -> f64| rows.iter().map(f).sum::<f64>() / n as f64;
    let summary = json!({
        "scene": name,
        "closed_loop": !open_loop,
        "perturbed": perturb,
        "seed": key.seed,
        "shard": key.shard.map(|s| s.to_string()),
        "trials": n,
        "reached": reached,
        "plan_pushes": task.plan.pushes,
        "plan_ms": task.plan.plan_time_ms,
        "mean_final_error_mm": mean(&|t| t.final_error_m * 1e3),
        "worst_final_error_mm": rows.iter().map(|t| t.final_error_m * 1e3).fold(0.0, f64::max),
        "mean_replans": mean(&|t| t.replans as f64),
        "contact_losses": rows.iter().map(|t| t.contact_losses).sum::<usize>(),
    });
    if g.json {
        println!("{}", json!({ "summary": summary, "trials": rows }));
    } else {
        println!(
            "{} ({} loop{}, seed {}): goal ±{:.0} mm, ±{:.1}°",
            name,
            if open_loop { "open" } else { "closed" },
            if perturb { ", perturbed" } else { "" },
            key.seed,
            task.problem.params.goal_xy * 1e3,
            task.problem.params.goal_theta.to_degrees()
        );
        println!("trial  reached  error mm   error °  re-plans  contact losses");
        for t in rows {
            println!("{:5}  {}", t.trial, trial_row(t));
        }
        println!(
            "reached {reached} of {n}; mean final error {:.1} mm; mean re-plans {:.1}",
            mean(&|t| t.final_error_m * 1e3),
            mean(&|t| t.replans as f64)
        );
        if let Some(s) = key.shard {
            println!(
                "shard {s}: {n} of the {} trials; join the shards' files with `pushbot eval \
                 merge`",
                key.trials
            );
        }
    }
    // `run` fails when the goal was missed; `eval` reports its numbers either way.
    let ok = !single || reached == n;
    Ok(if ok {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// Each trial's plan with its executed path, as `dir/trial-N.svg`.
#[cfg(feature = "sim")]
fn write_svgs(
    dir: &std::path::Path,
    task: &crate::experiments::stable_trials::StableTask,
    rows: &[crate::experiments::stable_trials::StableTrial],
) -> Result<(), CliError> {
    use crate::planner::stable::svg::render_executed;
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::bad_input(format!("--svg {}: {e}", dir.display())))?;
    for t in rows {
        let f = dir.join(format!("trial-{}.svg", t.trial));
        std::fs::write(
            &f,
            render_executed(&task.problem, Some(&task.plan), &t.path),
        )
        .map_err(|e| CliError::bad_input(format!("{}: {e}", f.display())))?;
    }
    Ok(())
}

#[cfg(not(feature = "sim"))]
fn eval_or_run(_g: &Global, a: &StableEvalArgs, _single: bool) -> CliResult {
    a.run.check()?;
    Err(super::no_simulated_target())
}

/// `pushbot eval stable --random N`: each random scene planned with the nominal model and run
/// once on the simulated robot (perturbed with --perturb); per scene whether a plan exists and
/// what the run did, and the share reached of all scenes and of those with a plan.
#[cfg(feature = "sim")]
fn eval_random(g: &Global, a: &StableEvalArgs, n: u64) -> CliResult {
    use crate::experiments::stable_trials::{StableTask, StableTrial, run_trial, run_trial_live};
    use crate::planner::stable::random_scene::RandomPusher;
    use rayon::prelude::*;
    let r = &a.run;
    r.check()?;
    if r.port.is_some() {
        return Err(CliError::bad_input(
            "--random builds simulated scenes; a real robot's table is what it is (no --port)",
        ));
    }
    let pusher = RandomPusher::parse(&a.pusher).map_err(|e| CliError::bad_input(format!("{e}")))?;
    if !matches!(pusher, RandomPusher::DiffDrive | RandomPusher::Car) {
        return Err(CliError::bad_input(format!(
            "--pusher {}: the simulated robot drives diff-drive and car scenes",
            a.pusher
        )));
    }
    let key = a.key(g, None, Some(pusher.name().to_owned()), n);
    let file = a.open(&key)?;
    let seeds = key.mine();
    let pb = super::progress_bar(g, seeds.len() as u64);
    pb.set_message(format!("random {} scenes", pusher.name()));
    let one = |seed: u64| -> anyhow::Result<(u64, Option<StableTrial>)> {
        if let Some(done) = file.as_ref().and_then(|f| f.get(seed)) {
            pb.inc(1);
            return Ok((seed, done.run.clone()));
        }
        let out = match StableTask::random(seed, pusher)? {
            None => None,
            Some(task) => {
                let pert = task.perturbation(g.seed, seed, r.perturb);
                Some(if r.hil {
                    run_trial_live(&task, seed, g.seed, pert, !r.open_loop, None, r.speed)?
                } else {
                    run_trial(&task, seed, g.seed, pert, !r.open_loop, r.sim_camera())?
                })
            }
        };
        if let Some(f) = &file {
            f.record(&crate::experiments::stable_sweep::TrialRecord {
                trial: seed,
                run: out.clone(),
            })?;
        }
        pb.inc(1);
        Ok((seed, out))
    };
    let results: Vec<anyhow::Result<(u64, Option<StableTrial>)>> = if r.hil {
        seeds.iter().map(|s| one(*s)).collect()
    } else {
        seeds.par_iter().map(|s| one(*s)).collect()
    };
    pb.finish_and_clear();
    let mut rows = Vec::new();
    for (s, res) in seeds.iter().zip(results) {
        rows.push(res.map_err(|e| CliError::Failed(e.context(format!("random scene {s}"))))?);
    }
    show_random(g, &key, &rows)
}

/// The end of an evaluation of random scenes (run whole, a shard's share, or the shards
/// merged): per scene whether a plan exists and what the run did.
#[cfg(feature = "sim")]
pub(super) fn show_random(
    g: &Global,
    key: &crate::experiments::stable_sweep::StableKey,
    rows: &[(u64, Option<crate::experiments::stable_trials::StableTrial>)],
) -> CliResult {
    use serde_json::json;

    use super::Status;
    let planned = rows.iter().filter(|(_, t)| t.is_some()).count();
    let reached = rows
        .iter()
        .filter(|(_, t)| t.as_ref().is_some_and(|t| t.reached))
        .count();
    let share = |k: usize, of: usize| if of == 0 { 0.0 } else { k as f64 / of as f64 };
    let summary = json!({
        "random": key.trials,
        "pusher": key.pusher,
        "closed_loop": key.closed_loop,
        "perturbed": key.perturbed,
        "seed": key.seed,
        "shard": key.shard.map(|s| s.to_string()),
        "trials": rows.len(),
        "planned": planned,
        "reached": reached,
        "reached_share": share(reached, rows.len()),
        "reached_share_of_planned": share(reached, planned),
        "contact_losses": rows.iter().filter_map(|(_, t)| t.as_ref()).map(|t| t.contact_losses).sum::<usize>(),
    });
    if g.json {
        let scenes: Vec<_> = rows
            .iter()
            .map(|(s, t)| json!({"scene": s, "planned": t.is_some(), "trial": t}))
            .collect();
        println!("{}", json!({ "summary": summary, "scenes": scenes }));
    } else {
        println!(
            "random {} scenes {}…{} ({} loop{}, seed {})",
            key.pusher.as_deref().unwrap_or_default(),
            key.first_trial,
            key.first_trial + key.trials - 1,
            if key.closed_loop { "closed" } else { "open" },
            if key.perturbed { ", perturbed" } else { "" },
            key.seed
        );
        println!("scene  plan  reached  error mm   error °  re-plans  contact losses");
        for (s, t) in rows {
            match t {
                None => println!("{s:5}  none"),
                Some(t) => println!("{s:5}  yes   {}", trial_row(t)),
            }
        }
        println!(
            "reached {reached} of {} scenes ({:.0} %); a plan exists in {planned}: reached {:.0} % \
             of those",
            rows.len(),
            100.0 * share(reached, rows.len()),
            100.0 * share(reached, planned)
        );
        if let Some(s) = key.shard {
            println!(
                "shard {s}: {} of the {} scenes; join the shards' files with `pushbot eval \
                 merge`",
                rows.len(),
                key.trials
            );
        }
    }
    Ok(Status::Success)
}

#[cfg(not(feature = "sim"))]
fn eval_random(_g: &Global, a: &StableEvalArgs, _n: u64) -> CliResult {
    a.run.check()?;
    Err(super::no_simulated_target())
}

/// One trial's row of the text tables: reached, final error (mm, °), re-plans, contact losses
/// and the failure, if any.
#[cfg(feature = "sim")]
fn trial_row(t: &crate::experiments::stable_trials::StableTrial) -> String {
    format!(
        "{:7}  {:8.1}  {:8.2}  {:8}  {:14}{}",
        if t.reached { "yes" } else { "NO" },
        t.final_error_m * 1e3,
        t.final_error_deg,
        t.replans,
        t.contact_losses,
        t.failure
            .as_ref()
            .map_or(String::new(), |f| format!("  ({f})"))
    )
}

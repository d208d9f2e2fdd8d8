//! `pushbot collect` and `pushbot eval delivery` in the in-process simulation (feature `sim`):
//! argument checks and printing around [`crate::exec::collect`] and
//! [`crate::experiments::strategy_eval`].

use std::path::PathBuf;

use pushbot_world::Scene;
use serde_json::json;

use super::SimCameraArg;
use super::progress_bar;
use super::strategy_args::{CollectArgs, DeliveryArgs, SimArgs, scene_with_starts};
use super::{CliError, CliResult, Global, Status};
use crate::exec::collect::{CollectParams, CollectReport, collect};
use crate::exec::deliver::Delivery;
use crate::experiments::delivery::collect_or_load;
use crate::experiments::resume::{CellRecord, Checkpoint, RunKey, SceneKey};
use crate::experiments::shard::Sweep;
use crate::experiments::strategy_eval::{
    LAU_SCENES, LabelledRun, Method, SceneEval, StartResult, TrialSetup, evaluate_cells,
    parse_starts,
};
use crate::experiments::trace::TraceDir;
use crate::sim::robot::{SimCamera, SimRobot, SimRobotOptions};
use crate::strategy::figures;
use crate::strategy::regression::{KernelParams, PushStrategy};
use crate::strategy::sample::Sample;
use crate::strategy::store::{self, StrategyWriter};

fn scene_for(object: &str, scene: Option<&str>) -> Result<(Scene, Option<String>), CliError> {
    let (name, id) = match scene {
        Some(s) => (s.to_owned(), Some(object.to_owned())),
        None => (format!("lau-{object}"), None),
    };
    let scene = Scene::preset_or_file(&name).map_err(|e| CliError::bad_input(e.to_string()))?;
    Ok((scene, id))
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

impl SimArgs {
    pub(super) fn options(&self, seed: u64) -> Result<SimRobotOptions, CliError> {
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
            camera: match self.sim_camera {
                Some(SimCameraArg::Rendered) => SimCamera::Rendered,
                Some(SimCameraArg::Truth) | None => SimCamera::Truth,
            },
            ..SimRobotOptions::default()
        })
    }
}

/// Collect in the simulation into `writer`'s file, starting from `existing` samples, with a
/// progress bar unless `quiet`.
#[allow(clippy::too_many_arguments)]
fn collect_in_sim(
    global: &Global,
    scene: Scene,
    object: Option<&str>,
    opts: SimRobotOptions,
    kernel: KernelParams,
    params: &CollectParams,
    existing: Vec<Sample>,
    writer: Option<&mut StrategyWriter>,
    quiet: bool,
) -> Result<(PushStrategy, CollectReport), CliError> {
    let mut io = SimRobot::new(scene, object, None, opts).map_err(CliError::BadInput)?;
    let mut strategy = PushStrategy::new(existing, kernel);
    let pb = if quiet {
        indicatif::ProgressBar::hidden()
    } else {
        progress_bar(global, params.initial as u64)
    };
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
pub(super) fn run_collect(global: &Global, a: CollectArgs) -> CliResult {
    let (scene, id) = scene_for(&a.object, a.scene.as_deref())?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.strategy", a.object)));
    let params = a.active.apply(CollectParams {
        initial: a.initial,
        streak: a.streak,
        max_queries: a.max_queries,
        seed: global.seed,
        ..CollectParams::default()
    })?;
    let (mut writer, existing) =
        StrategyWriter::open(&out, &a.object).map_err(|e| CliError::bad_input(e.to_string()))?;
    let had = existing.len();
    let outline = object_outline(&scene, id.as_deref());
    let (strategy, rep) = collect_in_sim(
        global,
        scene,
        id.as_deref(),
        a.sim.options(global.seed)?,
        a.sim.kernel()?,
        &params,
        existing,
        Some(&mut writer),
        false,
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

/// The strategy `eval delivery` runs in `scene` (`name` as given): from `--strategy`, from
/// `--strategy-dir` (collected there when missing), or collected here first on the scene's
/// table without its obstacles; and the collection's report when it collected. `quiet` hides
/// the progress bar (scenes collected side by side).
fn strategy_for(
    global: &Global,
    a: &DeliveryArgs,
    name: &str,
    scene: &Scene,
    setup: &TrialSetup,
    quiet: bool,
) -> Result<(Vec<Sample>, Option<CollectReport>), CliError> {
    let params = a.collect_params(global.seed)?;
    if let Some(path) = &a.strategy {
        let samples = store::load(path)
            .map_err(|e| CliError::bad_input(e.to_string()))?
            .samples;
        return Ok((samples, None));
    }
    if let Some(dir) = &a.strategy_dir {
        std::fs::create_dir_all(dir)
            .map_err(|e| CliError::bad_input(format!("cannot create {}: {e}", dir.display())))?;
        let file = dir.join(format!("{}.strategy", name.replace(['/', '.'], "_")));
        let pb = if quiet {
            indicatif::ProgressBar::hidden()
        } else {
            progress_bar(global, params.initial as u64)
        };
        let (samples, rep) = collect_or_load(
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
        return Ok((samples, rep));
    }
    let mut clear = scene.clone();
    clear.obstacles.clear();
    let (strategy, rep) = collect_in_sim(
        global,
        clear,
        a.object.as_deref(),
        setup.sim,
        setup.kernel,
        &params,
        Vec::new(),
        None,
        quiet,
    )?;
    Ok((strategy.samples().to_vec(), Some(rep)))
}

/// `pushbot eval delivery` on simulated trials; with `--figure 11`, Lau et al.'s Fig. 11 whole.
pub(super) fn eval_in_sim(global: &Global, mut a: DeliveryArgs) -> CliResult {
    use rayon::prelude::*;
    match (a.figure, a.scene.as_deref()) {
        (None, _) => {}
        (Some(11), None | Some("lau-all")) => {
            a.scene = Some("lau-all".into());
            a.sim.sim_camera.get_or_insert(SimCameraArg::Rendered);
            a.svg.get_or_insert_with(|| PathBuf::from("fig11.svg"));
        }
        (Some(11), Some(s)) => {
            return Err(CliError::bad_input(format!(
                "--figure 11 runs Lau et al.'s six objects; it takes no --scene ({s})"
            )));
        }
        (Some(7), _) if a.resume.is_some() => {
            return Err(CliError::bad_input(
                "--resume keeps trial cells; --figure 7 collects, and does not resume",
            ));
        }
        (Some(7), _) => return super::data_need::run_figure7(global, &a),
        (Some(n), _) => {
            return Err(CliError::bad_input(format!(
                "--figure {n}: the figures drawn are 7 (the data-need curve) and 11 (success per \
                 start, Lau et al. Fig. 11)"
            )));
        }
    }
    let starts = parse_starts(&a.start).map_err(CliError::bad_input)?;
    let scene_arg = a.scene.clone().unwrap_or_default();
    let names: Vec<String> = if scene_arg.trim() == "lau-all" {
        LAU_SCENES.iter().map(|s| (*s).to_owned()).collect()
    } else {
        scene_arg
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
    let mut setups = Vec::new();
    for n in &names {
        let scene = scene_with_starts(n, &starts)?;
        let setup = TrialSetup {
            scene,
            object: a.object.clone(),
            sim: a.sim.options(global.seed)?,
            delivery: a.delivery_params()?,
            kernel: a.sim.kernel()?,
        };
        setup.goal().map_err(CliError::BadInput)?;
        setups.push(setup);
    }
    if a.svg.is_some() && a.figure.is_none() && setups.len() != 1 {
        return Err(CliError::bad_input("--svg draws one scene's trajectories"));
    }
    let methods = a.method.methods();
    // The strategies, every scene's on its own core.
    let several = setups.len() > 1;
    let strategies = names
        .par_iter()
        .zip(&setups)
        .map(|(name, setup)| {
            if !methods.contains(&Method::Learned) {
                return Ok((Vec::new(), None));
            }
            strategy_for(global, &a, name, &setup.scene, setup, several)
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    let camera_name = a.sim.sim_camera.map_or("truth", |c| match c {
        SimCameraArg::Rendered => "rendered",
        SimCameraArg::Truth => "truth",
    });
    let scene_keys: Vec<SceneKey> = setups
        .iter()
        .zip(&strategies)
        .map(|(setup, (samples, _))| SceneKey::new(setup, samples))
        .collect();
    let sweep = a.shard.map(|shard| Sweep {
        shard,
        scenes: names.clone(),
        starts: starts.clone(),
        methods: methods.clone(),
        figure: a.figure,
        object: a.object.clone(),
    });
    let checkpoint = match &a.resume {
        Some(path) => {
            let mut key = RunKey::new(a.trials, global.seed, camera_name);
            if let Some(sw) = &sweep {
                key = key.sharded(sw.clone());
            }
            let c = Checkpoint::open(path, &key, &scene_keys).map_err(CliError::BadInput)?;
            if c.cells() > 0 && !global.json {
                println!(
                    "{}: {} cells done in an earlier run, not run again",
                    path.display(),
                    c.cells()
                );
            }
            Some(c)
        }
        None => None,
    };
    let trace = match &a.trace_dir {
        Some(dir) => Some(TraceDir::create(dir).map_err(CliError::BadInput)?),
        None => None,
    };
    // This run's cells of each scene: all of them, or its shard's share.
    let mine: Vec<Vec<(String, Method)>> = (0..setups.len())
        .map(|si| {
            let mut cells = Vec::new();
            for (ti, s) in starts.iter().enumerate() {
                for (mi, m) in methods.iter().enumerate() {
                    if sweep.as_ref().is_none_or(|sw| sw.owns(si, ti, mi)) {
                        cells.push((s.clone(), *m));
                    }
                }
            }
            cells
        })
        .collect();
    let total = (mine.iter().map(Vec::len).sum::<usize>() * a.trials) as u64;
    let pb = progress_bar(global, total);
    let mut evals = Vec::new();
    let mut trajectories = Vec::new();
    for (((setup, (samples, collection)), key), cells) in
        setups.iter().zip(strategies).zip(&scene_keys).zip(&mine)
    {
        let scene = &setup.scene;
        let resumed = |start: &str, method: Method| {
            let c = checkpoint.as_ref()?.cell(&scene.name, start, method)?;
            Some((c.result.clone(), c.first.clone()))
        };
        let goal = setup.goal()?;
        let outline = object_outline(scene, setup.object.as_deref());
        let report = |res: &StartResult, first: Option<&LabelledRun>, runs: Option<&[Delivery]>| {
            if let (Some(t), Some(runs)) = (&trace, runs) {
                for (k, d) in runs.iter().enumerate() {
                    t.write(scene, goal, &outline, &res.start, res.method, k, d)?;
                }
            }
            let resumed = runs.is_none();
            if let (Some(c), false) = (&checkpoint, resumed) {
                c.record(&CellRecord {
                    scene: key.clone(),
                    result: res.clone(),
                    first: first.cloned(),
                })?;
            }
            pb.inc(res.trials as u64);
            if !global.json {
                let line = format!(
                    "{} {} {:>7}: {:>5.1} % of {} | time {} | object path {} ({} shortest, worst {}) | failures {:?} | stalls recovered {} | time-outs without a recovery {}",
                    scene.name,
                    res.start,
                    format!("{:?}", res.method),
                    res.success_rate,
                    res.trials,
                    res.mean_time_s.map_or("-".into(), |t| format!("{t:.1} s")),
                    res.mean_object_path_m
                        .map_or("-".into(), |t| format!("{t:.2} m")),
                    res.mean_path_ratio
                        .map_or("-".into(), |t| format!("{t:.2}×")),
                    res.max_path_ratio
                        .map_or("-".into(), |t| format!("{t:.2}×")),
                    res.failures,
                    res.stall_recoveries,
                    res.silent_timeouts,
                );
                let line = if resumed {
                    format!("{line} (resumed)")
                } else {
                    line
                };
                // A hidden bar (output not a terminal) prints nothing.
                if pb.is_hidden() {
                    println!("{line}");
                } else {
                    pb.println(line);
                }
            }
            Ok(())
        };
        let (results, runs) = evaluate_cells(setup, cells, &samples, a.trials, &resumed, &report)?;
        if !several {
            trajectories.extend(runs);
        }
        evals.push(SceneEval {
            scene: scene.name.clone(),
            samples: samples.len(),
            collection,
            results,
        });
    }
    pb.finish_and_clear();
    let scene = (!several).then(|| (&setups[0].scene, a.object.as_deref()));
    super::eval_merge::show(
        global,
        super::eval_merge::SweepEnd {
            trials: a.trials,
            seed: global.seed,
            camera: camera_name,
            starts: &starts,
            methods: &methods,
            figure: a.figure,
            svg: a.svg.clone(),
            evals,
            trajectories,
            scene,
            shard: sweep.map(|sw| (sw.shard, mine.iter().map(Vec::len).sum())),
        },
    )
}

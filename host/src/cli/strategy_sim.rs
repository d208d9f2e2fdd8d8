//! `pushbot collect` and `pushbot eval delivery` in the in-process simulation (feature `sim`):
//! argument checks and printing around [`crate::exec::collect`] and
//! [`crate::experiments::strategy_eval`].

use std::path::PathBuf;

use pushbot_world::Scene;
use serde_json::json;

use super::progress_bar;
use super::strategy_args::{CollectArgs, DeliveryArgs, MethodArg, SimArgs};
use super::{CliError, CliResult, Global, Status};
use crate::exec::collect::{CollectParams, CollectReport, collect};
use crate::experiments::delivery::collect_or_load;
use crate::experiments::strategy_eval::{
    LAU_SCENES, Method, SceneEval, StartResult, TrialSetup, evaluate_scene, fig11_table,
    parse_starts,
};
use crate::planner::global::scene_goal;
use crate::sim::robot::{SimRobot, SimRobotOptions};
use crate::strategy::figures;
use crate::strategy::regression::PushStrategy;
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
            ..SimRobotOptions::default()
        })
    }
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

/// `pushbot eval delivery` on simulated trials.
pub(super) fn eval_in_sim(global: &Global, a: DeliveryArgs) -> CliResult {
    match a.figure {
        None => {}
        Some(7) => return super::data_need::run_figure7(global, &a),
        Some(n) => {
            return Err(CliError::bad_input(format!(
                "--figure {n}: the figures drawn are 7 (the data-need curve)"
            )));
        }
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
        let params = a.active.apply(CollectParams {
            initial: a.initial,
            streak: a.streak,
            seed: global.seed,
            ..CollectParams::default()
        })?;
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
        let (results, runs) = evaluate_scene(
            &setup,
            &methods,
            &samples,
            &starts,
            a.trials,
            &mut |res: &StartResult| {
                if !global.json {
                    println!(
                        "{} {} {:>7}: {:>5.1} % of {} | time {} | object path {} | failures {:?} | stalls recovered {}",
                        scene.name,
                        res.start,
                        format!("{:?}", res.method),
                        res.success_rate,
                        res.trials,
                        res.mean_time_s.map_or("-".into(), |t| format!("{t:.1} s")),
                        res.mean_object_path_m
                            .map_or("-".into(), |t| format!("{t:.2} m")),
                        res.failures,
                        res.stall_recoveries,
                    );
                }
            },
        )?;
        if names.len() == 1 {
            trajectories.extend(runs);
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
            let goal = scene_goal(scene, a.object.as_deref()).map_err(CliError::BadInput)?;
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

//! `pushbot collect`, `pushbot eval delivery` and `pushbot bench knn`: the learned pushing
//! strategy of Lau, Mitani & Igarashi (collection, Algorithm 1; delivery, Algorithm 2) and the
//! dipole-field baseline, run in the in-process simulation.

use pushbot_world::Scene;
use serde_json::json;

use super::strategy_args::{
    BenchArgs, BenchCmd, CollectArgs, DeliveryArgs, EvalArgs, EvalCmd, MethodArg,
};
use super::{CliError, CliResult, Global, Status, progress_bar};
use crate::exec::collect::{CollectParams, bring_inside, collect};
use crate::exec::deliver::{deliver_dipole, deliver_learned};
use crate::exec::deliver_path::deliver_among_obstacles;
use crate::exec::{LiveOptions, LiveRobot};
use crate::experiments::trials::{Method, summarise};
use crate::planner::global::{ObstacleParams, scene_goal, scene_obstacles};
use crate::strategy::regression::PushStrategy;
use crate::strategy::sample::Sample;
use crate::strategy::store;

/// Run `pushbot eval`.
pub fn run_eval(global: &Global, a: EvalArgs) -> CliResult {
    if let EvalCmd::Merge(m) = &a.cmd {
        return merge(global, m);
    }
    let EvalCmd::Delivery(a) = a.cmd else {
        return Err(CliError::bad_input(
            "pushbot eval: not a delivery evaluation",
        ));
    };
    let a = *a;
    if !(a.time_limit.is_finite() && a.time_limit > 0.0) {
        return Err(CliError::bad_input("--time-limit must be positive"));
    }
    if a.hil && a.figure.is_some() {
        return Err(CliError::bad_input(
            "--figure runs in the simulation; leave out --hil",
        ));
    }
    if a.hil {
        let name = a
            .scene
            .as_deref()
            .ok_or_else(|| CliError::bad_input("--hil delivers one --scene"))?;
        let scene = Scene::preset_or_file(name).map_err(|e| CliError::bad_input(e.to_string()))?;
        return run_hil(global, &a, &scene);
    }
    eval_in_sim(global, a)
}

/// `pushbot eval merge`.
#[cfg(feature = "sim")]
fn merge(global: &Global, a: &super::strategy_args::MergeArgs) -> CliResult {
    super::eval_merge::merge(global, a)
}

#[cfg(not(feature = "sim"))]
fn merge(_global: &Global, _a: &super::strategy_args::MergeArgs) -> CliResult {
    Err(super::no_simulated_target())
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
    if a.port.is_some() {
        return super::run::collect_on_robot(global, &a);
    }
    super::strategy_sim::run_collect(global, a)
}

/// Without the `sim` feature there is nothing to collect in.
#[cfg(not(feature = "sim"))]
pub fn run_collect(global: &Global, a: CollectArgs) -> CliResult {
    if a.port.is_some() {
        return super::run::collect_on_robot(global, &a);
    }
    Err(super::no_simulated_target())
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
    let recording = match &a.record {
        Some(p) => Some(crate::recording::RecordingHandle::new(
            crate::recording::Recording::create(p).map_err(CliError::BadInput)?,
        )),
        None => None,
    };
    let opts = LiveOptions {
        boundary_inset,
        object: a.object.clone(),
        watchdog_ms: a.watchdog_ms,
        link: global.link_options()?,
        recover: !global.no_recover,
        lens: global.lens()?,
        recording: recording.clone(),
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
            let params = a.collect_params(global.seed)?;
            // With --strategy-dir every sample is written as it is collected: a collection cut
            // short (a link that did not come back, a person stopping it) keeps what it had, and
            // the next run goes on from there.
            let mut writer = match &a.strategy_dir {
                Some(dir) => {
                    std::fs::create_dir_all(dir).map_err(|e| {
                        CliError::bad_input(format!("cannot create {}: {e}", dir.display()))
                    })?;
                    let id = a
                        .object
                        .clone()
                        .or_else(|| scene.objects.first().map(|o| o.id.clone()))
                        .ok_or_else(|| {
                            CliError::bad_input(format!("scene {} has no object", scene.name))
                        })?;
                    let file =
                        dir.join(format!("{}.strategy", scene.name.replace(['/', '.'], "_")));
                    Some(
                        store::StrategyWriter::open(&file, &id)
                            .map_err(|e| CliError::bad_input(e.to_string()))?,
                    )
                }
                None => None,
            };
            let existing = writer.as_mut().map(|(_, s)| std::mem::take(s));
            let mut strategy = PushStrategy::new(existing.unwrap_or_default(), kernel);
            let pb = progress_bar(global, params.initial as u64);
            let mut sink = |s: &Sample| -> anyhow::Result<()> {
                if let Some((w, _)) = writer.as_mut() {
                    w.append(s)?;
                }
                Ok(())
            };
            let rep = collect(&mut io, &mut strategy, &params, &mut sink, &pb);
            pb.finish_and_clear();
            let rep = rep.map_err(|e| match &writer {
                Some((w, _)) => CliError::Failed(e.context(format!(
                    "collection stopped; the {} samples collected so far are kept in {}",
                    strategy.samples().len(),
                    w.path().display()
                ))),
                None => CliError::Failed(e),
            })?;
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
    if let Some(h) = &recording {
        h.finish()?;
    }
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
                "recoveries": io.recoveries(),
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
        for r in io.recoveries() {
            println!(
                "link recovered at robot time {:.1} s ({}), {:.2} s",
                r.robot_time_s, r.cause, r.wall_s
            );
        }
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

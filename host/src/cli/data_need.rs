//! `pushbot eval delivery --figure 7`: the data-need curve (samples collected vs
//! success of Lau et al.'s deliveries), argument checks and printing around
//! [`crate::experiments::data_need`].

use std::path::PathBuf;

use pushbot_world::Scene;
use serde_json::json;

use super::strategy_args::DeliveryArgs;
use super::{CliError, CliResult, Global, Status};
use crate::experiments::data_need::{DataNeedSetup, VARIANTS, data_need, table};
use crate::experiments::data_need_figure::data_need_svg;
use crate::experiments::strategy_eval::{LAU_SCENES, parse_starts};

/// Checkpoints stop at this many samples: the paper's collection of an object it struggles
/// with can run to thousands.
const MAX_SAMPLES: usize = 1000;

/// Run `eval delivery --figure 7`.
pub(super) fn run_figure7(global: &Global, a: &DeliveryArgs) -> CliResult {
    if a.every == 0 || a.trials == 0 {
        return Err(CliError::bad_input(
            "--figure 7 needs --every and --trials of at least 1",
        ));
    }
    if a.strategy.is_some() || a.strategy_dir.is_some() {
        return Err(CliError::bad_input(
            "--figure 7 collects its own strategies; leave out --strategy and --strategy-dir",
        ));
    }
    let starts = parse_starts(&a.start).map_err(CliError::bad_input)?;
    let scene = a.scene.as_deref().unwrap_or("lau-all");
    let names: Vec<String> = if scene.trim() == "lau-all" {
        LAU_SCENES.iter().map(|s| (*s).to_owned()).collect()
    } else {
        scene
            .split(',')
            .map(|s| s.trim().to_owned())
            .filter(|s| !s.is_empty())
            .collect()
    };
    let mut scenes = Vec::new();
    for n in &names {
        let scene = Scene::preset_or_file(n).map_err(|e| CliError::bad_input(e.to_string()))?;
        if let Some(s) = starts.iter().find(|s| scene.position(s).is_none()) {
            return Err(CliError::bad_input(format!(
                "scene {} has no start position {s}",
                scene.name
            )));
        }
        scenes.push(scene);
    }
    if scenes.is_empty() {
        return Err(CliError::bad_input("no scene given"));
    }
    let setup = DataNeedSetup {
        every: a.every,
        tests: a.trials * starts.len(),
        max_samples: MAX_SAMPLES,
        streak: a.streak,
        seed: global.seed,
        sim: a.sim.options(global.seed)?,
        delivery: a.delivery_params()?,
        kernel: a.sim.kernel()?,
        starts,
    };
    let curves = data_need(&scenes, &VARIANTS, &setup).map_err(CliError::Failed)?;
    let svg = a
        .svg
        .clone()
        .unwrap_or_else(|| PathBuf::from("data-need.svg"));
    std::fs::write(&svg, data_need_svg(&curves))
        .map_err(|e| CliError::Failed(anyhow::anyhow!("writing {}: {e}", svg.display())))?;
    if global.json {
        println!(
            "{}",
            json!({"figure": 7, "seed": global.seed, "every": setup.every, "tests": setup.tests,
                   "svg": svg, "curves": curves})
        );
    } else {
        println!(
            "Data need (seed {}): success % of {} test deliveries after every {} samples\n",
            global.seed, setup.tests, setup.every
        );
        print!("{}", table(&curves));
        println!("figure written to {}", svg.display());
    }
    // Done when the active collection reaches the streak within 300 samples on every object.
    let ok = curves
        .iter()
        .filter(|c| c.variant.name == "explore")
        .all(|c| c.streak_at.is_some_and(|n| n <= 300));
    Ok(if ok {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

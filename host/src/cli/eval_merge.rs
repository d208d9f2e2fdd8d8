//! What `pushbot eval delivery` prints at its end (the table, the figure, `--json`), for a run
//! whole, one shard's share, or `pushbot eval merge` joining the shards' files
//! ([`crate::experiments::shard`]).

use std::collections::HashMap;
use std::path::PathBuf;

use pushbot_world::Scene;
use serde_json::json;

use super::strategy_args::MergeArgs;
use super::{CliError, CliResult, Global, Status};
use crate::experiments::fig11::{fig11_svg, fig11_table};
use crate::experiments::resume::{CellRecord, FileCells, RunKey, SceneKey};
use crate::experiments::shard::{Shard, Sweep};
use crate::experiments::strategy_eval::{LabelledRun, Method, SceneEval};
use crate::planner::global::scene_goal;
use crate::strategy::figures;

/// Everything the end of a delivery sweep shows.
pub(super) struct SweepEnd<'a> {
    /// Trials per cell.
    pub trials: usize,
    /// The run's seed.
    pub seed: u64,
    /// `truth` or `rendered`.
    pub camera: &'a str,
    /// The starts, in order.
    pub starts: &'a [String],
    /// The methods, in order.
    pub methods: &'a [Method],
    /// `--figure`.
    pub figure: Option<u8>,
    /// Where to draw (`--svg`).
    pub svg: Option<PathBuf>,
    /// One scene's evaluation each.
    pub evals: Vec<SceneEval>,
    /// With one scene: the first trial's trajectory of each cell, and the scene and object.
    pub trajectories: Vec<LabelledRun>,
    /// The one scene whose trajectories `--svg` draws (without `--figure`), and its object.
    pub scene: Option<(&'a Scene, Option<&'a str>)>,
    /// The share of a sweep this run was, if it was one.
    pub shard: Option<(Shard, usize)>,
}

/// Print the table (or `--json`), draw the figure; exit status: success when every learned
/// cell delivered at least 95 %.
pub(super) fn show(global: &Global, end: SweepEnd<'_>) -> CliResult {
    let camera = match end.camera {
        "rendered" => "the rendered camera in the loop",
        _ => "the simulator's poses with camera noise",
    };
    // A shard draws no figure: the merge of all shards does.
    let svg = end.svg.as_ref().filter(|_| end.shard.is_none());
    if let Some(svg) = svg {
        let text = if end.figure.is_some() {
            let caption = format!(
                "{} trials per bar, seed {}, {camera}; `pushbot eval delivery --figure 11 --trials {} --seed {}`",
                end.trials, end.seed, end.trials, end.seed
            );
            fig11_svg(&end.evals, end.starts, end.methods, &caption)
        } else {
            let Some((scene, object)) = end.scene else {
                return Err(CliError::bad_input("--svg draws one scene's trajectories"));
            };
            let goal = scene_goal(scene, object).map_err(CliError::BadInput)?;
            figures::trajectories_svg(&end.trajectories, scene, goal)
        };
        std::fs::write(svg, &text)
            .map_err(|e| CliError::Failed(anyhow::anyhow!("writing {}: {e}", svg.display())))?;
        crate::plot::svg_to_png(&text, &svg.with_extension("png")).map_err(CliError::Failed)?;
    }
    let learned_ok = end
        .evals
        .iter()
        .flat_map(|e| &e.results)
        .filter(|r| r.method == Method::Learned)
        .all(|r| r.success_rate >= 95.0);
    if global.json {
        println!(
            "{}",
            json!({
                "trials": end.trials,
                "starts": end.starts,
                "camera": end.camera,
                "figure": svg.filter(|_| end.figure.is_some()),
                "shard": end.shard.map(|(s, _)| s.to_string()),
                "scenes": end.evals,
            })
        );
    } else {
        println!(
            "\nSuccess % of {} trials (Lau et al. Fig. 11), {camera}:",
            end.trials
        );
        print!("{}", fig11_table(&end.evals, end.starts, end.methods));
        if let Some((shard, cells)) = end.shard {
            println!(
                "shard {shard}: {cells} cells of the sweep's {}; join the shards' files with \
                 `pushbot eval merge`",
                end.evals.len() * end.starts.len() * end.methods.len()
            );
        }
        if let (Some(_), Some(svg)) = (end.figure, svg) {
            println!(
                "figure written to {} and {}",
                svg.display(),
                svg.with_extension("png").display()
            );
        }
    }
    Ok(if learned_ok {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// `pushbot eval merge FILES…`: every shard of one sweep, once each, each cell of the sweep
/// in one of them; the table and figure as the sweep run whole prints them.
pub(super) fn merge(global: &Global, a: &MergeArgs) -> CliResult {
    let first = a
        .files
        .first()
        .ok_or_else(|| CliError::bad_input("no file given"))?;
    let header = std::fs::read_to_string(first)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(t.lines().next()?).ok());
    if header.is_some_and(|h| h["eval"] == "stable") {
        return merge_stable(global, a);
    }
    let mut key: Option<(RunKey, Sweep, String)> = None;
    let mut seen: HashMap<usize, String> = HashMap::new();
    let mut cells: HashMap<(String, String, Method), (CellRecord, String)> = HashMap::new();
    let mut scene_keys: HashMap<String, (SceneKey, String)> = HashMap::new();
    for path in &a.files {
        let shown = path.display().to_string();
        let read = FileCells::read(path)
            .map_err(|e| CliError::bad_input(format!("{e:#}")))?
            .ok_or_else(|| CliError::bad_input(format!("{shown}: no such file, or empty")))?;
        let Some(sweep) = read.header.sweep.clone() else {
            return Err(CliError::bad_input(format!(
                "{shown} is the file of a whole run, not of a shard (`--shard K/N`): there is \
                 nothing to merge it with"
            )));
        };
        match &key {
            None => key = Some((read.header.clone(), sweep.unsharded(), shown.clone())),
            Some((first, first_sweep, first_file)) => {
                let mut what = first.differences(&read.header);
                what.retain(|w| !w.starts_with("shard "));
                if sweep.shard.n != first_sweep.shard.n {
                    what.push(format!(
                        "{} shards in {shown}, {} in {first_file}",
                        sweep.shard.n, first_sweep.shard.n
                    ));
                }
                if !what.is_empty() {
                    return Err(CliError::bad_input(format!(
                        "{shown} is a shard of another sweep than {first_file} ({}): merge the \
                         files of one sweep",
                        what.join("; ")
                            .replace(" now", &format!(" in {first_file}"))
                    )));
                }
            }
        }
        if let Some(other) = seen.insert(sweep.shard.k, shown.clone()) {
            return Err(CliError::bad_input(format!(
                "{shown} and {other} are both shard {}: give each shard's file once",
                sweep.shard
            )));
        }
        for (line, c) in read.cells {
            let name = c.scene.scene.clone();
            match scene_keys.get(&name) {
                Some((k, f)) if k != &c.scene => {
                    return Err(CliError::bad_input(format!(
                        "{shown} line {line}: {name} was run with another setup or strategy \
                         than in {f} ({}): merge the files of one sweep",
                        k.differences(&c.scene).join("; ")
                    )));
                }
                Some(_) => {}
                None => {
                    scene_keys.insert(name.clone(), (c.scene.clone(), shown.clone()));
                }
            }
            let id = (name, c.result.start.clone(), c.result.method);
            cells.insert(id, (c, shown.clone()));
        }
    }
    let Some((run, sweep, _)) = key else {
        return Err(CliError::bad_input("no file given"));
    };
    let missing_shards: Vec<String> = (1..=sweep.shard.n)
        .filter(|k| !seen.contains_key(k))
        .map(|k| format!("{k}/{}", sweep.shard.n))
        .collect();
    if !missing_shards.is_empty() {
        return Err(CliError::bad_input(format!(
            "shard {} of the sweep not given: merge every shard's file",
            missing_shards.join(", ")
        )));
    }
    // The cells in the sweep's order, every one of them.
    let mut evals = Vec::new();
    let mut trajectories = Vec::new();
    let mut missing = Vec::new();
    for (si, name) in sweep.scenes.iter().enumerate() {
        let scene_name = scene_of(name);
        let mut results = Vec::new();
        let mut samples = 0;
        for (ti, start) in sweep.starts.iter().enumerate() {
            for (mi, m) in sweep.methods.iter().enumerate() {
                let k = 1
                    + (1..=sweep.shard.n)
                        .position(|k| {
                            Shard {
                                k,
                                n: sweep.shard.n,
                            }
                            .owns(sweep.index(si, ti, mi))
                        })
                        .unwrap_or(0);
                match cells.get(&(scene_name.clone(), start.clone(), *m)) {
                    Some((c, _)) => {
                        samples = c.scene.samples;
                        results.push(c.result.clone());
                        trajectories.extend(c.first.clone());
                    }
                    None => missing.push(format!(
                        "{scene_name} {start} {m:?} (shard {k}/{})",
                        sweep.shard.n
                    )),
                }
            }
        }
        evals.push(SceneEval {
            scene: scene_name,
            samples,
            collection: None,
            results,
        });
    }
    if !missing.is_empty() {
        return Err(CliError::bad_input(format!(
            "{} of the sweep's {} cells are in no file: {}; run those shards again with their \
             --resume files, then merge",
            missing.len(),
            sweep.cells(),
            missing.join(", ")
        )));
    }
    let one_scene = match sweep.scenes.as_slice() {
        [one] if sweep.figure.is_none() => {
            Some(Scene::preset_or_file(one).map_err(|e| CliError::bad_input(e.to_string()))?)
        }
        _ => None,
    };
    let svg = a
        .svg
        .clone()
        .or_else(|| (sweep.figure == Some(11)).then(|| PathBuf::from("fig11.svg")));
    show(
        global,
        SweepEnd {
            trials: run.trials,
            seed: run.seed,
            camera: &run.camera,
            starts: &sweep.starts,
            methods: &sweep.methods,
            figure: sweep.figure,
            svg,
            evals,
            trajectories: if one_scene.is_some() {
                trajectories
            } else {
                Vec::new()
            },
            scene: one_scene.as_ref().map(|s| (s, sweep.object.as_deref())),
            shard: None,
        },
    )
}

/// The scene's own name (what its cells are filed under) for a scene argument: a preset's
/// name, or the name inside a scene file.
fn scene_of(arg: &str) -> String {
    Scene::preset_or_file(arg).map_or_else(|_| arg.to_owned(), |s| s.name)
}

/// `pushbot eval merge` of a stable evaluation's shards (`eval stable --shard K/N --resume`).
fn merge_stable(global: &Global, a: &MergeArgs) -> CliResult {
    use std::collections::BTreeMap;

    use crate::experiments::stable_sweep::{self, StableKey, TrialRecord};
    use crate::experiments::stable_trials::StableTask;
    let mut first: Option<(StableKey, Shard, String)> = None;
    let mut seen: HashMap<usize, String> = HashMap::new();
    let mut trials: BTreeMap<u64, TrialRecord> = BTreeMap::new();
    for path in &a.files {
        let shown = path.display().to_string();
        let (key, recs, _) = stable_sweep::read(path)
            .map_err(|e| CliError::bad_input(format!("{e:#}")))?
            .ok_or_else(|| CliError::bad_input(format!("{shown}: no such file, or empty")))?;
        let Some(shard) = key.shard else {
            return Err(CliError::bad_input(format!(
                "{shown} is the file of a whole run, not of a shard (`--shard K/N`): there is \
                 nothing to merge it with"
            )));
        };
        let whole = StableKey { shard: None, ..key };
        match &first {
            None => first = Some((whole, shard, shown.clone())),
            Some((k, s, f)) => {
                let mut what = k.differences(&whole);
                if shard.n != s.n {
                    what.push(format!("{} shards in {shown}, {} in {f}", shard.n, s.n));
                }
                if !what.is_empty() {
                    return Err(CliError::bad_input(format!(
                        "{shown} is a shard of another evaluation than {f} ({}): merge the files \
                         of one evaluation",
                        what.join("; ").replace(" now", &format!(" in {f}"))
                    )));
                }
            }
        }
        if let Some(other) = seen.insert(shard.k, shown.clone()) {
            return Err(CliError::bad_input(format!(
                "{shown} and {other} are both shard {shard}: give each shard's file once"
            )));
        }
        trials.extend(recs);
    }
    let Some((key, shard, _)) = first else {
        return Err(CliError::bad_input("no file given"));
    };
    let missing: Vec<String> = (1..=shard.n)
        .filter(|k| !seen.contains_key(k))
        .map(|k| format!("{k}/{}", shard.n))
        .collect();
    if !missing.is_empty() {
        return Err(CliError::bad_input(format!(
            "shard {} of the evaluation not given: merge every shard's file",
            missing.join(", ")
        )));
    }
    let all = key.all_trials();
    let missing: Vec<String> = all
        .iter()
        .filter(|t| !trials.contains_key(t))
        .map(u64::to_string)
        .collect();
    if !missing.is_empty() {
        return Err(CliError::bad_input(format!(
            "{} of the evaluation's {} trials are in no file (trials {}); run those shards \
             again with their --resume files, then merge",
            missing.len(),
            all.len(),
            missing.join(", ")
        )));
    }
    match &key.scene {
        Some(name) => {
            let task = StableTask::load(name).map_err(|e| CliError::bad_input(format!("{e:#}")))?;
            let rows: Vec<_> = all.iter().filter_map(|t| trials[t].run.clone()).collect();
            super::stable_run::show_named(global, &key, &task, &rows, false)
        }
        None => {
            let rows: Vec<_> = all.iter().map(|t| (*t, trials[t].run.clone())).collect();
            super::stable_run::show_random(global, &key, &rows)
        }
    }
}

//! `pushbot mechanics`, `pushbot plan stable`, `pushbot bench stable`: stable pushing after
//! Lynch & Mason (1996) — STABLE and controllability (§3), the push planner (§4).

mod random_bench;

use std::fmt::Write as _;

use clap::Args;
use serde_json::json;

use super::{CliError, CliResult, Global, Status};
use crate::mechanics::controllability::{self, PushBoundary};
use crate::mechanics::stable::stable_all_edges;
use crate::mechanics::{LineContact, cor};
use crate::planner::stable::exact::finish_exactly;
use crate::planner::stable::presets::{CostOverride, PAPER_SECONDS, PRESETS, load_scene};
use crate::planner::stable::{plan, svg};

/// `pushbot mechanics`: STABLE per edge and the controllability verdicts.
#[derive(Args, Debug, Clone)]
pub struct MechanicsArgs {
    /// Scene: a preset name (fig13, fig15, fig16, fig17, fig18) or a TOML file.
    #[arg(long)]
    pub scene: String,
    /// Object id in the scene (default: the task's object).
    #[arg(long)]
    pub object: Option<String>,
}

/// `pushbot plan stable`.
#[derive(Args, Debug, Clone)]
pub struct PlanStableArgs {
    /// Scene: a preset name or a TOML file.
    #[arg(long)]
    pub scene: String,
    /// Cost per push step (overrides the scene).
    #[arg(long)]
    pub a: Option<u32>,
    /// Cost per control change.
    #[arg(long)]
    pub b: Option<u32>,
    /// Cost per contact change, or "inf".
    #[arg(long)]
    pub c: Option<String>,
    /// Back up and finish exactly on the goal (§4.5): with one stable push, or, for a car or a
    /// differential drive, with the Dubins path of its tightest stable turns.
    #[arg(long)]
    pub exact_goal: bool,
    /// Draw the plan as SVG into this file (with no plan: the tree the search explored).
    #[arg(long)]
    pub svg: Option<std::path::PathBuf>,
    /// Most configurations the search expands (overrides the scene's planner.max_nodes).
    #[arg(long, value_name = "N")]
    pub max_nodes: Option<usize>,
    /// Most a plan may cost (overrides the scene's planner.max_cost).
    #[arg(long, value_name = "COST")]
    pub max_cost: Option<u32>,
}

/// `pushbot bench stable`.
#[derive(Args, Debug, Clone)]
pub struct BenchStableArgs {
    /// Runs per preset (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub repeat: usize,
    /// Only these presets (repeatable; default: all of them).
    #[arg(long = "preset", value_name = "NAME", value_parser = clap::builder::PossibleValuesParser::new(PRESETS))]
    pub presets: Vec<String>,
    /// Random scenes per pusher (`planner::stable::random_scene`, seeds `--seed` on); 0: none.
    #[arg(long, default_value_t = 50)]
    pub random: u64,
    /// First seed of the random scenes.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Pushers of the random scenes (repeatable; default: diff-drive and car).
    #[arg(long = "pusher", value_name = "KIND", value_parser = clap::builder::PossibleValuesParser::new(["diff-drive", "car", "omni", "arm"]))]
    pub pushers: Vec<String>,
}

fn fmt_dir(v: &crate::mechanics::V3) -> serde_json::Value {
    match cor(v) {
        Some(c) => {
            json!({"twist": [v.x, v.y, v.z], "cor": [c.x, c.y], "sense": if v.z > 0.0 {"ccw"} else {"cw"}})
        }
        None => json!({"twist": [v.x, v.y, v.z], "translation": [v.x, v.y]}),
    }
}

/// Run `pushbot mechanics`.
pub fn run_mechanics(g: &Global, a: &MechanicsArgs) -> CliResult {
    let scene = load_scene(&a.scene).map_err(CliError::BadInput)?;
    let id = a
        .object
        .clone()
        .unwrap_or_else(|| scene.task.object.clone());
    let slider = scene.slider(&id).map_err(CliError::BadInput)?;
    let mu = scene.mu;
    let sets = stable_all_edges(&slider, mu).map_err(CliError::bad_input)?;
    let mut edges = Vec::new();
    for s in &sets {
        let e = s.contact.edge;
        edges.push(json!({
            "edge": e,
            "contact": [[s.contact.a.x, s.contact.a.y], [s.contact.b.x, s.contact.b.y]],
            "stable_constraints": s.constraints.iter().map(|r| [r.x, r.y, r.z]).collect::<Vec<_>>(),
            "extremal": s.extremal.iter().map(fmt_dir).collect::<Vec<_>>(),
            "controllable_theorem5": controllability::theorem5(&s.contact, mu),
            "controllable_prop2": controllability::controllable(&s.extremal),
            "stlc_prop4": controllability::small_time_locally_controllable(&s.extremal),
            "point_contact_controllable_theorem2": controllability::theorem2_edge(&slider, e, mu).unwrap_or(false),
        }));
    }
    let task_edges: Vec<usize> = if id == scene.task.object {
        scene.task.edges.clone()
    } else {
        vec![]
    };
    let task_contacts: Vec<LineContact> = task_edges
        .iter()
        .filter_map(|&e| LineContact::full_edge(&slider, e).ok())
        .collect();
    let union: Vec<_> = sets
        .iter()
        .filter(|s| task_edges.contains(&s.contact.edge))
        .flat_map(|s| s.extremal.clone())
        .collect();
    let all: Vec<LineContact> = sets.iter().map(|s| s.contact).collect();
    let out = json!({
        "object": id,
        "mu": mu,
        "centre_of_friction_radius": slider.radius(),
        "edges": edges,
        "task_edges": task_edges,
        "task_edges_stlc_theorem7": controllability::theorem7(&task_contacts, mu),
        "task_edges_stlc_prop4": controllability::small_time_locally_controllable(&union),
        "all_edges_stlc_theorem7": controllability::theorem7(&all, mu),
        "controllable_theorem6": controllability::theorem6(&slider, mu).unwrap_or(false),
        "point_contact_stlc_theorem3": controllability::theorem3(&PushBoundary::Polygon(slider.vertices.clone()), mu),
    });
    if g.json {
        println!("{out}");
    } else {
        let mut s = String::new();
        let _ = writeln!(s, "object {id}, mu {mu}");
        for e in out["edges"].as_array().into_iter().flatten() {
            let _ = writeln!(
                s,
                "edge {}: {} extremal stable directions, controllable (Thm 5): {}",
                e["edge"],
                e["extremal"].as_array().map_or(0, |v| v.len()),
                e["controllable_theorem5"]
            );
            for d in e["extremal"].as_array().into_iter().flatten() {
                let _ = writeln!(s, "    {d}");
            }
        }
        let _ = writeln!(
            s,
            "task edges {:?}: STLC (Thm 7) {}, STLC (Prop 4 on STABLE) {}",
            out["task_edges"], out["task_edges_stlc_theorem7"], out["task_edges_stlc_prop4"]
        );
        print!("{s}");
    }
    Ok(Status::Success)
}

fn parse_c(c: &Option<String>) -> Result<Option<Option<u32>>, CliError> {
    match c.as_deref() {
        None => Ok(None),
        Some("inf") => Ok(Some(None)),
        Some(v) => v.parse::<u32>().map(|x| Some(Some(x))).map_err(|_| {
            CliError::bad_input(format!("--c: expected an integer or inf, got {v:?}"))
        }),
    }
}

/// Run `pushbot plan stable`.
pub fn run_plan(g: &Global, a: &PlanStableArgs) -> CliResult {
    let scene = load_scene(&a.scene).map_err(CliError::BadInput)?;
    let costs = CostOverride {
        a: a.a,
        b: a.b,
        c: parse_c(&a.c)?,
    };
    let mut problem = scene.problem(costs).map_err(CliError::BadInput)?;
    if let Some(n) = a.max_nodes {
        problem.params.max_nodes = n;
    }
    if let Some(c) = a.max_cost {
        problem.params.max_cost = c;
    }
    let mut p = plan(&problem);
    if a.exact_goal && p.found {
        let t = p.plan_time_ms;
        match finish_exactly(&problem, &p) {
            Some(mut e) => {
                e.plan_time_ms = t;
                p = e;
            }
            None => {
                // The goal neighbourhood may have room where the exact goal has none.
                let goal_blocked = problem
                    .contacts
                    .iter()
                    .all(|cm| !cm.body.free_at(&problem.world, &problem.goal));
                let why = if goal_blocked {
                    "the goal configuration itself is not free: there the slider (with the pusher on any of its contacts) overlaps an obstacle or leaves the table"
                } else {
                    "neither one stable push nor a Dubins path of stable pushes (wheeled pushers) is free of collision from any configuration of the plan"
                };
                return Err(CliError::Failed(anyhow::anyhow!(
                    "no exact finish reaches the goal: {why}"
                )));
            }
        }
    }
    if let Some(path) = &a.svg {
        std::fs::write(path, svg::render(&problem, Some(&p)))
            .map_err(|e| CliError::Failed(anyhow::anyhow!("writing {}: {e}", path.display())))?;
    }
    let transit_length: f64 = p.transits.iter().map(|t| t.length).sum::<f64>() + 0.0;
    let no_plan = crate::planner::stable::no_plan::why(&problem, &p);
    if scene.outline_reversed && !g.json {
        println!(
            "note: the object's outline was clockwise and is stored counter-clockwise; edges \
             are named as the scene writes them"
        );
    }
    if g.json {
        let out = json!({
            "scene": scene.name,
            "found": p.found,
            "cost": p.cost,
            "pushes": p.pushes,
            "control_changes": p.control_changes,
            "contact_changes": p.contact_changes,
            "nodes_expanded": p.nodes_expanded,
            "plan_time_ms": p.plan_time_ms,
            "exact_goal": p.exact_goal,
            "costs": {"a": problem.params.a, "b": problem.params.b, "c": problem.params.c},
            "transit_length": transit_length,
            "contacts": problem.contacts.iter().map(|c| json!({
                "edge": c.label,
                "contact": [[c.placement.contact.a.x, c.placement.contact.a.y], [c.placement.contact.b.x, c.placement.contact.b.y]],
                "controls": c.usable.controls.iter().map(fmt_dir).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "path": p.steps,
            "transits": p.transits,
            "no_plan_reason": no_plan.as_ref().map(|u| u.to_string()),
            "edges_as_written": scene.outline_reversed,
        });
        println!("{out}");
    } else if p.found {
        println!(
            "found: cost {}, {} pushes, {} control changes, {} contact changes, {} nodes, {:.1} ms, transit {:.3} m",
            p.cost,
            p.pushes,
            p.control_changes,
            p.contact_changes,
            p.nodes_expanded,
            p.plan_time_ms,
            transit_length
        );
    } else {
        let why = no_plan
            .as_ref()
            .map_or_else(String::new, |u| format!(": {u}"));
        println!(
            "no plan ({} nodes expanded in {:.1} ms){why}",
            p.nodes_expanded, p.plan_time_ms
        );
    }
    Ok(if p.found {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

/// Run `pushbot bench stable`.
pub fn run_bench(g: &Global, a: &BenchStableArgs) -> CliResult {
    let mut rows = Vec::new();
    let mut all_found = true;
    for (name, paper) in PRESETS.iter().zip(PAPER_SECONDS) {
        if !a.presets.is_empty() && !a.presets.iter().any(|p| p == name) {
            continue;
        }
        let scene = load_scene(name).map_err(CliError::BadInput)?;
        let problem = scene
            .problem(CostOverride::default())
            .map_err(CliError::BadInput)?;
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..a.repeat.max(1) {
            let p = plan(&problem);
            times.push(p.plan_time_ms);
            last = Some(p);
        }
        times.sort_by(f64::total_cmp);
        let p = last.expect("at least one run");
        all_found &= p.found;
        rows.push(json!({
            "preset": name,
            "found": p.found,
            "cost": p.cost,
            "pushes": p.pushes,
            "contact_changes": p.contact_changes,
            "nodes_expanded": p.nodes_expanded,
            "plan_time_ms": times[times.len() / 2],
            "paper_s": paper,
        }));
    }
    let random = random_bench::bench_random(a)?;
    if g.json {
        println!(
            "{}",
            json!({"bench": "stable", "repeat": a.repeat.max(1), "results": rows, "random": random})
        );
    } else {
        println!(
            "{:<8} {:>6} {:>6} {:>8} {:>12} {:>8}",
            "preset", "found", "cost", "nodes", "time ms", "paper s"
        );
        for r in &rows {
            println!(
                "{:<8} {:>6} {:>6} {:>8} {:>12.2} {:>8}",
                r["preset"].as_str().unwrap_or(""),
                // A JSON value ignores width and alignment: print it as a string first.
                r["found"].to_string(),
                r["cost"].to_string(),
                r["nodes_expanded"].to_string(),
                r["plan_time_ms"].as_f64().unwrap_or(0.0),
                r["paper_s"].to_string()
            );
        }
        random_bench::print_random(&random);
    }
    Ok(if all_found {
        Status::Success
    } else {
        Status::TaskFailed
    })
}

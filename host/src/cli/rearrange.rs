//! `pushbot plan rearrange` and `pushbot bench rearrange`: Ben-Shahar & Rivlin rearrangement
//! planning (see `planner::rearrange`).

use std::time::Instant;

use clap::Args;
use serde_json::json;

use super::{CliError, CliResult, Global, Status};
use crate::planner::rearrange::{
    self, Config, Dir, Grid, Metric, Model, MovableSpec, MoveKind, Placement, Problem,
    RestoreError, RobotSpec, Rules, cases,
};

/// Arguments of `pushbot plan rearrange`.
#[derive(Args, Debug, Clone)]
pub struct PlanArgs {
    /// A case (A1 A2 A3 A4 B1 B2 C1 C2 D1), a scene preset with a `[rearrange]` section, or a
    /// scene file (TOML, the shared format with `[table]` and `[rearrange]`).
    #[arg(long)]
    pub scene: String,
    /// Write the plan as step-by-step figures (SVG) to this file.
    #[arg(long)]
    pub svg: Option<std::path::PathBuf>,
    /// Write the same figures as a PNG picture to this file.
    #[arg(long)]
    pub png: Option<std::path::PathBuf>,
}

/// Arguments of `pushbot bench rearrange`.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Small rooms (10 × 10 with 2 boxes, 8 × 8 with 3) for a quick check.
    #[arg(long)]
    pub quick: bool,
    /// Run only this benchmark: `2box` or `3box`.
    #[arg(long)]
    pub only: Option<String>,
}

/// Peak resident memory of this process in KiB (VmHWM), if the system tells.
pub fn peak_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// CPU time of this thread in ms (utime + stime from /proc, 10 ms resolution), if the system
/// tells; on a shared machine it is the fairer measure of the map's cost than wall time.
pub fn thread_cpu_ms() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(ticks as f64 * 10.0)
}

fn step_json(model: &Model, st: &rearrange::restore::PlanStep) -> serde_json::Value {
    let names = |mask: u8| -> Vec<String> {
        (0..model.r())
            .filter(|i| mask & (1 << i) != 0)
            .map(|i| model.problem.movables[i].name.clone())
            .collect()
    };
    let (kind, pushed, turn) = match st.step.kind {
        MoveKind::Transit => ("transit", vec![], 0),
        MoveKind::Push { pushed } => ("push", names(pushed), 0),
        MoveKind::Rotate { movable, turn } => ("rotate", names(1 << movable), turn),
    };
    let c = &st.config;
    json!({
        "dir": st.step.dir.letter().to_string(),
        "kind": kind,
        "pushed": pushed,
        "turn": turn,
        "cost": st.step.cost,
        "robot": [c.robot.0, c.robot.1],
        "movables": c.movables.iter().map(|p| json!([p.x, p.y, p.o])).collect::<Vec<_>>(),
    })
}

/// Run `pushbot plan rearrange`.
pub fn plan(global: &Global, args: PlanArgs) -> CliResult {
    let problem = cases::load_scene(&args.scene).map_err(CliError::bad_input)?;
    let model = Model::new(&problem)
        .map_err(|e| CliError::bad_input(format!("scene `{}`: {e}", args.scene)))?;
    let map = rearrange::cost_map(&model).map_err(|e| CliError::Failed(e.into()))?;
    let start = model.pack(&problem.start).ok_or_else(|| {
        CliError::bad_input(format!("scene `{}`: the start is not free", args.scene))
    })?;
    let result = rearrange::restore(&model, &map, start);
    let peak = peak_kib();
    let st = &map.stats;
    match &result {
        Ok(p) => {
            if args.svg.is_some() || args.png.is_some() {
                let svg = rearrange::svg::plan_svg(&model, p);
                if let Some(path) = &args.svg {
                    std::fs::write(path, &svg).map_err(|e| {
                        CliError::Failed(anyhow::anyhow!("writing {}: {e}", path.display()))
                    })?;
                }
                if let Some(path) = &args.png {
                    crate::plot::svg_to_png(&svg, path).map_err(CliError::Failed)?;
                }
            }
            if global.json {
                let j = json!({
                    "scene": problem.name,
                    "found": true,
                    "cost": p.cost,
                    "steps": p.steps.len(),
                    "pushes": p.pushes(),
                    "states_total": st.states_total,
                    "states_mapped": st.states_mapped,
                    "map_ms": st.map_ms,
                    "restore_ms": p.restore_ms,
                    "map_bytes": st.map_bytes,
                    "peak_kib": peak,
                    "plan": p.steps.iter().map(|s| step_json(&model, s)).collect::<Vec<_>>(),
                });
                println!("{j}");
            } else {
                println!(
                    "{}: cost {}, {} steps, {} pushes; mapped {} of {} configurations in {:.1} ms, restored in {:.3} ms",
                    problem.name,
                    p.cost,
                    p.steps.len(),
                    p.pushes(),
                    st.states_mapped,
                    st.states_total,
                    st.map_ms,
                    p.restore_ms
                );
                for (n, r) in rearrange::svg::stages(p).into_iter().enumerate() {
                    let mut line = format!("  stage {}:", n + 1);
                    for s in &p.steps[r] {
                        let k = match s.step.kind {
                            MoveKind::Transit => String::new(),
                            MoveKind::Push { pushed } => format!(
                                "[{}]",
                                (0..model.r())
                                    .filter(|i| pushed & (1 << i) != 0)
                                    .map(|i| model.problem.movables[i].name.as_str())
                                    .collect::<Vec<_>>()
                                    .join("+")
                            ),
                            MoveKind::Rotate { movable, turn } => format!(
                                "[{} {}]",
                                model.problem.movables[movable as usize].name,
                                if turn > 0 { "cw" } else { "ccw" }
                            ),
                        };
                        line.push_str(&format!(" {}{k}", s.step.dir.letter()));
                    }
                    println!("{line}");
                }
            }
            Ok(Status::Success)
        }
        Err(e) => {
            if global.json {
                let j = json!({
                    "scene": problem.name,
                    "found": false,
                    "reason": e.to_string(),
                    "states_total": st.states_total,
                    "states_mapped": st.states_mapped,
                    "map_ms": st.map_ms,
                    "map_bytes": st.map_bytes,
                    "peak_kib": peak,
                });
                println!("{j}");
            } else {
                println!(
                    "{}: {e} (mapped {} configurations in {:.1} ms)",
                    problem.name, st.states_mapped, st.map_ms
                );
            }
            match e {
                RestoreError::Inconsistent(_) => Err(CliError::Failed(anyhow::anyhow!("{e}"))),
                _ => Ok(Status::TaskFailed),
            }
        }
    }
}

/// A benchmark room: `side × side`, no inner obstacles, the robot and `boxes` one-cell boxes of
/// mass 1, one box at a time; goals in a row along the bottom, the robot anywhere.
pub fn bench_problem(side: i32, boxes: usize) -> Problem {
    let movables: Vec<MovableSpec> = (0..boxes)
        .map(|i| MovableSpec::with_faces(&format!("b{i}"), vec![(0, 0)], 1))
        .collect();
    let starts = (0..boxes)
        .map(|i| Placement {
            x: 2 + 2 * i as i32,
            y: 2,
            o: 0,
        })
        .collect();
    let goals = (0..boxes)
        .map(|i| {
            Some(Placement {
                x: side - 3 - 2 * i as i32,
                y: side - 3,
                o: 0,
            })
        })
        .collect();
    Problem {
        name: format!("{boxes}box-{side}x{side}"),
        grid: Grid::new(side, side),
        robot: RobotSpec { size: 1, mass: 1 },
        movables,
        rules: Rules::default(),
        metric: Metric::default(),
        start: Config {
            robot: (0, 0),
            heading: Dir::E,
            pushing: false,
            movables: starts,
        },
        goal_robot: None,
        goal_movables: goals,
    }
}

/// Run `pushbot bench rearrange`.
pub fn bench(global: &Global, args: BenchArgs) -> CliResult {
    let mut runs = vec![
        ("2box", if args.quick { 10 } else { 20 }, 2),
        ("3box", if args.quick { 8 } else { 12 }, 3),
    ];
    if let Some(only) = &args.only {
        runs.retain(|r| r.0 == only);
        if runs.is_empty() {
            return Err(CliError::bad_input(format!(
                "--only {only}: use 2box or 3box"
            )));
        }
    }
    let mut results = Vec::new();
    for (_, side, boxes) in runs {
        let problem = bench_problem(side, boxes);
        let t0 = Instant::now();
        let model = Model::new(&problem).map_err(|e| CliError::Failed(e.into()))?;
        let build_ms = t0.elapsed().as_secs_f64() * 1e3;
        let cpu0 = thread_cpu_ms();
        let map = rearrange::cost_map(&model).map_err(|e| CliError::Failed(e.into()))?;
        let map_cpu_ms = thread_cpu_ms().zip(cpu0).map(|(b, a)| b - a);
        let start = model
            .pack(&problem.start)
            .ok_or_else(|| CliError::Failed(anyhow::anyhow!("bench start")))?;
        let plan = rearrange::restore(&model, &map, start);
        let st = map.stats;
        let (cost, restore_ms) = match &plan {
            Ok(p) => (Some(p.cost), Some(p.restore_ms)),
            Err(_) => (None, None),
        };
        let j = json!({
            "name": problem.name,
            "states_total": st.states_total,
            "states_mapped": st.states_mapped,
            "relaxations": st.relaxations,
            "tables_ms": build_ms,
            "map_ms": st.map_ms,
            "map_cpu_ms": map_cpu_ms,
            "states_per_s": st.states_mapped as f64 / (st.map_ms / 1e3).max(1e-9),
            "states_per_cpu_s": map_cpu_ms.map(|c| st.states_mapped as f64 / (c / 1e3).max(1e-9)),
            "configs_per_s": st.states_total as f64 / (st.map_ms / 1e3).max(1e-9),
            "map_bytes": st.map_bytes,
            "peak_kib": peak_kib(),
            "cost": cost,
            "restore_ms": restore_ms,
        });
        if !global.json {
            println!(
                "{}: {} configurations, {} mapped in {:.0} ms wall, {:.0} ms CPU ({:.2e} mapped/s), map {} MiB, peak {} KiB, plan cost {:?}",
                problem.name,
                st.states_total,
                st.states_mapped,
                st.map_ms,
                map_cpu_ms.unwrap_or(f64::NAN),
                st.states_mapped as f64 / (st.map_ms / 1e3).max(1e-9),
                st.map_bytes >> 20,
                peak_kib().unwrap_or(0),
                cost
            );
        }
        results.push(j);
        drop(map);
    }
    if global.json {
        println!("{}", serde_json::Value::Array(results));
    }
    Ok(Status::Success)
}

//! `pushbot plan rearrange` and `pushbot bench rearrange`: Ben-Shahar & Rivlin rearrangement
//! planning (see `planner::rearrange`).

use clap::Args;
use serde_json::json;

use super::{CliError, CliResult, Global, Status};
use crate::experiments::rearrange_bench::{self, peak_kib};
use crate::planner::rearrange::budget::{ExactBudget, human};
use crate::planner::rearrange::practical::{self, Action, Options, PracticalError};
use crate::planner::rearrange::{self, Model, MoveKind, Problem, RestoreError, cases};

/// Which planner `plan rearrange` uses.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// The exact planner when its cost map fits in memory, else the practical mode.
    #[default]
    Auto,
    /// The exact cost map (optimal; refused when it would not fit).
    Exact,
    /// The object-level search over single-object legs (many movables; not proven optimal).
    Practical,
}

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
    /// The planner: `exact` (optimal), `practical` (many movables) or `auto` (exact when its
    /// map fits in memory).
    #[arg(long, value_enum, default_value_t = Mode::Auto)]
    pub mode: Mode,
}

/// Arguments of `pushbot bench rearrange`.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Small rooms (10 × 10 with 2 boxes, 8 × 8 with 3) for a quick check.
    #[arg(long)]
    pub quick: bool,
    /// Run only this benchmark: `2box`, `3box`, `4box`, `12box`, or `wide` (robot + 3 boxes on
    /// 16 × 16: 2³² configurations, past a u32 index; about 9 GiB and minutes).
    #[arg(long)]
    pub only: Option<String>,
    /// Skip the practical mode (time the exact map alone).
    #[arg(long)]
    pub exact_only: bool,
}

fn step_json(model: &Model, st: &rearrange::restore::PlanStep) -> serde_json::Value {
    let names = |mask: u64| -> Vec<String> {
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
    let budget = ExactBudget::of(&problem);
    let fits = budget.check();
    let exact = match args.mode {
        Mode::Exact => {
            fits.map_err(|e| CliError::bad_input(format!("scene `{}`: {e}", args.scene)))?;
            true
        }
        Mode::Practical => false,
        Mode::Auto => fits.is_ok(),
    };
    if !exact {
        return plan_practical(global, &args, &problem);
    }
    eprintln!(
        "exact cost map: {} configurations, about {} ({} cores)",
        budget.configurations,
        human(budget.bytes),
        rayon::current_num_threads()
    );
    let model = Model::new(&problem)
        .map_err(|e| CliError::bad_input(format!("scene `{}`: {e}", args.scene)))?;
    let pb = spinner(global, "cost map");
    let map = rearrange::cost_map(&model).map_err(|e| CliError::Failed(e.into()))?;
    pb.finish_and_clear();
    let start = model.pack(&problem.start).ok_or_else(|| {
        CliError::bad_input(format!("scene `{}`: the start is not free", args.scene))
    })?;
    let result = rearrange::restore(&model, &map, start);
    let peak = peak_kib();
    let st = &map.stats;
    match &result {
        Ok(p) => {
            if args.svg.is_some() || args.png.is_some() {
                write_figure(&args, &rearrange::svg::plan_svg(&model, p))?;
            }
            if global.json {
                let j = json!({
                    "scene": problem.name,
                    "mode": "exact",
                    "optimal": true,
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
                    "mode": "exact",
                    "found": false,
                    "proven": true,
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

/// `plan rearrange` in the practical mode: the same JSON fields as the exact planner's (those
/// of the map are null), plus `optimal`.
fn plan_practical(global: &Global, args: &PlanArgs, problem: &Problem) -> CliResult {
    if !global.json {
        eprintln!(
            "practical mode: {} movables (the exact map would take {} configurations, {})",
            problem.movables.len(),
            budget_text(problem),
            human(ExactBudget::of(problem).bytes)
        );
    }
    let pb = spinner(global, "object-level search");
    let result = practical::plan_practical(problem, &Options::for_problem(problem));
    pb.finish_and_clear();
    let peak = peak_kib();
    match result {
        Ok(p) => {
            if args.svg.is_some() || args.png.is_some() {
                write_figure(args, &rearrange::svg::practical_svg(problem, &p, None))?;
            }
            let name = |i: usize| problem.movables[i].name.clone();
            let steps: Vec<serde_json::Value> = p
                .moves
                .iter()
                .map(|m| {
                    let (kind, pushed, turn) = match m.action {
                        Action::Transit => ("transit", vec![], 0),
                        Action::Push(i) => ("push", vec![name(i)], 0),
                        Action::Rotate(i, t) => ("rotate", vec![name(i)], t),
                    };
                    let c = &m.config;
                    json!({
                        "dir": m.dir.letter().to_string(),
                        "kind": kind,
                        "pushed": pushed,
                        "turn": turn,
                        "cost": m.cost,
                        "robot": [c.robot.0, c.robot.1],
                        "movables": c.movables.iter().map(|p| json!([p.x, p.y, p.o])).collect::<Vec<_>>(),
                    })
                })
                .collect();
            if global.json {
                let j = json!({
                    "scene": problem.name,
                    "mode": "practical",
                    "optimal": p.optimal,
                    "found": true,
                    "cost": p.cost,
                    "steps": p.moves.len(),
                    "pushes": p.pushes(),
                    "legs": p.legs,
                    "expansions": p.expansions,
                    "states_total": null,
                    "states_mapped": p.settled,
                    "map_ms": null,
                    "plan_ms": p.plan_ms,
                    "restore_ms": 0.0,
                    "map_bytes": null,
                    "peak_kib": peak,
                    "plan": steps,
                });
                println!("{j}");
            } else {
                println!(
                    "{}: cost {} (not proven optimal), {} steps, {} pushes in {} legs; {} object-level nodes in {:.1} ms",
                    problem.name,
                    p.cost,
                    p.moves.len(),
                    p.pushes(),
                    p.legs,
                    p.expansions,
                    p.plan_ms
                );
                let line: String = p
                    .moves
                    .iter()
                    .map(|m| match m.action {
                        Action::Transit => format!(" {}", m.dir.letter()),
                        Action::Push(i) => format!(" {}[{}]", m.dir.letter(), name(i)),
                        Action::Rotate(i, t) => format!(
                            " {}[{} {}]",
                            m.dir.letter(),
                            name(i),
                            if t > 0 { "cw" } else { "ccw" }
                        ),
                    })
                    .collect();
                println!(" {line}");
            }
            Ok(Status::Success)
        }
        Err(PracticalError::Problem(e)) => {
            Err(CliError::bad_input(format!("scene `{}`: {e}", args.scene)))
        }
        Err(e) => {
            let proven = matches!(e, PracticalError::NoPlanExists(_));
            if global.json {
                let j = json!({
                    "scene": problem.name,
                    "mode": "practical",
                    "found": false,
                    "proven": proven,
                    "reason": e.to_string(),
                    "peak_kib": peak,
                });
                println!("{j}");
            } else {
                println!("{}: {e}", problem.name);
            }
            Ok(Status::TaskFailed)
        }
    }
}

/// Write the plan's figure where `--svg` and `--png` say.
fn write_figure(args: &PlanArgs, svg: &str) -> Result<(), CliError> {
    if let Some(path) = &args.svg {
        std::fs::write(path, svg)
            .map_err(|e| CliError::Failed(anyhow::anyhow!("writing {}: {e}", path.display())))?;
    }
    if let Some(path) = &args.png {
        crate::plot::svg_to_png(svg, path).map_err(CliError::Failed)?;
    }
    Ok(())
}

/// A spinner on stderr while long work runs (hidden with `--json` and off a terminal).
fn spinner(global: &Global, what: &str) -> indicatif::ProgressBar {
    if global.json {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::new_spinner();
    pb.set_message(what.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// The exact map's configurations as text.
fn budget_text(problem: &Problem) -> String {
    format!("{:.2e}", ExactBudget::of(problem).configurations_f64)
}

/// Run `pushbot bench rearrange`.
pub fn bench(global: &Global, args: BenchArgs) -> CliResult {
    let mut runs = rearrange_bench::instances(args.quick);
    if let Some(only) = &args.only {
        runs.push(rearrange_bench::wide_instance());
        runs.retain(|r| r.key == only);
        if runs.is_empty() {
            return Err(CliError::bad_input(format!(
                "--only {only}: use 2box, 3box, 4box, 12box or wide"
            )));
        }
    }
    let mut rows = Vec::new();
    for inst in &runs {
        let row = rearrange_bench::run(inst, !args.exact_only);
        if !global.json {
            print_row(&row);
        }
        rows.push(row);
    }
    if global.json {
        println!(
            "{}",
            serde_json::to_value(&rows).map_err(|e| CliError::Failed(e.into()))?
        );
    }
    Ok(Status::Success)
}

/// One bench row as text.
fn print_row(r: &rearrange_bench::Row) {
    let opt =
        |v: Option<f64>, unit: &str| v.map_or("–".to_string(), |v| format!("{v:.0} {unit}"));
    println!(
        "{}: {} movables, {:.3e} configurations (exact map ≈ {})",
        r.name,
        r.movables,
        r.configurations,
        human(r.map_bytes_estimate)
    );
    match &r.exact_refused {
        Some(why) => println!("  exact: refused: {why}"),
        None => println!(
            "  exact: {} wall, {} CPU ({:.2} cores), {:.2e} states/s, map {}, peak {} MiB, cost {}",
            opt(r.map_ms, "ms"),
            opt(r.map_cpu_ms, "ms"),
            r.cores_busy.unwrap_or(f64::NAN),
            r.states_per_s.unwrap_or(f64::NAN),
            human(r.map_bytes.unwrap_or(0)),
            r.peak_kib.unwrap_or(0) >> 10,
            r.cost.map_or("none".to_string(), |c| c.to_string())
        ),
    }
    match r.practical_cost {
        Some(c) => println!(
            "  practical: cost {c}{} in {}, {} object-level nodes",
            r.practical_over_optimum
                .map_or(String::new(), |q| format!(" ({q:.3}× the optimum)")),
            opt(r.practical_ms, "ms"),
            r.practical_expansions.unwrap_or(0)
        ),
        None if r.practical_ms.is_none() => println!("  practical: no plan found or not run"),
        None => {}
    }
}

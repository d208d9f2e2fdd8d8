//! `pushbot bench rearrange`: the exact cost map (Ben-Shahar & Rivlin §IV-A1) on large rooms,
//! on every core, and the practical mode on rooms the exact map cannot hold (§IV-E), with the
//! practical plan's cost over the optimum where both run. The CLI only prints the rows.

use std::time::Instant;

use serde::Serialize;

use crate::planner::rearrange::budget::ExactBudget;
use crate::planner::rearrange::practical::{Options, plan_practical};
use crate::planner::rearrange::problem::Cell;
use crate::planner::rearrange::{
    self, Config, Dir, Grid, Metric, Model, MovableSpec, Placement, Problem, RobotSpec, Rules,
};

/// One benchmark instance.
#[derive(Debug, Clone)]
pub struct Instance {
    /// Short name for `--only`.
    pub key: &'static str,
    /// The problem.
    pub problem: Problem,
}

/// The instances: robot + 2 boxes on 20 × 20, + 3 on 12 × 12, + 4 on 10 × 10 (beyond the exact
/// map), + 12 in a walled 20 × 20 warehouse; `quick` shrinks the rooms of the first two and
/// takes 6 boxes into the warehouse.
pub fn instances(quick: bool) -> Vec<Instance> {
    vec![
        Instance {
            key: "2box",
            problem: bench_problem(if quick { 10 } else { 20 }, 2),
        },
        Instance {
            key: "3box",
            problem: bench_problem(if quick { 8 } else { 12 }, 3),
        },
        Instance {
            key: "4box",
            problem: bench_problem(10, 4),
        },
        Instance {
            key: "12box",
            problem: warehouse_problem(if quick { 6 } else { 12 }),
        },
    ]
}

/// The first room past a `u32` index: robot + 3 boxes on 16 × 16, 2³² configurations (the map
/// takes about 9 GiB), run only when asked for (`--only wide`).
pub fn wide_instance() -> Instance {
    Instance {
        key: "wide",
        problem: bench_problem(16, 3),
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

/// A 20 × 20 warehouse with walls: an outer wall, an inner wall across the middle with two
/// doors; `boxes` (≤ 12) one-cell boxes of mass 1 stored in two rows in the north half, to be
/// moved to a 4-wide block in the south half, the robot starting in the north-west corner.
pub fn warehouse_problem(boxes: usize) -> Problem {
    let side = 20;
    let mut grid = Grid::new(side, side);
    let wall = Cell {
        obstacle: true,
        ..Cell::default()
    };
    for k in 0..side {
        for (x, y) in [(k, 0), (k, side - 1), (0, k), (side - 1, k)] {
            *grid.at_mut(x, y) = wall;
        }
    }
    for x in 1..side - 1 {
        if x != 4 && x != 15 {
            *grid.at_mut(x, 9) = wall;
        }
    }
    let boxes = boxes.min(12);
    let starts: Vec<Placement> = (0..boxes as i32)
        .map(|i| Placement {
            x: 3 + 2 * (i % 6) + (i / 6),
            y: 3 + 2 * (i / 6),
            o: 0,
        })
        .collect();
    let goals = (0..boxes as i32)
        .map(|i| {
            Some(Placement {
                x: 8 + i % 4,
                y: 12 + 2 * (i / 4),
                o: 0,
            })
        })
        .collect();
    Problem {
        name: format!("{boxes}box-warehouse-20x20"),
        grid,
        robot: RobotSpec { size: 1, mass: 1 },
        movables: (0..boxes)
            .map(|i| MovableSpec::with_faces(&format!("b{i}"), vec![(0, 0)], 1))
            .collect(),
        rules: Rules::default(),
        metric: Metric::default(),
        start: Config {
            robot: (1, 1),
            heading: Dir::E,
            pushing: false,
            movables: starts,
        },
        goal_robot: None,
        goal_movables: goals,
    }
}

/// What one instance measured.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// Instance name.
    pub name: String,
    /// Movables.
    pub movables: usize,
    /// Configurations of the exact map.
    pub configurations: f64,
    /// Estimated bytes of the exact map.
    pub map_bytes_estimate: u64,
    /// Why the exact planner refused, if it did.
    pub exact_refused: Option<String>,
    /// Exact: configurations mapped.
    pub states_mapped: Option<u64>,
    /// Exact: table building, ms.
    pub tables_ms: Option<f64>,
    /// Exact: map wall time, ms.
    pub map_ms: Option<f64>,
    /// Exact: CPU time of all threads during the map, ms.
    pub map_cpu_ms: Option<f64>,
    /// `map_cpu_ms / map_ms`: how many cores worked.
    pub cores_busy: Option<f64>,
    /// Exact: configurations settled per second of wall time.
    pub states_per_s: Option<f64>,
    /// Exact: bytes of the map and its wave front.
    pub map_bytes: Option<u64>,
    /// Exact: the optimal cost.
    pub cost: Option<u32>,
    /// Practical: the plan's cost.
    pub practical_cost: Option<u32>,
    /// Practical: wall time, ms.
    pub practical_ms: Option<f64>,
    /// Practical: object-level nodes expanded.
    pub practical_expansions: Option<usize>,
    /// Practical cost over the optimum, where both ran.
    pub practical_over_optimum: Option<f64>,
    /// Peak resident memory of this instance, KiB (VmHWM after a reset).
    pub peak_kib: Option<u64>,
}

/// Run one instance: the exact map if it fits, then the practical mode.
pub fn run(inst: &Instance, practical: bool) -> Row {
    let p = &inst.problem;
    reset_peak();
    let budget = ExactBudget::of(p);
    let mut row = Row {
        name: p.name.clone(),
        movables: p.movables.len(),
        configurations: budget.configurations_f64,
        map_bytes_estimate: budget.bytes,
        exact_refused: budget.check().err().map(|e| e.to_string()),
        states_mapped: None,
        tables_ms: None,
        map_ms: None,
        map_cpu_ms: None,
        cores_busy: None,
        states_per_s: None,
        map_bytes: None,
        cost: None,
        practical_cost: None,
        practical_ms: None,
        practical_expansions: None,
        practical_over_optimum: None,
        peak_kib: None,
    };
    let t0 = Instant::now();
    if row.exact_refused.is_none() {
        match Model::new(p) {
            Err(e) => row.exact_refused = Some(e.to_string()),
            Ok(model) => {
                row.tables_ms = Some(t0.elapsed().as_secs_f64() * 1e3);
                let cpu0 = process_cpu_ms();
                match rearrange::cost_map(&model) {
                    Err(e) => row.exact_refused = Some(e.to_string()),
                    Ok(map) => {
                        let cpu = process_cpu_ms().zip(cpu0).map(|(b, a)| b - a);
                        let st = map.stats;
                        row.states_mapped = Some(st.states_mapped);
                        row.map_ms = Some(st.map_ms);
                        row.map_cpu_ms = cpu;
                        row.cores_busy = cpu.map(|c| c / st.map_ms.max(1e-9));
                        row.states_per_s =
                            Some(st.states_mapped as f64 / (st.map_ms / 1e3).max(1e-9));
                        row.map_bytes = Some(st.map_bytes);
                        row.cost = model.pack(&p.start).and_then(|s| map.get(s));
                    }
                }
            }
        }
    }
    row.peak_kib = peak_kib();
    if practical && let Ok(plan) = plan_practical(p, &Options::for_problem(p)) {
        row.practical_cost = Some(plan.cost);
        row.practical_ms = Some(plan.plan_ms);
        row.practical_expansions = Some(plan.expansions);
        row.practical_over_optimum = row.cost.map(|c| plan.cost as f64 / c.max(1) as f64);
    }
    row
}

/// Peak resident memory of this process in KiB (VmHWM), if the system tells.
pub fn peak_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Reset this process's peak resident memory (`/proc/self/clear_refs`), so that each instance
/// reports its own; without it the peak is the process's so far.
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// CPU time of this process, all its threads, in ms (utime + stime from /proc, 10 ms
/// resolution), if the system tells; over the map's wall time it says how many cores worked.
pub fn process_cpu_ms() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    Some(ticks as f64 * 10.0)
}

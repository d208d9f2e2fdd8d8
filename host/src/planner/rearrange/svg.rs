//! Plans drawn as the step-by-step figures of Ben-Shahar & Rivlin §V-A (Figs. 9–19): one panel
//! per stage (a transit path, drawn as an arrow, then the pushes that follow it), ordered left to
//! right, top to bottom. Obstacles are black, rough cells grey (darker for very rough), cells
//! where movables may not be left hatched, goals dashed outlines, movables where the stage
//! leaves them (faint where it found them).

use super::admissibility::MoveKind;
use super::practical::{Action, PracticalPlan};
use super::problem::{Config, Model, Problem};
use super::restore::Plan;
use crate::plot::svg::{Doc, Draw, Group, Style};

const CELL: f64 = 18.0;
const PAD: f64 = 10.0;
/// The robot, its path and the path's arrowhead.
const BLUE: &str = "#1c7ed6";
const COLORS: [&str; 4] = ["#d9822b", "#2b8a3e", "#7048e8", "#c2255c"];

/// One move of a plan as drawn: does it push, and where it leaves everything.
#[derive(Debug, Clone, Copy)]
pub struct Drawn<'a> {
    /// A pushing move (translational or rotational).
    pub push: bool,
    /// The configuration after it.
    pub config: &'a Config,
}

/// The moves of an exact plan, for drawing.
fn drawn(plan: &Plan) -> Vec<Drawn<'_>> {
    plan.steps
        .iter()
        .map(|s| Drawn {
            push: s.step.kind != MoveKind::Transit,
            config: &s.config,
        })
        .collect()
}

/// The plan's stages: index ranges of steps, each transit moves then push moves.
pub fn stages(plan: &Plan) -> Vec<std::ops::Range<usize>> {
    stages_of(&drawn(plan))
}

/// Stages of drawn moves: each transit moves then push moves.
fn stages_of(moves: &[Drawn]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 0..moves.len() {
        let next_transit = moves.get(i + 1).is_none_or(|s| !s.push);
        if (moves[i].push && next_transit) || i + 1 == moves.len() {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    out
}

fn centre(x: i32, y: i32, size: i32) -> [f64; 2] {
    [
        (x as f64 + size as f64 / 2.0) * CELL,
        (y as f64 + size as f64 / 2.0) * CELL,
    ]
}

fn draw_movables(g: &mut Group, problem: &Problem, c: &Config, opacity: f64, outline_only: bool) {
    for (i, p) in c.movables.iter().enumerate() {
        let spec = &problem.movables[i];
        let col = COLORS[i % COLORS.len()];
        let style = if outline_only {
            Style::outline(col, 1.5).dash("3,2")
        } else {
            Style::new().fill(col).fill_opacity(opacity).stroke(col)
        };
        for (cx, cy) in spec.cells_at(p.o) {
            let at = [(p.x + cx) as f64 * CELL, (p.y + cy) as f64 * CELL];
            g.rect(at, [CELL, CELL], &style);
        }
        if !outline_only && opacity > 0.5 {
            let at = [(p.x as f64 + 0.5) * CELL, (p.y as f64 + 0.5) * CELL + 4.0];
            let label = Style::new().fill("white").font_size(11.0).anchor("middle");
            g.text(at, &spec.name, &label);
        }
    }
}

fn panel(g: &mut Group, problem: &Problem, before: &Config, steps: &[&Config], title: &str) {
    let grid = &problem.grid;
    let k = problem.robot.size;
    g.text([0.0, -3.0], title, &Style::new().font_size(11.0));
    for y in 0..grid.h {
        for x in 0..grid.w {
            let c = grid.cells[(y * grid.w + x) as usize];
            let fill = if c.obstacle {
                "#222"
            } else if c.rough == 2 {
                "#aaa"
            } else if c.rough == 1 {
                "#ccc"
            } else {
                "#fff"
            };
            let at = [x as f64 * CELL, y as f64 * CELL];
            g.rect(at, [CELL, CELL], &Style::new().fill(fill).stroke("#eee"));
            if c.no_leave {
                let end = [at[0] + CELL, at[1] + CELL];
                g.line(at, end, &Style::new().stroke("#999"));
            }
        }
    }
    // goals
    let goal = Config {
        robot: (0, 0),
        heading: before.heading,
        pushing: false,
        movables: (0..problem.movables.len())
            .map(|i| {
                problem.goal_movables[i].unwrap_or(super::problem::Placement {
                    x: -100,
                    y: -100,
                    o: 0,
                })
            })
            .collect(),
    };
    draw_movables(g, problem, &goal, 1.0, true);
    draw_movables(g, problem, before, 0.25, false);
    let last = steps.last().copied().unwrap_or(before);
    draw_movables(g, problem, last, 0.9, false);
    // robot path
    let mut pts = vec![centre(before.robot.0, before.robot.1, k)];
    pts.extend(steps.iter().map(|c| centre(c.robot.0, c.robot.1, k)));
    g.polyline(&pts, &Style::outline(BLUE, 2.0).arrow_end("arrow"));
    let at = [
        last.robot.0 as f64 * CELL + 2.0,
        last.robot.1 as f64 * CELL + 2.0,
    ];
    let side = k as f64 * CELL - 4.0;
    g.rect(
        at,
        [side, side],
        &Style::new()
            .fill(BLUE)
            .fill_opacity(0.8)
            .rounded(side / 2.0),
    );
}

/// Draw the plan as an SVG document of step panels.
pub fn plan_svg(model: &Model, plan: &Plan) -> String {
    plan_svg_in(model, plan, None)
}

/// [`plan_svg`] with axes in metres on every panel when the grid's cells are `cell` metres
/// wide (row 0 along the table's far edge, so y counts up from the last row).
pub fn plan_svg_in(model: &Model, plan: &Plan, cell: Option<f64>) -> String {
    moves_svg(&model.problem, &plan.start, &drawn(plan), cell)
}

/// A practical-mode plan drawn the same way (one panel per transit and the pushes after it).
pub fn practical_svg(problem: &Problem, plan: &PracticalPlan, cell: Option<f64>) -> String {
    let moves: Vec<Drawn> = plan
        .moves
        .iter()
        .map(|m| Drawn {
            push: m.action != Action::Transit,
            config: &m.config,
        })
        .collect();
    moves_svg(problem, &plan.start, &moves, cell)
}

/// Panels of drawn moves from `start`.
fn moves_svg(problem: &Problem, start: &Config, moves: &[Drawn], cell: Option<f64>) -> String {
    let grid = &problem.grid;
    // Room for the axes' labels on the left and below.
    let (left, below) = if cell.is_some() {
        (34.0, 18.0)
    } else {
        (0.0, 0.0)
    };
    let st = stages_of(moves);
    let panels = st.len().max(1);
    let cols = panels.min(3);
    let rows = panels.div_ceil(cols);
    let pw = grid.w as f64 * CELL + 2.0 * PAD + left;
    let ph = grid.h as f64 * CELL + 2.0 * PAD + 14.0 + below;
    let mut d = Doc::new(cols as f64 * pw, rows as f64 * ph);
    d.title(&problem.name);
    d.arrow_marker("arrow", BLUE);
    d.background(&Style::new().fill("white"));
    let mut before = start.clone();
    if st.is_empty() {
        let mut g = Group::translated(PAD + left, PAD + 14.0);
        let title = format!("{}: already at the goal", problem.name);
        panel(&mut g, problem, &before, &[], &title);
        if let Some(c) = cell {
            axes(&mut g, grid.w, grid.h, c);
        }
        d.group(g);
    }
    for (n, range) in st.iter().enumerate() {
        let (col, row) = (n % cols, n / cols);
        let mut g = Group::translated(col as f64 * pw + PAD + left, row as f64 * ph + PAD + 14.0);
        let cfgs: Vec<&Config> = moves[range.clone()].iter().map(|p| p.config).collect();
        let pushes = moves[range.clone()].iter().filter(|p| p.push).count();
        let title = format!(
            "{} step {}: {} moves, {} pushes",
            problem.name,
            n + 1,
            range.len(),
            pushes
        );
        panel(&mut g, problem, &before, &cfgs, &title);
        if let Some(c) = cell {
            axes(&mut g, grid.w, grid.h, c);
        }
        d.group(g);
        if let Some(c) = cfgs.last() {
            before = (*c).clone();
        }
    }
    d.to_string()
}

/// Ticks in metres along a panel's bottom and left edges (cells of `cell` metres).
fn axes(g: &mut Group, w: i32, h: i32, cell: f64) {
    let step = crate::plot::axes::tick_step(f64::from(w.max(h)) * cell);
    let every = (step / cell).round().max(1.0) as usize;
    let ink = Style::new().stroke("#444");
    let label = Style::new().fill("#333").font_size(9.0);
    let bottom = f64::from(h) * CELL;
    for x in (0..=w).step_by(every) {
        let px = f64::from(x) * CELL;
        g.line([px, bottom], [px, bottom + 4.0], &ink);
        let text = format!("{:.1}", f64::from(x) * cell);
        g.text([px, bottom + 13.0], &text, &label.clone().anchor("middle"));
    }
    for y in (0..=h).step_by(every) {
        // Row `h - y` from the top is `y` cells up from the near edge.
        let py = bottom - f64::from(y) * CELL;
        g.line([-4.0, py], [0.0, py], &ink);
        let text = format!("{:.1}", f64::from(y) * cell);
        g.text([-6.0, py + 3.0], &text, &label.clone().anchor("end"));
    }
    g.text(
        [f64::from(w) * CELL, bottom + 13.0],
        "m",
        &label.anchor("start"),
    );
}

//! Plans drawn as the step-by-step figures of Ben-Shahar & Rivlin §V-A (Figs. 9–19): one panel
//! per stage (a transit path, drawn as an arrow, then the pushes that follow it), ordered left to
//! right, top to bottom. Obstacles are black, rough cells grey (darker for very rough), cells
//! where movables may not be left hatched, goals dashed outlines, movables where the stage
//! leaves them (faint where it found them).

use std::fmt::Write;

use super::admissibility::MoveKind;
use super::problem::{Config, Model};
use super::restore::Plan;

const CELL: f64 = 18.0;
const PAD: f64 = 10.0;
const COLORS: [&str; 4] = ["#d9822b", "#2b8a3e", "#7048e8", "#c2255c"];

/// The plan's stages: index ranges of steps, each transit moves then push moves.
pub fn stages(plan: &Plan) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 0..plan.steps.len() {
        let push = plan.steps[i].step.kind != MoveKind::Transit;
        let next_transit = plan
            .steps
            .get(i + 1)
            .is_none_or(|s| s.step.kind == MoveKind::Transit);
        if (push && next_transit) || i + 1 == plan.steps.len() {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    out
}

fn centre(model: &Model, x: i32, y: i32, size: i32) -> (f64, f64) {
    let _ = model;
    (
        (x as f64 + size as f64 / 2.0) * CELL,
        (y as f64 + size as f64 / 2.0) * CELL,
    )
}

fn draw_movables(s: &mut String, model: &Model, c: &Config, opacity: f64, outline_only: bool) {
    for (i, p) in c.movables.iter().enumerate() {
        let spec = &model.problem.movables[i];
        let col = COLORS[i % COLORS.len()];
        for (cx, cy) in spec.cells_at(p.o) {
            let (x, y) = ((p.x + cx) as f64 * CELL, (p.y + cy) as f64 * CELL);
            if outline_only {
                let _ = write!(
                    s,
                    r#"<rect x="{x}" y="{y}" width="{CELL}" height="{CELL}" fill="none" stroke="{col}" stroke-dasharray="3,2" stroke-width="1.5"/>"#
                );
            } else {
                let _ = write!(
                    s,
                    r#"<rect x="{x}" y="{y}" width="{CELL}" height="{CELL}" fill="{col}" fill-opacity="{opacity}" stroke="{col}"/>"#
                );
            }
        }
        if !outline_only && opacity > 0.5 {
            let (x, y) = ((p.x as f64 + 0.5) * CELL, (p.y as f64 + 0.5) * CELL + 4.0);
            let _ = write!(
                s,
                r#"<text x="{x}" y="{y}" font-size="11" text-anchor="middle" fill="white">{}</text>"#,
                spec.name
            );
        }
    }
}

fn panel(s: &mut String, model: &Model, before: &Config, steps: &[&Config], title: &str) {
    let g = &model.problem.grid;
    let k = model.problem.robot.size;
    let _ = write!(s, r#"<text x="0" y="-3" font-size="11">{title}</text>"#);
    for y in 0..g.h {
        for x in 0..g.w {
            let c = g.cells[(y * g.w + x) as usize];
            let fill = if c.obstacle {
                "#222"
            } else if c.rough == 2 {
                "#aaa"
            } else if c.rough == 1 {
                "#ccc"
            } else {
                "#fff"
            };
            let _ = write!(
                s,
                r##"<rect x="{}" y="{}" width="{CELL}" height="{CELL}" fill="{fill}" stroke="#eee"/>"##,
                x as f64 * CELL,
                y as f64 * CELL
            );
            if c.no_leave {
                let _ = write!(
                    s,
                    r##"<path d="M{} {}l{CELL} {CELL}" stroke="#999"/>"##,
                    x as f64 * CELL,
                    y as f64 * CELL
                );
            }
        }
    }
    // goals
    let goal = Config {
        robot: (0, 0),
        heading: before.heading,
        pushing: false,
        movables: (0..model.r())
            .map(|i| {
                model.problem.goal_movables[i].unwrap_or(super::problem::Placement {
                    x: -100,
                    y: -100,
                    o: 0,
                })
            })
            .collect(),
    };
    draw_movables(s, model, &goal, 1.0, true);
    draw_movables(s, model, before, 0.25, false);
    let last = steps.last().copied().unwrap_or(before);
    draw_movables(s, model, last, 0.9, false);
    // robot path
    let mut pts = vec![centre(model, before.robot.0, before.robot.1, k)];
    pts.extend(steps.iter().map(|c| centre(model, c.robot.0, c.robot.1, k)));
    if pts.len() > 1 {
        let d: String = pts.iter().map(|(x, y)| format!("{x:.1},{y:.1} ")).collect();
        let _ = write!(
            s,
            r##"<polyline points="{d}" fill="none" stroke="#1c7ed6" stroke-width="2" marker-end="url(#arrow)"/>"##
        );
    }
    let (rx, ry) = (
        last.robot.0 as f64 * CELL + 2.0,
        last.robot.1 as f64 * CELL + 2.0,
    );
    let side = k as f64 * CELL - 4.0;
    let _ = write!(
        s,
        r##"<rect x="{rx}" y="{ry}" width="{side}" height="{side}" rx="{}" fill="#1c7ed6" fill-opacity="0.8"/>"##,
        side / 2.0
    );
}

/// Draw the plan as an SVG document of step panels.
pub fn plan_svg(model: &Model, plan: &Plan) -> String {
    let g = &model.problem.grid;
    let st = stages(plan);
    let panels = st.len().max(1);
    let cols = panels.min(3);
    let rows = panels.div_ceil(cols);
    let pw = g.w as f64 * CELL + 2.0 * PAD;
    let ph = g.h as f64 * CELL + 2.0 * PAD + 14.0;
    let mut s = String::new();
    let _ = write!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" font-family="sans-serif"><defs><marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="6" markerHeight="6" orient="auto-start-reverse"><path d="M0 0L10 5L0 10z" fill="#1c7ed6"/></marker></defs><rect width="100%" height="100%" fill="white"/>"##,
        cols as f64 * pw,
        rows as f64 * ph
    );
    let mut before = plan.start.clone();
    if st.is_empty() {
        let _ = write!(s, r#"<g transform="translate({PAD},{})">"#, PAD + 14.0);
        panel(
            &mut s,
            model,
            &before,
            &[],
            &format!("{}: already at the goal", model.problem.name),
        );
        s.push_str("</g>");
    }
    for (n, range) in st.iter().enumerate() {
        let (col, row) = (n % cols, n / cols);
        let _ = write!(
            s,
            r#"<g transform="translate({},{})">"#,
            col as f64 * pw + PAD,
            row as f64 * ph + PAD + 14.0
        );
        let cfgs: Vec<&Config> = plan.steps[range.clone()]
            .iter()
            .map(|p| &p.config)
            .collect();
        let pushes = plan.steps[range.clone()]
            .iter()
            .filter(|p| p.step.kind != MoveKind::Transit)
            .count();
        let title = format!(
            "{} step {}: {} moves, {} pushes",
            model.problem.name,
            n + 1,
            range.len(),
            pushes
        );
        panel(&mut s, model, &before, &cfgs, &title);
        s.push_str("</g>");
        if let Some(c) = cfgs.last() {
            before = (*c).clone();
        }
    }
    s.push_str("</svg>\n");
    s
}

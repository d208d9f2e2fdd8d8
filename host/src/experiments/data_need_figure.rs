//! The data-need figure (`eval delivery --figure 7`): one panel per object, success %
//! of the test deliveries (y) against samples in the strategy (x), one line per collection
//! [`super::data_need::Variant`], a dashed mark where each reached Lau et al.'s 10-streak
//! (§III-D), and the 300-sample budget.

use super::data_need::Curve;
use crate::plot::axes::tick_step;
use crate::plot::svg::{Doc, Draw, Group, Style};

const PANEL: [f64; 2] = [340.0, 220.0];
const PLOT: [f64; 2] = [270.0, 150.0];
const LEFT: f64 = 50.0;
const TOP: f64 = 30.0;
const COLUMNS: usize = 3;
/// The Done-when's sample budget, drawn in every panel.
const BUDGET: f64 = 300.0;

fn colour(variant: &str) -> &'static str {
    match variant {
        "paper" => "#777",
        "random" => "#e08000",
        "uncertain" => "#20a060",
        _ => "#1060c0",
    }
}

/// The figure as SVG text.
pub fn data_need_svg(curves: &[Curve]) -> String {
    let mut scenes: Vec<&str> = Vec::new();
    for c in curves {
        if !scenes.contains(&c.scene.as_str()) {
            scenes.push(&c.scene);
        }
    }
    let x_max = curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.samples as f64))
        .fold(BUDGET, f64::max);
    let step = tick_step(x_max);
    let x_max = (x_max / step).ceil() * step;
    let rows = scenes.len().div_ceil(COLUMNS).max(1);
    let mut d = Doc::new(
        PANEL[0] * COLUMNS.min(scenes.len().max(1)) as f64,
        PANEL[1] * rows as f64 + 40.0,
    );
    d.background(&Style::new().fill("white"));
    d.caption(
        "Data need: success % of test deliveries vs samples collected (dashed: 10-streak reached; red: 300)",
        14.0,
        &Style::new(),
    );
    let ink = Style::new().stroke("#444").width(1.0);
    let label = Style::new().fill("#333").font_size(10.0);
    for (i, scene) in scenes.iter().enumerate() {
        let mut g = Group::translated(
            (i % COLUMNS) as f64 * PANEL[0] + LEFT,
            (i / COLUMNS) as f64 * PANEL[1] + TOP + 30.0,
        );
        let map = |x: f64, y: f64| [PLOT[0] * x / x_max, PLOT[1] * (1.0 - y / 100.0)];
        g.rect([0.0, 0.0], PLOT, &Style::outline("#444", 1.0).fill("none"));
        g.text([0.0, -8.0], scene, &Style::new().font_size(12.0));
        let mut x = 0.0;
        while x <= x_max + 1e-9 {
            let p = map(x, 0.0);
            g.line(p, [p[0], p[1] + 4.0], &ink);
            g.text(
                [p[0], p[1] + 15.0],
                &format!("{x:.0}"),
                &label.clone().anchor("middle"),
            );
            x += step;
        }
        for y in [0.0, 50.0, 100.0] {
            let p = map(0.0, y);
            g.line(p, [p[0] - 4.0, p[1]], &ink);
            g.text(
                [p[0] - 6.0, p[1] + 3.0],
                &format!("{y:.0}%"),
                &label.clone().anchor("end"),
            );
        }
        g.line(
            map(BUDGET, 0.0),
            map(BUDGET, 100.0),
            &Style::outline("#c00000", 1.0).dash("2,3"),
        );
        for c in curves.iter().filter(|c| c.scene == *scene) {
            let col = colour(c.variant.name);
            let pts: Vec<[f64; 2]> = c
                .points
                .iter()
                .map(|p| map(p.samples as f64, p.rate()))
                .collect();
            g.polyline(&pts, &Style::outline(col, 1.8).tip(c.variant.name));
            for p in &pts {
                g.circle(*p, 2.0, &Style::new().fill(col));
            }
            if let Some(n) = c.streak_at {
                g.line(
                    map(n as f64, 0.0),
                    map(n as f64, 100.0),
                    &Style::outline(col, 1.2).dash("5,3"),
                );
            }
        }
        d.group(g);
    }
    // Legend.
    let mut x = 10.0;
    let y = PANEL[1] * rows as f64 + 30.0;
    let mut names: Vec<&str> = curves.iter().map(|c| c.variant.name).collect();
    names.dedup();
    names.sort_unstable();
    names.dedup();
    for n in names {
        d.line(
            [x, y - 4.0],
            [x + 20.0, y - 4.0],
            &Style::outline(colour(n), 2.0),
        );
        d.text([x + 24.0, y], n, &Style::new().font_size(11.0));
        x += 110.0;
    }
    d.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::collect::CollectReport;
    use crate::experiments::data_need::{CurvePoint, VARIANTS};

    #[test]
    fn one_panel_per_scene_and_one_line_per_curve() {
        let curve = |scene: &str, v: usize, streak: Option<usize>| Curve {
            scene: scene.to_owned(),
            variant: VARIANTS[v],
            streak_at: streak,
            collection: CollectReport::default(),
            points: (1..=4)
                .map(|i| CurvePoint {
                    samples: 25 * i,
                    tests: 6,
                    successes: i,
                })
                .collect(),
        };
        let curves = [
            curve("lau-a", 0, None),
            curve("lau-a", 2, Some(100)),
            curve("lau-b", 2, Some(75)),
        ];
        let svg = data_need_svg(&curves);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_eq!(svg.matches("<polyline").count(), 3);
        assert_eq!(svg.matches(">lau-a<").count(), 1);
        assert_eq!(svg.matches(">lau-b<").count(), 1);
        // Two streak marks and a budget line per panel.
        assert_eq!(svg.matches(r#"stroke-dasharray="5,3""#).count(), 2);
        assert_eq!(svg.matches(r#"stroke-dasharray="2,3""#).count(), 2);
    }
}

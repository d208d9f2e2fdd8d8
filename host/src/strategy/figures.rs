//! Plain-SVG figures in the style of Lau, Mitani & Igarashi: the pushing strategy (Fig. 7:
//! each sample's robot motion r drawn from its position p and the object motion s from the
//! marker, one colour per sample, over the object's outline) and delivery trajectories (Fig. 8:
//! robot blue, object red).

use std::fmt::Write;

use nalgebra::Vector2;
use pushbot_world::Scene;

use super::sample::{Pose2, Sample};

fn colour(i: usize, n: usize) -> String {
    let hue = 360.0 * i as f64 / n.max(1) as f64;
    format!("hsl({hue:.0},80%,45%)")
}

fn polygon(points: &[[f64; 2]], map: impl Fn([f64; 2]) -> (f64, f64)) -> String {
    points
        .iter()
        .map(|p| {
            let (x, y) = map(*p);
            format!("{x:.1},{y:.1}")
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The pushing strategy in the object's frame (marker at the centre), 1 px = 0.5 mm.
pub fn strategy_svg(samples: &[Sample], outline: &[[f64; 2]]) -> String {
    let half = samples
        .iter()
        .flat_map(|s| [s.p[0].abs(), s.p[1].abs()])
        .chain(outline.iter().flat_map(|v| [v[0].abs(), v[1].abs()]))
        .fold(0.1f64, f64::max)
        + 0.05;
    let scale = 2000.0; // px per m
    let size = 2.0 * half * scale;
    let map = |p: [f64; 2]| ((p[0] + half) * scale, (half - p[1]) * scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{size:.0}" height="{size:.0}" viewBox="0 0 {size:.0} {size:.0}">"#
    );
    let _ = writeln!(
        s,
        r#"<rect width="100%" height="100%" fill="white"/><polygon points="{}" fill="lightgrey" stroke="black"/>"#,
        polygon(outline, map)
    );
    for (i, smp) in samples.iter().enumerate() {
        let c = colour(i, samples.len());
        let (x0, y0) = map(smp.p);
        let (x1, y1) = map([smp.p[0] + smp.r[0], smp.p[1] + smp.r[1]]);
        let (sx, sy) = map(smp.s);
        let (ox, oy) = map([0.0, 0.0]);
        let _ = writeln!(
            s,
            r#"<line x1="{x0:.1}" y1="{y0:.1}" x2="{x1:.1}" y2="{y1:.1}" stroke="{c}" stroke-width="1.5"/><circle cx="{x0:.1}" cy="{y0:.1}" r="2" fill="{c}"/><line x1="{ox:.1}" y1="{oy:.1}" x2="{sx:.1}" y2="{sy:.1}" stroke="{c}" stroke-width="1" opacity="0.6"/>"#
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="8" y="20" font-family="sans-serif" font-size="16">{} samples</text></svg>"#,
        samples.len()
    );
    s
}

/// Trajectories of robot (blue) and object marker (red) on the scene's table, one group per
/// labelled run, with the goal and the start positions.
pub fn trajectories_svg(
    runs: &[(String, Vec<(Pose2, Pose2)>)],
    scene: &Scene,
    goal: Vector2<f64>,
) -> String {
    let scale = 500.0;
    let (w, h) = (scene.table.width * scale, scene.table.height * scale);
    let map = |x: f64, y: f64| (x * scale, h - y * scale);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}"><rect width="100%" height="100%" fill="white" stroke="black"/>"#
    );
    let (gx, gy) = map(goal.x, goal.y);
    let _ = writeln!(
        s,
        r#"<circle cx="{gx:.1}" cy="{gy:.1}" r="{:.1}" fill="none" stroke="green" stroke-width="2"/>"#,
        0.022 * scale
    );
    for p in &scene.positions {
        let (x, y) = map(p.pose.x, p.pose.y);
        let _ = writeln!(
            s,
            r#"<text x="{x:.1}" y="{y:.1}" font-family="sans-serif" font-size="14">{}</text>"#,
            p.name
        );
    }
    for (label, traj) in runs {
        for (pick, colour) in [(0usize, "blue"), (1, "red")] {
            let pts: Vec<String> = traj
                .iter()
                .map(|(r, o)| {
                    let q = if pick == 0 { r } else { o };
                    let (x, y) = map(q.x, q.y);
                    format!("{x:.1},{y:.1}")
                })
                .collect();
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="1.5"><title>{label}</title></polyline>"#,
                pts.join(" ")
            );
        }
    }
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strategy_svg_draws_one_arrow_pair_per_sample() {
        let smp = Sample {
            p: [-0.1, 0.0],
            r: [0.03, 0.0],
            s: [0.02, 0.001],
            theta: 0.0,
        };
        let svg = strategy_svg(&[smp; 3], &[[-0.05, -0.05], [0.05, -0.05], [0.0, 0.05]]);
        assert_eq!(svg.matches("<line").count(), 6);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    }
}

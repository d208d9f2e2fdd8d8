//! Plain-SVG figures in the style of Lau, Mitani & Igarashi: the pushing strategy (Fig. 7:
//! each sample's robot motion r drawn from its position p and the object motion s from the
//! marker, one colour per sample, over the object's outline) and delivery trajectories (Fig. 8:
//! robot blue, object red).

use nalgebra::Vector2;
use pushbot_world::Scene;

use super::sample::{Pose2, Sample};
use crate::plot::svg::{Doc, Draw, Frame, Style};

fn colour(i: usize, n: usize) -> String {
    let hue = 360.0 * i as f64 / n.max(1) as f64;
    format!("hsl({hue:.0},80%,45%)")
}

/// The pushing strategy in the object's frame (marker at the centre), 1 px = 0.5 mm.
pub fn strategy_svg(samples: &[Sample], outline: &[[f64; 2]]) -> String {
    let half = samples
        .iter()
        .flat_map(|s| [s.p[0].abs(), s.p[1].abs()])
        .chain(outline.iter().flat_map(|v| [v[0].abs(), v[1].abs()]))
        .fold(0.1f64, f64::max)
        + 0.05;
    let f = Frame::region([-half, -half], [half, half], 2000.0)
        .with_margin(44.0)
        .with_band(24.0);
    let mut d = Doc::for_frame(&f);
    d.background(&Style::new().fill("white"));
    crate::plot::axes::metre_axes(&mut d, &f, [-half, -half], [half, half]);
    d.polygon(
        &f.map_all(outline),
        &Style::new().fill("lightgrey").stroke("black"),
    );
    let marker = f.map([0.0, 0.0]);
    for (i, smp) in samples.iter().enumerate() {
        let c = colour(i, samples.len());
        let p = f.map(smp.p);
        let r = f.map([smp.p[0] + smp.r[0], smp.p[1] + smp.r[1]]);
        d.line(p, r, &Style::new().stroke(&c).width(1.5));
        d.circle(p, 2.0, &Style::new().fill(&c));
        d.line(
            marker,
            f.map(smp.s),
            &Style::new().stroke(&c).width(1.0).opacity(0.6),
        );
    }
    d.caption(
        &format!(
            "{} samples (object frame, origin at its marker)",
            samples.len()
        ),
        16.0,
        &Style::new(),
    );
    d.to_string()
}

/// The scene's table at 2 mm a pixel, its obstacles (grey) and the `goal` (a green circle): the
/// ground delivery figures are drawn on, and the frame that maps the table onto it.
pub fn table_doc(scene: &Scene, goal: Vector2<f64>) -> (Frame, Doc) {
    let f = Frame::table(scene.table.width, scene.table.height, 500.0);
    let mut d = Doc::for_frame(&f);
    d.background(&Style::new().fill("white").stroke("black"));
    for o in &scene.obstacles {
        d.polygon(&f.map_all(&o.outline), &Style::new().fill("#777"));
    }
    d.circle(
        f.map([goal.x, goal.y]),
        f.length(0.022),
        &Style::outline("green", 2.0),
    );
    (f, d)
}

/// Trajectories of robot (blue) and object marker (red) on the scene's table, one group per
/// labelled run, with the obstacles, the goal and the start positions.
pub fn trajectories_svg(
    runs: &[(String, Vec<(Pose2, Pose2)>)],
    scene: &Scene,
    goal: Vector2<f64>,
) -> String {
    let (f, mut d) = table_doc(scene, goal);
    for p in &scene.positions {
        let at = f.map([p.pose.x, p.pose.y]);
        d.text(at, &p.name, &Style::new().font_size(14.0));
    }
    for (label, traj) in runs {
        let robot: Vec<[f64; 2]> = traj.iter().map(|(r, _)| f.map([r.x, r.y])).collect();
        let object: Vec<[f64; 2]> = traj.iter().map(|(_, o)| f.map([o.x, o.y])).collect();
        for (pts, colour) in [(robot, "blue"), (object, "red")] {
            d.polyline(&pts, &Style::outline(colour, 1.5).tip(label));
        }
    }
    d.to_string()
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
        // Two per sample, besides the axes' ticks (drawn in #444).
        let ticks = svg.matches(r##"stroke="#444""##).count();
        assert!(ticks >= 6, "axes in metres");
        assert_eq!(svg.matches("<line").count() - ticks, 6);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    }
}

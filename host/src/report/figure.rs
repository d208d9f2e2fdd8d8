//! A run drawn on its table, as the papers draw executed pushes (Lau et al. Fig. 8; Ben-Shahar &
//! Rivlin's step-by-step figures; Lynch & Mason Fig. 13–18): obstacles, goals, every object's
//! outline where it started (dashed) and where it ended (solid), the object paths (red) and the
//! robot's path (blue), with the robot drawn at the start and at the end. Each path is drawn
//! so that what went wrong shows: a dot at every trace point (after each primitive) so loops
//! and back-and-forth read as such, the robot's path shaded from light (early) to dark (late),
//! and a ring where the robot stalled (a primitive ran and it did not move); axes in metres.

use pushbot_world::Scene;
use pushbot_world::scene::placed;

use crate::exec::record::TracePoint;
use crate::plot::axes::metre_axes;
use crate::plot::svg::{Doc, Draw, Frame, Style};
use crate::strategy::sample::Pose2;

/// Pixels per metre.
const SCALE: f64 = 600.0;
/// Room above the table for the title.
const BAND: f64 = 28.0;
/// Room around the table for the axes' ticks and labels, pixels.
const MARGIN: f64 = 44.0;
/// A robot that moved less than this between two trace points stalled, m.
const STALL_M: f64 = 0.002;

fn outline_at(scene: &Scene, id: &str, pose: &Pose2) -> Option<Vec<[f64; 2]>> {
    let o = scene.object(id)?;
    Some(placed(&o.outline, pose))
}

/// The run `trace` over `scene`, titled `title`; `truth` draws the simulator's true paths
/// instead of the camera's when the trace has them.
pub fn run_svg(scene: &Scene, trace: &[TracePoint], title: &str, truth: bool) -> String {
    let f = Frame::table(scene.table.width, scene.table.height, SCALE)
        .with_band(BAND)
        .with_margin(MARGIN);
    let mut d = Doc::for_frame(&f);
    d.title(title);
    let (at, size) = f.area();
    d.rect(
        at,
        size,
        &Style::new().fill("#f6f6f2").stroke("black").width(2.0),
    );
    d.caption(title, 16.0, &Style::new());
    metre_axes(
        &mut d,
        &f,
        [0.0, 0.0],
        [scene.table.width, scene.table.height],
    );
    for o in &scene.obstacles {
        d.polygon(&f.map_all(&o.outline), &Style::new().fill("#555"));
    }
    for g in &scene.goals {
        if let Some(pts) = outline_at(scene, &g.object, &g.pose) {
            d.polygon(&f.map_all(&pts), &Style::outline("green", 1.5).dash("2,3"));
        }
        d.circle(
            f.map([g.pose.x, g.pose.y]),
            f.length(g.tolerance).max(3.0),
            &Style::new().fill("green").opacity(0.35),
        );
    }
    let pick = |p: &TracePoint| -> (Pose2, Vec<(String, Pose2)>) {
        match (&p.truth, truth) {
            (Some(t), true) => t.clone(),
            _ => (p.robot, p.objects.clone()),
        }
    };
    let poses: Vec<(Pose2, Vec<(String, Pose2)>)> = trace.iter().map(pick).collect();
    // A drive that did not move the robot: a stall (a spin turns in place by design).
    let stalled: Vec<bool> = trace
        .iter()
        .zip(&poses)
        .enumerate()
        .map(|(i, (p, (r, _)))| {
            i > 0
                && matches!(p.after, "forward" | "drive")
                && (r.x - poses[i - 1].0.x).hypot(r.y - poses[i - 1].0.y) < STALL_M
        })
        .collect();
    for o in &scene.objects {
        let path: Vec<Pose2> = poses
            .iter()
            .filter_map(|(_, objs)| objs.iter().find(|(id, _)| *id == o.id).map(|(_, p)| *p))
            .filter(|p| p.x.is_finite() && p.y.is_finite())
            .collect();
        let (Some(first), Some(last)) = (path.first(), path.last()) else {
            continue;
        };
        if let Some(pts) = outline_at(scene, &o.id, first) {
            d.polygon(
                &f.map_all(&pts),
                &Style::new().fill("none").stroke("#888").dash("4,3"),
            );
        }
        if let Some(pts) = outline_at(scene, &o.id, last) {
            d.polygon(
                &f.map_all(&pts),
                &Style::new()
                    .fill("#e8c26a")
                    .fill_opacity(0.7)
                    .stroke("#7a5a00"),
            );
        }
        let line: Vec<[f64; 2]> = path.iter().map(|p| f.map([p.x, p.y])).collect();
        d.polyline(&line, &Style::outline("red", 2.0).tip(&o.id));
        for p in &line {
            d.circle(*p, 2.0, &Style::new().fill("red"));
        }
    }
    let (robot, stalled): (Vec<[f64; 2]>, Vec<bool>) = poses
        .iter()
        .zip(stalled)
        .map(|((r, _), s)| ([r.x, r.y], s))
        .filter(|(p, _)| p[0].is_finite() && p[1].is_finite())
        .unzip();
    // Early light, late dark: where the path crosses itself, which pass came later shows.
    let n = robot.len().max(2) - 1;
    for (i, w) in robot.windows(2).enumerate() {
        let k = i as f64 / n as f64;
        let shade = format!(
            "rgb({},{},{})",
            (150.0 * (1.0 - k)) as u8,
            (180.0 * (1.0 - k) + 40.0 * k) as u8,
            (255.0 * (1.0 - k) + 200.0 * k) as u8
        );
        d.line(f.map(w[0]), f.map(w[1]), &Style::outline(&shade, 1.6));
    }
    let mut stalls = 0;
    for (p, stalled) in robot.iter().zip(&stalled) {
        if *stalled {
            stalls += 1;
            d.circle(
                f.map(*p),
                6.0,
                &Style::outline("#f08c00", 2.0).tip("stalled"),
            );
        } else {
            d.circle(f.map(*p), 1.6, &Style::new().fill("#1c3fa0"));
        }
    }
    let legend = format!(
        "robot path light (early) to dark (late), a dot per primitive; objects red; {stalls} stall{} (a drive that did not move the robot: orange rings)",
        if stalls == 1 { "" } else { "s" }
    );
    let (at, size) = f.area();
    d.text(
        [at[0], at[1] + size[1] + 32.0],
        &legend,
        &Style::new().fill("#333").font_size(11.0),
    );
    let r = f.length(scene.robot.bumper_radius);
    for (p, fill) in [(robot.first(), "#9bb8ff"), (robot.last(), "#3b6cf0")] {
        if let Some(p) = p {
            d.circle(
                f.map(*p),
                r,
                &Style::new().fill(fill).fill_opacity(0.6).stroke("blue"),
            );
        }
    }
    d.to_string()
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_robot_that_does_not_move_is_marked_stalled() {
        let scene = Scene::preset("bsr-a").expect("preset");
        let at = |x: f64| TracePoint {
            t: x,
            after: "forward",
            robot: Pose2::new(x, 0.2, 0.0),
            objects: Vec::new(),
            truth: None,
        };
        let trace = [at(0.2), at(0.3), at(0.3), at(0.3005), at(0.4)];
        let svg = run_svg(&scene, &trace, "stall", false);
        assert!(svg.contains("2 stalls"), "{svg}");
        assert_eq!(svg.matches("<title>stalled</title>").count(), 2);
    }

    #[test]
    fn draws_obstacles_goals_paths_and_the_robot() {
        let scene = Scene::preset("bsr-a").expect("preset");
        let ids: Vec<String> = scene.objects.iter().map(|o| o.id.clone()).collect();
        let at = |dx: f64| TracePoint {
            t: dx,
            after: "forward",
            robot: Pose2::new(0.2 + dx, 0.2, 0.0),
            objects: ids
                .iter()
                .map(|id| {
                    let p = scene.object(id).expect("object").pose;
                    (id.clone(), Pose2::new(p.x + dx, p.y, p.theta))
                })
                .collect(),
            truth: None,
        };
        let svg = run_svg(&scene, &[at(0.0), at(0.1), at(0.2)], "A", false);
        assert_eq!(svg.matches("fill=\"#555\"").count(), scene.obstacles.len());
        assert_eq!(svg.matches("stroke=\"red\"").count(), scene.objects.len());
        // Goals, the robot at both ends, a dot per trace point for the robot and each object.
        assert_eq!(
            svg.matches("<circle").count(),
            scene.goals.len() + 2 + 3 * (1 + scene.objects.len())
        );
        assert!(svg.contains("x, y in metres"));
        assert!(svg.contains("0 stalls"));
        assert!(svg.trim_end().ends_with("</svg>"));
    }
}

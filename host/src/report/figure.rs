//! A run drawn on its table, as the papers draw executed pushes (Lau et al. Fig. 8; Ben-Shahar &
//! Rivlin's step-by-step figures; Lynch & Mason Fig. 13–18): obstacles, goals, every object's
//! outline where it started (dashed) and where it ended (solid), the object paths (red) and the
//! robot's path (blue), with the robot drawn at the start and at the end.

use pushbot_world::Scene;
use pushbot_world::scene::placed;

use crate::exec::record::TracePoint;
use crate::plot::svg::{Doc, Draw, Frame, Style};
use crate::strategy::sample::Pose2;

/// Pixels per metre.
const SCALE: f64 = 600.0;
/// Room above the table for the title.
const BAND: f64 = 28.0;

fn outline_at(scene: &Scene, id: &str, pose: &Pose2) -> Option<Vec<[f64; 2]>> {
    let o = scene.object(id)?;
    Some(placed(&o.outline, pose))
}

/// The run `trace` over `scene`, titled `title`; `truth` draws the simulator's true paths
/// instead of the camera's when the trace has them.
pub fn run_svg(scene: &Scene, trace: &[TracePoint], title: &str, truth: bool) -> String {
    let f = Frame::table(scene.table.width, scene.table.height, SCALE).with_band(BAND);
    let mut d = Doc::for_frame(&f);
    d.title(title);
    let (at, size) = f.area();
    d.rect(
        at,
        size,
        &Style::new().fill("#f6f6f2").stroke("black").width(2.0),
    );
    d.caption(title, 16.0, &Style::new());
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
    }
    let robot: Vec<[f64; 2]> = poses
        .iter()
        .map(|(r, _)| [r.x, r.y])
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .collect();
    d.polyline(
        &f.map_all(&robot),
        &Style::outline("blue", 1.2).opacity(0.8),
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
        assert_eq!(svg.matches("<circle").count(), scene.goals.len() + 2);
        assert!(svg.trim_end().ends_with("</svg>"));
    }
}

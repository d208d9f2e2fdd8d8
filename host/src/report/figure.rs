//! A run drawn on its table, as the papers draw executed pushes (Lau et al. Fig. 8; Ben-Shahar &
//! Rivlin's step-by-step figures; Lynch & Mason Fig. 13–18): obstacles, goals, every object's
//! outline where it started (dashed) and where it ended (solid), the object paths (red) and the
//! robot's path (blue), with the robot drawn at the start and at the end.

use std::fmt::Write;

use pushbot_world::Scene;
use pushbot_world::scene::placed;

use crate::exec::record::TracePoint;
use crate::strategy::sample::Pose2;

/// Pixels per metre.
const SCALE: f64 = 600.0;

fn points(pts: &[[f64; 2]], h: f64) -> String {
    pts.iter()
        .map(|p| format!("{:.1},{:.1}", p[0] * SCALE, h - p[1] * SCALE))
        .collect::<Vec<_>>()
        .join(" ")
}

fn outline_at(scene: &Scene, id: &str, pose: &Pose2) -> Option<Vec<[f64; 2]>> {
    let o = scene.object(id)?;
    Some(placed(
        &o.outline,
        &pushbot_world::Pose::new(pose.x, pose.y, pose.theta),
    ))
}

/// The run `trace` over `scene`, titled `title`; `truth` draws the simulator's true paths
/// instead of the camera's when the trace has them.
pub fn run_svg(scene: &Scene, trace: &[TracePoint], title: &str, truth: bool) -> String {
    let (w, h) = (scene.table.width * SCALE, scene.table.height * SCALE);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{:.0}" viewBox="0 -28 {w:.0} {:.0}">"#,
        h + 28.0,
        h + 28.0
    );
    let _ = writeln!(
        s,
        r##"<rect x="0" y="0" width="{w:.1}" height="{h:.1}" fill="#f6f6f2" stroke="black" stroke-width="2"/>"##
    );
    let _ = writeln!(
        s,
        r#"<text x="4" y="-9" font-family="sans-serif" font-size="16">{}</text>"#,
        super::html::escape(title)
    );
    for o in &scene.obstacles {
        let _ = writeln!(
            s,
            r##"<polygon points="{}" fill="#555"/>"##,
            points(&o.outline, h)
        );
    }
    for g in &scene.goals {
        if let Some(pts) = outline_at(
            scene,
            &g.object,
            &Pose2::new(g.pose.x, g.pose.y, g.pose.theta),
        ) {
            let _ = writeln!(
                s,
                r#"<polygon points="{}" fill="none" stroke="green" stroke-width="1.5" stroke-dasharray="2,3"/>"#,
                points(&pts, h)
            );
        }
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="green" opacity="0.35"/>"#,
            g.pose.x * SCALE,
            h - g.pose.y * SCALE,
            (g.tolerance * SCALE).max(3.0)
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
            let _ = writeln!(
                s,
                r##"<polygon points="{}" fill="none" stroke="#888" stroke-dasharray="4,3"/>"##,
                points(&pts, h)
            );
        }
        if let Some(pts) = outline_at(scene, &o.id, last) {
            let _ = writeln!(
                s,
                r##"<polygon points="{}" fill="#e8c26a" fill-opacity="0.7" stroke="#7a5a00"/>"##,
                points(&pts, h)
            );
        }
        let line: Vec<[f64; 2]> = path.iter().map(|p| [p.x, p.y]).collect();
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="red" stroke-width="2"><title>{}</title></polyline>"#,
            points(&line, h),
            super::html::escape(&o.id)
        );
    }
    let robot: Vec<[f64; 2]> = poses
        .iter()
        .map(|(r, _)| [r.x, r.y])
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .collect();
    let _ = writeln!(
        s,
        r#"<polyline points="{}" fill="none" stroke="blue" stroke-width="1.2" opacity="0.8"/>"#,
        points(&robot, h)
    );
    let r = scene.robot.bumper_radius * SCALE;
    for (p, fill) in [(robot.first(), "#9bb8ff"), (robot.last(), "#3b6cf0")] {
        if let Some(p) = p {
            let _ = writeln!(
                s,
                r#"<circle cx="{:.1}" cy="{:.1}" r="{r:.1}" fill="{fill}" fill-opacity="0.6" stroke="blue"/>"#,
                p[0] * SCALE,
                h - p[1] * SCALE
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

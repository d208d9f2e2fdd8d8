//! Per-trial traces of a delivery evaluation (`pushbot eval delivery --trace-dir DIR`), to find
//! where a long path, a stall or a time-out came from (Lau et al. §V's trials, one by one). For
//! every trial run, `SCENE-START-METHOD-TRIAL.json` holds how it went (the [`Delivery`], with
//! the robot's and the object's pose after every step) and `….svg` draws it: the table, the
//! obstacles and the goal, the global path planned for each leg (dashed green, the later ones
//! darker), the robot's track (blue), the object's marker track (red), its outline every few
//! steps (fading in as the trial goes on), and each stall recovered (orange, with what was
//! tried).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use nalgebra::Vector2;
use pushbot_world::Scene;
use serde::Serialize;

use super::trials::Method;
use crate::exec::deliver::Delivery;
use crate::plot::svg::{Draw, Style};
use crate::strategy::figures::table_doc;

/// Outlines drawn along one trial's track, at most.
const OUTLINES: usize = 24;

/// The folder traces are written to.
#[derive(Debug, Clone)]
pub struct TraceDir {
    dir: PathBuf,
}

/// One trial's JSON file.
#[derive(Serialize)]
struct TraceFile<'a> {
    scene: &'a str,
    start: &'a str,
    method: Method,
    trial: usize,
    goal: [f64; 2],
    delivery: &'a Delivery,
    /// `[[robot x, y, θ], [object marker x, y, θ]]` after every step.
    trajectory: Vec<[[f64; 3]; 2]>,
}

impl TraceDir {
    /// The folder `dir`, created if it is not there.
    pub fn create(dir: &Path) -> Result<TraceDir> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the trace folder {}", dir.display()))?;
        Ok(TraceDir {
            dir: dir.to_owned(),
        })
    }

    /// Write trial `trial` of `method` from `start` in `scene` (the object's `outline` relative
    /// to its marker): its JSON and its SVG.
    #[allow(clippy::too_many_arguments)]
    pub fn write(
        &self,
        scene: &Scene,
        goal: Vector2<f64>,
        outline: &[[f64; 2]],
        start: &str,
        method: Method,
        trial: usize,
        d: &Delivery,
    ) -> Result<()> {
        let name = format!(
            "{}-{start}-{}-{trial:03}",
            scene.name,
            match method {
                Method::Learned => "learned",
                Method::Dipole => "dipole",
            }
        );
        let file = TraceFile {
            scene: &scene.name,
            start,
            method,
            trial,
            goal: [goal.x, goal.y],
            delivery: d,
            trajectory: d
                .trajectory
                .iter()
                .map(|(r, o)| [[r.x, r.y, r.theta], [o.x, o.y, o.theta]])
                .collect(),
        };
        let json = self.dir.join(format!("{name}.json"));
        std::fs::write(&json, serde_json::to_string(&file)?)
            .with_context(|| format!("writing {}", json.display()))?;
        let svg = self.dir.join(format!("{name}.svg"));
        std::fs::write(&svg, trial_svg(scene, goal, outline, d, &name))
            .with_context(|| format!("writing {}", svg.display()))
    }
}

/// One trial drawn on its table (see the module doc), titled `title`.
pub fn trial_svg(
    scene: &Scene,
    goal: Vector2<f64>,
    outline: &[[f64; 2]],
    d: &Delivery,
    title: &str,
) -> String {
    let (f, mut doc) = table_doc(scene, goal);
    // The paths planned, one per leg, the later ones darker.
    for (k, path) in d.paths.iter().enumerate() {
        let shade = 0.3 + 0.6 * (k + 1) as f64 / d.paths.len() as f64;
        doc.polyline(
            &f.map_all(path),
            &Style::outline("#2a2", 1.5)
                .dash("6 4")
                .opacity(shade)
                .tip(&format!("path planned for leg {}", k + 1)),
        );
    }
    let n = d.trajectory.len();
    let every = n.div_ceil(OUTLINES).max(1);
    for (k, (_, o)) in d.trajectory.iter().enumerate() {
        if k % every != 0 && k + 1 != n {
            continue;
        }
        let (c, s) = (o.theta.cos(), o.theta.sin());
        let pts: Vec<[f64; 2]> = outline
            .iter()
            .map(|p| [o.x + c * p[0] - s * p[1], o.y + s * p[0] + c * p[1]])
            .collect();
        let fade = 0.15 + 0.6 * (k + 1) as f64 / n as f64;
        doc.polygon(
            &f.map_all(&pts),
            &Style::outline("#a33", 1.0)
                .opacity(fade)
                .tip(&format!("step {k}")),
        );
    }
    let robot: Vec<[f64; 2]> = d
        .trajectory
        .iter()
        .map(|(r, _)| f.map([r.x, r.y]))
        .collect();
    let object: Vec<[f64; 2]> = d
        .trajectory
        .iter()
        .map(|(_, o)| f.map([o.x, o.y]))
        .collect();
    doc.polyline(&robot, &Style::outline("blue", 1.0).opacity(0.6));
    doc.polyline(&object, &Style::outline("red", 1.5));
    for r in &d.recoveries {
        doc.circle(
            f.map(r.at),
            f.length(0.012),
            &Style::new()
                .fill("orange")
                .tip(&format!("{:.1} s: {}", r.t, r.action)),
        );
    }
    let ratio = d
        .shortest_path
        .filter(|s| *s > 0.0)
        .map_or("-".to_owned(), |s| format!("{:.2}×", d.body_path / s));
    let line = format!(
        "{title}: {}, {:.1} s, path {ratio} the shortest, {} recoveries",
        match d.failure {
            None if d.success => "delivered".to_owned(),
            Some(fail) => format!("{fail:?}"),
            None => "not delivered".to_owned(),
        },
        d.time,
        d.recoveries.len()
    );
    doc.title(&line);
    doc.caption(&line, 14.0, &Style::new().fill("black"));
    doc.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::deliver::{Failure, Recovery};
    use crate::strategy::sample::Pose2;

    /// The drawing has the outline at most OUTLINES + 1 times, one recovery mark per stall,
    /// the tracks, and says how the trial went; the JSON holds every step.
    #[test]
    fn a_trace_draws_the_outline_along_the_track_and_marks_the_stalls() {
        let scene = Scene::preset_or_file("lau-zigzag-l").unwrap();
        let mut d = Delivery::failed(Some(Failure::Stalled), 321.0, 0.3);
        d.trajectory = (0..100)
            .map(|k| {
                let x = 0.3 + 0.01 * k as f64;
                (
                    Pose2::new(x - 0.1, 0.5, 0.0),
                    Pose2::new(x, 0.5, 0.01 * k as f64),
                )
            })
            .collect();
        d.paths = vec![vec![[0.3, 0.5], [0.8, 0.5], [1.0, 0.5]]; 3];
        d.recoveries = vec![
            Recovery {
                t: 100.0,
                at: [0.5, 0.5],
                subgoal: [0.6, 0.5],
                action: "back off and re-plan".into(),
            };
            2
        ];
        let outline = [[-0.05, -0.02], [0.05, -0.02], [0.05, 0.02], [-0.05, 0.02]];
        let svg = trial_svg(&scene, Vector2::new(1.0, 0.5), &outline, &d, "t");
        let drawn = svg.matches(r##"stroke="#a33""##).count();
        assert!((20..=OUTLINES + 1).contains(&drawn), "{drawn} outlines");
        assert_eq!(svg.matches(r#"fill="orange""#).count(), 2);
        assert_eq!(svg.matches("path planned for leg").count(), 3);
        assert!(svg.contains("Stalled, 321.0 s"), "{svg}");
        let dir = tempfile::tempdir().unwrap();
        let t = TraceDir::create(&dir.path().join("a/b")).unwrap();
        t.write(
            &scene,
            Vector2::new(1.0, 0.5),
            &outline,
            "D",
            Method::Learned,
            7,
            &d,
        )
        .unwrap();
        let base = dir
            .path()
            .join("a/b")
            .join(format!("{}-D-learned-007", scene.name));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(base.with_extension("json")).unwrap())
                .unwrap();
        assert_eq!(v["trajectory"].as_array().unwrap().len(), 100);
        assert_eq!(v["delivery"]["recoveries"].as_array().unwrap().len(), 2);
        assert_eq!(v["delivery"]["paths"].as_array().unwrap().len(), 3);
        assert!(base.with_extension("svg").exists());
    }
}

//! The report of a replay (`pushbot replay FILE.mcap --out DIR`): the live run's report as it
//! was recorded (every stage's numbers, notes and figures, the same files), then a section per
//! recorded session with the run drawn from the recorded trace and the paths the replayed
//! tracking gives, and how far the replayed poses are from the recorded ones.

use std::path::{Path, PathBuf};

use anyhow::Result;

use super::replay::{Replay, SessionReplay};
use crate::exec::record::TracePoint;
use crate::report::{Report, StageReport, figure};
use crate::strategy::sample::Pose2;

/// The replayed tracking as trace points: one per robot pose, each object at its latest
/// replayed pose by then.
fn tracked_trace(s: &SessionReplay) -> Vec<TracePoint> {
    let Some(robot) = s.tracks.get("robot") else {
        return Vec::new();
    };
    robot
        .iter()
        .map(|r| TracePoint {
            t: r.t,
            after: "start",
            robot: Pose2::new(r.x, r.y, r.theta),
            objects: s
                .tracks
                .iter()
                .filter(|(id, _)| *id != "robot" && !id.starts_with("goal:"))
                .filter_map(|(id, ps)| {
                    let p = ps.iter().rev().find(|p| p.t <= r.t).or(ps.first())?;
                    Some((id.clone(), Pose2::new(p.x, p.y, p.theta)))
                })
                .collect(),
            truth: None,
        })
        .collect()
}

/// Write the report of `replay` into `dir`; returns `report.html`'s path.
pub fn write(replay: &Replay, dir: &Path, recording: &Path) -> Result<PathBuf> {
    let mut report = Report::create(dir, "pushbot replay", false)?;
    // The live run's own report, as recorded: the same stages, numbers, notes and figures.
    for (stage, svgs) in &replay.stages {
        let mut st = stage.clone();
        for (file, _) in &mut st.figures {
            let stem = file
                .rsplit_once('.')
                .map_or(file.as_str(), |(s, _)| s)
                .to_string();
            if let Some(svg) = svgs.get(&stem) {
                *file = report.figure(&stem, svg)?;
            }
        }
        report.add(st);
    }
    for s in &replay.sessions {
        let mut st = StageReport::new(
            &format!("session-{}", s.session),
            &format!("Session {}: {}", s.session, s.label),
            &format!("replayed from {}", recording.display()),
        );
        st.success = s.max_diff_m <= 1e-4;
        st.number("frames", s.frames);
        st.number("max_pose_difference_mm", s.max_diff_m * 1e3);
        st.number("max_heading_difference_deg", s.max_diff_rad.to_degrees());
        if let Some(scene) = &s.scene {
            if !s.trace.is_empty() {
                let f = report.figure(
                    &format!("session-{}-run", s.session),
                    &figure::run_svg(scene, &s.trace, &format!("{} as recorded", s.label), true),
                )?;
                st.figures.push((
                    f,
                    "The run as recorded after every primitive (the live report's figure): robot blue, objects red".into(),
                ));
            }
            let tracked = tracked_trace(s);
            if !tracked.is_empty() {
                let f = report.figure(
                    &format!("session-{}-tracked", s.session),
                    &figure::run_svg(
                        scene,
                        &tracked,
                        &format!("{} tracked again", s.label),
                        false,
                    ),
                )?;
                st.figures.push((
                    f,
                    "The paths the replayed tracking gives, frame by frame: robot blue, objects red".into(),
                ));
            }
        }
        if let Some(cut) = &replay.cut {
            st.notes.push(format!("the recording ends early: {cut}"));
        }
        report.add(st);
    }
    report.write()
}

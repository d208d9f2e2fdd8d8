//! The folder every run leaves: `run.mcap` (the recording: camera frames with what tracking
//! made of them, telemetry, events — Foxglove opens it as it is), `report.html` (the task's
//! numbers with units and its figure), `run.log` (every event, one JSON object a line) and
//! `summary.json` (for scripts).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use super::{Outcome, TaskEvent};
use crate::recording::{Recording, RecordingHandle};
use crate::report::{Report, figure};

/// A run's folder, being written.
#[derive(Debug)]
pub struct RunFolder {
    dir: PathBuf,
    log: std::sync::Mutex<std::fs::File>,
    recording: RecordingHandle,
}

impl RunFolder {
    /// Create `dir` (files in it are replaced) with its log and recording.
    pub fn create(dir: &Path) -> Result<RunFolder> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let log = std::fs::File::create(dir.join("run.log"))
            .with_context(|| format!("creating {}", dir.join("run.log").display()))?;
        let recording = RecordingHandle::new(Recording::create(&dir.join("run.mcap"))?);
        Ok(RunFolder {
            dir: dir.to_path_buf(),
            log: std::sync::Mutex::new(log),
            recording,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The recording, for the session's robot to record into.
    pub fn recording(&self) -> RecordingHandle {
        self.recording.clone()
    }

    /// Log an event (the log and the recording's log channel).
    pub fn event(&self, e: &TaskEvent) {
        let line = serde_json::to_string(e).unwrap_or_default();
        if let Ok(mut f) = self.log.lock() {
            let _ = writeln!(f, "{line}");
        }
        if !matches!(e, TaskEvent::Look { .. } | TaskEvent::Primitive { .. }) {
            self.recording.with(|r| r.log(2, "task", &line));
        }
    }

    /// Finish: the report with the run's figure, `summary.json`, the recording closed. Returns
    /// the summary written.
    pub fn finish(
        self,
        scene: &pushbot_world::Scene,
        task: &str,
        outcome: &Outcome,
    ) -> Result<serde_json::Value> {
        let report = Report::create(&self.dir, &format!("pushbot run {task}"), false)?;
        let mut stage = outcome.report.clone();
        if !outcome.trace.is_empty() {
            let truth = outcome.trace.iter().any(|p| p.truth.is_some());
            let f = report.figure(
                "run",
                &figure::run_svg(
                    scene,
                    &outcome.trace,
                    &format!("{task}: the run{}", if truth { " (truth)" } else { "" }),
                    truth,
                ),
            )?;
            stage.figures.push((
                f,
                format!(
                    "The run seen from above{}: robot blue, objects red, start dashed, goals green",
                    if truth {
                        ", as the simulator knows it"
                    } else {
                        ", as the camera saw it"
                    }
                ),
            ));
        }
        let mut report = report;
        report.add(stage);
        report.write()?;
        self.recording.finish()?;
        let summary = serde_json::json!({
            "task": task,
            "success": outcome.success,
            "stopped": outcome.stopped.map(|s| s.to_string()),
            "message": outcome.message,
            "mission_s": outcome.report.mission_s,
            "wall_s": outcome.report.wall_s,
            "folder": self.dir,
            "recording": self.dir.join("run.mcap"),
            "report": self.dir.join("report.html"),
            "result": outcome.summary,
        });
        std::fs::write(
            self.dir.join("summary.json"),
            serde_json::to_string_pretty(&summary)?,
        )
        .context("writing summary.json")?;
        Ok(summary)
    }
}

/// The default run folder: `runs/TASK-YYYYMMDD-HHMMSS` (UTC).
pub fn default_folder(task: &str) -> PathBuf {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rest) = ((secs / 86_400) as i64, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    PathBuf::from("runs").join(format!(
        "{task}-{y:04}{m:02}{d:02}-{:02}{:02}{:02}",
        rest / 3600,
        rest / 60 % 60,
        rest % 60
    ))
}

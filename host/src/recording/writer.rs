//! Writes a run as MCAP (`--record FILE.mcap`): every channel in a Foxglove well-known schema or
//! one of pushbot's own, JSON messages with JSON schemas, time stamps in robot time.
//!
//! A recording survives the process being killed: every camera look ends the current chunk and
//! flushes the file ([`Recording::frame`]), so what was written up to the last look stays
//! readable ([`super::reader`] reads a cut file up to its last whole chunk); [`Recording::finish`]
//! adds the summary and index a finished file has.
//!
//! Robot time: each connection to a robot (a *session*: the demo runs one per stage, each on a
//! fresh simulated target whose clock starts at zero) continues the recording's clock one
//! millisecond after the previous session's last message, so time never runs backwards in a
//! file; within a session, time stamps are the robot's clock (its telemetry's `time_us`).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result, anyhow};
use pushbot_world::Scene;
use serde_json::{Value, json};

use super::{foxglove, schema};
use crate::link::RobotEvent;
use crate::vision::FrameResult;
use crate::vision::calibration::Calibration;
use crate::vision::frame::Frame;

/// The channels of a recording: topic, schema name, schema.
pub fn channels() -> Vec<(&'static str, Value)> {
    vec![
        (topics::IMAGE, schema::compressed_image()),
        (topics::CALIBRATION, schema::camera_calibration()),
        (topics::ANNOTATIONS, schema::image_annotations()),
        (topics::TF, schema::frame_transforms()),
        (topics::SCENE, schema::scene_update()),
        (topics::PLANNED, schema::scene_update()),
        (topics::EXECUTED, schema::scene_update()),
        (topics::LOG, schema::log()),
        (topics::TELEMETRY, schema::telemetry()),
        (topics::EVENTS, schema::link_event()),
        (topics::TRACKED, schema::tracked()),
        (topics::SESSION, schema::session()),
        (topics::TRACE, schema::trace_point()),
        (topics::STAGE, schema::stage_report()),
    ]
}

/// The topics.
pub mod topics {
    /// `foxglove.CompressedImage`: the overhead camera, PNG.
    pub const IMAGE: &str = "/camera/image";
    /// `foxglove.CameraCalibration`.
    pub const CALIBRATION: &str = "/camera/calibration";
    /// `foxglove.ImageAnnotations`: detections and tracked bodies on the image.
    pub const ANNOTATIONS: &str = "/camera/annotations";
    /// `foxglove.FrameTransforms`: `table` → each tracked body.
    pub const TF: &str = "/tf";
    /// `foxglove.SceneUpdate`: table, obstacles, objects, goals, robot.
    pub const SCENE: &str = "/scene";
    /// `foxglove.SceneUpdate`: the planned path.
    pub const PLANNED: &str = "/paths/planned";
    /// `foxglove.SceneUpdate`: the executed paths (robot and objects, as tracked).
    pub const EXECUTED: &str = "/paths/executed";
    /// `foxglove.Log`.
    pub const LOG: &str = "/log";
    /// `pushbot.Telemetry`.
    pub const TELEMETRY: &str = "/robot/telemetry";
    /// `pushbot.LinkEvent`.
    pub const EVENTS: &str = "/robot/events";
    /// `pushbot.TrackedPoses`.
    pub const TRACKED: &str = "/pushbot/tracked";
    /// `pushbot.Session`.
    pub const SESSION: &str = "/pushbot/session";
    /// `pushbot.TracePoint`.
    pub const TRACE: &str = "/pushbot/trace";
    /// `pushbot.StageReport`.
    pub const STAGE: &str = "/pushbot/stage";
}

/// What a replay needs of a session, besides its frames.
#[derive(Debug, Clone)]
pub struct SessionInfo<'a> {
    /// What the session is (a demo stage's name, a command's).
    pub label: &'a str,
    /// The scene on the table, when there is one.
    pub scene: Option<&'a Scene>,
    /// The marker layout the tracker uses.
    pub layout: &'a crate::vision::layout::MarkerLayout,
    /// The camera's calibration.
    pub calibration: &'a Calibration,
    /// The tracker's settings.
    pub tracker: crate::vision::tracking::TrackerParams,
    /// The detector.
    pub detector: crate::vision::detect::DetectorKind,
    /// Whether every frame was searched whole (no regions of interest).
    pub whole_frames: bool,
}

/// An MCAP file being written.
pub struct Recording {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    ids: BTreeMap<&'static str, u16>,
    seq: u32,
    session: u32,
    /// Added to the robot's clock (ns) to make the recording's clock.
    offset_ns: i128,
    last_ns: u64,
    frames: u64,
    executed: BTreeMap<String, Vec<[f64; 2]>>,
    live: Option<super::ws::FoxgloveServer>,
}

impl std::fmt::Debug for Recording {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recording")
            .field("path", &self.path)
            .field("frames", &self.frames)
            .finish()
    }
}

impl Recording {
    /// Create `path` (replaced if it exists) with every channel.
    pub fn create(path: &Path) -> Result<Recording> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("creating the folder of {}", path.display()))?;
        }
        let file = File::create(path)
            .with_context(|| format!("creating the recording {}", path.display()))?;
        let mut writer = mcap::WriteOptions::new()
            .compression(None)
            .profile("")
            .library(concat!("pushbot ", env!("CARGO_PKG_VERSION")))
            .chunk_size(Some(1 << 20))
            .create(BufWriter::new(file))
            .map_err(|e| anyhow!("starting {}: {e}", path.display()))?;
        let mut ids = BTreeMap::new();
        for (topic, s) in channels() {
            let name = s["title"].as_str().unwrap_or_default().to_string();
            let data = serde_json::to_vec(&s)?;
            let schema_id = writer
                .add_schema(&name, schema::ENCODING, &data)
                .map_err(|e| anyhow!("writing schema {name}: {e}"))?;
            let id = writer
                .add_channel(schema_id, topic, "json", &BTreeMap::new())
                .map_err(|e| anyhow!("writing channel {topic}: {e}"))?;
            ids.insert(topic, id);
        }
        writer
            .flush()
            .map_err(|e| anyhow!("writing {}: {e}", path.display()))?;
        Ok(Recording {
            writer,
            path: path.to_path_buf(),
            ids,
            seq: 0,
            session: 0,
            offset_ns: 0,
            last_ns: 0,
            frames: 0,
            executed: BTreeMap::new(),
            live: None,
        })
    }

    /// Also serve every channel live to Foxglove on `addr` (`HOST:PORT`, port 0 picks one):
    /// every message written from now on is sent to the clients subscribed to its channel.
    /// Returns the address served.
    pub fn serve_foxglove(&mut self, addr: &str) -> Result<std::net::SocketAddr> {
        let chans = channels()
            .into_iter()
            .filter_map(|(topic, schema)| {
                Some(super::ws::Advertised {
                    id: *self.ids.get(topic)?,
                    topic: topic.to_string(),
                    schema_name: schema["title"].as_str().unwrap_or_default().to_string(),
                    schema,
                })
            })
            .collect();
        let server = super::ws::FoxgloveServer::start(addr, chans)?;
        let at = server.addr();
        self.live = Some(server);
        Ok(at)
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Camera frames written.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// The recording's time (ns) of a robot time (µs) in this session.
    fn at(&self, robot_us: u64) -> u64 {
        let t = self.offset_ns + i128::from(robot_us) * 1000;
        u64::try_from(t.max(0)).unwrap_or(u64::MAX)
    }

    fn put(&mut self, topic: &'static str, ns: u64, msg: &Value) -> Result<()> {
        let id = *self
            .ids
            .get(topic)
            .ok_or_else(|| anyhow!("no channel {topic}"))?;
        let data = serde_json::to_vec(msg)?;
        if let Some(live) = &self.live {
            live.publish(id, ns, &data);
        }
        self.seq = self.seq.wrapping_add(1);
        self.last_ns = self.last_ns.max(ns);
        self.writer
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: self.seq,
                    log_time: ns,
                    publish_time: ns,
                },
                &data,
            )
            .map_err(|e| anyhow!("writing {}: {e}", self.path.display()))
    }

    /// End the current chunk and flush the file: what was written so far survives a kill.
    pub fn flush(&mut self) -> Result<()> {
        self.writer
            .flush()
            .map_err(|e| anyhow!("writing {}: {e}", self.path.display()))
    }

    /// A new connection to a robot and a camera at the robot time `robot_us`: the scene, the
    /// calibration and the tracker's settings.
    pub fn begin_session(&mut self, info: &SessionInfo<'_>, robot_us: u64) -> Result<()> {
        self.session += 1;
        let start = if self.session == 1 {
            0
        } else {
            self.last_ns + 1_000_000
        };
        self.offset_ns = i128::from(start) - i128::from(robot_us) * 1000;
        self.executed.clear();
        let ns = self.at(robot_us);
        let msg = json!({
            "session": self.session,
            "label": info.label,
            "scene": info.scene,
            "layout": info.layout,
            "calibration": info.calibration,
            "tracker": info.tracker,
            "detector": info.detector,
            "whole_frames": info.whole_frames,
        });
        self.put(topics::SESSION, ns, &msg)?;
        if let Some(scene) = info.scene {
            self.put(topics::SCENE, ns, &foxglove::scene_update(ns, scene))?;
        }
        self.put(
            topics::CALIBRATION,
            ns,
            &foxglove::camera_calibration(ns, info.calibration),
        )?;
        self.log_at(
            ns,
            2,
            "session",
            &format!("session {}: {}", self.session, info.label),
        )?;
        self.flush()
    }

    /// One camera frame at robot time `robot_us`, what the pipeline made of it, and the
    /// calibration it used; ends the chunk (see the module's docs).
    pub fn frame(
        &mut self,
        robot_us: u64,
        frame: &Frame,
        result: &FrameResult,
        cal: &Calibration,
        odometry: Option<[f64; 3]>,
    ) -> Result<()> {
        let ns = self.at(robot_us);
        let png = png_of(frame)?;
        self.put(topics::IMAGE, ns, &foxglove::compressed_image(ns, &png))?;
        self.put(
            topics::ANNOTATIONS,
            ns,
            &foxglove::image_annotations(ns, result, cal),
        )?;
        self.put(topics::TF, ns, &foxglove::frame_transforms(ns, result))?;
        let bodies: Vec<Value> = result
            .tracked
            .iter()
            .map(|t| {
                json!({"body": t.body, "x": t.pose.x, "y": t.pose.y, "theta": t.pose.theta,
                       "seen": t.seen, "rejected": t.rejected, "age": t.age})
            })
            .collect();
        let tracked = json!({
            "session": self.session,
            "seq": frame.seq,
            "frame_time": frame.time,
            "full_frame": result.full_frame,
            "detections": result.detections.len(),
            "bodies": bodies,
            // The robot's odometry the tracker was given with this frame, so that a replay
            // gives it too.
            "odometry": odometry.map(|[x, y, theta]| json!({"x": x, "y": y, "theta": theta})),
        });
        self.put(topics::TRACKED, ns, &tracked)?;
        for t in result.tracked.iter().filter(|t| t.seen && !t.rejected) {
            self.executed
                .entry(t.body.clone())
                .or_default()
                .push([t.pose.x, t.pose.y]);
        }
        let mut ents = Vec::new();
        for (body, pts) in &self.executed {
            let c = if body == "robot" {
                foxglove::color(0.1, 0.4, 1.0, 1.0)
            } else {
                foxglove::color(1.0, 0.23, 0.19, 1.0)
            };
            let u = foxglove::path_update(ns, &format!("executed-{body}"), pts, c);
            ents.extend(u["entities"].as_array().cloned().unwrap_or_default());
        }
        self.put(
            topics::EXECUTED,
            ns,
            &json!({"deletions": [], "entities": ents}),
        )?;
        self.frames += 1;
        self.flush()
    }

    /// A report from the robot: telemetry, a contact or a motion's end.
    pub fn robot_event(&mut self, event: &RobotEvent) -> Result<()> {
        match event {
            RobotEvent::Telemetry(t) => {
                let ns = self.at(t.time_us);
                self.put(topics::TELEMETRY, ns, &serde_json::to_value(t)?)
            }
            RobotEvent::Contact(c) => {
                let ns = self.at(c.time_us);
                let mut v = serde_json::to_value(c)?;
                v["kind"] = json!("contact");
                self.put(topics::EVENTS, ns, &v)
            }
            RobotEvent::Done(d) => {
                let ns = self.at(d.time_us);
                let mut v = serde_json::to_value(d)?;
                v["kind"] = json!("done");
                self.put(topics::EVENTS, ns, &v)
            }
        }
    }

    /// The planned path (table metres), at the latest time written.
    pub fn planned_path(&mut self, pts: &[[f64; 2]]) -> Result<()> {
        let ns = self.last_ns;
        let msg = foxglove::path_update(ns, "plan", pts, foxglove::color(1.0, 0.6, 0.0, 1.0));
        self.put(topics::PLANNED, ns, &msg)
    }

    /// A trace point (after a primitive), at the latest time written.
    pub fn trace(&mut self, point: &crate::exec::record::TracePoint) -> Result<()> {
        let ns = self.last_ns;
        self.put(topics::TRACE, ns, &serde_json::to_value(point)?)
    }

    /// A stage's finished report with its figures (file stem → SVG text), at the latest time
    /// written; flushed at once.
    pub fn stage_report(
        &mut self,
        report: &crate::report::StageReport,
        figures: &BTreeMap<String, String>,
    ) -> Result<()> {
        let ns = self.last_ns;
        self.put(
            topics::STAGE,
            ns,
            &json!({"report": report, "figures": figures}),
        )?;
        self.flush()
    }

    /// A log line (`level`: 1 debug, 2 info, 3 warning, 4 error) at the latest time written.
    pub fn log(&mut self, level: u8, name: &str, message: &str) -> Result<()> {
        self.log_at(self.last_ns, level, name, message)
    }

    fn log_at(&mut self, ns: u64, level: u8, name: &str, message: &str) -> Result<()> {
        self.put(topics::LOG, ns, &foxglove::log(ns, level, name, message))
    }

    /// Write the summary and close the file.
    pub fn finish(mut self) -> Result<()> {
        self.writer
            .finish()
            .map_err(|e| anyhow!("finishing {}: {e}", self.path.display()))?;
        Ok(())
    }
}

fn png_of(frame: &Frame) -> Result<Vec<u8>> {
    let img = image::GrayImage::from_raw(frame.width, frame.height, frame.pixels.clone())
        .context("frame size does not match its pixels")?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .context("encoding the camera image")?;
    Ok(png)
}

/// A recording shared by the parts of a run that write to it (the robot's looks, the trace,
/// the log). A write that fails is logged once and the recording stops: a full disk ends the
/// recording, not the run.
#[derive(Clone)]
pub struct RecordingHandle(Arc<Mutex<Option<Recording>>>);

impl std::fmt::Debug for RecordingHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("RecordingHandle")
    }
}

impl PartialEq for RecordingHandle {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl RecordingHandle {
    /// Share `rec`.
    pub fn new(rec: Recording) -> RecordingHandle {
        RecordingHandle(Arc::new(Mutex::new(Some(rec))))
    }

    /// Write with `f`; on an error, log it and stop recording.
    pub fn with(&self, f: impl FnOnce(&mut Recording) -> Result<()>) {
        let mut guard = match self.0.lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        if let Some(rec) = guard.as_mut()
            && let Err(e) = f(rec)
        {
            tracing::warn!("recording stopped: {e:#}");
            *guard = None;
        }
    }

    /// Finish the file (summary and index); `Ok(None)` when it had stopped on an error.
    pub fn finish(&self) -> Result<Option<PathBuf>> {
        let rec = match self.0.lock() {
            Ok(mut g) => g.take(),
            Err(p) => p.into_inner().take(),
        };
        match rec {
            Some(r) => {
                let path = r.path().to_path_buf();
                r.finish()?;
                Ok(Some(path))
            }
            None => Ok(None),
        }
    }
}

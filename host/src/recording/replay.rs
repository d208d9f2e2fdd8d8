//! `pushbot replay FILE.mcap`: tracking re-run from a recording. Each session's pipeline is
//! rebuilt from what the recording says of it (marker layout, calibration, tracker settings,
//! detector), and every recorded camera image goes through it again in order; the poses it
//! gives are compared with the poses the live run recorded for the same frames.
//!
//! Sans-IO: [`replay`] takes the decoded [`Contents`]; reading the file is the caller's.

use std::collections::BTreeMap;

use anyhow::{Context, Result, anyhow, bail};
use serde::Serialize;
use serde_json::Value;

use super::foxglove;
use super::reader::Contents;
use super::writer::topics;
use crate::exec::record::TracePoint;
use crate::strategy::sample::Pose2;
use crate::vision::Pipeline;
use crate::vision::calibration::Calibration;
use crate::vision::detect::{DetectorKind, make_detector};
use crate::vision::frame::Frame;
use crate::vision::layout::MarkerLayout;
use crate::vision::tracking::TrackerParams;

/// One body's pose in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BodyPose {
    /// Frame time, s.
    pub t: f64,
    /// Table metres and radians.
    pub x: f64,
    /// Table metres.
    pub y: f64,
    /// Heading, radians.
    pub theta: f64,
}

/// A session replayed.
#[derive(Debug, Clone, Serialize)]
pub struct SessionReplay {
    /// Its number in the recording (from 1).
    pub session: u64,
    /// What it was (a demo stage's name).
    pub label: String,
    /// Frames re-tracked.
    pub frames: usize,
    /// Largest distance between a replayed and a recorded pose of the same body in the same
    /// frame, m.
    pub max_diff_m: f64,
    /// Largest heading difference, rad.
    pub max_diff_rad: f64,
    /// Each body's replayed poses (bodies seen and accepted in a frame).
    #[serde(skip)]
    pub tracks: BTreeMap<String, Vec<BodyPose>>,
    /// Each body's last replayed pose.
    pub last: BTreeMap<String, BodyPose>,
    /// The scene, for figures.
    #[serde(skip)]
    pub scene: Option<pushbot_world::Scene>,
    /// The trace points the live run recorded (after every primitive), for figures.
    #[serde(skip)]
    pub trace: Vec<TracePoint>,
}

/// The whole replay.
#[derive(Debug, Clone, Serialize)]
pub struct Replay {
    /// The sessions, in order.
    pub sessions: Vec<SessionReplay>,
    /// Frames re-tracked in all.
    pub frames: usize,
    /// Largest position difference over every session, m.
    pub max_diff_m: f64,
    /// Largest heading difference over every session, rad.
    pub max_diff_rad: f64,
    /// Why the file ended early, if it did.
    pub cut: Option<String>,
    /// The live run's stage reports with their figures (file stem → SVG), as recorded.
    #[serde(skip)]
    pub stages: Vec<(
        crate::report::StageReport,
        std::collections::BTreeMap<String, String>,
    )>,
}

struct Live {
    info: SessionReplay,
    pipeline: Pipeline,
    image: Option<Vec<u8>>,
}

fn field<T: serde::de::DeserializeOwned>(v: &Value, key: &str) -> Result<T> {
    serde_json::from_value(v.get(key).cloned().unwrap_or(Value::Null))
        .with_context(|| format!("the session's {key:?}"))
}

fn start(v: &Value) -> Result<Live> {
    let layout: MarkerLayout = field(v, "layout")?;
    let calibration: Calibration = field(v, "calibration")?;
    let tracker: TrackerParams = field(v, "tracker")?;
    let detector: DetectorKind = field(v, "detector")?;
    let scene: Option<pushbot_world::Scene> = field(v, "scene").ok();
    let det = make_detector(detector, &layout.families())?;
    Ok(Live {
        info: SessionReplay {
            session: v.get("session").and_then(Value::as_u64).unwrap_or(0),
            label: v
                .get("label")
                .and_then(Value::as_str)
                .unwrap_or_default()
                .to_string(),
            frames: 0,
            max_diff_m: 0.0,
            max_diff_rad: 0.0,
            tracks: BTreeMap::new(),
            last: BTreeMap::new(),
            scene,
            trace: Vec::new(),
        },
        pipeline: {
            // A calibration made through a lens carries it: the pipeline measures through it.
            let p = Pipeline::new(det, layout, calibration, tracker);
            if v.get("whole_frames").and_then(Value::as_bool) == Some(true) {
                p.with_roi(crate::vision::RoiParams::full_frames())
            } else {
                p
            }
        },
        image: None,
    })
}

fn frame_of(png: &[u8], seq: u64, time: f64) -> Result<Frame> {
    let img = image::load_from_memory_with_format(png, image::ImageFormat::Png)
        .context("decoding a recorded camera image")?
        .into_luma8();
    Ok(Frame {
        seq,
        time,
        width: img.width(),
        height: img.height(),
        pixels: img.into_raw(),
    })
}

/// Track a recording's frames again and compare with what the live run tracked.
pub fn replay(contents: &Contents) -> Result<Replay> {
    let mut done = Vec::new();
    let mut live: Option<Live> = None;
    let mut stages = Vec::new();
    for m in &contents.messages {
        match m.topic.as_str() {
            topics::SESSION => {
                if let Some(l) = live.take() {
                    done.push(l.info);
                }
                live = Some(start(&m.value)?);
            }
            topics::IMAGE => {
                let l = live
                    .as_mut()
                    .ok_or_else(|| anyhow!("a camera image before any session"))?;
                l.image = Some(
                    foxglove::image_data(&m.value)
                        .ok_or_else(|| anyhow!("a camera image without data"))?,
                );
            }
            topics::TRACKED => {
                let l = live
                    .as_mut()
                    .ok_or_else(|| anyhow!("tracked poses before any session"))?;
                let png = l
                    .image
                    .take()
                    .ok_or_else(|| anyhow!("tracked poses without their camera image"))?;
                let seq = m.value.get("seq").and_then(Value::as_u64).unwrap_or(0);
                let time = m
                    .value
                    .get("frame_time")
                    .and_then(Value::as_f64)
                    .ok_or_else(|| anyhow!("tracked poses without a frame time"))?;
                let frame = frame_of(&png, seq, time)?;
                // The robot's odometry, as the live tracker was given it with this frame.
                if let Some(o) = m.value.get("odometry").filter(|o| o.is_object()) {
                    let num = |k: &str| o.get(k).and_then(Value::as_f64);
                    if let (Some(x), Some(y), Some(theta)) = (num("x"), num("y"), num("theta")) {
                        l.pipeline.odometry(
                            "robot",
                            time,
                            crate::vision::layout::Pose::new(x, y, theta),
                        );
                    }
                }
                let r = l.pipeline.process(&frame)?;
                l.info.frames += 1;
                compare(&mut l.info, &r, &m.value)?;
            }
            topics::STAGE => {
                let report = serde_json::from_value(m.value["report"].clone())
                    .context("a recorded stage report")?;
                let figures = serde_json::from_value(m.value["figures"].clone())
                    .context("a recorded stage report's figures")?;
                stages.push((report, figures));
            }
            topics::TRACE => {
                if let Some(l) = live.as_mut()
                    && let Ok(p) = trace_point(&m.value)
                {
                    l.info.trace.push(p);
                }
            }
            _ => {}
        }
    }
    if let Some(l) = live.take() {
        done.push(l.info);
    }
    if done.is_empty() {
        bail!("the recording has no session (no robot and camera were connected)");
    }
    Ok(Replay {
        frames: done.iter().map(|s| s.frames).sum(),
        max_diff_m: done.iter().map(|s| s.max_diff_m).fold(0.0, f64::max),
        max_diff_rad: done.iter().map(|s| s.max_diff_rad).fold(0.0, f64::max),
        sessions: done,
        cut: contents.cut.clone(),
        stages,
    })
}

fn compare(s: &mut SessionReplay, r: &crate::vision::FrameResult, recorded: &Value) -> Result<()> {
    let rec = recorded
        .get("bodies")
        .and_then(Value::as_array)
        .ok_or_else(|| anyhow!("tracked poses without bodies"))?;
    if rec.len() != r.tracked.len() {
        // A body the live run tracked and the replay did not (or the reverse): as far apart
        // as can be.
        s.max_diff_m = f64::INFINITY;
    }
    for t in &r.tracked {
        let Some(b) = rec.iter().find(|b| b["body"] == t.body.as_str()) else {
            s.max_diff_m = f64::INFINITY;
            continue;
        };
        let num = |k: &str| b.get(k).and_then(Value::as_f64).unwrap_or(f64::NAN);
        let d = (num("x") - t.pose.x).hypot(num("y") - t.pose.y);
        let a = crate::strategy::sample::wrap_angle(num("theta") - t.pose.theta).abs();
        s.max_diff_m = s.max_diff_m.max(if d.is_nan() { f64::INFINITY } else { d });
        s.max_diff_rad = s
            .max_diff_rad
            .max(if a.is_nan() { f64::INFINITY } else { a });
        if t.seen && !t.rejected {
            let p = BodyPose {
                t: t.time,
                x: t.pose.x,
                y: t.pose.y,
                theta: t.pose.theta,
            };
            s.tracks.entry(t.body.clone()).or_default().push(p);
            s.last.insert(t.body.clone(), p);
        }
    }
    Ok(())
}

fn pose2(v: &Value) -> Option<Pose2> {
    let n = |k: &str| v.get(k).and_then(Value::as_f64);
    Some(Pose2::new(n("x")?, n("y")?, n("theta")?))
}

fn poses(v: &Value) -> Vec<(String, Pose2)> {
    v.as_array()
        .map(|a| {
            a.iter()
                .filter_map(|e| Some((e.get(0)?.as_str()?.to_string(), pose2(e.get(1)?)?)))
                .collect()
        })
        .unwrap_or_default()
}

/// A recorded trace point back (its `after` as one of the names the recorder uses).
fn trace_point(v: &Value) -> Result<TracePoint> {
    let after = match v.get("after").and_then(Value::as_str) {
        Some("spin") => "spin",
        Some("forward") => "forward",
        Some("drive") => "drive",
        _ => "start",
    };
    let truth = v.get("truth").and_then(|t| {
        let r = pose2(t.get(0)?)?;
        Some((r, poses(t.get(1)?)))
    });
    Ok(TracePoint {
        t: v.get("t").and_then(Value::as_f64).unwrap_or(0.0),
        after,
        robot: pose2(&v["robot"]).ok_or_else(|| anyhow!("a trace point without a robot"))?,
        objects: poses(&v["objects"]),
        truth,
    })
}

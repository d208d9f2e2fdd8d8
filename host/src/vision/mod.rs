//! Vision: the overhead camera's frames → marker detections → table-plane poses → filtered poses
//! of the robot, objects and goals (Lau et al. §IV: a ceiling camera tracks markers on the
//! robot, the object and the goal at 960×720, 30 fps).
//!
//! - [`source`]: frame sources behind [`source::FrameSource`] (V4L2, image folder, sim socket);
//! - [`detect`]: detectors behind [`detect::Detector`]: the reference C AprilTag ([`apriltag`],
//!   the default) and, with the `kornia` feature, the pure-Rust `kornia-apriltag` (`kornia`);
//! - [`homography`] and [`calibration`]: pixel → table-plane homography from markers at known
//!   places;
//! - [`layout`]: which marker is where (until the shared scene format carries it);
//! - [`tracking`]: a Kalman filter per body;
//! - [`synth`] and [`bench`]: rendered test frames with ground truth, and `pushbot bench vision`.

pub mod apriltag;
pub mod bench;
pub mod calibration;
pub mod detect;
pub mod folder;
pub mod homography;
#[cfg(feature = "kornia")]
pub mod kornia;
pub mod layout;
pub mod simsocket;
pub mod source;
pub mod synth;
pub mod tracking;
pub mod v4l2;

use serde::Serialize;

use calibration::Calibration;
use detect::{DetectError, Detection, Detector};
use layout::{MarkerLayout, Pose};
use source::Frame;
use tracking::{TrackedPose, Tracker, TrackerParams};

/// One body's pose measured from one detection (before filtering).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measurement {
    /// The body's name.
    pub body: String,
    /// The marker's id.
    pub marker: u32,
    /// The marker's pose on the table.
    pub marker_pose: Pose,
    /// The body's pose (marker pose composed with the inverse of its offset on the body).
    pub body_pose: Pose,
}

/// Markers whose fitted side differs from the layout's by more than this fraction are dropped
/// (a misdetection, or a marker of the wrong size).
pub const SIDE_TOLERANCE: f64 = 0.15;

/// Body poses from one frame's detections: markers not on a body, of the wrong size, or whose
/// body was already measured by a more confident detection are skipped.
pub fn measure(dets: &[Detection], cal: &Calibration, layout: &MarkerLayout) -> Vec<Measurement> {
    let mut best: Vec<(f32, Measurement)> = Vec::new();
    for d in dets {
        let Some(bm) = layout.body_marker(d.family, d.id) else {
            continue;
        };
        let Some((marker_pose, side)) = cal.marker_pose(d) else {
            continue;
        };
        if (side / bm.side - 1.0).abs() > SIDE_TOLERANCE {
            continue;
        }
        let m = Measurement {
            body: bm.body.clone(),
            marker: d.id,
            marker_pose,
            body_pose: bm.body_pose(&marker_pose),
        };
        match best.iter().position(|(_, b)| b.body == m.body) {
            Some(i) if best[i].0 < d.margin => best[i] = (d.margin, m),
            Some(_) => {}
            None => best.push((d.margin, m)),
        }
    }
    best.into_iter().map(|(_, m)| m).collect()
}

/// What the pipeline made of one frame.
#[derive(Debug, Clone)]
pub struct FrameResult {
    /// Frame number.
    pub seq: u64,
    /// Frame time, seconds.
    pub time: f64,
    /// Raw detections.
    pub detections: Vec<Detection>,
    /// Per-frame body poses.
    pub measurements: Vec<Measurement>,
    /// Filtered poses of every body tracked so far.
    pub tracked: Vec<TrackedPose>,
}

/// The whole tracking pipeline: detect, measure, filter.
pub struct Pipeline {
    detector: Box<dyn Detector>,
    layout: MarkerLayout,
    calibration: Calibration,
    tracker: Tracker,
}

impl std::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline")
            .field("detector", &self.detector.name())
            .field("tracker", &self.tracker)
            .finish()
    }
}

impl Pipeline {
    /// A pipeline from its parts.
    pub fn new(
        detector: Box<dyn Detector>,
        layout: MarkerLayout,
        calibration: Calibration,
        params: TrackerParams,
    ) -> Pipeline {
        Pipeline {
            detector,
            layout,
            calibration,
            tracker: Tracker::new(params),
        }
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// Process one frame.
    pub fn process(&mut self, frame: &Frame) -> Result<FrameResult, DetectError> {
        let detections = self.detector.detect(frame)?;
        let measurements = measure(&detections, &self.calibration, &self.layout);
        let obs: Vec<(String, Pose)> = measurements
            .iter()
            .map(|m| (m.body.clone(), m.body_pose))
            .collect();
        let tracked = self.tracker.update(frame.time, &obs);
        Ok(FrameResult {
            seq: frame.seq,
            time: frame.time,
            detections,
            measurements,
            tracked,
        })
    }
}

/// One JSON line of `pushbot track --json`.
#[derive(Debug, Clone, Serialize)]
pub struct TrackLine {
    /// Frame number.
    pub seq: u64,
    /// Frame time, seconds.
    pub time: f64,
    /// Every tracked body.
    pub bodies: Vec<TrackBody>,
}

/// One body in a [`TrackLine`].
#[derive(Debug, Clone, Serialize)]
pub struct TrackBody {
    /// The body's name.
    pub id: String,
    /// x, metres.
    pub x: f64,
    /// y, metres.
    pub y: f64,
    /// Heading, radians.
    pub theta: f64,
    /// Whether its marker was detected (and accepted) in this frame.
    pub seen: bool,
    /// Seconds since its last accepted detection.
    pub age: f64,
}

impl From<&FrameResult> for TrackLine {
    fn from(r: &FrameResult) -> TrackLine {
        TrackLine {
            seq: r.seq,
            time: r.time,
            bodies: r
                .tracked
                .iter()
                .map(|t| TrackBody {
                    id: t.body.clone(),
                    x: t.pose.x,
                    y: t.pose.y,
                    theta: t.pose.theta,
                    seen: t.seen && !t.rejected,
                    age: t.age,
                })
                .collect(),
        }
    }
}

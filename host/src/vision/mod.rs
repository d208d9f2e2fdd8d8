//! Vision: the overhead camera's frames → marker detections → table-plane poses → filtered poses
//! of the robot, objects and goals (Lau et al. §IV: a ceiling camera tracks markers on the
//! robot, the object and the goal at 960×720, 30 fps).
//!
//! - [`source`]: frame sources behind [`frame::FrameSource`] (V4L2, image folder, sim socket),
//!   and [`source::open_source`], which picks one;
//! - [`detect`]: detectors behind [`detection::Detector`]: the reference C AprilTag
//!   ([`apriltag`], the default) and, with the `kornia` feature, the pure-Rust
//!   `kornia-apriltag` (`kornia`); [`detect::make_detector`] picks one;
//! - [`homography`] and [`calibration`]: pixel → table-plane homography from markers at known
//!   places;
//! - [`lens_calib`]: the lens's intrinsics and distortion from frames of a printed AprilTag
//!   board (Zhang's method, Levenberg–Marquardt), and `board_svg` (with `sim`): the board to
//!   print;
//! - [`layout`]: which marker is where (until the shared scene format carries it);
//! - [`tracking`]: a Kalman filter per body;
//! - [`Pipeline`]: detect → measure → filter per frame; between whole-frame searches it looks
//!   only in regions around each tracked marker's predicted place ([`RoiParams`]);
//! - `crate::sim::synth` and `bench` (with the simulator): rendered test frames with ground
//!   truth, and `pushbot bench vision`.
//!
//! The choice, measured by `pushbot bench vision` on the same rendered 960×720 frames: the C
//! detector at `quad_sigma = 1` (as fast as kornia-apriltag at its defaults on whole frames,
//! with half its corner error, and without the faer build) in tracker-guided regions of
//! interest, about 2 ms per frame on one core against 30 ms for the reference C settings.

pub mod apriltag;
#[cfg(feature = "sim")]
pub mod bench;
#[cfg(feature = "sim")]
pub mod board_svg;
pub mod calibration;
pub mod detect;
pub mod detection;
pub mod folder;
pub mod frame;
pub mod homography;
#[cfg(feature = "kornia")]
pub mod kornia;
pub mod layout;
pub mod lens_calib;
pub mod odometry;
pub mod pnp;
mod roi;
pub mod simsocket;
pub mod source;
pub mod tracking;
mod travel;
pub mod undistort;
pub mod v4l2;

use serde::Serialize;

use calibration::Calibration;
use detection::{DetectError, Detection, Detector};
use frame::Frame;
use layout::{MarkerLayout, Pose};
use roi::Sighting;
pub use roi::{MotionBound, RoiParams};
use tracking::{TrackedPose, Tracker, TrackerParams};
use travel::Travel;

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
        let Some((marker_pose, side)) = cal.marker_pose_at(d, bm.height) else {
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
    /// Raw detections (with regions of interest: those found in the regions searched).
    pub detections: Vec<Detection>,
    /// Per-frame body poses.
    pub measurements: Vec<Measurement>,
    /// Filtered poses of every body tracked so far.
    pub tracked: Vec<TrackedPose>,
    /// Whether the whole frame was searched (rather than only regions around the predicted
    /// markers).
    pub full_frame: bool,
    /// Measurements dropped because they put a body off the table (a smeared or half-seen
    /// marker read wrong): never handed to the tracker.
    pub off_table: usize,
}

/// What one search found: its detections and the body poses measured from them.
type Seen = (Vec<Detection>, Vec<Measurement>);

/// How far past the table's edge a body's centre may be measured, metres.
pub const OFF_TABLE_MARGIN: f64 = 0.05;

/// The whole tracking pipeline: detect, measure, filter.
pub struct Pipeline {
    detector: Box<dyn Detector>,
    layout: MarkerLayout,
    calibration: Calibration,
    tracker: Tracker,
    roi: RoiParams,
    since_full: u32,
    /// Bodies seen in the last frame, by name.
    sightings: Vec<(String, Sighting)>,
    /// The latest sighting of every body seen so far, by name.
    last_seen: Vec<(String, Sighting)>,
    /// The camera's lens: detections are undistorted before they are measured.
    lens: Option<pushbot_world::lens::Intrinsics>,
    /// Of each body that whole-frame searches at full resolution have not found: when the
    /// last one was, and the seconds to wait before the next.
    fine_backoff: Vec<(String, f64, f64)>,
    /// How far anything can have moved since some time, when the caller knows it.
    travel: Travel,
    /// How far one body (the robot, by its own odometry) can have moved, when the caller knows.
    body_travel: Vec<(String, Travel)>,
}

/// Seconds between whole-frame searches at full resolution while a body is not found; the
/// wait doubles with every search that does not find it, up to [`FINE_EVERY_MAX`].
const FINE_EVERY: f64 = 0.5;

/// Seconds after its last sighting during which a missing body has every frame searched whole.
const REACQUIRE_S: f64 = 5.0;

/// The longest wait between searches at full resolution for a body still not found (a marker
/// hidden under something): a whole-frame one is the slowest search a frame can take.
const FINE_EVERY_MAX: f64 = 32.0;

impl std::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline")
            .field("detector", &self.detector.name())
            .field("roi", &self.roi)
            .field("tracker", &self.tracker)
            .finish()
    }
}

impl Pipeline {
    /// A pipeline from its parts, with the default regions of interest ([`RoiParams`]).
    pub fn new(
        detector: Box<dyn Detector>,
        layout: MarkerLayout,
        calibration: Calibration,
        params: TrackerParams,
    ) -> Pipeline {
        // A calibration fit through a lens measures through it ([`Calibration::fit_through`]).
        let lens = calibration.lens;
        Pipeline {
            detector,
            layout,
            calibration,
            tracker: Tracker::new(params),
            roi: RoiParams::default(),
            since_full: 0,
            sightings: Vec::new(),
            last_seen: Vec::new(),
            lens,
            fine_backoff: Vec::new(),
            travel: Travel::default(),
            body_travel: Vec::new(),
        }
    }

    /// Measure detections (raw pixels) through the lens, if there is one.
    fn measure_raw(&self, dets: &[Detection]) -> Vec<Measurement> {
        match &self.lens {
            Some(lens) => measure(
                &undistort::undistort_detections(dets, lens),
                &self.calibration,
                &self.layout,
            ),
            None => measure(dets, &self.calibration, &self.layout),
        }
    }

    /// Nothing on the table has moved farther than `bound` says between its time and the next
    /// frame (the caller's knowledge: its robot's odometry, when nothing else moves things).
    /// Given before every frame, the bounds add up: the region around a marker seen several
    /// frames ago reaches as far as their sum since then, however long the gap. A marker that
    /// moved farther anyway is missed in its region and found by the whole-frame search after.
    pub fn bound_motion(&mut self, bound: MotionBound) {
        self.travel.add(bound);
    }

    /// As [`Self::bound_motion`], for one body only (the robot, by its own odometry): its
    /// marker's region takes the tighter of the two.
    pub fn bound_body_motion(&mut self, body: &str, bound: MotionBound) {
        match self.body_travel.iter_mut().find(|(b, _)| b == body) {
            Some((_, t)) => t.add(bound),
            None => {
                let mut t = Travel::default();
                t.add(bound);
                self.body_travel.push((body.to_string(), t));
            }
        }
    }

    /// The farthest `body`, seen at `seen`, can have moved by a frame at `time`, metres, as the
    /// bounds given say; nothing for a body fixed to the table.
    fn moved(&self, body: &str, seen: f64, time: f64) -> Option<f64> {
        if self.is_fixed(body) {
            return Some(0.0);
        }
        let all = self.travel.since(seen, time);
        let own = self
            .body_travel
            .iter()
            .find(|(b, _)| b == body)
            .and_then(|(_, t)| t.since(seen, time));
        match (all, own) {
            (Some(a), Some(o)) => Some(a.min(o)),
            (a, o) => a.or(o),
        }
    }

    /// Whether `body`'s marker is fixed to the table ([`layout::BodyMarker::fixed`]).
    fn is_fixed(&self, body: &str) -> bool {
        self.layout.bodies.iter().any(|b| b.body == body && b.fixed)
    }

    /// Whether a body of the layout is neither tracked in the last frame nor fixed where it
    /// was seen: then the scheduled whole-frame searches look for it.
    fn untracked(&self) -> bool {
        self.layout.bodies.iter().any(|b| {
            let seen = |list: &[(String, Sighting)]| list.iter().any(|(n, _)| n == &b.body);
            !(seen(&self.sightings) || (b.fixed && seen(&self.last_seen)))
        })
    }

    /// The same pipeline with other region-of-interest settings.
    pub fn with_roi(mut self, roi: RoiParams) -> Pipeline {
        self.roi = roi;
        self
    }

    /// The robot's odometry pose (its own frame) at `time` (the frames' clock) for `body`:
    /// the tracker predicts that body's motion from it ([`odometry`]).
    pub fn odometry(&mut self, body: &str, time: f64, pose: Pose) {
        self.tracker.odometry(body, time, pose);
    }

    /// Forget `body`'s odometry (a robot that restarted counts from zero again): it is
    /// predicted from its velocity until new odometry comes.
    pub fn forget_odometry(&mut self, body: &str) {
        self.tracker.forget_odometry(body);
    }

    /// The calibration in use.
    pub fn calibration(&self) -> &Calibration {
        &self.calibration
    }

    /// The markers it knows.
    pub fn layout(&self) -> &MarkerLayout {
        &self.layout
    }

    /// The regions the next frame (taken at `time`, `width × height` pixels) will be searched
    /// in — around each body's predicted marker — or `None` when the whole frame is due. A
    /// camera that can read out parts of its sensor needs only these
    /// ([`Self::process_regions`]).
    pub fn plan(&self, time: f64, width: u32, height: u32) -> Option<Vec<detection::Region>> {
        if self.roi.full_every <= 1
            || (self.since_full + 1 >= self.roi.full_every && self.untracked())
            || self.sightings.is_empty()
        {
            return None;
        }
        self.expected(time)
            .iter()
            .map(|(body, s, _)| {
                let moved = self.moved(body, s.time(), time);
                s.region(time, width, height, &self.roi, moved)
            })
            .collect()
    }

    /// The bodies a frame at `time` is searched for in regions: those in the last frame, then
    /// those seen before but not in it (true): a body fixed to the table always (in the small
    /// square where it lies), others until they are found again or have been missing for
    /// REACQUIRE_S (then they are hidden, and the scheduled whole-frame searches look for
    /// them).
    fn expected(&self, time: f64) -> Vec<(String, Sighting, bool)> {
        let mut out: Vec<(String, Sighting, bool)> = self
            .sightings
            .iter()
            .map(|(b, s)| (b.clone(), *s, false))
            .collect();
        for (body, s) in &self.last_seen {
            if !self.sightings.iter().any(|(b, _)| b == body)
                && (self.is_fixed(body) || (0.0..REACQUIRE_S).contains(&(time - s.time())))
            {
                out.push((body.clone(), *s, true));
            }
        }
        out
    }

    /// Detect and measure in `regions` (as [`Self::plan`] gave them, one per body seen in the
    /// last frame); `None` when they miss a body they should have found ([`Self::bounded`]).
    fn look_regions(
        &mut self,
        frame: &Frame,
        regions: &[detection::Region],
    ) -> Result<Option<Seen>, DetectError> {
        let expected = self.expected(frame.time);
        if regions.len() != expected.len() || regions.is_empty() {
            return Ok(None);
        }
        let mut dets: Vec<Detection> = Vec::new();
        for (&r, (body, _, lost)) in regions.iter().zip(&expected) {
            let mut found = self.detector.detect_region(frame, r)?;
            // A marker too small for the decimated search: look again at full resolution (not
            // for a lost one in its wide region: the whole-frame searches do that; a fixed one,
            // covered where it lies, only from time to time).
            let want = self
                .layout
                .bodies
                .iter()
                .find(|b| &b.body == body)
                .map(|b| (b.family, b.id, b.fixed));
            let has = |found: &[Detection], (family, id): (_, u32)| {
                found.iter().any(|d| d.family == family && d.id == id)
            };
            if let Some((family, id, fixed)) = want
                && !has(&found, (family, id))
                && (!lost || (fixed && self.fine_due(body, frame.time)))
            {
                found = self.detector.detect_region_fine(frame, r)?;
                if *lost {
                    let hit = has(&found, (family, id));
                    self.fine_searched(body, frame.time, hit);
                }
            }
            for d in found {
                // Overlapping regions find the same marker twice: keep one.
                let dup = dets.iter().any(|e| {
                    e.family == d.family
                        && e.id == d.id
                        && (e.centre[0] - d.centre[0]).hypot(e.centre[1] - d.centre[1]) < 2.0
                });
                if !dup {
                    dets.push(d);
                }
            }
        }
        let ms = self.measure_raw(&dets);
        // A body missed where its motion bound put it is covered, not gone: the frame goes on
        // without it (the scheduled whole-frame searches look for it while it is untracked). A
        // body missed where only its velocity put it may have turned: the whole frame is due.
        if self
            .sightings
            .iter()
            .all(|(b, s)| ms.iter().any(|m| &m.body == b) || self.bounded(b, s.time(), frame.time))
        {
            self.since_full += 1;
            return Ok(Some((dets, ms)));
        }
        Ok(None)
    }

    /// Whether the region of `body`, seen at `seen`, in a frame at `time` was drawn by the
    /// motion bounds given ([`Self::bound_motion`]): after a gap longer than `max_gap`, with
    /// the body's bound tighter than `max_speed` allows. The marker is then inside it or
    /// covered.
    fn bounded(&self, body: &str, seen: f64, time: f64) -> bool {
        let gap = time - seen;
        gap > self.roi.max_gap
            && self
                .moved(body, seen, time)
                .is_some_and(|m| m <= self.roi.max_speed * gap)
    }

    /// Detect and measure in the whole frame (and at full resolution where a body is missing).
    fn look_whole(&mut self, frame: &Frame) -> Result<Seen, DetectError> {
        let mut dets = self.detector.detect(frame)?;
        let mut ms = self.measure_raw(&dets);
        // A body of the layout not found: search at full resolution too (its marker may be
        // small or far). Where it was last seen recently enough, only there; otherwise the
        // whole frame, every FINE_EVERY seconds at first and less often while it is not found
        // there (hidden under something). A marker fixed to the table is looked for only where
        // it lies, on the same backoff (the object over its goal's marker).
        let missing: Vec<String> = self
            .layout
            .bodies
            .iter()
            .filter(|b| !ms.iter().any(|m| m.body == b.body))
            .map(|b| b.body.clone())
            .collect();
        let mut regions = Vec::new();
        let mut whole = Vec::new();
        for body in &missing {
            let region = self
                .last_seen
                .iter()
                .find(|(b, _)| b == body)
                .and_then(|(_, s)| {
                    let moved = self.moved(body, s.time(), frame.time);
                    s.fine_region(frame.time, frame.width, frame.height, &self.roi, moved)
                });
            match region {
                // A fixed marker covered where it lies: searched there from time to time.
                Some(_) if self.is_fixed(body) && !self.fine_due(body, frame.time) => {}
                Some(r) if self.roi.full_every > 1 => regions.push((body.as_str(), r)),
                _ => whole.push(body.as_str()),
            }
        }
        let due = whole.iter().any(|body| self.fine_due(body, frame.time));
        let fine = if due {
            let fine = self.detector.detect_fine(frame)?;
            let found = self.measure_raw(&fine);
            let fixed: Vec<&str> = regions
                .iter()
                .map(|&(b, _)| b)
                .filter(|b| self.is_fixed(b))
                .collect();
            for body in whole.into_iter().chain(fixed) {
                let hit = found.iter().any(|m| m.body == body);
                self.fine_searched(body, frame.time, hit);
            }
            fine
        } else {
            let mut fine = Vec::new();
            for (body, r) in regions {
                let found = self.detector.detect_region_fine(frame, r)?;
                if self.is_fixed(body) {
                    let hit = self.measure_raw(&found).iter().any(|m| m.body == body);
                    self.fine_searched(body, frame.time, hit);
                }
                fine.extend(found);
            }
            fine
        };
        if !fine.is_empty() {
            for d in fine {
                if !dets.iter().any(|e| e.family == d.family && e.id == d.id) {
                    dets.push(d);
                }
            }
            ms = self.measure_raw(&dets);
        }
        self.since_full = 0;
        Ok((dets, ms))
    }

    /// Whether a search at full resolution for `body`, not found by the last ones, is due at
    /// `time`: every FINE_EVERY seconds at first, less often while it is not found.
    fn fine_due(&self, body: &str, time: f64) -> bool {
        self.fine_backoff
            .iter()
            .find(|(b, _, _)| b == body)
            .is_none_or(|&(_, last, wait)| !(0.0..wait).contains(&(time - last)))
    }

    /// A search at full resolution for `body` at `time` found it (`hit`) or not: the wait
    /// before the next starts again, or doubles up to FINE_EVERY_MAX.
    fn fine_searched(&mut self, body: &str, time: f64, hit: bool) {
        let entry = self.fine_backoff.iter().position(|(b, _, _)| b == body);
        match entry {
            Some(i) if hit => {
                self.fine_backoff.remove(i);
            }
            None if hit => {}
            Some(i) => {
                let (_, last, wait) = &mut self.fine_backoff[i];
                *last = time;
                *wait = (*wait * 2.0).min(FINE_EVERY_MAX);
            }
            None => self.fine_backoff.push((body.to_string(), time, FINE_EVERY)),
        }
    }

    /// Remember where each measured body's marker was seen.
    fn remember(&mut self, time: f64, dets: &[Detection], ms: &[Measurement]) {
        let mut next = Vec::with_capacity(ms.len());
        for m in ms {
            let Some(bm) = self.layout.bodies.iter().find(|b| b.body == m.body) else {
                continue;
            };
            let Some(d) = dets
                .iter()
                .filter(|d| d.family == bm.family && d.id == m.marker)
                .max_by(|a, b| a.margin.total_cmp(&b.margin))
            else {
                continue;
            };
            let previous = self.sightings.iter().find(|(b, _)| b == &m.body);
            if let Some(s) = Sighting::new(time, d, bm.side, previous.map(|(_, s)| s), &self.roi) {
                next.push((m.body.clone(), s));
            }
        }
        for (body, s) in &next {
            match self.last_seen.iter_mut().find(|(b, _)| b == body) {
                Some((_, last)) => *last = *s,
                None => self.last_seen.push((body.clone(), *s)),
            }
        }
        self.sightings = next;
    }

    /// Process one frame: searched in the regions of interest when they are due and find
    /// every body they should (one missed where its motion bound put it is covered), in the
    /// whole frame otherwise.
    pub fn process(&mut self, frame: &Frame) -> Result<FrameResult, DetectError> {
        self.check_size(frame)?;
        if let Some(regions) = self.plan(frame.time, frame.width, frame.height)
            && let Some(r) = self.process_regions(frame, &regions)?
        {
            return Ok(r);
        }
        self.process_whole(frame)
    }

    /// Process a frame of which only `regions` (as [`Self::plan`] gave them for it) are read:
    /// `None`, and nothing learnt, when they miss a body that only its velocity placed (it may
    /// have turned away) — then the whole frame is needed ([`Self::process_whole`]). A body
    /// missed in a region its motion bound drew is covered: the result leaves it unseen.
    pub fn process_regions(
        &mut self,
        frame: &Frame,
        regions: &[detection::Region],
    ) -> Result<Option<FrameResult>, DetectError> {
        self.check_size(frame)?;
        Ok(self
            .look_regions(frame, regions)?
            .map(|(dets, ms)| self.learn(frame, dets, ms, false)))
    }

    /// Process a frame searched whole, whatever regions are due.
    pub fn process_whole(&mut self, frame: &Frame) -> Result<FrameResult, DetectError> {
        self.check_size(frame)?;
        let (dets, ms) = self.look_whole(frame)?;
        Ok(self.learn(frame, dets, ms, true))
    }

    /// A frame of another size than the calibration's is refused.
    fn check_size(&self, frame: &Frame) -> Result<(), DetectError> {
        if [frame.width, frame.height] != self.calibration.image_size {
            let [w, h] = self.calibration.image_size;
            return Err(DetectError::Failed(format!(
                "the frame is {}×{}, the calibration was made for {w}×{h} frames: calibrate this \
                 camera at this size",
                frame.width, frame.height
            )));
        }
        Ok(())
    }

    /// Drop what is off the table, remember where the markers were, update the tracker.
    fn learn(
        &mut self,
        frame: &Frame,
        detections: Vec<Detection>,
        mut measurements: Vec<Measurement>,
        full_frame: bool,
    ) -> FrameResult {
        let [w, d] = self.layout.table;
        let m = OFF_TABLE_MARGIN;
        let before = measurements.len();
        measurements.retain(|ms| {
            let p = &ms.body_pose;
            (-m..=w + m).contains(&p.x) && (-m..=d + m).contains(&p.y) && p.theta.is_finite()
        });
        let off_table = before - measurements.len();
        self.travel.frame(frame.time);
        for (_, t) in &mut self.body_travel {
            t.frame(frame.time);
        }
        self.remember(frame.time, &detections, &measurements);
        let obs: Vec<(String, Pose)> = measurements
            .iter()
            .map(|m| (m.body.clone(), m.body_pose))
            .collect();
        let tracked = self.tracker.update(frame.time, &obs);
        FrameResult {
            seq: frame.seq,
            time: frame.time,
            detections,
            measurements,
            tracked,
            full_frame,
            off_table,
        }
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
    /// x, metres; `null` when the body is lost.
    pub x: Option<f64>,
    /// y, metres; `null` when lost.
    pub y: Option<f64>,
    /// Heading, radians; `null` when lost.
    pub theta: Option<f64>,
    /// Whether its marker was detected (and accepted) in this frame.
    pub seen: bool,
    /// Seconds since its last accepted detection.
    pub age: f64,
    /// Whether the tracker has lost it ([`tracking`]): no pose, rather than a guess.
    pub lost: bool,
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
                    x: (!t.lost).then_some(t.pose.x),
                    y: (!t.lost).then_some(t.pose.y),
                    theta: (!t.lost).then_some(t.pose.theta),
                    seen: t.seen && !t.rejected,
                    age: t.age,
                    lost: t.lost,
                })
                .collect(),
        }
    }
}

//! Where the pipeline spends its searches at full resolution (the slowest a frame can take):
//! a goal's marker fixed to the table and covered (the object over it) is looked for where it
//! lies, from time to time, and found there again when it is uncovered; the marker of a body that
//! moves, once missing, is hunted across the whole frame.

use std::cell::Cell;
use std::rc::Rc;

use pushbot::sim::synth::{self, SynthParams};
use pushbot::vision::apriltag::{AprilTagC, AprilTagCConfig};
use pushbot::vision::detect::{DetectError, Detection, Detector, Region};
use pushbot::vision::frame::Frame;
use pushbot::vision::layout::MarkerLayout;
use pushbot::vision::tracking::TrackerParams;
use pushbot::vision::{FrameResult, Pipeline};

/// Searches made, by kind.
#[derive(Debug, Default)]
struct Counts {
    whole: Cell<u32>,
    whole_fine: Cell<u32>,
    region: Cell<u32>,
    region_fine: Cell<u32>,
}

/// The C detector, counting its searches.
struct Counting {
    inner: AprilTagC,
    counts: Rc<Counts>,
}

fn bump(c: &Cell<u32>) {
    c.set(c.get() + 1);
}

impl Detector for Counting {
    fn name(&self) -> &'static str {
        "counting"
    }
    fn detect(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError> {
        bump(&self.counts.whole);
        self.inner.detect(frame)
    }
    fn detect_region(&mut self, frame: &Frame, r: Region) -> Result<Vec<Detection>, DetectError> {
        bump(&self.counts.region);
        self.inner.detect_region(frame, r)
    }
    fn detect_region_fine(
        &mut self,
        frame: &Frame,
        r: Region,
    ) -> Result<Vec<Detection>, DetectError> {
        if r == Region::full(frame.width, frame.height) {
            bump(&self.counts.whole_fine);
        } else {
            bump(&self.counts.region_fine);
        }
        self.inner.detect_region_fine(frame, r)
    }
    fn detect_fine(&mut self, frame: &Frame) -> Result<Vec<Detection>, DetectError> {
        bump(&self.counts.whole_fine);
        self.inner.detect_fine(frame)
    }
}

/// The goal's body in the built-in layout.
const GOAL: &str = "goal";

/// A still scene of the built-in table, and the same frame with the goal's marker painted over
/// (light grey, as an object resting on it).
fn still_scene() -> (MarkerLayout, Frame, Frame) {
    let layout = MarkerLayout::default_table();
    let first = synth::moving_frames(&layout, 1, 7, &SynthParams::default())
        .unwrap()
        .remove(0);
    let goal = layout.bodies.iter().find(|b| b.body == GOAL).unwrap().id;
    let truth = first.markers.iter().find(|m| m.marker.id == goal).unwrap();
    let xs = truth.corners_px.map(|c| c[0]);
    let ys = truth.corners_px.map(|c| c[1]);
    let lo = |v: [f64; 4]| (v.iter().cloned().fold(f64::INFINITY, f64::min) - 12.0).max(0.0);
    let hi = |v: [f64; 4]| v.iter().cloned().fold(0.0, f64::max) + 12.0;
    let mut covered = first.frame.clone();
    let w = covered.width as usize;
    for y in lo(ys) as usize..(hi(ys) as usize).min(covered.height as usize) {
        for x in lo(xs) as usize..(hi(xs) as usize).min(w) {
            covered.pixels[y * w + x] = 200;
        }
    }
    (layout, first.frame, covered)
}

/// A pipeline over `layout` whose detector counts its searches, calibrated from `frame`.
fn counting_pipeline(layout: &MarkerLayout, frame: &Frame) -> (Pipeline, Rc<Counts>) {
    let mut det = AprilTagC::new(&layout.families(), &AprilTagCConfig::default()).unwrap();
    let cal = synth::calibrate(&[det.detect(frame).unwrap()], layout, [960, 720]).unwrap();
    let counts = Rc::new(Counts::default());
    let det = Counting {
        inner: det,
        counts: counts.clone(),
    };
    let pipe = Pipeline::new(Box::new(det), layout.clone(), cal, TrackerParams::default());
    (pipe, counts)
}

/// `frame` as taken at frame number `seq` (30 fps).
fn at(frame: &Frame, seq: u64) -> Frame {
    Frame {
        seq,
        time: seq as f64 / 30.0,
        ..frame.clone()
    }
}

/// What 10 frames of the open scene, 120 covered (4 s) and 10 open again did.
struct Run {
    /// Whole-frame searches at full resolution, and regions searched at full resolution,
    /// while the goal was covered.
    covered_whole_fine: u32,
    covered_region_fine: u32,
    /// Frames searched whole while the goal was covered.
    covered_whole_frames: u32,
    /// Whether every other body was measured in every frame.
    others_always_seen: bool,
    /// The first open frame after the cover in which the goal was measured again.
    goal_back_after: Option<u64>,
}

fn run(fixed: bool) -> Run {
    let (mut layout, open, covered) = still_scene();
    layout
        .bodies
        .iter_mut()
        .filter(|b| b.body == GOAL)
        .for_each(|b| b.fixed = fixed);
    let (mut pipe, counts) = counting_pipeline(&layout, &open);
    let seen = |r: &FrameResult, body: &str| r.measurements.iter().any(|m| m.body == body);
    let mut others_always_seen = true;
    let mut check_others = |r: &FrameResult| {
        for b in layout.bodies.iter().filter(|b| b.body != GOAL) {
            others_always_seen &= seen(r, &b.body);
        }
    };
    for seq in 0..10 {
        let r = pipe.process(&at(&open, seq)).unwrap();
        assert!(seen(&r, GOAL), "the open goal is seen in frame {seq}");
        check_others(&r);
    }
    let (fine0, region0) = (counts.whole_fine.get(), counts.region_fine.get());
    let mut covered_whole_frames = 0;
    for seq in 10..130 {
        let r = pipe.process(&at(&covered, seq)).unwrap();
        assert!(
            !seen(&r, GOAL),
            "the covered goal is not seen in frame {seq}"
        );
        covered_whole_frames += u32::from(r.full_frame);
        check_others(&r);
    }
    let covered_whole_fine = counts.whole_fine.get() - fine0;
    let covered_region_fine = counts.region_fine.get() - region0;
    let mut goal_back_after = None;
    for seq in 130..140 {
        let r = pipe.process(&at(&open, seq)).unwrap();
        if goal_back_after.is_none() && seen(&r, GOAL) {
            goal_back_after = Some(seq - 130);
        }
        check_others(&r);
    }
    Run {
        covered_whole_fine,
        covered_region_fine,
        covered_whole_frames,
        others_always_seen,
        goal_back_after,
    }
}

/// A fixed goal under an object: no whole-frame search at full resolution in 4 s of cover,
/// its own place searched at full resolution a few times (the wait doubling from 0.5 s), one
/// whole frame (the frame its region first missed it), and found again in the first frame it
/// is open. The other bodies are tracked throughout.
#[test]
fn a_covered_fixed_marker_is_looked_for_where_it_lies() {
    let r = run(true);
    eprintln!(
        "fixed goal covered 4 s: {} whole-frame and {} region searches at full resolution, {} whole frames",
        r.covered_whole_fine, r.covered_region_fine, r.covered_whole_frames
    );
    assert!(r.others_always_seen);
    assert_eq!(r.covered_whole_fine, 0);
    assert!(
        (1..=5).contains(&r.covered_region_fine),
        "{}",
        r.covered_region_fine
    );
    assert!(r.covered_whole_frames <= 1, "{}", r.covered_whole_frames);
    assert_eq!(r.goal_back_after, Some(0));
}

/// The same marker on a body that may move: once missing it is hunted at full resolution in
/// the whole frame, and the scheduled whole-frame searches look for it, until it is back.
#[test]
fn a_missing_marker_of_a_moving_body_is_hunted_in_the_whole_frame() {
    let r = run(false);
    eprintln!(
        "moving goal covered 4 s: {} whole-frame and {} region searches at full resolution, {} whole frames",
        r.covered_whole_fine, r.covered_region_fine, r.covered_whole_frames
    );
    assert!(r.others_always_seen);
    assert!(r.covered_whole_fine >= 2, "{}", r.covered_whole_fine);
    assert!(r.covered_whole_frames >= 5, "{}", r.covered_whole_frames);
    assert!(r.goal_back_after.is_some_and(|k| k <= 9));
}

/// After a gap longer than `max_gap` a region reaches as far as the caller's motion bound says
/// the marker can have gone: a marker missed there is covered, and the frame goes on without
/// it (no whole frame). Without a bound, the same miss costs the whole frame.
#[test]
fn a_marker_missed_where_its_motion_bound_put_it_costs_no_whole_frame() {
    let (layout, open, covered) = still_scene();
    let gap = 0.5;
    for bounded in [true, false] {
        let (mut pipe, counts) = counting_pipeline(&layout, &open);
        for seq in 0..10 {
            pipe.process(&at(&open, seq)).unwrap();
        }
        let last = at(&open, 9).time;
        if bounded {
            pipe.bound_motion(pushbot::vision::MotionBound {
                since: last,
                metres: 0.01,
            });
        }
        let whole0 = counts.whole.get();
        let frame = Frame {
            seq: 10,
            time: last + gap,
            ..covered.clone()
        };
        let r = pipe.process(&frame).unwrap();
        let seen = |body: &str| r.measurements.iter().any(|m| m.body == body);
        assert!(!seen(GOAL), "the covered goal is not seen");
        for b in layout.bodies.iter().filter(|b| b.body != GOAL) {
            assert!(seen(&b.body), "{} is seen", b.body);
        }
        let whole = counts.whole.get() - whole0;
        eprintln!("bounded {bounded}: {whole} whole-frame searches");
        if bounded {
            assert!(!r.full_frame);
            assert_eq!(whole, 0);
        } else {
            assert!(r.full_frame);
            assert_eq!(whole, 1);
        }
    }
}

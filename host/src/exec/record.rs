//! A [`RobotIo`] that records what happens: after every primitive, the robot's and every
//! object's pose as the camera sees them (and, against a simulator, as they truly are), for the
//! trajectory figures and summaries of a run.

use anyhow::Result;
use serde::Serialize;

use crate::exec::io::{RobotIo, Workspace};
use crate::recording::RecordingHandle;
use crate::strategy::sample::Pose2;

/// One recorded instant: after a primitive (or at the start).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TracePoint {
    /// Robot time, s.
    pub t: f64,
    /// The primitive that just ended (`start` for the first point).
    pub after: &'static str,
    /// The robot's pose as seen.
    pub robot: Pose2,
    /// Each object's pose as seen (scene ids; absent when not seen).
    pub objects: Vec<(String, Pose2)>,
    /// The true robot and object poses, when a simulator tells them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub truth: Option<(Pose2, Vec<(String, Pose2)>)>,
}

/// Where the truth comes from, when there is one (a simulator).
pub type TruthProbe<'a> = Box<dyn Fn() -> (Pose2, Vec<(String, Pose2)>) + 'a>;

/// Records a robot's run.
pub struct Recorder<'a> {
    inner: &'a mut dyn RobotIo,
    ids: Vec<String>,
    truth: Option<TruthProbe<'a>>,
    trace: Vec<TracePoint>,
    primitives: usize,
    driven: f64,
    recording: Option<RecordingHandle>,
}

impl<'a> Recorder<'a> {
    /// Record `inner`, observing the objects `ids` after every primitive; `truth` reads the
    /// simulator's true poses, if there is one. Records the start at once.
    pub fn new(inner: &'a mut dyn RobotIo, ids: &[String], truth: Option<TruthProbe<'a>>) -> Self {
        let mut r = Recorder {
            inner,
            ids: ids.to_vec(),
            truth,
            trace: Vec::new(),
            primitives: 0,
            driven: 0.0,
            recording: None,
        };
        r.mark("start");
        r
    }

    /// Also write every trace point (those so far, then each new one) and every path shown
    /// into `recording`.
    pub fn with_recording(mut self, recording: Option<RecordingHandle>) -> Self {
        if let Some(h) = &recording {
            for p in &self.trace {
                h.with(|r| r.trace(p));
            }
        }
        self.recording = recording;
        self
    }

    /// Record the present as a point of the trace.
    pub fn mark(&mut self, after: &'static str) {
        let robot = self.inner.robot_pose();
        let objects = self
            .ids
            .iter()
            .filter_map(|id| self.inner.body_pose(id).map(|p| (id.clone(), p)))
            .collect();
        let truth = self.truth.as_ref().map(|f| f());
        let point = TracePoint {
            t: self.inner.time(),
            after,
            robot,
            objects,
            truth,
        };
        if let Some(h) = &self.recording {
            h.with(|r| r.trace(&point));
        }
        self.trace.push(point);
    }

    /// The trace so far.
    pub fn trace(&self) -> &[TracePoint] {
        &self.trace
    }

    /// Primitives run.
    pub fn primitives(&self) -> usize {
        self.primitives
    }

    /// Path length of the robot as seen, m.
    pub fn robot_path_length(&self) -> f64 {
        self.trace
            .windows(2)
            .map(|w| (w[1].robot.x - w[0].robot.x).hypot(w[1].robot.y - w[0].robot.y))
            .filter(|d| d.is_finite())
            .sum()
    }

    /// Distance commanded by `forward`, m (absolute).
    pub fn distance_commanded(&self) -> f64 {
        self.driven
    }

    /// Take the trace.
    pub fn into_trace(self) -> Vec<TracePoint> {
        self.trace
    }

    fn after(&mut self, what: &'static str, r: Result<()>) -> Result<()> {
        self.primitives += 1;
        self.mark(what);
        r
    }
}

impl RobotIo for Recorder<'_> {
    fn spin(&mut self, angle: f64) -> Result<()> {
        let r = self.inner.spin(angle);
        self.after("spin", r)
    }

    fn forward(&mut self, distance: f64) -> Result<()> {
        if distance.is_finite() {
            self.driven += distance.abs();
        }
        let r = self.inner.forward(distance);
        self.after("forward", r)
    }

    fn drive(&mut self, v: f64, omega: f64, duration: f64) -> Result<()> {
        let r = self.inner.drive(v, omega, duration);
        self.after("drive", r)
    }

    fn robot_pose(&mut self) -> Pose2 {
        self.inner.robot_pose()
    }

    fn object_pose(&mut self) -> Pose2 {
        self.inner.object_pose()
    }

    fn body_pose(&mut self, id: &str) -> Option<Pose2> {
        self.inner.body_pose(id)
    }

    fn time(&self) -> f64 {
        self.inner.time()
    }

    fn workspace(&self) -> Workspace {
        self.inner.workspace()
    }

    fn object_outline(&self) -> Vec<[f64; 2]> {
        self.inner.object_outline()
    }

    fn show_path(&mut self, path: &[[f64; 2]]) {
        if let Some(h) = &self.recording {
            h.with(|r| r.planned_path(path));
        }
        self.inner.show_path(path);
    }
}

#[cfg(all(test, feature = "sim"))]
mod tests {
    use super::*;
    use crate::sim::robot::{SimRobot, SimRobotOptions};

    #[test]
    fn records_a_point_after_every_primitive() {
        let scene = pushbot_world::Scene::preset("lau-irregular").expect("preset");
        let mut robot = SimRobot::new(scene, None, None, SimRobotOptions::default()).expect("sim");
        let ids = vec!["object".to_string()];
        let mut rec = Recorder::new(&mut robot, &ids, None);
        rec.forward(0.1).expect("forward");
        rec.spin(1.0).expect("spin");
        rec.forward(-0.05).expect("back");
        assert_eq!(rec.primitives(), 3);
        let trace = rec.trace();
        assert_eq!(trace.len(), 4);
        assert_eq!(trace[1].after, "forward");
        assert!(
            (rec.robot_path_length() - 0.15).abs() < 0.02,
            "{}",
            rec.robot_path_length()
        );
        assert!((rec.distance_commanded() - 0.15).abs() < 1e-12);
        assert!(trace.windows(2).all(|w| w[1].t > w[0].t));
        assert_eq!(trace[3].objects.len(), 1);
    }
}

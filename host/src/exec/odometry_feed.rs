//! The robot's telemetry as the tracker's odometry: every telemetry report the link
//! delivers carries the robot's wheel odometry and its own clock; the feed hands each one to the
//! vision pipeline on the camera's clock ([`crate::vision::Pipeline::odometry`]), so the tracker
//! predicts the robot's motion between frames from its wheels rather than from its last velocity.
//!
//! The two clocks: the simulated target's camera stamps frames with the simulated time the robot's
//! clock also counts (offset 0); a real camera counts from when it was opened, so the offset is
//! taken once, from the first frame and the robot's latest report at the same moment (good to a
//! frame's latency, which is what the odometry then lags by).

use std::sync::mpsc;

use crate::link::{Driver, RobotEvent};
use crate::robot::Robot;
use crate::vision::Pipeline;
use crate::vision::layout::Pose;

/// Telemetry from a robot, fed to a pipeline as odometry.
#[derive(Debug)]
pub struct OdometryFeed {
    events: mpsc::Receiver<RobotEvent>,
    /// Camera clock minus robot clock, seconds; `None` until the first frame sets it.
    offset: Option<f64>,
    /// The body the odometry is of.
    body: String,
    fed: u64,
}

impl OdometryFeed {
    /// Subscribe to `robot`'s reports. `offset`: the camera's clock minus the robot's, seconds,
    /// when known (0 for the simulated target's camera); `None` takes it from the first frame.
    pub fn new<D: Driver>(robot: &Robot<D>, offset: Option<f64>) -> OdometryFeed {
        OdometryFeed {
            events: robot.subscribe(),
            offset,
            body: "robot".into(),
            fed: 0,
        }
    }

    /// Give the pipeline every report received since the last call, before it processes the
    /// frame taken at `frame_time` (camera clock). Returns how many were given.
    pub fn feed<D: Driver>(
        &mut self,
        robot: &Robot<D>,
        pipeline: &mut Pipeline,
        frame_time: f64,
    ) -> usize {
        if self.offset.is_none()
            && let Some(t) = robot.telemetry()
        {
            self.offset = Some(frame_time - t.time_us as f64 * 1e-6);
        }
        let Some(offset) = self.offset else {
            return 0;
        };
        let mut n = 0;
        while let Ok(ev) = self.events.try_recv() {
            if let RobotEvent::Telemetry(t) = ev {
                let p = t.pose;
                pipeline.odometry(
                    &self.body,
                    t.time_us as f64 * 1e-6 + offset,
                    Pose::new(f64::from(p.x), f64::from(p.y), f64::from(p.theta)),
                );
                n += 1;
            }
        }
        self.fed += n as u64;
        n
    }

    /// Reports given so far.
    pub fn fed(&self) -> u64 {
        self.fed
    }
}

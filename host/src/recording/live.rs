//! What a robot seen by a camera ([`crate::exec::LiveRobot`]) records: a session when it
//! connects, then at every look the robot's reports since the last look (telemetry at its full
//! rate, contacts, motions' ends) and the camera frame with what tracking made of it.

use std::sync::mpsc::Receiver;

use super::RecordingHandle;
use super::writer::SessionInfo;
use crate::link::RobotEvent;
use crate::robot::Robot;
use crate::vision::FrameResult;
use crate::vision::calibration::Calibration;
use crate::vision::frame::Frame;

/// A live robot's link to a recording.
pub struct LiveRecording {
    handle: RecordingHandle,
    events: Receiver<RobotEvent>,
}

impl std::fmt::Debug for LiveRecording {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LiveRecording")
    }
}

/// The robot's clock now, µs (its latest telemetry).
fn robot_us(robot: &Robot) -> u64 {
    robot.telemetry().map_or(0, |t| t.time_us)
}

impl LiveRecording {
    /// Start a session for `robot`, described by `info` (scene, tracking set-up, lens).
    pub fn start(handle: &RecordingHandle, robot: &Robot, info: &SessionInfo<'_>) -> LiveRecording {
        let events = robot.subscribe();
        handle.with(|r| r.begin_session(info, robot_us(robot)));
        LiveRecording {
            handle: handle.clone(),
            events,
        }
    }

    /// A look: the robot's reports since the last one, then `frame`, the odometry the tracker
    /// was given with it, and its result.
    pub fn look(
        &self,
        robot: &Robot,
        frame: &Frame,
        result: &FrameResult,
        cal: &Calibration,
        odometry: Option<[f64; 3]>,
    ) {
        let now = robot_us(robot);
        self.handle.with(|r| {
            for e in self.events.try_iter() {
                r.robot_event(&e)?;
            }
            r.frame(now, frame, result, cal, odometry)
        });
    }
}

impl Drop for LiveRecording {
    /// The robot's reports since the last look (the end of the last motion) are recorded too.
    fn drop(&mut self) {
        self.handle.with(|r| {
            for e in self.events.try_iter() {
                r.robot_event(&e)?;
            }
            r.flush()
        });
    }
}

//! What a view outside the task may see of a live robot while the task runs: the latest look
//! ([`Watch`]: the frame's detections drawn over it, the tracked poses) and a way to stop the
//! robot at once from another thread ([`Stopper`]). Both only read or stop; neither decides.

use std::sync::{Arc, RwLock, RwLockReadGuard};

use anyhow::Result;
use pushbot_protocol::Telemetry;

use crate::link::LinkStats;
use crate::robot::Robot;
use crate::vision::FrameResult;

/// One tracked body as the latest look saw it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct WatchedBody {
    /// `robot`, an object id, or `goal:<id>`.
    pub id: String,
    /// Pose in the table frame: x, y (m), heading (rad).
    pub pose: [f64; 3],
    /// Whether its marker was seen in that frame.
    pub seen: bool,
    /// Position uncertainty, m (1 σ).
    pub sigma_m: f64,
}

/// The latest look of a live robot.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Watch {
    /// Looks so far (frames processed).
    pub looks: u64,
    /// Frame time of the latest look, s.
    pub time: f64,
    /// Markers detected in it.
    pub detections: usize,
    /// The overlay of that frame (SVG in its pixels): detections outlined, tracked bodies.
    #[serde(skip)]
    pub overlay_svg: String,
    /// Every tracked body.
    pub bodies: Vec<WatchedBody>,
}

impl Watch {
    /// Take in a look's result and its overlay.
    pub fn update(&mut self, r: &FrameResult, overlay_svg: String) {
        self.looks += 1;
        self.time = r.time;
        self.detections = r.detections.len();
        self.overlay_svg = overlay_svg;
        self.bodies = r
            .tracked
            .iter()
            .filter(|t| !t.lost)
            .map(|t| WatchedBody {
                id: t.body.clone(),
                pose: [t.pose.x, t.pose.y, t.pose.theta],
                seen: t.seen && !t.rejected,
                sigma_m: t.sigma_m,
            })
            .collect();
    }
}

/// Stops the robot from any thread, while a task's primitive runs on another.
#[derive(Clone)]
pub struct Stopper(Arc<RwLock<Robot>>);

impl std::fmt::Debug for Stopper {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Stopper")
    }
}

impl Stopper {
    /// A stopper for the robot behind `robot`.
    pub fn new(robot: Arc<RwLock<Robot>>) -> Stopper {
        Stopper(robot)
    }

    fn robot(&self) -> RwLockReadGuard<'_, Robot> {
        self.0
            .read()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Cut the motors at once and latch the emergency stop (the running primitive ends in
    /// that fault); returns the telemetry that shows it.
    pub fn emergency_stop(&self) -> Result<Telemetry> {
        Ok(self.robot().emergency_stop()?)
    }

    /// Brake to a stop (the running primitive ends aborted).
    pub fn stop(&self) -> Result<Telemetry> {
        Ok(self.robot().stop()?)
    }

    /// Clear the latched faults whose cause has gone; the faults still latched.
    pub fn clear_faults(&self) -> Result<pushbot_protocol::Faults> {
        Ok(self.robot().clear_faults()?)
    }

    /// The latest telemetry.
    pub fn telemetry(&self) -> Option<Telemetry> {
        self.robot().telemetry()
    }

    /// The link's counters.
    pub fn stats(&self) -> LinkStats {
        self.robot().stats()
    }

    /// The port's path.
    pub fn path(&self) -> String {
        self.robot().path().to_string()
    }

    /// Recoveries of the link so far.
    pub fn recoveries(&self) -> usize {
        self.robot().recoveries().len()
    }
}

//! What a board or the host may read from the [`Core`]: outputs, mode, faults, pose,
//! parameters, session and link counters, telemetry.

use pushbot_protocol::{Faults, Mode, Outcome, Pose, Telemetry};

use crate::params::{Limits, RobotParams};

use super::{Core, Kind, Outputs};

impl Core {
    /// The duties of the last step, or zero if a fault or a contact stop since then cut the
    /// motors (a board may apply this right after [`Core::receive`] so an emergency stop acts
    /// before the next tick).
    pub fn outputs(&self) -> Outputs {
        Outputs { duty: self.duty }
    }

    /// Move queued bytes for the host into `out`; returns how many were written.
    pub fn transmit(&mut self, out: &mut [u8]) -> usize {
        self.link.tx.drain(out)
    }

    /// What the robot is doing.
    pub fn mode(&self) -> Mode {
        if !self.faults.is_empty() {
            return Mode::Faulted;
        }
        match self.active.map(|a| a.kind) {
            Some(Kind::Velocity { .. }) => Mode::Velocity,
            Some(Kind::Move { .. }) => Mode::Move,
            Some(Kind::Spin { .. }) => Mode::Spin,
            Some(Kind::Advance { .. }) => Mode::Advance,
            None if self.braking => Mode::Braking,
            None => Mode::Idle,
        }
    }

    /// Latched faults.
    pub fn faults(&self) -> Faults {
        self.faults
    }

    /// Odometry pose.
    pub fn pose(&self) -> Pose {
        self.odometry.pose()
    }

    /// The settings the core was built with.
    pub fn params(&self) -> &RobotParams {
        &self.params
    }

    /// The motion limits in force (as last configured).
    pub fn limits(&self) -> Limits {
        self.limits
    }

    /// Whether a host with our protocol version has opened a session.
    pub fn has_session(&self) -> bool {
        self.link.session()
    }

    /// Sequence number of the running motion command.
    pub fn active(&self) -> Option<u16> {
        self.active.map(|a| a.seq)
    }

    /// The last motion command that ended, and how.
    pub fn last_done(&self) -> Option<(u16, Outcome)> {
        self.last_done
    }

    /// Debounced bumper switches.
    pub fn bumper(&self) -> u8 {
        self.bumper.state()
    }

    /// Measured wheel speeds [left, right], rad/s.
    pub fn wheel_speed(&self) -> [f32; 2] {
        self.measured
    }

    /// The state as telemetry reports it, at robot time `now_us`.
    pub fn telemetry(&self, now_us: u64) -> Telemetry {
        Telemetry {
            time_us: now_us,
            pose: self.odometry.pose(),
            wheel_speed: self.measured,
            bumper: self.bumper.state(),
            mode: self.mode(),
            faults: self.faults,
            active: self.active(),
            last_done: self.last_done,
        }
    }

    /// Messages dropped because the transmit queue was full.
    pub fn tx_dropped(&self) -> u32 {
        self.link.tx.dropped()
    }

    /// Received frames rejected (corrupt, oversized, not a message).
    pub fn rx_rejected(&self) -> u32 {
        self.link.rejected()
    }
}

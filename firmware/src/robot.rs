//! The core: ties the parts together behind the sans-IO contract of the crate docs.

use pushbot_protocol::{Faults, Mode, Pose};

use crate::params::RobotParams;

/// Sensor readings for one control step.
#[derive(Clone, Copy, Debug, Default)]
pub struct Inputs {
    /// Cumulative wrapping quadrature counts [left, right], positive = forward.
    pub encoder: [i32; 2],
    /// Raw bumper switch bits (bit 0 left, 1 centre, 2 right), undebounced.
    pub bumper: u8,
}

/// Actuator commands of one control step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outputs {
    /// Signed duty per wheel [left, right], -1..=1; 0 = motors off.
    pub duty: [f32; 2],
}

/// The robot: feed it link bytes, time and sensor readings; it returns duties and bytes to send.
pub struct Core {
    params: RobotParams,
    mode: Mode,
    faults: Faults,
    pose: Pose,
}

impl Core {
    /// A robot at rest, without a session, at pose zero.
    pub fn new(params: RobotParams) -> Self {
        Core {
            params,
            mode: Mode::Idle,
            faults: Faults::NONE,
            pose: Pose::default(),
        }
    }

    /// Control period, µs: call [`Core::step`] this often (`1e6 / control_hz`).
    pub fn tick_period_us(&self) -> u32 {
        self.params.tick_period_us()
    }

    /// Hand over bytes received from the link, at any time.
    pub fn receive(&mut self, now_us: u64, bytes: &[u8]) {
        let _ = (now_us, bytes);
    }

    /// Run one control step at robot time `now_us`; returns the motor duties.
    pub fn step(&mut self, now_us: u64, inputs: &Inputs) -> Outputs {
        let _ = (now_us, inputs);
        Outputs::default()
    }

    /// Move queued bytes for the host into `out`; returns how many were written.
    pub fn transmit(&mut self, out: &mut [u8]) -> usize {
        let _ = out;
        0
    }

    /// What the robot is doing.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Latched faults.
    pub fn faults(&self) -> Faults {
        self.faults
    }

    /// Odometry pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }
}

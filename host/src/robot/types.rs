//! The robot layer's plain types: link settings, what the robot said about itself, how a
//! motion ended, and the protocol's names and time budgets of commands.

use std::time::Duration;

use pushbot_protocol::{
    Command, FirmwareVersion, Geometry, Outcome, PROTOCOL_VERSION, Pose, Telemetry,
};

use crate::link::ClientOptions;

/// Settings of the link (not of the robot).
#[derive(Debug, Clone, PartialEq)]
pub struct LinkOptions {
    /// How long to wait for an `Ack`/`Nack` before resending, wall time.
    pub ack_timeout: Duration,
    /// How many times a command is sent before giving up.
    pub attempts: u32,
    /// How long the handshake keeps resending `Hello` (every `ack_timeout`), wall time: a
    /// board that was just plugged in or reset may take a moment to boot.
    pub hello_timeout: Duration,
    /// No byte at all from the robot for this long (wall time) means the link is dead.
    pub dead_link_timeout: Duration,
    /// The robot's link watchdog the heartbeats are paced for, ms of robot time (the firmware
    /// default is 200; [`super::Robot::configure`] keeps this up to date).
    pub watchdog_ms: u16,
    /// How long [`super::Robot::reconnect`] keeps trying while the port is away or mute, wall
    /// time (`--reconnect SECONDS`); zero: one attempt (a vanished port is then an error at once).
    pub reconnect_timeout: Duration,
    /// Offer this protocol version in the handshake instead of [`PROTOCOL_VERSION`]: a test and
    /// diagnostic hook to check that a mismatch is refused.
    pub protocol_version_override: Option<u16>,
}

impl Default for LinkOptions {
    fn default() -> Self {
        LinkOptions {
            ack_timeout: Duration::from_millis(150),
            attempts: 5,
            hello_timeout: Duration::from_millis(1500),
            dead_link_timeout: Duration::from_secs(3),
            watchdog_ms: 200,
            reconnect_timeout: Duration::ZERO,
            protocol_version_override: None,
        }
    }
}

impl LinkOptions {
    /// The link client's options for these settings, numbering commands from `first_seq`.
    pub fn client_options(&self, first_seq: u16) -> ClientOptions {
        ClientOptions {
            ack_timeout: self.ack_timeout,
            attempts: self.attempts,
            hello_timeout: self.hello_timeout,
            dead_link_timeout: self.dead_link_timeout,
            watchdog_ms: self.watchdog_ms,
            protocol_version: self.protocol_version_override.unwrap_or(PROTOCOL_VERSION),
            first_seq,
        }
    }
}

/// What the robot said about itself in the handshake, and its state now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotInfo {
    /// Protocol version both sides speak.
    pub protocol: u16,
    /// Firmware version.
    pub firmware: FirmwareVersion,
    /// The robot's build.
    pub geometry: Geometry,
    /// The latest telemetry (odometry, mode, faults).
    pub telemetry: Telemetry,
}

/// How a motion command ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoneReport {
    /// The command's sequence number.
    pub seq: u16,
    /// How it ended.
    pub outcome: Outcome,
    /// Odometry pose at the end.
    pub pose: Pose,
    /// Robot time at the end, µs.
    pub time_us: u64,
    /// Robot time the command took (from the acknowledgement's telemetry), s.
    pub duration_s: f64,
    /// Whether the `Done` frame was lost and the outcome was read from the telemetry instead.
    pub recovered: bool,
}

/// A motion command the robot accepted and has not finished: pass it to
/// [`super::Robot::wait`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// The command's sequence number.
    pub seq: u16,
    /// The command's name.
    pub what: &'static str,
    /// Robot time when it was acknowledged (latest telemetry), µs.
    pub started_us: Option<u64>,
    /// How much robot time it may take before the host gives up and sends `Stop`, µs.
    pub budget_us: u64,
}

/// The protocol's name of a command.
pub fn command_name(cmd: &Command) -> &'static str {
    match cmd {
        Command::Hello { .. } => "Hello",
        Command::Heartbeat => "Heartbeat",
        Command::Velocity { .. } => "Velocity",
        Command::Move { .. } => "Move",
        Command::Spin { .. } => "Spin",
        Command::AdvanceUntilContact { .. } => "AdvanceUntilContact",
        Command::Stop => "Stop",
        Command::EmergencyStop => "EmergencyStop",
        Command::ClearFaults => "ClearFaults",
        Command::Configure(_) => "Configure",
        Command::ResetOdometry(_) => "ResetOdometry",
    }
}

/// Robot time a motion may take before the host gives up: twice the cruise time plus 5 s
/// (acceleration ramps, wheel slip), or `None` for commands that are not motions.
pub fn motion_budget_us(cmd: &Command) -> Option<u64> {
    let slack = 5.0;
    let secs = match *cmd {
        Command::Move {
            distance, speed, ..
        } => 2.0 * f64::from(distance.abs()) / f64::from(speed) + slack,
        Command::Spin { angle, rate } => 2.0 * f64::from(angle.abs()) / f64::from(rate) + slack,
        Command::AdvanceUntilContact {
            max_distance,
            speed,
        } => 2.0 * f64::from(max_distance.abs()) / f64::from(speed) + slack,
        Command::Velocity { timeout_ms, .. } => f64::from(timeout_ms) / 1000.0 + slack,
        _ => return None,
    };
    Some((secs.clamp(0.0, 1.0e7) * 1.0e6) as u64)
}

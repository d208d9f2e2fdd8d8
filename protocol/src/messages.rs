//! The messages: what the host may ask of the robot and what the robot reports.
//!
//! Units are SI throughout: metres, seconds, radians; robot time is in microseconds since the
//! robot started. Angles grow counter-clockwise; the odometry frame has x forward and y to the
//! left of the robot's pose at the last odometry reset.

use serde::{Deserialize, Serialize};

/// A planar pose in the odometry frame: position in metres, heading in radians (−π, π].
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pose {
    /// x in metres.
    pub x: f32,
    /// y in metres.
    pub y: f32,
    /// Heading in radians.
    pub theta: f32,
}

/// One frame from the host to the robot: a command and its sequence number.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HostFrame {
    /// Sequence number; a frame repeating the previous command's number is a retry.
    pub seq: u16,
    /// What to do.
    pub cmd: Command,
}

/// Everything the host can ask of the robot.
///
/// Motion commands (`Velocity`, `Move`, `Spin`, `AdvanceUntilContact`) pre-empt a running one,
/// which then ends with [`Outcome::Aborted`]. Each motion command ends with exactly one
/// [`RobotMsg::Done`].
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// Open a session. Variant 0 forever; `protocol` is its first field forever.
    Hello {
        /// The host's [`crate::PROTOCOL_VERSION`].
        protocol: u16,
    },
    /// Keeps the link watchdog fed. Not acknowledged.
    Heartbeat,
    /// Drive at a body velocity until `timeout_ms` of robot time has passed (then
    /// `Done(Timeout)`), or until another command replaces it.
    Velocity {
        /// Forward speed, m/s.
        v: f32,
        /// Turn rate, rad/s (counter-clockwise positive).
        omega: f32,
        /// How long to keep going, ms of robot time.
        timeout_ms: u16,
    },
    /// Drive straight for a distance (negative: backwards) on an acceleration-limited profile.
    Move {
        /// Signed distance, m.
        distance: f32,
        /// Cruise speed, m/s (positive).
        speed: f32,
        /// End early with `Done(Contact)` at the first bumper contact.
        stop_on_contact: bool,
    },
    /// Turn on the spot by an angle.
    Spin {
        /// Signed angle, rad (counter-clockwise positive).
        angle: f32,
        /// Cruise turn rate, rad/s (positive).
        rate: f32,
    },
    /// Drive forward until the bumper closes (`Done(Contact)`) or `max_distance` is covered
    /// (`Done(Completed)`).
    AdvanceUntilContact {
        /// Distance limit, m (positive).
        max_distance: f32,
        /// Cruise speed, m/s (positive).
        speed: f32,
    },
    /// Brake to a stop on the deceleration limit; the running primitive ends `Aborted`.
    Stop,
    /// Cut the motors at once and latch [`Faults::EMERGENCY_STOP`].
    EmergencyStop,
    /// Clear latched faults (those whose cause has gone).
    ClearFaults,
    /// Change settings; fields that are `None` stay as they are.
    Configure(ConfigUpdate),
    /// Set the odometry pose.
    ResetOdometry(Pose),
}

/// Gains of the wheel-speed controller (per wheel, the same for both).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WheelGains {
    /// Proportional gain, duty per (rad/s) of wheel-speed error.
    pub kp: f32,
    /// Integral gain, duty per rad of accumulated wheel-angle error.
    pub ki: f32,
    /// Feed-forward, duty per (rad/s) of wheel-speed target.
    pub kff: f32,
}

/// A partial update of the robot's settings.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigUpdate {
    /// Wheel-speed controller gains.
    pub wheel_gains: Option<WheelGains>,
    /// Largest forward speed, m/s.
    pub max_speed: Option<f32>,
    /// Largest forward acceleration, m/s².
    pub max_accel: Option<f32>,
    /// Largest turn rate, rad/s.
    pub max_omega: Option<f32>,
    /// Largest angular acceleration, rad/s².
    pub max_alpha: Option<f32>,
    /// Link watchdog: motors off when no valid frame arrived for this long, ms of robot time.
    pub watchdog_ms: Option<u16>,
    /// Telemetry rate, Hz of robot time (0 turns telemetry off).
    pub telemetry_hz: Option<u16>,
}

/// Firmware version, semantic.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FirmwareVersion {
    /// Major version.
    pub major: u8,
    /// Minor version.
    pub minor: u8,
    /// Patch version.
    pub patch: u8,
}

/// The robot's build: what the host needs to plan for it.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Geometry {
    /// Distance between the wheel contact points, m.
    pub wheel_base: f32,
    /// Wheel radius, m.
    pub wheel_radius: f32,
    /// Radius of the circular bumper around the wheel-axle centre, m.
    pub bumper_radius: f32,
    /// Encoder counts per wheel revolution (after quadrature decoding).
    pub encoder_cpr: u32,
    /// Control loop rate, Hz.
    pub control_hz: u16,
}

/// The robot's answer to [`Command::Hello`].
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HelloReply {
    /// The robot's [`crate::PROTOCOL_VERSION`]. First field forever.
    pub protocol: u16,
    /// Whether the robot accepted the session (the versions match).
    pub accepted: bool,
    /// Firmware version.
    pub firmware: FirmwareVersion,
    /// Robot geometry.
    pub geometry: Geometry,
}

/// Latched fault flags. Motion is refused while any is set; [`Command::ClearFaults`] clears
/// those whose cause has gone.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Faults(pub u16);

impl Faults {
    /// No fault.
    pub const NONE: Faults = Faults(0);
    /// The left wheel was driven hard but did not turn.
    pub const STALL_LEFT: Faults = Faults(1 << 0);
    /// The right wheel was driven hard but did not turn.
    pub const STALL_RIGHT: Faults = Faults(1 << 1);
    /// No valid frame from the host within the watchdog time.
    pub const LINK_LOST: Faults = Faults(1 << 2);
    /// An emergency stop was commanded.
    pub const EMERGENCY_STOP: Faults = Faults(1 << 3);
    /// An encoder reported an impossible jump.
    pub const ENCODER: Faults = Faults(1 << 4);
    /// The control loop missed its deadline.
    pub const CONTROL_OVERRUN: Faults = Faults(1 << 5);

    /// Whether no flag is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
    /// Whether every flag of `other` is set in `self`.
    pub const fn contains(self, other: Faults) -> bool {
        self.0 & other.0 == other.0
    }
    /// The union of two sets of flags.
    pub const fn union(self, other: Faults) -> Faults {
        Faults(self.0 | other.0)
    }
    /// `self` without the flags of `other`.
    pub const fn without(self, other: Faults) -> Faults {
        Faults(self.0 & !other.0)
    }
}

/// Why the robot refused a command.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NackReason {
    /// The host's protocol version is not the robot's.
    VersionMismatch {
        /// The robot's version.
        robot: u16,
    },
    /// No accepted `Hello` yet in this session.
    NoSession,
    /// A value is not finite or outside the robot's limits.
    OutOfRange,
    /// Faults are latched; clear them first.
    Faulted(Faults),
}

/// How a motion command ended.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// It did what was asked.
    Completed,
    /// The bumper closed (for commands that stop on contact).
    Contact,
    /// Another command replaced it, or `Stop`.
    Aborted,
    /// A fault stopped it.
    Fault(Faults),
    /// Its time ran out (velocity commands; primitives that took far longer than planned).
    Timeout,
}

/// What the robot is doing.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// Standing still, motors off.
    Idle,
    /// Following a velocity command.
    Velocity,
    /// Executing a move.
    Move,
    /// Executing a spin.
    Spin,
    /// Advancing until contact.
    Advance,
    /// Braking to a stop.
    Braking,
    /// Stopped by a latched fault.
    Faulted,
}

/// Robot state, sent at the telemetry rate.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Telemetry {
    /// Robot time, µs.
    pub time_us: u64,
    /// Odometry pose.
    pub pose: Pose,
    /// Measured wheel speeds [left, right], rad/s.
    pub wheel_speed: [f32; 2],
    /// Bumper switches, debounced, one bit each (bit 0 = left, bit 1 = centre, bit 2 = right).
    pub bumper: u8,
    /// What the robot is doing.
    pub mode: Mode,
    /// Latched faults.
    pub faults: Faults,
    /// Sequence number of the running motion command.
    pub active: Option<u16>,
    /// The last motion command that ended, and how: lets the host recover a lost `Done`.
    pub last_done: Option<(u16, Outcome)>,
}

/// A motion command ended.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Done {
    /// The command's sequence number.
    pub seq: u16,
    /// How it ended.
    pub outcome: Outcome,
    /// Odometry pose when it ended.
    pub pose: Pose,
    /// Robot time when it ended, µs.
    pub time_us: u64,
}

/// The bumper closed.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ContactEvent {
    /// Robot time of the (debounced) closing edge, µs.
    pub time_us: u64,
    /// Switches closed, as in [`Telemetry::bumper`].
    pub bumper: u8,
    /// Odometry pose at contact.
    pub pose: Pose,
}

/// Everything the robot sends.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RobotMsg {
    /// Answer to `Hello`. Variant 0 forever.
    HelloReply(HelloReply),
    /// Command `seq` accepted.
    Ack {
        /// The command's sequence number.
        seq: u16,
    },
    /// Command `seq` refused.
    Nack {
        /// The command's sequence number.
        seq: u16,
        /// Why.
        reason: NackReason,
    },
    /// A motion command ended.
    Done(Done),
    /// Periodic state.
    Telemetry(Telemetry),
    /// The bumper closed.
    Contact(ContactEvent),
}

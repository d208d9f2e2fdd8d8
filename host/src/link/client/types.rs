//! The link client's vocabulary: host time, options, events, counters, and how commands,
//! the handshake and motions end.

use std::time::Duration;

use pushbot_protocol::{ContactEvent, Done, HelloReply, NackReason, PROTOCOL_VERSION, Telemetry};

/// A point of the driver's monotonic host time, µs since the driver's epoch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct HostTime(pub u64);

impl HostTime {
    /// `us` microseconds after the epoch.
    pub const fn from_micros(us: u64) -> HostTime {
        HostTime(us)
    }

    /// Microseconds since the epoch.
    pub const fn as_micros(self) -> u64 {
        self.0
    }

    /// Time from `earlier` to `self` (zero if `earlier` is later).
    pub fn since(self, earlier: HostTime) -> Duration {
        Duration::from_micros(self.0.saturating_sub(earlier.0))
    }

    /// The time `d` after `self`.
    pub fn after(self, d: Duration) -> HostTime {
        HostTime(
            self.0
                .saturating_add(u64::try_from(d.as_micros()).unwrap_or(u64::MAX)),
        )
    }
}

/// Settings of the client.
#[derive(Debug, Clone, PartialEq)]
pub struct ClientOptions {
    /// How long to wait for an `Ack`/`Nack` before resending, host time.
    pub ack_timeout: Duration,
    /// How many times a command is sent before giving up.
    pub attempts: u32,
    /// How long the handshake keeps resending `Hello` (every `ack_timeout`), host time.
    pub hello_timeout: Duration,
    /// No byte at all from the robot for this long (host time) means the link is dead.
    pub dead_link_timeout: Duration,
    /// The robot's link watchdog the heartbeats are paced for, ms of robot time.
    pub watchdog_ms: u16,
    /// The protocol version offered in the handshake.
    pub protocol_version: u16,
    /// The first sequence number to use.
    pub first_seq: u16,
}

impl Default for ClientOptions {
    fn default() -> Self {
        ClientOptions {
            ack_timeout: Duration::from_millis(150),
            attempts: 5,
            hello_timeout: Duration::from_millis(1500),
            dead_link_timeout: Duration::from_secs(3),
            watchdog_ms: 200,
            protocol_version: PROTOCOL_VERSION,
            first_seq: 0,
        }
    }
}

/// Something the client learned, in order, from [`super::Client::poll_event`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    /// Periodic state.
    Telemetry(Telemetry),
    /// The bumper closed.
    Contact(ContactEvent),
    /// A motion ended; `recovered` when its `Done` frame was lost and the end was read from
    /// the telemetry.
    Done {
        /// The end.
        done: Done,
        /// Read from the telemetry.
        recovered: bool,
    },
    /// The command `seq` was accepted.
    Ack {
        /// Its sequence number.
        seq: u16,
    },
    /// The command `seq` was refused.
    Nack {
        /// Its sequence number.
        seq: u16,
        /// Why.
        reason: NackReason,
    },
    /// The handshake finished: both sides speak this protocol version.
    Connected(HelloReply),
    /// The handshake was refused: the robot speaks another version, or refused ours.
    VersionMismatch {
        /// The version offered.
        host: u16,
        /// The robot's version.
        robot: u16,
    },
    /// The command (or `Hello`) `seq` went unanswered `attempts` times; the client gave up.
    GaveUp {
        /// Its sequence number.
        seq: u16,
        /// How many times it was sent.
        attempts: u32,
    },
    /// The motion `seq` did not end within its budget of robot time.
    MotionTimedOut {
        /// Its sequence number.
        seq: u16,
        /// Its budget, µs of robot time.
        budget_us: u64,
    },
    /// Nothing arrived for the dead-link time.
    LinkDead {
        /// How long nothing arrived.
        silent: Duration,
    },
}

/// Something the robot reported, as delivered to subscribers of a driver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RobotEvent {
    /// Periodic state.
    Telemetry(Telemetry),
    /// The bumper closed.
    Contact(ContactEvent),
    /// A motion command ended.
    Done(Done),
}

impl Event {
    /// The robot's report in this event, for subscribers.
    pub fn robot_event(&self) -> Option<RobotEvent> {
        match *self {
            Event::Telemetry(t) => Some(RobotEvent::Telemetry(t)),
            Event::Contact(c) => Some(RobotEvent::Contact(c)),
            Event::Done {
                done,
                recovered: false,
            } => Some(RobotEvent::Done(done)),
            _ => None,
        }
    }
}

/// Counters of the link, for diagnostics and tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct LinkStats {
    /// Bytes received.
    pub bytes_received: u64,
    /// Frames received that decoded to a message.
    pub frames_ok: u64,
    /// Frames received that were rejected (CRC, COBS, not a message, overflow).
    pub frames_rejected: u64,
    /// Frames sent (commands, retries, heartbeats).
    pub frames_sent: u64,
    /// Heartbeats sent.
    pub heartbeats_sent: u64,
    /// Command frames sent again because no answer came in time.
    pub retries: u64,
}

impl std::ops::AddAssign for LinkStats {
    /// Counters of two sessions of one link, summed.
    fn add_assign(&mut self, o: LinkStats) {
        self.bytes_received += o.bytes_received;
        self.frames_ok += o.frames_ok;
        self.frames_rejected += o.frames_rejected;
        self.frames_sent += o.frames_sent;
        self.heartbeats_sent += o.heartbeats_sent;
        self.retries += o.retries;
    }
}

/// How a command was answered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Answer {
    /// Accepted; robot time of the latest telemetry then, µs.
    Ack {
        /// Robot time at the acknowledgement (latest telemetry), µs.
        at_us: Option<u64>,
    },
    /// Refused.
    Nack(NackReason),
    /// Withdrawn unanswered by [`super::Client::emergency_stop`], which went ahead of it.
    Preempted,
    /// Never answered.
    GaveUp {
        /// How many times it was sent.
        attempts: u32,
    },
}

/// How the handshake ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Handshake {
    /// Both sides speak the same version.
    Connected(HelloReply),
    /// Versions differ (or the robot refused ours).
    VersionMismatch {
        /// The version offered.
        host: u16,
        /// The robot's version.
        robot: u16,
    },
    /// No reply.
    NoAnswer {
        /// How many times `Hello` was sent in the last round.
        attempts: u32,
        /// What arrived instead, while the host waited.
        heard: Heard,
    },
}

/// What arrived on the line while a `Hello` went unanswered: what tells a dead line from one
/// that talks, but not pushbot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Heard {
    /// Not one byte.
    Nothing,
    /// Only zero bytes: a line held low (a break), or a device sending at another baud rate.
    Zeros {
        /// How many.
        bytes: u64,
    },
    /// The host's own frames came back: a loopback, or a terminal echoing what it is sent.
    Echo {
        /// How many bytes arrived in all.
        bytes: u64,
    },
    /// Bytes of which no frame was a pushbot frame: a wrong baud rate, another device, another
    /// program on the port.
    Garbage {
        /// How many bytes arrived.
        bytes: u64,
        /// Over how long, s of host time.
        secs: f64,
    },
    /// Valid pushbot frames, but no reply to `Hello`.
    Frames {
        /// How many frames.
        frames: u64,
    },
}

/// How a motion ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotionEnd {
    /// It ended with this `Done` (read from the telemetry when `recovered`).
    Done {
        /// The end.
        done: Done,
        /// Whether the `Done` frame was lost and the end read from the telemetry.
        recovered: bool,
        /// Robot time when it was acknowledged (or first seen running), µs.
        started_us: Option<u64>,
    },
    /// It did not end within its budget of robot time.
    TimedOut {
        /// The budget, µs.
        budget_us: u64,
    },
}

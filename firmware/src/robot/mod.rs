//! The core: ties the parts together behind the sans-IO contract of the crate docs.
//!
//! Each [`Core::step`] runs, in order: loop timing (overrun), encoders (plausibility,
//! odometry, wheel speeds), bumper (debounce, contact events), link watchdog, stall detection,
//! then — unless a fault is latched, which cuts the motors — the running primitive's reference
//! and the wheel-speed controllers, and finally telemetry when due.
//!
//! The parts: this file holds the [`Core`] and its inputs and outputs; `step` is the control
//! step, `query` what a board or host may read, `motion` the running primitive and the
//! fault and telemetry internals, `commands` the host's commands.

mod commands;
mod motion;
mod query;
mod step;

use pushbot_protocol::{Faults, Outcome, WheelGains};

use crate::bumper::Debouncer;
use crate::link::{Link, Received};
use crate::odometry::Odometry;
use crate::params::{Limits, RobotParams};
use crate::profile::Profile;
use crate::safety::{StallDetector, Watchdog};
use crate::wheel::{SpeedEstimator, WheelController};

/// `ENCODER` and `CONTROL_OVERRUN` stay latched through `ClearFaults` while their event
/// happened less than this long ago, µs.
pub const FAULT_QUIET_US: u64 = 100_000;

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

/// A running motion primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Velocity { v: f32, omega: f32 },
    Move { cruise: f32, stop_on_contact: bool },
    Spin { rate: f32 },
    Advance { cruise: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Active {
    seq: u16,
    kind: Kind,
    /// Velocity: its timeout; others: the "far longer than planned" limit.
    deadline_us: u64,
    /// Move, advance: distance (m); spin: angle (rad), from where it started.
    goal: f32,
    settle_since_us: Option<u64>,
}

/// The robot: feed it link bytes, time and sensor readings; it returns duties and bytes to send.
///
/// Policies the protocol leaves to the robot:
/// * `ClearFaults` clears `EMERGENCY_STOP` (the command is the host's release of its own stop),
///   `LINK_LOST` (the frame proves the link), `STALL_*` (the motors are off, so nothing is being
///   driven into a stall); it keeps `ENCODER` and `CONTROL_OVERRUN` while such an event happened
///   within the last [`FAULT_QUIET_US`].
/// * A stop-on-contact `Move` or an `AdvanceUntilContact` that starts with the bumper already
///   (debounced) closed ends `Done(Contact)` at once.
/// * A retry is a frame repeating the last command's sequence number *and* command; the
///   cached answer is sent again and nothing is executed.
/// * `CONTROL_OVERRUN` latches only while the motors are driven (a late step at rest harms
///   nothing).
/// * A `Hello` with another protocol version is answered `HelloReply { accepted: false }` and
///   leaves an existing session as it is.
/// * Any frame that decodes (CRC good) feeds the watchdog, heartbeats and refused commands
///   included. Telemetry and contact events are sent only within a session.
/// * A contact event carries the time and pose of the *debounced* closing edge (the raw edge
///   plus the debounce time), once per closing edge of any switch, whatever is running.
/// * `Move`/`Spin`/`AdvanceUntilContact` complete when the reference profile has arrived and
///   the *measured* progress (from the encoders, since the command started) is within
///   `distance_tolerance`/`angle_tolerance`; if the wheels lag by more after `settle_ms`, the
///   remainder is planned again. They end `Timeout` after `timeout_factor` × planned time +
///   `timeout_slack_ms`, and a velocity command ends `Timeout` at its own timeout; both then
///   brake (mode `Braking`) to rest.
/// * Every fault cuts the duty to 0 at once (no braking ramp) and ends the running primitive
///   with `Done(Fault(the new flags))`. `Stop` with nothing running is simply acknowledged.
pub struct Core {
    params: RobotParams,
    limits: Limits,
    gains: WheelGains,
    watchdog_ms: u16,
    telemetry_hz: u16,

    link: Link,
    watchdog: Watchdog,
    odometry: Odometry,
    wheels: [WheelController; 2],
    speed: [SpeedEstimator; 2],
    stall: [StallDetector; 2],
    bumper: Debouncer,

    faults: Faults,
    encoder_fault_us: Option<u64>,
    overrun_us: Option<u64>,

    active: Option<Active>,
    braking: bool,
    v_ref: f32,
    w_ref: f32,
    profile: Profile,
    /// Measured progress of the running primitive toward `Active::goal` (m or rad).
    progress: f32,
    last_done: Option<(u16, Outcome)>,

    last_step_us: Option<u64>,
    last_encoder: Option<[i32; 2]>,
    duty: [f32; 2],
    measured: [f32; 2],
    next_telemetry_us: u64,
}

/// Whether `x` is finite and within `lo..=hi`.
fn finite_in(x: f32, lo: f32, hi: f32) -> bool {
    x.is_finite() && x >= lo && x <= hi
}

impl Core {
    /// A robot at rest, without a session, at pose zero.
    pub fn new(params: RobotParams) -> Self {
        let cpr = params.geometry.encoder_cpr;
        Core {
            params,
            limits: params.limits,
            gains: params.gains,
            watchdog_ms: params.watchdog_ms,
            telemetry_hz: params.telemetry_hz,
            link: Link::new(),
            watchdog: Watchdog::new(0),
            odometry: Odometry::new(&params.geometry),
            wheels: [WheelController::new(); 2],
            speed: [SpeedEstimator::new(cpr); 2],
            stall: [StallDetector::new(); 2],
            bumper: Debouncer::new(params.debounce_us),
            faults: Faults::NONE,
            encoder_fault_us: None,
            overrun_us: None,
            active: None,
            braking: false,
            v_ref: 0.0,
            w_ref: 0.0,
            profile: Profile::default(),
            progress: 0.0,
            last_done: None,
            last_step_us: None,
            last_encoder: None,
            duty: [0.0; 2],
            measured: [0.0; 2],
            next_telemetry_us: 0,
        }
    }

    /// Control period, µs: call [`Core::step`] this often (`1e6 / control_hz`).
    pub fn tick_period_us(&self) -> u32 {
        self.params.tick_period_us()
    }

    /// Hand over bytes received from the link, at any time.
    pub fn receive(&mut self, now_us: u64, bytes: &[u8]) {
        for &b in bytes {
            let Some(r) = self.link.push(b) else {
                continue;
            };
            self.watchdog.feed(now_us);
            if let Received::Command(frame) = r {
                let answer = self.execute(now_us, frame);
                self.link.answer(frame, answer);
            }
        }
    }
}

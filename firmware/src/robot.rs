//! The core: ties the parts together behind the sans-IO contract of the crate docs.
//!
//! Each [`Core::step`] runs, in order: loop timing (overrun), encoders (plausibility,
//! odometry, wheel speeds), bumper (debounce, contact events), link watchdog, stall detection,
//! then — unless a fault is latched, which cuts the motors — the running primitive's reference
//! and the wheel-speed controllers, and finally telemetry when due.

use pushbot_protocol::{
    Command, ConfigUpdate, ContactEvent, Done, Faults, HelloReply, HostFrame, Mode, NackReason,
    Outcome, PROTOCOL_VERSION, Pose, RobotMsg, Telemetry, WheelGains,
};

use crate::bumper::Debouncer;
use crate::link::{Link, Received};
use crate::odometry::{Odometry, count_delta, wrap_angle};
use crate::params::{Limits, RobotParams};
use crate::profile::{Profile, ramp, trapezoid_time};
use crate::safety::{
    StallDetector, StallLimits, Watchdog, encoder_jump, max_plausible_counts, overrun,
};
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

    /// Run one control step at robot time `now_us`; returns the motor duties.
    pub fn step(&mut self, now_us: u64, inputs: &Inputs) -> Outputs {
        let period = self.tick_period_us();
        let dt_us = self.last_step_us.map_or(0, |t| now_us.saturating_sub(t));
        let first = self.last_step_us.is_none();
        self.last_step_us = Some(self.last_step_us.map_or(now_us, |t| t.max(now_us)));
        let dt = dt_us as f32 * 1e-6;

        if !first && self.driving() && overrun(dt_us, period, self.params.overrun_periods) {
            warn!("control overrun: {} us between steps", dt_us);
            self.overrun_us = Some(now_us);
            self.latch(now_us, Faults::CONTROL_OVERRUN);
        }

        // Encoders.
        let mut delta = [0i32; 2];
        if let Some(prev) = self.last_encoder {
            delta = [
                count_delta(inputs.encoder[0], prev[0]),
                count_delta(inputs.encoder[1], prev[1]),
            ];
        }
        self.last_encoder = Some(inputs.encoder);
        let max_counts = max_plausible_counts(
            dt_us,
            self.params.max_wheel_speed,
            self.params.geometry.encoder_cpr,
        );
        if delta.iter().any(|&d| encoder_jump(d, max_counts)) {
            warn!("implausible encoder step {} {}", delta[0], delta[1]);
            delta = delta.map(|d| if encoder_jump(d, max_counts) { 0 } else { d });
            self.encoder_fault_us = Some(now_us);
            self.latch(now_us, Faults::ENCODER);
        }
        self.odometry.update(delta);
        if let Some(a) = self.active {
            let mpc = self.odometry.metres_per_count();
            let (dl, dr) = (delta[0] as f32 * mpc, delta[1] as f32 * mpc);
            self.progress += match a.kind {
                Kind::Spin { .. } => (dr - dl) / self.params.geometry.wheel_base.max(1e-6),
                _ => 0.5 * (dl + dr),
            };
        }
        if dt_us > 0 || first {
            for ((m, est), d) in self.measured.iter_mut().zip(&mut self.speed).zip(delta) {
                *m = est.update(now_us, d);
            }
        }

        // Bumper.
        if let Some(contact) = self.bumper.update(now_us, inputs.bumper) {
            info!("contact: bumper {}", contact.state);
            if self.link.session() {
                self.link.tx.push(RobotMsg::Contact(ContactEvent {
                    time_us: now_us,
                    bumper: contact.state,
                    pose: self.odometry.pose(),
                }));
            }
        }

        // Link watchdog.
        if self.link.session()
            && !self.faults.contains(Faults::LINK_LOST)
            && self.watchdog.expired(now_us, self.watchdog_ms)
        {
            warn!("link watchdog: no valid frame for {} ms", self.watchdog_ms);
            self.latch(now_us, Faults::LINK_LOST);
        }

        // Stall detection on the duty that drove the wheels since the last step.
        if dt_us > 0 {
            let limits = StallLimits {
                duty: self.params.stall_duty,
                speed: self.params.stall_speed,
                time_us: u64::from(self.params.stall_ms) * 1000,
            };
            let flags = [Faults::STALL_LEFT, Faults::STALL_RIGHT];
            let mut stalled = Faults::NONE;
            for (((det, duty), speed), flag) in self
                .stall
                .iter_mut()
                .zip(self.duty)
                .zip(self.measured)
                .zip(flags)
            {
                if det.update(now_us, duty, speed, &limits) {
                    stalled = stalled.union(flag);
                }
            }
            if !stalled.is_empty() {
                warn!("stall: {}", stalled.0);
                self.latch(now_us, stalled);
            }
        }

        if !self.faults.is_empty() {
            self.motors_off();
        } else {
            self.run_motion(now_us, dt);
            if self.driving() {
                let b2 = 0.5 * self.params.geometry.wheel_base;
                let r = self.params.geometry.wheel_radius.max(1e-6);
                let targets = [
                    (self.v_ref - self.w_ref * b2) / r,
                    (self.v_ref + self.w_ref * b2) / r,
                ];
                for i in 0..2 {
                    let dangle = delta[i] as f32 * self.speed[i].rad_per_count();
                    self.duty[i] = self.wheels[i].update(
                        &self.gains,
                        targets[i],
                        self.measured[i],
                        dangle,
                        dt,
                    );
                }
            } else {
                self.motors_off();
            }
        }

        self.send_telemetry(now_us);
        Outputs { duty: self.duty }
    }

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

    // ---- internals ----

    /// Whether the wheel controllers are running (a primitive, or braking).
    fn driving(&self) -> bool {
        self.active.is_some() || self.braking
    }

    fn motors_off(&mut self) {
        self.duty = [0.0; 2];
        self.v_ref = 0.0;
        self.w_ref = 0.0;
        self.braking = false;
        for w in &mut self.wheels {
            w.reset();
        }
    }

    /// End the running primitive, if any, with `outcome`.
    fn finish(&mut self, now_us: u64, outcome: Outcome) {
        if let Some(a) = self.active.take() {
            debug!("done seq {}", a.seq);
            self.last_done = Some((a.seq, outcome));
            self.link.tx.push(RobotMsg::Done(Done {
                seq: a.seq,
                outcome,
                pose: self.odometry.pose(),
                time_us: now_us,
            }));
        }
    }

    /// Latch `fault`: motors off at once, the running primitive ends `Fault`.
    fn latch(&mut self, now_us: u64, fault: Faults) {
        self.faults = self.faults.union(fault);
        self.finish(now_us, Outcome::Fault(fault));
        self.motors_off();
    }

    fn send_telemetry(&mut self, now_us: u64) {
        if !self.link.session() || self.telemetry_hz == 0 || now_us < self.next_telemetry_us {
            return;
        }
        let period = 1_000_000 / u64::from(self.telemetry_hz);
        let next = self.next_telemetry_us.saturating_add(period);
        self.next_telemetry_us = if next <= now_us {
            now_us.saturating_add(period)
        } else {
            next
        };
        let t = self.telemetry(now_us);
        self.link.tx.push(RobotMsg::Telemetry(t));
    }

    /// Advance the running primitive's reference by `dt` seconds.
    fn run_motion(&mut self, now_us: u64, dt: f32) {
        let lim = self.limits;
        let Some(mut a) = self.active else {
            if self.braking {
                self.v_ref = ramp(self.v_ref, 0.0, lim.max_accel * dt);
                self.w_ref = ramp(self.w_ref, 0.0, lim.max_alpha * dt);
                if self.v_ref == 0.0 && self.w_ref == 0.0 {
                    self.braking = false;
                }
            }
            return;
        };
        let tolerance = match a.kind {
            Kind::Velocity { v, omega } => {
                if now_us >= a.deadline_us {
                    self.finish(now_us, Outcome::Timeout);
                    self.braking = true;
                } else {
                    self.v_ref = ramp(self.v_ref, v, lim.max_accel * dt);
                    self.w_ref = ramp(self.w_ref, omega, lim.max_alpha * dt);
                }
                return;
            }
            Kind::Move { cruise, .. } | Kind::Advance { cruise } => {
                // Advancing is a straight move that always stops at contact.
                let stops_on_contact = matches!(
                    a.kind,
                    Kind::Advance { .. }
                        | Kind::Move {
                            stop_on_contact: true,
                            ..
                        }
                );
                if stops_on_contact && self.bumper.state() != 0 {
                    self.finish(now_us, Outcome::Contact);
                    self.motors_off();
                    return;
                }
                self.v_ref = self
                    .profile
                    .step(dt, cruise.min(lim.max_speed), lim.max_accel);
                self.w_ref = ramp(self.w_ref, 0.0, lim.max_alpha * dt);
                self.params.distance_tolerance
            }
            Kind::Spin { rate } => {
                self.w_ref = self
                    .profile
                    .step(dt, rate.min(lim.max_omega), lim.max_alpha);
                self.v_ref = ramp(self.v_ref, 0.0, lim.max_accel * dt);
                self.params.angle_tolerance
            }
        };
        if self.profile.done() && self.v_ref == 0.0 && self.w_ref == 0.0 {
            // The reference has arrived; the primitive completes when the measured progress
            // has too. If the wheels have not caught up within the settle time, plan a new
            // profile over what remains (the deadline bounds how often).
            let remaining = a.goal - self.progress;
            if libm::fabsf(remaining) <= tolerance {
                self.finish(now_us, Outcome::Completed);
                self.motors_off();
                return;
            }
            let since = *a.settle_since_us.get_or_insert(now_us);
            if now_us.saturating_sub(since) >= u64::from(self.params.settle_ms) * 1000 {
                debug!("seq {}: re-planning the remainder", a.seq);
                a.settle_since_us = None;
                self.profile = Profile::new(remaining, 0.0);
                for w in &mut self.wheels {
                    w.reset();
                }
            }
            self.active = Some(a);
        }
        if now_us >= a.deadline_us {
            warn!("primitive {} timed out", a.seq);
            self.finish(now_us, Outcome::Timeout);
            self.braking = true;
        }
    }

    /// Start a motion primitive (the running one ends `Aborted`).
    fn start(&mut self, now_us: u64, seq: u16, kind: Kind, goal: f32, planned_s: f32) {
        self.finish(now_us, Outcome::Aborted);
        let deadline_us = match kind {
            Kind::Velocity { .. } => now_us.saturating_add((planned_s * 1e6) as u64),
            _ => {
                let limit_s = self.params.timeout_factor * planned_s;
                now_us
                    .saturating_add((limit_s * 1e6) as u64)
                    .saturating_add(u64::from(self.params.timeout_slack_ms) * 1000)
            }
        };
        self.profile = match kind {
            Kind::Spin { .. } => Profile::new(goal, self.w_ref),
            _ => Profile::new(goal, self.v_ref),
        };
        self.braking = false;
        self.progress = 0.0;
        self.active = Some(Active {
            seq,
            kind,
            deadline_us,
            goal,
            settle_since_us: None,
        });
        info!("start seq {}", seq);
    }

    /// Execute a new command; returns its answer.
    fn execute(&mut self, now_us: u64, frame: HostFrame) -> RobotMsg {
        let seq = frame.seq;
        let ack = RobotMsg::Ack { seq };
        let nack = |reason| RobotMsg::Nack { seq, reason };
        let lim = self.limits;
        let p = self.params;
        if let Command::Hello { protocol } = frame.cmd {
            let accepted = protocol == PROTOCOL_VERSION;
            if accepted {
                info!("session opened");
                self.link.set_session(true);
                self.faults = self.faults.without(Faults::LINK_LOST);
                self.next_telemetry_us = now_us;
            } else {
                warn!("hello with protocol {} refused", protocol);
            }
            return RobotMsg::HelloReply(HelloReply {
                protocol: PROTOCOL_VERSION,
                accepted,
                firmware: p.firmware,
                geometry: p.geometry,
            });
        }
        if !self.link.session() {
            return nack(NackReason::NoSession);
        }
        let motion_ok = |valid: bool, faults: Faults| {
            if !valid {
                Some(nack(NackReason::OutOfRange))
            } else if !faults.is_empty() {
                Some(nack(NackReason::Faulted(faults)))
            } else {
                None
            }
        };
        match frame.cmd {
            Command::Hello { .. } | Command::Heartbeat => ack,
            Command::Velocity {
                v,
                omega,
                timeout_ms,
            } => {
                let valid = finite_in(v, -lim.max_speed, lim.max_speed)
                    && finite_in(omega, -lim.max_omega, lim.max_omega)
                    && timeout_ms > 0;
                if let Some(n) = motion_ok(valid, self.faults) {
                    return n;
                }
                let kind = Kind::Velocity { v, omega };
                self.start(now_us, seq, kind, 0.0, f32::from(timeout_ms) * 1e-3);
                ack
            }
            Command::Move {
                distance,
                speed,
                stop_on_contact,
            } => {
                let valid = finite_in(distance, -p.max_distance, p.max_distance)
                    && finite_in(speed, 0.0, lim.max_speed)
                    && speed > 0.0;
                if let Some(n) = motion_ok(valid, self.faults) {
                    return n;
                }
                let kind = Kind::Move {
                    cruise: speed,
                    stop_on_contact,
                };
                let t = trapezoid_time(distance, speed, lim.max_accel);
                self.start(now_us, seq, kind, distance, t);
                ack
            }
            Command::Spin { angle, rate } => {
                let valid = finite_in(angle, -p.max_angle, p.max_angle)
                    && finite_in(rate, 0.0, lim.max_omega)
                    && rate > 0.0;
                if let Some(n) = motion_ok(valid, self.faults) {
                    return n;
                }
                let t = trapezoid_time(angle, rate, lim.max_alpha);
                self.start(now_us, seq, Kind::Spin { rate }, angle, t);
                ack
            }
            Command::AdvanceUntilContact {
                max_distance,
                speed,
            } => {
                let valid = finite_in(max_distance, 0.0, p.max_distance)
                    && max_distance > 0.0
                    && finite_in(speed, 0.0, lim.max_speed)
                    && speed > 0.0;
                if let Some(n) = motion_ok(valid, self.faults) {
                    return n;
                }
                let t = trapezoid_time(max_distance, speed, lim.max_accel);
                let kind = Kind::Advance { cruise: speed };
                self.start(now_us, seq, kind, max_distance, t);
                ack
            }
            Command::Stop => {
                let was_running = self.active.is_some();
                self.finish(now_us, Outcome::Aborted);
                if self.faults.is_empty() && (was_running || self.braking) {
                    self.braking = true;
                }
                ack
            }
            Command::EmergencyStop => {
                warn!("emergency stop");
                self.latch(now_us, Faults::EMERGENCY_STOP);
                ack
            }
            Command::ClearFaults => {
                self.clear_faults(now_us);
                ack
            }
            Command::Configure(update) => {
                if self.configure(now_us, &update) {
                    ack
                } else {
                    nack(NackReason::OutOfRange)
                }
            }
            Command::ResetOdometry(pose) => {
                let valid = finite_in(pose.x, -1e4, 1e4)
                    && finite_in(pose.y, -1e4, 1e4)
                    && finite_in(
                        pose.theta,
                        -2.0 * core::f32::consts::PI,
                        2.0 * core::f32::consts::PI,
                    );
                if !valid {
                    return nack(NackReason::OutOfRange);
                }
                self.odometry.reset(Pose {
                    theta: wrap_angle(pose.theta),
                    ..pose
                });
                ack
            }
        }
    }

    fn clear_faults(&mut self, now_us: u64) {
        if self.faults.is_empty() {
            return;
        }
        let recent = |t: Option<u64>| t.is_some_and(|t| now_us.saturating_sub(t) < FAULT_QUIET_US);
        let mut keep = Faults::NONE;
        if self.faults.contains(Faults::ENCODER) && recent(self.encoder_fault_us) {
            keep = keep.union(Faults::ENCODER);
        }
        if self.faults.contains(Faults::CONTROL_OVERRUN) && recent(self.overrun_us) {
            keep = keep.union(Faults::CONTROL_OVERRUN);
        }
        self.faults = keep;
        for s in &mut self.stall {
            s.reset();
        }
        self.motors_off();
    }

    /// Apply a configuration update if every given value is within the hard bounds; all or
    /// nothing.
    fn configure(&mut self, now_us: u64, u: &ConfigUpdate) -> bool {
        let p = &self.params;
        let h = p.hard_limits;
        let pos = |x: Option<f32>, hi: f32| x.is_none_or(|x| finite_in(x, 0.0, hi) && x > 0.0);
        let gain_ok = |x: f32| finite_in(x, 0.0, p.max_gain);
        let valid = u
            .wheel_gains
            .is_none_or(|g| gain_ok(g.kp) && gain_ok(g.ki) && gain_ok(g.kff))
            && pos(u.max_speed, h.max_speed)
            && pos(u.max_accel, h.max_accel)
            && pos(u.max_omega, h.max_omega)
            && pos(u.max_alpha, h.max_alpha)
            && u.watchdog_ms
                .is_none_or(|w| (p.min_watchdog_ms..=p.max_watchdog_ms).contains(&w))
            && u.telemetry_hz.is_none_or(|t| t <= p.max_telemetry_hz);
        if !valid {
            return false;
        }
        if let Some(g) = u.wheel_gains {
            self.gains = g;
        }
        let l = &mut self.limits;
        l.max_speed = u.max_speed.unwrap_or(l.max_speed);
        l.max_accel = u.max_accel.unwrap_or(l.max_accel);
        l.max_omega = u.max_omega.unwrap_or(l.max_omega);
        l.max_alpha = u.max_alpha.unwrap_or(l.max_alpha);
        if let Some(w) = u.watchdog_ms {
            self.watchdog_ms = w;
        }
        if let Some(t) = u.telemetry_hz {
            self.telemetry_hz = t;
            self.next_telemetry_us = now_us;
        }
        true
    }
}

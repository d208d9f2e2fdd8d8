//! The typed robot API: connect (handshake), motion primitives that wait for their `Done`,
//! settings, faults, telemetry, reconnect.
//!
//! Sequencing follows the protocol's rules (`pushbot_protocol` crate docs): one command in
//! flight at a time; a command is resent with the *same* sequence number after a short
//! wall-clock timeout, a bounded number of times, so the robot answers again without executing
//! it twice; the next command takes the next number. Waiting for a `Done` is bounded in robot
//! time (from the telemetry), never by sleeping on the wall clock; only a dead link (no bytes
//! at all for [`LinkOptions::dead_link_timeout`]) is detected on the wall clock.

use std::sync::mpsc;
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use pushbot_protocol::{
    Command, ConfigUpdate, ContactEvent, Done, Faults, FirmwareVersion, Geometry, HelloReply,
    HostFrame, Mode, NackReason, Outcome, PROTOCOL_VERSION, Pose, Telemetry,
};

use super::error::{LinkError, Refusal};
use super::session::{Answer, LinkStats, RobotEvent, Session};

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
    /// default is 200; [`Robot::configure`] keeps this up to date).
    pub watchdog_ms: u16,
    /// How long [`Robot::reconnect`] keeps trying, wall time.
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
            hello_timeout: Duration::from_secs(2),
            dead_link_timeout: Duration::from_secs(3),
            watchdog_ms: 200,
            reconnect_timeout: Duration::from_secs(5),
            protocol_version_override: None,
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

/// A motion command the robot accepted and has not finished: pass it to [`Robot::wait`].
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

/// A connection to a robot running pushbot firmware (or the simulator), on a serial port.
pub struct Robot {
    path: String,
    opts: LinkOptions,
    session: Session,
    hello: HelloReply,
    /// The next sequence number; holding the lock is holding the right to have a command in
    /// flight.
    next_seq: Mutex<u16>,
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

fn check_finite(what: &str, values: &[(&str, f32)]) -> Result<(), LinkError> {
    for (name, v) in values {
        if !v.is_finite() {
            return Err(LinkError::InvalidArgument(format!(
                "{what}: {name} must be a finite number, got {v}"
            )));
        }
    }
    Ok(())
}

fn check_positive(what: &str, name: &str, v: f32) -> Result<(), LinkError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(LinkError::InvalidArgument(format!(
            "{what}: {name} must be positive, got {v}"
        )))
    }
}

impl Robot {
    /// Open the serial port at `path` and shake hands; a robot with another protocol version
    /// is refused ([`LinkError::VersionMismatch`]).
    pub fn connect(path: &str, opts: LinkOptions) -> Result<Robot, LinkError> {
        let session = Session::open(path, opts.watchdog_ms, opts.dead_link_timeout)?;
        // Start somewhere unpredictable: a robot still holding the last sequence number of an
        // earlier session must not take our first command for a retry.
        let first_seq: u16 = rand::random();
        let mut robot = Robot {
            path: path.to_string(),
            opts,
            session,
            hello: placeholder_hello(),
            next_seq: Mutex::new(first_seq),
        };
        robot.hello = robot.handshake()?;
        Ok(robot)
    }

    /// The port's path.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The robot's answer to the handshake.
    pub fn hello(&self) -> &HelloReply {
        &self.hello
    }

    fn seq_lock(&self) -> MutexGuard<'_, u16> {
        self.next_seq.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn handshake(&self) -> Result<HelloReply, LinkError> {
        let offered = self
            .opts
            .protocol_version_override
            .unwrap_or(PROTOCOL_VERSION);
        let shared = &self.session.shared;
        let per_attempt = self.opts.ack_timeout.max(Duration::from_millis(1));
        let attempts = self
            .opts
            .attempts
            .max((self.opts.hello_timeout.as_millis() / per_attempt.as_millis()) as u32);
        let mut next = self.seq_lock();
        // A collision with the robot's last sequence number shows as an Ack/Nack instead of a
        // HelloReply: then try again with the next number.
        for _ in 0..3 {
            let seq = *next;
            *next = seq.wrapping_add(1);
            {
                let mut st = shared.state();
                st.hello = None;
                st.foreign_hello = None;
                st.answers.clear();
                st.heartbeat_seq = seq;
            }
            let mut collided = false;
            for attempt in 0..attempts {
                if attempt > 0 {
                    shared.state().stats.retries += 1;
                }
                shared.send(&HostFrame {
                    seq,
                    cmd: Command::Hello { protocol: offered },
                })?;
                let deadline = Instant::now() + self.opts.ack_timeout;
                let got = shared.wait_until(Some(deadline), |st| {
                    if let Some(h) = st.hello.take() {
                        return Some(Ok(Ok(h)));
                    }
                    if let Some(robot) = st.foreign_hello.take() {
                        return Some(Err(self.mismatch(offered, robot)));
                    }
                    st.answers.remove(&seq).map(|a| Ok(Err(a)))
                })?;
                match got {
                    None => continue,
                    Some(Ok(h)) => {
                        if !h.accepted || h.protocol != offered || h.protocol != PROTOCOL_VERSION {
                            return Err(self.mismatch(offered, h.protocol));
                        }
                        return Ok(h);
                    }
                    Some(Err(Answer::Nack(NackReason::VersionMismatch { robot }))) => {
                        return Err(self.mismatch(offered, robot));
                    }
                    Some(Err(_)) => {
                        collided = true;
                        break;
                    }
                }
            }
            if !collided {
                break;
            }
        }
        Err(LinkError::NoAnswer {
            path: self.path.clone(),
            what: "Hello",
            attempts,
        })
    }

    fn mismatch(&self, host: u16, robot: u16) -> LinkError {
        LinkError::VersionMismatch {
            path: self.path.clone(),
            host,
            robot,
        }
    }

    /// Send a command and wait for its answer, resending it with the same sequence number a
    /// bounded number of times. A `Nack` becomes [`LinkError::Refused`].
    fn request(&self, cmd: Command) -> Result<(u16, Option<u64>), LinkError> {
        let what = command_name(&cmd);
        let shared = &self.session.shared;
        let mut next = self.seq_lock();
        let seq = *next;
        *next = seq.wrapping_add(1);
        {
            let mut st = shared.state();
            st.answers.clear();
            st.heartbeat_seq = seq;
        }
        for attempt in 0..self.opts.attempts {
            if attempt > 0 {
                tracing::debug!("no answer to {what} #{seq}; resending");
                shared.state().stats.retries += 1;
            }
            shared.send(&HostFrame { seq, cmd })?;
            let deadline = Instant::now() + self.opts.ack_timeout;
            let got = shared.wait_until(Some(deadline), |st| {
                st.answers
                    .remove(&seq)
                    .map(|a| Ok((a, st.telemetry.map(|t| t.time_us))))
            })?;
            match got {
                None => continue,
                Some((Answer::Ack, at)) => return Ok((seq, at)),
                Some((Answer::Nack(reason), _)) => {
                    return Err(LinkError::Refused {
                        what,
                        reason: Refusal(reason),
                    });
                }
            }
        }
        Err(LinkError::NoAnswer {
            path: self.path.clone(),
            what,
            attempts: self.opts.attempts,
        })
    }

    /// Send a motion command (`Velocity`, `Move`, `Spin`, `AdvanceUntilContact`) and return
    /// once the robot accepted it; [`Robot::wait`] then waits for its end.
    pub fn start(&self, cmd: Command) -> Result<Motion, LinkError> {
        let what = command_name(&cmd);
        let budget_us = motion_budget_us(&cmd)
            .ok_or_else(|| LinkError::InvalidArgument(format!("{what} is not a motion command")))?;
        let (seq, started_us) = self.request(cmd)?;
        Ok(Motion {
            seq,
            what,
            started_us,
            budget_us,
        })
    }

    /// Wait for a motion's `Done` (or read its outcome from the telemetry if the `Done` frame
    /// was lost). Bounded by the motion's budget of robot time; past it the host sends `Stop`
    /// and returns [`LinkError::DoneTimeout`].
    pub fn wait(&self, motion: &Motion) -> Result<DoneReport, LinkError> {
        let seq = motion.seq;
        let mut start = motion.started_us;
        let waited = self.session.shared.wait_until(None, |st| {
            let t = st.telemetry;
            let report = |d: Done, recovered: bool, start: Option<u64>| DoneReport {
                seq,
                outcome: d.outcome,
                pose: d.pose,
                time_us: d.time_us,
                duration_s: start.map_or(0.0, |s| d.time_us.saturating_sub(s) as f64 / 1e6),
                recovered,
            };
            if let Some(d) = st.dones.remove(&seq) {
                return Some(Ok(Ok(report(d, false, start))));
            }
            let t = t?;
            let s = *start.get_or_insert(t.time_us);
            if let Some((done_seq, outcome)) = t.last_done
                && done_seq == seq
                && t.active != Some(seq)
            {
                let d = Done {
                    seq,
                    outcome,
                    pose: t.pose,
                    time_us: t.time_us,
                };
                return Some(Ok(Ok(report(d, true, start))));
            }
            if t.time_us.saturating_sub(s) > motion.budget_us {
                return Some(Ok(Err(())));
            }
            None
        })?;
        match waited {
            Some(Ok(r)) => Ok(r),
            _ => {
                let _ = self.request(Command::Stop);
                Err(LinkError::DoneTimeout {
                    what: motion.what,
                    budget_s: motion.budget_us as f64 / 1e6,
                })
            }
        }
    }

    fn run(&self, cmd: Command) -> Result<DoneReport, LinkError> {
        let m = self.start(cmd)?;
        self.wait(&m)
    }

    /// Drive straight for `distance_m` (negative: backwards) at `speed` m/s; with
    /// `stop_on_contact`, end at the first bumper contact (`Outcome::Contact`).
    pub fn move_distance(
        &self,
        distance_m: f32,
        speed: f32,
        stop_on_contact: bool,
    ) -> Result<DoneReport, LinkError> {
        check_finite("move", &[("distance", distance_m)])?;
        check_positive("move", "speed", speed)?;
        self.run(Command::Move {
            distance: distance_m,
            speed,
            stop_on_contact,
        })
    }

    /// Turn on the spot by `angle_rad` (counter-clockwise positive) at `rate` rad/s.
    pub fn spin(&self, angle_rad: f32, rate: f32) -> Result<DoneReport, LinkError> {
        check_finite("spin", &[("angle", angle_rad)])?;
        check_positive("spin", "rate", rate)?;
        self.run(Command::Spin {
            angle: angle_rad,
            rate,
        })
    }

    /// Drive forward until the bumper closes (`Outcome::Contact`) or `max_distance_m` is
    /// covered (`Outcome::Completed`).
    pub fn advance_until_contact(
        &self,
        max_distance_m: f32,
        speed: f32,
    ) -> Result<DoneReport, LinkError> {
        check_positive("advance", "max_distance", max_distance_m)?;
        check_positive("advance", "speed", speed)?;
        self.run(Command::AdvanceUntilContact {
            max_distance: max_distance_m,
            speed,
        })
    }

    /// Start driving at body velocity (`v` m/s, `omega` rad/s) for at most `timeout` of robot
    /// time; returns once accepted. The motion ends `Timeout`, or `Aborted` when replaced.
    pub fn velocity(&self, v: f32, omega: f32, timeout: Duration) -> Result<Motion, LinkError> {
        check_finite("velocity", &[("v", v), ("omega", omega)])?;
        let timeout_ms = u16::try_from(timeout.as_millis()).map_err(|_| {
            LinkError::InvalidArgument(format!("velocity: timeout must be at most {} ms", u16::MAX))
        })?;
        self.start(Command::Velocity {
            v,
            omega,
            timeout_ms,
        })
    }

    /// Wait for telemetry newer than robot time `after_us` that satisfies `pred`, for at most
    /// `budget_us` of robot time.
    fn wait_telemetry_where(
        &self,
        after_us: Option<u64>,
        budget_us: u64,
        what: &'static str,
        pred: impl Fn(&Telemetry) -> bool,
    ) -> Result<Telemetry, LinkError> {
        let mut first: Option<u64> = None;
        let got = self.session.shared.wait_until(None, |st| {
            let t = st.telemetry?;
            if after_us.is_some_and(|a| t.time_us <= a) {
                return None;
            }
            if pred(&t) {
                return Some(Ok(Ok(t)));
            }
            let f = *first.get_or_insert(t.time_us);
            (t.time_us.saturating_sub(f) > budget_us).then_some(Ok(Err(())))
        })?;
        match got {
            Some(Ok(t)) => Ok(t),
            _ => Err(LinkError::DoneTimeout {
                what,
                budget_s: budget_us as f64 / 1e6,
            }),
        }
    }

    /// The next telemetry newer than robot time `after_us` (any, when `None`).
    pub fn wait_telemetry(&self, after_us: Option<u64>) -> Result<Telemetry, LinkError> {
        self.wait_telemetry_where(after_us, u64::MAX, "telemetry", |_| true)
    }

    /// Brake to a stop (a running primitive ends `Aborted`); returns the first telemetry that
    /// shows the robot standing (idle or faulted).
    pub fn stop(&self) -> Result<Telemetry, LinkError> {
        let (_, at) = self.request(Command::Stop)?;
        self.wait_telemetry_where(at, 10_000_000, "Stop", |t| {
            matches!(t.mode, Mode::Idle | Mode::Faulted)
        })
    }

    /// Cut the motors at once and latch `EMERGENCY_STOP`; returns the telemetry that shows it.
    pub fn emergency_stop(&self) -> Result<Telemetry, LinkError> {
        let (_, at) = self.request(Command::EmergencyStop)?;
        self.wait_telemetry_where(at, 2_000_000, "EmergencyStop", |t| {
            t.faults.contains(Faults::EMERGENCY_STOP)
        })
    }

    /// Clear the latched faults whose cause has gone; returns the faults still latched.
    pub fn clear_faults(&self) -> Result<Faults, LinkError> {
        let (_, at) = self.request(Command::ClearFaults)?;
        Ok(self.wait_telemetry(at)?.faults)
    }

    /// Change settings (fields left `None` stay). A new watchdog period re-paces heartbeats.
    pub fn configure(&self, update: ConfigUpdate) -> Result<(), LinkError> {
        if let Some(wd) = update.watchdog_ms {
            // Pace for the shorter of the old and new periods until the robot has it.
            let mut st = self.session.shared.state();
            st.watchdog_ms = st.watchdog_ms.min(wd);
        }
        self.request(Command::Configure(update))?;
        if let Some(wd) = update.watchdog_ms {
            self.session.shared.state().watchdog_ms = wd;
        }
        Ok(())
    }

    /// Set the odometry pose.
    pub fn reset_odometry(&self, pose: Pose) -> Result<(), LinkError> {
        check_finite(
            "reset odometry",
            &[("x", pose.x), ("y", pose.y), ("theta", pose.theta)],
        )?;
        self.request(Command::ResetOdometry(pose)).map(|_| ())
    }

    /// What the robot said in the handshake, with fresh telemetry.
    pub fn info(&self) -> Result<RobotInfo, LinkError> {
        let telemetry = match self.telemetry() {
            Some(t) => t,
            None => self.wait_telemetry(None)?,
        };
        Ok(RobotInfo {
            protocol: self.hello.protocol,
            firmware: self.hello.firmware,
            geometry: self.hello.geometry,
            telemetry,
        })
    }

    /// The latest telemetry, if any arrived.
    pub fn telemetry(&self) -> Option<Telemetry> {
        self.session.shared.state().telemetry
    }

    /// Every bumper contact reported since connecting.
    pub fn contacts(&self) -> Vec<ContactEvent> {
        self.session.shared.state().contacts.clone()
    }

    /// A receiver of every telemetry, contact and done from now on (the telemetry stream).
    pub fn subscribe(&self) -> mpsc::Receiver<RobotEvent> {
        self.session.shared.subscribe()
    }

    /// Link counters (frames, rejects, heartbeats, retries).
    pub fn stats(&self) -> LinkStats {
        self.session.shared.state().stats
    }

    /// Close the port and open it again (retrying for [`LinkOptions::reconnect_timeout`]),
    /// then shake hands anew, which clears a latched `LINK_LOST`.
    pub fn reconnect(&mut self) -> Result<(), LinkError> {
        self.session.close();
        let deadline = Instant::now() + self.opts.reconnect_timeout;
        let watchdog_ms = self.session.shared.state().watchdog_ms;
        loop {
            let attempt = Session::open(&self.path, watchdog_ms, self.opts.dead_link_timeout)
                .and_then(|s| {
                    self.session = s;
                    self.handshake()
                });
            match attempt {
                Ok(h) => {
                    self.hello = h;
                    return Ok(());
                }
                Err(e @ LinkError::VersionMismatch { .. }) => return Err(e),
                Err(e) if Instant::now() >= deadline => return Err(e),
                Err(e) => {
                    tracing::debug!("reconnect to {}: {e}; retrying", self.path);
                    // Waiting for a device to reappear is wall-clock business.
                    std::thread::sleep(Duration::from_millis(100));
                }
            }
        }
    }

    /// Test hook: stop (`true`) or resume heartbeats, as if the host went quiet. The robot's
    /// link watchdog should then stop the motors and latch `LINK_LOST`.
    pub fn pause_heartbeats(&self, paused: bool) {
        self.session.shared.pause_heartbeats(paused);
    }

    /// Diagnostic: write raw bytes to the port, bypassing framing (to inject garbage and
    /// corrupted frames in tests). Never needed to drive the robot.
    pub fn send_raw(&self, bytes: &[u8]) -> Result<(), LinkError> {
        self.session.shared.write_bytes(bytes)
    }
}

fn placeholder_hello() -> HelloReply {
    HelloReply {
        protocol: 0,
        accepted: false,
        firmware: FirmwareVersion {
            major: 0,
            minor: 0,
            patch: 0,
        },
        geometry: Geometry {
            wheel_base: 0.0,
            wheel_radius: 0.0,
            bumper_radius: 0.0,
            encoder_cpr: 0,
            control_hz: 0,
        },
    }
}

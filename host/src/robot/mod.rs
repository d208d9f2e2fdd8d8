//! The one robot interface: connect (handshake), motion primitives that wait for their
//! `Done`, settings, faults, telemetry and events, reconnect — written once over the link
//! client ([`crate::link::Client`]) and any of its drivers: the serial port
//! ([`crate::link::SerialDriver`]) or the in-process target (`crate::sim::inprocess`).
//!
//! Sequencing follows the protocol's rules (`pushbot_protocol` crate docs) and lives in the
//! client: one command in flight at a time here; a command is resent with the *same* sequence
//! number after `ack_timeout`, a bounded number of times, so the robot answers again without
//! executing it twice; the next command takes the next number. Waiting for a `Done` is bounded
//! in robot time (from the telemetry), never by sleeping on the wall clock; only a dead link
//! (no bytes at all for [`LinkOptions::dead_link_timeout`]) is detected on host time.
//!
//! ```no_run
//! use pushbot::robot::{LinkOptions, Robot};
//! let robot = Robot::connect("/dev/ttyACM0", LinkOptions::default())?;
//! let done = robot.move_distance(0.3, 0.1, false)?;
//! println!("{:?} at {:?}", done.outcome, done.pose);
//! # Ok::<(), pushbot::link::LinkError>(())
//! ```

mod recover;
mod types;

#[cfg(test)]
mod tests;

use std::sync::mpsc;
use std::sync::{Mutex, MutexGuard};
use std::time::Duration;

use pushbot_protocol::{
    Command, ConfigUpdate, ContactEvent, Faults, FirmwareVersion, Geometry, HelloReply, Mode,
    NackReason, Pose, Telemetry,
};

use crate::link::{
    Answer, Driver, Handshake, LinkError, LinkStats, MotionEnd, Refusal, RobotEvent, SerialDriver,
};

pub use recover::{Interrupted, Recovery, link_broke, outcome_name};
pub use types::{DoneReport, LinkOptions, Motion, RobotInfo, command_name, motion_budget_us};

/// A connection to a robot running pushbot firmware (or the simulator), over a driver of the
/// link client: a serial port by default.
pub struct Robot<D: Driver = SerialDriver> {
    opts: LinkOptions,
    driver: D,
    hello: HelloReply,
    /// Holding the lock is holding the right to have a command in flight.
    in_flight: Mutex<()>,
    /// Every recovery of the link so far ([`Robot::recover`]).
    recoveries: Mutex<Vec<Recovery>>,
    /// Link counters of the sessions before the current one.
    past_stats: LinkStats,
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

impl Robot<SerialDriver> {
    /// Open the serial port at `path` and shake hands; a robot with another protocol version
    /// is refused ([`LinkError::VersionMismatch`]).
    pub fn connect(path: &str, opts: LinkOptions) -> Result<Robot, LinkError> {
        // Start somewhere unpredictable: a robot still holding the last sequence number of an
        // earlier session must not take our first command for a retry.
        let first_seq: u16 = rand::random();
        let driver = SerialDriver::open(path, opts.client_options(first_seq))?;
        Robot::over(driver, opts)
    }
}

impl<D: Driver> Robot<D> {
    /// Shake hands over `driver` (whose client was made with `opts`).
    pub fn over(driver: D, opts: LinkOptions) -> Result<Robot<D>, LinkError> {
        let mut robot = Robot {
            opts,
            driver,
            hello: placeholder_hello(),
            in_flight: Mutex::new(()),
            recoveries: Mutex::new(Vec::new()),
            past_stats: LinkStats::default(),
        };
        robot.hello = robot.handshake()?;
        Ok(robot)
    }

    /// The port's path (the other end's name).
    pub fn path(&self) -> &str {
        self.driver.path()
    }

    /// The driver.
    pub fn driver(&self) -> &D {
        &self.driver
    }

    /// The robot's answer to the handshake.
    pub fn hello(&self) -> &HelloReply {
        &self.hello
    }

    fn lock(&self) -> MutexGuard<'_, ()> {
        self.in_flight.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn handshake(&self) -> Result<HelloReply, LinkError> {
        let _flight = self.lock();
        self.driver.with_client(|c, now| c.hello(now))?;
        let path = self.path().to_string();
        match self.driver.wait(|c, _| c.handshake())? {
            Handshake::Connected(h) => Ok(h),
            Handshake::VersionMismatch { host, robot } => {
                Err(LinkError::VersionMismatch { path, host, robot })
            }
            Handshake::NoAnswer { attempts, heard } => Err(LinkError::HelloUnanswered {
                path,
                attempts,
                heard,
            }),
        }
    }

    fn answered(&self, seq: u16, what: &'static str) -> Result<(u16, Option<u64>), LinkError> {
        match self.driver.wait(|c, _| c.take_answer(seq))? {
            Answer::Ack { at_us } => Ok((seq, at_us)),
            Answer::Nack(reason) => Err(LinkError::Refused {
                what,
                reason: Refusal(reason),
            }),
            // Withdrawn for the emergency stop sent ahead of it: the robot, stopped, would
            // refuse it now.
            Answer::Preempted => Err(LinkError::Refused {
                what,
                reason: Refusal(NackReason::Faulted(Faults::EMERGENCY_STOP)),
            }),
            Answer::GaveUp { attempts } => Err(LinkError::NoAnswer {
                path: self.path().to_string(),
                what,
                attempts,
            }),
        }
    }

    /// Send a command and wait for its answer (the client resends it with the same sequence
    /// number a bounded number of times). A `Nack` becomes [`LinkError::Refused`]; returns the
    /// sequence number and the robot time of the acknowledgement.
    pub fn request(&self, cmd: Command) -> Result<(u16, Option<u64>), LinkError> {
        let _flight = self.lock();
        let seq = self.driver.with_client(|c, now| c.command(now, cmd))?;
        self.answered(seq, command_name(&cmd))
    }

    /// Send a motion command (`Velocity`, `Move`, `Spin`, `AdvanceUntilContact`) and return
    /// once the robot accepted it; [`Robot::wait`] then waits for its end.
    pub fn start(&self, cmd: Command) -> Result<Motion, LinkError> {
        let what = command_name(&cmd);
        let budget_us = motion_budget_us(&cmd)
            .ok_or_else(|| LinkError::InvalidArgument(format!("{what} is not a motion command")))?;
        let _flight = self.lock();
        let seq = self
            .driver
            .with_client(|c, now| c.motion(now, cmd, budget_us))?;
        let (seq, started_us) = self.answered(seq, what)?;
        Ok(Motion {
            seq,
            what,
            started_us,
            budget_us,
        })
    }

    /// Wait for a motion's `Done` (or its outcome read from the telemetry if the `Done` frame
    /// was lost). Bounded by the motion's budget of robot time; past it the host sends `Stop`
    /// and returns [`LinkError::DoneTimeout`].
    pub fn wait(&self, motion: &Motion) -> Result<DoneReport, LinkError> {
        let seq = motion.seq;
        match self.driver.wait(|c, _| c.take_motion_end(seq))? {
            MotionEnd::Done {
                done,
                recovered,
                started_us,
            } => {
                let start = motion.started_us.or(started_us);
                Ok(DoneReport {
                    seq,
                    outcome: done.outcome,
                    pose: done.pose,
                    time_us: done.time_us,
                    duration_s: start.map_or(0.0, |s| done.time_us.saturating_sub(s) as f64 / 1e6),
                    recovered,
                })
            }
            MotionEnd::TimedOut { .. } => {
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
        let got = self.driver.wait(|c, _| {
            let t = c.telemetry()?;
            if after_us.is_some_and(|a| t.time_us <= a) {
                return None;
            }
            if pred(&t) {
                return Some(Ok(t));
            }
            let f = *first.get_or_insert(t.time_us);
            (t.time_us.saturating_sub(f) > budget_us).then_some(Err(()))
        })?;
        got.map_err(|()| LinkError::DoneTimeout {
            what,
            budget_s: budget_us as f64 / 1e6,
        })
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
    /// It does not wait for a command in flight: that one is withdrawn (and ends refused for
    /// the emergency stop), and the stop is written ahead of anything still queued.
    pub fn emergency_stop(&self) -> Result<Telemetry, LinkError> {
        let seq = self.driver.with_client(|c, now| c.emergency_stop(now))?;
        let (_, at) = self.answered(seq, "EmergencyStop")?;
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
            self.driver
                .with_client(|c, _| c.set_watchdog_ms(c.watchdog_ms().min(wd)))?;
        }
        self.request(Command::Configure(update))?;
        if let Some(wd) = update.watchdog_ms {
            self.driver.with_client(|c, _| c.set_watchdog_ms(wd))?;
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
        self.driver.inspect(|c| c.telemetry())
    }

    /// Every bumper contact reported since connecting.
    pub fn contacts(&self) -> Vec<ContactEvent> {
        self.driver.inspect(|c| c.contacts().to_vec())
    }

    /// A receiver of every telemetry, contact and done from now on (the telemetry stream).
    pub fn subscribe(&self) -> mpsc::Receiver<RobotEvent> {
        self.driver.subscribe()
    }

    /// Link counters (frames, rejects, heartbeats, retries), over every session so far.
    pub fn stats(&self) -> LinkStats {
        let mut s = self.past_stats;
        s += self.driver.inspect(|c| c.stats());
        s
    }

    /// Test hook: stop (`true`) or resume heartbeats, as if the host went quiet. The robot's
    /// link watchdog should then stop the motors and latch `LINK_LOST`.
    pub fn pause_heartbeats(&self, paused: bool) {
        let _ = self.driver.with_client(|c, _| c.pause_heartbeats(paused));
    }

    /// Diagnostic: write raw bytes to the port, bypassing framing (to inject garbage and
    /// corrupted frames in tests). Never needed to drive the robot.
    pub fn send_raw(&self, bytes: &[u8]) -> Result<(), LinkError> {
        self.driver.with_client(|c, _| c.send_raw(bytes))
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

//! The host's commands to the [`Core`]: executing a command frame, clearing faults and
//! applying configuration updates within the hard bounds.

use pushbot_protocol::{
    Command, ConfigUpdate, Faults, HelloReply, HostFrame, NackReason, Outcome, PROTOCOL_VERSION,
    Pose, RobotMsg,
};

use crate::odometry::wrap_angle;
use crate::profile::trapezoid_time;

use super::{Core, FAULT_QUIET_US, Kind, finite_in};

impl Core {
    /// Execute a new command; returns its answer.
    pub(super) fn execute(&mut self, now_us: u64, frame: HostFrame) -> RobotMsg {
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

    pub(super) fn clear_faults(&mut self, now_us: u64) {
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
    pub(super) fn configure(&mut self, now_us: u64, u: &ConfigUpdate) -> bool {
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

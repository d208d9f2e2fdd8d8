//! The [`Core`]'s internals: the running motion primitive (its reference, the wheel
//! controllers, its end), cutting the motors, latching faults and sending telemetry.

use pushbot_protocol::{Done, Faults, Outcome, RobotMsg};

use crate::profile::{Profile, ramp};

use super::{Active, Core, Kind};

impl Core {
    /// Whether the wheel controllers are running (a primitive, or braking).
    pub(super) fn driving(&self) -> bool {
        self.active.is_some() || self.braking
    }

    pub(super) fn motors_off(&mut self) {
        self.duty = [0.0; 2];
        self.v_ref = 0.0;
        self.w_ref = 0.0;
        self.braking = false;
        for w in &mut self.wheels {
            w.reset();
        }
    }

    /// End the running primitive, if any, with `outcome`.
    pub(super) fn finish(&mut self, now_us: u64, outcome: Outcome) {
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
    pub(super) fn latch(&mut self, now_us: u64, fault: Faults) {
        self.faults = self.faults.union(fault);
        self.finish(now_us, Outcome::Fault(fault));
        self.motors_off();
    }

    pub(super) fn send_telemetry(&mut self, now_us: u64) {
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
    pub(super) fn run_motion(&mut self, now_us: u64, dt: f32) {
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
    pub(super) fn start(&mut self, now_us: u64, seq: u16, kind: Kind, goal: f32, planned_s: f32) {
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
}

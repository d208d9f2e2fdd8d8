//! The control step ([`Core::step`]): loop timing, encoders, bumper, link watchdog, stall
//! detection, the running primitive and the wheel controllers, then telemetry when due.

use pushbot_protocol::{ContactEvent, Faults, RobotMsg};

use crate::odometry::count_delta;
use crate::safety::{StallLimits, encoder_jump, max_plausible_counts, overrun};

use super::{Core, Inputs, Kind, Outputs};

impl Core {
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
}

//! Acceleration-limited motion profiles.
//!
//! [`Profile`] drives a reference position to a goal on a trapezoidal velocity profile: it
//! accelerates at the limit up to the cruise speed, cruises, and brakes at the limit so it stops
//! exactly on the goal. It is computed step by step from the current reference velocity, so it
//! starts from any velocity (a primitive that pre-empts a moving one continues smoothly) and the
//! velocity never changes by more than `accel · dt` per step nor exceeds the cruise speed once
//! reached. [`ramp`] is the velocity-only counterpart for velocity commands and braking.

/// Move `current` toward `target` by at most `max_step`.
pub fn ramp(current: f32, target: f32, max_step: f32) -> f32 {
    let step = max_step.max(0.0);
    if target > current + step {
        current + step
    } else if target < current - step {
        current - step
    } else {
        target
    }
}

/// Braking on the profile uses this fraction of the acceleration limit (see [`Profile::step`]).
pub const BRAKE_MARGIN: f32 = 0.95;

/// Duration of the trapezoidal profile over `distance` from rest to rest, s.
pub fn trapezoid_time(distance: f32, cruise: f32, accel: f32) -> f32 {
    let d = libm::fabsf(distance);
    if cruise <= 0.0 || accel <= 0.0 {
        return 0.0;
    }
    if d >= cruise * cruise / accel {
        d / cruise + cruise / accel
    } else {
        2.0 * libm::sqrtf(d / accel)
    }
}

/// A reference position travelling to a goal on an acceleration-limited profile.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Profile {
    /// Reference position (m or rad), from the start of the profile.
    pub pos: f32,
    /// Reference velocity (m/s or rad/s).
    pub vel: f32,
    /// Where the profile ends.
    pub goal: f32,
    done: bool,
}

impl Profile {
    /// A profile from position 0 at velocity `vel` to `goal`.
    pub fn new(goal: f32, vel: f32) -> Self {
        Profile {
            pos: 0.0,
            vel,
            goal,
            done: false,
        }
    }

    /// Whether the reference has arrived on the goal (its velocity is then at most `a·dt`, and
    /// zero from the next step on).
    pub fn done(&self) -> bool {
        self.done
    }

    /// Advance by `dt` seconds with cruise speed `cruise` and acceleration limit `accel`;
    /// returns the new reference velocity.
    pub fn step(&mut self, dt: f32, cruise: f32, accel: f32) -> f32 {
        if self.done {
            // The step after arrival brings the reference to rest (|vel| ≤ a·dt there).
            self.vel = 0.0;
            return 0.0;
        }
        if dt <= 0.0 {
            return self.vel;
        }
        let a = accel.max(1e-6);
        let dv = a * dt;
        let rem = self.goal - self.pos;
        let dir = if rem >= 0.0 { 1.0 } else { -1.0 };
        // Fastest speed from which braking in steps of b·dt stops within |rem|:
        // v (v + b dt) / (2b) = |rem|. The braking curve uses b slightly below the limit a, so
        // a reference that starts above the curve (a moving start, float rounding) still
        // converges onto it and arrives at rest on the goal.
        let b = BRAKE_MARGIN * a;
        let db = b * dt;
        let brake = libm::sqrtf(db * db / 4.0 + 2.0 * b * libm::fabsf(rem)) - db / 2.0;
        let target = dir * cruise.max(0.0).min(brake);
        let v = ramp(self.vel, target, dv);
        self.pos += v * dt;
        self.vel = v;
        // Arrived: within one step's worth of the limit of the goal and slow enough to stop
        // in one step. Snapping onto the goal moves the reference by at most a·dt².
        if libm::fabsf(self.goal - self.pos) <= dv * dt * 1.0001 && libm::fabsf(v) <= dv {
            self.pos = self.goal;
            self.done = true;
        }
        self.vel
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(goal: f32, v0: f32, cruise: f32, accel: f32, dt: f32) -> (Vec<f32>, Profile) {
        let mut p = Profile::new(goal, v0);
        let mut vels = vec![v0];
        for _ in 0..1_000_000 {
            if p.done() {
                vels.push(p.step(dt, cruise, accel));
                assert_eq!(p.vel, 0.0);
                break;
            }
            vels.push(p.step(dt, cruise, accel));
        }
        (vels, p)
    }

    /// The profile never exceeds the speed and acceleration limits (the last step, which
    /// lands on the goal, may only slow down), and stops on the goal.
    #[test]
    fn profile_respects_limits_and_arrives() {
        let dt = 0.001;
        for &(goal, cruise, accel) in &[
            (0.3f32, 0.3f32, 0.6f32),
            (-0.3, 0.3, 0.6),
            (0.01, 0.3, 0.6),
            (core::f32::consts::FRAC_PI_2, 4.0, 12.0),
            (-3.0, 2.0, 12.0),
            (2.0, 0.1, 0.6),
            (0.0, 0.3, 0.6),
        ] {
            let (vels, p) = run(goal, 0.0, cruise, accel, dt);
            assert!(p.done(), "goal {goal} never reached");
            assert!((p.pos - goal).abs() < 1e-6);
            for w in vels.windows(2) {
                assert!(
                    w[1].abs() <= cruise * (1.0 + 1e-5),
                    "speed {} > {cruise}",
                    w[1]
                );
                let a = (w[1] - w[0]).abs() / dt;
                assert!(a <= accel * 1.001, "accel {a} > {accel} (goal {goal})");
            }
            // And it takes about the trapezoid's time, not much longer.
            let t = (vels.len() - 2) as f32 * dt;
            let t_ideal = trapezoid_time(goal, cruise, accel);
            assert!(t >= t_ideal - 2.0 * dt, "{t} < {t_ideal}");
            assert!(t <= t_ideal + 0.02 + 0.05 * t_ideal, "{t} >> {t_ideal}");
        }
    }

    /// Starting at speed away from the goal, it brakes at the limit, turns and arrives.
    #[test]
    fn profile_from_moving_start() {
        let dt = 0.001;
        let (vels, p) = run(-0.1, 0.3, 0.3, 0.6, dt);
        assert!(p.done());
        for w in vels.windows(2) {
            assert!((w[1] - w[0]).abs() / dt <= 0.6 * 1.001);
            assert!(w[1].abs() <= 0.3 * (1.0 + 1e-5));
        }
    }

    proptest::proptest! {
        /// Any goal, start velocity and limits: |Δv| ≤ a·dt every step, |v| ≤ max(cruise,
        /// |v0|) and never above cruise once there, and arrival on the goal in bounded time.
        #[test]
        fn profile_limits_hold_for_any_case(
            goal in -3.0f32..3.0,
            v0 in -0.5f32..0.5,
            cruise in 0.01f32..1.0,
            accel in 0.1f32..20.0,
        ) {
            let dt = 0.001;
            let (vels, p) = run(goal, v0, cruise, accel, dt);
            proptest::prop_assert!(p.done());
            proptest::prop_assert!((p.pos - goal).abs() < 1e-6);
            let mut reached = v0.abs() <= cruise;
            for w in vels.windows(2) {
                proptest::prop_assert!((w[1] - w[0]).abs() <= accel * dt * 1.001);
                reached |= w[1].abs() <= cruise;
                if reached {
                    proptest::prop_assert!(w[1].abs() <= cruise * (1.0 + 1e-5));
                }
            }
            // Bounded: brake from v0, then a rest-to-rest trapezoid over at most |goal| plus
            // the braking distance.
            let brake_t = v0.abs() / accel;
            let extra = v0 * v0 / (2.0 * accel);
            let bound = brake_t + trapezoid_time(goal.abs() + extra, cruise, accel) * 1.1 + 0.05;
            proptest::prop_assert!((vels.len() as f32) * dt <= bound, "{} > {}", vels.len() as f32 * dt, bound);
        }
    }

    #[test]
    fn ramp_steps() {
        assert_eq!(ramp(0.0, 1.0, 0.25), 0.25);
        assert_eq!(ramp(0.0, -1.0, 0.25), -0.25);
        assert_eq!(ramp(0.9, 1.0, 0.25), 1.0);
    }

    #[test]
    fn trapezoid_time_cases() {
        // Triangle: 2 sqrt(d/a).
        assert!((trapezoid_time(0.06, 0.3, 0.6) - 2.0 * (0.1f32).sqrt()).abs() < 1e-6);
        // Trapezoid: d/v + v/a.
        assert!((trapezoid_time(0.3, 0.3, 0.6) - 1.5).abs() < 1e-6);
    }
}

//! Wheel-speed control: PI on encoder feedback plus feed-forward, with anti-windup and duty
//! saturation; and the wheel-speed estimate from encoder counts.
//!
//! The integral term integrates the wheel-*angle* error: the target angle is the integral of
//! the target speed and the measured angle comes straight from the encoder counts, so the
//! integral is free of speed-estimate noise and a wheel that falls behind catches up. Anti-windup
//! is conditional integration (the error stops accumulating while the duty is saturated in the
//! direction the error pushes) plus a bound of ±1 duty on the integral term.

use pushbot_protocol::WheelGains;

/// PI + feed-forward speed controller for one wheel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelController {
    /// Target angle minus measured angle, rad.
    angle_error: f32,
}

impl WheelController {
    /// A controller at rest.
    pub const fn new() -> Self {
        WheelController { angle_error: 0.0 }
    }

    /// Forget the accumulated error (motors off).
    pub fn reset(&mut self) {
        self.angle_error = 0.0;
    }

    /// Target angle minus measured angle, rad.
    pub fn angle_error(&self) -> f32 {
        self.angle_error
    }

    /// One control step: target speed `target` (rad/s), measured speed `measured` (rad/s),
    /// measured angle change `dangle` (rad) over `dt` s. Returns the duty in −1..=1.
    pub fn update(
        &mut self,
        gains: &WheelGains,
        target: f32,
        measured: f32,
        dangle: f32,
        dt: f32,
    ) -> f32 {
        let previous = self.angle_error;
        self.angle_error += target * dt - dangle;
        if gains.ki > 0.0 {
            let bound = 1.0 / gains.ki;
            self.angle_error = self.angle_error.clamp(-bound, bound);
        }
        let base = gains.kff * target + gains.kp * (target - measured);
        let mut u = base + gains.ki * self.angle_error;
        if (u > 1.0 && self.angle_error > previous) || (u < -1.0 && self.angle_error < previous) {
            // Saturated and the error is pushing further: do not integrate this step.
            self.angle_error = previous;
            u = base + gains.ki * self.angle_error;
        }
        if u.is_finite() && self.angle_error.is_finite() {
            u.clamp(-1.0, 1.0)
        } else {
            self.reset();
            0.0
        }
    }
}

/// Number of samples in the speed estimator's window.
pub const SPEED_WINDOW: usize = 10;

/// Wheel speed from encoder counts: the count difference across a short window of samples
/// divided by its duration (a moving average that keeps quantisation noise low).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedEstimator {
    times: [u64; SPEED_WINDOW],
    counts: [i64; SPEED_WINDOW],
    head: usize,
    filled: usize,
    total: i64,
    rad_per_count: f32,
}

impl SpeedEstimator {
    /// An estimator for an encoder of `cpr` counts per wheel revolution.
    pub fn new(cpr: u32) -> Self {
        SpeedEstimator {
            times: [0; SPEED_WINDOW],
            counts: [0; SPEED_WINDOW],
            head: 0,
            filled: 0,
            total: 0,
            rad_per_count: 2.0 * core::f32::consts::PI / cpr.max(1) as f32,
        }
    }

    /// Radians of wheel rotation per count.
    pub fn rad_per_count(&self) -> f32 {
        self.rad_per_count
    }

    /// Record `delta` counts at time `now_us`; returns the speed estimate, rad/s.
    pub fn update(&mut self, now_us: u64, delta: i32) -> f32 {
        self.total = self.total.wrapping_add(i64::from(delta));
        self.head = (self.head + 1) % SPEED_WINDOW;
        if let (Some(t), Some(c)) = (
            self.times.get_mut(self.head),
            self.counts.get_mut(self.head),
        ) {
            *t = now_us;
            *c = self.total;
        }
        self.filled = (self.filled + 1).min(SPEED_WINDOW);
        self.speed()
    }

    /// The latest speed estimate, rad/s.
    pub fn speed(&self) -> f32 {
        if self.filled < 2 {
            return 0.0;
        }
        let oldest = (self.head + SPEED_WINDOW + 1 - self.filled) % SPEED_WINDOW;
        let (Some(&t0), Some(&c0), Some(&t1), Some(&c1)) = (
            self.times.get(oldest),
            self.counts.get(oldest),
            self.times.get(self.head),
            self.counts.get(self.head),
        ) else {
            return 0.0;
        };
        let dt = t1.saturating_sub(t0);
        if dt == 0 {
            return 0.0;
        }
        (c1.wrapping_sub(c0)) as f32 * self.rad_per_count * 1e6 / dt as f32
    }

    /// Forget the history (after a gap in the samples).
    pub fn reset(&mut self) {
        self.filled = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gains() -> WheelGains {
        crate::RobotParams::default().gains
    }

    /// A first-order motor, ω' = (K·u − ω)/τ: the controller brings it to the target speed
    /// with zero steady-state error, and the duty stays within −1..=1.
    #[test]
    fn tracks_speed_on_first_order_motor() {
        let g = gains();
        let mut c = WheelController::new();
        let (k, tau, dt) = (32.0f32, 0.02f32, 0.001f32);
        let mut w = 0.0f32;
        let target = 15.0;
        let mut angle_target = 0.0f32;
        let mut angle = 0.0f32;
        let mut dangle = 0.0f32;
        for _ in 0..1000 {
            let u = c.update(&g, target, w, dangle, dt);
            assert!((-1.0..=1.0).contains(&u));
            w += (k * u - w) / tau * dt;
            dangle = w * dt;
            angle += dangle;
            angle_target += target * dt;
            let _ = c.update(&g, 0.0, w, 0.0, 0.0); // dt = 0 changes nothing
        }
        assert!((w - target).abs() < 0.05, "speed {w}");
        assert!(
            (angle_target - angle).abs() < 0.2,
            "lag {}",
            angle_target - angle
        );
    }

    /// A blocked wheel: the duty saturates and the integral does not wind up past its bound.
    #[test]
    fn anti_windup_on_blocked_wheel() {
        let g = gains();
        let mut c = WheelController::new();
        for _ in 0..10_000 {
            let u = c.update(&g, 20.0, 0.0, 0.0, 0.001);
            assert!((-1.0..=1.0).contains(&u));
        }
        assert!(g.ki * c.angle_error() <= 1.0 + 1e-6);
        // Released, the duty recovers at once rather than after unwinding a huge integral.
        let u = c.update(&g, -20.0, 0.0, 0.0, 0.001);
        assert!(u < 0.5, "duty {u}");
    }

    #[test]
    fn non_finite_measurement_gives_zero_duty() {
        let mut c = WheelController::new();
        assert_eq!(c.update(&gains(), f32::NAN, 0.0, 0.0, 0.001), 0.0);
    }

    #[test]
    fn speed_estimate_of_constant_rate() {
        let mut s = SpeedEstimator::new(1400);
        let mut v = 0.0;
        for i in 1..100u64 {
            v = s.update(i * 1000, 5);
        }
        let expect = 5.0 * 1000.0 * 2.0 * core::f32::consts::PI / 1400.0;
        assert!((v - expect).abs() < 1e-3, "{v} vs {expect}");
    }
}

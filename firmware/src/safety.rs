//! Safety monitors: the link watchdog, stall detection, encoder plausibility and control-loop
//! overruns. Each only *detects*; the core latches the fault and cuts the motors.

/// Link watchdog: trips when no valid frame arrived for the configured time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Watchdog {
    last_feed_us: u64,
}

impl Watchdog {
    /// A watchdog fed at `now_us`.
    pub const fn new(now_us: u64) -> Self {
        Watchdog {
            last_feed_us: now_us,
        }
    }

    /// A valid frame arrived at `now_us`.
    pub fn feed(&mut self, now_us: u64) {
        self.last_feed_us = self.last_feed_us.max(now_us);
    }

    /// Whether `timeout_ms` or more passed since the last feed.
    pub fn expired(&self, now_us: u64, timeout_ms: u16) -> bool {
        now_us.saturating_sub(self.last_feed_us) >= u64::from(timeout_ms) * 1000
    }
}

/// Stall detection for one wheel: driven at |duty| ≥ a threshold while its measured speed
/// stays below a threshold, for longer than a time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StallDetector {
    since_us: Option<u64>,
}

/// Thresholds of [`StallDetector`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StallLimits {
    /// |duty| at or above this is "driven hard".
    pub duty: f32,
    /// |speed| below this (rad/s) is "not turning".
    pub speed: f32,
    /// How long both must hold, µs.
    pub time_us: u64,
}

impl StallDetector {
    /// Not stalled.
    pub const fn new() -> Self {
        StallDetector { since_us: None }
    }

    /// Forget (motors off).
    pub fn reset(&mut self) {
        self.since_us = None;
    }

    /// The wheel was driven at `duty` and measured at `speed` at `now_us`; true when stalled.
    pub fn update(&mut self, now_us: u64, duty: f32, speed: f32, limits: &StallLimits) -> bool {
        let hard = libm::fabsf(duty) >= limits.duty;
        let still = libm::fabsf(speed) < limits.speed || speed.is_nan();
        if hard && still {
            let t0 = *self.since_us.get_or_insert(now_us);
            now_us.saturating_sub(t0) > limits.time_us
        } else {
            self.since_us = None;
            false
        }
    }
}

/// Largest plausible encoder step, counts, over `dt_us` for a wheel no faster than
/// `max_speed` rad/s with `cpr` counts per revolution (plus a few counts of slack).
pub fn max_plausible_counts(dt_us: u64, max_speed: f32, cpr: u32) -> i64 {
    let per_us = max_speed.max(0.0) * cpr as f32 / (2.0 * core::f32::consts::PI) * 1e-6;
    let counts = per_us * dt_us.min(10_000_000) as f32;
    counts as i64 + 4
}

/// Whether an encoder step of `delta` counts is physically impossible.
pub fn encoder_jump(delta: i32, max_counts: i64) -> bool {
    i64::from(delta).abs() > max_counts
}

/// Whether the gap between two control steps (µs) overran the period: more than `periods`
/// periods.
pub fn overrun(dt_us: u64, period_us: u32, periods: u32) -> bool {
    dt_us > u64::from(periods.max(1)) * u64::from(period_us)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn watchdog_trips_at_timeout() {
        let mut w = Watchdog::new(0);
        w.feed(1_000);
        assert!(!w.expired(200_999, 200));
        assert!(w.expired(201_000, 200));
        w.feed(500); // time going backwards does not un-feed
        assert!(w.expired(201_000, 200));
    }

    #[test]
    fn stall_needs_time_and_both_conditions() {
        let lim = StallLimits {
            duty: 0.3,
            speed: 1.0,
            time_us: 150_000,
        };
        let mut s = StallDetector::new();
        for t in 0..=150u64 {
            assert!(!s.update(t * 1000, 0.8, 0.0, &lim));
        }
        assert!(s.update(151_000, 0.8, 0.0, &lim));
        // Turning wheel or low duty: never.
        let mut s = StallDetector::new();
        for t in 0..1000u64 {
            assert!(!s.update(t * 1000, 0.9, 5.0, &lim));
            assert!(!s.update(t * 1000, 0.1, 0.0, &lim));
        }
    }

    #[test]
    fn encoder_plausibility() {
        // 100 rad/s, 1400 cpr, 1 ms: 22.3 counts + 4.
        let m = max_plausible_counts(1000, 100.0, 1400);
        assert_eq!(m, 26);
        assert!(!encoder_jump(-26, m));
        assert!(encoder_jump(27, m));
        assert!(encoder_jump(i32::MIN, m));
    }

    #[test]
    fn overrun_after_three_periods() {
        assert!(!overrun(3000, 1000, 3));
        assert!(overrun(3001, 1000, 3));
        assert!(!overrun(250_000, 1000, 250));
        assert!(overrun(250_001, 1000, 250));
    }
}

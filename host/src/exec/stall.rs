//! Stall detection for a delivery among obstacles: no progress towards the goal (or along the
//! path) for a while is a stall, which [`crate::exec::deliver_path`] recovers from rather than
//! letting the time limit run out silently.

use crate::exec::delivery_params::DeliveryParams;

/// Watches the distance to the goal for a stall ([`DeliveryParams::stall_time`]).
pub(crate) struct StallWatch {
    time: f64,
    progress: f64,
    success: f64,
    best: f64,
    best_at: f64,
}

impl StallWatch {
    /// A watch from `now` with the delivery's stall time and progress.
    pub(crate) fn new(p: &DeliveryParams, now: f64) -> StallWatch {
        StallWatch {
            time: p.stall_time,
            progress: p.stall_progress,
            success: p.success_radius,
            best: f64::INFINITY,
            best_at: now,
        }
    }

    /// The object is `dist` from the goal at `now`: has it made no progress for too long?
    pub(crate) fn stalled(&mut self, dist: f64, now: f64) -> bool {
        let need = self.progress.min(0.5 * (self.best - self.success));
        if !self.best.is_finite() || self.best - dist >= need {
            self.best = dist;
            self.best_at = now;
        }
        self.time > 0.0 && now - self.best_at > self.time
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Progress of at least `stall_progress` restarts the clock; less does not, and after
    /// `stall_time` without it the leg has stalled. A stall time of 0 never stalls.
    #[test]
    fn a_stall_is_the_stall_time_without_progress() {
        let p = DeliveryParams {
            stall_time: 60.0,
            stall_progress: 0.02,
            ..DeliveryParams::default()
        };
        let mut w = StallWatch::new(&p, 0.0);
        assert!(!w.stalled(0.5, 0.0));
        assert!(!w.stalled(0.47, 50.0));
        // 1 cm more is not progress: the clock runs from t = 50.
        assert!(!w.stalled(0.46, 100.0));
        assert!(w.stalled(0.46, 111.0));
        let off = DeliveryParams::default();
        let mut w = StallWatch::new(&off, 0.0);
        assert!(!w.stalled(0.5, 0.0) && !w.stalled(0.5, 1e6));
    }
}

//! How far a body can have moved since it was last seen: the motion bounds a caller gives look
//! after look ([`MotionBound`], from its robot's odometry), chained. A marker last seen several
//! looks ago is looked for as far as their sum reaches, not as far as the fastest body goes in
//! the gap ([`super::RoiParams::max_speed`]).

use std::collections::VecDeque;

use super::roi::MotionBound;

/// Bounds kept: older sightings than the oldest kept bound get no bound.
const TRAVEL_STEPS: usize = 1024;

/// Frame times closer than this are the same look, seconds.
const SAME_TIME_S: f64 = 1e-9;

/// The chained motion bounds of one body (or of everything on the table).
#[derive(Debug, Clone, Default)]
pub(super) struct Travel {
    /// `(since, metres)` of each bound, oldest first, each reaching to the next one's `since`
    /// and the last to `until`.
    steps: VecDeque<(f64, f64)>,
    /// The frame the latest bound was given for; `None` until a frame is processed after it
    /// (the bound covers the next frame, whenever it is taken).
    until: Option<f64>,
}

impl Travel {
    /// A bound given before the next frame. One that begins after the time the last one
    /// reached leaves a gap nothing is known of: the chain starts again from it. One that
    /// begins before earlier ones replaces them.
    pub(super) fn add(&mut self, b: MotionBound) {
        if !(b.since.is_finite() && b.metres.is_finite() && b.metres >= 0.0) {
            self.steps.clear();
            self.until = None;
            return;
        }
        if let Some(u) = self.until
            && b.since > u + SAME_TIME_S
        {
            self.steps.clear();
        }
        while self.steps.back().is_some_and(|&(s, _)| s >= b.since) {
            self.steps.pop_back();
        }
        self.steps.push_back((b.since, b.metres));
        if self.steps.len() > TRAVEL_STEPS {
            self.steps.pop_front();
        }
        self.until = None;
    }

    /// A frame taken at `time` was processed: the latest bound reaches to it, no further.
    pub(super) fn frame(&mut self, time: f64) {
        if self.until.is_none() && !self.steps.is_empty() {
            self.until = Some(time);
        }
    }

    /// The farthest the body can have moved between `seen` and a frame at `time`; `None`
    /// when the bounds do not cover that span.
    pub(super) fn since(&self, seen: f64, time: f64) -> Option<f64> {
        if self.until.is_some_and(|u| time > u + SAME_TIME_S) {
            return None;
        }
        let i = self
            .steps
            .iter()
            .rposition(|&(s, _)| s <= seen + SAME_TIME_S)?;
        Some(self.steps.range(i..).map(|&(_, m)| m).sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bound(since: f64, metres: f64) -> MotionBound {
        MotionBound { since, metres }
    }

    /// Bounds look after look add up from the one that covers the sighting; a sighting older
    /// than them all, a frame later than the last one covers, or a gap between two bounds,
    /// gets no bound.
    #[test]
    fn bounds_add_up_from_the_sighting() {
        let mut t = Travel::default();
        assert_eq!(t.since(0.0, 1.0), None);
        t.add(bound(1.0, 0.02));
        assert_eq!(t.since(1.0, 2.0), Some(0.02));
        assert_eq!(t.since(0.5, 2.0), None);
        t.frame(2.0);
        t.add(bound(2.0, 0.03));
        t.frame(3.0);
        t.add(bound(3.0, 0.05));
        // Seen at the first look: all three; at the second: the last two; between the second
        // and the third: the bound that covers that time and the last.
        assert!((t.since(1.0, 4.0).unwrap() - 0.10).abs() < 1e-12);
        assert!((t.since(2.0, 4.0).unwrap() - 0.08).abs() < 1e-12);
        assert!((t.since(2.5, 4.0).unwrap() - 0.08).abs() < 1e-12);
        t.frame(4.0);
        // The same look's second frame is covered; a later one is not.
        assert!(t.since(3.0, 4.0).is_some());
        assert_eq!(t.since(3.0, 5.0), None);
        // A bound that begins after the last frame it covered: the chain starts again.
        t.add(bound(6.0, 0.01));
        assert_eq!(t.since(3.0, 7.0), None);
        assert_eq!(t.since(6.0, 7.0), Some(0.01));
        // A bound that is not a number says nothing, and forgets the rest.
        t.add(bound(7.0, f64::NAN));
        assert_eq!(t.since(6.0, 7.0), None);
    }
}

//! Tracker-guided regions of interest: between whole-frame searches, markers are looked for
//! only in squares around where each body's marker is expected, as real-time trackers do to
//! spend the detector's time where the targets are. A recent sighting is carried on at its
//! image velocity; after a longer gap (a robot that looks only between its moves) the square
//! is centred on the last sighting and reaches as far as a marker can travel in the gap.

use super::detection::{Detection, Region};

/// Regions are squares of a multiple of this many pixels, so a few buffer sizes serve.
const ROI_STEP: f64 = 16.0;

/// Where, and how wide, the pipeline looks between whole-frame searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoiParams {
    /// While a body of the layout is not tracked (neither found in the last frame nor fixed
    /// where it was seen), search the whole frame at least every this many frames (0 or 1:
    /// always the whole frame, no regions). The whole frame is also searched on the first
    /// frame, when a region would be too wide (after a long gap, [`Self::max_speed`]), and at
    /// once whenever a body expected where its velocity put it is not found there (one missed
    /// where its motion bound put it is covered, and waits for the scheduled searches).
    pub full_every: u32,
    /// Pixels of margin around a marker's predicted bounding square, on each side (covers
    /// acceleration between frames and the prediction's error).
    pub margin_px: f64,
    /// Seconds since the last sighting beyond which the image velocity is not trusted: the
    /// region is then centred on the last sighting and grows with the gap.
    pub max_gap: f64,
    /// The fastest a marker moves over the table, m/s: after a gap longer than `max_gap` a
    /// region reaches this far from the last sighting. A region wider than half the frame's
    /// shorter side is not worth it, and the whole frame is searched instead.
    pub max_speed: f64,
}

impl Default for RoiParams {
    fn default() -> Self {
        RoiParams {
            full_every: 15,
            margin_px: 20.0,
            max_gap: 0.2,
            max_speed: 0.5,
        }
    }
}

impl RoiParams {
    /// Always the whole frame.
    pub fn full_frames() -> RoiParams {
        RoiParams {
            full_every: 1,
            ..RoiParams::default()
        }
    }
}

/// What the caller knows of how far things moved: nothing on the table has moved more than
/// `metres` since `since` (the frames' clock) — from its robot's odometry, when nothing but the
/// robot moves things. A region after a gap then reaches no farther than that.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionBound {
    /// Since when, seconds.
    pub since: f64,
    /// The farthest anything moved, metres.
    pub metres: f64,
}

/// Where a body's marker was last seen in the image.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sighting {
    time: f64,
    centre: [f64; 2],
    velocity: [f64; 2],
    side_px: f64,
    /// Image pixels per metre at the marker (its side in pixels over its side in metres).
    px_per_m: f64,
}

impl Sighting {
    /// The sighting of detection `d` at `time`, a marker `side_m` metres wide; its image
    /// velocity from the `previous` sighting when that is at most `roi.max_gap` old. `None`
    /// for a detection with non-finite corners.
    pub(super) fn new(
        time: f64,
        d: &Detection,
        side_m: f64,
        previous: Option<&Sighting>,
        roi: &RoiParams,
    ) -> Option<Sighting> {
        let c = &d.corners;
        let side_px = (0..4)
            .map(|i| {
                let (p, q) = (c[i], c[(i + 1) % 4]);
                (p[0] - q[0]).hypot(p[1] - q[1])
            })
            .sum::<f64>()
            / 4.0;
        let velocity = match previous {
            Some(s) if time > s.time && time - s.time <= roi.max_gap => {
                let dt = time - s.time;
                [
                    (d.centre[0] - s.centre[0]) / dt,
                    (d.centre[1] - s.centre[1]) / dt,
                ]
            }
            _ => [0.0, 0.0],
        };
        let px_per_m = side_px / side_m;
        let finite = side_px.is_finite()
            && px_per_m.is_finite()
            && d.centre.iter().chain(&velocity).all(|v| v.is_finite());
        finite.then_some(Sighting {
            time,
            centre: d.centre,
            velocity,
            side_px,
            px_per_m,
        })
    }

    /// When it was seen, seconds.
    pub(super) fn time(&self) -> f64 {
        self.time
    }

    /// The square to search for this marker in a `width × height` frame taken at `time`, or
    /// `None` when it would be wider than half the frame's shorter side (or the frame is
    /// older than the sighting). `moved`: the farthest the marker can have gone since the
    /// sighting, metres, when the caller's motion bounds say ([`super::travel`]).
    pub(super) fn region(
        &self,
        time: f64,
        width: u32,
        height: u32,
        roi: &RoiParams,
        moved: Option<f64>,
    ) -> Option<Region> {
        let widest = f64::from(width.min(height)) / 2.0;
        self.region_within(time, width, height, roi, moved, widest)
    }

    /// The square to search at full resolution for this marker, missing from a whole-frame
    /// search: as [`Self::region`], as wide as the frame's longer side (clipped to the frame),
    /// so that even after a gap it costs a fraction of the whole frame at full resolution.
    pub(super) fn fine_region(
        &self,
        time: f64,
        width: u32,
        height: u32,
        roi: &RoiParams,
        moved: Option<f64>,
    ) -> Option<Region> {
        let widest = f64::from(width.max(height));
        self.region_within(time, width, height, roi, moved, widest)
    }

    fn region_within(
        &self,
        time: f64,
        width: u32,
        height: u32,
        roi: &RoiParams,
        moved: Option<f64>,
        widest: f64,
    ) -> Option<Region> {
        let dt = time - self.time;
        if !(0.0..).contains(&dt) {
            return None;
        }
        let (centre, reach) = if dt <= roi.max_gap {
            let c = [
                self.centre[0] + self.velocity[0] * dt,
                self.centre[1] + self.velocity[1] * dt,
            ];
            (c, 0.0)
        } else {
            let mut reach = roi.max_speed * dt;
            if let Some(m) = moved {
                reach = reach.min(m.max(0.0));
            }
            (self.centre, reach * self.px_per_m)
        };
        // The marker's bounding square at any heading, plus the margin and reach on each side.
        let side = self.side_px * std::f64::consts::SQRT_2 + 2.0 * (roi.margin_px + reach);
        if side.is_nan() || side > widest {
            return None;
        }
        let side = ((side / ROI_STEP).ceil() * ROI_STEP) as u32;
        Some(Region::square_around(centre, side, width, height))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn marker(centre: [f64; 2], side: f64) -> Detection {
        let h = side / 2.0;
        Detection {
            family: Default::default(),
            id: 3,
            centre,
            corners: [
                [centre[0] - h, centre[1] - h],
                [centre[0] + h, centre[1] - h],
                [centre[0] + h, centre[1] + h],
                [centre[0] - h, centre[1] + h],
            ],
            margin: 50.0,
            hamming: 0,
        }
    }

    /// A recent sighting moves on at its velocity in a square of the margin; an old one stays
    /// put and its square grows with the gap until it is too wide to be worth searching.
    #[test]
    fn a_region_follows_recent_motion_and_grows_with_the_gap() {
        let roi = RoiParams::default();
        // A 40 px marker 5 cm wide: 800 px a metre.
        let first = Sighting::new(0.0, &marker([300.0, 300.0], 40.0), 0.05, None, &roi).unwrap();
        let s =
            Sighting::new(0.1, &marker([310.0, 300.0], 40.0), 0.05, Some(&first), &roi).unwrap();
        assert_eq!(s.velocity, [100.0, 0.0]);
        assert!((s.px_per_m - 800.0).abs() < 1e-9);
        // 0.1 s on: 10 px further, the square 40√2 + 40 = 96.6 → 112 px.
        let r = s.region(0.2, 960, 720, &roi, None).unwrap();
        assert_eq!((r.width, r.height), (112, 112));
        assert!((f64::from(r.x) + 56.0 - 320.0).abs() <= 1.0, "{r:?}");
        // 0.3 s after the sighting: centred where it was seen, reaching 0.5 m/s × 0.3 s ×
        // 800 px/m = 120 px further on each side: 336.6 → 352 px.
        let r = s.region(0.4, 960, 720, &roi, None).unwrap();
        assert_eq!((r.width, r.height), (352, 352));
        assert!((f64::from(r.x) + 176.0 - 310.0).abs() <= 1.0, "{r:?}");
        // 0.4 s: 416.6 px, wider than half of 720: not a region.
        assert!(s.region(0.5, 960, 720, &roi, None).is_none());
        // At full resolution after a whole-frame miss, up to the frame's longer side, clipped:
        // 0.5 s after the sighting, 40√2 + 40 + 2 · 160 = 416.6 → 432 px.
        let r = s.fine_region(0.5, 960, 720, &roi, None).unwrap();
        assert_eq!((r.width, r.height), (432, 432));
        // 0.9 s: 736.6 px → 752 px wide, clipped to the frame's 720 rows.
        let r = s.fine_region(0.9, 960, 720, &roi, None).unwrap();
        assert_eq!((r.width, r.height), (752, 720));
        assert!(s.fine_region(1.2, 960, 720, &roi, None).is_none());
        // Known to have moved at most 5 cm since the sighting: 40√2 + 40 + 2 · 40 = 176.6 →
        // 192 px, even 0.4 s on; not moved at all: the marker's square and the margin.
        let r = s.region(0.5, 960, 720, &roi, Some(0.05)).unwrap();
        assert_eq!((r.width, r.height), (192, 192));
        let r = s.region(5.0, 960, 720, &roi, Some(0.0)).unwrap();
        assert_eq!((r.width, r.height), (112, 112));
        // A bound farther than the fastest marker goes in the gap does not widen it.
        let r = s.region(0.4, 960, 720, &roi, Some(1.0)).unwrap();
        assert_eq!((r.width, r.height), (352, 352));
        // A frame older than the sighting is not predicted backwards.
        assert!(s.region(0.05, 960, 720, &roi, None).is_none());
        // A sighting from a marker with a non-finite corner is no sighting.
        let mut bad = marker([300.0, 300.0], 40.0);
        bad.corners[2][0] = f64::NAN;
        assert!(Sighting::new(0.0, &bad, 0.05, None, &roi).is_none());
    }
}

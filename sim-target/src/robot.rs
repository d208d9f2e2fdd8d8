//! The robot's body: differential-drive kinematics, the true pose, and the circular bumper with
//! three switches that close by the angle at which something presses on it.
//!
//! Frames: the table frame has its origin at the table's lower-left corner, x along the width,
//! y along the height, angles counter-clockwise from +x. The robot's pose is the centre of its
//! wheel axle (which is also the bumper's centre) and its heading.

use rand::Rng;

pub use pushbot_world::pose::{Pose, wrap_angle};

/// Body twist from wheel rim speeds (m/s) `[left, right]`: (forward speed m/s, turn rate rad/s).
pub fn twist_from_wheels(rim: [f64; 2], wheel_base: f64) -> (f64, f64) {
    ((rim[0] + rim[1]) / 2.0, (rim[1] - rim[0]) / wheel_base)
}

/// Wheel rim speeds `[left, right]` (m/s) that realise a body twist.
pub fn wheels_from_twist(v: f64, omega: f64, wheel_base: f64) -> [f64; 2] {
    [v - omega * wheel_base / 2.0, v + omega * wheel_base / 2.0]
}

/// Displacement of a body moving at constant (v, ω) for `dt` from heading `theta`, exactly along
/// the arc: (dx, dy, dθ) in the table frame.
pub fn arc_displacement(theta: f64, v: f64, omega: f64, dt: f64) -> (f64, f64, f64) {
    let dth = omega * dt;
    // Chord length of the arc, along the mean heading.
    let chord = if dth.abs() < 1e-9 {
        v * dt
    } else {
        2.0 * v / omega * (dth / 2.0).sin()
    };
    let mid = theta + dth / 2.0;
    (chord * mid.cos(), chord * mid.sin(), dth)
}

pub use pushbot_world::body::switch;

/// Which switches a press at `angle` (rad, relative to the heading, counter-clockwise, so
/// positive is the robot's left) closes. The bumper covers the front half: the centre switch
/// closes for presses within ±35° of straight ahead, the left one from +15° to +100°, the right
/// one from −100° to −15° (the overlaps close two switches); presses further back close none.
pub fn switches_for_angle(angle: f64) -> u8 {
    let a = wrap_angle(angle).to_degrees();
    let mut bits = 0;
    if a.abs() <= 35.0 {
        bits |= switch::CENTRE;
    }
    if (15.0..=100.0).contains(&a) {
        bits |= switch::LEFT;
    }
    if (-100.0..=-15.0).contains(&a) {
        bits |= switch::RIGHT;
    }
    bits
}

/// The switches' contacts bounce: for a while after a change the raw bit reads at random.
#[derive(Clone, Debug, Default)]
pub struct BumperSwitches {
    /// The last settled state of each switch (bits).
    settled: u8,
    /// Until when (µs) each switch bounces.
    bounce_until_us: [u64; 3],
    /// Longest bounce after a change, µs (0 = clean switches).
    pub max_bounce_us: u64,
}

impl BumperSwitches {
    /// Switches that bounce for up to `max_bounce_us` after each change.
    pub fn new(max_bounce_us: u64) -> Self {
        BumperSwitches {
            max_bounce_us,
            ..Default::default()
        }
    }

    /// The raw bits at time `now_us` when the contacts are pressed as `pressed`.
    pub fn read(&mut self, now_us: u64, pressed: u8, rng: &mut impl Rng) -> u8 {
        let mut raw = 0;
        for (i, until) in self.bounce_until_us.iter_mut().enumerate() {
            let bit = 1u8 << i;
            if (pressed ^ self.settled) & bit != 0 {
                self.settled ^= bit;
                if self.max_bounce_us > 0 {
                    *until = now_us + rng.random_range(0..=self.max_bounce_us);
                }
            }
            let on = if now_us < *until {
                rng.random_bool(0.5)
            } else {
                self.settled & bit != 0
            };
            if on {
                raw |= bit;
            }
        }
        raw
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Kinematics round-trip, and the arc displacement of a full circle closes.
    #[test]
    fn kinematics_consistent() {
        let (v, w) = twist_from_wheels(wheels_from_twist(0.2, 1.5, 0.07), 0.07);
        assert!((v - 0.2).abs() < 1e-12 && (w - 1.5).abs() < 1e-12);
        // Integrate a full circle in 1000 arc steps: back to the start.
        let (mut x, mut y, mut th) = (0.0, 0.0, 0.3);
        let period = 2.0 * PI / 1.5;
        for _ in 0..1000 {
            let (dx, dy, dth) = arc_displacement(th, 0.2, 1.5, period / 1000.0);
            x += dx;
            y += dy;
            th += dth;
        }
        assert!(x.abs() < 1e-9 && y.abs() < 1e-9, "{x} {y}");
        // Quarter circle of radius v/ω from heading 0 ends at (R, R).
        let r = 0.2 / 1.5;
        let (dx, dy, _) = arc_displacement(0.0, 0.2, 1.5, PI / 2.0 / 1.5);
        assert!((dx - r).abs() < 1e-12 && (dy - r).abs() < 1e-12);
    }

    /// Switch sectors: front centre, both sides, overlaps, nothing behind.
    #[test]
    fn switch_sectors() {
        assert_eq!(switches_for_angle(0.0), switch::CENTRE);
        assert_eq!(switches_for_angle(60f64.to_radians()), switch::LEFT);
        assert_eq!(switches_for_angle(-60f64.to_radians()), switch::RIGHT);
        assert_eq!(
            switches_for_angle(25f64.to_radians()),
            switch::LEFT | switch::CENTRE
        );
        assert_eq!(switches_for_angle(PI), 0);
        assert_eq!(switches_for_angle(2.0 * PI), switch::CENTRE);
    }
}

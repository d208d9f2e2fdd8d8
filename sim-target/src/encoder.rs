//! A quadrature wheel encoder: the wheel angle quantised to counts, wrapping like a hardware
//! counter, with rare seeded read glitches.

use rand::Rng;

/// One wheel's encoder.
#[derive(Clone, Debug)]
pub struct Encoder {
    /// Counts per wheel revolution after quadrature decoding.
    pub cpr: u32,
    /// Probability that one reading is off by ±1 count (a glitch on the A/B lines).
    pub jitter_probability: f64,
    /// Counter value at wheel angle 0 (a hardware counter does not start at a known count).
    pub offset: i64,
}

impl Encoder {
    /// An encoder of `cpr` counts per revolution.
    pub fn new(cpr: u32, jitter_probability: f64, offset: i64) -> Self {
        Encoder {
            cpr,
            jitter_probability,
            offset,
        }
    }

    /// The exact count for a wheel angle (rad): `floor(angle·cpr/2π)`.
    pub fn counts(&self, angle: f64) -> i64 {
        let c = (angle * f64::from(self.cpr) / std::f64::consts::TAU).floor();
        // Saturating float → int; irrelevant in practice (2^63 counts).
        c as i64
    }

    /// What the firmware reads: the count plus offset, sometimes off by one, wrapped to `i32`.
    pub fn read(&self, angle: f64, rng: &mut impl Rng) -> i32 {
        let mut c = self.counts(angle).wrapping_add(self.offset);
        if self.jitter_probability > 0.0 && rng.random_bool(self.jitter_probability.min(1.0)) {
            c = c.wrapping_add(if rng.random_bool(0.5) { 1 } else { -1 });
        }
        // Wrap like a 32-bit hardware counter.
        c as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// Counts are the floor of the angle in counts, and differences wrap like i32.
    #[test]
    fn quantises_and_wraps() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let e = Encoder::new(1400, 0.0, i64::from(i32::MAX) - 10);
        let step = std::f64::consts::TAU / 1400.0;
        assert_eq!(e.counts(step * 2.5), 2);
        assert_eq!(e.counts(-step * 0.5), -1);
        let a = e.read(0.0, &mut rng);
        let b = e.read(step * 20.5, &mut rng);
        assert_eq!(b.wrapping_sub(a), 20);
        assert!(b < a, "the counter wrapped");
    }
}

//! Bumper switch debouncing and contact edges.
//!
//! Each switch is debounced on its own: a raw change counts once the switch has held its new
//! state for the debounce time; shorter glitches are ignored. A closing edge of the debounced
//! state is a contact.

/// Number of bumper switches (bit 0 left, 1 centre, 2 right).
pub const SWITCHES: usize = 3;

/// Mask of the bumper bits that exist.
pub const MASK: u8 = (1 << SWITCHES) - 1;

/// A debounced closing edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Contact {
    /// Switches that closed at this edge.
    pub closed: u8,
    /// The whole debounced state after the edge.
    pub state: u8,
}

/// Debouncer for the bumper switches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Debouncer {
    debounce_us: u64,
    state: u8,
    /// Per switch: raw value differing from `state` since this time.
    pending_since: [Option<u64>; SWITCHES],
}

impl Debouncer {
    /// All switches open; a change must hold `debounce_us` to count.
    pub fn new(debounce_us: u32) -> Self {
        Debouncer {
            debounce_us: u64::from(debounce_us),
            state: 0,
            pending_since: [None; SWITCHES],
        }
    }

    /// The debounced switch state.
    pub fn state(&self) -> u8 {
        self.state
    }

    /// Sample the raw switches at `now_us`; returns the closing edge if switches closed.
    pub fn update(&mut self, now_us: u64, raw: u8) -> Option<Contact> {
        let raw = raw & MASK;
        let mut closed = 0u8;
        for (bit, since) in self.pending_since.iter_mut().enumerate() {
            let m = 1u8 << bit;
            if raw & m == self.state & m {
                *since = None;
                continue;
            }
            let t0 = *since.get_or_insert(now_us);
            if now_us.saturating_sub(t0) >= self.debounce_us {
                *since = None;
                self.state ^= m;
                if self.state & m != 0 {
                    closed |= m;
                }
            }
        }
        (closed != 0).then_some(Contact {
            closed,
            state: self.state,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glitch_of_one_ms_is_ignored() {
        let mut d = Debouncer::new(5_000);
        for t in 0..100u64 {
            let raw = if (20..21).contains(&t) { 0b010 } else { 0 };
            assert_eq!(d.update(t * 1000, raw), None, "at {t} ms");
        }
        assert_eq!(d.state(), 0);
    }

    #[test]
    fn held_contact_counts_once_after_debounce() {
        let mut d = Debouncer::new(5_000);
        let mut edges = Vec::new();
        for t in 0..100u64 {
            let raw = if t >= 10 { 0b001 } else { 0 };
            if let Some(c) = d.update(t * 1000, raw) {
                edges.push((t, c));
            }
        }
        assert_eq!(
            edges,
            vec![(
                15,
                Contact {
                    closed: 1,
                    state: 1
                }
            )]
        );
    }

    #[test]
    fn bouncing_then_release_and_reclose() {
        let mut d = Debouncer::new(5_000);
        let mut n = 0;
        for t in 0..200u64 {
            let raw = match t {
                10..=12 => (t % 2) as u8 * 4, // bounce
                13..=60 => 4,
                61..=100 => 0,
                101..=200 => 4,
                _ => 0,
            };
            if d.update(t * 1000, raw | 0b1000_0000).is_some() {
                n += 1;
            }
        }
        assert_eq!(n, 2, "two closing edges");
        assert_eq!(d.state(), 4);
    }
}

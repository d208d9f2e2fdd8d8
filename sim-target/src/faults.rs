//! Link faults between the host and the simulated robot, both directions, seeded: dropped
//! bytes, corrupted bytes (one random bit flipped), delayed bursts (order kept), and periodic
//! link cuts during which every byte is lost. Times are simulated time.

use std::collections::VecDeque;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// What goes wrong on the link, and how often.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkFaults {
    /// Probability that a byte is lost.
    pub drop: f64,
    /// Probability that a byte has one bit flipped.
    pub corrupt: f64,
    /// Each burst of bytes is held for a delay drawn uniformly from 0..=`max_delay_us`.
    pub max_delay_us: u64,
    /// The link is cut for `cut_for_us` at the end of every `cut_every_us` (0 = never).
    pub cut_every_us: u64,
    /// Length of each cut.
    pub cut_for_us: u64,
}

impl Default for LinkFaults {
    /// The `--faults` profile: 0.1 % drops, 0.1 % corruptions, up to 20 ms delay, and a
    /// 300 ms cut every 10 s.
    fn default() -> Self {
        LinkFaults {
            drop: 1e-3,
            corrupt: 1e-3,
            max_delay_us: 20_000,
            cut_every_us: 10_000_000,
            cut_for_us: 300_000,
        }
    }
}

impl LinkFaults {
    /// Whether the link is cut at `now_us`.
    pub fn cut(&self, now_us: u64) -> bool {
        self.cut_every_us > 0
            && self.cut_for_us > 0
            && now_us % self.cut_every_us >= self.cut_every_us.saturating_sub(self.cut_for_us)
    }
}

/// One direction of a faulty link.
#[derive(Clone, Debug)]
struct Direction {
    queue: VecDeque<(u64, u8)>,
    last_due: u64,
}

/// Both directions of a faulty link.
#[derive(Clone, Debug)]
pub struct FaultyLink {
    cfg: LinkFaults,
    rng: ChaCha8Rng,
    to_robot: Direction,
    to_host: Direction,
    /// Bytes lost so far (dropped or cut).
    pub dropped: u64,
    /// Bytes corrupted so far.
    pub corrupted: u64,
}

impl FaultyLink {
    /// A link with these faults, drawing from `seed` (its own stream).
    pub fn new(cfg: LinkFaults, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(2);
        let d = || Direction {
            queue: VecDeque::new(),
            last_due: 0,
        };
        FaultyLink {
            cfg,
            rng,
            to_robot: d(),
            to_host: d(),
            dropped: 0,
            corrupted: 0,
        }
    }

    /// Bytes the host sent at `now_us`.
    pub fn from_host(&mut self, now_us: u64, bytes: &[u8]) {
        self.enqueue(true, now_us, bytes);
    }

    /// Bytes the robot sent at `now_us`.
    pub fn from_robot(&mut self, now_us: u64, bytes: &[u8]) {
        self.enqueue(false, now_us, bytes);
    }

    /// Bytes that reach the robot by `now_us`.
    pub fn to_robot(&mut self, now_us: u64, out: &mut Vec<u8>) {
        deliver(&mut self.to_robot, now_us, out);
    }

    /// Bytes that reach the host by `now_us`.
    pub fn to_host(&mut self, now_us: u64, out: &mut Vec<u8>) {
        deliver(&mut self.to_host, now_us, out);
    }

    fn enqueue(&mut self, to_robot: bool, now_us: u64, bytes: &[u8]) {
        if bytes.is_empty() {
            return;
        }
        let delay = if self.cfg.max_delay_us > 0 {
            self.rng.random_range(0..=self.cfg.max_delay_us)
        } else {
            0
        };
        let cut = self.cfg.cut(now_us);
        let dir = if to_robot {
            &mut self.to_robot
        } else {
            &mut self.to_host
        };
        // Keep the order: a burst never overtakes the one before.
        let due = (now_us + delay).max(dir.last_due);
        dir.last_due = due;
        for &b in bytes {
            if cut || (self.cfg.drop > 0.0 && self.rng.random_bool(self.cfg.drop.min(1.0))) {
                self.dropped += 1;
                continue;
            }
            let mut b = b;
            if self.cfg.corrupt > 0.0 && self.rng.random_bool(self.cfg.corrupt.min(1.0)) {
                b ^= 1 << self.rng.random_range(0..8);
                self.corrupted += 1;
            }
            dir.queue.push_back((due, b));
        }
    }
}

fn deliver(dir: &mut Direction, now_us: u64, out: &mut Vec<u8>) {
    while let Some(&(due, b)) = dir.queue.front() {
        if due > now_us {
            break;
        }
        out.push(b);
        dir.queue.pop_front();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without faults every byte arrives in order at once; with drops about the expected share
    /// is lost; during a cut everything is; delays keep order and hold bytes back.
    #[test]
    fn faults_behave_as_configured() {
        let none = LinkFaults {
            drop: 0.0,
            corrupt: 0.0,
            max_delay_us: 0,
            cut_every_us: 0,
            cut_for_us: 0,
        };
        let data: Vec<u8> = (0..=255).collect();
        let mut l = FaultyLink::new(none, 1);
        l.from_host(0, &data);
        let mut out = Vec::new();
        l.to_robot(0, &mut out);
        assert_eq!(out, data);

        let mut l = FaultyLink::new(LinkFaults { drop: 0.1, ..none }, 1);
        for t in 0..100 {
            l.from_robot(t, &data);
        }
        let mut out = Vec::new();
        l.to_host(100, &mut out);
        let lost = 25_600 - out.len();
        assert!((2_000..3_200).contains(&lost), "{lost}");
        assert_eq!(l.dropped as usize, lost);

        let cut = LinkFaults {
            cut_every_us: 1000,
            cut_for_us: 100,
            ..none
        };
        let mut l = FaultyLink::new(cut, 1);
        l.from_host(950, &data);
        l.from_host(1050, &data);
        let mut out = Vec::new();
        l.to_robot(2000, &mut out);
        assert_eq!(out, data, "only the burst outside the cut arrives");

        let mut l = FaultyLink::new(
            LinkFaults {
                max_delay_us: 500,
                ..none
            },
            3,
        );
        let mut out = Vec::new();
        for t in 0..50u64 {
            l.from_host(t * 10, &[t as u8]);
            l.to_robot(t * 10, &mut out);
        }
        l.to_robot(10_000, &mut out);
        assert_eq!(out, (0..50).collect::<Vec<u8>>());
    }
}

//! Link faults between the host and the simulated robot, both directions, seeded: dropped
//! bytes, corrupted bytes (one random bit flipped), inserted garbage, lost and duplicated
//! frames, delayed bursts (order kept), and link cuts during which every byte is lost. Times
//! are simulated time. Each direction is a sans-IO [`FaultPipe`] (`crate::fault_pipe`).

pub use crate::fault_pipe::{FaultPipe, LinkFaults, PipeStats};

/// Both directions of a faulty link: one [`FaultPipe`] each, on their own streams of the seed.
#[derive(Clone, Debug)]
pub struct FaultyLink {
    to_robot: FaultPipe,
    to_host: FaultPipe,
}

impl FaultyLink {
    /// A link with these faults, drawing from `seed` (streams of their own).
    pub fn new(cfg: LinkFaults, seed: u64) -> Self {
        FaultyLink {
            to_robot: FaultPipe::new(cfg, seed, 2),
            to_host: FaultPipe::new(cfg, seed, 3),
        }
    }

    /// Bytes the host sent at `now_us`.
    pub fn from_host(&mut self, now_us: u64, bytes: &[u8]) {
        self.to_robot.push(now_us, bytes);
    }

    /// Bytes the robot sent at `now_us`.
    pub fn from_robot(&mut self, now_us: u64, bytes: &[u8]) {
        self.to_host.push(now_us, bytes);
    }

    /// Bytes that reach the robot by `now_us`.
    pub fn to_robot(&mut self, now_us: u64, out: &mut Vec<u8>) {
        self.to_robot.pull(now_us, out);
    }

    /// Bytes that reach the host by `now_us`.
    pub fn to_host(&mut self, now_us: u64, out: &mut Vec<u8>) {
        self.to_host.pull(now_us, out);
    }

    /// Cut both directions from `now_us` for `len_us`.
    pub fn cut_for(&mut self, now_us: u64, len_us: u64) {
        self.to_robot.cut_for(now_us, len_us);
        self.to_host.cut_for(now_us, len_us);
    }

    /// What each direction did so far: (host → robot, robot → host).
    pub fn stats(&self) -> (PipeStats, PipeStats) {
        (self.to_robot.stats(), self.to_host.stats())
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
            garbage: 0.0,
            frame_loss: 0.0,
            duplicate: 0.0,
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
        assert_eq!(l.stats().1.dropped as usize, lost);

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

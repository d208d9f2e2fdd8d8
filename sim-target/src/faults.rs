//! Link faults between the host and the simulated robot, both directions, seeded: dropped
//! bytes, corrupted bytes (one random bit flipped), inserted garbage, lost and duplicated
//! frames, delayed bursts (order kept), and link cuts during which every byte is lost. Times
//! are simulated time. Each direction is a sans-IO [`FaultPipe`] (`crate::fault_pipe`).

pub use crate::fault_pipe::{FaultPipe, LinkFaults, PipeStats};

/// The link-fault flags, as `pushbot-sim` and `pushbot demo` take them (`--faults` and its
/// `--fault-*` refinements): flatten into a clap parser, then [`FaultArgs::link_faults`].
#[derive(clap::Args, Debug, Clone, Default, PartialEq)]
pub struct FaultArgs {
    /// Inject link faults (seeded): the default profile is 0.1 % dropped and 0.1 % corrupted
    /// bytes, bursts delayed up to 20 ms, and a 300 ms cut every 10 s of simulated time.
    #[arg(long)]
    pub faults: bool,
    /// With --faults: probability that a byte is dropped.
    #[arg(long, value_name = "P", requires = "faults")]
    pub fault_drop: Option<f64>,
    /// With --faults: probability that a byte has a bit flipped.
    #[arg(long, value_name = "P", requires = "faults")]
    pub fault_corrupt: Option<f64>,
    /// With --faults: probability that a random byte is inserted before a byte (garbage).
    #[arg(long, value_name = "P", requires = "faults")]
    pub fault_garbage: Option<f64>,
    /// With --faults: probability that a whole frame (up to its 0x00 delimiter) is lost.
    #[arg(long, value_name = "P", requires = "faults")]
    pub fault_frame_loss: Option<f64>,
    /// With --faults: probability that a frame is delivered twice.
    #[arg(long, value_name = "P", requires = "faults")]
    pub fault_duplicate: Option<f64>,
    /// With --faults: longest delay of a burst of bytes, ms.
    #[arg(long, value_name = "MS", requires = "faults")]
    pub fault_delay_ms: Option<f64>,
    /// With --faults: cut the link every this many seconds of simulated time (0 = never)…
    #[arg(long, value_name = "S", requires = "faults")]
    pub fault_cut_every: Option<f64>,
    /// …for this many seconds.
    #[arg(long, value_name = "S", requires = "faults")]
    pub fault_cut_for: Option<f64>,
}

impl FaultArgs {
    /// The faults these flags ask for (`None` without `--faults`), or what is wrong with them.
    pub fn link_faults(&self) -> Result<Option<LinkFaults>, String> {
        if !self.faults {
            return Ok(None);
        }
        let prob = |name: &str, p: Option<f64>, default: f64| match p {
            None => Ok(default),
            Some(p) if (0.0..=1.0).contains(&p) => Ok(p),
            Some(p) => Err(format!("--{name} must be a probability in 0..=1, not {p}")),
        };
        let dur = |name: &str, s: Option<f64>, scale: f64, default: u64| match s {
            None => Ok(default),
            Some(s) if s.is_finite() && s >= 0.0 && s * scale < 1e15 => Ok((s * scale) as u64),
            Some(s) => Err(format!("--{name} must be a duration ≥ 0, not {s}")),
        };
        let d = LinkFaults::default();
        Ok(Some(LinkFaults {
            drop: prob("fault-drop", self.fault_drop, d.drop)?,
            corrupt: prob("fault-corrupt", self.fault_corrupt, d.corrupt)?,
            garbage: prob("fault-garbage", self.fault_garbage, d.garbage)?,
            frame_loss: prob("fault-frame-loss", self.fault_frame_loss, d.frame_loss)?,
            duplicate: prob("fault-duplicate", self.fault_duplicate, d.duplicate)?,
            max_delay_us: dur("fault-delay-ms", self.fault_delay_ms, 1e3, d.max_delay_us)?,
            cut_every_us: dur("fault-cut-every", self.fault_cut_every, 1e6, d.cut_every_us)?,
            cut_for_us: dur("fault-cut-for", self.fault_cut_for, 1e6, d.cut_for_us)?,
        }))
    }
}

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
        let none = LinkFaults::NONE;
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

//! One direction of a faulty wire as a sans-IO, seeded byte pipe: bytes go in with
//! [`FaultPipe::push`] at a time `now` (µs, any monotonic clock the caller keeps) and come out
//! with [`FaultPipe::pull`] once due. It owns no clock, thread or port, so the same pipe sits
//! between the host's link client and the in-process target and behind `pushbot-sim --faults`.
//!
//! | fault | unit | what happens |
//! |---|---|---|
//! | `drop` | byte | lost |
//! | `corrupt` | byte | one random bit flipped |
//! | `garbage` | byte | a random byte inserted before it (a zero too: it may split a frame) |
//! | `frame_loss` | frame | the whole frame lost |
//! | `duplicate` | frame | the frame delivered twice in a row |
//! | `max_delay_us` | write | the write is held 0..=`max_delay_us`, never overtaking the one before |
//! | cuts | time | every byte written during a cut is lost ([`LinkFaults::cut`], [`FaultPipe::cut_for`]) |
//!
//! Frames are delimited by `0x00` (COBS). Only when a frame fault is asked for does the pipe
//! hold bytes until their frame's delimiter (at most [`MAX_HELD`] bytes, then they go as they
//! are); otherwise every byte is judged on its own as it arrives.

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
    /// Probability that a random byte is inserted before a byte.
    pub garbage: f64,
    /// Probability that a whole frame (up to its `0x00` delimiter) is lost.
    pub frame_loss: f64,
    /// Probability that a frame is delivered twice.
    pub duplicate: f64,
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
            garbage: 0.0,
            frame_loss: 0.0,
            duplicate: 0.0,
            max_delay_us: 20_000,
            cut_every_us: 10_000_000,
            cut_for_us: 300_000,
        }
    }
}

impl LinkFaults {
    /// A clean wire: no fault at all (what a pipe is before its faults are switched on).
    pub const NONE: LinkFaults = LinkFaults {
        drop: 0.0,
        corrupt: 0.0,
        garbage: 0.0,
        frame_loss: 0.0,
        duplicate: 0.0,
        max_delay_us: 0,
        cut_every_us: 0,
        cut_for_us: 0,
    };

    /// Whether the link is cut at `now_us`.
    pub fn cut(&self, now_us: u64) -> bool {
        self.cut_every_us > 0
            && self.cut_for_us > 0
            && now_us % self.cut_every_us >= self.cut_every_us.saturating_sub(self.cut_for_us)
    }
}

/// The most bytes held while waiting for a frame's delimiter.
pub const MAX_HELD: usize = 1024;

/// What one pipe did so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PipeStats {
    /// Bytes written into the pipe.
    pub bytes_in: u64,
    /// Bytes lost one by one (`drop`).
    pub dropped: u64,
    /// Bytes lost to cuts.
    pub cut: u64,
    /// Bytes with a bit flipped.
    pub corrupted: u64,
    /// Random bytes inserted.
    pub garbage: u64,
    /// Whole frames lost.
    pub frames_lost: u64,
    /// Frames delivered twice.
    pub frames_duplicated: u64,
}

/// One direction of a faulty wire. See the module docs.
#[derive(Clone, Debug)]
pub struct FaultPipe {
    cfg: LinkFaults,
    rng: ChaCha8Rng,
    queue: VecDeque<(u64, u8)>,
    last_due: u64,
    held: Vec<u8>,
    /// A cut asked for: from, until (µs).
    cut: (u64, u64),
    stats: PipeStats,
}

impl FaultPipe {
    /// A pipe with these faults, drawing from `seed` on its own `stream` (give each direction
    /// its own).
    pub fn new(cfg: LinkFaults, seed: u64, stream: u64) -> FaultPipe {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(stream);
        FaultPipe {
            cfg,
            rng,
            queue: VecDeque::new(),
            last_due: 0,
            held: Vec::new(),
            cut: (0, 0),
            stats: PipeStats::default(),
        }
    }

    /// The faults.
    pub fn faults(&self) -> &LinkFaults {
        &self.cfg
    }

    /// What the pipe did so far.
    pub fn stats(&self) -> PipeStats {
        self.stats
    }

    /// Cut the wire from `now_us` for `len_us`: everything written meanwhile is lost.
    pub fn cut_for(&mut self, now_us: u64, len_us: u64) {
        let until = now_us.saturating_add(len_us);
        self.cut = if self.is_cut(now_us) && self.cut.1 > now_us {
            (self.cut.0, self.cut.1.max(until))
        } else {
            (now_us, until)
        };
    }

    /// Whether the wire is cut at `now_us` (periodic or [`FaultPipe::cut_for`]).
    pub fn is_cut(&self, now_us: u64) -> bool {
        (self.cut.0..self.cut.1).contains(&now_us) || self.cfg.cut(now_us)
    }

    /// Bytes in flight or held for their frame's end.
    pub fn in_flight(&self) -> usize {
        self.queue.len() + self.held.len()
    }

    fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.rng.random_bool(p.min(1.0))
    }

    fn frames(&self) -> bool {
        self.cfg.frame_loss > 0.0 || self.cfg.duplicate > 0.0
    }

    /// Bytes written into the pipe at `now_us`.
    pub fn push(&mut self, now_us: u64, bytes: &[u8]) {
        if bytes.is_empty() {
            return;
        }
        self.stats.bytes_in += bytes.len() as u64;
        let delay = if self.cfg.max_delay_us > 0 {
            self.rng.random_range(0..=self.cfg.max_delay_us)
        } else {
            0
        };
        // Keep the order: a write never overtakes the one before.
        let due = (now_us + delay).max(self.last_due);
        self.last_due = due;
        if self.is_cut(now_us) {
            self.stats.cut += bytes.len() as u64;
            return;
        }
        if !self.frames() {
            let mut out = Vec::with_capacity(bytes.len());
            self.mangle(bytes, &mut out);
            self.queue.extend(out.into_iter().map(|b| (due, b)));
            return;
        }
        for &b in bytes {
            self.held.push(b);
            if b == 0 || self.held.len() >= MAX_HELD {
                let frame = std::mem::take(&mut self.held);
                self.frame(due, &frame);
            }
        }
    }

    /// A whole frame (with its delimiter) leaves for the other end, due at `due`.
    fn frame(&mut self, due: u64, frame: &[u8]) {
        if self.chance(self.cfg.frame_loss) {
            self.stats.frames_lost += 1;
            return;
        }
        let mut out = Vec::with_capacity(frame.len() + 4);
        self.mangle(frame, &mut out);
        let copies = if self.chance(self.cfg.duplicate) {
            self.stats.frames_duplicated += 1;
            2
        } else {
            1
        };
        for _ in 0..copies {
            self.queue.extend(out.iter().map(|&b| (due, b)));
        }
    }

    /// The byte faults: garbage before a byte, the byte dropped, or a bit of it flipped.
    fn mangle(&mut self, bytes: &[u8], out: &mut Vec<u8>) {
        for &b in bytes {
            if self.chance(self.cfg.garbage) {
                out.push(self.rng.random());
                self.stats.garbage += 1;
            }
            if self.chance(self.cfg.drop) {
                self.stats.dropped += 1;
                continue;
            }
            let mut b = b;
            if self.chance(self.cfg.corrupt) {
                b ^= 1 << self.rng.random_range(0..8);
                self.stats.corrupted += 1;
            }
            out.push(b);
        }
    }

    /// Append the bytes due by `now_us` to `out`, in order.
    pub fn pull(&mut self, now_us: u64, out: &mut Vec<u8>) {
        while let Some(&(due, b)) = self.queue.front() {
            if due > now_us {
                break;
            }
            out.push(b);
            self.queue.pop_front();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NONE: LinkFaults = LinkFaults::NONE;

    /// 1000 frames of 9 bytes: bytes 1..=8 then the delimiter.
    fn frames() -> Vec<u8> {
        (0..1000u32)
            .flat_map(|i| {
                let mut f: Vec<u8> = (1..=8).map(|k| ((i + k) % 255 + 1) as u8).collect();
                f.push(0);
                f
            })
            .collect()
    }

    fn run(cfg: LinkFaults, seed: u64, data: &[u8]) -> (Vec<u8>, PipeStats) {
        let mut p = FaultPipe::new(cfg, seed, 2);
        for (t, chunk) in data.chunks(9).enumerate() {
            p.push(t as u64 * 10, chunk);
        }
        let mut out = Vec::new();
        p.pull(u64::MAX, &mut out);
        (out, p.stats())
    }

    fn split(bytes: &[u8]) -> Vec<&[u8]> {
        bytes.split_inclusive(|&b| b == 0).collect()
    }

    #[test]
    fn without_faults_every_byte_arrives_in_order() {
        let data = frames();
        let (out, s) = run(NONE, 1, &data);
        assert_eq!(out, data);
        assert_eq!(s.bytes_in, data.len() as u64);
    }

    #[test]
    fn drops_lose_about_their_share_of_bytes() {
        let data = frames();
        let (out, s) = run(LinkFaults { drop: 0.1, ..NONE }, 1, &data);
        let lost = data.len() - out.len();
        assert!((700..1100).contains(&lost), "{lost}");
        assert_eq!(s.dropped as usize, lost);
    }

    #[test]
    fn bit_flips_change_one_bit_of_a_byte() {
        let data = frames();
        let (out, s) = run(
            LinkFaults {
                corrupt: 0.05,
                ..NONE
            },
            2,
            &data,
        );
        assert_eq!(out.len(), data.len());
        let diffs: Vec<u32> = data
            .iter()
            .zip(&out)
            .map(|(a, b)| (a ^ b).count_ones())
            .filter(|&n| n > 0)
            .collect();
        assert!(diffs.iter().all(|&n| n == 1));
        assert_eq!(diffs.len() as u64, s.corrupted);
        assert!((300..600).contains(&diffs.len()), "{}", diffs.len());
    }

    #[test]
    fn garbage_inserts_bytes_and_keeps_the_rest() {
        let data = frames();
        let (out, s) = run(
            LinkFaults {
                garbage: 0.02,
                ..NONE
            },
            3,
            &data,
        );
        assert_eq!(out.len() - data.len(), s.garbage as usize);
        assert!((100..260).contains(&s.garbage), "{}", s.garbage);
        // The original bytes are a subsequence of what arrived.
        let mut it = out.iter();
        assert!(data.iter().all(|b| it.any(|o| o == b)));
    }

    #[test]
    fn frame_loss_loses_whole_frames_only() {
        let data = frames();
        let (out, s) = run(
            LinkFaults {
                frame_loss: 0.2,
                ..NONE
            },
            4,
            &data,
        );
        let sent = split(&data);
        let got = split(&out);
        assert_eq!(got.len() as u64 + s.frames_lost, 1000);
        assert!((150..250).contains(&s.frames_lost), "{}", s.frames_lost);
        // What arrived are whole frames, in order.
        let mut it = sent.iter();
        assert!(got.iter().all(|g| it.any(|f| f == g)));
    }

    #[test]
    fn duplicates_arrive_twice_in_a_row() {
        let data = frames();
        let (out, s) = run(
            LinkFaults {
                duplicate: 0.1,
                ..NONE
            },
            5,
            &data,
        );
        let got = split(&out);
        assert_eq!(got.len() as u64, 1000 + s.frames_duplicated);
        assert!((60..140).contains(&s.frames_duplicated));
        let mut deduped = got.clone();
        deduped.dedup();
        assert_eq!(deduped, split(&data));
    }

    #[test]
    fn delayed_writes_keep_their_order_and_are_held() {
        let mut p = FaultPipe::new(
            LinkFaults {
                max_delay_us: 500,
                ..NONE
            },
            6,
            2,
        );
        let mut out = Vec::new();
        for t in 0..100u64 {
            p.push(t * 10, &[t as u8]);
            p.pull(t * 10, &mut out);
        }
        assert!(out.len() < 100, "some bytes are still held");
        p.pull(10_000, &mut out);
        assert_eq!(out, (0..100).collect::<Vec<u8>>());
    }

    #[test]
    fn cuts_lose_everything_written_meanwhile() {
        let periodic = LinkFaults {
            cut_every_us: 1000,
            cut_for_us: 100,
            ..NONE
        };
        let mut p = FaultPipe::new(periodic, 7, 2);
        p.push(950, &[1, 2, 0]);
        p.push(1050, &[3, 4, 0]);
        let mut out = Vec::new();
        p.pull(2000, &mut out);
        assert_eq!(out, [3, 4, 0]);
        assert_eq!(p.stats().cut, 3);

        let mut p = FaultPipe::new(NONE, 7, 2);
        p.cut_for(5_000, 250);
        p.push(4_999, &[1]);
        p.push(5_000, &[2]);
        p.push(5_249, &[3]);
        p.push(5_250, &[4]);
        let mut out = Vec::new();
        p.pull(u64::MAX, &mut out);
        assert_eq!(out, [1, 4]);
    }

    #[test]
    fn the_same_seed_gives_the_same_faults() {
        let cfg = LinkFaults {
            drop: 0.01,
            corrupt: 0.01,
            garbage: 0.01,
            frame_loss: 0.05,
            duplicate: 0.05,
            max_delay_us: 30,
            cut_every_us: 0,
            cut_for_us: 0,
        };
        let data = frames();
        assert_eq!(run(cfg, 9, &data), run(cfg, 9, &data));
        assert_ne!(run(cfg, 9, &data).0, run(cfg, 10, &data).0);
    }
}

//! The wave front of the cost mapping phase (Ben-Shahar & Rivlin §IV-A1) as a Dial queue: a ring
//! of `max_edge + 1` buckets of packed indices, one per cost modulo the ring's length, swept one
//! bucket at a time by every core.
//!
//! Every move costs at least 1 and at most `max_edge`, so while bucket `c` is swept nothing is
//! pushed into it: its contents are fixed, and its indices can be split among the cores, each of
//! which pushes the origins it relaxes into the *other* buckets. Two shapes of bucket:
//! - [`BitRing`]: each bucket a two-level bit set over the whole space (atomic words, so that
//!   two cores may set bits side by side, in pages allocated when first written); inserting is setting a bit, duplicates vanish, and a
//!   bucket is swept in index order for free, so the scattered front visits the cost array in
//!   one forward pass per cost;
//! - [`VecRing`]: each bucket a vector, sorted by index when large; each core collects its pushes
//!   locally and they are appended after the sweep (for metrics with expensive moves, where a
//!   bit set per bucket would outweigh the cost array).

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering::Relaxed};
use std::sync::{Mutex, OnceLock};

use rayon::prelude::*;

use super::problem::PackedIndex;

/// Buckets larger than this are sorted by index before they are swept.
const SORT_MIN: usize = 4096;
/// Indices per task when a vector bucket is swept.
const VEC_TASK: usize = 2048;

/// What the tasks of one sweep did, summed.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct Tally {
    /// Entries swept (stale ones included).
    pub swept: u64,
    /// Entries pushed that were not queued in their bucket yet.
    pub pushed: u64,
    /// States settled.
    pub mapped: u64,
    /// Origins examined.
    pub relaxations: u64,
    /// Some origin's cost would not fit in a `u16`.
    pub overflow: bool,
}

impl Tally {
    fn add(mut self, o: Tally) -> Tally {
        self.swept += o.swept;
        self.pushed += o.pushed;
        self.mapped += o.mapped;
        self.relaxations += o.relaxations;
        self.overflow |= o.overflow;
        self
    }
}

/// A ring of buckets of packed indices `I`, swept on every core.
pub(super) trait Front<I: PackedIndex>: Sync + Sized {
    /// What one task gathers besides its tally (pushes not yet in the ring).
    type Local: Default + Send;
    /// Queue `idx` in bucket `b` (never the bucket being swept).
    fn push(&self, local: &mut Self::Local, tally: &mut Tally, b: usize, idx: I);
    /// Put what a task gathered into the ring.
    fn absorb(&mut self, local: Self::Local);
    /// Sweep bucket `b` on every core, calling `f` on each of its indices, and empty it.
    fn sweep<G>(&mut self, b: usize, f: G) -> Tally
    where
        G: Fn(I, &Self, &mut Self::Local, &mut Tally, &mut Vec<(I, u32)>) + Sync;
    /// Most bytes the ring held.
    fn peak_bytes(&self) -> u64;
}

/// Words of one page of a bit-set bucket (4 KiB): pages are taken when first written and given
/// back when their bucket is swept, so the parts of the space the wave front never reaches take
/// no memory, and the ring holds only the pages of the costs still queued.
const PAGE_WORDS: usize = 512;

/// One bit-set bucket: `pages` hold one bit per index, `summary` one bit per non-zero word.
#[derive(Default)]
struct BitBucket {
    pages: Vec<OnceLock<Page>>,
    summary: Vec<AtomicU64>,
}

/// A page of a bit-set bucket.
type Page = Box<[AtomicU64]>;

/// Buckets as two-level bit sets over the whole space, with the pages they share.
pub(super) struct BitRing {
    buckets: Vec<BitBucket>,
    /// Swept pages (all words zero again), reused before new ones are allocated.
    spare: Mutex<Vec<Page>>,
    /// Pages allocated so far: the ring's memory never exceeds them.
    allocated: AtomicUsize,
}

impl BitRing {
    /// `ring` empty buckets over `n` indices.
    pub fn new(ring: usize, n: usize) -> BitRing {
        let nw = n.div_ceil(64);
        BitRing {
            buckets: (0..ring)
                .map(|_| BitBucket {
                    pages: (0..nw.div_ceil(PAGE_WORDS))
                        .map(|_| OnceLock::new())
                        .collect(),
                    summary: (0..nw.div_ceil(64)).map(|_| AtomicU64::new(0)).collect(),
                })
                .collect(),
            spare: Mutex::new(Vec::new()),
            allocated: AtomicUsize::new(0),
        }
    }

    /// A zero page: a swept one if any, else a new one.
    fn take_page(&self) -> Page {
        let reused = self.spare.lock().map(|mut s| s.pop()).unwrap_or(None);
        reused.unwrap_or_else(|| {
            self.allocated.fetch_add(1, Relaxed);
            (0..PAGE_WORDS).map(|_| AtomicU64::new(0)).collect()
        })
    }

    /// Most bytes of `ring` buckets over `n` indices (every page written).
    pub fn bytes(ring: usize, n: usize) -> u64 {
        let nw = n.div_ceil(64);
        (ring * (nw + nw.div_ceil(64)) * 8) as u64
    }
}

impl<I: PackedIndex> Front<I> for BitRing {
    type Local = ();
    #[inline]
    fn push(&self, _: &mut (), tally: &mut Tally, b: usize, idx: I) {
        let bucket = &self.buckets[b];
        let idx = idx.as_usize();
        let w = idx >> 6;
        let bit = 1u64 << (idx & 63);
        let word = &bucket.pages[w / PAGE_WORDS].get_or_init(|| self.take_page())[w % PAGE_WORDS];
        if word.load(Relaxed) & bit != 0 {
            return;
        }
        let old = word.fetch_or(bit, Relaxed);
        if old & bit == 0 {
            tally.pushed += 1;
            if old == 0 {
                bucket.summary[w >> 6].fetch_or(1 << (w & 63), Relaxed);
            }
        }
    }
    fn absorb(&mut self, _: ()) {}
    fn sweep<G>(&mut self, b: usize, f: G) -> Tally
    where
        G: Fn(I, &Self, &mut (), &mut Tally, &mut Vec<(I, u32)>) + Sync,
    {
        let mut bucket = std::mem::take(&mut self.buckets[b]);
        let this = &*self;
        let (tally, swept) = bucket
            .summary
            .par_chunks_mut(PAGE_WORDS / 64)
            .zip(bucket.pages.par_iter_mut())
            .enumerate()
            // One page per job: the front of one cost gathers in a few parts of the space, and
            // rayon's adaptive splitting alone would leave such a part to one core.
            .with_max_len(1)
            .map(|(k, (summary, page))| {
                let mut t = Tally::default();
                let Some(mut words) = page.take() else {
                    return (t, None);
                };
                let base = k * PAGE_WORDS * 64;
                let mut local = ();
                let mut origins = Vec::with_capacity(64);
                for (si, s) in summary.iter_mut().enumerate() {
                    let mut sbits = std::mem::take(s.get_mut());
                    while sbits != 0 {
                        let wl = si * 64 + sbits.trailing_zeros() as usize;
                        sbits &= sbits - 1;
                        let mut bits = std::mem::take(words[wl].get_mut());
                        while bits != 0 {
                            let idx =
                                I::from_u64((base + wl * 64) as u64 + bits.trailing_zeros() as u64);
                            bits &= bits - 1;
                            t.swept += 1;
                            f(idx, this, &mut local, &mut t, &mut origins);
                        }
                    }
                }
                (t, Some(words))
            })
            .fold(
                || (Tally::default(), Vec::new()),
                |(t, mut pages), (u, page)| {
                    pages.extend(page);
                    (t.add(u), pages)
                },
            )
            .reduce(
                || (Tally::default(), Vec::new()),
                |(t, mut pages), (u, more)| {
                    pages.extend(more);
                    (t.add(u), pages)
                },
            );
        if let Ok(mut spare) = self.spare.lock() {
            spare.extend(swept);
        }
        self.buckets[b] = bucket;
        tally
    }
    fn peak_bytes(&self) -> u64 {
        let index: usize = self
            .buckets
            .iter()
            .map(|b| b.summary.len() * 8 + b.pages.len() * std::mem::size_of::<OnceLock<Page>>())
            .sum();
        (self.allocated.load(Relaxed) * PAGE_WORDS * 8 + index) as u64
    }
}

/// Buckets as vectors of indices `I`; large ones are sorted before they are swept.
pub(super) struct VecRing<I> {
    buckets: Vec<Vec<I>>,
    peak: u64,
}

impl<I: PackedIndex> VecRing<I> {
    /// `ring` empty buckets.
    pub fn new(ring: usize) -> VecRing<I> {
        VecRing {
            buckets: vec![Vec::new(); ring],
            peak: 0,
        }
    }
}

impl<I: PackedIndex> Front<I> for VecRing<I> {
    /// Pushes of one task: (bucket, index).
    type Local = Vec<(u32, I)>;
    #[inline]
    fn push(&self, local: &mut Vec<(u32, I)>, tally: &mut Tally, b: usize, idx: I) {
        local.push((b as u32, idx));
        tally.pushed += 1;
    }
    fn absorb(&mut self, local: Vec<(u32, I)>) {
        for (b, idx) in local {
            self.buckets[b as usize].push(idx);
        }
    }
    fn sweep<G>(&mut self, b: usize, f: G) -> Tally
    where
        G: Fn(I, &Self, &mut Self::Local, &mut Tally, &mut Vec<(I, u32)>) + Sync,
    {
        let held: usize = self.buckets.iter().map(Vec::capacity).sum();
        let size = std::mem::size_of::<I>() as u64;
        self.peak = self.peak.max(held as u64 * size);
        let mut bucket = std::mem::take(&mut self.buckets[b]);
        // Entries of one cost are scattered over the map; in index order they sweep it once,
        // so the cache misses of the settled-check and of nearby origins are shared.
        if bucket.len() > SORT_MIN {
            bucket.par_sort_unstable();
        }
        let this = &*self;
        let parts: Vec<(Vec<(u32, I)>, Tally)> = bucket
            .par_chunks(VEC_TASK)
            .with_max_len(1)
            .map(|chunk| {
                let mut t = Tally::default();
                let mut local = Vec::new();
                let mut origins = Vec::with_capacity(64);
                for &idx in chunk {
                    t.swept += 1;
                    f(idx, this, &mut local, &mut t, &mut origins);
                }
                (local, t)
            })
            .collect();
        let mut tally = Tally::default();
        let pending: usize = parts.iter().map(|(l, _)| l.len()).sum();
        let entry = std::mem::size_of::<(u32, I)>() as u64;
        self.peak = self.peak.max(held as u64 * size + pending as u64 * entry);
        for (local, t) in parts {
            tally = tally.add(t);
            self.absorb(local);
        }
        bucket.clear();
        self.buckets[b] = bucket;
        tally
    }
    fn peak_bytes(&self) -> u64 {
        self.peak
    }
}

//! The cost mapping phase, Ben-Shahar & Rivlin §IV-A1: a context-sensitive back propagation.
//!
//! A cost wave starts at the *set* of goal configurations (cost 0) and floods only admissible
//! origins N_A⁻¹(Q), each relaxed by D(Q̂, Q), in the order of Dijkstra's algorithm. Costs are
//! integers, so the wave front is a bucket (Dial) queue: a ring of `max_edge + 1` buckets of
//! packed `u32` indices. The map is one `u16` per packed configuration (`u16::MAX` = ∞, which also
//! covers configurations in CCO and trap points: the backward wave never reaches them). A state
//! is settled when it is popped with the cost it holds; stale entries are skipped, so no extra
//! "settled" bit is needed. The map does not depend on the start: any start reuses it (§IV-A2).

use std::time::Instant;

use super::problem::Model;

/// Cost of a configuration the wave never reached (no pushing path, CCO, trap points).
pub const INF: u16 = u16::MAX;

/// Buckets larger than this are sorted by index before they are expanded.
const SORT_MIN: usize = 4096;

/// Numbers about one cost mapping.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct MapStats {
    /// Packed configurations (the map's length).
    pub states_total: u64,
    /// Configurations with a finite cost.
    pub states_mapped: u64,
    /// Goal configurations.
    pub goals: u64,
    /// Origins examined (relaxations tried).
    pub relaxations: u64,
    /// Largest finite cost.
    pub max_cost: u32,
    /// Wall time of the propagation in ms.
    pub map_ms: f64,
    /// Bytes of the cost array and the wave front (bucket queue) at their largest.
    pub map_bytes: u64,
}

/// The mapping of every configuration to the cost of its optimal pushing plan.
#[derive(Debug, Clone)]
pub struct CostMap {
    /// `cost[idx]`, `INF` if no pushing path exists from `idx`.
    pub cost: Vec<u16>,
    /// How the mapping went.
    pub stats: MapStats,
}

/// Why a map could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MapError {
    /// Costs grew past what a `u16` holds.
    #[error("plan costs exceed {max}: the map stores costs as u16; lower the metric weights", max = INF - 1)]
    CostOverflow,
}

impl CostMap {
    /// Cost of a configuration, `None` when infinite.
    pub fn get(&self, idx: u32) -> Option<u32> {
        match self.cost.get(idx as usize) {
            Some(&c) if c != INF => Some(c as u32),
            _ => None,
        }
    }
}

/// Build the cost map from the model's goal set.
pub fn cost_map(model: &Model) -> Result<CostMap, MapError> {
    let goals = model.goal_states();
    cost_map_from(model, &goals)
}

/// Build the cost map from an explicit goal set (packed indices in CCF).
///
/// The wave front is a ring of buckets, one per cost modulo `max_edge + 1`. When the ring of
/// bit sets fits in [`BITSET_BUDGET`] times the cost array, each bucket is a two-level bit set
/// over the whole space: inserting is setting a bit, duplicates vanish, and a bucket is swept in
/// index order for free, so the scattered front visits the cost array in one forward pass.
/// Otherwise (very expensive moves, so many buckets) each bucket is a vector, sorted by index
/// when large.
pub fn cost_map_from(model: &Model, goals: &[u32]) -> Result<CostMap, MapError> {
    let t0 = Instant::now();
    let n = model.n_states as usize;
    let ring = model.max_edge as usize + 1;
    let bitset_bytes = ring * n.div_ceil(64) * 8;
    let mut map = if bitset_bytes <= BITSET_BUDGET * n * std::mem::size_of::<u16>() {
        propagate(model, goals, &mut BitRing::new(ring, n))?
    } else {
        propagate(model, goals, &mut VecRing::new(ring))?
    };
    map.stats.map_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(map)
}

/// The bit-set ring may take this many times the bytes of the cost array.
pub const BITSET_BUDGET: usize = 1;

/// A ring of buckets of packed indices: the wave front of a Dial queue.
trait Ring {
    /// One bucket, taken out of the ring while it is swept.
    type Bucket;
    /// Put `idx` into bucket `b`.
    fn push(&mut self, b: usize, idx: u32);
    /// Take bucket `b` out (the ring keeps an empty one in its place).
    fn take(&mut self, b: usize) -> Self::Bucket;
    /// Put a swept, empty bucket back at `b`.
    fn put_back(&mut self, b: usize, bucket: Self::Bucket);
    /// Visit the bucket's indices (in ascending order when large) and empty it.
    fn sweep(
        bucket: &mut Self::Bucket,
        f: impl FnMut(u32) -> Result<(), MapError>,
    ) -> Result<(), MapError>;
    /// Indices queued in all buckets (stale entries included).
    fn queued(&self) -> u64;
    /// Most bytes the ring held.
    fn peak_bytes(&self) -> u64;
}

/// Buckets as vectors; large ones are sorted before they are swept.
struct VecRing {
    buckets: Vec<Vec<u32>>,
    queued: u64,
    peak: u64,
}

impl VecRing {
    fn new(ring: usize) -> VecRing {
        VecRing {
            buckets: vec![Vec::new(); ring],
            queued: 0,
            peak: 0,
        }
    }
}

impl Ring for VecRing {
    type Bucket = Vec<u32>;
    #[inline]
    fn push(&mut self, b: usize, idx: u32) {
        self.buckets[b].push(idx);
        self.queued += 1;
    }
    fn take(&mut self, b: usize) -> Vec<u32> {
        let held: usize = self.buckets.iter().map(Vec::capacity).sum();
        self.peak = self.peak.max(held as u64 * 4);
        let v = std::mem::take(&mut self.buckets[b]);
        self.queued -= v.len() as u64;
        v
    }
    fn put_back(&mut self, b: usize, bucket: Vec<u32>) {
        self.buckets[b] = bucket;
    }
    fn sweep(
        bucket: &mut Vec<u32>,
        mut f: impl FnMut(u32) -> Result<(), MapError>,
    ) -> Result<(), MapError> {
        // Entries of one cost are scattered over the map; in index order they sweep it once,
        // so the cache misses of the settled-check and of nearby origins are shared.
        if bucket.len() > SORT_MIN {
            bucket.sort_unstable();
        }
        let r = bucket.iter().try_for_each(|&q| f(q));
        bucket.clear();
        r
    }
    fn queued(&self) -> u64 {
        self.queued
    }
    fn peak_bytes(&self) -> u64 {
        self.peak
    }
}

/// One bit-set bucket: `words` holds one bit per index, `summary` one bit per non-zero word.
#[derive(Default)]
struct BitBucket {
    words: Vec<u64>,
    summary: Vec<u64>,
    count: u64,
}

/// Buckets as two-level bit sets over the whole space.
struct BitRing {
    buckets: Vec<BitBucket>,
    queued: u64,
}

impl BitRing {
    fn new(ring: usize, n: usize) -> BitRing {
        let nw = n.div_ceil(64);
        BitRing {
            buckets: (0..ring)
                .map(|_| BitBucket {
                    words: vec![0; nw],
                    summary: vec![0; nw.div_ceil(64)],
                    count: 0,
                })
                .collect(),
            queued: 0,
        }
    }
}

impl Ring for BitRing {
    type Bucket = BitBucket;
    #[inline]
    fn push(&mut self, b: usize, idx: u32) {
        let bucket = &mut self.buckets[b];
        let w = idx as usize >> 6;
        let bit = 1u64 << (idx & 63);
        let word = &mut bucket.words[w];
        if *word & bit == 0 {
            if *word == 0 {
                bucket.summary[w >> 6] |= 1 << (w & 63);
            }
            *word |= bit;
            bucket.count += 1;
            self.queued += 1;
        }
    }
    fn take(&mut self, b: usize) -> BitBucket {
        let bucket = std::mem::take(&mut self.buckets[b]);
        self.queued -= bucket.count;
        bucket
    }
    fn put_back(&mut self, b: usize, bucket: BitBucket) {
        self.buckets[b] = bucket;
    }
    fn sweep(
        bucket: &mut BitBucket,
        mut f: impl FnMut(u32) -> Result<(), MapError>,
    ) -> Result<(), MapError> {
        if bucket.count == 0 {
            return Ok(());
        }
        bucket.count = 0;
        let mut result = Ok(());
        for si in 0..bucket.summary.len() {
            let mut sbits = std::mem::take(&mut bucket.summary[si]);
            while sbits != 0 {
                let w = si * 64 + sbits.trailing_zeros() as usize;
                sbits &= sbits - 1;
                let mut bits = std::mem::take(&mut bucket.words[w]);
                while bits != 0 {
                    let idx = (w * 64) as u32 + bits.trailing_zeros();
                    bits &= bits - 1;
                    if result.is_ok() {
                        result = f(idx);
                    }
                }
            }
        }
        result
    }
    fn queued(&self) -> u64 {
        self.queued
    }
    fn peak_bytes(&self) -> u64 {
        self.buckets
            .iter()
            .map(|b| (b.words.len() + b.summary.len()) as u64 * 8)
            .sum()
    }
}

/// Dijkstra's order over the buckets: a state is settled when it is swept with the cost it
/// holds; stale entries (improved since) are skipped.
fn propagate<R: Ring>(model: &Model, goals: &[u32], queue: &mut R) -> Result<CostMap, MapError> {
    let n = model.n_states as usize;
    let mut cost = vec![INF; n];
    let ring = model.max_edge as usize + 1;
    let mut goal_count = 0;
    for &g in goals {
        if cost[g as usize] != 0 {
            cost[g as usize] = 0;
            queue.push(0, g);
            goal_count += 1;
        }
    }
    let mut stats = MapStats {
        states_total: n as u64,
        goals: goal_count,
        ..MapStats::default()
    };
    let peak = queue.peak_bytes();
    let mut origins: Vec<(u32, u32)> = Vec::with_capacity(64);
    let mut c: u32 = 0;
    while queue.queued() > 0 {
        let b = c as usize % ring;
        let mut bucket = queue.take(b);
        // Every origin costs at least 1 and at most `max_edge` more, so it never lands in `b`.
        let r = R::sweep(&mut bucket, |q| {
            if cost[q as usize] as u32 != c {
                return Ok(()); // stale: settled earlier with a lower cost
            }
            stats.states_mapped += 1;
            stats.max_cost = c;
            model.origins(q, &mut origins);
            stats.relaxations += origins.len() as u64;
            for &(p, d) in origins.iter() {
                let nc = c + d;
                if nc < cost[p as usize] as u32 {
                    if nc >= INF as u32 {
                        return Err(MapError::CostOverflow);
                    }
                    cost[p as usize] = nc as u16;
                    queue.push(nc as usize % ring, p);
                }
            }
            Ok(())
        });
        queue.put_back(b, bucket);
        r?;
        c += 1;
    }
    stats.map_bytes = (n * std::mem::size_of::<u16>()) as u64 + queue.peak_bytes().max(peak);
    Ok(CostMap { cost, stats })
}

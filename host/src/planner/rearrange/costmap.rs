//! The cost mapping phase, Ben-Shahar & Rivlin §IV-A1: a context-sensitive back propagation.
//!
//! A cost wave starts at the *set* of goal configurations (cost 0) and floods only admissible
//! origins N_A⁻¹(Q), each relaxed by D(Q̂, Q), in the order of Dijkstra's algorithm. Costs are
//! integers, so the wave front is a bucket (Dial) queue (`wavefront`): a ring of
//! `max_edge + 1` buckets of packed indices. The map is one `u16` per packed configuration
//! (`u16::MAX` = ∞, which also covers configurations in CCO and trap points: the backward wave
//! never reaches them). A state is settled when it is swept with the cost it holds; stale
//! entries are skipped, so no extra "settled" bit is needed. The map does not depend on the
//! start: any start reuses it (§IV-A2).
//!
//! Every core works: the states of one cost are settled in parallel (each move costs at least 1,
//! so settling them only lowers costs of other buckets); costs are lowered with an atomic
//! minimum, so the map is the same whatever order the cores take. The compact encoding — the
//! mixed-radix packed index of [`super::problem`], two bytes of cost per configuration, one bit
//! per configuration and bucket of wave front — is sized before the map is built
//! ([`map_bytes_estimate`]), so that a map that would not fit can be refused up front.

use std::sync::atomic::{AtomicU16, Ordering::Relaxed};
use std::time::Instant;

use super::problem::{Model, PackedIndex};
use super::wavefront::{BitRing, Front, Tally, VecRing};

/// Cost of a configuration the wave never reached (no pushing path, CCO, trap points).
pub const INF: u16 = u16::MAX;

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
    /// Worker threads that shared the propagation.
    pub threads: usize,
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
    pub fn get(&self, idx: u64) -> Option<u32> {
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

/// Build the cost map with packed indices of type `I` throughout ([`cost_map_from`] picks the
/// narrowest that numbers the space; a wider one gives the same map with more memory).
///
/// # Panics
/// If `I` cannot number the model's space.
pub fn cost_map_with<I: PackedIndex>(model: &Model, goals: &[u64]) -> Result<CostMap, MapError> {
    assert!(
        model.n_states <= I::from_u64(u64::MAX).as_u64(),
        "{} configurations do not fit this index type",
        model.n_states
    );
    let t0 = Instant::now();
    let n = model.n_states as usize;
    let ring = model.max_edge as usize + 1;
    let goals: Vec<I> = goals.iter().map(|&g| I::from_u64(g)).collect();
    let mut map = if uses_bitset(ring, n) {
        propagate(model, &goals, BitRing::new(ring, n))?
    } else {
        propagate(model, &goals, VecRing::<I>::new(ring))?
    };
    map.stats.map_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(map)
}

/// The bit-set ring may take this many times the bytes of the cost array.
pub const BITSET_BUDGET: usize = 1;

/// Does a map with `ring` buckets over `n` configurations keep its wave front in bit sets?
fn uses_bitset(ring: usize, n: usize) -> bool {
    BitRing::bytes(ring, n) <= (BITSET_BUDGET * n * std::mem::size_of::<u16>()) as u64
}

/// Bytes a cost map over `n_states` configurations with moves up to `max_edge` needs at its
/// peak: the cost array, and the wave front (its bit sets, or vectors bounded by the same
/// budget). Saturates at `u64::MAX`.
pub fn map_bytes_estimate(n_states: u64, max_edge: u32) -> u64 {
    let n = n_states as u128;
    let ring = max_edge as u128 + 1;
    let cost = n * std::mem::size_of::<u16>() as u128;
    let words = n.div_ceil(64);
    let bits = ring * (words + words.div_ceil(64)) * 8;
    let front = if bits <= BITSET_BUDGET as u128 * cost {
        bits
    } else {
        BITSET_BUDGET as u128 * cost
    };
    u64::try_from(cost + front).unwrap_or(u64::MAX)
}

/// Build the cost map from an explicit goal set (packed indices in CCF).
///
/// When the ring of bit sets fits in [`BITSET_BUDGET`] times the cost array, the wave front is
/// a ring of bit sets; otherwise (very expensive moves, so many buckets) a ring of vectors.
/// Indices are `u32` while the space has fewer than 2³² configurations, `u64` past it.
pub fn cost_map_from(model: &Model, goals: &[u64]) -> Result<CostMap, MapError> {
    if model.wide() {
        cost_map_with::<u64>(model, goals)
    } else {
        cost_map_with::<u32>(model, goals)
    }
}

/// The cost array and the cost being settled, shared by the cores during one sweep.
struct Wave<'a> {
    model: &'a Model,
    cost: &'a [AtomicU16],
    c: u32,
}

impl Wave<'_> {
    /// Settle `q` if it still holds cost `c`, relaxing its admissible origins.
    #[inline]
    fn settle<I: PackedIndex, F: Front<I>>(
        &self,
        q: I,
        front: &F,
        local: &mut F::Local,
        t: &mut Tally,
        origins: &mut Vec<(I, u32)>,
    ) {
        let (model, cost, c) = (self.model, self.cost, self.c);
        if cost[q.as_usize()].load(Relaxed) as u32 != c {
            return; // stale: settled earlier with a lower cost
        }
        let ring = model.max_edge as usize + 1;
        t.mapped += 1;
        model.origins(q, origins);
        t.relaxations += origins.len() as u64;
        for &(p, d) in origins.iter() {
            let nc = c + d;
            let slot = &cost[p.as_usize()];
            if nc >= INF as u32 {
                t.overflow |= slot.load(Relaxed) == INF;
                continue;
            }
            if (nc as u16) < slot.load(Relaxed) && (nc as u16) < slot.fetch_min(nc as u16, Relaxed)
            {
                front.push(local, t, nc as usize % ring, p);
            }
        }
    }
}

/// Dijkstra's order over the buckets: a state is settled when it is swept with the cost it
/// holds; stale entries (improved since) are skipped. Each bucket is swept on every core.
fn propagate<I: PackedIndex, F: Front<I>>(
    model: &Model,
    goals: &[I],
    mut front: F,
) -> Result<CostMap, MapError> {
    let n = model.n_states as usize;
    let ring = model.max_edge as usize + 1;
    // Built from a `u16` vector, and turned back into one in place at the end (same layout).
    let cost: Vec<AtomicU16> = vec![INF; n].into_iter().map(AtomicU16::new).collect();
    let mut goal_count = 0;
    let mut queued = 0u64;
    let mut local = F::Local::default();
    let mut t = Tally::default();
    for &g in goals {
        if cost[g.as_usize()].load(Relaxed) != 0 {
            cost[g.as_usize()].store(0, Relaxed);
            front.push(&mut local, &mut t, 0, g);
            goal_count += 1;
        }
    }
    front.absorb(local);
    queued += t.pushed;
    let mut stats = MapStats {
        states_total: n as u64,
        goals: goal_count,
        threads: rayon::current_num_threads(),
        ..MapStats::default()
    };
    let mut c: u32 = 0;
    while queued > 0 {
        let b = c as usize % ring;
        let wave = Wave {
            model,
            cost: &cost,
            c,
        };
        let t = front.sweep(b, |q, front, local, t, origins| {
            wave.settle(q, front, local, t, origins)
        });
        if t.overflow {
            return Err(MapError::CostOverflow);
        }
        queued = queued + t.pushed - t.swept;
        if t.mapped > 0 {
            stats.max_cost = c;
        }
        stats.states_mapped += t.mapped;
        stats.relaxations += t.relaxations;
        c += 1;
    }
    stats.map_bytes = (n * std::mem::size_of::<u16>()) as u64 + front.peak_bytes();
    let cost: Vec<u16> = cost.into_iter().map(AtomicU16::into_inner).collect();
    Ok(CostMap { cost, stats })
}

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
    /// Bytes of the cost array.
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
pub fn cost_map_from(model: &Model, goals: &[u32]) -> Result<CostMap, MapError> {
    let t0 = Instant::now();
    let n = model.n_states as usize;
    let mut cost = vec![INF; n];
    let ring = model.max_edge as usize + 1;
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); ring];
    let mut queued: u64 = 0;
    for &g in goals {
        if cost[g as usize] != 0 {
            cost[g as usize] = 0;
            buckets[0].push(g);
            queued += 1;
        }
    }
    let mut stats = MapStats {
        states_total: n as u64,
        goals: queued,
        ..MapStats::default()
    };
    let mut origins: Vec<(u32, u32)> = Vec::with_capacity(64);
    let mut c: u32 = 0;
    let mut cur: Vec<u32> = Vec::new();
    while queued > 0 {
        let b = c as usize % ring;
        std::mem::swap(&mut cur, &mut buckets[b]);
        queued -= cur.len() as u64;
        // Entries of one cost are scattered over the map; in index order they sweep it once,
        // so the cache misses of the settled-check and of nearby origins are shared.
        if cur.len() > SORT_MIN {
            cur.sort_unstable();
        }
        for &q in &cur {
            if cost[q as usize] as u32 != c {
                continue; // stale: settled earlier with a lower cost
            }
            stats.states_mapped += 1;
            stats.max_cost = c;
            model.origins(q, &mut origins);
            stats.relaxations += origins.len() as u64;
            for &(p, d) in &origins {
                let nc = c + d;
                if nc < cost[p as usize] as u32 {
                    if nc >= INF as u32 {
                        return Err(MapError::CostOverflow);
                    }
                    cost[p as usize] = nc as u16;
                    buckets[nc as usize % ring].push(p);
                    queued += 1;
                }
            }
        }
        cur.clear();
        c += 1;
    }
    stats.map_ms = t0.elapsed().as_secs_f64() * 1e3;
    stats.map_bytes = (n * std::mem::size_of::<u16>()) as u64;
    Ok(CostMap { cost, stats })
}

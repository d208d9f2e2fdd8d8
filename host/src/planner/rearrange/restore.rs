//! The pushing C-path restoration phase, Ben-Shahar & Rivlin §IV-A2.
//!
//! From any start Q₀ the plan follows the map downhill, but only through admissible neighbours
//! N_A(Q_C) whose cost is exactly `cost(Q_C) − D(Q_C, Q)`; taking the cheapest neighbour instead
//! could give a non-optimal path (Fig. 5). An infinite `cost(Q₀)` means no pushing path exists.

use std::time::Instant;

use super::admissibility::{MoveKind, Step};
use super::costmap::CostMap;
use super::problem::{Config, Model};

/// One move of a plan with the configuration it reaches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlanStep {
    /// The move.
    pub step: Step,
    /// The configuration after it.
    pub config: Config,
}

/// An optimal pushing plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The start configuration.
    pub start: Config,
    /// The moves, in order.
    pub steps: Vec<PlanStep>,
    /// Its cost (equals the map's cost of the start).
    pub cost: u32,
    /// Wall time of the restoration in ms.
    pub restore_ms: f64,
}

impl Plan {
    /// Number of pushing moves (translational or rotational).
    pub fn pushes(&self) -> usize {
        self.steps
            .iter()
            .filter(|s| s.step.kind != MoveKind::Transit)
            .count()
    }
}

/// Why no plan came out.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RestoreError {
    /// The start overlaps something.
    #[error("the start configuration is not free (bodies overlap)")]
    StartNotFree,
    /// `cost(Q₀) = ∞`.
    #[error("no pushing path exists")]
    NoPushingPath,
    /// The map does not belong to this model (no downhill neighbour).
    #[error("the cost map is inconsistent with the model at step {0}")]
    Inconsistent(usize),
}

/// Restore an optimal pushing path from `start` (packed) using the map.
pub fn restore(model: &Model, map: &CostMap, start: u64) -> Result<Plan, RestoreError> {
    let t0 = Instant::now();
    if start >= model.n_states || !model.valid(&model.decode(start)) {
        return Err(RestoreError::StartNotFree);
    }
    let total = map.get(start).ok_or(RestoreError::NoPushingPath)?;
    let mut cur = start;
    let mut c = total;
    let mut steps = Vec::new();
    let mut nb = Vec::new();
    while c > 0 {
        model.neighbours(cur, &mut nb);
        let next = nb
            .iter()
            .find(|st| st.cost <= c && map.get(st.to) == Some(c - st.cost));
        let Some(&st) = next else {
            return Err(RestoreError::Inconsistent(steps.len()));
        };
        steps.push(PlanStep {
            step: st,
            config: model.unpack(st.to),
        });
        cur = st.to;
        c -= st.cost;
    }
    Ok(Plan {
        start: model.unpack(start),
        steps,
        cost: total,
        restore_ms: t0.elapsed().as_secs_f64() * 1e3,
    })
}

//! Where the rearrangement executor's moves come from (Ben-Shahar & Rivlin §IV-A2 and §V-B):
//! after every segment the executor observes the table and asks its source for the rest of a
//! plan from what it saw.
//!
//! - [`ExactSource`]: the cost map holds the optimal cost of *every* configuration, so the rest
//!   of the plan from any observation is restored from it (§IV-A2) — a lookup, never a new map.
//! - [`PracticalSource`]: the practical mode's plan is followed while the camera agrees with
//!   it; when the observation is not where the plan had put things (a box pushed off its cell,
//!   moved by hand), the practical mode plans again from the observation.

use anyhow::{Result, anyhow};

use crate::planner::rearrange::admissibility::MoveKind;
use crate::planner::rearrange::costmap::CostMap;
use crate::planner::rearrange::practical::{Action, Options, plan_practical};
use crate::planner::rearrange::problem::{Config, Dir, Model, Problem};
use crate::planner::rearrange::restore::restore;

/// One grid move of a plan, as the executor carries it out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlannedMove {
    /// The robot's direction of motion.
    pub dir: Dir,
    /// What it does.
    pub kind: MoveKind,
    /// Its cost D under the problem's metric.
    pub cost: u32,
    /// The configuration after it.
    pub config: Config,
}

/// The rest of a plan from an observed configuration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rest {
    /// Its cost (0 at the goal).
    pub cost: u32,
    /// Its moves (none at the goal).
    pub moves: Vec<PlannedMove>,
    /// It was planned anew from this observation (practical mode), not read off a plan.
    pub replanned: bool,
}

/// A planner the executor can ask for the rest of a plan.
pub trait PlanSource {
    /// The problem being executed.
    fn problem(&self) -> &Problem;
    /// Is `q` in the free space CCF?
    fn free(&self, q: &Config) -> bool;
    /// The rest of a plan from the observed configuration `q`.
    fn rest_from(&mut self, q: &Config) -> Result<Rest>;
    /// The executor carried out the first `n` moves of the last rest.
    fn advance(&mut self, n: usize);
    /// Says "exact" or "practical", for logs and reports.
    fn mode(&self) -> &'static str;
    /// Plans made so far (the exact map's lookups are not new plans: 1).
    fn plans(&self) -> usize {
        1
    }
}

/// The exact cost map: the rest of the optimal plan from any configuration (§IV-A2).
pub struct ExactSource<'a> {
    /// The compiled problem.
    pub model: &'a Model,
    /// Its cost map.
    pub map: &'a CostMap,
}

impl PlanSource for ExactSource<'_> {
    fn problem(&self) -> &Problem {
        &self.model.problem
    }
    fn free(&self, q: &Config) -> bool {
        self.model.pack(q).is_some()
    }
    fn rest_from(&mut self, q: &Config) -> Result<Rest> {
        let idx = self.model.pack(q).ok_or_else(|| {
            anyhow!(
                "the observed configuration (robot {:?}, movables {:?}) is not free on the grid",
                q.robot,
                q.movables
            )
        })?;
        let cost = self
            .map
            .get(idx)
            .ok_or_else(|| anyhow!("no pushing path exists from the observed configuration"))?;
        let moves = if cost == 0 {
            Vec::new()
        } else {
            restore(self.model, self.map, idx)
                .map_err(|e| anyhow!("restoring the plan: {e}"))?
                .steps
                .into_iter()
                .map(|s| PlannedMove {
                    dir: s.step.dir,
                    kind: s.step.kind,
                    cost: s.step.cost,
                    config: s.config,
                })
                .collect()
        };
        Ok(Rest {
            cost,
            moves,
            replanned: false,
        })
    }
    fn advance(&mut self, _: usize) {}
    fn mode(&self) -> &'static str {
        "exact"
    }
}

/// The practical mode: its plan, followed while observations agree with it, planned again from
/// the observation when they do not.
pub struct PracticalSource {
    problem: Problem,
    opts: Options,
    /// Where the plan has things now, and the moves left from there.
    plan: Option<(Config, Vec<PlannedMove>)>,
    plans: usize,
}

impl PracticalSource {
    /// A source for `problem`, planning with `opts` (the plan is made at the first observation).
    pub fn new(problem: &Problem, opts: Options) -> PracticalSource {
        PracticalSource {
            problem: problem.clone(),
            opts,
            plan: None,
            plans: 0,
        }
    }
}

/// Same robot cell and movables' placements (the robot's memory is not observed).
fn same_place(a: &Config, b: &Config) -> bool {
    a.robot == b.robot && a.movables == b.movables
}

impl PlanSource for PracticalSource {
    fn problem(&self) -> &Problem {
        &self.problem
    }
    fn free(&self, q: &Config) -> bool {
        self.problem.is_free(q)
    }
    fn rest_from(&mut self, q: &Config) -> Result<Rest> {
        if let Some((at, moves)) = &self.plan
            && same_place(at, q)
        {
            return Ok(Rest {
                cost: moves.iter().map(|m| m.cost).sum(),
                moves: moves.clone(),
                replanned: false,
            });
        }
        let mut p = self.problem.clone();
        p.start = q.clone();
        let plan = plan_practical(&p, &self.opts)
            .map_err(|e| anyhow!("from the observed configuration: {e}"))?;
        self.plans += 1;
        let moves = plan
            .moves
            .into_iter()
            .map(|m| {
                Ok(PlannedMove {
                    dir: m.dir,
                    kind: match m.action {
                        Action::Transit => MoveKind::Transit,
                        Action::Push(i) => MoveKind::Push {
                            pushed: 1u64
                                .checked_shl(i as u32)
                                .ok_or_else(|| anyhow!("more than 64 movables"))?,
                        },
                        Action::Rotate(i, turn) => MoveKind::Rotate {
                            movable: u8::try_from(i).map_err(|_| anyhow!("too many movables"))?,
                            turn,
                        },
                    },
                    cost: m.cost,
                    config: m.config,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        self.plan = Some((q.clone(), moves.clone()));
        Ok(Rest {
            cost: plan.cost,
            moves,
            replanned: self.plans > 1,
        })
    }
    fn advance(&mut self, n: usize) {
        if let Some((at, moves)) = &mut self.plan {
            let n = n.min(moves.len());
            if n > 0 {
                *at = moves[n - 1].config.clone();
                moves.drain(..n);
            }
        }
    }
    fn mode(&self) -> &'static str {
        "practical"
    }
    fn plans(&self) -> usize {
        self.plans
    }
}

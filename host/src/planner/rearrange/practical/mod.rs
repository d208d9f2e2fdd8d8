//! The practical mode for many movables: an object-level search over which movable to push
//! next and where to park those in the way, whose single-object legs are exact searches of one
//! movable among the others held fixed ([`leg`]). Ben-Shahar & Rivlin §IV-E name the limit of
//! the exact planner (memory grows as (free cells)^(1 + r)) and leave larger problems to
//! heuristics; this is one, built on their own single-object cost mapping (§IV-A) and
//! admissibility (§IV-B).
//!
//! A node is a full configuration; its successors are, for each movable not at its goal, the
//! leg that pushes it to its goal and the legs that park it on the cheapest placements that
//! cover no other movable's goal (when every movable is placed, the robot's own leg to its goal).
//! Nodes are expanded best-first on g + w·h, where h sums, over the movables not at their goals,
//! the anchor's Manhattan distance times the cheapest push (a lower bound for translational
//! pushes; rotations may shift the anchor further). The plan is legal under the full problem's
//! rules (a distance limit binds the robot to the movables held fixed too); it pushes one
//! movable at a time, and it is not proven optimal. When the search ends without a plan it says
//! "no plan found" and why it gave up: its node budget spent, or every configuration it reaches
//! tried (naming the pushes of several movables at once that the rules allow and this mode never
//! makes) — unless some movable cannot reach its goal even alone on the table, which proves that
//! no plan exists (one movable pushed at a time, no distance limit).
//!
//! Every move is charged what the exact planner charges it (§IV-C): a leg's sub-problem holds
//! the other movables as obstacles for admissibility only, its costs are the full table's
//! ([`leg::leg_model`]), and a movable left where movables may not be left must be the next one
//! pushed, as §IV-B's admissibility demands after every move.

pub mod leg;

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};
use std::time::Instant;

pub use leg::{Action, Leg, Move};

use super::problem::{Config, Dir, Placement, Problem, ProblemError};

/// How hard the object-level search tries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Weight w of the estimate (1: best-first on a lower bound; larger: greedier, faster).
    pub weight: f64,
    /// Parking placements tried per movable and node.
    pub parkings: usize,
    /// Nodes expanded before giving up.
    pub max_expansions: usize,
}

impl Options {
    /// Defaults for a problem: thorough for a few movables, greedy for many.
    pub fn for_problem(p: &Problem) -> Options {
        if p.movables.len() <= 4 {
            Options {
                weight: 1.0,
                parkings: 3,
                max_expansions: 20000,
            }
        } else {
            Options {
                weight: 5.0,
                parkings: 2,
                max_expansions: 2000,
            }
        }
    }
}

/// A plan of the practical mode.
#[derive(Debug, Clone)]
pub struct PracticalPlan {
    /// The start configuration.
    pub start: Config,
    /// The moves, in order.
    pub moves: Vec<Move>,
    /// Its cost under the problem's metric.
    pub cost: u32,
    /// Legs (single-object pushes and parkings) it is made of.
    pub legs: usize,
    /// Proven optimal (never, in this mode).
    pub optimal: bool,
    /// Object-level nodes expanded.
    pub expansions: usize,
    /// Configurations the leg searches settled, summed.
    pub settled: u64,
    /// Wall time in ms.
    pub plan_ms: f64,
}

impl PracticalPlan {
    /// Number of pushing moves.
    pub fn pushes(&self) -> usize {
        self.moves
            .iter()
            .filter(|m| m.action != Action::Transit)
            .count()
    }
}

/// Why the practical mode returned no plan.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PracticalError {
    /// The search ended without a plan; one may still exist.
    #[error(
        "no plan found (searched {expansions} object-level nodes; a plan may still exist): {why}"
    )]
    NoPlanFound {
        /// Nodes expanded, over every round of the search.
        expansions: usize,
        /// Why the search gave up.
        why: GaveUp,
    },
    /// Proven: this movable cannot reach its goal even alone on the table.
    #[error("no plan exists: movable `{0}` cannot reach its goal even alone on the table")]
    NoPlanExists(String),
    /// The description is wrong.
    #[error(transparent)]
    Problem(#[from] ProblemError),
}

/// Why the object-level search gave up without a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum GaveUp {
    /// Its last round expanded [`Options::max_expansions`] nodes; a larger budget may find one.
    #[error("the budget of {limit} object-level nodes was spent (raise `Options::max_expansions`)")]
    Budget {
        /// The budget of one round.
        limit: usize,
    },
    /// Every configuration this mode reaches was expanded: one movable pushed at a time, to its
    /// goal or parked on one of the `parkings` cheapest placements of each leg search.
    #[error(
        "every configuration reached by pushing one movable at a time (parking each on up to \
         {parkings} placements) was tried{}",
        if *several_at_once {
            "; the rules let one move push several movables, which this mode never does, and a \
             plan may need it"
        } else {
            ""
        }
    )]
    Exhausted {
        /// Parking placements tried per movable and node in the last round.
        parkings: usize,
        /// The rules let one move push several movables (`max_pushed` is not 1).
        several_at_once: bool,
    },
}

/// One object-level node: where it is, what it cost, how it got there.
struct Node {
    config: Config,
    g: u32,
    parent: Option<usize>,
    leg: Vec<Move>,
}

/// Plan a rearrangement with the object-level search in rounds: first parking only the
/// movables in the way, then, if that finds nothing, parking any movable at every node, and
/// when that round ran out of nodes with some leg's parkings cut short, once more with four
/// times the parkings. Without a plan it says why the last round gave up ([`GaveUp`]).
pub fn plan_practical(p: &Problem, opts: &Options) -> Result<PracticalPlan, PracticalError> {
    let t0 = Instant::now();
    let mut expansions = 0;
    let mut round = |wide: bool, parkings: usize| {
        let o = Options { parkings, ..*opts };
        let r = search(p, &o, wide, t0);
        if let Err(Stop::Exhausted { nodes, .. } | Stop::Budget { nodes }) = &r {
            expansions += nodes;
        }
        r
    };
    let mut last = round(false, opts.parkings);
    if matches!(last, Err(Stop::Exhausted { .. } | Stop::Budget { .. })) {
        last = round(true, opts.parkings);
    }
    if let Err(Stop::Exhausted { cut: true, .. }) = last {
        last = round(true, 4 * opts.parkings);
    }
    let several_at_once = p.rules.max_pushed != 1 && p.movables.len() > 1;
    last.map_err(|stop| match stop {
        Stop::Error(e) => e,
        Stop::Budget { .. } => PracticalError::NoPlanFound {
            expansions,
            why: GaveUp::Budget {
                limit: opts.max_expansions,
            },
        },
        Stop::Exhausted { parkings, .. } => PracticalError::NoPlanFound {
            expansions,
            why: GaveUp::Exhausted {
                parkings,
                several_at_once,
            },
        },
    })
}

/// How one round of the search ended without a plan.
enum Stop {
    /// It expanded its whole budget of `nodes`.
    Budget { nodes: usize },
    /// It ran out of nodes after `nodes`; `cut`: some leg found as many parkings as it was
    /// allowed (more might have helped), each leg `parkings` of them.
    Exhausted {
        nodes: usize,
        cut: bool,
        parkings: usize,
    },
    /// The problem is wrong or no plan exists.
    Error(PracticalError),
}

impl From<ProblemError> for Stop {
    fn from(e: ProblemError) -> Stop {
        Stop::Error(e.into())
    }
}

/// One object-level search; `wide` parks any movable at every node.
fn search(p: &Problem, opts: &Options, wide: bool, t0: Instant) -> Result<PracticalPlan, Stop> {
    let r = p.movables.len();
    if p.start.movables.len() != r || p.goal_movables.len() != r {
        return Err(ProblemError::Invalid("start and goal must place every movable".into()).into());
    }
    // Per movable: the cheapest push (robot step + push), and whether it can reach its goal alone.
    // That proves something only when one move pushes one movable: a chain of pushes moves the
    // last movable without the robot at one of its contact modes.
    let relaxation_proves = p.rules.distance_limit.is_none() && p.rules.max_pushed == 1;
    let per_push = (0..r)
        .map(|i| cheapest_push_or_proof(p, i, relaxation_proves))
        .collect::<Result<Vec<u32>, PracticalError>>()
        .map_err(Stop::Error)?;
    let h = |c: &Config| -> u32 {
        (0..r)
            .filter_map(|i| {
                let g = p.goal_movables[i]?;
                let m = c.movables[i];
                Some(((m.x - g.x).unsigned_abs() + (m.y - g.y).unsigned_abs()) * per_push[i])
            })
            .sum()
    };
    let done = |c: &Config| -> bool {
        (0..r).all(|i| p.goal_movables[i].is_none_or(|g| c.movables[i] == g))
            && p.goal_robot.is_none_or(|g| c.robot == g)
    };
    let key = |f: f64| (f * 16.0) as u64;
    let mut start = p.start.clone();
    normalize(p, &mut start);
    let mut nodes = vec![Node {
        config: start.clone(),
        g: 0,
        parent: None,
        leg: Vec::new(),
    }];
    let mut best: HashMap<Config, u32> = HashMap::new();
    best.insert(start.clone(), 0);
    let mut heap = BinaryHeap::new();
    heap.push(Reverse((
        key(opts.weight * h(&start) as f64),
        Reverse(0u32),
        0usize,
    )));
    let mut expansions = 0;
    let mut settled = 0;
    let mut cut = false;
    let ncells = (p.grid.w * p.grid.h) as usize;
    while let Some(Reverse((_, _, id))) = heap.pop() {
        let (config, g) = (nodes[id].config.clone(), nodes[id].g);
        if best.get(&config).is_some_and(|&b| b < g) {
            continue;
        }
        if done(&config) {
            return Ok(finish(p, &nodes, id, expansions, settled, t0));
        }
        if expansions >= opts.max_expansions {
            return Err(Stop::Budget { nodes: expansions });
        }
        expansions += 1;
        let mut children: Vec<Leg> = Vec::new();
        let unplaced: Vec<usize> = (0..r)
            .filter(|&i| p.goal_movables[i].is_some_and(|g| config.movables[i] != g))
            .collect();
        // A movable on a cell where none may be left must be the one pushed next (§IV-B: after
        // every move, each movable not pushed lies where it may be left).
        let unleavable: Vec<usize> = (0..r)
            .filter(|&j| !may_leave(p, j, config.movables[j]))
            .collect();
        let may_push = |i: Option<usize>| unleavable.iter().all(|&j| Some(j) == i);
        if unplaced.is_empty() && may_push(None) {
            let want = leg::Wanted {
                target: None,
                robot_target: p.goal_robot,
                avoid: &[],
                parkings: 0,
            };
            let legs = leg::legs(p, &config, None, false, &want)?;
            settled += legs.settled;
            children.extend(legs.direct);
        }
        // Direct legs first; parkings only for movables in the way: on the goal of another
        // movable still to be placed, or anywhere when some movable has no direct leg.
        let mut stuck = false;
        let mut direct: Vec<Leg> = Vec::new();
        for &i in unplaced.iter().filter(|&&i| may_push(Some(i))) {
            let want = leg::Wanted {
                target: p.goal_movables[i],
                robot_target: None,
                avoid: &[],
                parkings: 0,
            };
            let legs = leg::legs(p, &config, Some(i), false, &want)?;
            settled += legs.settled;
            match legs.direct {
                Some(l) => direct.push(l),
                None => stuck = true,
            }
        }
        children.extend(direct);
        for j in 0..r {
            let on_goal = unplaced.iter().any(|&i| {
                i != j
                    && p.goal_movables[i].is_some_and(|g| overlaps(p, j, config.movables[j], i, g))
            });
            if !(on_goal || stuck || wide) || !may_push(Some(j)) {
                continue;
            }
            // A parked movable must not cover the goal of another movable still to be placed.
            let mut avoid = vec![false; ncells];
            for &i in &unplaced {
                if i != j {
                    mark(p, i, p.goal_movables[i], &mut avoid);
                }
            }
            let want = leg::Wanted {
                target: None,
                robot_target: None,
                avoid: &avoid,
                parkings: opts.parkings,
            };
            let legs = leg::legs(p, &config, Some(j), false, &want)?;
            settled += legs.settled;
            cut |= legs.parkings.len() >= opts.parkings;
            children.extend(legs.parkings);
        }
        for mut leg in children {
            normalize(p, &mut leg.end);
            let g2 = g + leg.cost;
            if best.get(&leg.end).is_some_and(|&b| b <= g2) {
                continue;
            }
            best.insert(leg.end.clone(), g2);
            let f = g2 as f64 + opts.weight * h(&leg.end) as f64;
            nodes.push(Node {
                config: leg.end,
                g: g2,
                parent: Some(id),
                leg: leg.moves,
            });
            heap.push(Reverse((key(f), Reverse(g2), nodes.len() - 1)));
        }
    }
    Err(Stop::Exhausted {
        nodes: expansions,
        cut,
        parkings: opts.parkings,
    })
}

/// Forget the robot's last move when the metric does not charge it (fewer distinct nodes).
fn normalize(p: &Problem, c: &mut Config) {
    if !p.metric.needs_memory() {
        c.heading = Dir::E;
        c.pushing = false;
    }
}

/// The cheapest push of movable `i` (robot step + push) on the bare table; with `proves`, an
/// error if it cannot reach its goal even alone there (then no plan exists).
fn cheapest_push_or_proof(p: &Problem, i: usize, proves: bool) -> Result<u32, PracticalError> {
    let bare = leg::sub_problem(p, &p.start, Some(i), true);
    let model = leg::leg_model(p, &bare)?;
    let robot_min = model.robot_cost.iter().copied().min().unwrap_or(1);
    let push_min = model.push_cost[0].iter().copied().min().unwrap_or(0);
    if proves
        && let Some(goal) = p.goal_movables[i]
        && goal != p.start.movables[i]
    {
        let want = leg::Wanted {
            target: Some(goal),
            robot_target: None,
            avoid: &[],
            parkings: 0,
        };
        if leg::legs(p, &p.start, Some(i), true, &want)?
            .direct
            .is_none()
        {
            return Err(PracticalError::NoPlanExists(p.movables[i].name.clone()));
        }
    }
    Ok(robot_min + push_min)
}

/// Does movable `j` at `a` overlap movable `i` at `b`?
fn overlaps(p: &Problem, j: usize, a: Placement, i: usize, b: Placement) -> bool {
    let cj: Vec<(i32, i32)> = p.movables[j]
        .cells_at(a.o)
        .iter()
        .map(|&(x, y)| (a.x + x, a.y + y))
        .collect();
    p.movables[i]
        .cells_at(b.o)
        .iter()
        .any(|&(x, y)| cj.contains(&(b.x + x, b.y + y)))
}

/// May movable `j` be left at `pl` (no cell of it where movables may not be left)?
fn may_leave(p: &Problem, j: usize, pl: Placement) -> bool {
    p.movables[j]
        .cells_at(pl.o)
        .iter()
        .all(|&(x, y)| p.grid.get(pl.x + x, pl.y + y).is_none_or(|c| !c.no_leave))
}

/// Mark the cells movable `j` covers at `pl`.
fn mark(p: &Problem, j: usize, pl: Option<Placement>, cells: &mut [bool]) {
    let Some(pl) = pl else { return };
    for (cx, cy) in p.movables[j].cells_at(pl.o) {
        let (x, y) = (pl.x + cx, pl.y + cy);
        if x >= 0 && y >= 0 && x < p.grid.w && y < p.grid.h {
            cells[(y * p.grid.w + x) as usize] = true;
        }
    }
}

/// The plan ending at node `id`.
fn finish(
    p: &Problem,
    nodes: &[Node],
    id: usize,
    expansions: usize,
    settled: u64,
    t0: Instant,
) -> PracticalPlan {
    let mut chain = Vec::new();
    let mut at = Some(id);
    while let Some(k) = at {
        chain.push(k);
        at = nodes[k].parent;
    }
    chain.reverse();
    let moves: Vec<Move> = chain
        .iter()
        .flat_map(|&k| nodes[k].leg.iter().cloned())
        .collect();
    PracticalPlan {
        start: p.start.clone(),
        cost: moves.iter().map(|m| m.cost).sum(),
        moves,
        legs: chain.len() - 1,
        optimal: false,
        expansions,
        settled,
        plan_ms: t0.elapsed().as_secs_f64() * 1e3,
    }
}

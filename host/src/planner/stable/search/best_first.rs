//! The best-first (A*) search loop of Lynch & Mason (1996) §4.1–4.2: take the cheapest step
//! from OPEN, check it, prune it on the grid, stop at the goal neighbourhood, MAXCOST or the
//! node limit, and expand it with every contact's controls; then read the plan back.

use std::collections::{BinaryHeap, HashMap};
use std::hash::BuildHasherDefault;
use std::time::Instant;

use super::bound::Heuristic;
use super::crossing::goal_finish;
use super::finish::pushes_in_steps;
use super::grid::{Cells, Grid, GridHasher};
use super::open::{Fifo, Finish, Open, Pending, Queue};
use super::steps::{
    Plan, SearchEnd, SearchTrace, Step, TREE_EDGES, goal_measure, step_cost, summarise,
};
use crate::planner::stable::collision::Frame;
use crate::planner::stable::reach::unreachable;
use crate::planner::stable::transit::{TransitPath, Transits};
use crate::planner::stable::{Pose, Problem, step_twist};

const NONE: u32 = u32::MAX;

/// The transit found (index into the plan's transits) or not for each (expanded node, contact).
type TransitCache = HashMap<(u32, u32), Option<u32>, BuildHasherDefault<GridHasher>>;

/// When a generated step's collision is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Checks {
    /// When the step is generated, before it enters OPEN (the paper's order, §4.2.1).
    Eager,
    /// When its node is taken from OPEN, before the goal test and the grid is marked: a node
    /// whose cell is already occupied at that time, or that is never taken before the search
    /// ends, is never checked. The search expands the same nodes in the same order and
    /// returns the same plan as [`Checks::Eager`] (a colliding node in OPEN is only skipped).
    Lazy,
}

/// A configuration taken from OPEN and expanded, or the goal: the search tree's inner nodes.
#[derive(Clone, Copy)]
struct Expanded {
    q: Pose,
    /// `(sin θ, cos θ)` of `q` (its children's steps and checks use it): the parent's composed
    /// with the step's rotation, as [`step_ok`] does for the step's end.
    sc: (f64, f64),
    /// Whether `q` is in the refined region (§4.5): its children take the fine steps.
    fine: bool,
    /// The part of its step the node took: 1, or less for an exact finish.
    frac: f64,
    contact: u32,
    control: u32,
    parent: u32,
    cost: u32,
    transit: u32,
}

/// Plan with the paper's bucketed OPEN list.
pub fn plan(p: &Problem) -> Plan {
    plan_with(p, Queue::Buckets)
}

/// Whether the step of contact `ci`, control `k` from `from` (with `sc` = `(sin, cos)` of its
/// angle, `fine`: whether it is near the goal) to `to` is free along its whole length.
fn step_ok(
    p: &Problem,
    from: &Pose,
    (sc, fine): ((f64, f64), bool),
    ci: usize,
    k: usize,
    to: &Pose,
) -> bool {
    let cm = &p.contacts[ci];
    let (xi, swept, (sd, cd)) = if fine {
        (&cm.fine_steps[k], &cm.fine_swept[k], cm.fine_delta_sc[k])
    } else {
        (&cm.steps[k], &cm.swept[k], cm.delta_sc[k])
    };
    let frame = Frame {
        x: from.x,
        y: from.y,
        s: sc.0,
        c: sc.1,
    };
    // `(sin, cos)` at the step's end, composed from the start's and the step's rotation.
    let sc2 = compose_sc(sc, (sd, cd));
    cm.body
        .step_free_swept_in(&p.world, from, &frame, xi, swept, to, sc2)
}

/// The key a node of cost `g` and bound `h` takes in OPEN: `g + w·h` (weighted A*, §4.2.2's
/// order when `w = 1`), at most `max_cost` (the bucket list's last).
#[inline(always)]
fn weighted(g: u32, h: u32, w: f64, max_cost: u32) -> u32 {
    if w == 1.0 {
        return g.saturating_add(h).min(max_cost);
    }
    (g as f64 + w * h as f64).round().min(max_cost as f64) as u32
}

/// Whether the step `xi` from `q` to `q2` may pass through the goal neighbourhood: both ends
/// within the neighbourhood's half-diagonal plus the length of the path the centre of friction
/// takes (`|(ξx, ξy)|`) of the goal (a cheap filter before [`goal_crossing`]).
#[inline(always)]
fn near_goal_of(p: &Problem, q: &Pose, q2: &Pose, xi: &crate::mechanics::V3) -> bool {
    let r = p.params.goal_xy * std::f64::consts::SQRT_2 + xi.x.hypot(xi.y);
    let d = |a: &Pose| (a.x - p.goal.x).hypot(a.y - p.goal.y);
    d(q) <= r && d(q2) <= r
}

/// `(sin, cos)` of the sum of two angles given as `(sin, cos)`.
#[inline(always)]
fn compose_sc((s, c): (f64, f64), (sd, cd): (f64, f64)) -> (f64, f64) {
    (s * cd + c * sd, c * cd - s * sd)
}

/// The transit path (index into `transits`) of a mobile pusher from expanded node `parent`'s
/// contact to `contact`, found once per pair (§4.6); `None` if there is none. The search needs
/// only whether one exists ([`Transits::any_path`]); the plan's own are made shortest when it
/// is read off ([`shortest`]).
fn transit_of(
    p: &Problem,
    shared: &Transits,
    closed: &[Expanded],
    cache: &mut TransitCache,
    transits: &mut Vec<TransitPath>,
    parent: u32,
    contact: u32,
) -> Option<u32> {
    *cache.entry((parent, contact)).or_insert_with(|| {
        let par = &closed[parent as usize];
        shared
            .any_path(p, &par.q, par.contact as usize, contact as usize)
            .map(|tp| {
                transits.push(tp);
                (transits.len() - 1) as u32
            })
    })
}

/// A shortest transit path in place of `t` (found by [`Transits::any_path`]), which stands if
/// none is found (there is one: the two agree on existence).
fn shortest(p: &Problem, shared: &Transits, t: &TransitPath) -> TransitPath {
    shared
        .path(p, &t.at, t.from_contact, t.to_contact)
        .unwrap_or_else(|| t.clone())
}

/// Plan with the given OPEN list.
///
/// A* on `f = g + h` ([`Heuristic`]). The paper prunes a configuration whose grid cell was
/// already reached "with the same or lower cost and the same pushing contact" (§4.2.3); the grid
/// remembers the least cost `g` each cell was expanded with, so a cell reached again more
/// cheaply (possible once the order is by `f`, not `g`) is expanded again.
pub fn plan_with(p: &Problem, queue: Queue) -> Plan {
    plan_checked(p, queue, Checks::Lazy)
}

/// Plan with the given OPEN list and collision-check timing ([`Checks`]). A goal that
/// [`unreachable`](fn@unreachable) proves cut off from the start is "no plan" without a search (no
/// node expanded; `unreachable(p)` gives the reason).
pub fn plan_checked(p: &Problem, queue: Queue, checks: Checks) -> Plan {
    let t0 = Instant::now();
    if unreachable(p).is_some() {
        return Plan {
            found: false,
            cost: 0,
            pushes: 0,
            control_changes: 0,
            contact_changes: 0,
            nodes_expanded: 0,
            plan_time_ms: t0.elapsed().as_secs_f64() * 1e3,
            steps: vec![],
            transits: vec![],
            exact_goal: false,
            search: SearchTrace {
                ended: SearchEnd::Unreachable,
                ..SearchTrace::default()
            },
        };
    }
    let heur = Heuristic::new(p);
    let mut trace = SearchTrace::default();
    // Expanded nodes (the goal last): parents of what is in OPEN, and the plan's chain.
    let mut closed: Vec<Expanded> = Vec::with_capacity(p.params.max_nodes.min(1 << 20) + 1);
    let mut transits: Vec<TransitPath> = Vec::new();
    let mut transit_cache = TransitCache::default();
    let shared = Transits::new(p);
    let mut occupied = Grid::new(p);
    let cells = Cells::new(p);
    let max_cost = p.params.max_cost;
    let mut open = match queue {
        Queue::Buckets => Open::Buckets {
            lists: vec![Fifo::default(); max_cost as usize + 1],
            cur: 0,
            spare: Vec::new(),
        },
        Queue::Heap => Open::Heap {
            heap: BinaryHeap::new(),
            store: Vec::new(),
        },
    };
    let start_contact = p.start_contact.map_or(NONE, |c| c as u32);
    let weight = p.params.weight.max(1.0);
    open.push(
        weighted(0, heur.cost(heur.steps(&p.start)), weight, max_cost),
        Pending {
            parent: NONE,
            contact: start_contact,
            control: NONE,
            cost: 0,
            finish: Finish::No,
        },
    );
    let heur_zero = heur.cost(u32::MAX) == 0;
    let start_sc = p.start.theta.sin_cos();
    let lazy = checks == Checks::Lazy;
    let mobile = p.pusher.is_mobile();
    let mut expanded = 0usize;
    let mut goal_node = None;
    // The start must be free for some contact's body; each step checks its own body.
    while let Some(n) = open.pop() {
        if n.finish == Finish::Push {
            // §4.5's finish: one usable push from the parent onto the goal, free all along.
            let par = closed[n.parent as usize];
            let cm = &p.contacts[n.contact as usize];
            let xi = par.q.twist_to(&p.goal);
            if !cm.usable.set.contains(&xi) || !cm.body.step_free(&p.world, &par.q, &xi) {
                continue;
            }
            let mut transit_id = NONE;
            if mobile && par.contact != NONE && par.contact != n.contact {
                match transit_of(
                    p,
                    &shared,
                    &closed,
                    &mut transit_cache,
                    &mut transits,
                    n.parent,
                    n.contact,
                ) {
                    Some(ti) => transit_id = ti,
                    None => {
                        trace.no_transit += 1;
                        continue;
                    }
                }
            }
            closed.push(Expanded {
                q: p.goal,
                sc: p.goal.theta.sin_cos(),
                fine: par.fine,
                frac: 1.0,
                contact: n.contact,
                control: NONE,
                parent: n.parent,
                cost: n.cost,
                transit: transit_id,
            });
            goal_node = Some((closed.len() - 1) as u32);
            break;
        }
        if n.finish == Finish::Crossing {
            // An exact finish: the parent's step up to the goal neighbourhood, checked along
            // its whole length; a goal if it is free.
            let par = closed[n.parent as usize];
            let cm = &p.contacts[n.contact as usize];
            let xi = if par.fine {
                cm.fine_steps[n.control as usize]
            } else {
                cm.steps[n.control as usize]
            };
            let Some(t) = goal_finish(p, &par.q, &xi) else {
                continue;
            };
            let part = xi * t;
            let q = par.q.integrate(&part);
            if !p.in_goal(&q) || !cm.body.step_free(&p.world, &par.q, &part) {
                continue;
            }
            let mut transit_id = NONE;
            if mobile && par.contact != NONE && par.contact != n.contact {
                match transit_of(
                    p,
                    &shared,
                    &closed,
                    &mut transit_cache,
                    &mut transits,
                    n.parent,
                    n.contact,
                ) {
                    Some(ti) => transit_id = ti,
                    None => {
                        trace.no_transit += 1;
                        continue;
                    }
                }
            }
            closed.push(Expanded {
                q,
                sc: q.theta.sin_cos(),
                fine: par.fine,
                frac: t,
                contact: n.contact,
                control: n.control,
                parent: n.parent,
                cost: n.cost,
                transit: transit_id,
            });
            goal_node = Some((closed.len() - 1) as u32);
            break;
        }
        // The configuration: the start, or the parent's step (as when it was generated).
        let q = if n.parent == NONE {
            p.start
        } else {
            let par = &closed[n.parent as usize];
            let cm = &p.contacts[n.contact as usize];
            let d = if par.fine {
                &cm.fine_deltas[n.control as usize]
            } else {
                &cm.deltas[n.control as usize]
            };
            par.q.compose(d, par.sc)
        };
        // The node's grid cell (the start, with no contact yet, has none).
        let key = (n.contact != NONE).then(|| cells.cell(&q, n.contact));
        let in_goal = p.in_goal(&q);
        if lazy && n.parent != NONE {
            // Pruned at the grid test below anyway (unless it is a goal): skip the check.
            if !in_goal && key.is_some_and(|k| occupied.get(k) <= n.cost) {
                continue;
            }
            let par = &closed[n.parent as usize];
            if !step_ok(
                p,
                &par.q,
                (par.sc, par.fine),
                n.contact as usize,
                n.control as usize,
                &q,
            ) {
                trace.collided += 1;
                continue;
            }
        }
        let mut transit_id = NONE;
        if mobile && n.parent != NONE {
            let par_contact = closed[n.parent as usize].contact;
            if par_contact != NONE && par_contact != n.contact {
                match transit_of(
                    p,
                    &shared,
                    &closed,
                    &mut transit_cache,
                    &mut transits,
                    n.parent,
                    n.contact,
                ) {
                    Some(ti) => transit_id = ti,
                    None => {
                        trace.no_transit += 1;
                        continue;
                    }
                }
            }
        }
        let node = Expanded {
            q,
            sc: (0.0, 1.0),
            fine: false,
            frac: 1.0,
            contact: n.contact,
            control: n.control,
            parent: n.parent,
            cost: n.cost,
            transit: transit_id,
        };
        if in_goal {
            closed.push(node);
            goal_node = Some((closed.len() - 1) as u32);
            break;
        }
        if let Some(key) = key {
            if occupied.get(key) <= n.cost {
                continue;
            }
            occupied.set(key, n.cost);
        }
        if expanded >= p.params.max_nodes {
            trace.ended = SearchEnd::NodeLimit;
            break;
        }
        expanded += 1;
        let m = goal_measure(p, &q);
        if trace.closest.is_none_or(|(_, best)| m < best) {
            trace.closest = Some((q, m));
        }
        let prev = (n.contact != NONE).then_some((
            n.contact as usize,
            if n.control == NONE {
                usize::MAX
            } else {
                n.control as usize
            },
        ));
        let sc = if n.parent == NONE {
            start_sc
        } else {
            let par = &closed[n.parent as usize];
            let cm = &p.contacts[n.contact as usize];
            let (sd, cd) = if par.fine {
                cm.fine_delta_sc[n.control as usize]
            } else {
                cm.delta_sc[n.control as usize]
            };
            compose_sc(par.sc, (sd, cd))
        };
        let fine = cells.near_goal(&q);
        let me = closed.len() as u32;
        closed.push(Expanded { sc, fine, ..node });
        for (ci, cm) in p.contacts.iter().enumerate() {
            let deltas = if fine { &cm.fine_deltas } else { &cm.deltas };
            for (k, delta) in deltas.iter().enumerate() {
                let Some(dc) = step_cost(p, prev, ci, k) else {
                    continue;
                };
                let cost = n.cost.saturating_add(dc);
                if cost > max_cost {
                    trace.cut_by_cost += 1;
                    continue;
                }
                let q2 = q.compose(delta, sc);
                // Both tests only filter; the grid's, more selective, goes first. With `a = 0`
                // the bound is 0 and is not computed.
                if occupied.get(cells.cell(&q2, ci as u32)) <= cost {
                    continue;
                }
                let h = if heur_zero {
                    0
                } else {
                    heur.cost(heur.quick(&q2))
                };
                // The curve of control `k` through `q2` is the one through `q`.
                let h = h.saturating_add(heur.turn_cost(&q, sc, ci, k));
                if cost.saturating_add(h) > max_cost {
                    trace.cut_by_cost += 1;
                    continue;
                }
                let f = weighted(cost, h, weight, max_cost);
                if !lazy && !step_ok(p, &q, (sc, fine), ci, k, &q2) {
                    trace.collided += 1;
                    continue;
                }
                open.push(
                    f,
                    Pending {
                        parent: me,
                        contact: ci as u32,
                        control: k as u32,
                        cost,
                        finish: Finish::No,
                    },
                );
                // The exact finish: a step that passes through the goal neighbourhood between
                // its ends reaches the goal at this cost (the bound there is 0).
                let xi = if fine {
                    &cm.fine_steps[k]
                } else {
                    &cm.steps[k]
                };
                if near_goal_of(p, &q, &q2, xi)
                    && !p.in_goal(&q2)
                    && goal_finish(p, &q, xi).is_some()
                {
                    open.push(
                        cost.min(max_cost),
                        Pending {
                            parent: me,
                            contact: ci as u32,
                            control: k as u32,
                            cost,
                            finish: Finish::Crossing,
                        },
                    );
                }
            }
        }
        // §4.5's finish from here: one usable push of a contact straight onto the goal, tried
        // within two steps of it (where the grid's steps may not land in a small neighbourhood).
        let xi = q.twist_to(&p.goal);
        if xi.norm() > 1e-12 && p.slider_reach(&xi) <= 2.0 * p.params.step {
            for (ci, cm) in p.contacts.iter().enumerate() {
                if !cm.usable.set.contains(&xi) {
                    continue;
                }
                let Some(first) = step_cost(p, prev, ci, usize::MAX) else {
                    continue;
                };
                // As many steps as its length needs, and no fewer than the bound says any
                // plan from here takes (so that every step is a step the bound knows).
                let unit = step_twist(&p.slider, &xi, p.params.step);
                let n_steps =
                    ((xi.norm() / unit.norm()).ceil().max(1.0) as u32).max(heur.steps(&q));
                let cost = n
                    .cost
                    .saturating_add(first)
                    .saturating_add(p.params.a.saturating_mul(n_steps - 1));
                if cost <= max_cost {
                    open.push(
                        cost,
                        Pending {
                            parent: me,
                            contact: ci as u32,
                            control: NONE,
                            cost,
                            finish: Finish::Push,
                        },
                    );
                }
            }
        }
    }
    let mut plan = Plan {
        found: false,
        cost: 0,
        pushes: 0,
        control_changes: 0,
        contact_changes: 0,
        nodes_expanded: expanded,
        plan_time_ms: 0.0,
        steps: vec![],
        transits: vec![],
        exact_goal: false,
        search: trace,
    };
    if goal_node.is_some() {
        plan.search.ended = SearchEnd::Goal;
    } else {
        plan.search.tree = closed
            .iter()
            .filter(|n| n.parent != NONE)
            .take(TREE_EDGES)
            .map(|n| [closed[n.parent as usize].q, n.q])
            .collect();
    }
    if let Some(g) = goal_node {
        let mut chain = Vec::new();
        let mut i = g;
        while closed[i as usize].parent != NONE {
            chain.push(i);
            i = closed[i as usize].parent;
        }
        chain.reverse();
        for &i in &chain {
            let n = &closed[i as usize];
            let par = &closed[n.parent as usize];
            let cm = &p.contacts[n.contact as usize];
            if n.control == NONE {
                // §4.5's finish: one push onto the goal, cut into steps.
                let xi = par.q.twist_to(&p.goal);
                plan.steps.extend(pushes_in_steps(
                    p,
                    n.contact as usize,
                    &par.q,
                    &[(xi, usize::MAX)],
                    &p.goal,
                    heur.steps(&par.q) as usize,
                ));
                if n.transit != NONE {
                    plan.transits
                        .push(shortest(p, &shared, &transits[n.transit as usize]));
                }
                continue;
            }
            let xi = p.steps_at(n.contact as usize, &par.q)[n.control as usize] * n.frac;
            plan.steps.push(Step {
                contact: n.contact as usize,
                edge: cm.label,
                control: n.control as usize,
                from: par.q,
                to: n.q,
                twist: [xi.x, xi.y, xi.z],
            });
            if n.transit != NONE {
                plan.transits
                    .push(shortest(p, &shared, &transits[n.transit as usize]));
            }
        }
        plan.found = true;
        plan.cost = closed[g as usize].cost;
        summarise(p, &mut plan);
    }
    plan.plan_time_ms = t0.elapsed().as_secs_f64() * 1e3;
    plan
}

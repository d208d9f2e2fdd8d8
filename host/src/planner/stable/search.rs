//! The best-first push planner of Lynch & Mason (1996) §4.1–4.2 (after Barraquand & Latombe
//! 1993): OPEN is a 1-D array of FIFO lists indexed by integer cost (§4.2.2), a configuration is
//! expanded only if its grid cell has not been occupied with the same contact (§4.2.3), and the
//! search stops at the goal neighbourhood, at MAXCOST or at the node limit (§4.2.4).
//!
//! Costs: each push step costs `a`; a step whose control (contact and direction) differs from
//! the previous step's costs `b` more; a step on a different contact than the previous step
//! costs `c` more (a contact change is also a control change). For a mobile pusher a
//! contact-changing step is accepted only if a transit path exists (§4.6); that path is found
//! lazily, when the node is taken from OPEN, and kept in the plan. The exact-goal variant of
//! §4.5 backs up along the found path to a configuration from which one stable push reaches the
//! goal exactly.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};
use std::hash::{BuildHasherDefault, Hasher};
use std::time::Instant;

use super::collision::Frame;
use super::transit::{TransitPath, transit};
use super::{Pose, Problem};
use crate::mechanics::{V2, V3};

const NONE: u32 = u32::MAX;

/// A small multiplicative hasher for the pruning grid's integer keys (SipHash is the search's
/// bottleneck otherwise).
#[derive(Default)]
struct GridHasher(u64);

impl Hasher for GridHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(u64::from(*b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }
}

type GridMap = HashMap<(i64, i64, i64, u32), u32, BuildHasherDefault<GridHasher>>;

/// One push step of a plan.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Step {
    /// Index into the problem's contacts.
    pub contact: usize,
    /// Slider edge of that contact.
    pub edge: usize,
    /// Control index within the contact's controls (`usize::MAX` for an exact-goal push).
    pub control: usize,
    /// Configuration before the step.
    pub from: Pose,
    /// Configuration after the step.
    pub to: Pose,
    /// Slider-frame twist integrated over the step.
    pub twist: [f64; 3],
}

/// A plan and the search statistics.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Plan {
    /// Whether a path to the goal neighbourhood was found.
    pub found: bool,
    /// Total cost `a·pushes + b·control changes + c·contact changes`.
    pub cost: u32,
    /// Number of push steps.
    pub pushes: usize,
    /// Number of control changes.
    pub control_changes: usize,
    /// Number of contact changes.
    pub contact_changes: usize,
    /// Configurations expanded.
    pub nodes_expanded: usize,
    /// Planning time (ms).
    pub plan_time_ms: f64,
    /// The push steps.
    pub steps: Vec<Step>,
    /// Transit paths of the pusher, one per contact change.
    pub transits: Vec<TransitPath>,
    /// Whether the plan ends exactly at the goal (§4.5 variant).
    pub exact_goal: bool,
}

/// Which OPEN list to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Queue {
    /// The paper's array of first-in first-out lists indexed by integer cost (here `f = g + h`).
    Buckets,
    /// A binary heap ordered by `(f, insertion order)`; for cross-checking.
    Heap,
}

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
    contact: u32,
    control: u32,
    parent: u32,
    cost: u32,
    transit: u32,
}

/// A generated step waiting in OPEN: control `control` of contact `contact` from the expanded
/// node `parent` (`NONE`: the start itself), reaching cost `cost`. Its end configuration is
/// recomputed from the parent when it is taken, with the same arithmetic, so bit for bit the
/// one tested when it was generated; OPEN holds 16 bytes per entry.
#[derive(Clone, Copy)]
struct Pending {
    parent: u32,
    contact: u32,
    control: u32,
    cost: u32,
}

/// An admissible lower bound on the cost still to pay from a configuration to the goal
/// neighbourhood: `a` times a lower bound on the number of push steps, plus `b` when a control
/// change is surely due. It turns the paper's best-first search (§4.1) into A* without
/// changing what it minimises.
///
/// Why the step count is a lower bound: a step of length `step` moves no slider vertex farther
/// than `step` along its arc, so the centre of friction (inside the convex hull of the
/// vertices, hence no farther from the rotation centre than some vertex) moves at most `step`.
/// Every step of a control turns the slider by the same angle, so no step turns it more than
/// the largest of the controls' step rotations (the problem's own steps, precomputed; at most
/// `step / R` with `R` = half the slider length, as every point has a vertex at least that far
/// away). Steps that start within `fine_radius` of the goal are `fine_factor` times shorter
/// (§4.5): after the last step that starts outside that disk the centre is still at least
/// `fine_radius − step` from the goal, and the goal box lies within `goal_xy·√2` of it. Fine
/// steps turn by their own (smaller) largest rotation, so the turning still to do is bounded
/// with the same split into fine and coarse steps (see [`Heuristic::steps`]).
///
/// The control-change term: a configuration reached with control `k` of a contact reaches the
/// goal neighbourhood without another control change only along the curve that repeating `k`
/// traces (a circle about the control's fixed rotation centre, or a ray; refined steps near
/// the goal follow the same curve). If that curve never enters the neighbourhood, at least one
/// more control change, costing `b`, is due ([`Heuristic::turns`]). Steps and control changes
/// are separate terms of the cost, so the sum is still a bound; and it is consistent: a step
/// that keeps the control stays on the curve, one that changes it pays `b`.
#[derive(Debug, Clone)]
pub struct Heuristic {
    a: u32,
    b: u32,
    /// Per contact, per control: its curve in the slider frame.
    curves: Vec<Vec<Curve>>,
    step: f64,
    fine_step: f64,
    fine_radius: f64,
    /// Fine steps needed after the last coarse step.
    fine_tail: f64,
    /// Largest rotation of one (coarse) step.
    turn: f64,
    goal: Pose,
    goal_xy: f64,
    goal_theta: f64,
    /// Largest rotation of one fine step.
    turn_fine: f64,
    /// Reciprocals of `step`, `fine_step`, `turn` and `turn_fine` (see [`Heuristic::quick`]).
    inv: [f64; 4],
}

impl Heuristic {
    /// The bound for problem `p`.
    pub fn new(p: &Problem) -> Self {
        let pa = &p.params;
        let fine_on = pa.fine_factor > 1.0 && pa.fine_radius > 0.0;
        let fine_step = if fine_on {
            pa.step / pa.fine_factor
        } else {
            pa.step
        };
        let fine_radius = if fine_on { pa.fine_radius } else { 0.0 };
        let fine_tail = if fine_on {
            ((fine_radius - pa.step - pa.goal_xy * std::f64::consts::SQRT_2) / fine_step).max(0.0)
        } else {
            0.0
        };
        let half_len = p.slider.length() / 2.0;
        let turn_any = if half_len > 0.0 {
            pa.step / half_len
        } else {
            f64::INFINITY
        };
        // The largest rotation of one step of any control (each bounded by `turn_any`);
        // kept above 0 so that "cannot turn" reads as an unreachable heading, not a NaN.
        let max_turn = |deltas: fn(&super::ContactModel) -> &[Pose], cap: f64| {
            p.contacts
                .iter()
                .flat_map(|cm| deltas(cm).iter())
                .map(|d| d.theta.abs())
                .fold(0.0f64, f64::max)
                .min(cap)
                .max(1e-12)
        };
        let turn = max_turn(|cm| &cm.deltas, turn_any);
        let turn_fine = if fine_on {
            max_turn(|cm| &cm.fine_deltas, turn_any * fine_step / pa.step)
        } else {
            turn
        };
        let (sg, cg) = p.goal.theta.sin_cos();
        let curves = p
            .contacts
            .iter()
            .map(|cm| {
                cm.steps
                    .iter()
                    .map(|xi| match super::cor_of(xi) {
                        Some(c) => Curve::Turn {
                            cor: c,
                            cor_at_goal: V2::new(cg * c.x - sg * c.y, sg * c.x + cg * c.y),
                            radius: c.norm(),
                        },
                        None => Curve::Line {
                            dir: V2::new(xi.x, xi.y),
                        },
                    })
                    .collect()
            })
            .collect();
        Heuristic {
            a: pa.a,
            b: pa.b,
            curves,
            step: pa.step,
            fine_step,
            fine_radius,
            fine_tail,
            turn,
            goal: p.goal,
            goal_xy: pa.goal_xy,
            goal_theta: pa.goal_theta,
            turn_fine,
            inv: [pa.step, fine_step, turn, turn_fine].map(|v| 1.0 / v),
        }
    }

    /// A lower bound on the number of push steps from `q` to the goal neighbourhood.
    ///
    /// Distance and turning are bounded together per case: inside the refined disk either
    /// every remaining step is fine (`fine_factor` times shorter, turning that much less), or
    /// the path leaves the disk and comes back, which takes at least `A` fine steps (out and
    /// the tail in) and the rest of the turning at the coarse rate; outside the disk the
    /// path ends with at least the fine tail.
    pub fn steps(&self, q: &Pose) -> u32 {
        ceil_bound(self.raw::<true>(q))
    }

    /// [`Heuristic::steps`], bit for bit, multiplying by reciprocals instead of dividing; the
    /// few configurations whose bound lands within `1e-7` of an integer (where the two
    /// roundings could differ) are recomputed with the divisions.
    fn quick(&self, q: &Pose) -> u32 {
        let v = shrink(self.raw::<false>(q));
        let t = floor(v);
        let fr = v - t as f64;
        if v.abs() < 1e6 && fr > 1e-7 && fr < 1.0 - 1e-7 {
            // Not an integer: its ceiling is `t + 1`, and it is positive unless `t < 0`.
            (t + 1).clamp(0, i64::from(u32::MAX)) as u32
        } else {
            self.steps(q)
        }
    }

    /// The bound before rounding; `EXACT`: divide, else multiply by the reciprocals (the same
    /// to a few units in the last place).
    #[inline(always)]
    fn raw<const EXACT: bool>(&self, q: &Pose) -> f64 {
        // `x / d`, `d` being `step`, `fine_step`, `turn` or `turn_fine` (index `i`).
        let div = |x: f64, d: f64, i: usize| if EXACT { x / d } else { x * self.inv[i] };
        let (dx, dy) = ((q.x - self.goal.x).abs(), (q.y - self.goal.y).abs());
        let (bx, by) = ((dx - self.goal_xy).max(0.0), (dy - self.goal_xy).max(0.0));
        let d_box = (bx * bx + by * by).sqrt();
        let d_centre = (dx * dx + dy * dy).sqrt();
        let turn = (super::angle_diff(q.theta, self.goal.theta).abs() - self.goal_theta).max(0.0);
        let turn_fine = self.turn_fine;
        // Steps when `n_f` of them are fine and the rest of the turning is coarse.
        let mixed = |n_f: f64| n_f + div(turn - n_f * turn_fine, self.turn, 2).max(0.0);
        if self.fine_radius <= 0.0 {
            div(d_box, self.step, 0).max(div(turn, self.turn, 2))
        } else if d_centre > self.fine_radius {
            let tail = self.fine_tail;
            (tail + div(d_box - tail * self.fine_step, self.step, 0).max(0.0)).max(mixed(tail))
        } else {
            let all_fine = div(d_box, self.fine_step, 1).max(div(turn, turn_fine, 3));
            let out_and_back = div(self.fine_radius - d_centre, self.fine_step, 1) + self.fine_tail;
            all_fine.min(out_and_back.max(mixed(out_and_back)))
        }
    }

    /// The lower bound on the remaining cost: `a · steps`.
    pub fn cost(&self, steps: u32) -> u32 {
        self.a.saturating_mul(steps)
    }

    /// Whether a configuration `q` (with `(sin θ, cos θ)` = `sc`) reached with control
    /// `control` of contact `contact` needs at least one more control change: repeating the
    /// control traces a curve that never enters the goal neighbourhood (tested with a margin,
    /// so it errs towards `false`).
    pub fn turns(&self, q: &Pose, (s, c): (f64, f64), contact: usize, control: usize) -> bool {
        const EPS: f64 = 1e-9;
        let Some(curve) = self.curves.get(contact).and_then(|v| v.get(control)) else {
            return false;
        };
        let (gx, gy, r) = (self.goal.x, self.goal.y, self.goal_xy);
        match *curve {
            Curve::Turn {
                cor,
                cor_at_goal,
                radius,
            } => {
                // On the circle about the world rotation centre `q.apply(cor)`, the pose with
                // the goal's heading is `m = q + R(θ)·cor − R(θ_goal)·cor`; poses with a
                // heading within `goal_theta` of it lie within `radius·goal_theta` of `m`.
                let mx = q.x + c * cor.x - s * cor.y - cor_at_goal.x;
                let my = q.y + s * cor.x + c * cor.y - cor_at_goal.y;
                let dx = ((mx - gx).abs() - r).max(0.0);
                let dy = ((my - gy).abs() - r).max(0.0);
                let tol = radius * self.goal_theta + EPS;
                dx * dx + dy * dy > tol * tol
            }
            Curve::Line { dir } => {
                if super::angle_diff(q.theta, self.goal.theta).abs() > self.goal_theta + EPS {
                    return true;
                }
                // Slab test of the ray `q + t·d`, t ≥ 0, against the goal box.
                let d = V2::new(c * dir.x - s * dir.y, s * dir.x + c * dir.y);
                let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
                for (o, d, g) in [(q.x, d.x, gx), (q.y, d.y, gy)] {
                    let (lo, hi) = (g - r - EPS, g + r + EPS);
                    if d.abs() < 1e-15 {
                        if o < lo || o > hi {
                            return true;
                        }
                    } else {
                        let (a, b) = ((lo - o) / d, (hi - o) / d);
                        t0 = t0.max(a.min(b));
                        t1 = t1.min(a.max(b));
                    }
                }
                t0 > t1
            }
        }
    }

    /// The control-change term of the bound: `b` if [`Heuristic::turns`], else 0.
    fn turn_cost(&self, q: &Pose, sc: (f64, f64), contact: usize, control: usize) -> u32 {
        if self.b > 0 && self.turns(q, sc, contact, control) {
            self.b
        } else {
            0
        }
    }
}

/// The curve a control traces when repeated.
#[derive(Debug, Clone, Copy)]
enum Curve {
    /// A rotation about `cor` (slider frame); `cor_at_goal` is `cor` rotated by the goal's
    /// heading; `radius = |cor|`.
    Turn {
        cor: V2,
        cor_at_goal: V2,
        radius: f64,
    },
    /// A translation along `dir` (slider frame).
    Line { dir: V2 },
}

/// A bound `n` less a little for rounding errors: rounded up, it is a bound, never more.
fn shrink(n: f64) -> f64 {
    n * (1.0 - 1e-9) - 1e-9
}

/// `shrink(n).ceil()` as a step count (at least 0), without the libm call: truncate, then
/// round up.
fn ceil_bound(n: f64) -> u32 {
    let v = shrink(n);
    let t = v as i64;
    let t = if (t as f64) < v {
        t.saturating_add(1)
    } else {
        t
    };
    t.clamp(0, i64::from(u32::MAX)) as u32
}

/// A cell key: `(x, y, θ, contact)` indices, `x` tagged for refined cells.
type Key = (i64, i64, i64, u32);

/// One dense block of the pruning grid: the least cost each cell was expanded with, as `u16`
/// (`u16::MAX`: never) to halve its cache footprint; only built when MAXCOST fits below that.
struct Block {
    lo: [i64; 3],
    dim: [i64; 3],
    contacts: i64,
    cost: Vec<u16>,
}

impl Block {
    /// A block covering cells `lo ..= hi`, or `None` if it would be too large to hold densely.
    fn new(lo: [i64; 3], hi: [i64; 3], contacts: usize) -> Option<Self> {
        let dim = [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1];
        let n = dim
            .iter()
            .try_fold(contacts as i64, |a, &d| a.checked_mul(d.max(0)))?;
        (n <= 1 << 24).then(|| Block {
            lo,
            dim,
            contacts: contacts as i64,
            cost: vec![u16::MAX; n as usize],
        })
    }

    fn index(&self, k: &Key) -> Option<usize> {
        let i = [k.0 - self.lo[0], k.1 - self.lo[1], k.2 - self.lo[2]];
        let inside =
            (0..3).all(|j| i[j] >= 0 && i[j] < self.dim[j]) && (k.3 as i64) < self.contacts;
        inside.then(|| {
            (((i[2] * self.dim[1] + i[1]) * self.dim[0] + i[0]) * self.contacts + k.3 as i64)
                as usize
        })
    }
}

/// The pruning grid (§4.2.3): for each cell and contact, the least cost it was expanded with
/// (`u32::MAX`: never). Dense blocks over the table (coarse cells) and around the goal
/// (refined cells) keep the lookups in cache; cells outside them go to a hash map.
struct Grid {
    blocks: Vec<Block>,
    rest: GridMap,
}

impl Grid {
    fn new(p: &Problem) -> Self {
        let pa = &p.params;
        let contacts = p.contacts.len();
        let nt = (2.0 * std::f64::consts::PI / pa.grid_theta).ceil() as i64;
        let mut blocks = Vec::new();
        if pa.max_cost >= u32::from(u16::MAX) {
            // Costs would not fit the dense blocks: everything goes to the hash map.
            return Grid {
                blocks,
                rest: GridMap::default(),
            };
        }
        let (w, h) = p.world.table;
        let coarse = Block::new(
            [0, 0, 0],
            [
                (w / pa.grid_xy).floor() as i64,
                (h / pa.grid_xy).floor() as i64,
                nt,
            ],
            contacts,
        );
        blocks.extend(coarse);
        if pa.fine_factor > 1.0 && pa.fine_radius > 0.0 {
            let f = pa.fine_factor / pa.grid_xy;
            let r = pa.fine_radius;
            let (gx, gy) = (p.goal.x, p.goal.y);
            let fine = Block::new(
                [
                    ((gx - r) * f).floor() as i64 + (1 << 40),
                    ((gy - r) * f).floor() as i64,
                    0,
                ],
                [
                    ((gx + r) * f).floor() as i64 + (1 << 40),
                    ((gy + r) * f).floor() as i64,
                    (2.0 * std::f64::consts::PI * pa.fine_factor / pa.grid_theta).ceil() as i64,
                ],
                contacts,
            );
            blocks.extend(fine);
        }
        Grid {
            blocks,
            rest: GridMap::default(),
        }
    }

    /// The least cost cell `k` was expanded with (`u32::MAX`: never).
    fn get(&self, k: Key) -> u32 {
        for b in &self.blocks {
            if let Some(i) = b.index(&k) {
                let c = b.cost[i];
                return if c == u16::MAX {
                    u32::MAX
                } else {
                    u32::from(c)
                };
            }
        }
        self.rest.get(&k).copied().unwrap_or(u32::MAX)
    }

    fn set(&mut self, k: Key, g: u32) {
        for b in &mut self.blocks {
            if let Some(i) = b.index(&k) {
                // Blocks exist only when MAXCOST < u16::MAX, and expanded costs are ≤ MAXCOST.
                b.cost[i] = u16::try_from(g).unwrap_or(u16::MAX - 1);
                return;
            }
        }
        self.rest.insert(k, g);
    }
}

/// Plan with the paper's bucketed OPEN list.
pub fn plan(p: &Problem) -> Plan {
    plan_with(p, Queue::Buckets)
}

/// The grid's cell sizes and their reciprocals, for [`Cells::cell`] in the hot loop.
struct Cells {
    goal: (f64, f64),
    fine_on: bool,
    /// `fine_radius²`, as [`Problem::near_goal`] computes it.
    r2: f64,
    fine_factor: f64,
    grid_xy: f64,
    grid_theta: f64,
    inv_xy: f64,
    inv_theta: f64,
}

impl Cells {
    fn new(p: &Problem) -> Self {
        let pa = &p.params;
        Cells {
            goal: (p.goal.x, p.goal.y),
            fine_on: pa.fine_factor > 1.0,
            r2: pa.fine_radius * pa.fine_radius,
            fine_factor: pa.fine_factor,
            grid_xy: pa.grid_xy,
            grid_theta: pa.grid_theta,
            inv_xy: 1.0 / pa.grid_xy,
            inv_theta: 1.0 / pa.grid_theta,
        }
    }

    /// [`Problem::near_goal`], the same arithmetic.
    fn near_goal(&self, q: &Pose) -> bool {
        let (dx, dy) = (q.x - self.goal.0, q.y - self.goal.1);
        self.fine_on && dx * dx + dy * dy <= self.r2
    }

    /// The grid cell of a configuration: refined cells near the goal carry a tag so they
    /// never share a key with coarse cells.
    fn cell(&self, q: &Pose, contact: u32) -> Key {
        let th = super::wrap_2pi(q.theta);
        let (f, tag) = if self.near_goal(q) {
            (self.fine_factor, 1i64 << 40)
        } else {
            (1.0, 0)
        };
        (
            floor_div(q.x * f, self.grid_xy, self.inv_xy) + tag,
            floor_div(q.y * f, self.grid_xy, self.inv_xy),
            floor_div(th * f, self.grid_theta, self.inv_theta),
            contact,
        )
    }
}

/// `floor(y / d)`, bit for bit, given `inv = 1 / d`: for quotients below `10⁶`, `z = y · inv`
/// is within `1e-9` of the quotient, so when `z` is positive and that far from an integer its
/// truncation is the quotient's floor; otherwise (rare: negative, large, or close to an integer)
/// the division is done.
fn floor_div(y: f64, d: f64, inv: f64) -> i64 {
    let z = y * inv;
    let t = z as i64;
    let fr = z - t as f64;
    if fr > 1e-9 && fr < 1.0 - 1e-9 && z < 1e6 {
        t
    } else {
        floor(y / d)
    }
}

/// `x.floor() as i64` without the libm call: truncate, then round down.
fn floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

/// Cost of a step given the previous step's (contact, control).
pub fn step_cost(
    p: &Problem,
    prev: Option<(usize, usize)>,
    contact: usize,
    control: usize,
) -> Option<u32> {
    let mut c = p.params.a;
    // Saturating: costs come from the command line.
    if let Some((pc, pk)) = prev {
        // `pk == usize::MAX`: the pusher waits at its start contact, no control yet; leaving
        // that contact is still a contact (and so a control) change.
        if (pc, pk) != (contact, control) && (pk != usize::MAX || pc != contact) {
            c = c.saturating_add(p.params.b);
        }
        if pc != contact {
            c = c.saturating_add(p.params.c?);
        }
    }
    Some(c)
}

/// One of the paper's FIFO lists: a vector read from `head` on.
#[derive(Clone, Default)]
struct Fifo {
    items: Vec<Pending>,
    head: usize,
}

/// OPEN: the paper's cost-indexed FIFO lists, or one heap (ordered by `(f, insertion order)`
/// over a store of the entries).
enum Open {
    Buckets {
        lists: Vec<Fifo>,
        cur: usize,
        /// Emptied lists' buffers, reused by lists that fill up (fewer page faults and copies).
        spare: Vec<Vec<Pending>>,
    },
    Heap {
        heap: BinaryHeap<Reverse<(u32, u32)>>,
        store: Vec<Pending>,
    },
}

impl Open {
    fn push(&mut self, f: u32, n: Pending) {
        match self {
            Open::Buckets { lists, cur, spare } => {
                let f = f as usize;
                if let Some(l) = lists.get_mut(f) {
                    if l.items.capacity() == 0
                        && let Some(v) = spare.pop()
                    {
                        l.items = v;
                    }
                    l.items.push(n);
                    *cur = (*cur).min(f);
                }
            }
            Open::Heap { heap, store } => {
                heap.push(Reverse((f, store.len() as u32)));
                store.push(n);
            }
        }
    }

    fn pop(&mut self) -> Option<Pending> {
        match self {
            Open::Buckets { lists, cur, spare } => {
                while let Some(l) = lists.get_mut(*cur) {
                    if let Some(&n) = l.items.get(l.head) {
                        l.head += 1;
                        if l.head == l.items.len() {
                            // Drained: keep its buffer for another list.
                            let mut v = std::mem::take(&mut l.items);
                            l.head = 0;
                            v.clear();
                            spare.push(v);
                        }
                        return Some(n);
                    }
                    *cur += 1;
                }
                None
            }
            Open::Heap { heap, store } => heap.pop().map(|Reverse((_, i))| store[i as usize]),
        }
    }
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

/// `(sin, cos)` of the sum of two angles given as `(sin, cos)`.
#[inline(always)]
fn compose_sc((s, c): (f64, f64), (sd, cd): (f64, f64)) -> (f64, f64) {
    (s * cd + c * sd, c * cd - s * sd)
}

/// The transit path (index into `transits`) of a mobile pusher from expanded node `parent`'s
/// contact to `contact`, found once per pair (§4.6); `None` if there is none.
fn transit_of(
    p: &Problem,
    closed: &[Expanded],
    cache: &mut HashMap<(u32, u32), Option<u32>>,
    transits: &mut Vec<TransitPath>,
    parent: u32,
    contact: u32,
) -> Option<u32> {
    *cache.entry((parent, contact)).or_insert_with(|| {
        let par = &closed[parent as usize];
        transit(
            p,
            &par.q,
            par.contact as usize,
            contact as usize,
            closed.len() as u32,
        )
        .map(|tp| {
            transits.push(tp);
            (transits.len() - 1) as u32
        })
    })
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

/// Plan with the given OPEN list and collision-check timing ([`Checks`]).
pub fn plan_checked(p: &Problem, queue: Queue, checks: Checks) -> Plan {
    let t0 = Instant::now();
    let heur = Heuristic::new(p);
    // Expanded nodes (the goal last): parents of what is in OPEN, and the plan's chain.
    let mut closed: Vec<Expanded> = Vec::with_capacity(p.params.max_nodes.min(1 << 20) + 1);
    let mut transits: Vec<TransitPath> = Vec::new();
    let mut transit_cache: HashMap<(u32, u32), Option<u32>> = HashMap::new();
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
    open.push(
        heur.cost(heur.steps(&p.start)),
        Pending {
            parent: NONE,
            contact: start_contact,
            control: NONE,
            cost: 0,
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
                continue;
            }
        }
        let mut transit_id = NONE;
        if mobile && n.parent != NONE {
            let par_contact = closed[n.parent as usize].contact;
            if par_contact != NONE && par_contact != n.contact {
                match transit_of(
                    p,
                    &closed,
                    &mut transit_cache,
                    &mut transits,
                    n.parent,
                    n.contact,
                ) {
                    Some(ti) => transit_id = ti,
                    None => continue,
                }
            }
        }
        let node = Expanded {
            q,
            sc: (0.0, 1.0),
            fine: false,
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
            break;
        }
        expanded += 1;
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
                    continue;
                }
                let q2 = q.compose(delta, sc);
                // Both tests only filter; the grid's, more selective, goes first. With `a = 0`
                // the bound is 0 and is not computed.
                if occupied.get(cells.cell(&q2, ci as u32)) <= cost {
                    continue;
                }
                let f = if heur_zero {
                    cost
                } else {
                    cost.saturating_add(heur.cost(heur.quick(&q2)))
                };
                // The curve of control `k` through `q2` is the one through `q`.
                let f = f.saturating_add(heur.turn_cost(&q, sc, ci, k));
                if f > max_cost {
                    continue;
                }
                if !lazy && !step_ok(p, &q, (sc, fine), ci, k, &q2) {
                    continue;
                }
                open.push(
                    f,
                    Pending {
                        parent: me,
                        contact: ci as u32,
                        control: k as u32,
                        cost,
                    },
                );
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
    };
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
            let xi = p.steps_at(n.contact as usize, &par.q)[n.control as usize];
            plan.steps.push(Step {
                contact: n.contact as usize,
                edge: cm.edge,
                control: n.control as usize,
                from: par.q,
                to: n.q,
                twist: [xi.x, xi.y, xi.z],
            });
            if n.transit != NONE {
                plan.transits.push(transits[n.transit as usize].clone());
            }
        }
        plan.found = true;
        plan.cost = closed[g as usize].cost;
        summarise(p, &mut plan);
    }
    plan.plan_time_ms = t0.elapsed().as_secs_f64() * 1e3;
    plan
}

/// Fill in the counts (and recompute the cost) from the steps.
pub fn summarise(p: &Problem, plan: &mut Plan) {
    plan.pushes = plan.steps.len();
    plan.control_changes = 0;
    plan.contact_changes = 0;
    let mut cost = 0u32;
    let mut prev: Option<(usize, usize)> = p.start_contact.map(|c| (c, usize::MAX));
    for s in &plan.steps {
        if let Some((pc, pk)) = prev {
            if (pc, pk) != (s.contact, s.control) && (pk != usize::MAX || pc != s.contact) {
                plan.control_changes += 1;
            }
            if pc != s.contact {
                plan.contact_changes += 1;
            }
        }
        cost = cost.saturating_add(step_cost(p, prev, s.contact, s.control).unwrap_or(0));
        prev = Some((s.contact, s.control));
    }
    plan.cost = cost;
}

/// The exact-goal variant of §4.5: back up along `plan` until a configuration from which a
/// single usable push of one contact moves `PS` collision-free exactly onto the goal; the
/// final push is counted as `ceil(length / step)` steps of one control. Only pushers whose
/// usable set has interior on the velocity sphere (arm, omnidirectional) can do this.
pub fn exact_goal(p: &Problem, plan: &Plan) -> Option<Plan> {
    if !plan.found {
        return None;
    }
    for back in (0..=plan.steps.len()).rev() {
        let q = if back == 0 {
            p.start
        } else {
            plan.steps[back - 1].to
        };
        let last_contact = if back == 0 {
            p.start_contact
        } else {
            Some(plan.steps[back - 1].contact)
        };
        let xi = q.twist_to(&p.goal);
        if xi.norm() < 1e-12 {
            continue;
        }
        // Prefer the contact already in use (no transit).
        let mut order: Vec<usize> = (0..p.contacts.len()).collect();
        if let Some(lc) = last_contact {
            order.sort_by_key(|&c| c != lc);
        }
        for ci in order {
            let cm = &p.contacts[ci];
            if !cm.usable.set.contains(&xi) || !cm.body.step_free(&p.world, &q, &xi) {
                continue;
            }
            let change = last_contact.is_some_and(|lc| lc != ci);
            if change && p.params.c.is_none() {
                continue;
            }
            let mut out = backed_up(plan, back);
            if change && p.pusher.is_mobile() {
                match transit(p, &q, last_contact.unwrap_or(ci), ci, 0) {
                    Some(t) => out.transits.push(t),
                    None => continue,
                }
            }
            out.steps
                .extend(push_steps(p, ci, &q, &[(xi, usize::MAX)], &p.goal));
            summarise(p, &mut out);
            out.exact_goal = true;
            return Some(out);
        }
    }
    None
}

/// `plan` backed up to its first `back` steps, with the transit paths of the contact changes
/// among them: where the exact-goal finishes of §4.5 continue from.
pub(super) fn backed_up(plan: &Plan, back: usize) -> Plan {
    let mut out = plan.clone();
    out.steps.truncate(back);
    let changes = out
        .steps
        .windows(2)
        .filter(|w| w[0].contact != w[1].contact)
        .count();
    out.transits.truncate(changes);
    out
}

/// The steps of the constant pushes `pushes` (whole slider-frame twists, each with its control
/// index) with contact `ci` from `q`, each push cut into steps of the problem's step length (so
/// the cost counts them as the search counts steps); the last step ends on `goal` exactly.
pub(super) fn push_steps(
    p: &Problem,
    ci: usize,
    q: &Pose,
    pushes: &[(V3, usize)],
    goal: &Pose,
) -> Vec<Step> {
    let edge = p.contacts[ci].edge;
    let mut out = Vec::new();
    let mut at = *q;
    for (j, &(xi, control)) in pushes.iter().enumerate() {
        let unit = super::step_twist(&p.slider, &xi, p.params.step);
        let n = (xi.norm() / unit.norm()).ceil().max(1.0) as usize;
        let tw = xi / n as f64;
        for k in 0..n {
            let from = at.integrate(&(xi * (k as f64 / n as f64)));
            let to = if j + 1 == pushes.len() && k + 1 == n {
                *goal
            } else {
                at.integrate(&(xi * ((k + 1) as f64 / n as f64)))
            };
            out.push(Step {
                contact: ci,
                edge,
                control,
                from,
                to,
                twist: [tw.x, tw.y, tw.z],
            });
        }
        at = at.integrate(&xi);
    }
    out
}

/// Brute-force uniform-cost search over the same step discretisation *without grid pruning*,
/// exploring every control sequence up to `depth` steps; returns the least cost that reaches
/// the goal neighbourhood (no transit checks: for arm pushers). For testing the planner's
/// optimality claims (§4.3) on small instances.
pub fn brute_force_cost(p: &Problem, depth: usize) -> Option<u32> {
    let mut best: Option<u32> = None;
    fn rec(
        p: &Problem,
        q: Pose,
        prev: Option<(usize, usize)>,
        cost: u32,
        depth: usize,
        best: &mut Option<u32>,
    ) {
        if best.is_some_and(|b| cost >= b) {
            return;
        }
        if prev.is_some_and(|(_, k)| k != usize::MAX) && p.in_goal(&q) {
            *best = Some(cost);
            return;
        }
        if depth == 0 {
            return;
        }
        for (ci, cm) in p.contacts.iter().enumerate() {
            for (k, xi) in p.steps_at(ci, &q).iter().enumerate() {
                let Some(dc) = step_cost(p, prev, ci, k) else {
                    continue;
                };
                if cost.saturating_add(dc) > p.params.max_cost
                    || !cm.body.step_free(&p.world, &q, xi)
                {
                    continue;
                }
                rec(
                    p,
                    q.integrate(xi),
                    Some((ci, k)),
                    cost + dc,
                    depth - 1,
                    best,
                );
            }
        }
    }
    rec(
        p,
        p.start,
        p.start_contact.map(|c| (c, usize::MAX)),
        0,
        depth,
        &mut best,
    );
    best
}

/// The slider-frame twist of a step as a vector.
pub fn step_twist_of(s: &Step) -> V3 {
    V3::new(s.twist[0], s.twist[1], s.twist[2])
}

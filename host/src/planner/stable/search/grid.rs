//! The pruning grid of Lynch & Mason (1996) §4.2.3: a configuration is expanded only if its
//! grid cell has not been expanded with the same contact at the same or lower cost. Dense
//! blocks around the table and the goal, a hash map elsewhere, and the cell arithmetic.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use crate::planner::stable::{Pose, Problem, wrap_2pi};

/// A small multiplicative hasher for the pruning grid's integer keys (SipHash is the search's
/// bottleneck otherwise), and the search's other integer-keyed maps.
#[derive(Default)]
pub(super) struct GridHasher(u64);

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

/// A cell key: `(x, y, θ, contact)` indices, `x` tagged for refined cells.
pub(super) type Key = (i64, i64, i64, u32);

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
pub(super) struct Grid {
    blocks: Vec<Block>,
    rest: GridMap,
}

impl Grid {
    /// The empty grid for problem `p`.
    pub(super) fn new(p: &Problem) -> Self {
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
    pub(super) fn get(&self, k: Key) -> u32 {
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

    /// Record that cell `k` was expanded with cost `g`.
    pub(super) fn set(&mut self, k: Key, g: u32) {
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

/// The grid's cell sizes and their reciprocals, for [`Cells::cell`] in the hot loop.
pub(super) struct Cells {
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
    /// The cell sizes of problem `p`.
    pub(super) fn new(p: &Problem) -> Self {
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
    pub(super) fn near_goal(&self, q: &Pose) -> bool {
        let (dx, dy) = (q.x - self.goal.0, q.y - self.goal.1);
        self.fine_on && dx * dx + dy * dy <= self.r2
    }

    /// The grid cell of a configuration: refined cells near the goal carry a tag so they
    /// never share a key with coarse cells.
    pub(super) fn cell(&self, q: &Pose, contact: u32) -> Key {
        let th = wrap_2pi(q.theta);
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
pub(super) fn floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x { t - 1 } else { t }
}

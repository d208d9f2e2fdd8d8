//! The dense tables a problem compiles into (Ben-Shahar & Rivlin §II-A, §IV-E): each body's
//! statically valid placements with local indices, pairwise overlap and contact bit tables (the
//! C-obstacle CCO), the movables' contact tables, and the decoded form of a packed configuration.

use super::super::grid::{Dir, Grid, rot};
use super::spec::Placement;

/// The most movables a problem may have.
pub const MAX_MOVABLES: usize = 4;
/// Marks "no placement" in the local index tables.
pub const NONE: u32 = u32::MAX;

/// The statically valid placements of one body with their tables.
#[derive(Debug, Clone)]
pub struct Domain {
    /// Placement of each local index.
    pub place: Vec<Placement>,
    /// Local index of (orientation, cell), `NONE` if not valid.
    pub local: Vec<u32>,
    /// Orientations this body can take (1 or 4).
    pub orients: u8,
    /// Neighbour by translation: `shift[l * 4 + d]`.
    pub shift: Vec<u32>,
    /// Occupied grid cells per local index.
    pub cells: Vec<Vec<u32>>,
}

impl Domain {
    /// Local index of a placement.
    pub fn lookup(&self, w: i32, h: i32, p: Placement) -> u32 {
        if p.x < 0 || p.y < 0 || p.x >= w || p.y >= h || p.o >= self.orients {
            return NONE;
        }
        self.local[(p.o as i32 * w * h + p.y * w + p.x) as usize]
    }
    /// Number of placements.
    pub fn len(&self) -> u32 {
        self.place.len() as u32
    }
    /// No placement at all.
    pub fn is_empty(&self) -> bool {
        self.place.is_empty()
    }
}

/// A dense bit table.
#[derive(Debug, Clone)]
pub struct Bits {
    words: Vec<u64>,
}

impl Bits {
    fn new(n: usize) -> Bits {
        Bits {
            words: vec![0; n.div_ceil(64)],
        }
    }
    fn set(&mut self, i: usize) {
        self.words[i >> 6] |= 1 << (i & 63);
    }
    /// Bit `i`.
    #[inline]
    pub fn get(&self, i: usize) -> bool {
        (self.words[i >> 6] >> (i & 63)) & 1 == 1
    }
}

/// A rotational push ready for one pre-push orientation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RotInstance {
    /// Orientation before the push.
    pub pre_o: u8,
    /// Robot anchor minus movable anchor before the push.
    pub robot_off: (i32, i32),
    /// The robot's direction of motion.
    pub dir: Dir,
    /// New anchor minus old anchor.
    pub shift: (i32, i32),
    /// Orientation after the push.
    pub post_o: u8,
    /// Cells swept by the turn (bounding box of the movable before and after), relative to the
    /// anchor before the push; they must be free of obstacles and other movables.
    pub sweep: Vec<(i32, i32)>,
}

/// Translational contact table of one movable: robot anchor offsets allowed per (orientation, dir).
#[derive(Debug, Clone)]
pub struct ContactTable {
    /// Smallest offset coordinate.
    pub lo: i32,
    /// Side of the offset window.
    pub side: i32,
    /// `ok[(o * 4 + d) * side² + (dy - lo) * side + (dx - lo)]`.
    pub ok: Vec<bool>,
}

impl ContactTable {
    /// May the robot at offset (dx, dy) from the anchor push the movable at orientation o in d?
    #[inline]
    pub fn allows(&self, o: u8, d: Dir, dx: i32, dy: i32) -> bool {
        let (x, y) = (dx - self.lo, dy - self.lo);
        if x < 0 || y < 0 || x >= self.side || y >= self.side {
            return false;
        }
        let s2 = (self.side * self.side) as usize;
        self.ok[(o as usize * 4 + d as usize) * s2 + (y * self.side + x) as usize]
    }
}

/// Division of a `u32` by a fixed divisor as a multiply and a shift (Lemire, Kaser & Kurz,
/// "Faster remainder by direct computation", 2019): with `m = ⌈2⁶⁴ / d⌉`, `n / d` is the high
/// 64 bits of `m · n` for every 32-bit `n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FastDiv {
    m: u64,
    d: u32,
}

impl FastDiv {
    /// A divider by `d` (≥ 1).
    pub fn new(d: u32) -> FastDiv {
        let d = d.max(1);
        FastDiv {
            m: if d == 1 { 0 } else { u64::MAX / d as u64 + 1 },
            d,
        }
    }
    /// The divisor.
    pub fn divisor(self) -> u32 {
        self.d
    }
    /// `(n / d, n % d)`.
    #[inline(always)]
    pub fn div_rem(self, n: u32) -> (u32, u32) {
        if self.d == 1 {
            return (n, 0);
        }
        let q = ((self.m as u128 * n as u128) >> 64) as u32;
        (q, n - q * self.d)
    }
}

/// A packed configuration index (§II-A's CSS in mixed radix): `u32` while the space has fewer
/// than 2³² configurations — every index, and every wave-front entry that holds one, then takes
/// four bytes — and `u64` past it, for any space that fits in memory.
pub trait PackedIndex:
    Copy + Send + Sync + Ord + std::hash::Hash + std::fmt::Debug + 'static
{
    /// From a `u64` known to be in range.
    fn from_u64(x: u64) -> Self;
    /// As a `u64`.
    fn as_u64(self) -> u64;
    /// As an array index.
    fn as_usize(self) -> usize;
    /// `(self / d, self % d)`.
    fn div_rem(self, d: FastDiv) -> (Self, u32);
    /// `self × radix + digit` (one more digit, below the others).
    fn push_digit(self, radix: u32, digit: u32) -> Self;
    /// The index with the digit of stride `stride` changed from `from` to `to`.
    fn with_digit(self, stride: u32, from: u32, to: u32) -> Self;
    /// `self + k`.
    fn plus(self, k: u32) -> Self;
}

impl PackedIndex for u32 {
    #[inline(always)]
    fn from_u64(x: u64) -> u32 {
        x as u32
    }
    #[inline(always)]
    fn as_u64(self) -> u64 {
        self as u64
    }
    #[inline(always)]
    fn as_usize(self) -> usize {
        self as usize
    }
    #[inline(always)]
    fn div_rem(self, d: FastDiv) -> (u32, u32) {
        d.div_rem(self)
    }
    #[inline(always)]
    fn push_digit(self, radix: u32, digit: u32) -> u32 {
        self * radix + digit
    }
    #[inline(always)]
    fn with_digit(self, stride: u32, from: u32, to: u32) -> u32 {
        // The result is in range, so arithmetic modulo 2³² gives it exactly.
        self.wrapping_add(to.wrapping_sub(from).wrapping_mul(stride))
    }
    #[inline(always)]
    fn plus(self, k: u32) -> u32 {
        self + k
    }
}

impl PackedIndex for u64 {
    #[inline(always)]
    fn from_u64(x: u64) -> u64 {
        x
    }
    #[inline(always)]
    fn as_u64(self) -> u64 {
        self
    }
    #[inline(always)]
    fn as_usize(self) -> usize {
        self as usize
    }
    #[inline(always)]
    fn div_rem(self, d: FastDiv) -> (u64, u32) {
        // The multiply-and-shift holds for 32-bit dividends only; the hardware divides these.
        let d = d.divisor() as u64;
        (self / d, (self % d) as u32)
    }
    #[inline(always)]
    fn push_digit(self, radix: u32, digit: u32) -> u64 {
        self * radix as u64 + digit as u64
    }
    #[inline(always)]
    fn with_digit(self, stride: u32, from: u32, to: u32) -> u64 {
        self - from as u64 * stride as u64 + to as u64 * stride as u64
    }
    #[inline(always)]
    fn plus(self, k: u32) -> u64 {
        self + k as u64
    }
}

/// A packed configuration, decoded into local indices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct State {
    /// Robot memory.
    pub aux: u32,
    /// Robot local index.
    pub r: u32,
    /// Movable local indices.
    pub m: [u32; MAX_MOVABLES],
}

/// The statically valid placements of a body of cells `shape` with `orients` orientations.
pub(super) fn build_domain(grid: &Grid, shape: &[(i32, i32)], orients: u8) -> Domain {
    let (w, h) = (grid.w, grid.h);
    let n = (w * h) as usize;
    let mut local = vec![NONE; n * orients as usize];
    let mut place = Vec::new();
    let mut cells = Vec::new();
    for o in 0..orients {
        let sh: Vec<(i32, i32)> = shape.iter().map(|&c| rot(c, o)).collect();
        for y in 0..h {
            for x in 0..w {
                if sh.iter().all(|&(cx, cy)| grid.free(x + cx, y + cy)) {
                    local[o as usize * n + (y * w + x) as usize] = place.len() as u32;
                    place.push(Placement { x, y, o });
                    cells.push(
                        sh.iter()
                            .map(|&(cx, cy)| ((y + cy) * w + x + cx) as u32)
                            .collect(),
                    );
                }
            }
        }
    }
    let mut dom = Domain {
        place,
        local,
        orients,
        shift: Vec::new(),
        cells,
    };
    let mut shift = vec![NONE; dom.place.len() * 4];
    for (l, p) in dom.place.iter().enumerate() {
        for d in Dir::ALL {
            let (dx, dy) = d.delta();
            shift[l * 4 + d as usize] = dom.lookup(
                w,
                h,
                Placement {
                    x: p.x + dx,
                    y: p.y + dy,
                    o: p.o,
                },
            );
        }
    }
    dom.shift = shift;
    dom
}

/// Which placements of `a` and `b` touch (a cell of each side by side): `a`-major bits.
pub(super) fn touch_table(a: &Domain, b: &Domain, grid: &Grid) -> Bits {
    let ncells = (grid.w * grid.h) as usize;
    let mut cover: Vec<Vec<u32>> = vec![Vec::new(); ncells];
    for (l, cs) in b.cells.iter().enumerate() {
        for &c in cs {
            cover[c as usize].push(l as u32);
        }
    }
    let nb = b.len() as usize;
    let mut bits = Bits::new(a.len() as usize * nb);
    for (la, cs) in a.cells.iter().enumerate() {
        for &c in cs {
            let (x, y) = (c as i32 % grid.w, c as i32 / grid.w);
            for d in Dir::ALL {
                let (dx, dy) = d.delta();
                if grid.get(x + dx, y + dy).is_some() {
                    for &lb in &cover[((y + dy) * grid.w + x + dx) as usize] {
                        bits.set(la * nb + lb as usize);
                    }
                }
            }
        }
    }
    bits
}

/// Which placements of `a` and `b` overlap: `a`-major bits.
pub(super) fn overlap_table(a: &Domain, b: &Domain, ncells: usize) -> Bits {
    // cell -> placements of b covering it
    let mut cover: Vec<Vec<u32>> = vec![Vec::new(); ncells];
    for (l, cs) in b.cells.iter().enumerate() {
        for &c in cs {
            cover[c as usize].push(l as u32);
        }
    }
    let nb = b.len() as usize;
    let mut bits = Bits::new(a.len() as usize * nb);
    for (la, cs) in a.cells.iter().enumerate() {
        for &c in cs {
            for &lb in &cover[c as usize] {
                bits.set(la * nb + lb as usize);
            }
        }
    }
    bits
}

#[cfg(test)]
mod tests {
    use super::FastDiv;
    use rand::{Rng, SeedableRng};

    #[test]
    fn fast_division_equals_division() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut divisors: Vec<u32> = vec![1, 2, 3, 7, 8, 400, 401, 65_536, u32::MAX - 1, u32::MAX];
        divisors.extend((0..200).map(|_| rng.random_range(1..=u32::MAX)));
        divisors.extend((0..200).map(|_| rng.random_range(1..=5000)));
        for d in divisors {
            let f = FastDiv::new(d);
            let mut ns: Vec<u32> = vec![0, 1, d - 1, d, d.wrapping_add(1), u32::MAX, u32::MAX - 1];
            ns.extend((0..500).map(|_| rng.random::<u32>()));
            for n in ns {
                assert_eq!(f.div_rem(n), (n / d, n % d), "{n} / {d}");
            }
        }
    }
}

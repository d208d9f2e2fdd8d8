//! The pushing problem of Ben-Shahar & Rivlin §II-A on a grid, and its composite configuration
//! space CSS packed into integer indices.
//!
//! A [`Problem`] is what a scene describes: the table grid (static obstacles 𝓘, rough cells,
//! cells where no movable may be left), the robot 𝓡 (a k × k block of cells), the movables
//! 𝓜₁…𝓜ᵣ (any cell shape, a mass, 2-DOF or 3-DOF with 90° turns, and their pushing contact
//! modes, Fig. 15 and 18), the admissibility rules (§IV-B), the metric (§IV-C), a start and a goal.
//!
//! [`Model`] compiles a problem into dense tables: every body's statically valid placements get
//! a local index, and a composite configuration Q = (q_𝓡, q_𝓜₁, …, q_𝓜ᵣ) is packed in mixed
//! radix (robot memory, robot, movable 1, …) into a `u32`. Placements that overlap an obstacle
//! never get an index, so the packed space is the product of the bodies' free placements;
//! overlaps between bodies (the C-obstacle CCO) are found with precomputed pairwise bit tables.

use super::metric::Metric;

/// The most movables a problem may have.
pub const MAX_MOVABLES: usize = 4;
/// Marks "no placement" in the local index tables.
pub const NONE: u32 = u32::MAX;

/// One of the four main directions of the grid (x grows east, y grows south).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Dir {
    /// +x.
    E = 0,
    /// +y.
    S = 1,
    /// −x.
    W = 2,
    /// −y.
    N = 3,
}

impl Dir {
    /// All four, in index order.
    pub const ALL: [Dir; 4] = [Dir::E, Dir::S, Dir::W, Dir::N];
    /// The direction with this index (mod 4).
    pub fn from_index(i: usize) -> Dir {
        Dir::ALL[i % 4]
    }
    /// The unit step.
    pub fn delta(self) -> (i32, i32) {
        match self {
            Dir::E => (1, 0),
            Dir::S => (0, 1),
            Dir::W => (-1, 0),
            Dir::N => (0, -1),
        }
    }
    /// The opposite direction.
    pub fn opposite(self) -> Dir {
        Dir::from_index(self as usize + 2)
    }
    /// This direction turned by `quarter` quarter turns clockwise on screen.
    pub fn rotated(self, quarter: u8) -> Dir {
        Dir::from_index(self as usize + quarter as usize)
    }
    /// Parse `E`, `S`, `W`, `N` (case-insensitive).
    pub fn parse(s: &str) -> Option<Dir> {
        match s.to_ascii_uppercase().as_str() {
            "E" => Some(Dir::E),
            "S" => Some(Dir::S),
            "W" => Some(Dir::W),
            "N" => Some(Dir::N),
            _ => None,
        }
    }
    /// The letter.
    pub fn letter(self) -> char {
        ['E', 'S', 'W', 'N'][self as usize]
    }
}

/// Rotate a cell offset by `quarter` quarter turns clockwise on screen: (x, y) → (−y, x).
pub fn rot(p: (i32, i32), quarter: u8) -> (i32, i32) {
    let mut p = p;
    for _ in 0..quarter % 4 {
        p = (-p.1, p.0);
    }
    p
}

/// One cell of the table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Cell {
    /// Part of the static obstacles 𝓘.
    pub obstacle: bool,
    /// Passability level: 0 normal, 1 rough, 2 very rough (§V, "passability metric").
    pub rough: u8,
    /// No movable may be left here (§IV-B, "limit the areas in which the robot can dismiss").
    pub no_leave: bool,
}

/// The table: `w × h` cells, row-major, outside the grid counts as obstacle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Grid {
    /// Width in cells.
    pub w: i32,
    /// Height in cells.
    pub h: i32,
    /// The cells, `y * w + x`.
    pub cells: Vec<Cell>,
}

impl Grid {
    /// An empty table.
    pub fn new(w: i32, h: i32) -> Grid {
        Grid {
            w,
            h,
            cells: vec![Cell::default(); (w.max(0) * h.max(0)) as usize],
        }
    }
    /// The cell at (x, y), `None` outside.
    pub fn get(&self, x: i32, y: i32) -> Option<&Cell> {
        if x < 0 || y < 0 || x >= self.w || y >= self.h {
            None
        } else {
            self.cells.get((y * self.w + x) as usize)
        }
    }
    /// The cell at (x, y) for writing; panics outside (for building grids in code).
    pub fn at_mut(&mut self, x: i32, y: i32) -> &mut Cell {
        let i = (y * self.w + x) as usize;
        &mut self.cells[i]
    }
    /// Inside the grid and not an obstacle.
    pub fn free(&self, x: i32, y: i32) -> bool {
        self.get(x, y).is_some_and(|c| !c.obstacle)
    }
}

/// The robot: a `size × size` block of cells whose anchor is its top-left cell (2-DOF).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RobotSpec {
    /// Side of the block in cells.
    pub size: i32,
    /// Cost weight of the robot's own motion (its "mass" in the mass metric).
    pub mass: u32,
}

impl RobotSpec {
    /// The robot's cells relative to its anchor.
    pub fn cells(&self) -> Vec<(i32, i32)> {
        let mut v = Vec::new();
        for y in 0..self.size {
            for x in 0..self.size {
                v.push((x, y));
            }
        }
        v
    }
    /// Robot anchors (relative to a point p) whose leading edge, moving `d`, contains p.
    pub fn anchors_touching(&self, p: (i32, i32), d: Dir) -> Vec<(i32, i32)> {
        let k = self.size;
        (0..k)
            .map(|j| match d {
                Dir::E => (p.0 - k + 1, p.1 - j),
                Dir::W => (p.0, p.1 - j),
                Dir::S => (p.0 - j, p.1 - k + 1),
                Dir::N => (p.0 - j, p.1),
            })
            .collect()
    }
}

/// A pushing contact mode of a movable, in the movable's own frame (orientation 0).
///
/// `point` is the cell just outside the movable that the robot's leading face must cover when it
/// moves one cell in `dir`; `point + dir` is a cell of the movable (Fig. 15c, Fig. 18b–e).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ContactMode {
    /// The push translates the movable one cell in `dir`.
    Translate {
        /// The contact point.
        point: (i32, i32),
        /// The pushing direction.
        dir: Dir,
    },
    /// The push turns the movable 90° (`turn` = +1 clockwise on screen, −1 counter-clockwise)
    /// and moves its anchor by `shift`; the result is aligned with the grid again (§V-A).
    Rotate {
        /// The contact point.
        point: (i32, i32),
        /// The robot's direction of motion.
        dir: Dir,
        /// +1 or −1 quarter turn.
        turn: i8,
        /// New anchor minus old anchor, in the movable's frame.
        shift: (i32, i32),
    },
}

/// A movable object 𝓜ᵢ.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MovableSpec {
    /// Its name (for plans and figures).
    pub name: String,
    /// Its cells relative to its anchor, at orientation 0.
    pub cells: Vec<(i32, i32)>,
    /// Its mass (mass metric).
    pub mass: u32,
    /// 3-DOF: may take the four orientations (otherwise 2-DOF, orientation stays as it starts).
    pub rotates: bool,
    /// Its pushing contact modes.
    pub modes: Vec<ContactMode>,
}

impl MovableSpec {
    /// A movable with translational contact modes on every face ("faces").
    pub fn with_faces(name: &str, cells: Vec<(i32, i32)>, mass: u32) -> MovableSpec {
        let modes = face_modes(&cells);
        MovableSpec {
            name: name.to_string(),
            cells,
            mass,
            rotates: false,
            modes,
        }
    }
    /// The cells at orientation `o`, relative to the anchor.
    pub fn cells_at(&self, o: u8) -> Vec<(i32, i32)> {
        self.cells.iter().map(|&c| rot(c, o)).collect()
    }
}

/// Every translational contact mode on the faces of a shape: each outside cell next to the shape,
/// pushing towards it.
pub fn face_modes(cells: &[(i32, i32)]) -> Vec<ContactMode> {
    let mut modes = Vec::new();
    for d in Dir::ALL {
        let (dx, dy) = d.delta();
        for &(x, y) in cells {
            let p = (x - dx, y - dy);
            if !cells.contains(&p) {
                modes.push(ContactMode::Translate { point: p, dir: d });
            }
        }
    }
    modes
}

/// A placement of a body: anchor cell and orientation (0..4, quarter turns clockwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Placement {
    /// Anchor x.
    pub x: i32,
    /// Anchor y.
    pub y: i32,
    /// Orientation in quarter turns.
    pub o: u8,
}

/// The admissibility options of §IV-B and §V-A.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rules {
    /// Allowed pushing directions (bit `d` for `Dir` d), for translational pushes.
    pub push_dirs: u8,
    /// Most movables pushed by one move (0 = any number).
    pub max_pushed: u8,
    /// Manhattan distance limit (between anchors) from the robot to every movable it is not
    /// pushing, checked after each move.
    pub distance_limit: Option<u32>,
    /// The robot may only touch a movable through one of its contact modes; otherwise any
    /// translational collision pushes.
    pub strict_contact: bool,
    /// Rotational contact modes are used.
    pub rotations: bool,
}

impl Default for Rules {
    fn default() -> Self {
        Rules {
            push_dirs: 0b1111,
            max_pushed: 1,
            distance_limit: None,
            strict_contact: true,
            rotations: true,
        }
    }
}

/// A goal for one body: a placement, or anywhere.
pub type GoalPlacement = Option<Placement>;

/// A complete pushing problem.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Name (case or file).
    pub name: String,
    /// The table.
    pub grid: Grid,
    /// The robot.
    pub robot: RobotSpec,
    /// The movables.
    pub movables: Vec<MovableSpec>,
    /// Admissibility.
    pub rules: Rules,
    /// Metric.
    pub metric: Metric,
    /// The start Q₀.
    pub start: Config,
    /// Goal of the robot (usually anywhere).
    pub goal_robot: Option<(i32, i32)>,
    /// Goal of each movable (None = anywhere).
    pub goal_movables: Vec<GoalPlacement>,
}

/// A composite configuration in grid terms.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Config {
    /// The robot's anchor.
    pub robot: (i32, i32),
    /// The direction of the robot's last move (used when the metric charges turns).
    pub heading: Dir,
    /// The last move was a translational push (used when the metric charges contact changes).
    pub pushing: bool,
    /// The movables' placements.
    pub movables: Vec<Placement>,
}

/// Why a problem cannot be compiled.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ProblemError {
    /// Something about the description is wrong.
    #[error("{0}")]
    Invalid(String),
}

fn invalid<T>(msg: impl Into<String>) -> Result<T, ProblemError> {
    Err(ProblemError::Invalid(msg.into()))
}

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

/// A problem compiled to dense tables; the packed composite configuration space.
#[derive(Debug, Clone)]
pub struct Model {
    /// The problem it was built from.
    pub problem: Problem,
    /// Robot memory states per robot placement: 1, or 8 (last direction × last move was a
    /// translational push) when the metric charges turns or contact-mode changes.
    pub n_aux: u32,
    /// The robot's placements.
    pub robot: Domain,
    /// Each movable's placements.
    pub movables: Vec<Domain>,
    /// `radix[0] = n_aux`, `radix[1]` = robot placements, then each movable's.
    pub radix: Vec<u32>,
    /// Number of packed configurations.
    pub n_states: u64,
    /// Index stride of each digit: `stride[k] = radix[0] × … × radix[k−1]`.
    pub stride: Vec<u32>,
    /// Robot/movable overlap: `rm[i].get(m * n_robot + r)` (movable-major, so the robot's
    /// neighbouring placements share cache lines).
    pub rm: Vec<Bits>,
    /// Robot/movable contact (a robot cell and a movable cell side by side): `touch[i]`, same
    /// layout as `rm`. No push can have led to a configuration where the robot touches nothing.
    pub touch: Vec<Bits>,
    /// Some movable has rotational pushes.
    pub any_rotation: bool,
    /// Movable/movable overlap for i < j: `mm[i * MAX + j].get(mi * n_j + mj)`.
    pub mm: Vec<Option<Bits>>,
    /// Cost of the robot arriving at a placement (mass × passability).
    pub robot_cost: Vec<u32>,
    /// Cost of pushing movable i into a placement (mass × passability + safety).
    pub push_cost: Vec<Vec<u32>>,
    /// May movable i be left at this placement?
    pub leave_ok: Vec<Vec<bool>>,
    /// Translational contact tables.
    pub contact: Vec<ContactTable>,
    /// Rotational pushes by pre-push orientation: `rot_pre[i][o]`.
    pub rot_pre: Vec<[Vec<RotInstance>; 4]>,
    /// Rotational pushes by post-push orientation: `rot_post[i][o]`.
    pub rot_post: Vec<[Vec<RotInstance>; 4]>,
    /// Largest cost of one move.
    pub max_edge: u32,
    /// Division by each radix without a divide instruction (decoding is in the hot loop).
    pub div: Vec<FastDiv>,
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

fn build_domain(grid: &Grid, shape: &[(i32, i32)], orients: u8) -> Domain {
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

fn touch_table(a: &Domain, b: &Domain, grid: &Grid) -> Bits {
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

fn overlap_table(a: &Domain, b: &Domain, ncells: usize) -> Bits {
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

impl Model {
    /// Compile a problem; checks sizes, shapes, start and goals.
    pub fn new(problem: &Problem) -> Result<Model, ProblemError> {
        let p = problem;
        let g = &p.grid;
        if g.w < 1 || g.h < 1 || g.w > 256 || g.h > 256 || g.cells.len() != (g.w * g.h) as usize {
            return invalid(format!("grid {}×{}: each side must be 1..=256", g.w, g.h));
        }
        if p.movables.len() > MAX_MOVABLES {
            return invalid(format!(
                "{} movables: at most {MAX_MOVABLES}",
                p.movables.len()
            ));
        }
        if p.robot.size < 1 || p.robot.size > 8 {
            return invalid(format!("robot size {}: must be 1..=8", p.robot.size));
        }
        if p.robot.mass < 1 || p.robot.mass > 1000 {
            return invalid("robot mass must be 1..=1000");
        }
        for m in &p.movables {
            if m.cells.is_empty() || m.cells.len() > 64 {
                return invalid(format!("movable `{}`: needs 1..=64 cells", m.name));
            }
            if m.cells.iter().any(|&(x, y)| x.abs() > 16 || y.abs() > 16) {
                return invalid(format!(
                    "movable `{}`: cells must lie within 16 of the anchor",
                    m.name
                ));
            }
            if m.mass > 1000 {
                return invalid(format!("movable `{}`: mass must be 0..=1000", m.name));
            }
            for mode in &m.modes {
                let (pt, d) = match mode {
                    ContactMode::Translate { point, dir } => (*point, *dir),
                    ContactMode::Rotate {
                        point,
                        dir,
                        turn,
                        shift,
                    } => {
                        if *turn != 1 && *turn != -1 {
                            return invalid(format!(
                                "movable `{}`: rotation turn must be +1 or -1",
                                m.name
                            ));
                        }
                        if shift.0.abs() > 16 || shift.1.abs() > 16 {
                            return invalid(format!(
                                "movable `{}`: rotation shift too large",
                                m.name
                            ));
                        }
                        if !m.rotates {
                            return invalid(format!(
                                "movable `{}`: has a rotational contact mode but does not rotate",
                                m.name
                            ));
                        }
                        (*point, *dir)
                    }
                };
                let (dx, dy) = d.delta();
                if m.cells.contains(&pt) || !m.cells.contains(&(pt.0 + dx, pt.1 + dy)) {
                    return invalid(format!(
                        "movable `{}`: contact point ({}, {}) pushing {} must be outside the shape, next to it",
                        m.name,
                        pt.0,
                        pt.1,
                        d.letter()
                    ));
                }
            }
        }
        if p.start.movables.len() != p.movables.len() || p.goal_movables.len() != p.movables.len() {
            return invalid("start and goal must place every movable");
        }
        let metric = &p.metric;
        metric.check().map_err(ProblemError::Invalid)?;
        let n_aux = if metric.needs_memory() { 8 } else { 1 };
        let ncells = (g.w * g.h) as usize;
        let robot = build_domain(g, &p.robot.cells(), 1);
        let movables: Vec<Domain> = p
            .movables
            .iter()
            .map(|m| build_domain(g, &m.cells, if m.rotates { 4 } else { 1 }))
            .collect();
        let mut radix = vec![n_aux, robot.len()];
        radix.extend(movables.iter().map(|d| d.len()));
        let n_states: u64 = radix.iter().map(|&r| r as u64).product();
        if n_states >= NONE as u64 {
            return invalid(format!(
                "{n_states} composite configurations: more than a u32 index holds"
            ));
        }
        if radix.contains(&0) {
            return invalid("some body has no free placement on this grid");
        }
        let rm = movables
            .iter()
            .map(|d| overlap_table(d, &robot, ncells))
            .collect();
        let touch = movables.iter().map(|d| touch_table(d, &robot, g)).collect();
        let mut mm = vec![None; MAX_MOVABLES * MAX_MOVABLES];
        for i in 0..movables.len() {
            for j in i + 1..movables.len() {
                mm[i * MAX_MOVABLES + j] = Some(overlap_table(&movables[i], &movables[j], ncells));
            }
        }
        let robot_cost: Vec<u32> = robot
            .cells
            .iter()
            .map(|cs| metric.move_cost(p.robot.mass, cs, g))
            .collect();
        let push_cost: Vec<Vec<u32>> = movables
            .iter()
            .zip(&p.movables)
            .map(|(d, spec)| {
                d.cells
                    .iter()
                    .map(|cs| metric.push_cost(spec.mass, cs, g))
                    .collect()
            })
            .collect();
        let leave_ok = movables
            .iter()
            .map(|d| {
                d.cells
                    .iter()
                    .map(|cs| cs.iter().all(|&c| !g.cells[c as usize].no_leave))
                    .collect()
            })
            .collect();
        let mut contact = Vec::new();
        let mut rot_pre = Vec::new();
        let mut rot_post = Vec::new();
        let k = p.robot.size;
        for (i, spec) in p.movables.iter().enumerate() {
            let lo = -(16 + k + 1);
            let side = 2 * (16 + k + 1) + 1;
            let s2 = (side * side) as usize;
            let orients = movables[i].orients;
            let mut ok = vec![false; 16 * s2];
            let mut pre: [Vec<RotInstance>; 4] = Default::default();
            let mut post: [Vec<RotInstance>; 4] = Default::default();
            for o in 0..orients {
                for mode in &spec.modes {
                    match *mode {
                        ContactMode::Translate { point, dir } => {
                            let (pt, d) = (rot(point, o), dir.rotated(o));
                            for a in p.robot.anchors_touching(pt, d) {
                                let (x, y) = (a.0 - lo, a.1 - lo);
                                ok[(o as usize * 4 + d as usize) * s2 + (y * side + x) as usize] =
                                    true;
                            }
                        }
                        ContactMode::Rotate {
                            point,
                            dir,
                            turn,
                            shift,
                        } => {
                            let (pt, d) = (rot(point, o), dir.rotated(o));
                            let post_o = ((o as i32 + turn as i32).rem_euclid(4)) as u8;
                            let sh = rot(shift, o);
                            let mut all: Vec<(i32, i32)> = spec.cells_at(o);
                            all.extend(
                                spec.cells_at(post_o)
                                    .iter()
                                    .map(|&(x, y)| (x + sh.0, y + sh.1)),
                            );
                            let (x0, x1) = (
                                all.iter().map(|c| c.0).min().unwrap_or(0),
                                all.iter().map(|c| c.0).max().unwrap_or(0),
                            );
                            let (y0, y1) = (
                                all.iter().map(|c| c.1).min().unwrap_or(0),
                                all.iter().map(|c| c.1).max().unwrap_or(0),
                            );
                            let sweep: Vec<(i32, i32)> = (y0..=y1)
                                .flat_map(|y| (x0..=x1).map(move |x| (x, y)))
                                .collect();
                            for a in p.robot.anchors_touching(pt, d) {
                                let inst = RotInstance {
                                    pre_o: o,
                                    robot_off: a,
                                    dir: d,
                                    shift: sh,
                                    post_o,
                                    sweep: sweep.clone(),
                                };
                                pre[o as usize].push(inst.clone());
                                post[post_o as usize].push(inst);
                            }
                        }
                    }
                }
            }
            if !p.rules.rotations {
                pre = Default::default();
                post = Default::default();
            }
            contact.push(ContactTable { lo, side, ok });
            rot_pre.push(pre);
            rot_post.push(post);
        }
        let any_rotation = rot_post.iter().any(|r| r.iter().any(|v| !v.is_empty()));
        let max_edge = metric.max_edge(p, &robot_cost, &push_cost);
        if max_edge > 4000 {
            return invalid(format!(
                "one move may cost {max_edge}: the metric weights are too large (limit 4000)"
            ));
        }
        let mut model = Model {
            problem: p.clone(),
            n_aux,
            robot,
            movables,
            stride: radix
                .iter()
                .scan(1u32, |acc, &r| {
                    let s = *acc;
                    *acc = acc.wrapping_mul(r);
                    Some(s)
                })
                .collect(),
            radix,
            n_states,
            rm,
            touch,
            any_rotation,
            mm,
            robot_cost,
            push_cost,
            leave_ok,
            contact,
            rot_pre,
            rot_post,
            max_edge,
            div: Vec::new(),
        };
        model.div = model.radix.iter().map(|&r| FastDiv::new(r)).collect();
        if model.pack(&p.start).is_none() {
            return invalid(
                "the start configuration overlaps an obstacle, the grid border or another body",
            );
        }
        for (i, g) in p.goal_movables.iter().enumerate() {
            if let Some(pl) = g
                && model.movables[i].lookup(model.w(), model.h(), *pl) == NONE
            {
                return invalid(format!(
                    "movable `{}`: its goal overlaps an obstacle",
                    p.movables[i].name
                ));
            }
        }
        Ok(model)
    }

    /// Grid width.
    pub fn w(&self) -> i32 {
        self.problem.grid.w
    }
    /// Grid height.
    pub fn h(&self) -> i32 {
        self.problem.grid.h
    }
    /// Number of movables.
    pub fn r(&self) -> usize {
        self.movables.len()
    }

    /// Decode a packed index.
    #[inline]
    pub fn decode(&self, idx: u32) -> State {
        let mut s = State {
            aux: 0,
            r: 0,
            m: [0; MAX_MOVABLES],
        };
        let mut x = idx;
        if self.n_aux > 1 {
            (x, s.aux) = self.div[0].div_rem(x);
        }
        (x, s.r) = self.div[1].div_rem(x);
        for i in 0..self.r() {
            (x, s.m[i]) = self.div[2 + i].div_rem(x);
        }
        s
    }

    /// Encode local indices.
    #[inline]
    pub fn encode(&self, s: &State) -> u32 {
        let mut x = 0u32;
        for i in (0..self.r()).rev() {
            x = x * self.radix[2 + i] + s.m[i];
        }
        (x * self.radix[1] + s.r) * self.radix[0] + s.aux
    }

    /// Are the two bodies overlapping? (robot vs movable i)
    #[inline]
    pub fn rm_overlap(&self, i: usize, r: u32, m: u32) -> bool {
        self.rm[i].get(m as usize * self.radix[1] as usize + r as usize)
    }

    /// Are movables i and j (i ≠ j) overlapping?
    #[inline]
    pub fn mm_overlap(&self, i: usize, mi: u32, j: usize, mj: u32) -> bool {
        if i < j {
            match &self.mm[i * MAX_MOVABLES + j] {
                Some(b) => b.get(mi as usize * self.radix[2 + j] as usize + mj as usize),
                None => false,
            }
        } else {
            self.mm_overlap(j, mj, i, mi)
        }
    }

    /// Is a decoded state in the free space CCF (no two bodies overlap)?
    #[inline]
    pub fn valid(&self, s: &State) -> bool {
        let r = self.r();
        for i in 0..r {
            if self.rm_overlap(i, s.r, s.m[i]) {
                return false;
            }
            for j in i + 1..r {
                if self.mm_overlap(i, s.m[i], j, s.m[j]) {
                    return false;
                }
            }
        }
        true
    }

    /// Robot memory index for a last move.
    #[inline]
    pub fn aux_of(&self, dir: Dir, pushing: bool) -> u32 {
        if self.n_aux == 1 {
            0
        } else {
            dir as u32 * 2 + pushing as u32
        }
    }

    /// Pack a grid configuration (None if outside CCF).
    pub fn pack(&self, c: &Config) -> Option<u32> {
        if c.movables.len() != self.r() {
            return None;
        }
        let (w, h) = (self.w(), self.h());
        let r = self.robot.lookup(
            w,
            h,
            Placement {
                x: c.robot.0,
                y: c.robot.1,
                o: 0,
            },
        );
        if r == NONE {
            return None;
        }
        let mut s = State {
            aux: self.aux_of(c.heading, c.pushing),
            r,
            m: [0; MAX_MOVABLES],
        };
        for (i, p) in c.movables.iter().enumerate() {
            let l = self.movables[i].lookup(w, h, *p);
            if l == NONE {
                return None;
            }
            s.m[i] = l;
        }
        self.valid(&s).then(|| self.encode(&s))
    }

    /// Unpack an index into grid terms.
    pub fn unpack(&self, idx: u32) -> Config {
        let s = self.decode(idx);
        let rp = self.robot.place[s.r as usize];
        Config {
            robot: (rp.x, rp.y),
            heading: Dir::from_index((s.aux / 2) as usize),
            pushing: self.n_aux > 1 && s.aux % 2 == 1,
            movables: (0..self.r())
                .map(|i| self.movables[i].place[s.m[i] as usize])
                .collect(),
        }
    }

    /// The goal set: every configuration in CCF with each body at its goal (or anywhere).
    pub fn goal_states(&self) -> Vec<u32> {
        let p = &self.problem;
        let (w, h) = (self.w(), self.h());
        let choices = |dom: &Domain, g: Option<Placement>| -> Vec<u32> {
            match g {
                Some(pl) => {
                    let l = dom.lookup(w, h, pl);
                    if l == NONE { vec![] } else { vec![l] }
                }
                None => (0..dom.len()).collect(),
            }
        };
        let rob = choices(
            &self.robot,
            p.goal_robot.map(|(x, y)| Placement { x, y, o: 0 }),
        );
        let ms: Vec<Vec<u32>> = (0..self.r())
            .map(|i| choices(&self.movables[i], p.goal_movables[i]))
            .collect();
        let mut out = Vec::new();
        let mut s = State {
            aux: 0,
            r: 0,
            m: [0; MAX_MOVABLES],
        };
        let mut digits = vec![0usize; self.r()];
        if ms.iter().any(|v| v.is_empty()) {
            return out;
        }
        loop {
            for i in 0..self.r() {
                s.m[i] = ms[i][digits[i]];
            }
            let movables_ok = (0..self.r())
                .all(|i| (i + 1..self.r()).all(|j| !self.mm_overlap(i, s.m[i], j, s.m[j])));
            if movables_ok {
                for &r in &rob {
                    s.r = r;
                    if (0..self.r()).all(|i| !self.rm_overlap(i, r, s.m[i])) {
                        for a in 0..self.n_aux {
                            s.aux = a;
                            out.push(self.encode(&s));
                        }
                    }
                }
            }
            // next combination
            let mut k = 0;
            loop {
                if k == self.r() {
                    return out;
                }
                digits[k] += 1;
                if digits[k] < ms[k].len() {
                    break;
                }
                digits[k] = 0;
                k += 1;
            }
        }
    }
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

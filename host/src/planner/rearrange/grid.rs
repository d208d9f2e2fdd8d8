//! The table grid of Ben-Shahar & Rivlin §II-A: cells (static obstacles 𝓘, passability,
//! no-leave areas), the four directions of motion and quarter turns of cell offsets. Below
//! both the problem and the metric.

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

//! A pushing problem as a scene describes it (Ben-Shahar & Rivlin §II-A): the robot 𝓡, the
//! movables 𝓜₁…𝓜ᵣ with their contact modes (Fig. 15 and 18), the admissibility rules (§IV-B),
//! the metric (§IV-C), a start and goals.

use super::super::grid::{Dir, Grid, rot};
use super::super::metric::Metric;

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

/// A [`ProblemError::Invalid`] with message `msg`.
pub(super) fn invalid<T>(msg: impl Into<String>) -> Result<T, ProblemError> {
    Err(ProblemError::Invalid(msg.into()))
}

impl Problem {
    /// Is `c` in the free space CCF (every body on free cells of the grid, no two overlapping)?
    /// The same test as packing into a model's tables, for any number of movables.
    pub fn is_free(&self, c: &Config) -> bool {
        if c.movables.len() != self.movables.len() {
            return false;
        }
        let g = &self.grid;
        let mut taken = vec![false; (g.w * g.h).max(0) as usize];
        let mut place = |cells: Vec<(i32, i32)>, (ax, ay): (i32, i32)| -> bool {
            cells.into_iter().all(|(x, y)| {
                let (x, y) = (ax + x, ay + y);
                if !g.free(x, y) {
                    return false;
                }
                let k = (y * g.w + x) as usize;
                !std::mem::replace(&mut taken[k], true)
            })
        };
        place(self.robot.cells(), c.robot)
            && self.movables.iter().zip(&c.movables).all(|(m, p)| {
                (p.o == 0 || m.rotates && p.o < 4) && place(m.cells_at(p.o), (p.x, p.y))
            })
    }
}
